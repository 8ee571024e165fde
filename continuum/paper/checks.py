"""The paper's claims judged on the full runs of one parameter set (paper notes, "What the figures claim").

Verification checks (the code solves its equations; true by construction for any set) and the
reproduction claims that need whole sweeps (Fig 7's sigma series, Fig 8a's velocity sweeps and wet
near-escape sweeps), which are judged on the nominal set only: sampling them would rerun every sweep
per sample. The claims judged on every sample are in ``sampled_claims``. Entries: ``verdict.entry``.
"""
from __future__ import annotations

import math

import numpy as np

from .sampled_claims import RUN_RTOL, STICK_FRACTION
from .samples import ESCAPE_REL_TOL
from .verdict import FAIL, REPRODUCTION, VERIFICATION, band, entry, not_evaluable, over_samples

ESCAPE_TREND = "fig8a_escape_velocity_falls_as_sigma_rises"
FIG7 = "fig7_rebounds_rise_with_sigma"
TIME_RISES = "fig8a_rough_impact_time_rises_as_velocity_falls"
#: What the sweep claims were sampled over (recorded in each entry's `sampled`).
NOMINAL_ONLY = {"nominal": 1, "uncertainty": 0,
                "note": "judged on the nominal set only: sampling it reruns whole velocity or sigma sweeps"}
#: Why each claim judged on the nominal set alone is not judged on the samples (checks.json -> sampled.note).
NOT_SAMPLED = {
    "fig7_rebounds_rise_with_sigma": "the full drop (up to 100 impacts) at seven sigmas per sample; a discrete seed "
    "draws a different surface at each sigma, so its scatter (fig7_sigma3_sticks_at_first_impact's band at 3 nm) "
    "is not the trend. The claim's end point at 3 nm is sampled on its own",
    "fig8a_rough_impact_time_rises_as_velocity_falls": "a ten-speed sweep at four sigmas per sample (40 impacts, "
    "the longest near escape); not run per sample",
    "fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a": "menisci are modelled on the averaged summits only "
    "(no discrete seed can carry them); per uncertainty row it needs the wet law's tables, the wet sweep's two "
    "bisections, the t_a band's edge and the t_a study, the longest task of a set; not run per sample",
}


def nominal_only(name: str) -> dict:
    """`sampled` of a claim judged on the nominal set alone, with the reason (NOT_SAMPLED)."""
    return dict(NOMINAL_ONLY, note="judged on the nominal set only: " + NOT_SAMPLED[name]) if name in NOT_SAMPLED \
        else dict(NOMINAL_ONLY)


def rebounds(result: dict) -> list[float]:
    """Rebound heights (m) above 1e-3 h0, in order (the bounces before sticking)."""
    h0 = result["scene"]["si"]["release_height"]
    out = []
    for b in result["bounces"]:
        r = b["rebound_height"]
        if r is None or r <= STICK_FRACTION * h0:
            break
        out.append(r)
    return out


def _v(name, s, values, thr, margin, tol, units, reason=None, state=None):
    return entry(name, s, VERIFICATION, values, thr, margin, tol, units, reason, state)


