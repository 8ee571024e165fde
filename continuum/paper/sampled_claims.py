"""The reproduction claims judged on every sample: each a pure function of one bundle (``samples.bundle``).

The same function judges the nominal bundle and each seed or uncertainty sample, so a claim has one
definition. Threshold shapes (how many rebounds, how high the first one) are not claims: they are
reported as bands over the samples (``bands``).
"""
from __future__ import annotations

import math

from .samples import ESCAPE_REL_TOL, SAMPLE_MAX_BOUNCES
from .verdict import FAIL, NOT_EVALUABLE, PASS, REPRODUCTION, band, entry, not_evaluable, over_samples, proportion

#: "Sticks" means no rebound above this fraction of the release height h0 (the paper notes).
STICK_FRACTION = 1e-3
#: Relative accuracy of an impact's rebound height, duration and peak force: the integrator's and the
#: tables' tolerance (< 1e-7 relative, docs/benchmarks.md), with a safety factor of 10.
RUN_RTOL = 1e-6

NAMES = ("fig4_ots_loop_smaller_than_silica", "fig5a_ots_outbounces_silica",
         "fig5a_silica_impacts_weaken_until_it_sticks", "fig7_sigma3_sticks_at_first_impact",
         "fig8b_ots_lower_escape_velocity", "fig8b_ots_impact_shorter_at_the_same_low_velocity")
#: Failing samples a claim's reason names (checks.json -> failing_samples lists them all).
NAMED_FAILURES = 8


def rebounds(seq: dict) -> list[float]:
    """Rebound heights / h0 above STICK_FRACTION, in order (the bounces before sticking)."""
    out = []
    for r in seq["rebound_over_h0"]:
        if r <= STICK_FRACTION:
            break
        out.append(r)
    return out


def loop_claim(s: str, b: dict) -> dict:
    """OTS's adhesive loop (Fig 4's pressure-gap characteristic) smaller than bare silica's."""
    name, units = NAMES[0], "1 (1 - loop ratio)"
    thr = "OTS's adhesive loop area < bare silica's (the loop ratio's size is a band)"
    if "loop" not in b:
        return not_evaluable(name, s, REPRODUCTION, thr, units,
                             b.get("loop_missing", "no averaged law in this sample (discrete seed)"))
    ratio = b["loop"]["ots"] / b["loop"]["silica"] if b["loop"]["silica"] > 0 else math.inf
    return entry(name, s, REPRODUCTION, {"loop_ratio": ratio, "loop_area_J_per_m": b["loop"]}, thr, 1.0 - ratio,
                 RUN_RTOL, units)


def _outbounce(s, b):
    """OTS's first rebound higher than silica's and at least as many rebounds. A conjunct that fails decides a fail;
    the claim is not evaluable only when the first rebounds hold and both drops still rebound at the end of the
    run with as many rebounds (the count undecided)."""
    name, units = NAMES[1], "h0 (first rebound of OTS - of silica)"
    thr = ("OTS-covered silica rebounds higher at the first impact than bare silica and bounces at least as often "
           "before sticking")
    r_si, r_ots = rebounds(b["silica"]), rebounds(b["ots"])
    first = (r_ots[0] if r_ots else 0.0) - (r_si[0] if r_si else 0.0)
    values = {"rebounds_silica": len(r_si), "rebounds_ots": len(r_ots), "ots_status": b["ots"]["status"],
              "first_rebound_ots_over_h0": r_ots[0] if r_ots else 0.0,
              "first_rebound_silica_over_h0": r_si[0] if r_si else 0.0}
    e = entry(name, s, REPRODUCTION, values, thr, first, RUN_RTOL, units)
    if e["state"] == FAIL:
        e["reason"] = "OTS's first rebound is lower than silica's"
    elif len(r_ots) < len(r_si):
        e.update(state=FAIL, reason="OTS sticks after fewer rebounds than silica")
    elif e["state"] == PASS and len(r_ots) == len(r_si) and b["ots"]["status"] == "max_bounces":
        e.update(state=NOT_EVALUABLE, reason=f"both still rebound after {b['ots']['impacts']} impacts")
    e["pass"] = e["state"] == PASS
    return e


