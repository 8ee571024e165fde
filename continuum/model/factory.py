"""The factory: builds the contact law the decisions call for. The only module of `continuum` (outside
`continuum.laws` itself) that imports a concrete law class; everything else sees a `ContactLaw`
(`tests/test_architecture.py` holds it to that).

Each function takes what has been decided (law names, booleans, table resolutions) and the scene's
numbers, and returns the built object; nothing here decides or records.
"""
from __future__ import annotations

import functools
import json

from ..laws.base import ContactLaw
from ..scene import Scene


def smooth_law(scene: Scene, adhesion: str, first_impact_speed: float,
               limiting_pressure: float | None = None) -> tuple[ContactLaw, str]:
    """The law of a smooth body under `adhesion` ('none', 'jkr', 'dmt', 'maugis_dugdale'), and what it is; with a
    `limiting_pressure` (Pa) the JKR sphere is the Thornton-Ning elastic-plastic one."""
    from ..laws.branch_sphere import BranchSphere
    from ..laws.hertz import HertzLine, HertzSphere, LinearSpring, roller_constant_stiffness
    from ..laws.jkr import JKRSphere
    from ..laws.plastic_sphere import PlasticJKRSphere

    body, surf, phys = scene.body, scene.surfaces, scene.physics
    e_star = surf.e_star
    if adhesion == "none":
        if body.shape == "sphere":
            return HertzSphere(body.radius, e_star), "smooth sphere, no adhesion: Hertz point contact"
        if phys.line_stiffness == "implicit":
            return (HertzLine(body.radius, body.length, e_star),
                    "smooth cylinder, no adhesion: Hertz line contact with b(W) solved exactly")
        k, load = roller_constant_stiffness(body.mass, first_impact_speed, body.radius, body.length, e_star)
        return (LinearSpring(k, {"reference_load": load, "reference_speed": first_impact_speed}),
                "smooth cylinder, line_stiffness = 'constant': K of eq 1 frozen at the first impact's peak load "
                "(paper eq 2)")
    # adhesive: scene validation admits only a sphere for smooth contact
    if adhesion in ("dmt", "maugis_dugdale"):
        return (BranchSphere(adhesion, body.radius, surf.interface_work_of_adhesion, e_star,
                             surf.interface_interaction_range),
                f"smooth sphere, {adhesion} approach and retreat branches with their jumps (continuum.rough."
                "branch_laws), displacement-controlled release")
    if limiting_pressure is not None:
        return (PlasticJKRSphere(body.radius, surf.interface_work_of_adhesion, e_star, limiting_pressure,
                                 phys.detachment),
                f"smooth sphere, Thornton-Ning adhesive elastic-plastic: JKR to yield, limiting contact pressure "
                f"{limiting_pressure:.4g} Pa, JKR unloading about the flattened radius, {phys.detachment}-controlled "
                "release; the flattening is carried into later impacts")
    return (JKRSphere(body.radius, surf.interface_work_of_adhesion, e_star, phys.detachment),
            f"smooth sphere, JKR with Fuller-Tabor hysteresis, {phys.detachment}-controlled release")


def averaged_surface(stats, *, summit_law=None, work_of_adhesion: float = 0.0, summit_e_star: float = 0.0,
                     z_max: float, detachment: str = "displacement", resolution="standard"):
    """The GW surface of the summits: generic (`summit_law` given, quadrature) or tabulated JKR/Hertz."""
    if summit_law is not None:
        from ..rough.gw_branches import GWBranchSurface
        return GWBranchSurface(stats, summit_law, z_max=z_max, resolution=resolution)
    from ..rough.gw import GWJKRSurface
    return GWJKRSurface(stats, work_of_adhesion, summit_e_star, z_max=z_max, detachment=detachment,
                        resolution=resolution)


def rigid_roller(surface, radius: float, length: float, resolution: str = "standard") -> ContactLaw:
    """Averaged rough roller on a rigid substrate (footprint tables at `resolution`)."""
    from ..laws.rough_rigid import RigidRoughRoller
    return RigidRoughRoller(surface, radius, length, resolution=resolution)


