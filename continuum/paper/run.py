"""Run the paper's cases for each parameter set, in parallel, and write everything into one folder.

Layout of `--out DIR`:
    cases/<case>/<set>/result.json (+ timeseries.csv, height.png, impacts.png)   the impact schema
    fig4.png fig5a.png fig5b.png fig6.png fig7.png fig8a.png                       figures
    data/fig*.csv                                                                  the data behind them
    summary.md                                                                     per case and set
    checks.json                                                                    the paper's claims
Independent runs go to a local process pool (no server; `workers` defaults to the CPU count).
"""
from __future__ import annotations

import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Callable

import numpy as np

from ..escape import escape_velocity, single_impact
from ..impact import first_impact_speed, run_impact, write_impact
from ..models import select_law
from ..scene import ResolvedScene, resolve_scene
from .cases import FIG8_SIGMAS_NM, Case, dry_cases, sigma_case

#: Fig 8a velocity sweep: impact speeds as multiples of the 100 nm drop speed.
FIG8_SPEED_FACTORS = tuple(np.geomspace(0.05, 20.0, 10))


def resolve_case(case: Case, params: str, fidelity: str | None) -> ResolvedScene:
    overrides = dict(case.overrides)
    if fidelity is not None:
        overrides["numerics.fidelity"] = fidelity
    return resolve_scene(case.path, params=params, overrides=overrides, override_label=f"paper case {case.name}")


def _impact_task(case: Case, params: str, fidelity: str | None, out: str) -> dict:
    resolved = resolve_case(case, params, fidelity)
    result, trace = run_impact(resolved)
    folder = Path(out) / "cases" / case.name / Path(params).stem
    write_impact(folder, result, trace)
    return {"kind": "impact", "case": case.name, "set": Path(params).stem, "folder": str(folder),
            "result": result}


def _sweep_task(case: Case, params: str, fidelity: str | None) -> dict:
    """Single impacts over FIG8_SPEED_FACTORS and the escape velocity by bisection."""
    resolved = resolve_case(case, params, fidelity)
    scene = resolved.scene
    v0 = first_impact_speed(resolved)
    law, _ = select_law(scene, v0)
    mass, g, rtol = scene.body.mass, scene.environment.gravity, scene.numerics.rtol
    points = []
    for factor in FIG8_SPEED_FACTORS:
        v = v0 * factor
        run = single_impact(law, mass, g, v, rtol)
        b = run.bounces[0]
        points.append({"v_impact": v, "stuck": run.stuck, "duration": b.duration, "v_rebound": b.v_rebound,
                       "restitution": b.restitution})
    escape = None
    stuck = [p["v_impact"] for p in points if p["stuck"]]
    free = [p["v_impact"] for p in points if not p["stuck"]]
    if stuck and free and max(stuck) < min(free):
        escape = escape_velocity(law, mass, g, max(stuck), min(free), rel_tol=1e-2, rtol=rtol)
    sigma = scene.surfaces.roughness.sigma if scene.surfaces.roughness is not None else None
    return {"kind": "sweep", "case": case.name, "set": Path(params).stem, "points": points, "escape": escape,
            "v_drop": v0, "sigma": sigma if scene.contact == "rough" else None}


def _run(task):
    kind, args = task
    start = time.perf_counter()
    out = _impact_task(*args) if kind == "impact" else _sweep_task(*args)
    out["wall_s"] = time.perf_counter() - start
    return out


def fig8_cases() -> list[Case]:
    rough = []
    for s in FIG8_SIGMAS_NM:
        case = sigma_case(s)
        rough.append(Case(case.name, case.scene, {**case.overrides, "surfaces.roughness.sigma": s * 1e-9,
                                                  "physics.half_space": "off"}, ("8a",)))
    return [Case("hertz", "hertz_roller.toml", {"numerics.max_bounces": 1}, ("8a",))] + rough


def run_paper(sets: list[str], out: str | Path, *, fidelity: str | None = None, workers: int | None = None,
              progress: Callable[[str], None] = print) -> dict:
    """Run every dry case and sweep for every parameter set; returns the collected outputs."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = [("impact", (case, s, fidelity, str(out))) for s in sets for case in dry_cases()]
    tasks += [("sweep", (case, s, fidelity)) for s in sets for case in fig8_cases()]
    workers = workers or os.cpu_count() or 1
    collected = {"impacts": {}, "sweeps": {}, "wall_s": {}}
    start = time.perf_counter()
    progress(f"paper: {len(tasks)} runs on {workers} worker(s) for set(s) {', '.join(sets)}")
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for done, item in enumerate(pool.map(_run, tasks), 1):
            key = (item["case"], item["set"])
            collected["impacts" if item["kind"] == "impact" else "sweeps"][key] = item
            collected["wall_s"][f"{item['kind']}:{item['case']}:{item['set']}"] = item["wall_s"]
            progress(f"  [{done}/{len(tasks)}] {item['kind']} {item['case']} ({item['set']}): {item['wall_s']:.1f} s")
    collected["total_wall_s"] = time.perf_counter() - start
    return collected


def finite(x):
    return x is not None and math.isfinite(x)
