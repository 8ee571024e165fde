"""The numbers that place a scene, derived once per run into one frozen `Regime`: summit modulus (coated summits
where the SAM has a layer modulus), Tabor and Fuller-Tabor parameters, plasticity index, the first impact's estimate,
the condensation time, the Kelvin radius against its cutoff, and the menisci's parameters.

`run_impact` (`continuum.dynamics.impact`) calls `regime_of` once and passes the `Regime` on: every decision
(`continuum.model.decisions`), the law's plan (`continuum.model.select`) and record (`continuum.model.record`) read
it instead of deriving again from the scene, so no number is computed twice with different guards. The functions
below `regime_of` are the derivations it is made of (pure functions of the scene).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Mapping

from ..physics import coated as coated_layer
from ..rough.datum import tallest_summit
from ..rough.summits import SummitStatistics
from ..scene import Scene
from ..wet import menisci as men
from . import factory, regimes
from .estimates import RoughImpactEstimate, rough_impact_estimate


@dataclass(frozen=True)
class Regime:
    """Where a scene sits, derived once from its surfaces, environment and (rough contact) first impact; SI.

    The mappings (`coated`, `meniscus`) are read-only records as result.json shows them; they are left out of the
    regime's equality and hash, which the scalar fields already fix for one scene."""

    rough: bool
    """contact = 'rough' (summits) or 'smooth' (the body itself)."""
    radius: float
    """Radius of the contacting asperity (m): the summits' tip radius, or the body's radius."""
    e_star: float
    """Contact modulus of that asperity (Pa): the summits' E* (coated where the SAM has a layer modulus), or the
    bodies'."""
    substrate_e_star: float
    """Contact modulus of the bare summits (Pa): surfaces.roughness.summit_modulus, else the bodies' E*."""
    work_of_adhesion: float
    """Interface work of adhesion (J/m^2): SAM-SAM where both faces are covered."""
    interaction_range: float
    """Range z0 (m) of the surface interaction, for the Tabor parameter."""
    tabor_parameter: float | None
    """Tabor's mu of the asperity; None without adhesion."""
    fuller_tabor_theta: float | None
    """Fuller-Tabor theta of the summits; None for smooth contact or without adhesion."""
    plasticity_index: float | None
    """GW plasticity index of the summits; None for smooth contact or without surfaces.hardness."""
    speed: float | None
    """Speed at the first touch (m/s) the regime was derived for; None for a regime without an impact."""
    estimate: RoughImpactEstimate | None
    """The first impact's Hertz estimate at `speed` (rough contact), or None where none was asked for."""
    condensation_time: float
    """Time t_a (s) a bridge needs to condense (infinite in dry air)."""
    condensation_time_source: str
    kelvin_radius: float | None
    """Kelvin radius r_K (m) at the scene's humidity; None outside 0 < RH < 1."""
    min_kelvin_radius: float
    """Smallest r_K a smooth sphere's bridge is given (m)."""
    min_kelvin_radius_source: str
    solid_liquid_works: tuple[float | None, float | None]
    """Measured solid-water works of adhesion W_SL (J/m^2) of the two faces, None where not given."""
    coated: Mapping[str, Any] | None = field(default=None, compare=False)
    """The coated summits' record (`coated_summits`), None without a SAM layer modulus or for smooth contact."""
    meniscus: Mapping[str, Any] | None = field(default=None, compare=False)
    """The menisci's parameters (`meniscus_record`): Kelvin gap, bridge pull, t_a, growth length, ...; None where
    no Kelvin radius exists (RH outside (0, 1)) or a face has no water contact angle; `meniscus_parameters` refuses
    that case."""

    def __reduce__(self):
        """Pickled (an ensemble's members carry the regime to other processes) with its read-only mappings as
        dicts, made read-only again on arrival."""
        state = dict(vars(self))
        state.update({k: None if state[k] is None else dict(state[k]) for k in ("coated", "meniscus")})
        return _regime_from_state, (state,)

    def meniscus_parameters(self) -> Mapping[str, Any]:
        """The menisci's parameters; ValueError where no Kelvin radius exists (RH outside (0, 1))."""
        if self.meniscus is None:
            raise ValueError("menisci need 0 < relative_humidity < 1 (a finite Kelvin radius) and both faces' water "
                             "contact angles")
        return self.meniscus


