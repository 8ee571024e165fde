"""The SAM layer's modulus, thickness and Poisson ratio as the calibrated set carries them (calibration.mdset).

Modulus. The contact model needs the layer's small-strain stiffness: the tangent confined modulus M0 at the zero-force
point of the compression branch of the OTS/OTS flat-slab curve (md.analysis.tangent_confined_modulus), not the chord
through a branch that stiffens. It is normalised by the annealed stack thickness: both SAMs' all-trans CH3 height at
the anneal's mean tilt (md.analysis.small_strain_layer_record; the builder's 15 deg tilt relaxes to ~28 deg). A result
that predates the quantity has it derived here from its committed windows, system record and anneal tilt series with
the same function. The layer thickness the continuum uses (surfaces.sam.thickness) is the same MD's per-layer
thickness, so the measured stiffness per area M0 / t is what the continuum's layer has.

Poisson ratio. The scene key is Young's modulus of an isotropic layer, E = M (1 + nu)(1 - 2 nu)/(1 - nu), and the
coated contact uses E' = E/(1 - nu^2) = M (1 - 2 nu)/(1 - nu)^2: at fixed measured M, nu enters twice. Where the MD
measured nu from the SAM's own stress (sam_poisson_ratio, adhesion option sam_stress) it is used; otherwise nu stays
the set's declared choice and E's stderr carries the spread of E'(nu) over NU_UNMEASURED (md.analysis.poisson_spread).

Not in the stderr: the loading rate. The compression windows move 0.8 A per 12 ps (~1e9 /s strain rate), an
unrelaxed (glassy) modulus; the slow-loading pass that would bound it is staged, not run (docs/md.md).
"""
from __future__ import annotations

import math

from md import chain_geometry, poisson_spread, small_strain_layer_record, tilt_of_anneal, young_from_confined

#: where an unmeasured layer Poisson ratio may lie (a declared choice, docs/md.md "SAM layer modulus"): glassy
#: polymers 0.3-0.4 and chain-molecule solids up to ~0.45 (a reviewer's estimate, unchecked); 0.25 below them
NU_UNMEASURED = (0.25, 0.45)

LAYER_QUANTITIES = ("sam_layer_tangent_modulus",)
THICKNESS_QUANTITIES = ("sam_layer_thickness_per_layer",)


def _height_of_tilt(chain_length: int):
    return lambda th: float(chain_geometry(int(chain_length), th)[0][-1][2])


def with_layer_quantities(res: dict | None) -> dict | None:
    """The result with ``sam_layer_tangent_modulus`` (derived from its committed windows where the run predates it)
    and ``sam_layer_thickness_per_layer`` (the thickness that modulus used, per SAM) in its quantities. A result
    without windows, or whose branch has fewer than four repulsive windows, is returned as it is."""
    if res is None:
        return None
    q = dict(res.get("quantities") or {})
    if "sam_layer_tangent_modulus" not in q:
        win, system = (res.get("details") or {}).get("pmf_windows"), res.get("system") or {}
        tilt = tilt_of_anneal(((res.get("details") or {}).get("anneal") or {}).get("mean_tilt_deg") or [])
        n = (res.get("settings") or {}).get("chain_length", 18)
        try:
            force = [f + t for f, t in zip(win["mean_force_kcal_mol_A"],
                                           win.get("tail_force_kcal_mol_A") or [0.0] * len(win["separation_A"]))]
            rec = small_strain_layer_record(win["separation_A"], force, win["stderr_kcal_mol_A"], system["area_A2"],
                                            system, tilt, _height_of_tilt(n))
        except (KeyError, TypeError, ValueError):
            return res
        tg = rec["tangent"]
        q["sam_layer_tangent_modulus"] = {
            "value": rec["modulus_Pa"], "stderr": rec["stderr_Pa"], "units": "Pa", "derived_from_windows": True,
            "thickness_m": rec["thickness_A"] * 1e-10, "thickness_stderr_m": rec["thickness_stderr_A"] * 1e-10,
            "thickness_per_layer_m": rec["thickness_per_layer_m"], "layers": rec["layers"],
            "thickness_source": rec["thickness_source"], "chord_modulus_Pa": tg["chord_modulus_Pa"],
            "curvature_delta_chi2": tg["curvature_delta_chi2"], "windows": tg["windows"],
            "strain_max": tg["strain_max"], "builder_thickness_m": rec["builder_thickness_A"] * 1e-10}
    lm = q["sam_layer_tangent_modulus"]
    if "sam_layer_thickness_per_layer" not in q and lm.get("thickness_per_layer_m"):
        layers = int(lm.get("layers") or 1)
        q["sam_layer_thickness_per_layer"] = {
            "value": lm["thickness_per_layer_m"], "stderr": (lm.get("thickness_stderr_m") or 0.0) / layers,
            "units": "m", "derived_from_windows": bool(lm.get("derived_from_windows")),
            "source": lm.get("thickness_source", "")}
    return {**res, "quantities": q}


