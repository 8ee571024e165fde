"""Warnings a result carries: too few summits for an average, grid too small, yield onset.

Sources: Johnson, Contact Mechanics (1985) §4.2/§6.2 (line contact first yields at p_max = 1.67 Y
Tresca, 1.79 Y von Mises); Greenwood & Williamson (1966) (plasticity index psi > 1: most summits
yield; < 0.6: elastic).
"""
from __future__ import annotations

import math

from ..model import regimes
from ..reference import hertz as href

#: Below this many summits attached at maximum approach, the GW average is not to be trusted.
MIN_CONTACTS = 10.0


def result_warnings(scene, law, bounces) -> list[str]:
    out = []
    surf = scene.surfaces
    diag = law.diagnostics()
    if scene.contact == "rough":
        n = diag.get("max_contacts", 0.0)
        mode = surf.roughness.mode
        if n < MIN_CONTACTS and mode == "mean_field":
            out.append(f"averaged rough contact with only {n:.3g} summits attached at most (< {MIN_CONTACTS:g}): "
                       "the Greenwood-Williamson average is not reliable here; run surfaces.roughness.mode = "
                       "'ensemble' (or 'auto') for the distribution over realisations")
        elif n < MIN_CONTACTS and mode == "ensemble":
            out.append(f"the mean-field trajectory has only {n:.3g} summits attached at most: it describes no single "
                       "impact; the prediction is the ensemble block's distribution")
        elif n < MIN_CONTACTS:
            out.append(f"discrete realisation with {n:.3g} summits attached at most: its result depends on the "
                       "seed; surfaces.roughness.mode = 'ensemble' gives the spread")
        if diag.get("edge_touched"):
            out.append("attached summits reached the edge of the grid: the footprint was larger than the grid's "
                       "design depth; raise numerics.grid_points or report this case")
    if surf.yield_strength is not None:
        y = surf.yield_strength
        if scene.contact == "rough":
            p_max = diag.get("max_nominal_pressure", 0.0)
            what = "nominal peak pressure"
        elif scene.body.shape == "cylinder" and bounces:
            load = max(b.peak_force for b in bounces)
            p_max = float(href.line_peak_pressure(load, scene.body.radius, scene.body.length, surf.e_star))
            what = "Hertz peak pressure"
        else:
            p_max = 0.0
            what = "peak pressure"
        if p_max > regimes.LINE_YIELD_TRESCA * y:
            crit = "von Mises" if p_max > regimes.LINE_YIELD_VON_MISES * y else "Tresca (not yet von Mises)"
            out.append(f"{what} {p_max:.3g} Pa exceeds the {crit} onset of yield "
                       f"({regimes.LINE_YIELD_TRESCA:g} Y = {regimes.LINE_YIELD_TRESCA * y:.3g} Pa): the elastic model "
                       "no longer holds")
    if surf.hardness is not None and surf.roughness is not None:
        e_s = surf.roughness.summit_modulus or surf.e_star
        psi = regimes.plasticity_index(e_s, surf.hardness, surf.roughness.sigma, surf.roughness.summit_radius)
        if psi > 1.0:
            out.append(f"plasticity index psi = {psi:.3g} > 1: most summits yield (Greenwood & Williamson 1966); "
                       + ("they run the Thornton-Ning elastic-plastic law (models.plasticity)"
                          if diag.get("plastic_summits") else "this run's elastic summits overstate the rebound "
                          "(models.plasticity says why; an ensemble's members record their own summits)"))
        elif psi > 0.6 and math.isfinite(psi):
            out.append(f"plasticity index psi = {psi:.3g} between 0.6 and 1: some summits yield")
    return out


#: Bridges are modelled with r_K << beta; above this D_K/beta the azimuthal curvature matters.
MAX_KELVIN_GAP_OVER_RADIUS = 0.1


def model_warnings(models: dict) -> list[str]:
    """Warnings about the models chosen (from result.json -> models)."""
    out = []
    adhesion = models.get("adhesion", {})
    men = models.get("menisci", {})
    ratio = men.get("kelvin_gap_over_summit_radius")
    if men.get("used") and ratio is not None and ratio > MAX_KELVIN_GAP_OVER_RADIUS:
        out.append(f"Kelvin gap / summit radius = {ratio:.3g} > {MAX_KELVIN_GAP_OVER_RADIUS:g}: the bridge force "
                   "assumes r_K << beta (humidity close to saturation or tiny summits)")
    if adhesion.get("decided_by") == "geometry" and not adhesion.get("used", True) and adhesion.get("work_of_adhesion"):
        out.append("work of adhesion given but a smooth roller has no adhesive law here: adhesion left out")
    return out


def audit_warnings(scene, audit: dict) -> list[str]:
    """A warning where the run's energy audit exceeds the scene's `numerics.audit_tolerance` (none if unset)."""
    tolerance = scene.numerics.audit_tolerance
    error = audit.get("max_relative_error", 0.0)
    if tolerance is None or not error > tolerance:
        return []
    return [f"energy audit error {error:.3g} of the first impact's kinetic energy exceeds numerics.audit_tolerance "
            f"= {tolerance:g} (relative to the run's turnover: {audit.get('max_error_over_turnover', 0.0):.3g}): "
            "the integration or the contact tables are not accurate enough for this scene (try numerics.fidelity = "
            "'reference'), or the model is outside its range (see the surface block's validity checks)"]
