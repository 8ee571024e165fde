"""The run loop: a :class:`~md.engine.plan.Job`'s legs in chunks, with a content-hashed cache, restarts and resume.

It runs what a workflow planned and hands the stored data back to the workflow's ``analyse``; it never imports
a workflow or a recipe (:mod:`md.workflows` calls it with both resolved).

Where
    The run directory is ``<cache>/<recipe>-<fidelity>-<hash16>`` (:mod:`md.engine.store`). The hash is the
    SHA-256 of the recipe's resolved content at that fidelity, the bytes of the force-field files and the
    workflow's protocol version (:func:`md.engine.hashing.run_hash`); the nanoimpact and LAMMPS versions are
    recorded in ``result.json``'s provenance, not hashed. A run directory holding a ``result.json`` is a finished
    run: it is reused, not repeated (logged at INFO, with a warning naming the versions when they differ from the
    running ones; ``same_versions`` runs it again instead).

Chunks, restarts and resume
    After each chunk (1) the samples LAMMPS wrote during the chunk (``fix ave/time ... file``, a step column
    first) are appended to ``legs/<leg>/samples.csv`` -- only rows with chunk start < step <= chunk end, so a
    chunk boundary never gives a duplicate -- and stored configurations go to ``frames/<end>.npz``; then (2)
    the restart file LAMMPS wrote is renamed into place and ``state.json`` records its step (atomic renames).
    ``--resume`` reads ``state.json``, drops every sample and frame file past the restart's step (a crash
    between (1) and (2) leaves such rows) and continues from that restart. Nothing is lost or counted twice.
    Without ``--resume`` an unfinished run directory is cleared and the run starts again.

One writer per run directory
    :func:`run_job` holds :func:`nanoimpact.lock.run_lock` (``flock`` on ``<run dir>.lock`` beside the run
    directory) from the cache check to the export of ``result.json``. A second process (a second command, a Dask
    retry) on the same run waits for the first and then reuses its finished result -- or, with ``wait=False``
    (``--no-wait``), stops at once with :class:`nanoimpact.errors.RunBusy` naming the holder's PID, host and start
    time. The kernel drops the lock when its holder dies, SIGKILL included, so a killed run never blocks the
    next one; its restart files stay, for ``--resume``. Every file of the run directory is written by one
    process, and ``result.json``, ``state.json``, ``hash.json``, frame files and the files exported to
    ``--out`` atomically (unique temporary name, fsync, rename: :mod:`nanoimpact.fileio`); ``samples.csv`` is
    appended to, and ``--resume`` drops rows past the committed restart and a torn last row.
    Each invocation that runs MD appends its ``np``, ``jobs``, ``fill_cores`` and host to ``invocations.json``;
    ``result.json`` gives them under ``provenance.md_invocations`` and, at its top level, the last one's, so a
    reanalysis (``--resume`` on a finished run, no MD) records how the legs ran, not how it was invoked.

Legs in parallel
    ``jobs`` > 1 runs up to that many legs at once, each in a forked child process (``np`` ranks each), a leg
    starting as soon as the legs it reads from (:attr:`~md.engine.plan.Leg.after`) are done; legs of a workflow
    that declares nothing wait for every earlier leg, so they still run one after the other. A leg's result does
    not depend on when it runs (its inputs are its predecessors' restarts, its seeds its own), so the samples are
    the same as in one process. The children are forked, not spawned, because legs hold closures; the parent never
    loads LAMMPS before forking. The parent follows the children's committed ``state.json`` for the progress bar; a
    failed child stops the others (their last restarts stay, for ``--resume``) and its error is raised here. Each
    child leads a process group of its own (a stop reaches its ``mpirun`` and ranks) and, on Linux, is sent SIGTERM
    when the parent dies, so no leg runs on after a parent killed outright. Independent legs are what a many-core
    machine gains from: the systems are small and MPI scales poorly on them. With ``fill`` (``--fill-cores``) a leg
    that would run alone -- no other leg running or able to start -- gets all ``jobs`` x ``np`` cores as MPI ranks;
    its samples then differ from a one-process run's by the rounding that another rank count brings (each leg's
    ``ranks`` in ``result.json`` says what it ran on).

Errors
    A LAMMPS error (lost atoms, bad parameters, ...) raises :class:`~md.engine.lammps.MDRunError`;
    ``result.json`` is written only at the very end (temporary file + rename), so a failed run never leaves one.
"""
from __future__ import annotations

