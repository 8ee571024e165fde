"""Old import path of the MD engine, kept for the code that still uses it (``nanoimpact md`` looks
``run_recipe`` up here, and tests and benchmarks patch it here). New code imports :mod:`md.engine` (plan, store,
engines, the run loop) and :mod:`md.workflows` (``run_recipe``, ``run_hash``)."""
from __future__ import annotations

from md.engine.hashing import lammps_version, package_version
from md.engine.lammps import LOG_TAIL_LINES, MDRunError
from md.engine.lammps import InProcess as _InProcess  # noqa: F401  (benchmarks/bench_md_engine.py patches it)
from md.engine.plan import Analysis, Frames, Leg, Plan, Stage, id_ranges
from md.engine.runner import SCHEMA_VERSION, Interrupted
from md.engine.store import RunContext, RunOutcome, cache_root, read_frames, read_samples
from md.workflows.facade import MDResult, run_hash, run_recipe

__all__ = ["Stage", "Leg", "Frames", "Plan", "Analysis", "RunContext", "MDRunError", "Interrupted", "RunOutcome",
           "MDResult", "run_recipe", "run_hash", "cache_root", "SCHEMA_VERSION", "LOG_TAIL_LINES", "read_samples",
           "read_frames", "lammps_version", "package_version", "id_ranges"]
