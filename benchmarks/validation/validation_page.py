"""docs/validation.md from the results of run_validation.py: every number is read from them."""
from __future__ import annotations

from nanoimpact.fileio import atomic_write_text


def _g(x, digits=3):
    return "—" if x is None else f"{x:.{digits}g}"


def _band(b, digits=3):
    if b is None:
        return "—"
    return _g(b[0], digits) if b[0] == b[1] else f"{_g(b[0], digits)} – {_g(b[1], digits)}"


def _vs_band(measured, band):
    """'inside' or the factor by which the measurement lies above or below the band."""
    if band is None:
        return "not applicable"
    lo, hi = band
    if lo <= measured <= hi:
        return "inside"
    return f"×{measured / hi:.3g} above" if measured > hi else f"×{lo / measured:.3g} below"


def _vs_value(measured, value):
    return "—" if value is None else f"measured / predicted = {measured / value:.3g}"


def _capture(res, ds, simulate):
    ex = res["exponents"]
    lines = [f"## Capture velocity against size: {ds['title']}", "",
             f"Source: {ds['citation']}. DOI: {ds['doi']}.", f"Where: {ds['where']}.", "", ds["note"], "",
             f"E* = {res['e_star']:.4g} Pa (body and substrate below), density {res['density']:g} kg/m^3; "
             f"work of adhesion swept over {_band(ds['bands']['work_of_adhesion'])} J/m^2 "
             f"({ds['bands']['work_of_adhesion_reason']}); limiting contact pressure over "
             f"{_band(ds['bands']['limiting_pressure'])} Pa ({ds['bands']['limiting_pressure_reason']}).", "",
             "| diameter (nm) | measured (m/s) | how | elastic closed form (m/s) | vs elastic | "
             "Thornton–Ning (m/s) | TN grid applicable | vs TN | simulator (m/s) | vs simulator |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for p in res["points"]:
        sim = p.get("simulator")
        sim_txt = _g(sim) if sim is not None else (f"failed: {p['simulator_error']}" if simulate else "not run")
        lines.append(f"| {p['diameter'] * 1e9:g} | {p['measured']:g} | {p['how']} ({p['where']}) | "
                     f"{_band(p['elastic_band'])} | {_vs_band(p['measured'], p['elastic_band'])} | "
                     f"{_band(p['tn_band'])} | {p['tn_applicable_fraction']:.0%} | "
                     f"{_vs_band(p['measured'], p['tn_band'])} | {sim_txt} | {_vs_value(p['measured'], sim)} |")
    if simulate:
        w = res["points"][0].get("simulator_work_of_adhesion")
        agree = [f"{p['diameter'] * 1e9:g} nm: simulator / elastic closed form = "
                 f"{p['simulator'] / p['elastic_at_simulator_w']:.6f}"
                 for p in res["points"] if p.get("simulator") is not None]
        lines += ["", f"The simulator runs the smooth sphere with the JKR law at the band's geometric mean "
                      f"w = {_g(w)} J/m^2; its capture velocity is bisected on stick/rebound (20 halvings of a "
                      "factor-4 bracket in log: 1.3e-6 relative). "
                      "At the same w: " + ("; ".join(agree) if agree else "no simulator value") + "."]
    tn_rng = ex["tn_range"]
    lines += ["", f"Size exponent between the two printed end points: measured {ex['measured_end_points']:.3g} "
                  f"(the abstract prints {ds['printed_size_exponent']:g} for the fit to all sizes); elastic "
                  f"closed form {ex['elastic']:.4g} for every w; Thornton–Ning {_band(tn_rng)} over the "
                  f"{ex['tn_applicable_pairs']} of {ex['pairs']} (w, p_y) pairs it applies to at both sizes.",
              "", "The Thornton–Ning band has steps where (w, p_y) pairs enter its range of validity: p_y must "
                  "exceed the adhesive stress scale E* a0/(pi R), which grows as R^(-1/3) towards small spheres.",
              "", "![capture velocity against size](figures/validation_capture.png)", ""]
    return lines


def _restitution(res, ds, simulate):
    f = res["facts"]
    floor = res["points"][0]["measured_floor"]
    lost_max = 1.0 - floor ** 2
    lines = [f"## Restitution at high speed: {ds['title']}", "",
             f"Source: {ds['citation']}. DOI: {ds['doi']}.", f"Where: {ds['where']}.", "", ds["note"], "",
             f"Sphere diameter {ds['diameter'] * 1e6:g} um ({ds['diameter_reason']}); E* = {res['e_star']:.4g} Pa; "
             f"limiting contact pressure {res['limiting_pressure']:.4g} Pa; work of adhesion band "
             f"{_band(res['work_of_adhesion_band'])} J/m^2 ({ds['bands']['work_of_adhesion_reason']}).", "",
             f"At the mid-band w = {_g(res['work_of_adhesion_mid'])} J/m^2 the Thornton–Ning yield velocity is "
             f"{_g(f['yield_velocity'])} m/s, the capture velocity {_g(f['capture_tn'])} m/s against the elastic "
             f"{_g(f['capture_elastic'])} m/s, and the adhesive stress scale {_g(f['adhesive_stress_scale'])} Pa.", "",
             f"Measured: the share of the impact energy lost, 1 - e^2, reaches 'up to half' ({_g(lost_max)}) over "
             f"{_band(res['high_velocity_range'])} m/s, read as the largest loss seen there (e >= {floor:.3g}). "
             "Predicted below: e and the share lost 1 - e^2.", "",
             "| impact velocity (m/s) | elastic closed form e (lost) | Thornton–Ning e (lost) "
             "| simulator, JKR e (lost) | simulator, Thornton–Ning law e (lost) |",
             "|---|---|---|---|---|"]
    agree = []
    for p in res["points"]:
        sim_txt, plastic_txt = _sim_text(p, "simulator", simulate), _sim_text(p, "simulator_plastic", simulate)
        if p.get("simulator_plastic") and p.get("tn_at_simulator_w"):
            agree.append(f"{p['velocity']:g} m/s: {p['simulator_plastic'] / p['tn_at_simulator_w']:.7f}")
        na = p["tn_inapplicable_w"]
        tn_txt = f"{_band(p['tn_band'], 3)} ({_lost(p['tn_band'])})" + (
            f"; not applicable at w = {', '.join(f'{w:g}' for w in na)} J/m^2 (p_y below the adhesive stress "
            "scale)" if na else "") + (
            f"; **beyond the law's range**: a*/R = {p['tn_radius_ratio']:.2f} > {p['tn_range']:g} (small-strain "
            "Hertz/JKR relations)" if p.get("tn_beyond_range") else "")
        lines.append(f"| {p['velocity']:g} | {_band(p['elastic_band'], 4)} ({_lost(p['elastic_band'])}) | "
                     f"{tn_txt} | {sim_txt} | {plastic_txt} |")
    if agree:
        lines += ["", "The simulator's Thornton–Ning law (`continuum.laws.plastic_sphere`) runs at the mid-band w = "
                  f"{_g(res['work_of_adhesion_mid'])} J/m^2; its restitution over the closed form's at the same w: "
                  + "; ".join(agree) + ". For a single smooth sphere the simulator adds nothing to the closed form "
                  "but the trajectory: later impacts on the flattened spot (carried R_p and delta_p) and gravity."]
    lines += ["", "Largest share lost over the range against the measured " + _g(lost_max) + ": " + "; ".join(
        f"{label} {_g(v)} ({'×' + _g(v / lost_max) + ' the measured' if v else 'none'})"
        for label, v in _largest_losses(res)) + ".", "",
        "![restitution against impact velocity](figures/validation_restitution.png)", ""]
    return lines


def _sim_text(p, key, simulate):
    """A simulator's e (and share lost) for the table, or why there is none."""
    sim = p.get(key)
    if sim is not None:
        return f"{sim:.4g} ({_lost([sim, sim])})"
    return f"failed: {p[key + '_error']}" if simulate and p.get(key + "_error") else "not run"


def _lost(band):
    """The share of the energy lost, 1 - e^2, for a band of e (largest e gives the smallest loss)."""
    if band is None:
        return "—"
    lo, hi = sorted(1.0 - e * e for e in band)
    return f"{lo:.3g}" if lo == hi else f"{lo:.3g} – {hi:.3g}"


def _largest_losses(res):
    """(label, largest 1 - e^2 over the velocities) for each predictor that has values."""
    out = []
    for label, key in (("elastic closed form", "elastic_band"), ("Thornton–Ning", "tn_band"),
                       ("simulator, JKR", "simulator"), ("simulator, Thornton–Ning law", "simulator_plastic")):
        vals = []
        for p in res["points"]:
            v = p.get(key)
            if v is not None:
                vals += [1.0 - e * e for e in (v if isinstance(v, list) else [v])]
        if vals:
            out.append((label, max(vals)))
    return out


def _capillary(res, ds):
    return [f"## Capillary adhesion of rough MEMS surfaces: {ds['title']}", "",
            f"Source: {ds['citation']}. DOI: {ds['doi']}.", f"Where: {ds['where']}.", "", ds["note"], "",
            f"Predicted upper limit: gamma_lv (cos th1 + cos th2) (the project's `continuum.wet.menisci` wetting sum), "
            f"gamma_lv = {res['surface_tension']:g} N/m ({ds['liquid']['source']}), contact angle "
            f"{_band(res['contact_angle_band'])} deg ({ds['bands']['contact_angle_reason']}).", "",
            "| quantity | measured (J/m^2) | how | predicted (J/m^2) | vs predicted |", "|---|---|---|---|---|",
            f"| upper limit at high RH | {res['measured']:g} | {res['how']} ({res['where']}) | "
            f"{_band(res['predicted_band'], 4)} | {_vs_band(res['measured'], res['predicted_band'])} |", "",
            "The humidity dependence below saturation (the jump at the threshold RH and the rise towards the "
            "limit) is in the paper's figures, not read here, so the simulator's rough wet contact is not "
            "compared with it.", "", "![capillary adhesion limit](figures/validation_capillary.png)", ""]


def _humidity(res, ds):
    rh = res["relative_humidity"]
    lines = [f"## AFM pull-off against humidity: {ds['title']}", "",
             f"Source: {ds['citation']}. DOI: {ds['doi']}.", f"Where: {ds['where']}.", "", ds["note"], "",
             f"Predicted by the smooth sphere with its capillary bridge (`continuum.laws.sphere_meniscus`, the "
             f"`afm_tip_humidity` scene at R = {res['tip_radius'] * 1e9:g} nm; its sphere law by the Tabor parameter: "
             f"{', '.join(res['curves'][next(iter(res['curves']))]['laws'])}): the quasi-static pull-off, bridge in "
             f"equilibrium with the vapour, swept by `benchmarks/validation/pull_off_humidity.py`. Contact angle "
             f"{_band(res['contact_angle_band'])} deg ({ds['bands']['contact_angle_reason']}); work of adhesion "
             f"{_band(res['work_of_adhesion_band'])} J/m^2 ({ds['bands']['work_of_adhesion_reason']}); gamma_lv = "
             f"{res['surface_tension']:g} N/m ({ds['liquid']['source']}). {ds['choices']['solid_adhesion_reason']}. "
             f"{ds['materials']['source']}.", "",
             f"A bridge condenses from RH = {_g(res['first_bridged_rh'])} on (the first humidity of the sweep whose "
             f"Kelvin radius reaches one water molecule, {res['min_kelvin_radius'] * 1e9:.2g} nm); below it the "
             "pull-off is the dry one.", "",
             "| solid adhesion | predicted with the bridge (nN) | predicted dry, RH below the cutoff (nN) | "
             "measured (nN) | how | vs predicted with the bridge |", "|---|---|---|---|---|---|"]
    for choice, c in res["curves"].items():
        band = [x * 1e9 for x in c["band_with_bridge"]] if c["band_with_bridge"] else None
        lines.append(f"| {choice} | {_band(band)} | {_band([x * 1e9 for x in c['band_dry']])} | "
                     f"{res['measured'] * 1e9:g} | {res['how']} ({res['where']}; {res['reading']}) | "
                     f"{_vs_band(res['measured'] * 1e9, band)} |")
    changes = []
    for choice, c in res["curves"].items():
        i = c["bridged"].index(True) if True in c["bridged"] else None
        if i is not None:
            rise = max(abs(c[k][-1] / c[k][i] - 1.0) for k in ("low", "high"))
            changes.append(f"'{choice}' {rise:.1%}")
    lines += ["", f"Trend: the abstract prints '{ds['trend']}'. The model's bridge pulls F0 = 4 pi R gamma cos t at "
                  "touch whatever the humidity (r_K << R): its pull-off steps up where the bridge condenses and "
                  f"then hardly moves (the band's ends change by at most {', '.join(changes)} from RH = "
                  f"{_g(res['first_bridged_rh'])} to {_g(rh[-1])}), so it does not reproduce a uniform rise over "
                  f"{_g(rh[0])}–{_g(rh[-1])}. The r_K << R form is also stretched at high humidity (r_K/R = "
                  f"{res['kelvin_radius'][-1] / res['tip_radius']:.2g} at RH = {_g(rh[-1])}).", "",
              "![AFM pull-off against humidity](figures/validation_humidity.png)", ""]
    return lines


def _constants(datasets):
    lines = ["## Material constants and their sources", ""]
    for name in ("arffman2015", "wall1990"):
        for part in ("body", "substrate"):
            c = datasets[name][part]
            vals = ", ".join(f"{k} = {v:g}" for k, v in c.items() if isinstance(v, float))
            lines.append(f"- {name} {part}: {vals}. {c['source']}.")
    return lines + [""]


def _summary(results):
    """One line per data set, every number read from the results."""
    cap, res, cpl, hum = results["capture"], results["restitution"], results["capillary"], results["humidity"]
    pts = cap["points"]
    cap_txt = "; ".join(f"{p['diameter'] * 1e9:g} nm: elastic {_vs_band(p['measured'], p['elastic_band'])}, "
                        f"Thornton–Ning {_vs_band(p['measured'], p['tn_band'])}" for p in pts)
    ex = cap["exponents"]
    floor = res["points"][0]["measured_floor"]
    losses = ", ".join(f"{label} {_g(v)}" for label, v in _largest_losses(res))
    return ["## Summary", "",
            "- Capture velocity of silver spheres, where the measurement lies against each predicted band: "
            f"{cap_txt}. Size "
            f"exponent measured {ex['measured_end_points']:.3g}, elastic {ex['elastic']:.4g}, Thornton–Ning "
            f"{_band(ex['tn_range'])}.",
            f"- Share of the impact energy lost by 4.9 um ammonium fluorescein spheres at 20–100 m/s: measured "
            f"up to {_g(1.0 - floor ** 2)}; largest predicted: {losses}.",
            f"- Capillary adhesion limit of wet rough polysilicon: measured {cpl['measured']:g} J/m^2, predicted "
            f"{_band(cpl['predicted_band'], 4)} J/m^2 ({_vs_band(cpl['measured'], cpl['predicted_band'])}).",
            "- AFM pull-off of a ~20 nm silicon tip in humid air: measured ~"
            f"{hum['measured'] * 1e9:g} nN; predicted with the bridge " + "; ".join(
                f"{k} {_band([x * 1e9 for x in c['band_with_bridge']])} nN "
                f"({_vs_band(hum['measured'] * 1e9, [x * 1e9 for x in c['band_with_bridge']])})"
                for k, c in hum["curves"].items() if c["band_with_bridge"]) + ".", ""]


def write(path, results, datasets, simulate):
    """Write the page (atomically)."""
    lines = ["# Validation against published measurements", "",
             "Generated by `python benchmarks/validation/run_validation.py` from the data files in "
             "`benchmarks/validation/` (each with its citation, where in the source each number is and "
             "whether it was printed or read from a figure) — do not edit by hand. Each data set is "
             "predicted by the elastic closed form (JKR with Fuller–Tabor hysteresis, which is Thornton & "
             "Ning's elastic limit), by the Thornton & Ning (1998) adhesive elastic-plastic closed form "
             "(`continuum.reference.thornton_ning`) and, where an impact run applies, by the smooth-sphere "
             "simulator. An input that was not measured is swept over a stated range and shown as a band; "
             "nothing is fitted.", ""]
    lines += _summary(results)
    lines += _capture(results["capture"], datasets["arffman2015"], simulate)
    lines += _restitution(results["restitution"], datasets["wall1990"], simulate)
    lines += _capillary(results["capillary"], datasets["delrio2007"])
    lines += _humidity(results["humidity"], datasets["jones2002"])
    lines += _constants(datasets)
    lines += ["## Data sets named but not used", "",
              "Their numbers could not be read in the sources reachable when this suite was built; none of "
              "their values appears here.", ""]
    lines += [f"- {v}" for v in datasets["not_read"].values()] + [""]
    atomic_write_text(path, "\n".join(lines))