import contextlib
import datetime
import io
import json
import logging
import os
import platform
import shutil
import sys
import time
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from md import units
from md.engine.hashing import run_hash
from md.engine.lammps import InProcess, MDRunError, MpiRun
from md.engine.plan import Job, Leg, Planner, leg_dependencies
from md.engine.provenance import describe_differences, run_provenance, version_differences
from md.engine.store import (
    RunContext,
    RunOutcome,
    export,
    leg_state,
    parse_ave_time,
    parse_dump,
    run_dir_for,
    truncate_samples,
    write_csv,
)
from nanoimpact.fileio import atomic_write_bytes, atomic_write_text, clean_json
from nanoimpact.lock import run_lock

__all__ = ["run_job", "Interrupted", "SCHEMA_VERSION", "RESTARTS_KEPT"]

log = logging.getLogger(__name__)

SCHEMA_VERSION = 1
RESTARTS_KEPT = 2
#: the run directory's record of the invocations that ran MD (their np, jobs, fill_cores, host, first step)
INVOCATIONS = "invocations.json"


class Interrupted(RuntimeError):
    """Raised by ``stop_after_chunks`` (tests: a run cut short after a restart, like a killed process)."""


# ================================================================================================ leg runner

def _leg_state_for_start(leg: Leg, leg_dir: Path, resume: bool) -> dict[str, Any]:
    """The leg's state to run from: the stored one when resuming (samples and frames past its last restart
    dropped), else a fresh leg directory and state."""
    state = leg_state(leg_dir) if resume else {}
    if state.get("done"):
        return state
    if not state:
        if leg_dir.exists():
            shutil.rmtree(leg_dir)
        leg_dir.mkdir(parents=True)
        return {"step": 0, "restart": None, "dynamics_wall_s": 0.0, "setup_wall_s": 0.0, "chunks": 0,
                "done": False, "n_atoms": leg.n_atoms, "total_steps": leg.total_steps}
    dropped = truncate_samples(leg_dir / "samples.csv", state["step"])
    for f in (leg_dir / "frames").glob("*.npz"):
        if int(f.stem) > state["step"]:
            f.unlink()
            dropped += 1
    state["resumed_from"] = state["step"]
    state["dropped_on_resume"] = state.get("dropped_on_resume", 0) + dropped
    return state


def _chunk_commands(leg: Leg, k: int, stage_start: bool, n: int, leg_dir: Path) -> tuple[list[str], bool]:
    """The LAMMPS commands of one chunk of ``n`` steps of stage ``k`` (the stage's ``begin`` if the chunk starts
    it; sampling, frames of sampled stages, the restart written to ``restart.tmp``) and whether it stores frames;
    the chunk's sample and frame files are removed first."""
    stage = leg.stages[k]
    cmds: list[str] = list(stage.begin) if stage_start else []
    chunk_file = leg_dir / "chunk_samples.dat"
    dump_file = leg_dir / "chunk_frames.dump"
    for f in (chunk_file, dump_file):
        if f.exists():
            f.unlink()
    si = leg.sample_interval
    cmds.append(f"fix _samp all ave/time {si} 1 {si} {' '.join(leg.columns.values())} file {chunk_file.as_posix()}")
    use_frames = leg.frames is not None and stage.sampled
    if use_frames:
        cmds += [f"dump _frames {leg.frames.group} custom {leg.frames.interval} {dump_file.as_posix()} "
                 f"id x y z", "dump_modify _frames sort id"]
    cmds.append(f"run {n}")
    cmds.append("unfix _samp")
    if use_frames:
        cmds.append("undump _frames")
    cmds.append(f"write_restart {(leg_dir / 'restart.tmp').as_posix()}")
    return cmds, use_frames