def _weaken(s, b):
    """Each impact weaker than the one before: rebound heights fall, contact times rise, peak forces fall, until
    it sticks within SAMPLE_MAX_BOUNCES impacts (the stuck impact, infinitely long, closes the sequence)."""
    name, units = NAMES[2], "1 (smallest relative step of the three sequences)"
    thr = (f"rebound heights strictly fall, impact durations strictly rise, peak forces strictly fall, and it sticks "
           f"within {SAMPLE_MAX_BOUNCES} impacts (the number of rebounds is a band)")
    seq = b["silica"]
    n = len(rebounds(seq))
    values = {"rebounds": n, "status": seq["status"], "rebound_over_h0": seq["rebound_over_h0"][: n + 1]}
    if seq["status"] not in ("stuck", "rest"):
        return entry(name, s, REPRODUCTION, values, thr, None, RUN_RTOL, units,
                     f"still rebounding after {seq['impacts']} impacts", "fail")
    if n == 0:
        return entry(name, s, REPRODUCTION, values, thr, None, RUN_RTOL, units,
                     "sticks at the first impact: no rebound, no sequence (Fig 5a shows rebounds)", "fail")
    h = [1.0] + seq["rebound_over_h0"][: n + 1]
    t, p = seq["duration_s"][: n + 1], seq["peak_force_N"][: n + 1]
    steps = [h[i] - h[i + 1] for i in range(len(h) - 1)]
    steps += [(t[i + 1] - t[i]) / t[i] for i in range(len(t) - 1)]
    steps += [(p[i] - p[i + 1]) / p[i] for i in range(len(p) - 1)]
    return entry(name, s, REPRODUCTION, values, thr, min(steps), RUN_RTOL, units)


def _sigma3(s, b):
    """sigma = 3 nm sticks at the first impact. On the averaged law (a bundle that searched the escape velocity at
    3 nm) the margin is the drop's distance below escape in energy, 1 - (v0 / v_esc)^2, with the escape bracket's
    and the runs' accuracy as tolerance; a discrete surface (no escape search) is judged on its first rebound."""
    name = NAMES[3]
    thr = "sigma = 3 nm: no rebound above 1e-3 h0 at the first impact"
    if "sigma3" not in b:
        return not_evaluable(name, s, REPRODUCTION, thr, "1", "the sigma = 3 nm drop was not run")
    seq = b["sigma3"]
    first = seq["rebound_over_h0"][0]
    esc = next((e for x, e in (b.get("escape_sigma") or {}).items() if abs(x / 3e-9 - 1.0) < 1e-6), None) or {}
    v0, v_esc = seq.get("v_impact"), esc.get("escape_velocity")
    values = {"first_rebound_over_h0": first}
    if v0 and v_esc:
        values.update(v_impact_m_per_s=v0, escape_velocity_m_per_s=v_esc)
        e = entry(name, s, REPRODUCTION, values, thr, 1.0 - (v0 / v_esc) ** 2,
                  2.0 * esc.get("rel_tol", ESCAPE_REL_TOL) + RUN_RTOL, "1 (1 - (v0 / v_esc,3nm)^2)")
        if (first <= STICK_FRACTION) != (e["state"] == PASS) and e["state"] != NOT_EVALUABLE:
            e.update(state=NOT_EVALUABLE, reason=f"the drop's first rebound ({first:.3g} h0) disagrees with its "
                     f"speed against the escape velocity ({v0:.4g} against {v_esc:.4g} m/s)", **{"pass": False})
        return e
    return entry(name, s, REPRODUCTION, values, thr, STICK_FRACTION - first, RUN_RTOL, "h0 (1e-3 - first rebound)")


def _escape(s, b):
    name, units = NAMES[4], "1 (1 - v_esc,OTS / v_esc,silica)"
    thr = ("OTS's escape velocity < bare silica's (dry), so bare silica's limiting gap v_esc^2/2g is larger "
           "(menisci only raise silica's)")
    if "escape" not in b:
        return not_evaluable(name, s, REPRODUCTION, thr, units, "no averaged law in this sample (discrete seed)")
    e_si, e_ots = b["escape"]["silica"], b["escape"]["ots"]
    values = {"silica_m_per_s": e_si.get("escape_velocity"), "ots_m_per_s": e_ots.get("escape_velocity")}
    tol = e_si.get("rel_tol", ESCAPE_REL_TOL) + e_ots.get("rel_tol", ESCAPE_REL_TOL) + 2 * RUN_RTOL
    if not (values["silica_m_per_s"] and values["ots_m_per_s"]):
        why = "; ".join(f"{k}: {e['reason']}" for k, e in (("silica", e_si), ("OTS", e_ots)) if e.get("reason"))
        return not_evaluable(name, s, REPRODUCTION, thr, units, why, values, tol)
    return entry(name, s, REPRODUCTION, values, thr, 1.0 - values["ots_m_per_s"] / values["silica_m_per_s"], tol,
                 units)


