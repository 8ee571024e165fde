"""Run the paper's cases for each parameter set, in parallel, and write everything into one folder.

Layout of `--out DIR`:
    cases/<case>/<set>/result.json, timeseries.csv                              the impact schema
                       (+ height.png, impacts.png with `case_figures`, `nanoimpact paper --case-figures`)
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

from ..dynamics.impact import first_impact_speed, run_impact
from ..model import factory, menisci_decision, regime_of, select_law
from ..numerics.compiled_contact import warm_up
from ..output.impact_result import write_impact
from ..output.results import write_run
from ..scene import ResolvedScene, SceneError, resolve_scene
from ..wet import menisci as men
from . import seed_cache
from .cases import FIG4_ELASTIC, FIG8_SIGMAS_NM, Case, dry_cases, sigma_case, wet_cases
from .samples import ESCAPE_REL_TOL, bundle, bundle_cases, escape_search, low_speed_runs, seed_overrides
from .seed_runs import single_surface_runs
from .speeds import (
    BAND_POINTS,
    FIG8_SPEED_FACTORS,
    MAX_BAND_EPS,
    STUDY_BAND_FACTOR,
    STUDY_LN_WIDTH,
    WET_DRY_REL_TOL,
    WET_EPS,
    WET_REL_TOL,
    fastest_first,
    t_a_band_edge,
)
from .speeds import outcome as _outcome
from .wet_flips import BAND_EDGE, BEYOND_SCAN, FAILS, HOLDS, NO_SUBJECT, REFUSED, at_condensation_time, t_a_flips


def resolve_case(case: Case, params: str, fidelity: str | None) -> ResolvedScene:
    overrides = dict(case.overrides)
    if fidelity is not None:
        overrides["numerics.fidelity"] = fidelity
    return resolve_scene(case.path, params=params, overrides=overrides, override_label=f"paper case {case.name}")


def _impact_task(case: Case, params: str, fidelity: str | None, out: str, figures: bool = False) -> dict:
    """One dry or wet case's impact run, written as `nanoimpact impact` writes it; its own diagnostic figures
    (height.png, impacts.png: ~0.15 s of matplotlib per case, a tenth of the paper command's CPU over its 36
    runs, and no paper figure reads them) only with `figures`."""
    resolved = resolve_case(case, params, fidelity)
    run = run_impact(resolved)
    result, trace = run.to_dict(), dict(run.trace)
    folder = Path(out) / "cases" / case.name / Path(params).stem
    if figures:
        write_impact(folder, result, trace)
    else:
        write_run(folder, result, trace)
    return {"kind": "impact", "case": case.name, "set": Path(params).stem, "folder": str(folder),
            "result": result}


def _sweep_task(case: Case, params: str, fidelity: str | None) -> dict:
    """Single impacts over FIG8_SPEED_FACTORS and the escape velocity by bisection."""
    resolved = resolve_case(case, params, fidelity)
    scene = resolved.scene
    v0 = first_impact_speed(resolved)
    law, _ = select_law(scene, v0)
    mass, g, rtol = scene.body.mass, scene.environment.gravity, scene.numerics.rtol
    points, skipped = [], []
    for factor in fastest_first(FIG8_SPEED_FACTORS):
        v = v0 * factor
        try:
            points.append({"v_impact": v, **_outcome(law, mass, g, v, rtol)})
        except SceneError as exc:       # the law refuses a speed (its tables would cost too much): said, not run
            skipped.append({"v_impact": v, "reason": str(exc)})
    points.sort(key=lambda p: p["v_impact"])
    # the grid's outcomes bracket the escape velocity where they can; below the grid the bracket is extended
    escape = escape_search(law, mass, g, v0, rtol, ESCAPE_REL_TOL, {p["v_impact"]: p["stuck"] for p in points})
    sigma = scene.surfaces.roughness.sigma if scene.surfaces.roughness is not None else None
    out = {"kind": "sweep", "case": case.name, "set": Path(params).stem, "points": points, "escape": escape,
           "skipped": skipped, "v_drop": v0, "sigma": sigma if scene.contact == "rough" else None}
    if case.name == "rough_silica":     # Fig 8b's low-speed pair at 1.2 v_esc, on the escape velocity found here
        out["low_speed"] = low_speed_runs(params, fidelity, law, mass, g, rtol, escape.get("escape_velocity"))
    return out


def _wet_task(case: Case, params: str, fidelity: str | None) -> dict:
    """Near-escape sweep of a wet case: each speed run without and (if bridges can pull) with menisci.

    The dry escape velocity is bracketed (adaptively, from the drop speed) and bisected to WET_DRY_REL_TOL;
    speeds just above it (WET_EPS) and inside the band where dry impacts outlast t_a (`_t_a_band`) run dry
    and wet; the wet escape velocity is bracketed from the wet runs' own outcomes and bisected with the wet law to
    WET_REL_TOL. The longest dry impact that still rebounds (at the dry bracket's upper end) is the t_a above which
    menisci change nothing. A search that finds no bracket, or whose bracket the law contradicts, gives no escape
    velocity and its reason (the claims built on it are then not evaluable), never an error. With menisci, the
    t_a study (`wet_flips.t_a_flips`) finds where Fig 8a's t_a claim flips, below and above the declared t_a.
    """
    resolved = resolve_case(case, params, fidelity)
    scene = resolved.scene
    v0 = first_impact_speed(resolved)
    mass, g, rtol = scene.body.mass, scene.environment.gravity, scene.numerics.rtol
    regime = regime_of(scene, v0)
    dry, _ = select_law(scene, v0, menisci=False, regime=regime)
    menisci = menisci_decision(scene, regime)
    wet_possible = menisci.choice != "off"
    wet = select_law(scene, v0, menisci=True, regime=regime)[0] if wet_possible else None
    dry_law = "the scene's dry law"
    if wet is not None:
        wet = factory.wet_sharing_dry_tables(wet, dry)
        own = factory.wet_dry_part(wet)
        if own is not None and own is not dry:
            # other solids under the bridges (plastic summits yield dry, but the mean field's bridges wrap elastic
            # summits: continuum.model.decisions.summit_plasticity): the humidity comparison runs both on the wet
            # law's own dry part, so that before t_a the two runs are the same computation
            dry, dry_law = own, "the wet law's own dry summits (elastic: the mean field's bridges wrap elastic summits)"
    m = dict(regime.meniscus_parameters()) if wet is not None else {}
    t_a = m.get("condensation_time")
    grid, dry_runs, skipped = [], {}, []
    for v in fastest_first([v0 * f for f in FIG8_SPEED_FACTORS]):
        try:
            dry_runs[v] = _outcome(dry, mass, g, v, rtol)
            grid.append(v)
        except SceneError as exc:       # the law refuses a speed (its tables would cost too much): said, not run
            skipped.append({"v_impact": v, "reason": str(exc)})
    esc_dry = escape_search(dry, mass, g, v0, rtol, WET_DRY_REL_TOL, {v: r["stuck"] for v, r in dry_runs.items()})
    speeds = set(grid)
    longest = edge = None
    if esc_dry.get("escape_velocity"):
        up = esc_dry["upper"]
        if up not in dry_runs:
            dry_runs[up] = _outcome(dry, mass, g, up, rtol)
        longest = None if dry_runs[up]["stuck"] else dry_runs[up]["duration"]
        try:
            band, edge = _t_a_band(dry, mass, g, rtol, up, t_a, dry_runs)
        except SceneError as exc:       # the band reaches speeds the law refuses: no edge, and why
            band, edge = [], {"eps": None, "reason": f"a speed in the band's scan is refused: {exc}"}
        speeds |= {up * (1.0 + e) for e in WET_EPS} | set(band)
    speeds = sorted(speeds)
    wet_runs = {}
    for v in fastest_first(speeds):
        if wet is None:
            if v not in dry_runs:
                dry_runs[v] = _outcome(dry, mass, g, v, rtol)
            continue
        # the pair back to back: on the shared tables (`continuum.model.factory.wet_sharing_dry_tables`) both see
        # the same table sizes
        try:
            dry_runs[v] = _outcome(dry, mass, g, v, rtol)
            wet_runs[v] = _outcome(wet, mass, g, v, rtol)
        except SceneError as exc:
            skipped.append({"v_impact": v, "reason": f"with menisci: {exc}"})
    speeds = [v for v in speeds if wet is None or v in wet_runs]
    points = [{"v_impact": v, "dry": dry_runs[v], **({"wet": wet_runs[v]} if wet is not None else {})} for v in speeds]
    esc_wet = flips = None
    if wet is not None and esc_dry.get("escape_velocity"):
        start = min((v for v, r in wet_runs.items() if not r["stuck"]), default=esc_dry["upper"])
        esc_wet = escape_search(wet, mass, g, start, rtol, WET_REL_TOL, {v: r["stuck"] for v, r in wet_runs.items()})
        flips = _t_a_study(scene, v0, fidelity, case, params, dry, wet, mass, g, rtol, esc_dry, t_a, longest,
                           dry_runs)
    return {"kind": "wet", "case": case.name, "set": Path(params).stem, "points": points, "escape_dry": esc_dry,
            "escape_wet": esc_wet, "menisci_possible": wet_possible, "condensation_time": t_a,
            "condensation_time_nucleation": _nucleation_time(scene), "longest_dry_rebound_s": longest,
            "t_a_band_edge": edge, "t_a_study": flips, "skipped": skipped, "dry_law": dry_law,
            "menisci": {k: m[k] for k in ("kelvin_gap", "bridge_pull_off", "growth_length", "solid_adhesion",
                                          "solid_pull")} if m else None,
            "why_no_menisci": None if wet_possible else menisci.why,
            "gravity": g, "v_drop": v0, "sigma": scene.surfaces.roughness.sigma}


def _t_a_study(scene, v0, fidelity, case, params, dry, wet, mass, g, rtol, esc_dry, t_a, longest, dry_runs) -> dict:
    """Fig 8a's t_a claim at other condensation times (`wet_flips`): at each t_a the band edge on the dry law's
    impact time, then one wet run at v* = v_esc,dry + (1 - BAND_EDGE) (v_ta - v_esc,dry)."""
    v_dry, up = esc_dry["escape_velocity"], esc_dry["upper"]

    def rebuild(t):
        o = {**case.overrides, "menisci.condensation_time": t}
        if fidelity is not None:
            o["numerics.fidelity"] = fidelity
        r = resolve_scene(case.path, params=params, overrides=o, override_label=f"paper t_a study {case.name}")
        return select_law(r.scene, v0, menisci=True)[0]

    # the study's band scans stop at a few times the declared band (at least v = 3 v_esc): wider bands push the dry
    # law to impacts whose footprint tables cost seconds each; a t_a whose band reaches past that is not judged
    declared = _t_a_band(dry, mass, g, rtol, up, t_a, dry_runs)[1] if t_a and longest and longest >= t_a else None
    max_eps = max(WET_EPS[-1], STUDY_BAND_FACTOR * ((declared or {}).get("eps") or 0.0))

    def state_at(t):
        if longest is None or longest < t:
            return NO_SUBJECT, {}
        try:
            _, e = _t_a_band(dry, mass, g, rtol, up, t, dry_runs, max_eps, STUDY_LN_WIDTH)
            if e is None:
                return NO_SUBJECT, {}
            if e.get("speed") is None:
                return (BEYOND_SCAN if "fastest speed" in e.get("reason", "") else NO_SUBJECT), {}
            v_star = v_dry + (1.0 - BAND_EDGE) * (e["speed"] - v_dry)
            stuck = _outcome(at_condensation_time(wet, t, rebuild), mass, g, v_star, rtol)["stuck"]
        except SceneError as exc:       # a speed the law refuses (its tables would cost too much): said, not run
            return REFUSED, {"reason": str(exc)}
        return (HOLDS if stuck else FAILS), {}

    return t_a_flips(state_at, t_a, longest)


def _nucleation_time(scene) -> float | None:
    """The kinetic t_a the project offers (menisci.condensation_model = 'nucleation') for this scene's RH and T."""
    env = scene.environment
    return men.nucleation_condensation_time(env.relative_humidity, env.temperature) if 0 < env.relative_humidity < 1 \
        else None


def _t_a_band(dry, mass, g, rtol, upper: float, t_a: float | None, runs: dict,
              max_eps: float = MAX_BAND_EPS, ln_width: float = 2e-8) -> tuple[list[float], dict | None]:
    """Speeds inside the band above the escape velocity where dry impacts rebound after more than t_a: the band's
    upper end (dry duration = t_a) found by `t_a_band_edge` on the dry law's impact time, then BAND_POINTS speeds
    spread geometrically in it. Returns (speeds, edge); edge is `t_a_band_edge`'s dict, with 'speed' added when
    the edge was found; ([], None) when no dry impact that rebounds lasts t_a (or without menisci)."""
    if t_a is None or runs[upper]["stuck"] or runs[upper]["duration"] < t_a:
        return [], None

    def duration(eps: float) -> float:
        v = upper * (1.0 + eps)
        if v not in runs:
            runs[v] = _outcome(dry, mass, g, v, rtol)
        return math.inf if runs[v]["stuck"] else runs[v]["duration"]

    edge = t_a_band_edge(duration, t_a, WET_EPS, WET_DRY_REL_TOL, ln_width=ln_width, max_eps=max_eps)
    if edge.get("eps") is None:
        return [], edge
    edge["speed"] = upper * (1.0 + edge["eps"])
    return [upper * (1.0 + e) for e in np.geomspace(WET_DRY_REL_TOL, edge["eps"], BAND_POINTS)], edge


def fig4_curves(set_name: str, fidelity: str | None) -> dict:
    """Pressure-gap characteristics of rough silica and OTS-covered silica for one set (Fig 4)."""
    from .figures import characteristic

    curves = {}
    for key, scene in (("silica", "rough_silica.toml"), ("ots", "rough_ots.toml")):
        resolved = resolve_case(Case(key, scene, FIG4_ELASTIC), set_name, fidelity)
        law, _ = select_law(resolved.scene, 0.0)
        curves[key] = characteristic(law.surface)
    return curves


def _curves_task(params: str, fidelity: str | None) -> dict:
    """Fig 4's curves as a pool task (GW tables for two scenes, ~1-2 s), beside the runs instead of after them."""
    return {"kind": "curves", "case": "fig4", "set": Path(params).stem, "curves": fig4_curves(params, fidelity)}


def _run(task):
    kind, args = task
    start, cpu = time.perf_counter(), time.process_time()
    out = {"impact": _impact_task, "sweep": _sweep_task, "wet": _wet_task, "curves": _curves_task,
           "bundle": _bundle_task}[kind](*args)
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


def _bundle_task(params: str, label: str, overrides: dict, fidelity: str | None, cases: dict, full: bool,
                 single: bool = True) -> dict:
    """One sample's bundle of runs (continuum.paper.samples.bundle); a discrete seed's also carries its
    single-surface runs (`seed_runs`), which answer the claims judged on whole sweeps. Bundles are kept in the
    sample cache (`seed_cache`: the same inputs and code give the same runs)."""
    def runs() -> dict:
        b = bundle(params, label, overrides, fidelity, cases, full)
        if single and b.get("seed") and "error" not in b:
            try:
                b.update(single_surface_runs(params, overrides, fidelity, cases, b))
            except (SceneError, ValueError, RuntimeError) as exc:     # as `bundle`: the sample counted undecided
                b["single_surface_error"] = f"{type(exc).__name__}: {exc}"
        return b

    key = seed_cache.bundle_key(params, overrides, fidelity, [*cases.values(), wet_cases()[0]], [full, single])
    b = seed_cache.cached(key, runs)
    return {"kind": "bundle", "case": label, "set": Path(params).stem, "bundle": b}


def sample_tasks(s: str, fidelity: str | None, seeds: int, uncertainty: list[dict]) -> list[tuple[str, tuple]]:
    """The sampled claims' bundles of set `s`: `seeds` discrete seeds and the `uncertainty` rows (scene overrides);
    the nominal bundle is made of the set's own runs (`samples.nominal_bundle`). None when the run leaves out rough
    silica or OTS (their claims have no nominal case)."""
    cases = bundle_cases(dry_cases())
    if cases is None:
        return []
    # a seed's single-surface runs mirror the Fig 8a sweeps and the wet sweep: only when this run makes them
    single = bool(wet_cases()) and {sigma_case(x).name for x in FIG8_SIGMAS_NM} <= {c.name for c in fig8_cases()}
    tasks = [("bundle", (s, label, o, fidelity, cases, False, single)) for label, o in seed_overrides(seeds)]
    tasks += [("bundle", (s, f"uncertainty {i + 1}", o, fidelity, cases, True)) for i, o in enumerate(uncertainty)]
    return tasks


def paper_tasks(sets: list[str], out: Path, fidelity: str | None, seeds: int = 0,
                uncertainty: dict[str, list[dict]] | None = None,
                case_figures: bool = False) -> list[tuple[str, tuple]]:
    """The runs of every set, set after set; within a set the longest first (the sampled bundles, the wet
    near-escape sweeps, then the Fig 8a sweeps, the impacts, Fig 4's curves), so no long run starts last and the
    first sets finish early: `run_paper` hands each finished set to its caller (its figures) while the pool runs
    the next. `seeds` and `uncertainty` ({set name: [overrides, ...]}): `sample_tasks`; `case_figures`: the impact
runs draw their own figures (`_impact_task`)."""
    tasks = []
    for s in sets:
        tasks += sample_tasks(s, fidelity, seeds, (uncertainty or {}).get(Path(s).stem, []))
        tasks += [("wet", (case, s, fidelity)) for case in wet_cases()]
        tasks += [("sweep", (case, s, fidelity)) for case in fig8_cases()]
        # absolute: the runs write there from the workers, whose working directory may differ (a Dask cluster)
        tasks += [("impact", (case, s, fidelity, str(out.resolve()), case_figures))
                  for case in dry_cases() + wet_cases()]
        tasks.append(("curves", (s, fidelity)))
    return tasks


def _set_of(task) -> str:
    kind, args = task
    return Path(args[0] if kind in ("curves", "bundle") else args[1]).stem


def run_paper(sets: list[str], out: str | Path, *, fidelity: str | None = None, workers: int | None = None,
              executor_name: str = "processes", scheduler: str | None = None, executor=None,
              progress: Callable[[str], None] = print,
              on_set_done: Callable[[str, dict], None] | None = None, seeds: int = 0,
              uncertainty: dict[str, list[dict]] | None = None, case_figures: bool = False) -> dict:
    """Run every dry case and sweep for every parameter set; returns the collected outputs.

    With the sampled claims' bundles (`sample_tasks`): `seeds` discrete-summit seeds and the `uncertainty` rows
    ({set name: [scene overrides, ...]}) per set; collected["bundles"][(label, set)].
    `case_figures`: each impact run also draws its own height.png and impacts.png (`_impact_task`).

    Runs go to `executor` (an object from nanoimpact.executors, left open: its owner closes it) or, without one,
    to a new `executor_name` executor (default: a local process pool of `workers`, default the CPU count).
    The first run that fails stops the rest and its error propagates. `on_set_done(set_name, collected)` is
    called in this process as soon as every run of a set has arrived (the pool goes on with the other sets).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = paper_tasks(sets, out, fidelity, seeds, uncertainty, case_figures)
    left = {}
    for task in tasks:
        left[_set_of(task)] = left.get(_set_of(task), 0) + 1
    collected = {"impacts": {}, "sweeps": {}, "wet": {}, "curves": {}, "bundles": {}, "wall_s": {}, "cpu_s": {}}
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
                group = {"impact": "impacts", "sweep": "sweeps", "wet": "wet", "bundle": "bundles"}[item["kind"]]
                collected[group][key] = item
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