def verify_dry(s: str, impacts: dict, sweeps: dict, fig4: dict) -> list[dict]:
    """Verification checks of the dry runs: Hertz limits, Fig 4's loop, Fig 5b, Fig 6, Fig 8a's Hertz slope."""
    out = []
    hz, si, ots = impacts.get("hertz"), impacts.get("rough_silica"), impacts.get("rough_ots")
    if fig4:
        area = fig4["silica"]["loop_area"]
        out.append(_v("fig4_silica_has_adhesive_loop", s, {"loop_area": area}, "> 0 (holds whenever dgamma > 0)",
                      area, RUN_RTOL * abs(area), "loop area (the characteristic's units)"))
    if hz:
        h0 = hz["scene"]["si"]["release_height"]
        dev = max(abs(b["rebound_height"] / h0 - 1.0) for b in hz["bounces"])
        e = _v("fig5a_hertz_returns_to_h0", s, {"bounces": hz["n_bounces"], "max_relative_deviation": dev},
               ">= 20 bounces, each rebound within 1e-6 of h0", 1e-6 - dev, 0.0, "h0")
        short = dict(e, state=FAIL, reason="fewer than 20 bounces", **{"pass": False})
        out.append(e if hz["n_bounces"] >= 20 else short)
        b = hz["bounces"][0]
        d, t = b["max_penetration"], b["duration"]
        out.append(_v("fig6_hertz_scale", s, {"max_penetration_m": d, "duration_s": t},
                      "delta_max ~ 6 pm (3-12 pm), t ~ 14 ns (7-28 ns)",
                      min(math.log(d / 3e-12), math.log(12e-12 / d), math.log(t / 7e-9), math.log(28e-9 / t)),
                      RUN_RTOL, "ln (distance to the nearer band edge)"))
    if hz and si and ots:
        t_h, f_h = hz["bounces"][0]["duration"], hz["bounces"][0]["peak_force"]
        others = [c["bounces"][0] for c in (si, ots)]
        t_r = [b["duration"] if b["duration"] is not None else math.inf for b in others]
        f_r = [b["peak_force"] for b in others]
        out.append(_v("fig5b_hertz_shorter_and_higher", s, {"hertz_duration_s": t_h, "rough_durations_s": t_r,
                                                             "hertz_peak_N": f_h, "rough_peaks_N": f_r},
                      "hertz duration < rough, hertz peak > rough",
                      min([t / t_h - 1.0 for t in t_r] + [f_h / f - 1.0 for f in f_r]), RUN_RTOL, "1 (relative)"))
    out += _fig6(s, impacts.get("fig6_halfspace") or si)
    if "hertz" in sweeps:
        pts = [p for p in sweeps["hertz"]["points"] if not p["stuck"]]
        slope = (float(np.polyfit(np.log([p["v_impact"] for p in pts]), np.log([p["duration"] for p in pts]), 1)[0])
                 if len(pts) > 1 else math.nan)
        out.append(_v("fig8a_hertz_time_nearly_independent_of_velocity", s, {"dlnt_dlnv": slope}, "|slope| < 0.05",
                      0.05 - abs(slope), RUN_RTOL, "1 (0.05 - |d ln t / d ln v|)"))
    return out


def _fig6(s: str, run: dict | None) -> list[dict]:
    prof = run["bounces"][0].get("profiles") if run else None
    out = []
    if prof and "max_approach" in prof:
        m = prof["max_approach"]
        x, p = np.asarray(m["x"]), np.asarray(m["pressure"])
        x_peak = float(x[int(np.argmax(p))])
        centre = abs(x_peak) <= 2.0 * (x[1] - x[0]) + 1e-3 * (x[-1] - x[0])
        e = _v("fig6_max_approach_compressive_peak_at_centre", s, {"net_force_N": m["force"], "x_of_peak_m": x_peak},
               "net > 0, peak at x = 0", m["force"], RUN_RTOL * abs(m["force"]), "N (net force)")
        out.append(e if centre else dict(e, state=FAIL, reason="pressure peak off centre", **{"pass": False}))
    if prof and "pull_off" in prof:
        q = prof["pull_off"]
        p = np.asarray(q["pressure"])
        pmin = float(np.min(p))
        e = _v("fig6_pull_off_tensile", s, {"min_pressure_Pa": pmin, "net_force_N": q["force"]},
               "min pressure < 0, net force <= 0", -pmin / float(np.max(np.abs(p))), RUN_RTOL,
               "1 (-min pressure / max |pressure|)")
        out.append(e if q["force"] <= 0 else dict(e, state=FAIL, reason="net force > 0 at pull-off", **{"pass": False}))
    return out


def _nominal(e: dict, bands: dict | None = None) -> dict:
    return over_samples(e, [], nominal_only(e["name"]), bands)


def reproduce_dry(s: str, impacts: dict, sweeps: dict, samples: list[dict] = ()) -> list[dict]:
    """Fig 7's trend in sigma and Fig 8a's sweeps, on the nominal set; the escape velocity's trend also on the
    `samples` (bundles, continuum.paper.samples) that carry it."""
    out = []
    sig = sorted(((c["scene"]["si"]["surfaces"]["roughness"]["sigma"], c) for k, c in impacts.items()
                  if k.startswith("sigma_") or k == "rough_silica"), key=lambda t: t[0])
    if sig:
        out.append(_fig7(s, sig))
    rough = {k: v for k, v in sweeps.items() if k != "hertz"}
    if rough:
        out.append(_time_rises(s, rough))
        out.append(_escape_falls(s, rough, list(samples)))
    return out


def _fig7(s: str, sig: list) -> dict:
    h0 = sig[0][1]["scene"]["si"]["release_height"]
    first = [(rebounds(c)[0] / h0 if rebounds(c) else 0.0) for _, c in sig]
    e = fig7_entry(s, [x for x, _ in sig], first, [len(rebounds(c)) for _, c in sig],
                   [c["status"] == "max_bounces" for _, c in sig])
    return _nominal(e, {"first_rebound_over_h0_at_largest_sigma": band([first[-1]])})


