"""Hold the project against published measurements (a script, not a test).

    python benchmarks/validation/run_validation.py [--no-simulator]

For every data set in benchmarks/validation/datasets.toml it predicts the measured quantity with
(a) the elastic closed form (JKR with Fuller-Tabor hysteresis = Thornton & Ning's elastic limit,
continuum.reference.jkr), (b) the adhesive elastic-plastic closed form of Thornton & Ning
(continuum.reference.thornton_ning) and (c) the smooth-sphere simulator (continuum.run_scene)
where an impact run applies: with the JKR law, and where the data set states a limiting contact
pressure also with the Thornton-Ning elastic-plastic law (the pressure given as the body's
hardness, physics.plasticity = 'auto'). A work of adhesion (or a yield pressure) that was not
measured is swept over the range datasets.toml states and shown as a band, never fitted. Writes
docs/figures/validation_<case>.png and .json and the page docs/validation.md; every number on the
page is read from those results.
"""
from __future__ import annotations

import argparse
import logging
import tomllib
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from continuum.reference import thornton_ning as tn
from nanoimpact.errors import InputError
from nanoimpact.fileio import atomic_save_figure, atomic_write_json

try:  # the page is written by the sibling module; both run as a script or as a package member
    from . import pull_off_humidity, validation_page
except ImportError:
    import pull_off_humidity
    import validation_page

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
FIGURES = ROOT / "docs" / "figures"
log = logging.getLogger("validation")


def contact_modulus(body, substrate):
    """Johnson's E* = [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]^-1 (Pa)."""
    return 1.0 / ((1 - body["poisson_ratio"] ** 2) / body["youngs_modulus"]
                  + (1 - substrate["poisson_ratio"] ** 2) / substrate["youngs_modulus"])


def read_csv(path):
    """Rows of a small data CSV as dicts (numbers stay strings until used)."""
    import csv
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


# ------------------------------------------------------------------------------------------------
# The smooth-sphere simulator
# ------------------------------------------------------------------------------------------------
def _scene(radius, density, w, body, substrate, velocity, limiting_pressure=None):
    """A smooth sphere's scene; with `limiting_pressure` (Pa) it is the body's hardness and plasticity is 'auto'."""
    scene = {"name": "validation", "description": "validation: smooth sphere on a flat, JKR",
            "impact_velocity": float(velocity),
            "body": {"shape": "sphere", "radius": float(radius), "density": float(density)},
            "surfaces": {"work_of_adhesion": float(w),
                         "body": {k: body[k] for k in ("youngs_modulus", "poisson_ratio")},
                         "substrate": {k: substrate[k] for k in ("youngs_modulus", "poisson_ratio")}},
            "physics": {"adhesion_law": "jkr", "detachment": "displacement", "menisci": "off"},
            "numerics": {"max_bounces": 1}}
    if limiting_pressure is not None:
        scene["description"] = "validation: smooth sphere on a flat, Thornton-Ning elastic-plastic"
        scene["surfaces"]["body"]["hardness"] = float(limiting_pressure)
        scene["physics"]["plasticity"] = "auto"
    return scene


def simulator_restitution(radius, density, w, body, substrate, velocity, limiting_pressure=None):
    """First-impact restitution of the simulator (0 when the sphere sticks); raises on failure."""
    from continuum import run_scene
    result = run_scene(_scene(radius, density, w, body, substrate, velocity, limiting_pressure))
    if result.stuck or not result.bounces:
        return 0.0
    return float(result.bounces[0].restitution)


def simulator_capture(radius, density, w, body, substrate, guess, steps=20):
    """Simulator capture velocity by bisection on stick/rebound in [guess/2, 2 guess] (m/s)."""
    lo, hi = 0.5 * guess, 2.0 * guess
    if simulator_restitution(radius, density, w, body, substrate, lo) > 0.0 or \
            simulator_restitution(radius, density, w, body, substrate, hi) == 0.0:
        raise RuntimeError("capture velocity outside [guess/2, 2 guess]")
    for _ in range(steps):
        mid = np.sqrt(lo * hi)
        if simulator_restitution(radius, density, w, body, substrate, mid) > 0.0:
            hi = mid
        else:
            lo = mid
    return float(np.sqrt(lo * hi))


def _try_simulator(fn, *args):
    """(value, None) or (None, one-line reason): a failing simulator is reported, not hidden."""
    try:
        return fn(*args), None
    except Exception as exc:  # noqa: BLE001 - any failure is recorded on the page as it is
        line = f"{type(exc).__name__}: {exc}".splitlines()[0]
        log.warning("simulator failed: %s", line)
        return None, line


