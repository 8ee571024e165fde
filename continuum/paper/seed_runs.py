"""The runs a discrete-summit seed adds to its bundle so that every reproduction claim can be judged on it.

A seed's bundle (``samples.bundle``) holds its drops; the claims judged on whole sweeps need, per surface, the
same questions the nominal runs ask of the averaged law (``run``), asked of this realisation's discrete law:
- Fig 8a: single impacts over ``FIG8_SPEED_FACTORS`` times the drop speed at each of ``FIG8_SIGMAS_NM`` (at
  ``SWEEP_RTOL``) and the escape velocity there (adaptive bracket from the drop speed, bisected to
  ``SEED_ESCAPE_REL_TOL``);
- Fig 8b: OTS's escape velocity, and both impacts at 1.2 times silica's;
- Fig 7: the drop (at most ``SAMPLE_MAX_BOUNCES`` impacts) at each of ``SIGMAS_NM`` (6 nm is the bundle's own);
- Fig 4: the adhesive loop per summit of each surface (from the drops' law records; a seed's silica and OTS share
  their summits, so at one depth both reach the same summits and the loop ratio is the per-summit one);
- Fig 8a's t_a line: the 6 nm escape bracket bisected on to ``WET_DRY_REL_TOL``, the band edge v_ta where the dry impact
  time falls through t_a (``speeds.t_a_band_edge``), and the one wet impact at v* that decides it
  (``wet_flips``: the claim holds exactly when that impact sticks).
A discrete impact costs milliseconds to a tenth of a second (the summits' laws in closed form or their own
tables, no footprint tables), so these ~300 impacts cost one to a few seconds of CPU per seed; the sample cache
(`seed_cache`) keeps them for the next run with the same inputs and code.
"""
from __future__ import annotations

import math

from ..dynamics.escape import escape_velocity, single_impact
from ..dynamics.impact import first_impact_speed, run_impact
from ..model import menisci_decision, regime_of, select_law
from ..scene import SceneError
from .cases import FIG8_SIGMAS_NM, SIGMAS_NM, Case, sigma_case, wet_cases
from .samples import SAMPLE_MAX_BOUNCES, _resolved, _sequence, escape_search
from .speeds import (
    FIG8_SPEED_FACTORS,
    MAX_BAND_EPS,
    STUDY_LN_WIDTH,
    WET_DRY_REL_TOL,
    WET_EPS,
    fastest_first,
    outcome,
    t_a_band_edge,
)
from .wet_flips import BAND_EDGE

#: Integration tolerance of a seed's Fig 8a sweep: its claim orders the impact times of speeds a factor 1.9 apart
#: (their durations differ by tens of per cent), and the deep impacts at 10-20 times the drop speed cost ~1 s each at
#: the scenes' 1e-8; at 1e-6 they cost ~0.1 s and their durations move by ~1e-4 relative (seed 3, sigma = 3 nm,
#: `paper`), which SWEEP_DURATION_RTOL bounds with a factor 10.
SWEEP_RTOL = 1e-6
SWEEP_DURATION_RTOL = 1e-3
#: Relative bracket of a seed's escape velocities: on a single surface the escape velocity jumps with the number of
#: summits an impact reaches (steps of tens of per cent between the sweep's sigmas and between silica and OTS), so
#: 1 % resolves the claims built on it with 7 bisections instead of 10 (the claims' tolerances carry it).
SEED_ESCAPE_REL_TOL = 1e-2


def _law(case: Case, params: str, overrides: dict, fidelity: str | None, menisci: bool | None = None):
    resolved = _resolved(case, params, overrides, fidelity, 1)
    sc, v0 = resolved.scene, first_impact_speed(resolved)
    kw = {} if menisci is None else {"menisci": menisci}
    return select_law(sc, v0, **kw)[0], sc, v0