def _regime_from_state(state: dict) -> Regime:
    """The `Regime` of a pickled `state` (`Regime.__reduce__`)."""
    return Regime(**{**state, **{k: None if state[k] is None else MappingProxyType(state[k])
                                 for k in ("coated", "meniscus")}})


def substrate_e_star(scene: Scene) -> float:
    """Contact modulus of the bare summits (Pa): surfaces.roughness.summit_modulus, else (and for smooth contact)
    the bodies' E*."""
    rough = scene.surfaces.roughness
    return rough.summit_modulus if rough is not None and rough.summit_modulus is not None else scene.surfaces.e_star


def coated_summits(scene: Scene) -> dict | None:
    """The SAM as a compliant layer on every summit (continuum.physics.coated), or None without a layer modulus.

    Both surfaces carry a layer of surfaces.sam.thickness. The substrates' plane-strain moduli are the bodies'
    E/(1 - nu^2), or 2 x surfaces.roughness.summit_modulus on each side where that is given. Returns the coated
    E* (Pa), the reference contact radius (m) it is evaluated at, and the inputs."""
    sam, surf = scene.surfaces.sam, scene.surfaces
    if sam is None or sam.layer_modulus is None or scene.contact != "rough":
        return None
    rough = surf.roughness
    e_f = coated_layer.plane_strain_modulus(sam.layer_modulus, sam.layer_poisson_ratio)
    if rough.summit_modulus is not None:
        e_1 = e_2 = 2.0 * rough.summit_modulus
    else:
        e_1 = coated_layer.plane_strain_modulus(surf.body.youngs_modulus, surf.body.poisson_ratio)
        e_2 = coated_layer.plane_strain_modulus(surf.substrate.youngs_modulus, surf.substrate.poisson_ratio)
    e_star, a_ref = coated_layer.coated_summit_modulus(rough.summit_radius, surf.interface_work_of_adhesion,
                                                       rough.sigma, sam.thickness, e_f, e_1, e_2)
    return {"e_star": e_star, "reference_radius": a_ref, "reference_radius_over_thickness": a_ref / sam.thickness,
            "substrate_e_star": substrate_e_star(scene), "layer_plane_strain_modulus": e_f,
            "thickness_each_side": sam.thickness,
            "reference": "JKR zero-load radius" if surf.interface_work_of_adhesion > 0 else "sqrt(beta sigma)",
            "model": "Perriot & Barthel (2004) equivalent modulus of each coated summit, compliances in series, "
                     "frozen at the reference radius (continuum.physics.coated)"}


def summit_e_star(scene: Scene) -> float:
    """Contact modulus of the summits (Pa): the coated summits' E* where the SAM has a layer modulus, else
    surfaces.roughness.summit_modulus, else the bodies' E*."""
    coated = coated_summits(scene)
    return coated["e_star"] if coated is not None else substrate_e_star(scene)


def first_impact_speed(scene: Scene) -> float:
    """Speed (m/s) at the first touch: sqrt(2 g h0) for a release height, else the given velocity."""
    if scene.release_height is not None:
        return math.sqrt(2.0 * scene.environment.gravity * scene.release_height)
    return scene.impact_velocity


def impact_estimate(scene: Scene, speed: float, e_star: float) -> RoughImpactEstimate:
    """Quasi-static first approach of Hertz summits of contact modulus `e_star` (Pa) on a rigid substrate absorbing
    an impact at `speed` (m/s) (`continuum.model.estimates`): depth, contacts, peak force and the half-space's
    deflection span."""
    body, rough = scene.body, scene.surfaces.roughness
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    start = time.perf_counter()
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    surface = factory.averaged_surface(stats, work_of_adhesion=0.0, summit_e_star=e_star, z_max=datum["z_max"],
                                       resolution="fast")
    law = factory.rigid_roller(surface, body.radius, body.length, resolution="fast")
    # beyond the averaged model's range the depth search refuses the scene (SceneError, continuum.laws.costs)
    estimate = rough_impact_estimate(surface, law, scene.surfaces.e_star, body.radius, body.length, body.mass, speed,
                                     scene.environment.gravity)
    return replace(estimate, seconds=time.perf_counter() - start)      # the tables' build included