# ------------------------------------------------------------------------------------------------
# Capture velocity against size (Arffman et al. 2015)
# ------------------------------------------------------------------------------------------------
def _tn_capture_grid(radius, rho, e_star, w_grid, p_grid):
    """Thornton-Ning capture velocity over the (w, p_y) grid; NaN where p_y <= the adhesive scale."""
    out = np.full((len(w_grid), len(p_grid)), np.nan)
    for i, w in enumerate(w_grid):
        for j, p in enumerate(p_grid):
            try:
                out[i, j] = tn.capture_velocity(radius, w, e_star, rho, p)
            except InputError:
                pass
    return out


def capture_case(name, ds, simulate):
    """Predicted capture velocities (bands) at each printed size and along a size sweep."""
    body, sub, bands = ds["body"], ds["substrate"], ds["bands"]
    e_star, rho = contact_modulus(body, sub), body["density"]
    w_lo, w_hi = bands["work_of_adhesion"]
    w_grid = np.geomspace(w_lo, w_hi, 5)
    p_grid = np.geomspace(*bands["limiting_pressure"], 5)
    points = []
    for row in read_csv(HERE / ds["file"]):
        d, v_meas = float(row["particle_diameter_m"]), float(row["capture_velocity_m_s"])
        r = d / 2
        el = [float(tn.capture_velocity_elastic(r, w, e_star, rho)) for w in (w_lo, w_hi)]
        grid = _tn_capture_grid(r, rho, e_star, w_grid, p_grid)
        ok = np.isfinite(grid)
        point = {"diameter": d, "measured": v_meas, "where": row["where_in_source"],
                 "how": row["how_obtained"], "elastic_band": el,
                 "tn_band": [float(np.nanmin(grid)), float(np.nanmax(grid))] if ok.any() else None,
                 "tn_applicable_fraction": float(ok.mean())}
        if simulate:
            w_mid = float(np.sqrt(w_lo * w_hi))
            guess = float(tn.capture_velocity_elastic(r, w_mid, e_star, rho))
            point["simulator_work_of_adhesion"] = w_mid
            point["elastic_at_simulator_w"] = guess
            point["simulator"], point["simulator_error"] = _try_simulator(
                simulator_capture, r, rho, w_mid, body, sub, guess)
        points.append(point)
    sweep = _capture_sweep(points, e_star, rho, w_grid, p_grid)
    return {"case": name, "e_star": e_star, "density": rho, "work_of_adhesion_grid": w_grid.tolist(),
            "limiting_pressure_grid": p_grid.tolist(), "points": points, "sweep": sweep,
            "exponents": _exponents(points, e_star, rho, w_grid, p_grid)}


def _capture_sweep(points, e_star, rho, w_grid, p_grid):
    d = np.geomspace(min(p["diameter"] for p in points), max(p["diameter"] for p in points), 25)
    el_lo = tn.capture_velocity_elastic(d / 2, w_grid[0], e_star, rho)
    el_hi = tn.capture_velocity_elastic(d / 2, w_grid[-1], e_star, rho)
    tn_lo, tn_hi = [], []
    for di in d:
        g = _tn_capture_grid(di / 2, rho, e_star, w_grid, p_grid)
        tn_lo.append(float(np.nanmin(g)) if np.isfinite(g).any() else None)
        tn_hi.append(float(np.nanmax(g)) if np.isfinite(g).any() else None)
    return {"diameter": d.tolist(), "elastic_low": np.asarray(el_lo).tolist(),
            "elastic_high": np.asarray(el_hi).tolist(), "tn_low": tn_lo, "tn_high": tn_hi}


def _exponents(points, e_star, rho, w_grid, p_grid):
    """Size exponent between the two end sizes: elastic (any w) and TN over the (w, p_y) grid."""
    d0, d1 = points[0]["diameter"], points[-1]["diameter"]
    measured = np.log(points[-1]["measured"] / points[0]["measured"]) / np.log(d1 / d0)
    el = np.log(tn.capture_velocity_elastic(d1 / 2, 1.0, e_star, rho)
                / tn.capture_velocity_elastic(d0 / 2, 1.0, e_star, rho)) / np.log(d1 / d0)
    g0 = _tn_capture_grid(d0 / 2, rho, e_star, w_grid, p_grid)
    g1 = _tn_capture_grid(d1 / 2, rho, e_star, w_grid, p_grid)
    k = np.log(g1 / g0) / np.log(d1 / d0)
    ok = np.isfinite(k)
    return {"measured_end_points": float(measured), "elastic": float(el),
            "tn_range": [float(k[ok].min()), float(k[ok].max())] if ok.any() else None,
            "tn_applicable_pairs": int(ok.sum()), "pairs": int(k.size)}


