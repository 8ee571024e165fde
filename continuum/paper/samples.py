"""The paper's sampled claims: one small bundle of runs per sample, and where the samples come from.

A *bundle* is what the sampled reproduction claims read (``claims.bundle_claims``): the 100 nm drops of
rough silica and OTS-covered silica (sigma = 6 nm, at most ``SAMPLE_MAX_BOUNCES`` impacts), the first
impact at sigma = 3 nm and, with averaged summits only, both escape velocities (adaptive bracket,
bisection to ``ESCAPE_REL_TOL``), bare silica's at each of Fig 8a's sigmas, both impact times at 1.2
times silica's escape velocity, and both adhesive loops.
Every run is on a rigid substrate (the half-space deflection under this roller is femtometres).

Samples of a parameter set:
- the nominal bundle (the set as declared, averaged GW summits);
- discrete-summit seeds: ``surfaces.roughness.mode = 'discrete'`` with seeds 1..n (paired: silica and
  OTS of one seed share the summits), the model's own scatter when few summits carry an impact;
- uncertainty samples: rows of scene overrides the caller passes in, such as the Latin hypercube the
  calibration writes to OUT/uncertainty.csv (``read_uncertainty_csv``). The continuum never draws them:
  the calibration owns the measured values' distributions.
"""
from __future__ import annotations

import csv
import math
from dataclasses import replace
from pathlib import Path

from ..dynamics.escape import escape_velocity, single_impact
from ..dynamics.impact import first_impact_speed, run_impact
from ..model import select_law
from ..scene import SceneError, find_params, read_toml, resolve_scene
from .cases import FIG4_ELASTIC, FIG8_SIGMAS_NM, RIGID, Case, sigma_case

#: Impacts per sampled drop: the sampled claims read at most this many ("sticks within 20 impacts").
SAMPLE_MAX_BOUNCES = 20
#: Discrete-summit seeds per set that `nanoimpact paper` samples by default (8: ~1 s of runs each).
DEFAULT_SEEDS = 8
#: Relative bracket width of the escape velocity's bisection in a bundle.
ESCAPE_REL_TOL = 1e-3
#: Halvings (or doublings) of the impact speed tried to bracket an escape velocity before giving up.
MAX_BRACKET_STEPS = 40
#: Columns of the calibration's uncertainty.csv that are results, not inputs.
RESULT_COLUMNS = ("rebound1_over_h0", "rebound2_over_h0", "rebound3_over_h0", "rebound_count",
                  "escape_velocity_m_per_s", "error")


def seed_overrides(n: int) -> list[tuple[str, dict]]:
    """(label, overrides) of `n` discrete-summit realisations, seeds 1..n."""
    return [(f"seed {s}", {"surfaces.roughness.mode": "discrete", "surfaces.roughness.seed": s})
            for s in range(1, n + 1)]


def read_uncertainty_csv(path: str | Path) -> list[dict]:
    """Scene overrides per row of a calibration uncertainty.csv: the dotted-key input columns, rows whose
    `error` column is empty (a refused sample stays refused)."""
    rows = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            if row.get("error"):
                continue
            rows.append({k: float(v) for k, v in row.items() if k not in RESULT_COLUMNS and v not in ("", None)})
    return rows


def set_uncertainty_rows(sets: list[str]) -> dict[str, list[dict]]:
    """The uncertainty rows each parameter set points to: `[meta] uncertainty_rows`, a calibration's uncertainty.csv
    (its Latin hypercube; a path relative to the set's file), read with `read_uncertainty_csv`; {set name: rows} for
    the sets that point to rows. A pointer to a missing file is an input error naming the key."""
    out = {}
    for spec in sets:
        path = find_params(spec)
        rel = (read_toml(path, "params").get("meta") or {}).get("uncertainty_rows")
        if rel is None:
            continue
        csv_path = path.parent / rel
        if not csv_path.is_file():
            raise SceneError("meta.uncertainty_rows", rel, f"a CSV file relative to {path} (not found)")
        out[Path(spec).stem] = read_uncertainty_csv(csv_path)
    return out


def escape_search(law, mass: float, gravity: float, v_start: float, rtol: float,
                  rel_tol: float = ESCAPE_REL_TOL, known: dict | None = None) -> dict:
    """Escape velocity by an adaptive bracket from `v_start` (halve until it sticks, double until it rebounds),
    then bisection to `rel_tol`. `known` = {speed: stuck} already run with this law. Returns the bisection's dict,
    or {'escape_velocity': None, 'reason': ...} when no bracket is found within MAX_BRACKET_STEPS, the known
    outcomes contradict each other (a speed that sticks above one that rebounds: no single escape velocity), or
    the law refuses a speed the search needs."""
    try:
        return _escape_search(law, mass, gravity, v_start, rtol, rel_tol, dict(known or {}))
    except SceneError as exc:           # a bracket speed the law refuses (its tables would cost too much)
        return {"escape_velocity": None, "reason": f"refused: {exc}"}


