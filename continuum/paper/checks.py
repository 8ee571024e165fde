"""The paper's claims, with the numbers that decide them (paper notes, "What the figures claim").

Each check is {"name", "set", "values", "threshold", "pass"}. h0 is the release height; "sticks"
means no rebound higher than 1e-3 h0, so "bounces before sticking" counts rebounds above that.
"""
from __future__ import annotations

import math

import numpy as np

STICK_FRACTION = 1e-3


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


def sticks(result: dict) -> bool:
    """True if the run ended without a rebound above 1e-3 h0 (stuck, or came to rest)."""
    return result["status"] in ("stuck", "rest")


def _check(name, set_name, values, threshold, ok):
    return {"name": name, "set": set_name, "values": values, "threshold": threshold, "pass": bool(ok)}


def strictly_monotone(x, sign):
    d = np.diff(np.asarray(x, float))
    return bool(np.all(sign * d > 0)) if d.size else True


def evaluate(set_name: str, impacts: dict, sweeps: dict, fig4: dict) -> list[dict]:
    """All checks for one parameter set. `impacts` maps case -> result dict; `sweeps` case -> sweep."""
    out = []
    hz, si, ots = impacts.get("hertz"), impacts.get("rough_silica"), impacts.get("rough_ots")
    h0 = hz["scene"]["si"]["release_height"] if hz else None

    # Fig 4: adhesive loop of the pressure-gap characteristic; OTS's below 0.3 of silica's
    if fig4:
        ratio = fig4["ots"]["loop_area"] / fig4["silica"]["loop_area"] if fig4["silica"]["loop_area"] > 0 else math.inf
        out.append(_check("fig4_silica_has_adhesive_loop", set_name, {"loop_area_J_per_m2": fig4["silica"]["loop_area"]},
                          "> 0", fig4["silica"]["loop_area"] > 0))
        out.append(_check("fig4_ots_loop_below_0.3_of_silica", set_name, {"ratio": ratio}, "< 0.3", ratio < 0.3))

    # Fig 5a
    if hz:
        dev = max(abs(b["rebound_height"] / h0 - 1.0) for b in hz["bounces"])
        out.append(_check("fig5a_hertz_returns_to_h0", set_name,
                          {"bounces": hz["n_bounces"], "max_relative_deviation": dev}, ">= 20 bounces, <= 1e-6",
                          hz["n_bounces"] >= 20 and dev <= 1e-6))
    if si:
        rb = rebounds(si)
        n = len(rb)
        bounces = si["bounces"][: n]
        out.append(_check("fig5a_silica_rebounds_strictly_fall", set_name, {"rebound_heights_m": rb}, "strictly falling",
                          n >= 2 and strictly_monotone(rb, -1)))
        durations = [b["duration"] for b in bounces]
        out.append(_check("fig5a_silica_durations_strictly_rise", set_name, {"durations_s": durations},
                          "strictly rising", n >= 2 and strictly_monotone(durations, +1)))
        peaks = [b["peak_force"] for b in bounces]
        out.append(_check("fig5a_silica_peak_forces_strictly_fall", set_name, {"peak_forces_N": peaks},
                          "strictly falling", n >= 2 and strictly_monotone(peaks, -1)))
        out.append(_check("fig5a_silica_sticks_within_50_bounces", set_name,
                          {"rebounds_before_sticking": n, "status": si["status"]}, "sticks, <= 50 rebounds",
                          sticks(si) and n <= 50))
    if ots:
        rb_ots = rebounds(ots)
        first = rb_ots[0] / h0 if rb_ots and h0 else 0.0
        out.append(_check("fig5a_ots_first_rebound_at_least_0.9_h0", set_name, {"first_rebound_over_h0": first},
                          ">= 0.9", first >= 0.9))
        if si:
            n_si, n_ots = len(rebounds(si)), len(rb_ots)
            ok = (not sticks(ots)) or (n_ots >= 3 * n_si)
            out.append(_check("fig5a_ots_three_times_the_bounces_of_silica", set_name,
                              {"silica": n_si, "ots": n_ots, "ots_status": ots["status"]},
                              ">= 3x, or no sticking within the run", ok))
    # Fig 5b
    if hz and si and ots:
        t_h, f_h = hz["bounces"][0]["duration"], hz["bounces"][0]["peak_force"]
        others = [c["bounces"][0] for c in (si, ots)]
        t_r = [b["duration"] if b["duration"] is not None else math.inf for b in others]
        f_r = [b["peak_force"] for b in others]
        out.append(_check("fig5b_hertz_shorter_and_higher", set_name,
                          {"hertz_duration_s": t_h, "rough_durations_s": t_r, "hertz_peak_N": f_h, "rough_peaks_N": f_r},
                          "hertz duration < rough, hertz peak > rough", all(t_h < t for t in t_r) and all(f_h > f for f in f_r)))
    # Fig 6
    fig6 = impacts.get("fig6_halfspace") or si
    prof = fig6["bounces"][0].get("profiles") if fig6 else None
    if prof and "max_approach" in prof:
        m = prof["max_approach"]
        x, p = np.asarray(m["x"]), np.asarray(m["pressure"])
        centre = abs(x[int(np.argmax(p))]) <= 2.0 * (x[1] - x[0]) + 1e-3 * (x[-1] - x[0])
        out.append(_check("fig6_max_approach_compressive_peak_at_centre", set_name,
                          {"net_force_N": m["force"], "x_of_peak_m": float(x[int(np.argmax(p))])},
                          "net > 0, peak at x = 0", m["force"] > 0 and centre))
    if prof and "pull_off" in prof:
        q = prof["pull_off"]
        pmin = float(np.min(q["pressure"]))
        out.append(_check("fig6_pull_off_tensile", set_name, {"min_pressure_Pa": pmin, "net_force_N": q["force"]},
                          "min pressure < 0, net force <= 0", pmin < 0 and q["force"] <= 0))
    if hz:
        b = hz["bounces"][0]
        out.append(_check("fig6_hertz_scale", set_name, {"max_penetration_m": b["max_penetration"], "duration_s": b["duration"]},
                          "delta_max ~ 6 pm (3-12 pm), t ~ 14 ns (7-28 ns)",
                          3e-12 < b["max_penetration"] < 12e-12 and 7e-9 < b["duration"] < 28e-9))
    # Fig 7
    sig = sorted(((c["scene"]["si"]["surfaces"]["roughness"]["sigma"], c) for k, c in impacts.items()
                  if k.startswith("sigma_") or k == "rough_silica"), key=lambda t: t[0])
    if sig:
        first = [(rebounds(c)[0] / h0 if rebounds(c) else 0.0) for _, c in sig]
        counts = [len(rebounds(c)) for _, c in sig]
        sigmas = [s for s, _ in sig]
        s3 = [c for s, c in sig if abs(s - 3e-9) < 1e-12]
        s30 = [c for s, c in sig if abs(s - 30e-9) < 1e-12]
        if s3:
            out.append(_check("fig7_sigma3_sticks_at_first_impact", set_name,
                              {"rebounds": len(rebounds(s3[0])), "status": s3[0]["status"]}, "0 rebounds",
                              len(rebounds(s3[0])) == 0))
        if s30:
            f30 = rebounds(s30[0])[0] / h0 if rebounds(s30[0]) else 0.0
            out.append(_check("fig7_sigma30_first_rebound_at_least_0.95_h0", set_name, {"first_rebound_over_h0": f30},
                              ">= 0.95", f30 >= 0.95))
        nondec = all(np.diff(first) >= 0) and all(np.diff(counts) >= 0)
        out.append(_check("fig7_rebound_and_bounces_do_not_decrease_with_sigma", set_name,
                          {"sigma_m": sigmas, "first_rebound_over_h0": first, "rebounds_before_sticking": counts},
                          "non-decreasing in sigma", nondec))
    # Fig 8a
    if "hertz" in sweeps:
        pts = [p for p in sweeps["hertz"]["points"] if not p["stuck"]]
        v = np.log([p["v_impact"] for p in pts])
        t = np.log([p["duration"] for p in pts])
        slope = float(np.polyfit(v, t, 1)[0]) if len(pts) > 1 else math.nan
        out.append(_check("fig8a_hertz_time_nearly_independent_of_velocity", set_name, {"dlnt_dlnv": slope},
                          "|slope| < 0.05", abs(slope) < 0.05))
    rough = {k: s for k, s in sweeps.items() if k != "hertz"}
    if rough:
        rises = {}
        for k, s in rough.items():
            pts = [p for p in s["points"] if not p["stuck"]]
            d = [p["duration"] for p in pts]
            rises[k] = bool(len(d) >= 2 and all(np.diff(d) < 0))
        out.append(_check("fig8a_rough_impact_time_rises_as_velocity_falls", set_name, rises,
                          "duration strictly decreasing in impact velocity, every sigma", all(rises.values())))
        esc = sorted((sweeps[k]["sigma"], sweeps[k]["escape"]["escape_velocity"] if sweeps[k]["escape"] else None)
                     for k in rough)
        vals = [e for _, e in esc]
        ok = all(e is not None for e in vals) and all(np.diff(vals) < 0)
        out.append(_check("fig8a_escape_velocity_falls_as_sigma_rises", set_name,
                          {"sigma_m": [s for s, _ in esc], "escape_velocity_m_per_s": vals},
                          "strictly decreasing in sigma", ok))
    return out