# ------------------------------------------------------------------------------------------------
# Restitution at 20-100 m/s (Wall et al. 1990)
# ------------------------------------------------------------------------------------------------
def _tn_restitution(v, r, w, e_star, rho, p_y):
    """Thornton-Ning restitution, or None where p_y is below the adhesive stress scale of (r, w)."""
    try:
        e = tn.restitution(v, r, w, e_star, rho, p_y)
    except InputError:
        return None
    return float(e) if np.ndim(e) == 0 else e


def restitution_case(name, ds, simulate):
    """Elastic, Thornton-Ning and simulator restitution against the printed energy-loss bound."""
    body, sub, bands = ds["body"], ds["substrate"], ds["bands"]
    e_star, rho, r = contact_modulus(body, sub), body["density"], ds["diameter"] / 2
    p_y = body["limiting_pressure"]
    rows = {row["quantity"]: row for row in read_csv(HERE / ds["file"])}
    loss = rows["energy_lost_fraction_high_velocity"]
    e_floor = float(np.sqrt(1.0 - float(loss["high"])))
    w_lo, w_hi = bands["work_of_adhesion"]
    w_mid = float(np.sqrt(w_lo * w_hi))
    points = []
    for v in ds["velocities"]:
        el = [float(tn.restitution(v, r, w, e_star, rho, np.inf)) for w in (w_hi, w_lo)]
        tn_w = {w: _tn_restitution(v, r, w, e_star, rho, p_y) for w in (w_lo, w_hi)}
        tnb = [x for x in tn_w.values() if x is not None]
        point = {"velocity": v, "measured_floor": e_floor, "elastic_band": el,
                 "tn_band": [min(tnb), max(tnb)] if tnb else None,
                 "tn_inapplicable_w": [w for w, x in tn_w.items() if x is None]}
        ratios = [float(tn.contact_radius_ratio(v, r, w, e_star, rho, p_y)) for w, x in tn_w.items() if x is not None]
        point["tn_radius_ratio"] = max(ratios) if ratios else None
        point["tn_beyond_range"] = bool(ratios) and max(ratios) > tn.LAW_RANGE_RADIUS_RATIO
        point["tn_range"] = tn.LAW_RANGE_RADIUS_RATIO
        if simulate:
            point["simulator_work_of_adhesion"] = w_mid
            point["simulator"], point["simulator_error"] = _try_simulator(
                simulator_restitution, r, rho, w_mid, body, sub, v)
            point["simulator_plastic"], point["simulator_plastic_error"] = _try_simulator(
                simulator_restitution, r, rho, w_mid, body, sub, v, p_y)
            point["tn_at_simulator_w"] = _tn_restitution(v, r, w_mid, e_star, rho, p_y)
        points.append(point)
    v_curve = np.geomspace(0.1, 100.0, 120)
    curves = {"velocity": v_curve.tolist()}
    for w in (w_lo, w_mid, w_hi):
        curves[f"elastic_w{w:g}"] = np.asarray(tn.restitution(v_curve, r, w, e_star, rho, np.inf)).tolist()
        e_tn = _tn_restitution(v_curve, r, w, e_star, rho, p_y)
        curves[f"tn_w{w:g}"] = None if e_tn is None else np.asarray(e_tn).tolist()
    facts = {"yield_velocity": float(tn.yield_velocity(p_y, r, w_mid, e_star, rho)),
             "capture_elastic": float(tn.capture_velocity_elastic(r, w_mid, e_star, rho)),
             "capture_tn": float(tn.capture_velocity(r, w_mid, e_star, rho, p_y)),
             "adhesive_stress_scale": float(tn.adhesive_stress_scale(r, w_mid, e_star))}
    return {"case": name, "e_star": e_star, "limiting_pressure": p_y, "radius": r,
            "high_velocity_range": [float(rows["high_velocity_range"]["low"]),
                                    float(rows["high_velocity_range"]["high"])],
            "work_of_adhesion_band": [w_lo, w_hi], "work_of_adhesion_mid": w_mid,
            "points": points, "curves": curves, "facts": facts}