def measured_poisson(res: dict) -> dict | None:
    """The result's measured layer Poisson ratio (sam_poisson_ratio) as {value, stderr}, or None."""
    p = (res.get("quantities") or {}).get("sam_poisson_ratio") or {}
    v, e = p.get("value"), p.get("stderr")
    if v is None or not math.isfinite(v) or not 0.0 <= v < 0.5:
        return None
    return {"value": float(v), "stderr": float(e) if e is not None and math.isfinite(e) else None,
            "c13_over_c33": p.get("c13_over_c33")}


def young_with_nu(modulus: float, stderr: float | None, nu_set: float, res: dict) -> tuple[float, float | None, dict]:
    """(E, its stderr, the poisson_ratio record) of a layer of confined modulus M: E = M (1 + nu)(1 - 2 nu)/(1 - nu)
    with the measured nu where the result has one, else the set's; the stderr holds M's and nu's part, the latter
    as the relative spread of E' = M (1 - 2 nu)/(1 - nu)^2 (what the coated contact uses at fixed M)."""
    meas = measured_poisson(res)
    if meas is not None:
        nu, nu_err = meas["value"], meas["stderr"] or 0.0
        rel_nu = abs(-2.0 / (1.0 - 2.0 * nu) + 2.0 / (1.0 - nu)) * nu_err
        rec = {"value": nu, "stderr": nu_err, "measured": True, "c13_over_c33": meas["c13_over_c33"],
               "note": "measured: C13/C33 of the SAM stack from its own stress in the compression windows, the "
                       "isotropic layer with that ratio (md.analysis.stress_ratio_poisson)"}
    else:
        nu = float(nu_set)
        lo, hi = NU_UNMEASURED
        sp = poisson_spread(min(lo, nu), max(hi, nu), nu)
        rel_nu = sp["relative_stderr"]
        rec = {"value": nu, "stderr": sp["nu_stderr"], "measured": False, "interval": [lo, hi],
               "note": f"NOT MEASURED (needs the sam_stress MD, staged: docs/md.md): the set's declared nu = {nu:g}; "
                       f"over nu uniform on [{lo:g}, {hi:g}] the coated contact's E' at fixed M ranges "
                       f"{sp['ratio_min']:.2f}-{sp['ratio_max']:.2f} x its value at {nu:g}, rms {rel_nu:.0%}, "
                       f"which E's stderr carries"}
    factor = young_from_confined(1.0, nu)
    e = modulus * factor
    rel_m = (stderr / modulus) if stderr is not None and modulus else 0.0
    rec["E_relative_stderr_from_nu"] = rel_nu
    return e, e * math.hypot(rel_m, rel_nu), rec


def thickness_record(lm: dict, continuum_thickness_m: float | None) -> dict:
    """The thickness the modulus used and how it compares with the set's surfaces.sam.thickness."""
    per = lm.get("thickness_per_layer_m")
    out = {"total_m": lm.get("thickness_m"), "per_layer_m": per, "layers": lm.get("layers"),
           "stderr_total_m": lm.get("thickness_stderr_m"), "source": lm.get("thickness_source"),
           "builder_total_m": lm.get("builder_thickness_m")}
    if per and continuum_thickness_m:
        out["continuum_thickness_m"] = float(continuum_thickness_m)
        out["continuum_over_md"] = float(continuum_thickness_m) / per
        out["matches_within_5_percent"] = abs(float(continuum_thickness_m) / per - 1.0) <= 0.05
    return out
