"""Run the paper's cases for each parameter set, in parallel, and write everything into one folder.

Layout of `--out DIR`:
    cases/<case>/<set>/result.json (+ timeseries.csv, height.png, impacts.png)   the impact schema
    fig4.png fig5a.png fig5b.png fig6.png fig7.png fig8a.png                       figures
    data/fig*.csv                                                                  the data behind them
    summary.md                                                                     per case and set
    checks.json                                                                    the paper's claims
Independent runs go to an executor (nanoimpact.executors): by default a local process pool (no
server; `workers` defaults to the CPU count); `executor_name`/`scheduler` pick another, or the
caller passes its own executor (calibration passes the one the user chose).
"""
from __future__ import annotations

import math
import os
import time
from pathlib import Path
from typing import Callable

import numpy as np

from nanoimpact.executors import executor as make_executor

from ..compiled_contact import warm_up
from ..escape import escape_velocity, single_impact
from ..impact import first_impact_speed, run_impact, write_impact
from ..model import meniscus_parameters, menisci_decision, select_law
from ..scene import ResolvedScene, resolve_scene
from .cases import FIG8_SIGMAS_NM, Case, dry_cases, sigma_case, wet_cases

#: Fig 8a velocity sweep: impact speeds as multiples of the 100 nm drop speed.
FIG8_SPEED_FACTORS = tuple(np.geomspace(0.05, 20.0, 10))
#: Wet sweeps: impact speeds just above the dry escape velocity, v = v_esc (1 + eps), where the
#: impact time diverges and outlasts t_a.
WET_EPS = tuple(np.geomspace(1e-3, 2.0, 12))


def fastest_first(speeds):
    """Sweep speeds in the order they run: the fastest first. The rigid rough law sizes its footprint tables
    for the deepest impact it has seen and keeps them for impacts down to 1/20 of that depth
    (`RigidRoughRoller.prepare`), so a descending sweep builds them once (~1 s) instead of at every speed of
    an ascending one; the points move by the tables' and the integration's tolerance (< 1e-7 relative,
    docs/benchmarks.md). The results are reported in ascending order."""
    return sorted(speeds, reverse=True)


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
    for factor in fastest_first(FIG8_SPEED_FACTORS):
        v = v0 * factor
        run = single_impact(law, mass, g, v, rtol)
        b = run.bounces[0]
        points.append({"v_impact": v, "stuck": run.stuck, "duration": b.duration, "v_rebound": b.v_rebound,
                       "restitution": b.restitution})
    points.sort(key=lambda p: p["v_impact"])
    escape = None
    stuck = [p["v_impact"] for p in points if p["stuck"]]
    free = [p["v_impact"] for p in points if not p["stuck"]]
    if stuck and free and max(stuck) < min(free):
        escape = escape_velocity(law, mass, g, max(stuck), min(free), rel_tol=1e-2, rtol=rtol)
    sigma = scene.surfaces.roughness.sigma if scene.surfaces.roughness is not None else None
    return {"kind": "sweep", "case": case.name, "set": Path(params).stem, "points": points, "escape": escape,
            "v_drop": v0, "sigma": sigma if scene.contact == "rough" else None}


def _outcome(law, mass, g, v, rtol) -> dict:
    run = single_impact(law, mass, g, v, rtol)
    b = run.bounces[0]
    return {"stuck": run.stuck, "duration": b.duration, "v_rebound": b.v_rebound, "restitution": b.restitution}


def _wet_task(case: Case, params: str, fidelity: str | None) -> dict:
    """Near-escape sweep of a wet case: each speed run without and (if bridges can pull) with menisci.

    The dry escape velocity is bracketed on the drop-speed grid and bisected; then speeds just above
    it (WET_EPS), where the impact time passes t_a, run dry and wet; the wet escape velocity is
    bisected with the wet law.
    """
    resolved = resolve_case(case, params, fidelity)
    scene = resolved.scene
    v0 = first_impact_speed(resolved)
    mass, g, rtol = scene.body.mass, scene.environment.gravity, scene.numerics.rtol
    dry, _ = select_law(scene, v0, menisci=False)
    menisci = menisci_decision(scene)
    wet_possible = menisci.choice != "off"
    wet = select_law(scene, v0, menisci=True)[0] if wet_possible else None
    grid = [v0 * f for f in FIG8_SPEED_FACTORS]
    # each dry impact runs once: the grid's outcomes are reused by the near-escape sweep below
    dry_runs = {v: _outcome(dry, mass, g, v, rtol) for v in fastest_first(grid)}
    stuck = [v for v in grid if dry_runs[v]["stuck"]]
    free = [v for v in grid if v not in stuck]
    esc_dry = escape_velocity(dry, mass, g, max(stuck), min(free), rel_tol=1e-3, rtol=rtol) if stuck and free else None
    speeds = sorted(set(grid) | ({esc_dry["upper"] * (1.0 + e) for e in WET_EPS} if esc_dry else set()))
    for v in fastest_first(speeds):
        if v not in dry_runs:
            dry_runs[v] = _outcome(dry, mass, g, v, rtol)
    wet_runs = {v: _outcome(wet, mass, g, v, rtol) for v in fastest_first(speeds)} if wet is not None else {}
    points = []
    for v in speeds:
        p = {"v_impact": v, "dry": dry_runs[v]}
        if wet is not None:
            p["wet"] = wet_runs[v]
        points.append(p)
    esc_wet = None
    if wet is not None and esc_dry is not None:
        free_wet = [p["v_impact"] for p in points if not p["wet"]["stuck"]]
        if free_wet:
            esc_wet = escape_velocity(wet, mass, g, esc_dry["lower"], min(free_wet), rel_tol=1e-3, rtol=rtol)
    m = meniscus_parameters(scene) if wet is not None else {}
    return {"kind": "wet", "case": case.name, "set": Path(params).stem, "points": points, "escape_dry": esc_dry,
            "escape_wet": esc_wet, "menisci_possible": wet_possible, "condensation_time": m.get("condensation_time"),
            "menisci": {k: m[k] for k in ("kelvin_gap", "bridge_pull_off", "growth_length")} if m else None,
            "why_no_menisci": None if wet_possible else menisci.why,
            "gravity": g, "v_drop": v0, "sigma": scene.surfaces.roughness.sigma}