def _store_chunk(leg_dir: Path, k: int, step: int, end: int, use_frames: bool) -> None:
    """Append the chunk's samples (steps in (step, end]) to samples.csv, durably, and store its frames as one
    ``frames/<end>.npz``."""
    rows = parse_ave_time(leg_dir / "chunk_samples.dat")
    if rows.size:
        rows = rows[(rows[:, 0] > step) & (rows[:, 0] <= end)]
        with open(leg_dir / "samples.csv", "a") as fh:
            for r in rows:
                fh.write(",".join([str(int(r[0])), str(k)] + [repr(float(x)) for x in r[1:]]) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
    if use_frames:
        fr = [f for f in parse_dump(leg_dir / "chunk_frames.dump") if step < f[0] <= end]
        if fr:
            buf = io.BytesIO()
            np.savez(buf, steps=np.array([f[0] for f in fr]), ids=fr[0][1],
                     positions=np.stack([f[2] for f in fr]), box=np.stack([f[3] for f in fr]))
            atomic_write_bytes(leg_dir / "frames" / f"{end}.npz", buf.getvalue())


def _commit_chunk(leg: Leg, leg_dir: Path, state: dict[str, Any], end: int) -> Path:
    """Commit the chunk's restart, then the state; keep the last :data:`RESTARTS_KEPT` restarts."""
    final = leg_dir / f"restart.{end}"
    os.replace(leg_dir / "restart.tmp", final)
    state.update(step=end, restart=final.name, chunks=state["chunks"] + 1, done=end >= leg.total_steps)
    atomic_write_text(leg_dir / "state.json", json.dumps(state, indent=1))
    restarts = sorted(leg_dir.glob("restart.[0-9]*"), key=lambda p: int(p.suffix[1:]))
    for p in restarts[:-RESTARTS_KEPT]:
        p.unlink()
    return final


def leg_host() -> str:
    """The machine a leg (or a part of it) ran on, as its state records it: host name, architecture, cores (a
    leg resumed elsewhere lists both, so a result whose legs ran on several machines says which ran where)."""
    return f"{platform.node()} ({platform.machine()}, {os.cpu_count()} cores)"


def _run_leg(leg: Leg, leg_dir: Path, *, np_: int, resume: bool, progress, chunk_counter: list[int],
             stop_after_chunks: int | None, extra_commands: Sequence[str]) -> dict[str, Any]:
    """Run (or resume) one leg chunk by chunk: each chunk's samples and frames are stored, then its restart and
    the leg's state committed, so an interrupted leg resumes from its last restart."""
    state = _leg_state_for_start(leg, leg_dir, resume)
    if state.get("done"):
        return state
    (leg_dir / "frames").mkdir(exist_ok=True)
    samples_csv = leg_dir / "samples.csv"
    if not samples_csv.exists():
        atomic_write_text(samples_csv, ",".join(["step", "stage"] + list(leg.columns)) + "\n")
    state["ranks"] = sorted(set(state.get("ranks", [])) | {np_})     # a resumed leg may have run on other counts
    state["hosts"] = sorted(set(state.get("hosts", [])) | {leg_host()})   # ... and on another machine
    engine = InProcess(leg_dir) if np_ <= 1 else MpiRun(leg_dir, np_)
    try:
        t0 = time.perf_counter()
        step = int(state["step"])
        if state["restart"]:
            head = leg.restart_head(leg_dir / state["restart"]) + leg.define(step) + list(extra_commands)
        else:
            head = leg.fresh(leg_dir) + leg.define(0) + list(extra_commands) + leg.prepare(leg_dir)
        engine.start(head)
        if np_ <= 1:
            state["setup_wall_s"] += time.perf_counter() - t0
        while step < leg.total_steps:
            k, s0, s1 = leg.stage_at(step)
            n = min(leg.chunk_steps, s1 - step)
            end = step + n
            cmds, use_frames = _chunk_commands(leg, k, step == s0, n, leg_dir)
            t1 = time.perf_counter()
            engine.chunk(cmds)
            state["dynamics_wall_s"] += time.perf_counter() - t1
            _store_chunk(leg_dir, k, step, end, use_frames)
            final = _commit_chunk(leg, leg_dir, state, end)
            step = end
            if np_ > 1 and step < leg.total_steps:      # the next mpirun starts from this restart
                engine.start(leg.restart_head(final) + leg.define(step) + list(extra_commands))
            if progress is not None:
                progress.update(n)
            chunk_counter[0] += 1
            if stop_after_chunks is not None and chunk_counter[0] >= stop_after_chunks and step < leg.total_steps:
                raise Interrupted(f"stopped after {chunk_counter[0]} chunks (leg {leg.name}, step {step})")
        if engine.version:
            state["lammps_version_string"] = engine.version
        state["done"] = True
        atomic_write_text(leg_dir / "state.json", json.dumps(state, indent=1))
        return state
    finally:
        engine.close()
        for f in ("chunk_samples.dat", "chunk_frames.dump"):
            with contextlib.suppress(OSError):
                (leg_dir / f).unlink()


# ================================================================================================ the run

def run_job(job: Job, workflow: Planner, *, out: str | Path | None = None, cache: str | Path | None = None,
            resume: bool = False, np_: int = 1, progress: bool = True, force: bool = False,
            stop_after_chunks: int | None = None, extra_commands: Sequence[str] = (),
            echo: Callable[[str], None] | None = None, wait: bool = True,
            wait_timeout: float | None = None, jobs: int = 1, fill: bool = False,
            same_versions: bool = False) -> RunOutcome:
    """Run ``job`` with ``workflow``'s plan and analysis (or reuse the cached result) and copy the result into
    ``out``.

    ``np_`` > 1 runs every chunk with ``mpirun -np np_``; ``jobs`` > 1 runs up to that many independent legs at
    once (module docstring, "Legs in parallel"); with ``fill`` a leg that runs alone takes all ``jobs`` x ``np_``
    cores as ranks. ``force`` ignores a cached result. A cached result made under other nanoimpact or LAMMPS
    versions (its ``provenance``; they are not part of the hash) is reused with a warning naming them, or, with
    ``same_versions`` (``--require-same-versions``), discarded and run again. ``stop_after_chunks``
    and ``extra_commands`` (LAMMPS commands issued after each leg's set-up) are for tests and debugging. What the
    run does (reused, discarded, resumed, written) is logged at INFO on ``md.engine.runner``; ``echo``, if given,
    receives the same lines.

    One writer per run directory: everything that reads or writes it (the cache check, the legs, the analysis,
    the export) runs under :func:`nanoimpact.lock.run_lock`. If another process (or thread) is running the same
    recipe, fidelity and hash, ``wait=True`` (default) waits for it -- logging ``waiting for PID N on HOST to
    finish <run dir>`` -- and then goes on as if started afterwards: its finished result is reused (so both
    report the same numbers); after a failed or killed one, the unfinished directory is discarded, or continued
    with ``resume``. ``wait=False`` raises :class:`nanoimpact.errors.RunBusy` (exit code 75) at once, and
    ``wait_timeout`` (seconds) raises it after that long.
    """
    def say(line: str) -> None:
        log.info("%s", line)
        if echo is not None:
            echo(line)

    digest, hashed = run_hash(job.canonical, job.fidelity, job.forcefield_files, job.workflow_version)
    run_dir = run_dir_for(job.name, job.fidelity, digest, cache)
    with run_lock(run_dir, wait=wait, timeout=wait_timeout,
                  hint="wait for it to finish and run again, or leave out --no-wait to wait for it"):
        return _run_locked(job, workflow, digest, hashed, run_dir, out=out, resume=resume, np_=np_,
                           progress=progress, force=force, stop_after_chunks=stop_after_chunks,
                           extra_commands=extra_commands, say=say, jobs=jobs, fill=fill,
                           same_versions=same_versions)


def _run_locked(job: Job, wf: Planner, digest: str, hashed: Mapping[str, Any], run_dir: Path, *, out,
                resume: bool, np_: int, progress: bool, force: bool, stop_after_chunks: int | None,
                extra_commands: Sequence[str], say: Callable[[str], None], jobs: int = 1,
                fill: bool = False, same_versions: bool = False) -> RunOutcome:
    """:func:`run_job`'s work on ``run_dir``; the caller holds its lock."""
    result_path = run_dir / "result.json"
    refused = False
    if result_path.exists() and not force and not extra_commands:
        result = json.loads(result_path.read_text())
        made = describe_differences(version_differences(result.get("provenance", {})))
        refused = bool(made) and same_versions
        if not refused:
            if made:
                log.warning("cached result %s %s", result_path, made)
            say(f"reusing cached result {result_path} (run hash {digest[:16]}{'; ' + made if made else ''}); "
                "nothing was run")
            return RunOutcome(result, run_dir, True, export(run_dir, out))
        say(f"not reusing the cached result {result_path}: {made}, and the same versions are required; "
            "running it again")
    if run_dir.exists() and (refused or not resume):
        if any(run_dir.iterdir()):
            say(f"discarding the unfinished (or forced) run in {run_dir}; use --resume to continue it")
        shutil.rmtree(run_dir)
    if result_path.exists():
        result_path.unlink()
    run_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_text(run_dir / "hash.json", json.dumps(hashed, indent=1, sort_keys=True))
    plan = wf.plan(job.settings, run_dir)
    total = sum(l.total_steps for l in plan.legs)
    done = 0
    if resume:
        for l in plan.legs:
            st = leg_state(run_dir / "legs" / l.name)
            done += int(st.get("step", 0)) if st else 0
        if done:
            say(f"resuming {run_dir.name} at {done} of {total} steps")
    say(f"{job.name} [{job.fidelity}]: {len(plan.legs)} leg(s), {plan.n_atoms} atoms, {total} MD steps, "
        f"run directory {run_dir}" + (f", up to {jobs} legs at a time" if jobs > 1 else "")
        + (f", a leg alone on {jobs * np_} ranks" if fill and jobs > 1 else ""))
    t_start = time.perf_counter()
    if done < total:
        _record_invocation(run_dir, np_=np_, jobs=jobs, fill=fill, from_step=done)
    legs_state = _run_legs(job, plan, run_dir, done=done, total=total, np_=np_, resume=resume, progress=progress,
                           stop_after_chunks=stop_after_chunks, extra_commands=extra_commands, jobs=jobs, fill=fill)
    result = _analyse_and_record(job, wf, digest, plan, run_dir, legs_state, reanalysed=resume and done == total,
                                 t_start=t_start)
    atomic_write_text(result_path, json.dumps(clean_json(result), indent=1))
    say(f"wrote {result_path}")
    return RunOutcome(json.loads(result_path.read_text()), run_dir, False, export(run_dir, out))


def _record_invocation(run_dir: Path, *, np_: int, jobs: int, fill: bool, from_step: int) -> None:
    """Append this invocation's parallel flags to ``invocations.json`` before it runs MD, so that a later
    reanalysis (``--resume`` on a finished run) records how the legs ran, not how it was itself invoked."""
    path = run_dir / INVOCATIONS
    past = json.loads(path.read_text()) if path.exists() else []
    past.append({"np": np_, "jobs": jobs, "fill_cores": fill, "from_step": from_step, "host": leg_host(),
                 "started_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")})
    atomic_write_text(path, json.dumps(past, indent=1))