@functools.lru_cache(maxsize=16)
def _plastic_summit_law(name: str, radius: float, work_of_adhesion: float, summit_e_star: float,
                        limiting_pressure: float, z0: float, delta_max: float):
    """The plastic summit law of these values, built once per process (16 kept, least recently used dropped): a
    pure function of them, and nothing writes into one after it is built (the compiled tables it derives,
    `continuum.rough.plastic_kernel`, are a function of it too)."""
    from ..rough.plastic_branches import PlasticBranchSummitLaw
    from ..rough.plastic_summits import PlasticSummitLaw
    if name == "jkr":
        return PlasticSummitLaw(radius, work_of_adhesion, summit_e_star, limiting_pressure)
    return PlasticBranchSummitLaw(name, radius, work_of_adhesion, summit_e_star, limiting_pressure, z0=z0,
                                  delta_max=delta_max)


def plastic_summit_law(scene: Scene, name: str, summit_e_star: float, limiting_pressure: float):
    """One summit's adhesive elastic-plastic law on the summit law `name`: JKR's Thornton-Ning closed forms, or
    Thornton-Ning's construction on the tabulated Maugis-Dugdale / DMT law (tabulated to 30 sigma, as the elastic
    summit law). Built once per process for a set of numbers (an ensemble's members share it): the cache is keyed
    by the values as Python floats, and JKR's closed forms by the four that enter them."""
    surf = scene.surfaces
    tabulated = name != "jkr"
    return _plastic_summit_law(str(name), float(surf.roughness.summit_radius), float(surf.interface_work_of_adhesion),
                               float(summit_e_star), float(limiting_pressure),
                               float(surf.interface_interaction_range) if tabulated else 0.0,
                               float(30.0 * surf.roughness.sigma) if tabulated else 0.0)


def plastic_rigid_roller(scene: Scene, summit_e_star: float, limiting_pressure: float, z_max: float,
                         summit_law: str = "jkr") -> ContactLaw:
    """Rigid roller on the GW mean field of Thornton-Ning summits on `summit_law` (JKR closed forms, or the
    construction on Maugis-Dugdale / DMT) over a rigid substrate (summits of the scene's roughness, the summits'
    E*, limiting contact pressure p_y in Pa, truncation z_max in units of sigma)."""
    from ..laws.plastic_rough import PlasticGWRoller
    rough, body = scene.surfaces.roughness, scene.body
    law = plastic_summit_law(scene, summit_law, summit_e_star, limiting_pressure)
    return PlasticGWRoller(law, rough.sigma, rough.summit_density, z_max, body.radius, body.length)


def plastic_discrete_roller(elastic: ContactLaw, scene: Scene, summit_e_star: float,
                            limiting_pressure: float, summit_law: str = "jkr") -> ContactLaw:
    """The realisation of the elastic discrete roller `elastic` (a rigid-substrate `DiscreteRoughRoller`: its kept
    effective heights) with adhesive elastic-plastic summits on `summit_law`, limiting contact pressure p_y (Pa)."""
    from ..laws.plastic_rough import PlasticDiscreteRoller
    rough = scene.surfaces.roughness
    law = plastic_summit_law(scene, summit_law, summit_e_star, limiting_pressure)
    return PlasticDiscreteRoller(law, elastic.eff, rough.sigma, elastic.depth_keep)


def grid_roller(surface, scene: Scene) -> ContactLaw:
    """Averaged rough roller on the elastic half-space (grid of scene.numerics.grid_points cells)."""
    from ..laws.rough_roller import RoughRoller
    body = scene.body
    return RoughRoller(surface, body.radius, body.length, scene.surfaces.e_star, half_space=True,
                       grid_points=scene.numerics.grid_points)