def _low_speed(s, b):
    name, units = NAMES[5], "1 (1 - t_OTS / t_silica)"
    thr = "at 1.2x bare silica's escape velocity the OTS impact is shorter than bare silica's"
    low = b.get("low_speed")
    if not low or low["silica"]["stuck"]:
        return not_evaluable(name, s, REPRODUCTION, thr, units, "no rebounding silica impact at 1.2 v_esc"
                             if low else "no escape velocity of silica (see fig8b_ots_lower_escape_velocity)")
    t_ots = math.inf if low["ots"]["stuck"] else low["ots"]["duration"]
    return entry(name, s, REPRODUCTION, {"v_impact_m_per_s": low["v_impact"], "silica_s": low["silica"]["duration"],
                                         "ots_s": t_ots}, thr, 1.0 - t_ots / low["silica"]["duration"], RUN_RTOL,
                 units)


JUDGES = (loop_claim, _outbounce, _weaken, _sigma3, _escape, _low_speed)


def bundle_claims(set_name: str, b: dict) -> list[dict]:
    """Every sampled claim on one bundle (a refused sample: every claim not evaluable, with its error)."""
    if "error" in b:
        return [not_evaluable(n, set_name, REPRODUCTION, "", "", f"sample refused or failed: {b['error']}")
                for n in NAMES]
    return [j(set_name, b) for j in JUDGES]


def judged_over_samples(set_name: str, nominal: dict, samples: list[dict]) -> list[dict]:
    """The nominal bundle's claims judged on the paper's model (the averaged GW surface): the nominal set and its
    uncertainty rows (`samples` without 'seed', each its own averaged-law bundle), holds_fraction over them
    (`verdict.over_samples`), with the bands of their threshold shapes. The discrete-summit seeds (`samples` with
    'seed') judge nothing here: `single_surfaces.attach` reports them beside every claim."""
    nom = {c["name"]: c for c in bundle_claims(set_name, nominal)}
    rows = [b for b in samples if not b.get("seed")]
    per = [{c["name"]: c for c in bundle_claims(set_name, b)} for b in rows]
    out = []
    for name in NAMES:
        e = over_samples(nom[name], [p[name]["state"] for p in per], {"nominal": 1, "uncertainty": len(rows)},
                         _bands(name, [nominal] + rows))
        failing = [{"label": b["label"], "margin": p[name]["margin"], **({"reason": p[name]["reason"]}
                                                                          if p[name].get("reason") else {})}
                   for p, b in zip(per, rows) if p[name]["state"] == FAIL]
        e["sample_margins"] = [{"label": b["label"], "margin": p[name]["margin"], "state": p[name]["state"]}
                               for p, b in zip(per, rows)]
        if failing:
            e["failing_samples"] = failing
            if e["state"] == FAIL and nom[name]["state"] != FAIL:
                e["reason"] += "; fails on " + ", ".join(
                    f["label"] + (f" (margin {f['margin']:.3g})" if f["margin"] is not None else "")
                    for f in failing[:NAMED_FAILURES]) + (f" and {len(failing) - NAMED_FAILURES} more (failing_samples)"
                                                          if len(failing) > NAMED_FAILURES else "")
        out.append(e)
    return out


def _bands(name: str, bundles: list[dict]) -> dict | None:
    ok = [b for b in bundles if "error" not in b]
    if name == NAMES[1]:
        return {"first_rebound_ots_over_h0": band(rebounds(b["ots"])[0] if rebounds(b["ots"]) else 0.0 for b in ok),
                "rebounds_ots_over_silica": band(len(rebounds(b["ots"])) / max(len(rebounds(b["silica"])), 1)
                                                 for b in ok)}
    if name == NAMES[2]:
        return {"rebounds_silica": band(len(rebounds(b["silica"])) for b in ok)}
    if name == NAMES[3]:
        ok = [b for b in ok if "sigma3" in b]
        return {"first_rebound_over_h0": band(b["sigma3"]["rebound_over_h0"][0] for b in ok),
                "stuck_at_first_impact": proportion(b["sigma3"]["rebound_over_h0"][0] <= STICK_FRACTION
                                                    for b in ok)}
    if name == NAMES[0]:
        return {"loop_ratio": band(b["loop"]["ots"] / b["loop"]["silica"] for b in ok if "loop" in b)}
    return None