def _md_flags(run_dir: Path) -> tuple[dict[str, Any], list]:
    """``np``, ``jobs`` and ``fill_cores`` of the last invocation that ran MD (``invocations.json``: this one when it
    ran MD, an earlier one after a reanalysis), with the whole record; None for a run directory that predates the
    record (each leg's ``ranks`` and ``hosts`` still say how it ran)."""
    path = run_dir / INVOCATIONS
    invocations = json.loads(path.read_text()) if path.exists() else []
    last = invocations[-1] if invocations else {}
    return {k: last.get(k) for k in ("np", "jobs", "fill_cores")}, invocations


def _run_legs(job: Job, plan, run_dir: Path, *, done: int, total: int, np_: int, resume: bool, progress: bool,
              stop_after_chunks: int | None, extra_commands: Sequence[str], jobs: int = 1,
              fill: bool = False) -> dict[str, Any]:
    """Every leg of ``plan`` in order (:func:`_run_leg`), or up to ``jobs`` at once (:func:`_run_legs_parallel`),
    behind a progress bar if asked; their final states."""
    if jobs > 1 and stop_after_chunks is not None:
        raise ValueError("stop_after_chunks counts chunks of one process; it needs jobs = 1")
    bar = None
    if progress:
        try:
            from tqdm import tqdm  # noqa: PLC0415
            if jobs > 1:
                tqdm.monitor_interval = 0        # no monitor thread in a process that forks
            bar = tqdm(total=total, initial=done, unit="step", desc=job.name, file=sys.stderr,
                       dynamic_ncols=True, leave=False)
        except ImportError:
            bar = None
    if jobs > 1:
        try:
            return _run_legs_parallel(plan, run_dir, jobs=jobs, np_=np_, resume=resume, bar=bar,
                                      extra_commands=extra_commands, name=job.name, fill=fill)
        finally:
            if bar is not None:
                bar.close()
    legs_state: dict[str, Any] = {}
    counter = [0]
    try:
        for leg in plan.legs:
            if bar is not None:
                bar.set_description(f"{job.name}:{leg.name}")
            legs_state[leg.name] = _run_leg(leg, run_dir / "legs" / leg.name, np_=np_, resume=resume,
                                            progress=bar, chunk_counter=counter,
                                            stop_after_chunks=stop_after_chunks, extra_commands=extra_commands)
    finally:
        if bar is not None:
            bar.close()
    return legs_state