# ------------------------------------------------------------------------------------------------
# Capillary adhesion limit (DelRio et al. 2007)
# ------------------------------------------------------------------------------------------------
def capillary_case(name, ds):
    """Upper limit of capillary adhesion between flat surfaces, gamma_lv (cos th1 + cos th2)."""
    from continuum.wet import menisci
    gamma = ds["liquid"]["surface_tension"]
    th_lo, th_hi = ds["bands"]["contact_angle"]
    band = sorted(gamma * menisci.wetting_sum(np.radians(t), np.radians(t)) for t in (th_lo, th_hi))
    row = read_csv(HERE / ds["file"])[0]
    return {"case": name, "measured": float(row["value"]), "where": row["where_in_source"],
            "how": row["how_obtained"], "predicted_band": band, "surface_tension": gamma,
            "contact_angle_band": [th_lo, th_hi]}


# ------------------------------------------------------------------------------------------------
# AFM pull-off against humidity (Jones et al. 2002)
# ------------------------------------------------------------------------------------------------
def humidity_case(name, ds):
    """Pull-off of the afm_tip_humidity scene at the printed tip radius over the printed RH range, as a band over
    the contact angle and work of adhesion ranges, for each menisci.solid_adhesion choice."""
    rows = {r["quantity"]: r for r in read_csv(HERE / ds["file"])}
    lo, hi = float(rows["relative_humidity_low"]["value"]), float(rows["relative_humidity_high"]["value"])
    rhs = [float(x) for x in np.round(np.arange(lo, hi + 1e-9, 0.05), 2)]
    radius = float(rows["tip_radius"]["value"])
    bands = ds["bands"]
    curves = {}
    for choice in ds["choices"]["solid_adhesion"]:
        runs = [pull_off_humidity.pull_off_curve(
            "afm_tip_humidity", rhs, {"body.radius": radius, "surfaces.body.contact_angle": theta,
                                      "surfaces.substrate.contact_angle": theta, "surfaces.work_of_adhesion": w,
                                      "menisci.solid_adhesion": choice, "menisci.surface_tension":
                                      ds["liquid"]["surface_tension"]})
                for theta in bands["contact_angle"] for w in bands["work_of_adhesion"]]
        forces = np.array([[r["pull_off_force"] for r in run] for run in runs])
        bridged = [all(run[i]["bridge"] for run in runs) for i in range(len(rhs))]
        wet = forces[:, bridged]
        curves[choice] = {"low": forces.min(axis=0).tolist(), "high": forces.max(axis=0).tolist(),
                          "bridged": bridged, "band_with_bridge": [float(wet.min()), float(wet.max())]
                          if wet.size else None, "band_dry": [float(forces[:, 0].min()), float(forces[:, 0].max())],
                          "laws": sorted({r["law"] for run in runs for r in run})}
    first = next((rh for rh, b in zip(rhs, curves[ds["choices"]["solid_adhesion"][0]]["bridged"]) if b), None)
    row = rows["pull_off_force_small_contacts"]
    return {"case": name, "relative_humidity": rhs, "tip_radius": radius, "curves": curves,
            "kelvin_radius": [r["kelvin_radius"] for r in runs[0]],
            "min_kelvin_radius": runs[0][0]["min_kelvin_radius"],
            "measured": float(row["value"]), "where": row["where_in_source"], "how": row["how_obtained"],
            "reading": row["reading"], "first_bridged_rh": first, "contact_angle_band": bands["contact_angle"],
            "work_of_adhesion_band": bands["work_of_adhesion"], "surface_tension": ds["liquid"]["surface_tension"]}


# ------------------------------------------------------------------------------------------------
# Figures
# ------------------------------------------------------------------------------------------------
def figure_capture(res):
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    s = res["sweep"]
    d = np.asarray(s["diameter"]) * 1e9
    ax.fill_between(d, s["elastic_low"], s["elastic_high"], alpha=0.3, label="elastic JKR/TN closed form (w band)")
    lo = np.array([np.nan if x is None else x for x in s["tn_low"]])
    hi = np.array([np.nan if x is None else x for x in s["tn_high"]])
    ax.fill_between(d, lo, hi, alpha=0.3, color="tab:red", label="Thornton-Ning elastic-plastic (w, p_y band)")
    for p in res["points"]:
        ax.plot(p["diameter"] * 1e9, p["measured"], "ks")
        if p.get("simulator") is not None:
            ax.plot(p["diameter"] * 1e9, p["simulator"], "o", color="tab:blue", mfc="none")
    ax.plot([], [], "ks", label="Arffman et al. 2015 (printed)")
    ax.plot([], [], "o", color="tab:blue", mfc="none", label="simulator (JKR, mid-band w)")
    ax.set(xscale="log", yscale="log", xlabel="particle diameter (nm)", ylabel="capture velocity (m/s)",
           title="Silver spheres on aluminium")
    ax.legend(fontsize=7)
    return fig


