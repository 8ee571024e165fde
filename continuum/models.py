"""Choose the contact law a scene needs, and say why (recorded in result.json -> models)."""
from __future__ import annotations

import math

from . import regimes
from .reference import jkr as jkr_ref

#: Below this sigma/delta_c the `fast` GW tables miss 1e-6 (measured, docs/rough-gw.md).
FAST_TABLE_MIN_SIGMA_OVER_DELTA_C = 3.0
from .laws.base import ContactLaw
from .laws.hertz import HertzLine, HertzSphere, LinearSpring, roller_constant_stiffness
from .laws.jkr import JKRSphere
from .scene import Scene


def rough_law(scene: Scene) -> tuple[ContactLaw, dict]:
    """GW/JKR rough roller for `scene`, and the record of its datum, regime numbers and choices."""
    from .laws.rough_roller import RoughRoller
    from .rough.datum import tallest_summit
    from .rough.gw import GWJKRSurface, SummitStatistics

    body, surf, phys = scene.body, scene.surfaces, scene.physics
    rough = surf.roughness
    w = surf.interface_work_of_adhesion if phys.adhesion_law == "jkr" else 0.0
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    summit_e_star = rough.summit_modulus if rough.summit_modulus is not None else surf.e_star
    if rough.mode == "discrete":
        # a seeded realisation of individual summits, same per-summit laws; no GW tables are built
        from .laws.discrete_roller import DiscreteRoughRoller
        law = DiscreteRoughRoller(stats, w, summit_e_star, body.radius, body.length, surf.e_star, seed=rough.seed,
                                  detachment=phys.detachment, half_space=phys.half_space == "on",
                                  grid_points=scene.numerics.grid_points,
                                  footprint_half_width=datum["footprint_half_width"])
        surface = law                                   # carries delta_c for the regime numbers
    else:
        table = scene.numerics.table
        if table == "fast" and w > 0 and rough.sigma < FAST_TABLE_MIN_SIGMA_OVER_DELTA_C * float(
                jkr_ref.critical_approach(rough.summit_radius, w, summit_e_star)):
            table = "standard"          # fast tables miss 1e-6 when adhesion dominates (docs/rough-gw.md)
        surface = GWJKRSurface(stats, w, summit_e_star, z_max=datum["z_max"], detachment=phys.detachment,
                               resolution=table)
        if phys.half_space == "on":
            law = RoughRoller(surface, body.radius, body.length, surf.e_star, half_space=True,
                              grid_points=scene.numerics.grid_points)
        else:
            from .laws.rough_rigid import RigidRoughRoller
            law = RigidRoughRoller(surface, body.radius, body.length, resolution=scene.numerics.table)
    regime = {
        "summit_e_star": summit_e_star,
        "sigma_over_delta_c": rough.sigma / surface.delta_c if w > 0 else math.inf,
        "fuller_tabor_theta": regimes.fuller_tabor_theta(rough.sigma, rough.summit_radius, w, summit_e_star),
        "tabor_parameter": regimes.tabor_parameter(rough.summit_radius, w, summit_e_star) if w > 0 else 0.0,
        "tabor_z0": regimes.Z0_DEFAULT,
    }
    if surf.hardness is not None:
        regime["plasticity_index"] = regimes.plasticity_index(summit_e_star, surf.hardness, rough.sigma,
                                                              rough.summit_radius)
    record = {"datum": {**datum, "z_max_m": datum["z_max"] * rough.sigma, "release_from": rough.datum},
              "regime": regime, "table": {"resolution": getattr(surface, "resolution", scene.numerics.table),
                                          "build_seconds": getattr(surface, "build_seconds", None)}}
    if rough.mode != "discrete" and table != scene.numerics.table:
        record["table"]["why"] = (f"the '{scene.numerics.table}' preset asked for '{scene.numerics.table}' tables, "
                                  f"but sigma/delta_c < {FAST_TABLE_MIN_SIGMA_OVER_DELTA_C:g}, where they miss their "
                                  "1e-6 accuracy: 'standard' tables were built")
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
        record["mode"] = "averaged"
    return law, record


def select_law(scene: Scene, first_impact_speed: float) -> tuple[ContactLaw, dict]:
    """The contact law for `scene` and a record of what runs, what is left out, and why."""
    body, surf, phys = scene.body, scene.surfaces, scene.physics
    e_star = surf.e_star
    models: dict = {}
    if scene.contact == "rough":
        law, record = rough_law(scene)
        adhesive = phys.adhesion_law == "jkr"
        models["contact_law"] = {**law.describe(), **record,
                                 "why": "contact = 'rough': GW summits on a grid under the roller"}
        models["adhesion"] = {"used": adhesive, "law": phys.adhesion_law,
                              "work_of_adhesion": surf.interface_work_of_adhesion if adhesive else 0.0,
                              "source": "SAM-SAM" if surf.sam is not None else "surfaces.work_of_adhesion",
                              "why": f"adhesion_law = '{phys.adhesion_law}' set in the scene"}
        models["half_space"] = {"used": phys.half_space == "on",
                                "why": f"physics.half_space = '{phys.half_space}'"}
        models["menisci"] = {"used": False, "why": "not modelled yet (wet contact is a later model)"}
        models["sam"] = ({"used": True, "thickness": surf.sam.thickness,
                          "why": "both surfaces covered: SAM-SAM work of adhesion; a uniform layer conforming "
                                 "to the summits shifts all gaps equally, so its thickness does not enter the "
                                 "mechanics (its compliance is a later model)"}
                         if surf.sam is not None else {"used": False, "why": "surfaces.sam.coverage = 'none'"})
        models["free_flight"] = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}
        return law, models
    if phys.adhesion_law == "none":
        if body.shape == "sphere":
            law = HertzSphere(body.radius, e_star)
            why = "smooth sphere, adhesion_law = 'none': Hertz point contact"
        elif phys.line_stiffness == "implicit":
            law = HertzLine(body.radius, body.length, e_star)
            why = "smooth cylinder, adhesion_law = 'none': Hertz line contact with b(W) solved exactly"
        else:
            k, load = roller_constant_stiffness(body.mass, first_impact_speed, body.radius, body.length, e_star)
            law = LinearSpring(k, {"reference_load": load, "reference_speed": first_impact_speed})
            why = ("smooth cylinder, line_stiffness = 'constant': K of eq 1 frozen at the first impact's "
                   "peak load (paper eq 2)")
        if surf.work_of_adhesion > 0:
            models["adhesion"] = {"used": False, "why": "adhesion_law = 'none' (work_of_adhesion ignored)"}
        else:
            models["adhesion"] = {"used": False, "why": "adhesion_law = 'none'"}
    else:  # jkr; scene validation admits only a sphere for smooth contact
        law = JKRSphere(body.radius, surf.interface_work_of_adhesion, e_star, phys.detachment)
        why = f"smooth sphere, adhesion_law = 'jkr': JKR with Fuller-Tabor hysteresis, {phys.detachment}-controlled release"
        models["adhesion"] = {"used": True, "law": "jkr", "why": "adhesion_law = 'jkr' set in the scene"}
    models["contact_law"] = {**law.describe(), "why": why}
    models["menisci"] = {"used": False, "why": "not modelled for smooth contact (wet contact is a later model)"}
    models["half_space"] = {"used": False, "why": "smooth contact: the closed-form law already contains the elastic half-space"}
    models["free_flight"] = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}
    return law, models