def _escape_search(law, mass, gravity, v_start, rtol, rel_tol, known) -> dict:
    def stuck(v):
        if v not in known:
            known[v] = single_impact(law, mass, gravity, v, rtol, series=False).stuck
        return known[v]

    lo = max((v for v, s in known.items() if s), default=None)
    hi = min((v for v, s in known.items() if not s), default=None)
    if lo is not None and hi is not None and lo > hi:
        return {"escape_velocity": None, "reason": f"the outcomes are not monotone in the speed: it sticks at "
                f"{lo:.6g} m/s and rebounds at {hi:.6g} m/s below it"}
    v = v_start
    for _ in range(MAX_BRACKET_STEPS):
        if lo is not None and hi is not None and lo < hi:
            break
        if stuck(v):
            lo = v if lo is None else max(lo, v)
            v = 2.0 * v
        else:
            hi = v if hi is None else min(hi, v)
            v = 0.5 * v
    if lo is None or hi is None or not lo < hi:
        return {"escape_velocity": None, "reason": f"no bracket within {v_start * 2.0 ** -MAX_BRACKET_STEPS:.3g}-"
                f"{v_start * 2.0 ** MAX_BRACKET_STEPS:.3g} m/s ({MAX_BRACKET_STEPS} halvings and doublings)"}
    # both ends were run here (stuck at lo, rebound at hi): not run again, so a law whose outcome at a speed depends
    # on the impacts run before it (tables sized by the deepest) cannot contradict its bracket
    out = escape_velocity(law, mass, gravity, lo, hi, rel_tol=rel_tol, rtol=rtol, ends_known=True)
    out["rel_tol"] = rel_tol
    return out


def _sequence(result: dict) -> dict:
    """The drop's impacts in order: rebound heights / h0 (0 when it stuck), durations (inf when stuck), peaks; the
    first impact's speed; the most summits attached at once and one summit's JKR loop over the drop energy
    m g h0 (where the law records them: the mechanism of `sampled_claims.single_surfaces`)."""
    h0 = result["scene"]["si"]["release_height"]
    b = result["bounces"]
    law = result["models"].get("contact_law", {})
    loop, ref = law.get("loop_energy_per_summit"), result.get("energy_audit", {}).get("reference_energy")
    return {"rebound_over_h0": [(x["rebound_height"] or 0.0) / h0 for x in b],
            "duration_s": [x["duration"] if x["duration"] is not None else math.inf for x in b],
            "peak_force_N": [x["peak_force"] for x in b], "status": result["status"], "impacts": len(b),
            "v_impact": b[0]["v_impact"] if b else None,
            "max_contacts": result["models"].get("diagnostics", {}).get("max_contacts"),
            "loop_per_summit_over_drop": loop / ref if loop and ref else None, "loop_energy_per_summit": loop}


#: Scene keys a case states its claim at, kept against a sample's row: Fig 7's sigma = 3 nm claim is made at
#: 3 nm whatever sigma an uncertainty row draws for the 6 nm surface (the calibration's rows sample
#: surfaces.roughness.sigma around rough_silica's 6 nm).
CASE_PINNED = ("surfaces.roughness.sigma",)


def sample_overrides(case: Case, overrides: dict) -> dict:
    """A sample's scene overrides on `case`: the sample's row over the case's own overrides, except the keys
    the case states its claim at (CASE_PINNED), which keep the case's value."""
    pinned = {k: case.overrides[k] for k in CASE_PINNED if k in case.overrides}
    return {**case.overrides, **overrides, **pinned}


def row_for_scene(scene: str | Path, params: str, overrides: dict, row: dict) -> tuple[dict, list[str]]:
    """The keys of a sample's `row` that describe the scene: a row drawn for a whole parameter set carries the
    SAM's values (work of adhesion, angle, range, layer modulus), which describe nothing on a scene without a
    SAM (bare silica; the scene refuses a layer modulus there). Returns (row without them where the scene, with
    `params` and its `overrides`, has no SAM; the keys left out)."""
    sam_keys = [k for k in row if k.startswith("surfaces.sam.") and k != "surfaces.sam.coverage"]
    if not sam_keys:
        return dict(row), []
    plain = resolve_scene(scene, params=params, overrides=overrides, override_label="sample scene")
    if plain.scene.surfaces.sam is not None:
        return dict(row), []
    return {k: v for k, v in row.items() if k not in sam_keys}, sam_keys