def discrete_roller(scene: Scene, stats, work_of_adhesion: float, summit_e_star: float, half_space: bool,
                    footprint_half_width: float, summit_law=None, summits=None, heights=None) -> ContactLaw:
    """A seeded realisation of individual summits (surfaces.roughness.seed) under the roller, or the given
    `summits` (x, y, z) of a map patch: closed-form JKR or Hertz summits, or `summit_law`'s tabulated branches
    (Maugis-Dugdale, DMT, coated summits). `heights`: the summit-height distribution drawn from (None: Gaussian of
    sigma; `continuum.rough.tail`)."""
    from ..laws.discrete_roller import DiscreteRoughRoller
    body, surf = scene.body, scene.surfaces
    return DiscreteRoughRoller(stats, work_of_adhesion, summit_e_star, body.radius, body.length, surf.e_star,
                               seed=surf.roughness.seed, detachment=scene.physics.detachment, half_space=half_space,
                               grid_points=scene.numerics.grid_points, footprint_half_width=footprint_half_width,
                               summit_law=summit_law, summits=summits, heights=heights)


def with_menisci(dry: ContactLaw, scene: Scene, stats, parameters: dict) -> ContactLaw:
    """`dry` (an averaged rough roller) plus capillary bridges with the scene's meniscus `parameters`.

    menisci.solid_adhesion = 'wet' on the rigid mean field of JKR (or Hertz) summits: the bridged summits adhere at
    max(W_wet, 0), force and loop, on a second footprint table (`continuum.laws.wet_mean_field`). Otherwise the
    summits keep their dry law inside the bridges, with the DMT solid pull ('wet') or without it ('additive'); the
    record's `solids_inside_bridges` says which and why."""
    from ..laws.rough_rigid import RigidRoughRoller
    from ..laws.wet import MeniscusBridges, WetRoughRoller
    from ..laws.wet_mean_field import wet_mean_field_roller
    body, p = scene.body, parameters
    bridges = MeniscusBridges(stats, dry.z_top, body.radius, body.length, p["bridge_pull_off"], p["kelvin_gap"],
                              p["condensation_time"], p["growth_length"])
    w_wet = max(p["work_of_adhesion_wet"], 0.0)
    if p["solid_adhesion"] != "wet":
        return WetRoughRoller(dry, bridges, {**p, "solids_inside_bridges": "dry summit law, dry loop "
                                             "(menisci.solid_adhesion = 'additive': the paper's eq 14)"})
    s = dry.surface if isinstance(dry, RigidRoughRoller) else None
    why = ("the elastic half-space couples the summits (the deflection breaks the split in h + delta)"
           if not isinstance(dry, RigidRoughRoller) else
           f"{s.law_name} summits on quadrature tables (jump-in and reach): the split is written for JKR/Hertz"
           if s.kind != "tabulated" else
           f"W_wet = {w_wet:.4g} > dgamma = {s.work_of_adhesion:.4g} J/m^2" if w_wet > s.work_of_adhesion else None)
    if why is not None:
        return WetRoughRoller(dry, bridges, {**p, "solids_inside_bridges": f"dry summit law, DMT solid pull "
                                             f"2 pi beta (dgamma - max(W_wet, 0)) (loop dry: {why})"})
    wet_surface = averaged_surface(stats, work_of_adhesion=w_wet, summit_e_star=s.e_star, z_max=s._tmax,
                                   detachment=s.detachment, resolution=s.resolution)
    wet = rigid_roller(wet_surface, body.radius, body.length, resolution=dry.resolution)
    return wet_mean_field_roller(dry, wet, bridges, p)


def with_sphere_meniscus(dry: ContactLaw, wet: ContactLaw, parameters: dict) -> ContactLaw:
    """`dry` (a smooth-sphere law) plus one capillary bridge at its contact with the meniscus `parameters`; `wet`:
    the sphere's law for solids touching inside the bridge (`dry` itself for the additive choice)."""
    from ..laws.sphere_meniscus import SphereBridge, WetSphere
    p = parameters
    bridge = SphereBridge(p["bridge_pull_off"], p["kelvin_gap"], p["condensation_time"], p["growth_length"])
    return WetSphere(dry, wet, bridge, p)


def wet_summit_roller(elastic: ContactLaw, wet: ContactLaw, parameters: dict) -> ContactLaw:
    """A discrete roller whose summits inside a bridge run `wet` (the summit law rebuilt at the wet work of
    adhesion) and outside it `elastic` (`continuum.laws.wet_summits`)."""
    from ..laws.wet_summits import wet_summit_roller as build
    return build(elastic, wet, parameters)