def fig4_curves(set_name: str, fidelity: str | None) -> dict:
    """Pressure-gap characteristics of rough silica and OTS-covered silica for one set (Fig 4)."""
    from .figures import characteristic

    curves = {}
    for key, scene in (("silica", "rough_silica.toml"), ("ots", "rough_ots.toml")):
        resolved = resolve_case(Case(key, scene), set_name, fidelity)
        law, _ = select_law(resolved.scene, 0.0)
        curves[key] = characteristic(law.surface)
    return curves


def _curves_task(params: str, fidelity: str | None) -> dict:
    """Fig 4's curves as a pool task (GW tables for two scenes, ~1-2 s), beside the runs instead of after them."""
    return {"kind": "curves", "case": "fig4", "set": Path(params).stem, "curves": fig4_curves(params, fidelity)}


def _run(task):
    kind, args = task
    start, cpu = time.perf_counter(), time.process_time()
    out = {"impact": _impact_task, "sweep": _sweep_task, "wet": _wet_task, "curves": _curves_task}[kind](*args)
    out["wall_s"] = time.perf_counter() - start
    out["cpu_s"] = time.process_time() - cpu       # on a shared machine the CPU time is the steadier measure
    return out


def fig8_cases() -> list[Case]:
    rough = []
    for s in FIG8_SIGMAS_NM:
        case = sigma_case(s)
        rough.append(Case(case.name, case.scene, {**case.overrides, "surfaces.roughness.sigma": s * 1e-9,
                                                  "physics.half_space": "off"}, ("8a",)))
    return [Case("hertz", "hertz_roller.toml", {"numerics.max_bounces": 1}, ("8a",))] + rough


def paper_tasks(sets: list[str], out: Path, fidelity: str | None) -> list[tuple[str, tuple]]:
    """The runs of every set, set after set; within a set the longest first (the wet near-escape sweeps, then
    the Fig 8a sweeps, the impacts, Fig 4's curves), so no long run starts last and the first sets finish
    early: `run_paper` hands each finished set to its caller (its figures) while the pool runs the next."""
    tasks = []
    for s in sets:
        tasks += [("wet", (case, s, fidelity)) for case in wet_cases()]
        tasks += [("sweep", (case, s, fidelity)) for case in fig8_cases()]
        # absolute: the runs write there from the workers, whose working directory may differ (a Dask cluster)
        tasks += [("impact", (case, s, fidelity, str(out.resolve()))) for case in dry_cases() + wet_cases()]
        tasks.append(("curves", (s, fidelity)))
    return tasks


def _set_of(task) -> str:
    kind, args = task
    return Path(args[0] if kind == "curves" else args[1]).stem


def run_paper(sets: list[str], out: str | Path, *, fidelity: str | None = None, workers: int | None = None,
              executor_name: str = "processes", scheduler: str | None = None, executor=None,
              progress: Callable[[str], None] = print,
              on_set_done: Callable[[str, dict], None] | None = None) -> dict:
    """Run every dry case and sweep for every parameter set; returns the collected outputs.

    Runs go to `executor` (an object from nanoimpact.executors, left open: its owner closes it) or, without one,
    to a new `executor_name` executor (default: a local process pool of `workers`, default the CPU count).
    The first run that fails stops the rest and its error propagates. `on_set_done(set_name, collected)` is
    called in this process as soon as every run of a set has arrived (the pool goes on with the other sets).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = paper_tasks(sets, out, fidelity)
    left = {}
    for task in tasks:
        left[_set_of(task)] = left.get(_set_of(task), 0) + 1
    collected = {"impacts": {}, "sweeps": {}, "wet": {}, "curves": {}, "wall_s": {}, "cpu_s": {}}
    start = time.perf_counter()
    own = executor is None
    warm_up()                       # forked workers inherit the compiled contact kernel
    if own:
        if executor_name == "processes" and workers is None:
            workers = os.cpu_count() or 1
        executor = make_executor(executor_name, workers, scheduler)
    try:
        progress(f"paper: {len(tasks)} runs for set(s) {', '.join(sets)} on {executor.describe()}")
        for done, (_, item) in enumerate(executor.map(_run, tasks), 1):
            key = (item["case"], item["set"])
            if item["kind"] == "curves":
                collected["curves"][item["set"]] = item["curves"]
            else:
                collected[{"impact": "impacts", "sweep": "sweeps", "wet": "wet"}[item["kind"]]][key] = item
            collected["wall_s"][f"{item['kind']}:{item['case']}:{item['set']}"] = item["wall_s"]
            collected["cpu_s"][f"{item['kind']}:{item['case']}:{item['set']}"] = item["cpu_s"]
            progress(f"  [{done}/{len(tasks)}] {item['kind']} {item['case']} ({item['set']}): {item['wall_s']:.1f} s "
                     f"({item['cpu_s']:.1f} s CPU)")
            left[item["set"]] -= 1
            if left[item["set"]] == 0 and on_set_done is not None:
                on_set_done(item["set"], collected)
    except BaseException:
        if own:
            executor.close(cancel=True)
        raise
    else:
        if own:
            executor.close()
    collected["total_wall_s"] = time.perf_counter() - start
    return collected


def finite(x):
    return x is not None and math.isfinite(x)
