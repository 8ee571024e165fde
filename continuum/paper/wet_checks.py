"""Wet claims (Fig 8a's t_a limit, Fig 5's wet drop, Fig 8b's hydrophobic OTS) on the nominal set.

Fig 8a's t_a line is one claim: with menisci the impacts that outlast t_a stick (the wet escape velocity
rising above the dry one follows from it: in every shipped set the wet escape velocity reaches the band edge,
so a separate "menisci raise the escape velocity" measured the dry band's width, not the menisci). It
records its t_a study both ways (``wet_flips``): the lower and upper flips of t_a, bisected, and the range
in which it holds; above the longest dry impact that still rebounds no impact lasts t_a, no bridge forms,
and the claim has no subject (not evaluable, with the reason). The kinetic estimate of t_a (Szoszkiewicz &
Riedo 2005, the project's `menisci.condensation_model = 'nucleation'`) is reported beside the declared value.
"""
from __future__ import annotations

import math

from .checks import nominal_only, rebounds
from .sampled_claims import RUN_RTOL
from .speeds import WET_DRY_REL_TOL, WET_REL_TOL
from .verdict import FAIL, REPRODUCTION, VERIFICATION, entry, not_evaluable, over_samples
from .wet_flips import BAND_EDGE

T_A_CLAIM = "fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a"


def _t_a_values(si: dict) -> dict:
    study = si.get("t_a_study") or {}
    return {"t_a_s": si["condensation_time"], "longest_dry_rebound_s": si.get("longest_dry_rebound_s"),
            "t_a_nucleation_s": si.get("condensation_time_nucleation"),
            "t_a_lower_flip_s": study.get("lower_flip_s"), "t_a_upper_flip_s": study.get("upper_flip_s"),
            "t_a_holds_in_s": study.get("holds_in_s"), "t_a_holds_anywhere_s": study.get("holds_anywhere_s"),
            "t_a_flips": study.get("flips"),
            "t_a_flip_rel_tol": study.get("rel_tol"),
            "t_a_note": "above longest_dry_rebound_s no rebounding impact lasts t_a: menisci change nothing and the "
                        "claim has no subject"}


def _end_rebounds(s: str, si: dict) -> dict:
    """Fig 8a's t_a line: the menisci end the rebounds of the impacts that outlast t_a. Dry impacts outlast t_a
    between the escape velocity and the band edge v_ta (dry duration = t_a); the claim holds when the wet escape
    velocity reaches v_ta, so every such impact sticks with menisci. Margin: the captured fraction of the band,
    (v_esc,wet - v_esc,dry) / (v_ta - v_esc,dry), less its threshold 1 - BAND_EDGE; tolerance: the three speeds'
    brackets and the runs' accuracy (RUN_RTOL each), over the band's relative width."""
    name = T_A_CLAIM
    units = f"1 (captured fraction of the t_a band - {1 - BAND_EDGE:g})"
    thr = (f"with menisci the impacts that outlast t_a dry stick: the wet escape velocity reaches v_ta (the speed "
           f"below which dry impacts outlast t_a) but for the band's outer {BAND_EDGE:g}")
    t_a, pts, edge = si["condensation_time"], si["points"], si.get("t_a_band_edge")
    outlast = [p for p in pts if not p["dry"]["stuck"] and p["dry"]["duration"] >= t_a]
    e_dry, e_wet = si["escape_dry"] or {}, si["escape_wet"] or {}
    v_dry, v_wet = e_dry.get("escape_velocity"), e_wet.get("escape_velocity")
    values = {"dry_rebounding_impacts_outlasting_t_a": len(outlast),
              "of_which_stick_with_menisci": sum(p["wet"]["stuck"] for p in outlast),
              "v_ta_m_per_s": (edge or {}).get("speed"), "escape_velocity_dry_m_per_s": v_dry,
              "escape_velocity_wet_m_per_s": v_wet,
              "wet_over_dry_escape_velocity": v_wet / v_dry if v_dry and v_wet else None, **_t_a_values(si)}
    rel = (e_wet.get("rel_tol", WET_REL_TOL) + e_dry.get("rel_tol", WET_DRY_REL_TOL)
           + ((edge or {}).get("rel_tol") or 0.0) + 3 * RUN_RTOL)
    if edge is None or edge.get("speed") is None or not (v_dry and v_wet):
        longest = si.get("longest_dry_rebound_s")
        why = (f"no dry impact that rebounds lasts t_a = {t_a:.4g} s (the longest, at the escape velocity's bracket, "
               f"lasts {longest if longest is not None else math.nan:.4g} s): the claim has no subject at this t_a"
               if edge is None else f"no band edge: {edge['reason']}" if edge.get("speed") is None
               else "no escape velocity: " + "; ".join(f"{k}: {e['reason']}" for k, e in (("dry", e_dry),
                                                                                            ("wet", e_wet))
                                                        if e.get("reason")))
        e = not_evaluable(name, s, REPRODUCTION, thr, units, why, values, rel)
    else:
        width = edge["speed"] / v_dry - 1.0
        captured = (v_wet - v_dry) / (edge["speed"] - v_dry)
        values.update(captured_fraction_of_band=captured, band_width_relative=width)
        e = entry(name, s, REPRODUCTION, values, thr, captured - (1.0 - BAND_EDGE), rel / width, units)
    return over_samples(e, [], nominal_only(name))