def regime_of(scene: Scene, speed: float | None = None) -> Regime:
    """The scene's regime, derived once; for rough contact with the first impact's estimate at `speed` (m/s; None:
    no estimate). `with_estimate` adds one to a regime derived without."""
    surf = scene.surfaces
    rough = scene.contact == "rough"
    w, z0 = surf.interface_work_of_adhesion, surf.interface_interaction_range
    coated = coated_summits(scene)
    e_sub = substrate_e_star(scene)
    if rough:
        beta, e_s = surf.roughness.summit_radius, coated["e_star"] if coated is not None else e_sub
    else:
        beta, e_s = scene.body.radius, surf.e_star
    estimate = impact_estimate(scene, speed, e_s) if rough and speed is not None else None
    adhesive = w > 0
    t_a, t_src = condensation_time(scene)
    r_k, cutoff, cutoff_src = kelvin_radius_cutoff(scene)
    w_sl = solid_liquid_works(scene)
    # a bridge needs a Kelvin radius (0 < RH < 1) and both faces' water contact angles (required where menisci run)
    meniscus = (None if r_k is None or None in surf.contact_angles else
                MappingProxyType(meniscus_record(scene, r_k, t_a, t_src, cutoff, cutoff_src, w_sl)))
    return Regime(
        rough=rough, radius=beta, e_star=e_s, substrate_e_star=e_sub, work_of_adhesion=w, interaction_range=z0,
        tabor_parameter=regimes.tabor_parameter(beta, w, e_s, z0) if adhesive else None,
        fuller_tabor_theta=regimes.fuller_tabor_theta(surf.roughness.sigma, beta, w, e_s) if rough and adhesive
        else None,
        plasticity_index=regimes.plasticity_index(e_s, surf.hardness, surf.roughness.sigma, beta)
        if rough and surf.hardness is not None else None,
        speed=speed, estimate=estimate, condensation_time=t_a, condensation_time_source=t_src, kelvin_radius=r_k,
        min_kelvin_radius=cutoff, min_kelvin_radius_source=cutoff_src, solid_liquid_works=w_sl,
        coated=None if coated is None else MappingProxyType(coated), meniscus=meniscus)


def with_estimate(regime: Regime, scene: Scene, speed: float) -> Regime:
    """`regime` (of rough `scene`) with the first impact's estimate at `speed` (m/s), derived here if it has none
    at that speed."""
    if regime.estimate is not None and regime.speed == speed:
        return regime
    return replace(regime, speed=speed, estimate=impact_estimate(scene, speed, regime.e_star))


def condensation_time(scene: Scene) -> tuple[float, str]:
    """(t_a s, its source): the time a bridge needs to condense.

    Nucleation (Szoszkiewicz & Riedo 2005): infinite without vapour (RH = 0: ln(1/RH) diverges); at saturation
    the barrier, proportional to ln(1/RH), vanishes and t_a is the attempt time. Else menisci.condensation_time."""
    m, env = scene.menisci, scene.environment
    if m.condensation_model != "nucleation":
        return m.condensation_time, "menisci.condensation_time"
    rh = env.relative_humidity
    t_a = men.nucleation_condensation_time(rh, env.temperature) if rh > 0.0 else math.inf
    return t_a, "nucleation (Szoszkiewicz & Riedo 2005)"


def condensation_time_range(scene: Scene, regime: Regime | None = None) -> dict:
    """The scene's t_a (s: its `regime`'s where a run derived one, else `condensation_time`) and the range the
    nucleation estimate allows at the scene's humidity and temperature (`continuum.wet.menisci.nucleation_time_range`:
    the attempt frequency anywhere in Szoszkiewicz & Riedo's 4-250 GHz), with the inputs it rests on; SI. A 'fixed'
    t_a is a declared choice: the range is reported beside it, so a reader sees where the declared value sits."""
    env = scene.environment
    t_a, source = (condensation_time(scene) if regime is None else
                   (regime.condensation_time, regime.condensation_time_source))
    rh, temp = env.relative_humidity, env.temperature
    lo, hi = men.nucleation_time_range(rh, temp)
    return {"condensation_time_s": t_a, "source": source, "nucleation_s": men.nucleation_condensation_time(rh, temp),
            "range_s": [lo, hi], "relative_humidity": rh, "temperature_K": temp,
            "range_from": "attempt frequency 4-250 GHz (Szoszkiewicz & Riedo, PRL 95 (2005) 135502) with the barrier "
                          "7.8e-20 J ln(1/RH)/ln(1/0.4) at the scene's humidity and temperature"}


