"""The MD engine: runs what a workflow planned, in chunks, with a content-hashed cache, restarts and resume.

:mod:`~md.engine.plan` (the data model a workflow fills in: a leaf), :mod:`~md.engine.hashing` (the run hash),
:mod:`~md.engine.provenance` (the versions and machine a result records, and how they differ from the running ones),
:mod:`~md.engine.store` (run directories, samples, frames, export), :mod:`~md.engine.lammps` (the in-process and
``mpirun`` engines), :mod:`~md.engine.runner` (the leg loop and the run). The engine never imports a workflow
or a recipe: :mod:`md.workflows` hands it a :class:`~md.engine.plan.Job` and the workflow object.
"""
from md.engine.hashing import run_hash
from md.engine.lammps import MDRunError
from md.engine.plan import Analysis, Frames, Job, Leg, Plan, Stage, id_ranges
from md.engine.provenance import describe_differences, version_differences
from md.engine.runner import Interrupted, run_job
from md.engine.store import RunContext, RunOutcome, cache_root, read_frames, read_samples

__all__ = ["Analysis", "Frames", "Job", "Leg", "Plan", "Stage", "id_ranges", "run_hash", "run_job", "Interrupted",
           "MDRunError", "RunContext", "RunOutcome", "cache_root", "read_frames", "read_samples",
           "describe_differences", "version_differences"]