#: Seconds between the parent's looks at its children's progress (``jobs`` > 1); a child's end wakes it at once.
POLL_S = 2.0


def _leg_error_path(leg_dir: Path) -> Path:
    return leg_dir.parent / f"{leg_dir.name}.error"


def _die_with_parent(parent: int) -> None:
    """Linux: SIGTERM this process when its parent dies (prctl PR_SET_PDEATHSIG), so a parent killed outright
    (SIGKILL, which runs no clean-up) leaves no leg running on, holding the run's lock; elsewhere a no-op."""
    import ctypes  # noqa: PLC0415
    import signal  # noqa: PLC0415
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM))      # 1 = PR_SET_PDEATHSIG
    if os.getppid() != parent:          # it died before the request took effect
        os._exit(1)


def _leg_child(leg: Leg, leg_dir: Path, np_: int, resume: bool, extra_commands: Sequence[str],
               parent: int) -> None:
    """A forked child's whole life: run one leg; on any error write its message beside the leg directory for the
    parent and exit 1. os._exit: the parent's exit handlers and inherited stdio buffers are not the child's to
    run or flush (a flush could wait on a lock another of the parent's threads held at the fork); what the child
    reports goes to files and to logging, whose handlers flush every record."""
    code = 0
    try:
        os.setpgrp()            # a group of its own: stopping it also stops its mpirun and the ranks
        _die_with_parent(parent)
        _run_leg(leg, leg_dir, np_=np_, resume=resume, progress=None, chunk_counter=[0], stop_after_chunks=None,
                 extra_commands=extra_commands)
    except BaseException as exc:  # noqa: BLE001 -- everything a child meets must reach the parent
        msg = str(exc) or type(exc).__name__
        with contextlib.suppress(OSError):
            atomic_write_text(_leg_error_path(leg_dir), f"{type(exc).__name__}: {msg}")
        code = 1
    os._exit(code)


