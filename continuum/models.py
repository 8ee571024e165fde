"""Choose the contact law a scene needs, and say why (recorded in result.json -> models)."""
from __future__ import annotations

from .laws.base import ContactLaw
from .laws.hertz import HertzLine, HertzSphere, LinearSpring, roller_constant_stiffness
from .laws.jkr import JKRSphere
from .scene import Scene


def select_law(scene: Scene, first_impact_speed: float) -> tuple[ContactLaw, dict]:
    """The contact law for `scene` and a record of what runs, what is left out, and why."""
    body, surf, phys = scene.body, scene.surfaces, scene.physics
    e_star = surf.e_star
    models: dict = {}
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
        law = JKRSphere(body.radius, surf.work_of_adhesion, e_star, phys.detachment)
        why = f"smooth sphere, adhesion_law = 'jkr': JKR with Fuller-Tabor hysteresis, {phys.detachment}-controlled release"
        models["adhesion"] = {"used": True, "law": "jkr", "why": "adhesion_law = 'jkr' set in the scene"}
    models["contact_law"] = {**law.describe(), "why": why}
    models["menisci"] = {"used": False, "why": "not modelled for smooth contact (wet contact is a later model)"}
    models["half_space"] = {"used": False, "why": "smooth contact: the closed-form law already contains the elastic half-space"}
    models["free_flight"] = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}
    return law, models
