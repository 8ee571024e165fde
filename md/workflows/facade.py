"""The Python front door of md: :func:`run_recipe` (a recipe at a fidelity -> :class:`MDResult`) and
:func:`run_hash` (what the run's hash would be, without running it).

A recipe is resolved here (its settings at the fidelity, its workflow, the force-field files) into an
:class:`md.engine.Job`; the engine runs it with the workflow's plan and analysis. ``nanoimpact md`` calls
:func:`run_recipe` and prints what it returns; the files it writes (``result.json``, curves, figures) are the
engine's.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any, Callable, Mapping, Sequence

from md.engine import hashing
from md.engine.plan import Job
from md.engine.runner import run_job
from md.engine.store import export
from md.recipe import Recipe, load_recipe
from md.workflows.registry import get_workflow
from nanoimpact.fileio import atomic_write_bytes

__all__ = ["MDResult", "run_recipe", "run_hash", "job_for"]


@dataclass(frozen=True)
class MDResult:
    """One finished MD run, typed.

    ``quantities`` (SI values by name), ``stderr`` (their standard errors, None where not estimated) and
    ``units`` come from ``result.json``'s ``quantities``; ``provenance`` is its provenance block; ``result`` is
    the whole ``result.json``. ``run_dir`` is the run directory in the cache, ``reused`` whether the cached
    result was reused (nothing run), ``out_dir`` where the files were copied (or None).
    :meth:`write` copies ``result.json``, the curves and the figures into a folder.
    """
    recipe: str
    workflow: str
    fidelity: str
    run_hash: str
    quantities: Mapping[str, float | None]
    stderr: Mapping[str, float | None]
    units: Mapping[str, str]
    provenance: Mapping[str, Any]
    notes: tuple[str, ...]
    result: Mapping[str, Any]
    run_dir: Path
    reused: bool = False
    out_dir: Path | None = None

    @classmethod
    def from_result(cls, result: Mapping[str, Any], run_dir: Path, reused: bool = False,
                    out_dir: Path | None = None) -> "MDResult":
        q = result.get("quantities", {})
        return cls(recipe=result["recipe"], workflow=result["workflow"], fidelity=result["fidelity"],
                   run_hash=result["run_hash"],
                   quantities=MappingProxyType({k: v.get("value") for k, v in q.items()}),
                   stderr=MappingProxyType({k: v.get("stderr") for k, v in q.items()}),
                   units=MappingProxyType({k: v.get("units", "") for k, v in q.items()}),
                   provenance=MappingProxyType(dict(result.get("provenance", {}))),
                   notes=tuple(result.get("notes", ())), result=result, run_dir=Path(run_dir), reused=reused,
                   out_dir=out_dir)

    @classmethod
    def read(cls, run_dir: str | Path) -> "MDResult":
        """The finished run in ``run_dir`` (a run directory of the cache)."""
        run_dir = Path(run_dir)
        return cls.from_result(json.loads((run_dir / "result.json").read_text()), run_dir)

    def write(self, folder: str | Path) -> Path:
        """Copy ``result.json``, the CSV curves and the PNG figures into ``folder`` (the files ``--out`` gets), from
        a run directory of the cache or from a folder that holds them beside ``result.json`` (``--out``, the
        committed results); each file atomically, ``result.json`` last."""
        folder = Path(folder)
        if (self.run_dir / "export").is_dir():
            return export(self.run_dir, folder)
        folder.mkdir(parents=True, exist_ok=True)
        for f in sorted(self.run_dir.iterdir()):
            if f.is_file() and f.name != "result.json":
                atomic_write_bytes(folder / f.name, f.read_bytes())
        atomic_write_bytes(folder / "result.json", (self.run_dir / "result.json").read_bytes())
        return folder


def job_for(recipe: Recipe, fidelity: str) -> Job:
    """What the engine needs of ``recipe`` at ``fidelity``."""
    wf = get_workflow(recipe.workflow)
    settings = recipe.typed_settings(fidelity)
    return Job(name=recipe.name, workflow=recipe.workflow, description=recipe.description, fidelity=fidelity,
               settings=settings, settings_record=recipe.settings(fidelity), canonical=recipe.canonical(fidelity),
               forcefield_files=tuple(wf.forcefield_files(settings)), workflow_version=wf.protocol_version(settings),
               source=str(recipe.path) if recipe.path else recipe.name, file_sha256=recipe.file_sha256,
               content_sha256=recipe.canonical_sha256(fidelity))


def run_hash(recipe: Recipe | str | Path, fidelity: str,
             forcefield_files: Sequence[str] | None = None) -> tuple[str, dict[str, Any]]:
    """The run hash of ``recipe`` (a Recipe, a shipped name or a file) at ``fidelity``: hex digest and the hashed
    document (:func:`md.engine.hashing.run_hash` with the workflow's version). ``forcefield_files`` defaults to
    the workflow's own for the recipe's settings -- what a run would use."""
    if not isinstance(recipe, Recipe):
        recipe = load_recipe(recipe)
    wf = get_workflow(recipe.workflow)
    settings = recipe.typed_settings(fidelity)
    if forcefield_files is None:
        forcefield_files = wf.forcefield_files(settings)
    return hashing.run_hash(recipe.canonical(fidelity), fidelity, forcefield_files, wf.protocol_version(settings))


def run_recipe(recipe: Recipe | str | Path, fidelity: str = "quick", *, out: str | Path | None = None,
               cache: str | Path | None = None, resume: bool = False, np_: int = 1, progress: bool = True,
               force: bool = False, stop_after_chunks: int | None = None, extra_commands: Sequence[str] = (),
               echo: Callable[[str], None] | None = None, wait: bool = True,
               wait_timeout: float | None = None, jobs: int = 1, fill: bool = False,
               same_versions: bool = False) -> MDResult:
    """Run ``recipe`` (a :class:`~md.recipe.Recipe`, a shipped name or a file) at ``fidelity``, or reuse its
    cached result, and copy the files into ``out``; returns the :class:`MDResult`.

    The options are :func:`md.engine.runner.run_job`'s (cache, resume, MPI ranks, legs at once, idle cores to a
    lone leg, locking, ``same_versions``: rerun a cached result made under other nanoimpact or LAMMPS versions)."""
    if not isinstance(recipe, Recipe):
        recipe = load_recipe(recipe)
    outcome = run_job(job_for(recipe, fidelity), get_workflow(recipe.workflow), out=out, cache=cache,
                      resume=resume, np_=np_, progress=progress, force=force, stop_after_chunks=stop_after_chunks,
                      extra_commands=extra_commands, echo=echo, wait=wait, wait_timeout=wait_timeout, jobs=jobs,
                      fill=fill, same_versions=same_versions)
    return MDResult.from_result(outcome.result, outcome.run_dir, outcome.reused, outcome.out_dir)