def _unchanged(s: str, si: dict) -> dict:
    t_a, pts = si["condensation_time"], si["points"]
    shorter = [p for p in pts if not p["dry"]["stuck"] and p["dry"]["duration"] < t_a]
    # rebound energies, not speeds: near escape the rebound speed is small and the tables' error is amplified in e
    worst = max((abs(p["wet"]["restitution"] ** 2 - p["dry"]["restitution"] ** 2) for p in shorter
                 if not p["wet"]["stuck"]), default=math.inf)
    e = entry("fig8a_impacts_shorter_than_t_a_are_unchanged_by_humidity", s, VERIFICATION,
              {"impacts": len(shorter), "max_abs_difference_e_squared": worst},
              "every one rebounds with and without menisci, |e_wet^2 - e_dry^2| <= 1e-5 (the law is the dry one "
              "before t_a)", 1e-5 - worst, 0.0, "1 (1e-5 - |e_wet^2 - e_dry^2|)")
    if any(p["wet"]["stuck"] for p in shorter):
        e.update(state=FAIL, reason="an impact shorter than t_a sticks with menisci", **{"pass": False})
    return e


def evaluate_wet(s: str, wet: dict, impacts: dict) -> list[dict]:
    """Wet and SAM entries from the near-escape sweeps `wet` (case -> sweep) and the drops `impacts`."""
    out = []
    si = wet.get("wet_silica")
    if si and si["menisci_possible"]:
        out += [_end_rebounds(s, si), _unchanged(s, si)]
    drop, dry = impacts.get("wet_silica"), impacts.get("rough_silica")
    if drop is not None and dry is not None:
        m = drop["models"]["menisci"]
        a, b = rebounds(drop), rebounds(dry)
        h0 = drop["scene"]["si"]["release_height"]
        t_a, longest = m.get("condensation_time_s"), m.get("longest_contact_s")
        e = entry("fig5_wet_drop_is_the_dry_drop_contacts_shorter_than_t_a", s, VERIFICATION,
                  {"menisci_used": m.get("used"), "longest_contact_s": longest, "t_a_s": t_a,
                   "rebounds_wet": len(a), "rebounds_dry": len(b)},
                  "menisci left out (longest contact < t_a) and every rebound within 1e-6 h0 of the dry drop",
                  (t_a - longest) / t_a if t_a and longest is not None else None, RUN_RTOL, "1 ((t_a - longest) / t_a)")
        same = len(a) == len(b) and all(abs(x - y) <= 1e-6 * h0 for x, y in zip(a, b))
        if m.get("used") or not same:
            e.update(state=FAIL, reason="menisci used or rebounds differ from the dry drop", **{"pass": False})
        out.append(e)
    drop_ots = impacts.get("wet_ots")
    if drop_ots is not None:
        m = drop_ots["models"]["menisci"]
        c = m.get("cos_theta1_plus_cos_theta2")
        e = entry("fig8b_ots_grows_no_bridges", s, VERIFICATION, {"decided_by": m.get("decided_by"),
                                                                   "cos_theta1_plus_cos_theta2": c},
                  "menisci left out as hydrophobic (cos t1 + cos t2 <= 0; holds whenever theta > 90 deg)",
                  -c if c is not None else None, 0.0, "1 (-(cos t1 + cos t2))")
        if m.get("used") is not False or m.get("decided_by") != "contact_angles":
            e.update(state=FAIL, reason="menisci not left out by the contact angles", **{"pass": False})
        out.append(e)
    return out
