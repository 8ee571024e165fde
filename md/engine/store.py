"""The run store: where a run directory lives, what it holds, and reading it back.

The run directory is ``<cache>/<recipe>-<fidelity>-<hash16>``; ``<cache>`` is ``--cache DIR``, else the
``NANOIMPACT_CACHE`` environment variable, else ``~/.cache/nanoimpact/md`` -- outside the work tree. A leg's data
are ``legs/<leg>/samples.csv`` (a step and a stage column first), ``legs/<leg>/frames/<end step>.npz``,
``legs/<leg>/state.json`` and its restart files; the run's ``result.json`` and ``export/`` (curves and figures)
are copied to ``--out`` by :func:`export`.
"""
from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from md.engine.plan import Leg, Plan
from nanoimpact.fileio import atomic_write_bytes, atomic_write_text

__all__ = ["DEFAULT_CACHE", "cache_root", "read_samples", "read_frames", "parse_ave_time", "parse_dump",
           "leg_state", "truncate_samples", "export", "write_csv", "RunContext", "RunOutcome"]

DEFAULT_CACHE = Path("~/.cache/nanoimpact/md")


def cache_root(cache: str | Path | None = None) -> Path:
    if cache:
        return Path(cache).expanduser().resolve()
    env = os.environ.get("NANOIMPACT_CACHE", "").strip()
    return Path(env).expanduser().resolve() if env else DEFAULT_CACHE.expanduser()


def run_dir_for(name: str, fidelity: str, digest: str, cache: str | Path | None = None) -> Path:
    """The run directory of recipe ``name`` at ``fidelity`` with run hash ``digest`` in the cache (the one place
    that names it)."""
    return cache_root(cache) / f"{name}-{fidelity}-{digest[:16]}"


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


def parse_ave_time(path: Path) -> np.ndarray:
    rows = []
    if path.exists():
        for line in path.read_text().splitlines():
            if line.startswith("#") or not line.strip():
                continue
            rows.append([float(x) for x in line.split()])
    return np.array(rows, float) if rows else np.zeros((0, 0))


def parse_dump(path: Path) -> list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]:
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


def leg_state(leg_dir: Path) -> dict[str, Any]:
    p = leg_dir / "state.json"
    return json.loads(p.read_text()) if p.exists() else {}


def truncate_samples(path: Path, step: int) -> int:
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


def export(run_dir: Path, out_dir: Path | None) -> Path | None:
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


def write_csv(path: Path, columns: Sequence[str], rows: np.ndarray) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in np.atleast_2d(rows):
        w.writerow([repr(float(x)) for x in r])
    path.write_text(buf.getvalue())


@dataclass
class RunContext:
    """Handed to ``workflow.analyse``: where the legs' data are, the plan, and the job's typed settings."""
    run_dir: Path
    plan: Plan
    settings: Any

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
