"""`nanoimpact sweep`: one scene over a Cartesian product of overrides, resumable, tidy table + plot.

Every point is validated (continuum.scene.resolve_scene) before anything runs or is written, so a
bad value stops the sweep with one line naming the key, the value and the allowed range. Each point's
result.json lands in DIR/points/<input hash[:16]>/ (the hash of the resolved physics inputs), so a
rerun skips finished points and never mixes a changed input with an old result. DIR/sweep.csv has
one row per point; DIR/sweep.png plots the first rebound height and the rebound count against the
first varied key.

A point that fails while running (a refusal that needs the model, a solver that does not finish, a
Dask worker lost) does not stop the others: its row says status `failed` with the one-line reason in
the `error` column, DIR/failures.json lists every failed point, and the record's `failed` list and
`exit_code` (nanoimpact.errors.EXIT_PARTIAL) tell the command line to exit non-zero. A failed point
writes no result.json, so a rerun tries it again and reuses the rest.
"""
from __future__ import annotations

import csv
import io
import itertools
import logging
import time
from pathlib import Path

from matplotlib.figure import Figure

from continuum.api import ImpactResult, SceneError, load_scene, read_result, run_scene
from nanoimpact.errors import EXIT_OK, EXIT_PARTIAL
from nanoimpact.executors import Failure, Local, check_executor, executor
from nanoimpact.fileio import atomic_write_bytes, atomic_write_json, atomic_write_text

log = logging.getLogger(__name__)

COLUMNS = ("status", "n_bounces", "rebounds_above_1e-3_h0", "first_rebound_height_m", "first_restitution",
           "longest_contact_s", "adhesion_law", "half_space", "menisci", "input_hash", "error")


def parse_vary(specs: list[str]) -> dict[str, list]:
    """['KEY=V1,V2', ...] -> {KEY: [values]} (numbers as float/int, others as strings)."""
    out = {}
    for spec in specs:
        if "=" not in spec:
            raise SceneError("--vary", spec, "must be KEY=V1,V2,... (dotted scene key, file units)")
        key, values = spec.split("=", 1)
        parsed = []
        for v in values.split(","):
            v = v.strip()
            try:
                parsed.append(int(v) if v.lstrip("-").isdigit() else float(v))
            except ValueError:
                parsed.append({"true": True, "false": False}.get(v.lower(), v))
        if not parsed or key.strip() in out:
            raise SceneError("--vary", spec, "needs at least one value, and each key once")
        out[key.strip()] = parsed
    return out


def plan(scene: str, vary: dict[str, list], params: str | None = None) -> list[dict]:
    """Every point as {overrides, hash}; raises SceneError for the first invalid one (nothing written)."""
    points = []
    keys = list(vary)
    for combo in itertools.product(*(vary[k] for k in keys)):
        overrides = dict(zip(keys, combo))
        resolved = load_scene(scene, params=params, overrides=overrides, override_label="sweep")
        points.append({"overrides": overrides, "hash": resolved.input_hash})
    return points


def _row(result: ImpactResult) -> dict:
    h0 = result.release_height
    b = result.bounces
    reb = [x.rebound_height for x in b if x.rebound_height is not None]
    above = [r for r in reb if h0 is None or r > 1e-3 * h0]
    m = result.models
    adhesion, half_space, menisci = (m.get(name) for name in ("adhesion", "half_space", "menisci"))
    return {"status": result.status, "n_bounces": result.n_bounces, "rebounds_above_1e-3_h0": len(above),
            "first_rebound_height_m": reb[0] if reb else 0.0, "first_restitution": b[0].restitution if b else None,
            "longest_contact_s": result.regimes.get("longest_contact_s"),
            "adhesion_law": adhesion.numbers.get("law") if adhesion else None,
            "half_space": half_space.used if half_space else None, "menisci": menisci.used if menisci else None,
            "input_hash": result.input_hash, "error": ""}


def _failed_row(input_hash: str, reason: str) -> dict:
    return {**{k: None for k in COLUMNS}, "status": "failed", "input_hash": input_hash, "error": reason}


def run_point(task: tuple) -> dict:
    """Run one point (module-level: picklable for process pools and Dask) and write its result.json."""
    scene, params, overrides, folder = task
    result = run_scene(load_scene(scene, params=params, overrides=overrides, override_label="sweep"))
    Path(folder).mkdir(parents=True, exist_ok=True)
    result.write_record(folder)
    return _row(result)


def _absolute(spec):
    """A path that exists here, made absolute (a Dask worker's working directory may differ); names unchanged."""
    return str(Path(spec).resolve()) if spec is not None and Path(spec).is_file() else spec