def bridged_discrete_roller(dry: ContactLaw, source: ContactLaw, parameters: dict) -> ContactLaw:
    """`dry` (a discrete summit law, plastic summits included) with a bridge on each of `source`'s summits, by the
    scene's meniscus `parameters` (`continuum.laws.discrete_bridges.wet_discrete`)."""
    from ..laws.discrete_bridges import wet_discrete
    return wet_discrete(dry, source, parameters)


def wet_sharing_dry_tables(wet: ContactLaw, dry: ContactLaw) -> ContactLaw:
    """The averaged wet roller `wet` rebuilt on the dry law `dry` itself where its own dry part is the same law
    (`WetRoughRoller(dry, bridges, record)`, equal `describe()`), else `wet` unchanged. The rigid rough law sizes its
    footprint tables for the deepest impact it has seen (`RigidRoughRoller.prepare`), so two instances run through
    different speeds carry tables of different sizes, whose interpolation errors differ (|e^2| moved by up to ~2e-5
    near escape); on one instance, an impact run dry and then wet at the same speed sees the same tables, and before
    t_a the two runs are the same computation (Fig 8a's 'impacts shorter than t_a are unchanged' compares exactly
    that)."""
    from ..laws.wet import WetRoughRoller

    if isinstance(wet, WetRoughRoller) and _same_law(wet.dry, dry):
        return WetRoughRoller(dry, wet.bridges, wet.record)
    return wet


def wet_dry_part(wet: ContactLaw) -> ContactLaw | None:
    """The dry law inside the averaged wet roller `wet` (what it runs before t_a and outside its bridges); None where
    `wet` is another law."""
    from ..laws.wet import WetRoughRoller

    return wet.dry if isinstance(wet, WetRoughRoller) else None


def _same_law(a: ContactLaw, b: ContactLaw) -> bool:
    return type(a) is type(b) and json.dumps(a.describe(), sort_keys=True, default=repr) == \
        json.dumps(b.describe(), sort_keys=True, default=repr)


def wet_roller_with_condensation_time(wet: ContactLaw, t_a: float) -> ContactLaw | None:
    """The averaged wet roller `wet` with its bridges' condensation time set to `t_a` (s): a copy sharing the dry
    law's tables (`continuum.laws.wet.WetRoughRoller`); None where `wet` is another law."""
    import copy

    from ..laws.wet import WetRoughRoller
    if not isinstance(wet, WetRoughRoller):
        return None
    bridges = copy.copy(wet.bridges)
    bridges.t_a = t_a
    bridges.reset()
    return type(wet)(wet.dry, bridges, dict(wet.record, condensation_time=t_a))


def wet_plastic_summit_law(plastic: ContactLaw, wet_scene: Scene, work_of_adhesion_wet: float):
    """The plastic summit law of the plastic discrete roller `plastic` rebuilt for `wet_scene` (the scene with the wet
    work of adhesion `work_of_adhesion_wet` = max(W_wet, 0), J/m^2): the same summit law, E*, tip radius, limiting
    contact pressure and range z0; Thornton-Ning without adhesion (Hertz to yield) where it is 0."""
    from ..rough.hertz_plastic import HertzPlasticSummitLaw
    from ..rough.plastic_summits import PlasticSummitLaw
    law = plastic.law
    if not work_of_adhesion_wet > 0.0:
        return HertzPlasticSummitLaw(law.radius, law.e_star, law.limiting_pressure)
    name = "jkr" if isinstance(law, PlasticSummitLaw) else law.name
    return plastic_summit_law(wet_scene, name, law.e_star, law.limiting_pressure)


def wet_plastic_summit_roller(plastic: ContactLaw, wet, elastic: ContactLaw, parameters: dict) -> ContactLaw:
    """A plastic discrete roller whose summits inside a bridge run `wet` (its plastic summit law at W_wet) and outside
    it their dry law, each summit carrying its deepest approach (`continuum.laws.wet_plastic_summits`); the bridges
    on the summits of the elastic discrete roller `elastic` whose realisation `plastic` runs on."""
    from ..laws.wet_plastic_summits import wet_plastic_summit_roller as build
    return build(plastic, wet, elastic, parameters)