def evaluate_wet(set_name: str, wet: dict, impacts: dict) -> list[dict]:
    """Wet and SAM claims (Fig 8a's t_a limit, Fig 8b) from the near-escape sweeps `wet` (case -> sweep)."""
    out = []
    si, ots = wet.get("wet_silica"), wet.get("wet_ots")
    if si and si["menisci_possible"]:
        t_a = si["condensation_time"]
        pts = si["points"]
        wet_free = [p["wet"]["duration"] for p in pts if not p["wet"]["stuck"]]
        longest = max(wet_free, default=0.0)
        outlast = [p for p in pts if not p["dry"]["stuck"] and p["dry"]["duration"] >= t_a]
        ended = all(p["wet"]["stuck"] for p in outlast)
        e_dry, e_wet = si["escape_dry"], si["escape_wet"]
        v_dry = (e_dry or {}).get("escape_velocity")
        v_wet = (e_wet or {}).get("escape_velocity")
        out.append(_check("fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a", set_name,
                          {"t_a_s": t_a, "dry_rebounding_impacts_outlasting_t_a": len(outlast),
                           "of_which_stick_with_menisci": sum(p["wet"]["stuck"] for p in outlast),
                           "longest_rebounding_wet_impact_s": longest,
                           "escape_velocity_dry_m_per_s": v_dry, "escape_velocity_wet_m_per_s": v_wet},
                          "at least one dry impact outlasts t_a and still rebounds; with menisci every such impact "
                          "sticks, every wet impact that rebounds lasts < t_a, and wet escape velocity >= dry",
                          bool(outlast) and ended and longest < t_a and bool(v_dry and v_wet and v_wet >= v_dry)))
        shortest_stuck = min((p["dry"]["duration"] for p in pts if p["wet"]["stuck"] and not p["dry"]["stuck"]),
                             default=None)
        out.append(_check("fig8a_t_a_line_separates_rebounds_from_sticking", set_name,
                          {"t_a_s": t_a, "longest_rebounding_wet_impact_s": longest,
                           "shortest_dry_impact_that_sticks_with_menisci_s": shortest_stuck},
                          "longest rebounding wet impact < t_a <= every dry impact time that sticks with menisci",
                          bool(wet_free) and longest < t_a and shortest_stuck is not None and shortest_stuck >= t_a))
        shorter = [p for p in pts if not p["dry"]["stuck"] and p["dry"]["duration"] < t_a]
        # compare rebound energies against the impact energy: near escape the rebound speed is small and
        # the table interpolation error (~1e-7 of the force; the wet law sizes its tables deeper) is
        # amplified in e but not in e^2
        worst = max((abs(p["wet"]["restitution"] ** 2 - p["dry"]["restitution"] ** 2) for p in shorter
                     if not p["wet"]["stuck"]), default=math.inf)
        same = all(not p["wet"]["stuck"] for p in shorter) and worst <= 1e-5
        out.append(_check("fig8a_impacts_shorter_than_t_a_are_unchanged_by_humidity", set_name,
                          {"impacts": len(shorter), "max_abs_difference_e_squared": worst},
                          "every one rebounds with and without menisci, |e_wet^2 - e_dry^2| <= 1e-5",
                          bool(shorter) and same))
        out.append(_check("fig8a_menisci_raise_the_escape_velocity", set_name,
                          {"dry_m_per_s": (e_dry or {}).get("escape_velocity"),
                           "wet_m_per_s": (e_wet or {}).get("escape_velocity")},
                          "wet > dry", bool(e_dry and e_wet and e_wet["escape_velocity"] > e_dry["escape_velocity"])))
    if si and ots:
        esc_si = (si["escape_wet"] or si["escape_dry"] or {}).get("escape_velocity")
        esc_ots = (ots["escape_dry"] or {}).get("escape_velocity")
        g = si["gravity"]
        gap = {k: (v * v / (2 * g) if v else None) for k, v in (("silica", esc_si), ("ots", esc_ots))}
        out.append(_check("fig8b_ots_lower_escape_velocity", set_name,
                          {"silica_m_per_s": esc_si, "ots_m_per_s": esc_ots,
                           "limiting_gap_silica_m": gap["silica"], "limiting_gap_ots_m": gap["ots"]},
                          "OTS < bare silica (so bare silica's limiting gap v^2/2g is larger)",
                          bool(esc_si and esc_ots and esc_ots < esc_si)))
        out.append(_check("fig8b_bare_silica_limiting_gap_larger", set_name,
                          {"limiting_gap_silica_m": gap["silica"], "limiting_gap_ots_m": gap["ots"]},
                          "bare silica's v_esc^2/2g > OTS's",
                          bool(gap["silica"] and gap["ots"] and gap["silica"] > gap["ots"])))
        if esc_si:
            v = 1.2 * esc_si

            def duration_at(sweep, key):
                pts = [p for p in sweep["points"] if not p[key]["stuck"]]
                vs = np.array([p["v_impact"] for p in pts])
                ds = np.array([p[key]["duration"] for p in pts])
                return float(np.exp(np.interp(math.log(v), np.log(vs), np.log(ds)))) if len(pts) > 1 else math.nan

            t_si = duration_at(si, "wet" if si["menisci_possible"] else "dry")
            t_ots = duration_at(ots, "dry")
            out.append(_check("fig8b_ots_impact_shorter_at_the_same_low_velocity", set_name,
                              {"impact_velocity_m_per_s": v, "silica_duration_s": t_si, "ots_duration_s": t_ots},
                              "OTS < bare silica at 1.2x silica's escape velocity", t_ots < t_si))
    # Fig 5 (paper section 5): "no effect from meniscus, because the impact durations are below water
    # condensation time" -- the 100 nm drop onto wet silica is the dry drop, and OTS grows no bridge
    drop, dry = impacts.get("wet_silica"), impacts.get("rough_silica")
    if drop is not None and dry is not None:
        m = drop["models"]["menisci"]
        a, b = rebounds(drop), rebounds(dry)
        h0 = drop["scene"]["si"]["release_height"]
        same = len(a) == len(b) and all(abs(x - y) <= 1e-6 * h0 for x, y in zip(a, b))
        out.append(_check("fig5_wet_drop_is_the_dry_drop_contacts_shorter_than_t_a", set_name,
                          {"menisci_used": m.get("used"), "longest_contact_s": m.get("longest_contact_s"),
                           "t_a_s": m.get("condensation_time_s"), "rebounds_wet": len(a), "rebounds_dry": len(b)},
                          "menisci left out (longest contact < t_a) and every rebound within 1e-6 h0 of the dry drop",
                          m.get("used") is False and same))
    drop_ots = impacts.get("wet_ots")
    if drop_ots is not None:
        m = drop_ots["models"]["menisci"]
        out.append(_check("fig8b_ots_grows_no_bridges", set_name,
                          {"decided_by": m.get("decided_by"), "cos_theta1_plus_cos_theta2": m.get("cos_theta1_plus_cos_theta2")},
                          "menisci left out as hydrophobic (cos t1 + cos t2 <= 0)",
                          m.get("used") is False and m.get("decided_by") == "contact_angles"))
    return out