def _resolved(case: Case, params: str, overrides: dict, fidelity: str | None, max_bounces: int):
    overrides, _ = row_for_scene(case.path, params, case.overrides, overrides)
    o = {**sample_overrides(case, overrides), "physics.half_space": RIGID,
         "numerics.max_bounces": min(max_bounces, case.overrides.get("numerics.max_bounces", max_bounces))}
    if fidelity is not None:
        o["numerics.fidelity"] = fidelity
    return resolve_scene(case.path, params=params, overrides=o, override_label=f"paper sample {case.name}")


def bundle(params: str, label: str, overrides: dict, fidelity: str | None, cases: dict[str, Case],
           full: bool) -> dict:
    """One sample's runs (module docstring). `cases`: the run's rough_silica and rough_ots cases. A sample the
    scene refuses or a run that fails is returned with its `error` (counted as undecided)."""
    try:
        return _bundle(params, label, overrides, fidelity, cases, full)
    except (SceneError, ValueError, RuntimeError) as exc:
        return {"label": label, "overrides": overrides, "seed": _is_seed(overrides),
                "error": f"{type(exc).__name__}: {exc}"}


def _is_seed(overrides: dict) -> bool:
    return overrides.get("surfaces.roughness.mode") == "discrete"


def _bundle(params, label, overrides, fidelity, cases, full) -> dict:
    """The runs of one sample. With `full` (averaged summits: the nominal set and its uncertainty samples)
    also the escape velocities, the impacts at 1.2 v_esc and Fig 4's loops; a discrete seed runs the drops alone
    (a discrete impact costs ~0.3 s, an escape search ~15 of them). OTS runs only as many impacts as it needs
    to show whether it outbounces silica (silica's rebounds + 2)."""
    out = {"label": label, "overrides": overrides, "seed": _is_seed(overrides)}
    left = row_for_scene(cases["rough_silica"].path, params, cases["rough_silica"].overrides, overrides)[1]
    if left:
        out["left_out_on_bare_silica"] = left
    laws = {}
    n_si = SAMPLE_MAX_BOUNCES
    for key, case in (("silica", cases["rough_silica"]), ("ots", cases["rough_ots"])):
        resolved = _resolved(case, params, overrides, fidelity, n_si)
        run = run_impact(resolved, series=False)     # read for its bounces only (`_sequence`)
        out[key] = _sequence(run.to_dict())
        n_si = min(SAMPLE_MAX_BOUNCES, out[key]["impacts"] + 2)
        if full:
            sc = resolved.scene
            v0 = first_impact_speed(resolved)
            laws[key] = (select_law(sc, v0, regime=run.regime)[0], sc.body.mass, sc.environment.gravity,
                         sc.numerics.rtol, v0)
    s3 = _resolved(sigma_case(3.0), params, overrides, fidelity, 1)
    out["sigma3"] = _sequence(run_impact(s3, series=False).to_dict())
    if not full:
        return out
    out["escape"] = {k: escape_search(law, m, g, v0, rtol) for k, (law, m, g, rtol, v0) in laws.items()}
    out["escape_sigma"] = _escape_over_sigma(params, overrides, fidelity, out["escape"]["silica"])
    v_si = out["escape"]["silica"].get("escape_velocity")
    if v_si:
        v = 1.2 * v_si
        runs = {k: single_impact(law, m, g, v, rtol, series=False) for k, (law, m, g, rtol, _) in laws.items()}
        out["low_speed"] = {"v_impact": v, **{k: {"stuck": r.stuck, "duration": r.bounces[0].duration}
                                              for k, r in runs.items()}}
    from .figures import characteristic

    out["loop"] = {}
    for key in laws:        # Fig 4's loop: the paper's elastic characteristic (`cases.FIG4_ELASTIC`)
        case = cases["rough_silica" if key == "silica" else "rough_ots"]
        elastic = replace(case, overrides={**case.overrides, **FIG4_ELASTIC})
        out["loop"][key] = characteristic(select_law(_resolved(elastic, params, overrides, fidelity, 1).scene,
                                                     laws[key][4])[0].surface)["loop_area"]
    return out


