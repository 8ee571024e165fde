"""`nanoimpact sweep`: one scene over a Cartesian product of overrides, resumable, tidy table + plot.

Every point is validated (continuum.scene.resolve_scene) before anything runs or is written, so a
bad value stops the sweep with one line naming the key, the value and the allowed range. Each point's
result.json lands in DIR/points/<input hash[:16]>/ (the hash of the resolved physics inputs), so a
rerun skips finished points and never mixes a changed input with an old result. DIR/sweep.csv has
one row per point; DIR/sweep.png plots the first rebound height and the rebound count against the
first varied key.
"""
from __future__ import annotations

import csv
import itertools
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from continuum.scene import SceneError, resolve_scene  # noqa: E402

from .executors import executor  # noqa: E402

COLUMNS = ("status", "n_bounces", "rebounds_above_1e-3_h0", "first_rebound_height_m", "first_restitution",
           "longest_contact_s", "adhesion_law", "half_space", "menisci", "input_hash")


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
        resolved = resolve_scene(scene, params=params, overrides=overrides, override_label="sweep")
        points.append({"overrides": overrides, "hash": resolved.input_hash})
    return points


def _row(result: dict) -> dict:
    h0 = result["scene"]["si"]["release_height"]
    b = result["bounces"]
    reb = [x["rebound_height"] for x in b if x["rebound_height"] is not None]
    above = [r for r in reb if h0 is None or r > 1e-3 * h0]
    m = result["models"]
    return {"status": result["status"], "n_bounces": result["n_bounces"], "rebounds_above_1e-3_h0": len(above),
            "first_rebound_height_m": reb[0] if reb else 0.0, "first_restitution": b[0]["restitution"] if b else None,
            "longest_contact_s": m.get("regimes", {}).get("longest_contact_s"),
            "adhesion_law": m.get("adhesion", {}).get("law"), "half_space": m.get("half_space", {}).get("used"),
            "menisci": m.get("menisci", {}).get("used"), "input_hash": result["provenance"].get("input_hash")}


def run_point(task: tuple) -> dict:
    """Run one point (module-level: picklable for process pools and Dask) and write its result.json."""
    scene, params, overrides, folder = task
    from continuum.impact import run_impact
    from continuum.results import dumps

    resolved = resolve_scene(scene, params=params, overrides=overrides, override_label="sweep")
    result, _ = run_impact(resolved)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / "result.json.tmp"
    tmp.write_text(dumps(result) + "\n")
    tmp.replace(folder / "result.json")
    return _row(result)


def run_sweep(scene: str, vary: dict[str, list], out: str | Path, *, params: str | None = None,
              executor_name: str = "local", workers: int | None = None, scheduler: str | None = None,
              progress=print) -> dict:
    """Run (or resume) the sweep; returns {"rows": [...], "computed": n, "reused": n, "wall_s": s}."""
    start = time.perf_counter()
    points = plan(scene, vary, params)
    out = Path(out)
    rows: list[dict | None] = [None] * len(points)
    todo = []
    for i, p in enumerate(points):
        folder = out / "points" / p["hash"][:16]
        if (folder / "result.json").is_file():
            rows[i] = _row(json.loads((folder / "result.json").read_text()))
        else:
            todo.append((i, (str(scene), params, p["overrides"], str(folder))))
    progress(f"sweep: {len(points)} points, {len(points) - len(todo)} reused, {len(todo)} to run "
             f"({executor_name})")
    ex = executor(executor_name, workers, scheduler)
    try:
        for done, (k, row) in enumerate(ex.map(run_point, [t for _, t in todo]), 1):
            rows[todo[k][0]] = row
            progress(f"  [{done}/{len(todo)}] {points[todo[k][0]]['overrides']}: {row['status']}, "
                     f"{row['rebounds_above_1e-3_h0']} rebounds")
    finally:
        ex.close()
    keys = list(vary)
    table = [{**{k: p["overrides"][k] for k in keys}, **r} for p, r in zip(points, rows)]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "sweep.csv.tmp", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys + list(COLUMNS))
        w.writeheader()
        w.writerows(table)
    (out / "sweep.csv.tmp").replace(out / "sweep.csv")
    plot(table, keys, out / "sweep.png")
    return {"rows": table, "computed": len(todo), "reused": len(points) - len(todo),
            "wall_s": time.perf_counter() - start}


def plot(table: list[dict], keys: list[str], path: Path, ax=None):
    """First rebound height and rebound count against the first varied key (one line per other combo)."""
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 4))
    ax2 = ax.twinx()
    x_key = keys[0]
    groups: dict[tuple, list[dict]] = {}
    for row in table:
        groups.setdefault(tuple((k, row[k]) for k in keys[1:]), []).append(row)
    for label, rows in groups.items():
        rows = sorted(rows, key=lambda r: r[x_key])
        xs = [r[x_key] for r in rows]
        name = ", ".join(f"{k}={v}" for k, v in label) or "sweep"
        line, = ax.plot(xs, [r["first_rebound_height_m"] * 1e9 for r in rows], "o-", label=f"{name}: first rebound")
        ax2.plot(xs, [r["rebounds_above_1e-3_h0"] for r in rows], "s--", color=line.get_color(), mfc="none")
    ax.set_xlabel(x_key)
    ax.set_ylabel("first rebound height (nm), filled")
    ax2.set_ylabel("rebounds above 1e-3 h0, open")
    ax.legend(fontsize=7)
    ax.figure.tight_layout()
    tmp = path.with_name(path.stem + ".tmp.png")
    ax.figure.savefig(tmp, dpi=110)
    plt.close(ax.figure)
    tmp.replace(path)
    return ax
