"""The record: what result.json's `models` says about the contact law, the estimate and the SAM.

Decisions write their own records (`continuum.model.decisions`); this module writes the rest, from the
regime, the plan of the rough law and the law that was built.
"""
from __future__ import annotations

import math

from ..scene import Scene
from .regime import Regime

#: The estimate's record says what it is.
ESTIMATE_WHAT = ("quasi-static first approach of Hertz summits on a rigid substrate absorbing the first impact's "
                 "energy (continuum.model.estimates)")
FREE_FLIGHT = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}


def estimate_record(estimate) -> dict:
    return {**estimate.to_json(), "what": ESTIMATE_WHAT}


def free_flight_record() -> dict:
    return dict(FREE_FLIGHT)


def sam_record(scene: Scene, regime: Regime) -> dict:
    """Whether SAM layers enter, and how (the coated summits from the scene's `regime`)."""
    sam = scene.surfaces.sam
    if sam is None:
        return {"used": False, "why": "surfaces.sam.coverage = 'none'"}
    rec = {"used": True, "thickness": sam.thickness, "work_of_adhesion": sam.work_of_adhesion,
           "contact_angle_deg": math.degrees(sam.contact_angle) if sam.contact_angle is not None else None}
    coated = regime.coated
    if coated is None:
        why = ("no surfaces.sam.layer_modulus: a rigid uniform layer conforming to the summits shifts all gaps "
               "equally and does not enter the mechanics" if sam.layer_modulus is None else
               "smooth contact: the coated-summit model is for rough contact")
        rec["layer"] = {"used": False, "why": why}
    else:
        rec["layer"] = {"used": True, "modulus": sam.layer_modulus, "poisson_ratio": sam.layer_poisson_ratio,
                        **coated, "why": "a compliant layer on each summit: the summits' contact modulus is the "
                                         "coated pair's equivalent modulus (docs/model.md, Coated summits)"}
    rec["why"] = "both surfaces covered: SAM-SAM work of adhesion and contact angle"
    return rec


def rough_regime_record(scene: Scene, regime: Regime, work_of_adhesion: float, delta_c: float) -> dict:
    """The regime numbers of the rough law that runs: `work_of_adhesion` is the one it uses (0 where adhesion
    was left out), `delta_c` its summits' JKR separation approach (m)."""
    rough, w = scene.surfaces.roughness, work_of_adhesion
    rec = {
        "summit_e_star": regime.e_star,
        "sigma_over_delta_c": rough.sigma / delta_c if w > 0 else math.inf,
        "fuller_tabor_theta": regime.fuller_tabor_theta if w > 0 else math.inf,
        "tabor_parameter": regime.tabor_parameter if w > 0 else 0.0,
        "tabor_z0": regime.interaction_range,
    }
    if regime.plasticity_index is not None:
        rec["plasticity_index"] = regime.plasticity_index
    return rec


def rough_law_record(scene: Scene, *, datum: dict, regime: dict, surface=None, cost: dict | None, table: str,
                     fast_min_sigma_over_delta_c: float, law=None, summit_law_record=None) -> dict:
    """The rough law's record (merged into models.contact_law): datum, regime, tables, mode.

    `surface` is the averaged model's summit surface (None in discrete mode, where `law` is the discrete
    roller); `table` the GW tables' resolution used; `summit_law_record` what to record of a generic summit law
    (its description, or its name where no surface was built), None for tabulated JKR/Hertz summits."""
    rough = scene.surfaces.roughness
    record = {"datum": {**datum, "z_max_m": datum["z_max"] * rough.sigma, "release_from": rough.datum},
              "regime": regime,
              "table": {"resolution": surface.resolution if surface is not None else scene.numerics.table,
                        "build_seconds": surface.build_seconds if surface is not None else None}}
    if cost is not None:
        record["table"]["cost_estimate"] = cost
    if rough.mode != "discrete" and table != scene.numerics.table:
        record["table"]["why"] = (f"the '{scene.numerics.table}' preset asked for '{scene.numerics.table}' tables, "
                                  f"but sigma/delta_c < {fast_min_sigma_over_delta_c:g}, where they miss their "
                                  "1e-6 accuracy: 'standard' tables were built (GW and, on a rigid substrate, "
                                  "footprint tables)")
        record["table"]["resolution"] = table
    if rough.mode == "discrete":
        record["mode"] = "discrete"
        record["seed"] = rough.seed
        record["datum"]["realised"] = {
            "definition": "tallest effective summit of the realisation, max(z_i - x_i^2/2R)",
            "z_top_m": law.z_top, "z_top_sigma": law.z_top / rough.sigma,
            "summits_in_strip": law.summits_in_strip, "summits_kept": law.summits_kept}
        record["table"] = {"used": False, "why": "discrete mode evaluates each summit's JKR law in closed form"}
    else:
        record["mode"] = "mean_field"
    if summit_law_record is not None:
        record["summit_law"] = summit_law_record
    return record