def _escape_over_sigma(params, overrides, fidelity, at_6nm: dict) -> dict[float, dict]:
    """Bare silica's escape velocity at each of Fig 8a's sigmas (averaged summits), {sigma (m): escape_search};
    6 nm is the bundle's own silica search, whose escape velocity starts the other searches' brackets (the
    escape velocity changes by a few times over 3-30 nm), and the law's tables are sized for that speed (sized for
    the 100 nm drop's speed, a 30 nm law's footprint tables can exceed their cost bound). A sigma whose search the
    law refuses (a bracket speed whose footprint
    tables would cost too much) has no escape velocity and the reason; the bundle's other runs stand."""
    out = {}
    for s in FIG8_SIGMAS_NM:
        case = sigma_case(s)
        if case.name == "rough_silica":
            out[s * 1e-9] = at_6nm
            continue
        try:
            resolved = _resolved(case, params, overrides, fidelity, 1)
            sc, v0 = resolved.scene, first_impact_speed(resolved)
            start = at_6nm.get("escape_velocity") or v0       # near the answer: no deep impact at the drop speed
            out[s * 1e-9] = escape_search(select_law(sc, start)[0], sc.body.mass, sc.environment.gravity, start,
                                          sc.numerics.rtol)
        except SceneError as exc:       # a speed the law refuses (its tables would cost too much): that sigma alone
            out[s * 1e-9] = {"escape_velocity": None, "reason": f"refused: {exc}"}
    return out


def truncated(seq: dict, n: int) -> dict:
    """A drop's `_sequence` cut to its first `n` impacts, as a run with numerics.max_bounces = n gives it (the
    impacts before are the same: each starts from the state the one before left)."""
    if seq["impacts"] <= n:
        return seq
    return dict(seq, rebound_over_h0=seq["rebound_over_h0"][:n], duration_s=seq["duration_s"][:n],
                peak_force_N=seq["peak_force_N"][:n], status="max_bounces", impacts=n)


def low_speed_runs(params: str, fidelity: str | None, silica_law, mass: float, g: float, rtol: float,
                   v_esc: float | None) -> dict | None:
    """Fig 8b's low-speed impacts: bare silica (`silica_law`) and OTS at 1.2 times silica's escape velocity (None
    without one)."""
    if not v_esc:
        return None
    ots = _resolved(Case("rough_ots", "rough_ots.toml"), params, {}, fidelity, 1).scene
    v = 1.2 * v_esc
    runs = {"silica": single_impact(silica_law, mass, g, v, rtol, series=False),
            "ots": single_impact(select_law(ots, v)[0], ots.body.mass, ots.environment.gravity, v, ots.numerics.rtol,
                                 series=False)}
    return {"v_impact": v, **{k: {"stuck": r.stuck, "duration": r.bounces[0].duration} for k, r in runs.items()}}


def nominal_bundle(impacts: dict, sweeps: dict, wet: dict, curves: dict | None) -> dict | None:
    """The nominal set's bundle from the runs the paper makes anyway (instead of running them again): the drops of
    rough silica, OTS and sigma = 3 nm (`impacts`: case -> result, cut as `_bundle` runs them), each Fig 8a
    sigma's escape velocity and the low-speed impacts (`sweeps`), OTS's dry escape velocity (the wet_ots sweep's
    dry law is rough_ots's: the same scene at 40 % RH, menisci off) and Fig 4's loops (`curves`). None when the
    run leaves out rough silica or OTS."""
    if not {"rough_silica", "rough_ots"} <= set(impacts):
        return None
    silica = truncated(_sequence(impacts["rough_silica"]), SAMPLE_MAX_BOUNCES)
    out = {"label": "nominal", "overrides": {}, "seed": False, "silica": silica,
           "ots": truncated(_sequence(impacts["rough_ots"]), min(SAMPLE_MAX_BOUNCES, silica["impacts"] + 2))}
    if "sigma_3nm" in impacts:
        out["sigma3"] = truncated(_sequence(impacts["sigma_3nm"]), 1)
    rough = {k: sw for k, sw in sweeps.items() if sw.get("sigma")}
    if "rough_silica" in rough:
        missing = {"escape_velocity": None, "reason": "the wet_ots sweep was not run"}
        out["escape"] = {"silica": rough["rough_silica"]["escape"],
                         "ots": (wet.get("wet_ots") or {}).get("escape_dry") or missing}
        out["escape_sigma"] = {sw["sigma"]: sw["escape"] for sw in rough.values()}
        out["low_speed"] = rough["rough_silica"].get("low_speed")
    if curves:
        out["loop"] = {k: v["loop_area"] for k, v in curves.items()}
    return out


def bundle_cases(dry: list[Case]) -> dict[str, Case] | None:
    """The run's rough silica and OTS cases, or None when the run leaves either out (then nothing is sampled)."""
    by = {c.name: c for c in dry}
    return {k: by[k] for k in ("rough_silica", "rough_ots")} if {"rough_silica", "rough_ots"} <= set(by) else None