def single_surface_runs(params: str, overrides: dict, fidelity: str | None, cases: dict[str, Case],
                        drops: dict) -> dict:
    """The seed's runs (module docstring) as bundle keys: 'sweep_sigma' {sigma: points}, 'escape_sigma',
    'escape' (silica, OTS), 'low_speed', 'loop' (per summit), 'drops_sigma' {sigma: sequence} and 't_a'.
    `drops`: the bundle (its 6 nm drops of silica and OTS). A run the law refuses leaves that quantity out with
    its reason."""
    out: dict = {"sweep_sigma": {}, "escape_sigma": {}}
    laws = {}
    for s in FIG8_SIGMAS_NM:
        x = sigma_case(s).overrides.get("surfaces.roughness.sigma", 6e-9)
        try:
            law, sc, v0 = _law(sigma_case(s), params, overrides, fidelity)
            m, g, rtol = sc.body.mass, sc.environment.gravity, sc.numerics.rtol
            pts = [{"v_impact": v0 * f, **outcome(law, m, g, v0 * f, max(rtol, SWEEP_RTOL))}
                   for f in fastest_first(FIG8_SPEED_FACTORS)]
            out["sweep_sigma"][x] = sorted(pts, key=lambda p: p["v_impact"])
            out["escape_sigma"][x] = escape_search(law, m, g, v0, rtol, SEED_ESCAPE_REL_TOL)
            laws[x] = (law, m, g, rtol)
        except SceneError as exc:
            out["escape_sigma"][x] = {"escape_velocity": None, "reason": f"refused: {exc}"}
    ots, sc, v0 = _law(cases["rough_ots"], params, overrides, fidelity)
    out["escape"] = {"silica": out["escape_sigma"].get(6e-9, {"escape_velocity": None, "reason": "not run"}),
                     "ots": escape_search(ots, sc.body.mass, sc.environment.gravity, v0, sc.numerics.rtol,
                                          SEED_ESCAPE_REL_TOL)}
    v_si = out["escape"]["silica"].get("escape_velocity")
    if v_si:
        v = 1.2 * v_si
        law, m, g, rtol = laws[6e-9]
        runs = {"silica": single_impact(law, m, g, v, rtol, series=False),
                "ots": single_impact(ots, sc.body.mass, sc.environment.gravity, v, sc.numerics.rtol, series=False)}
        out["low_speed"] = {"v_impact": v, **{k: {"stuck": r.stuck, "duration": r.bounces[0].duration}
                                              for k, r in runs.items()}}
    loops = {k: drops[k].get("loop_energy_per_summit") for k in ("silica", "ots")}
    if all(loops.values()):
        out["loop"] = loops
    else:       # the summit law records no closed-form loop (plastic or tabulated summits): the claim says so
        out["loop_missing"] = "the summit law of this seed records no loop per summit (" + ", ".join(
            k for k, v in loops.items() if not v) + ")"
    out["mass_kg"] = sc.body.mass
    out["drops_sigma"] = {6e-9: drops["silica"]}
    for s in SIGMAS_NM:
        if s != 6.0:
            r = run_impact(_resolved(sigma_case(s), params, overrides, fidelity, SAMPLE_MAX_BOUNCES),
                           series=False).to_dict()
            out["drops_sigma"][s * 1e-9] = _sequence(r)
    out["t_a"] = _t_a_claim(params, overrides, fidelity, laws.get(6e-9), out["escape"]["silica"])
    return out


def _t_a_claim(params: str, overrides: dict, fidelity: str | None, dry_law, esc_6nm: dict) -> dict:
    """Fig 8a's t_a line on this realisation at the set's declared t_a: {'holds': bool} with the speeds, or
    {'holds': None, 'reason'} where it has no subject (no dry impact that rebounds lasts t_a) or cannot be judged.
    The dry law is rough silica's at 6 nm (`dry_law`: law, mass, g, rtol), the wet scene with menisci off (the
    two scenes differ only in the humidity), and its escape bracket `esc_6nm` is bisected on to WET_DRY_REL_TOL."""
    case = wet_cases()[0]
    if dry_law is None or not esc_6nm.get("escape_velocity"):
        return {"holds": None, "reason": f"no dry escape velocity: {esc_6nm.get('reason', 'not run')}"}
    try:
        resolved = _resolved(case, params, overrides, fidelity, 1)
        sc = resolved.scene
        v0 = first_impact_speed(resolved)
        regime = regime_of(sc, v0)
        decision = menisci_decision(sc, regime)
        if decision.choice == "off":
            return {"holds": None, "reason": f"no menisci: {decision.why}"}
        wet = select_law(sc, v0, menisci=True, regime=regime)[0]
        t_a = regime.meniscus_parameters()["condensation_time"]
        dry, m, g, rtol = dry_law
        esc = escape_velocity(dry, m, g, esc_6nm["lower"], esc_6nm["upper"], rel_tol=WET_DRY_REL_TOL, rtol=rtol,
                              ends_known=True)
        up = esc["upper"]
        runs = {}

        def duration(eps: float) -> float:
            v = up * (1.0 + eps)
            if v not in runs:
                runs[v] = outcome(dry, m, g, v, rtol)
            return math.inf if runs[v]["stuck"] else runs[v]["duration"]

        longest = duration(0.0)
        if longest < t_a:
            return {"holds": None, "t_a_s": t_a, "longest_dry_rebound_s": longest,
                    "reason": f"no dry impact that rebounds lasts t_a = {t_a:.4g} s (the longest lasts "
                              f"{longest:.4g} s): no subject"}
        edge = t_a_band_edge(duration, t_a, WET_EPS, WET_DRY_REL_TOL, ln_width=STUDY_LN_WIDTH, max_eps=MAX_BAND_EPS)
        if edge.get("eps") is None:
            return {"holds": None, "t_a_s": t_a, "reason": f"no band edge: {edge['reason']}"}
        v_dry, v_ta = esc["escape_velocity"], up * (1.0 + edge["eps"])
        v_star = v_dry + (1.0 - BAND_EDGE) * (v_ta - v_dry)
        stuck = single_impact(wet, m, g, v_star, rtol, series=False).stuck
        return {"holds": bool(stuck), "t_a_s": t_a, "escape_velocity_dry_m_per_s": v_dry, "v_ta_m_per_s": v_ta,
                "v_star_m_per_s": v_star, "band_width_relative": v_ta / v_dry - 1.0}
    except SceneError as exc:
        return {"holds": None, "reason": f"refused: {exc}"}