def figure_restitution(res):
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    c = res["curves"]
    v = c["velocity"]
    for key, style in (("elastic", "-"), ("tn", "--")):
        for w, col in zip((res["work_of_adhesion_band"][0], res["work_of_adhesion_mid"],
                           res["work_of_adhesion_band"][1]), ("tab:green", "tab:blue", "tab:purple")):
            lab = f"{'elastic JKR/TN' if key == 'elastic' else 'Thornton-Ning'}, w = {w:.2g} J/m^2"
            if c[f"{key}_w{w:g}"] is not None:
                ax.plot(v, c[f"{key}_w{w:g}"], style, color=col, label=lab)
    lo, hi = res["high_velocity_range"]
    ax.fill_between([lo, hi], res["points"][0]["measured_floor"], 1.0, color="0.8",
                    label="Wall et al. 1990: at most half the energy lost (printed)")
    for p in res["points"]:
        if p.get("simulator") is not None:
            ax.plot(p["velocity"], p["simulator"], "o", color="tab:blue", mfc="none")
    ax.plot([], [], "o", color="tab:blue", mfc="none", label="simulator (JKR, mid-band w)")
    for p in res["points"]:
        if p.get("simulator_plastic") is not None:
            ax.plot(p["velocity"], p["simulator_plastic"], "x", color="tab:red")
    ax.plot([], [], "x", color="tab:red", label="simulator (Thornton-Ning law, mid-band w)")
    ax.set(xscale="log", xlabel="impact velocity (m/s)", ylabel="coefficient of restitution",
           ylim=(0, 1.02), title="Ammonium fluorescein, d = 4.9 um, on silicon")
    ax.legend(fontsize=6)
    return fig


def figure_capillary(res):
    fig = Figure(figsize=(4.8, 3.6))
    ax = fig.subplots()
    ax.axhspan(*res["predicted_band"], color="tab:blue", alpha=0.3,
               label="gamma_lv (cos th1 + cos th2), th in band")
    ax.plot([0], [res["measured"]], "ks", label="DelRio et al. 2007 upper limit (printed)")
    ax.set(xticks=[], ylabel="adhesion energy (J/m^2)", ylim=(0, 0.2), title="Wet rough polysilicon")
    ax.legend(fontsize=7)
    return fig


def figure_humidity(res):
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    rh = np.asarray(res["relative_humidity"]) * 100
    for (choice, c), col in zip(res["curves"].items(), ("tab:blue", "tab:red")):
        ax.fill_between(rh, np.asarray(c["low"]) * 1e9, np.asarray(c["high"]) * 1e9, color=col, alpha=0.3,
                        step="mid", label=f"model, solid adhesion '{choice}' (angle, w band)")
    ax.hlines(res["measured"] * 1e9, rh[0], rh[-1], colors="k", linestyles="--",
              label="Jones et al. 2002: ~20 nN at R ~ 20 nm, humidity not stated (printed)")
    ax.set(xlabel="relative humidity (%)", ylabel="pull-off force (nN)", ylim=(0, None),
           title=f"Silicon tip, R = {res['tip_radius'] * 1e9:g} nm, on hydrophilic silicon")
    ax.legend(fontsize=7)
    return fig


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-simulator", action="store_true", help="closed forms only")
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    with open(HERE / "datasets.toml", "rb") as fh:
        datasets = tomllib.load(fh)
    simulate = not args.no_simulator
    results = {"capture": capture_case("arffman2015", datasets["arffman2015"], simulate),
               "restitution": restitution_case("wall1990", datasets["wall1990"], simulate),
               "capillary": capillary_case("delrio2007", datasets["delrio2007"]),
               "humidity": humidity_case("jones2002", datasets["jones2002"])}
    makers = {"capture": figure_capture, "restitution": figure_restitution, "capillary": figure_capillary,
              "humidity": figure_humidity}
    for key, res in results.items():
        atomic_write_json(FIGURES / f"validation_{key}.json", res)
        atomic_save_figure(makers[key](res), FIGURES / f"validation_{key}.png", dpi=120)
    validation_page.write(ROOT / "docs" / "validation.md", results, datasets, simulate)
    log.info("wrote docs/validation.md and docs/figures/validation_*.png/json")


if __name__ == "__main__":
    main()