def run_sweep(scene: str, vary: dict[str, list], out: str | Path, *, params: str | None = None,
              executor_name: str = "local", workers: int | None = None, scheduler: str | None = None,
              progress=log.info) -> dict:
    """Run (or resume) the sweep; a point that fails is recorded and the others go on.

    Returns {"rows", "computed", "reused", "failed": [{overrides, input_hash, error}], "exit_code", "wall_s"};
    `exit_code` is EXIT_PARTIAL (4) when any point failed, else 0. SceneError (nothing run or written) for an
    invalid point; the executor's errors (InputError, BackendUnavailable) for a bad executor choice.
    """
    start = time.perf_counter()
    points = plan(scene, vary, params)
    check_executor(executor_name, workers, scheduler)
    out = Path(out)
    rows: list[dict | None] = [None] * len(points)
    todo = []
    for i, p in enumerate(points):
        folder = out / "points" / p["hash"][:16]
        if (folder / "result.json").is_file():
            rows[i] = _row(read_result(folder))
        else:
            todo.append((i, (_absolute(scene), _absolute(params), p["overrides"], str(folder.resolve()))))
    progress(f"sweep: {len(points)} points, {len(points) - len(todo)} reused, {len(todo)} to run "
             f"({executor_name})")
    failed = []
    # the executor logs where it runs (a Dask dashboard's address); nothing to run: no cluster started
    with executor(executor_name, workers, scheduler) if todo else Local() as ex:
        results = ex.map(run_point, [t for _, t in todo], on_error="collect")
        for done, (k, row) in enumerate(results, 1):
            i = todo[k][0]
            if isinstance(row, Failure):
                rows[i] = _failed_row(points[i]["hash"], row.reason)
                failed.append({"overrides": points[i]["overrides"], "input_hash": points[i]["hash"],
                               "error": row.reason})
                progress(f"  [{done}/{len(todo)}] {points[i]['overrides']}: FAILED: {row.reason}")
                continue
            rows[i] = row
            progress(f"  [{done}/{len(todo)}] {points[i]['overrides']}: {row['status']}, "
                     f"{row['rebounds_above_1e-3_h0']} rebounds")
    keys = list(vary)
    table = [{**{k: p["overrides"][k] for k in keys}, **r} for p, r in zip(points, rows)]
    out.mkdir(parents=True, exist_ok=True)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=keys + list(COLUMNS))
    w.writeheader()
    w.writerows(table)
    atomic_write_text(out / "sweep.csv", buf.getvalue())
    plot(table, keys, out / "sweep.png")
    order = {p["hash"]: i for i, p in enumerate(points)}
    failed.sort(key=lambda f: order[f["input_hash"]])
    if failed:
        atomic_write_json(out / "failures.json", {"scene": str(scene), "params": params, "failed": failed,
                                                  "points": len(points)})
        log.warning("sweep: %d of %d points failed (%s)", len(failed), len(points), out / "failures.json")
    else:
        (out / "failures.json").unlink(missing_ok=True)      # a rerun that ran them all: no stale list
    return {"rows": table, "computed": len(todo), "reused": len(points) - len(todo), "failed": failed,
            "exit_code": EXIT_PARTIAL if failed else EXIT_OK, "wall_s": time.perf_counter() - start}


def plot(table: list[dict], keys: list[str], path: Path, ax=None):
    """First rebound height and rebound count against the first varied key (one line per other combo).

    Failed points (status `failed`) are left out. Drawn on matplotlib's object API (no backend, no pyplot)."""
    if ax is None:
        ax = Figure(figsize=(7, 4)).subplots()
    ax2 = ax.twinx()
    x_key = keys[0]
    groups: dict[tuple, list[dict]] = {}
    for row in table:
        if row.get("status") == "failed":
            continue
        groups.setdefault(tuple((k, row[k]) for k in keys[1:]), []).append(row)
    for label, rows in groups.items():
        rows = sorted(rows, key=lambda r: r[x_key])
        xs = [r[x_key] for r in rows]
        name = ", ".join(f"{k}={v}" for k, v in label) or "sweep"
        line, = ax.plot(xs, [r["first_rebound_height_m"] * 1e9 for r in rows], "o-", label=f"{name}: first rebound")
        ax2.plot(xs, [r["rebounds_above_1e-3_h0"] for r in rows], "s--", color=line.get_color(), mfc="none")
    n_failed = sum(row.get("status") == "failed" for row in table)
    if n_failed:
        ax.set_title(f"{n_failed} of {len(table)} points failed (left out; see failures.json)", fontsize=8)
    ax.set_xlabel(x_key)
    ax.set_ylabel("first rebound height (nm), filled")
    ax2.set_ylabel("rebounds above 1e-3 h0, open")
    if groups:
        ax.legend(fontsize=7)
    ax.figure.tight_layout()
    buf = io.BytesIO()
    ax.figure.savefig(buf, format="png", dpi=110)
    atomic_write_bytes(path, buf.getvalue())
    return ax