def critical_paths(legs: Sequence[Leg], waits: Mapping[str, frozenset[str]], remaining: Mapping[str, int]
                   ) -> dict[str, int]:
    """Leg name -> the MD steps from its start to the end of the longest chain of legs that waits on it, its own
    remaining steps included: the run cannot end sooner than that after the leg starts. Starting the ready leg
    with the longest such path first is list scheduling by level (Hu 1961; Adam, Chandy & Dickson, Commun. ACM
    17 (1974) 685), which keeps a long chain of windows from being left to run alone at the end."""
    later: dict[str, list[str]] = {l.name: [] for l in legs}
    for name, before in waits.items():
        for w in before:
            later[w].append(name)
    path: dict[str, int] = {}
    for leg in reversed(legs):          # a leg waits only for earlier legs: every later one is known already
        path[leg.name] = int(remaining[leg.name]) + max((path[m] for m in later[leg.name]), default=0)
    return path


def _run_legs_parallel(plan, run_dir: Path, *, jobs: int, np_: int, resume: bool, bar,
                       extra_commands: Sequence[str], name: str = "md", fill: bool = False) -> dict[str, Any]:
    """Up to ``jobs`` legs at once, each in a forked child, a leg started once every leg it waits for
    (:func:`~md.engine.plan.leg_dependencies`) is done; among the legs that can start, the one with the longest
    chain still behind it first (:func:`critical_paths`), plan order between equals; the legs' final states.

    ``fill``: a leg that starts while no other runs and no other can start gets ``jobs`` x ``np_`` ranks instead
    of ``np_``. Nothing else can start before it ends (a leg waits only for done legs), so the cores it takes
    would otherwise idle: an anneal, a contact, the last chain of windows. A leg keeps its rank count to its end,
    so one that is left alone when a neighbour finishes runs on with ``np_``."""
    import multiprocessing as mp  # noqa: PLC0415
    from multiprocessing.connection import wait as mp_wait  # noqa: PLC0415
    ctx = mp.get_context("fork")
    waits = leg_dependencies(plan.legs)
    legs_dir = run_dir / "legs"
    done = {l.name for l in plan.legs if leg_state(legs_dir / l.name).get("done")}
    counted = {l.name: int(leg_state(legs_dir / l.name).get("step", 0)) for l in plan.legs}
    remaining = {l.name: 0 if l.name in done else max(l.total_steps - counted[l.name], 0) for l in plan.legs}
    priority = critical_paths(plan.legs, waits, remaining)
    order = {l.name: k for k, l in enumerate(plan.legs)}
    running: dict[str, Any] = {}
    shown = [""]

    def count(leg_name: str) -> None:
        step = int(leg_state(legs_dir / leg_name).get("step", 0))
        if bar is not None and step > counted[leg_name]:
            bar.update(step - counted[leg_name])
        counted[leg_name] = max(counted[leg_name], step)

    def follow() -> None:
        if bar is None:
            return
        for leg_name in running:
            count(leg_name)
        desc = f"{name}:{','.join(running)}"[:70]
        if desc != shown[0]:            # a redraw only when the set of running legs changes
            bar.set_description(desc)
            shown[0] = desc

    try:
        while len(done) < len(plan.legs):
            startable = sorted((l for l in plan.legs
                                if l.name not in done and l.name not in running and waits[l.name] <= done),
                               key=lambda l: (-priority[l.name], order[l.name]))
            ranks = jobs * np_ if fill and not running and len(startable) == 1 else np_
            for leg in startable:
                if len(running) >= jobs:
                    break
                leg_dir = legs_dir / leg.name
                with contextlib.suppress(FileNotFoundError):
                    _leg_error_path(leg_dir).unlink()
                proc = ctx.Process(target=_leg_child,
                                   args=(leg, leg_dir, ranks, resume, tuple(extra_commands), os.getpid()),
                                   name=f"md leg {leg.name}", daemon=False)
                proc.start()
                running[leg.name] = proc
                log.info("leg %s started (pid %d)%s", leg.name, proc.pid,
                         f" alone, on {ranks} ranks" if ranks != np_ else "")
            if not running:     # cannot happen for a valid plan: leg_dependencies only allows earlier legs
                raise RuntimeError(f"no leg can start; done: {sorted(done)}")
            mp_wait([p.sentinel for p in running.values()], timeout=POLL_S)
            for leg_name, proc in list(running.items()):
                if proc.exitcode is None:
                    continue
                proc.join()
                del running[leg_name]
                if proc.exitcode != 0:
                    err = _leg_error_path(legs_dir / leg_name)
                    msg = err.read_text() if err.exists() else f"the leg's process ended with code {proc.exitcode}"
                    raise MDRunError(f"leg {leg_name!r} failed: {msg}", "", legs_dir / leg_name / "log.lammps")
                done.add(leg_name)
                count(leg_name)                  # its last chunks, committed since the previous look
                log.info("leg %s done", leg_name)
            follow()
    finally:
        _stop_children(list(running.values()))      # an error or an interrupt: stop the others at once
    return {l.name: leg_state(legs_dir / l.name) for l in plan.legs}