def kelvin_radius_cutoff(scene: Scene) -> tuple[float | None, float, str]:
    """(r_K m, the smallest r_K a smooth sphere's bridge is given m, its source) at the scene's humidity; r_K is None
    outside 0 < RH < 1, where no Kelvin radius exists."""
    env, m = scene.environment, scene.menisci
    rh = env.relative_humidity
    r_k = men.kelvin_radius(rh, env.temperature, m.surface_tension, m.molar_volume) if 0.0 < rh < 1.0 else None
    if m.min_kelvin_radius is not None:
        return r_k, m.min_kelvin_radius, "menisci.min_kelvin_radius"
    return r_k, men.WATER_MOLECULE_DIAMETER, "one water molecule, n_w^(-1/3)"


def solid_liquid_works(scene: Scene) -> tuple[float | None, float | None]:
    """Measured solid-water works of adhesion W_SL (J/m^2) of the two contacting faces (the SAM's on both when
    covered), None where not given (then `continuum.wet.menisci.solid_liquid_work` takes gamma_lv (1 + cos theta))."""
    surf = scene.surfaces
    if surf.sam is not None:
        return surf.sam.work_of_adhesion_sl, surf.sam.work_of_adhesion_sl
    return surf.body.work_of_adhesion_sl, surf.substrate.work_of_adhesion_sl


def meniscus_record(scene: Scene, r_k: float, t_a: float, t_src: str, cutoff: float, cutoff_src: str,
                    w_sl: tuple[float | None, float | None]) -> dict:
    """Kelvin radius `r_k` (m) and gap, bridge pull, t_a (`t_a` s, from `t_src`) and growth length for the scene
    (SI), with their sources: at the summits (radius beta) of rough contact, or at a smooth sphere's contact (its
    radius R, with the smallest Kelvin radius `cutoff` m from `cutoff_src`); `w_sl`: `solid_liquid_works`."""
    surf, env, m = scene.surfaces, scene.environment, scene.menisci
    t1, t2 = surf.contact_angles
    rh = env.relative_humidity
    d_k = men.kelvin_gap(r_k, t1, t2)
    smooth = scene.contact == "smooth"
    beta = scene.body.radius if smooth else surf.roughness.summit_radius
    h1 = m.growth_length if m.growth_length is not None else men.default_growth_length(rh)
    w = surf.interface_work_of_adhesion
    out = {"kelvin_radius": r_k, "kelvin_gap": d_k, "kelvin_gap_over_summit_radius": d_k / beta,
           "bridge_pull_off": men.bridge_pull_off(beta, m.surface_tension, t1, t2),
           "solid_adhesion": m.solid_adhesion,
           "work_of_adhesion_wet": men.wet_work_of_adhesion(w, m.surface_tension, t1, t2, w_sl),
           "work_of_adhesion_wet_source": ("dgamma + 2 gamma_lv - W_1L - W_2L with the measured W_SL "
                                           f"{[x for x in w_sl if x is not None]} J/m^2 (Dupre in the liquid)"
                                           if any(x is not None for x in w_sl)
                                           else "dgamma - gamma_lv (cos t1 + cos t2) (Dupre in the liquid, Young)"),
           "solid_pull": men.solid_pull_inside_bridge(beta, w, m.surface_tension, t1, t2, m.solid_adhesion, w_sl),
           "condensation_time": t_a, "condensation_time_source": t_src, "growth_length": h1,
           "growth_length_source": "menisci.growth_length" if m.growth_length is not None
           else "1/(n_w^(1/3) ln(1/RH)) (one molecule's cross-section)",
           "surface_tension": m.surface_tension, "force_law": "constant Kelvin radius, F0 (1 - g/D_K), "
           "rupture at D_K (docs/model.md, Menisci)", "bridges_see": "rigid geometry (half-space deflection left "
           "out of the bridges' gaps)"}
    if smooth:
        out.pop("kelvin_gap_over_summit_radius")
        out.update({"bridge_radius": beta, "kelvin_radius_over_radius": r_k / beta, "min_kelvin_radius": cutoff,
                    "min_kelvin_radius_source": cutoff_src, "bridges_see": "the sphere's rigid approach (one bridge "
                    "at its contact, continuum.laws.sphere_meniscus)"})
    return out


def meniscus_parameters(scene: Scene) -> dict:
    """The menisci's parameters of `scene` (`Regime.meniscus`, `meniscus_record`) for a reader outside a run;
    ValueError where no Kelvin radius exists (RH outside (0, 1))."""
    return dict(regime_of(scene).meniscus_parameters())