def fig7_entry(s: str, sigmas: list[float], first: list[float], counts: list[int], capped: list[bool]) -> dict:
    """Fig 7: the first rebound (/ h0, 0 where it sticks) rises with sigma and the rebounds before sticking do not
    decrease (a capped drop, still rebounding at its last impact, bounds its count from below)."""
    steps = [b - a for a, b in zip(first, first[1:]) if a > 0.0 or b > 0.0]
    values = {"sigma_m": list(sigmas), "first_rebound_over_h0": first, "rebounds_before_sticking": counts,
              "capped": capped}
    thr = ("first rebound height rises with sigma (ties only where both stick at once), bounces before sticking "
           "do not decrease; sigma = 30 nm's first rebound is a band")
    e = entry(FIG7, s, REPRODUCTION, values, thr, min(steps, default=None), RUN_RTOL,
              "h0 (smallest rise of the first rebound)",
              None if steps else "every sigma sticks at the first impact")
    fell = [i for i in range(len(counts) - 1) if counts[i + 1] < counts[i] and not capped[i + 1]]
    if fell:
        e.update(state=FAIL, reason=f"fewer bounces at sigma = {sigmas[fell[0] + 1] * 1e9:g} nm", **{"pass": False})
    return e


def _time_rises(s: str, rough: dict) -> dict:
    return _nominal(time_rises_entry(s, rough, RUN_RTOL))


def time_rises_entry(s: str, rough: dict, tolerance: float) -> dict:
    """Fig 8a: the impact time strictly rises as the velocity falls, at every sigma; `rough` = {case: sweep with
    'points' ascending in speed}; `tolerance`: the durations' relative accuracy."""
    steps, values = [], {}
    for k, sw in rough.items():
        d = [p["duration"] for p in sw["points"] if not p["stuck"]]
        values[k] = d
        steps += [d[i] / d[i + 1] - 1.0 for i in range(len(d) - 1)]
    left_out = {k: [p["v_impact"] for p in sw.get("skipped", [])] for k, sw in rough.items() if sw.get("skipped")}
    return entry(TIME_RISES, s, REPRODUCTION, {"durations_s": values, "speeds_left_out_m_per_s": left_out},
                 "impact duration strictly falls with impact velocity, every sigma", min(steps, default=None),
                 tolerance, "1 (smallest relative rise as v falls)")


def escape_trend(s: str, esc: list[tuple[float, dict]]) -> dict:
    """Fig 8a: the escape velocity strictly falls as sigma rises; `esc` = [(sigma, escape_search dict), ...]."""
    esc = sorted(esc, key=lambda t: t[0])
    vals = [e.get("escape_velocity") for _, e in esc]
    thr = "escape velocity strictly falls as sigma rises (adaptive bracket, bisection)"
    units = "1 (smallest 1 - v_esc(next sigma) / v_esc)"
    values = {"sigma_m": [x for x, _ in esc], "escape_velocity_m_per_s": vals}
    if not all(vals):
        why = "; ".join(f"sigma {x * 1e9:g} nm: {e.get('reason')}" for x, e in esc if not e.get("escape_velocity"))
        return not_evaluable(ESCAPE_TREND, s, REPRODUCTION, thr, units, why, values, 2 * ESCAPE_REL_TOL)
    return entry(ESCAPE_TREND, s, REPRODUCTION, values, thr, min(1.0 - b / a for a, b in zip(vals, vals[1:])),
                 2 * ESCAPE_REL_TOL, units)


def _escape_falls(s: str, rough: dict, samples: list[dict]) -> dict:
    """The trend on the Fig 8a sweeps, judged also on every sample bundle that searched each sigma's escape
    velocity (the averaged law's: the nominal bundle and the uncertainty rows; a discrete seed searches none)."""
    nominal = escape_trend(s, [(sw["sigma"], sw["escape"]) for sw in rough.values()])
    used = [b for b in samples if "escape_sigma" in b and not b.get("seed")]
    states = [escape_trend(s, list(b["escape_sigma"].items()))["state"] for b in used]
    sources = {"nominal": 1, "uncertainty": len(used)}
    sigmas = sorted(used[0]["escape_sigma"]) if used else []
    bands = {f"escape_velocity_m_per_s_at_{x * 1e9:g}nm": band(b["escape_sigma"][x].get("escape_velocity")
                                                              for b in used) for x in sigmas}
    return over_samples(nominal, states, sources, bands)