def _stop_children(procs, grace_s: float = 10.0) -> None:
    """SIGTERM to every child's process group (the child, its mpirun, the ranks), SIGKILL to a group still there
    after ``grace_s``. Their last committed restarts stay for ``--resume``."""
    import signal  # noqa: PLC0415

    def signal_group(proc, sig) -> None:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, sig)
    for proc in procs:
        signal_group(proc, signal.SIGTERM)
        proc.terminate()                         # also a child stopped before its setpgrp
    deadline = time.monotonic() + grace_s
    for proc in procs:
        proc.join(max(0.0, deadline - time.monotonic()))
        if proc.exitcode is None:
            signal_group(proc, signal.SIGKILL)
            proc.kill()
            proc.join()
        signal_group(proc, signal.SIGKILL)       # descendants that outlived their child


def _analyse_and_record(job: Job, wf: Planner, digest: str, plan, run_dir: Path, legs_state: Mapping[str, Any], *,
                        reanalysed: bool, t_start: float) -> dict[str, Any]:
    """The workflow's analysis of the finished legs, its curves and figures exported (a figure that fails is
    named in the notes, never loses the run), and the run's ``result.json`` record."""
    analysis = wf.analyse(RunContext(run_dir, plan, job.settings))
    export_dir = run_dir / "export"
    if export_dir.exists():
        shutil.rmtree(export_dir)
    export_dir.mkdir()
    for name, (cols, rows) in analysis.curves.items():
        write_csv(export_dir / f"{name}.csv", cols, rows)
    figure_errors = {}
    for name, draw in analysis.figures.items():
        try:
            draw(export_dir / f"{name}.png")
        except Exception as exc:  # noqa: BLE001 -- a figure must not lose a finished run
            figure_errors[name] = f"{type(exc).__name__}: {exc}"
    md_steps = sum(int(s.get("total_steps", 0)) for s in legs_state.values())
    dyn_wall = sum(float(s.get("dynamics_wall_s", 0.0)) for s in legs_state.values())
    atom_steps = sum(l.n_atoms * l.total_steps for l in plan.legs)
    flags, invocations = _md_flags(run_dir)
    prov = run_provenance(job, plan, legs_state, flags["np"])
    prov["md_invocations"] = invocations
    if reanalysed:
        # every leg had finished: this invocation only re-ran the analysis (e.g. after an analysis fix)
        prov["reanalysed_without_md"] = True
        if not invocations:
            prov["md_flags_note"] = ("np, jobs and fill_cores of the invocations that ran MD were not recorded (the "
                                     "run predates invocations.json); each leg's ranks and hosts say how it ran")
    notes = list(analysis.notes)
    if figure_errors:
        notes.append(f"figures not drawn: {figure_errors}")
    return {
        "schema_version": SCHEMA_VERSION,
        "run_hash": digest,
        "recipe": job.name,
        "workflow": job.workflow,
        "description": job.description,
        "fidelity": job.fidelity,
        "quantities": analysis.quantities,
        "n_atoms": plan.n_atoms,
        "steps": md_steps,
        "timestep_fs": plan.timestep_fs,
        "ns_per_day": units.ns_per_day(md_steps, plan.timestep_fs, dyn_wall),
        "wall_s": {"dynamics": dyn_wall, "total_this_invocation": time.perf_counter() - t_start},
        "atom_steps_per_s": atom_steps / dyn_wall if dyn_wall > 0 else None,
        **flags,
        "seeds": plan.seeds,
        "settings": dict(job.settings_record),
        "system": plan.system_info,
        "legs": {name: {k: s.get(k) for k in ("total_steps", "n_atoms", "chunks", "dynamics_wall_s", "setup_wall_s",
                                              "resumed_from", "dropped_on_resume", "ranks", "hosts")}
                 for name, s in legs_state.items()},
        "provenance": prov,
        "notes": notes,
        "details": analysis.details,
        "files": sorted(p.name for p in export_dir.iterdir()),
    }
