"""Choose the models a scene needs, have the factory build its contact law, and say why.

regime (`continuum.model.regime`, computed once) -> decisions (`decisions`) -> plan of the rough law (table
resolution, cost checks) -> law (`factory`) -> record (`record`, result.json -> models).
"""
from __future__ import annotations

from ..laws.base import ContactLaw
from ..reference import jkr as jkr_ref
from ..scene import Scene, SceneError
from . import factory
from . import record as rec
from .decisions import (
    SMOOTH_HALF_SPACE,
    adhesion_decision,
    half_space_decision,
    menisci_decision,
    plasticity_decision,
    summit_law,
)
from .estimates import check_table_cost
from .regime import Regime, first_impact_speed, regime_of, with_estimate

#: Below this sigma/delta_c the `fast` GW tables miss 1e-6 (measured, docs/rough-gw.md).
FAST_TABLE_MIN_SIGMA_OVER_DELTA_C = 3.0
#: GW tables estimated to take longer than this (s) are built only after the adhesive approach has been
#: checked against the averaged model's range (`adhesive_range_check`, < 1 s).
LARGE_TABLE_SECONDS = 2.0


def branch_summits(adhesion: str) -> bool:
    """Whether summits of law `adhesion` run on tabulated branches (`continuum.rough.branch_laws`): Maugis-Dugdale
    and DMT; JKR and Hertz summits have closed forms (GW tables, the discrete law's own)."""
    return adhesion in ("dmt", "maugis_dugdale")


def adhesive_range_check(scene: Scene, stats, z_max_sigma: float, speed: float, e_star: float) -> None:
    """Refuse (SceneError, continuum.laws.costs.beyond_range) if the first impact's adhesive JKR
    approach of summits of contact modulus `e_star` (Pa), integrated by quadrature over the footprint on a rigid
    substrate, would press the roller beyond the averaged model's range; return otherwise."""
    surface = factory.averaged_surface(stats, summit_law=summit_law("jkr", scene, e_star), z_max=z_max_sigma)
    law = factory.rigid_roller(surface, scene.body.radius, scene.body.length, resolution="fast")
    law.quasi_static_depth(0.5 * scene.body.mass * speed * speed, scene.body.mass * scene.environment.gravity)


def _mean_field_cost(scene: Scene, adhesion: str, half_space: bool, w: float, e_s: float, stats, datum: dict,
                     table: str, est, speed: float):
    """The mean-field rough law's table resolution, its summit law (branch summits) and the tables' cost (sized by
    the impact estimate `est`), checked before any table is built: a scene beyond the bounds is refused with a
    SceneError (`continuum.model.estimates.check_table_cost`). Returns (table, summit law or None, cost)."""
    rough, phys = scene.surfaces.roughness, scene.physics
    generic = branch_summits(adhesion)
    slaw = None
    if not generic and table == "fast" and w > 0 and rough.sigma < FAST_TABLE_MIN_SIGMA_OVER_DELTA_C * float(
            jkr_ref.critical_approach(rough.summit_radius, w, e_s)):
        table = "standard"      # fast tables miss 1e-6 when adhesion dominates (docs/rough-gw.md)
    if generic:
        slaw = summit_law(adhesion, scene, e_s)
        release_stretch, end_gap = max(-slaw.delta_out, 0.0), max(-slaw.delta_out, slaw.reach, 0.0)
    else:
        release_stretch = end_gap = (float(jkr_ref.critical_approach(rough.summit_radius, w, e_s)) *
                                     (1.0 if phys.detachment == "displacement"
                                      else -jkr_ref.LOAD_DETACH_APPROACH_RATIO) if w > 0 else 0.0)
    try:
        cost = check_table_cost(stats=stats, work_of_adhesion=w, summit_e_star=e_s, z_max_sigma=datum["z_max"],
                                detachment=phys.detachment, resolution=table, gw_tables=not generic,
                                rigid=not half_space, rigid_resolution=table,
                                release_stretch=release_stretch, end_gap=end_gap,
                                depth_estimate=est.depth if est else None, sigma_key_value=rough.sigma)
    except SceneError:
        # Refused for size. The Hertz estimate leaves adhesion out, and an adhesive approach can pull the
        # roller beyond the averaged model's range, where every way out of the size refusal would be refused
        # too: say so instead (the approach branch by quadrature, no tables; < 1 s).
        if w > 0 and not generic:
            adhesive_range_check(scene, stats, datum["z_max"], speed, e_s)
        raise
    if w > 0 and not generic and cost.get("gw_table", {}).get("estimated_seconds", 0.0) > LARGE_TABLE_SECONDS:
        # a large table (seconds, hundreds of MB) is worth building only if the impact stays in range
        adhesive_range_check(scene, stats, datum["z_max"], speed, e_s)
    return table, slaw, cost


def rough_law(scene: Scene, adhesion: str | None = None, half_space: bool | None = None,
              with_menisci: bool = False, regime: Regime | None = None,
              tables: bool = True) -> tuple[ContactLaw | None, dict]:
    """GW rough roller for `scene` and the record of its datum and regime numbers.

    `regime` is the scene's (`regime_of`; derived here, at the scene's first impact, where not given).
    `adhesion` (a law name) and `half_space` default to the scene's choices; where the scene says
    'auto' they are decided as `select_law` does, on the regime's first-impact estimate. Before any table is
    built the tables' size is estimated and a scene beyond the bounds is refused with a `SceneError`
    (`continuum.model.estimates.check_table_cost`). `tables` False (mean field, no menisci): only the record, for a
    law that replaces this one and needs no tables (plastic summits): nothing built or sized, the law is None.
    """
    from ..rough.datum import tallest_summit
    from ..rough.summits import SummitStatistics

    body, surf, phys = scene.body, scene.surfaces, scene.physics
    rough = surf.roughness
    if regime is None:
        regime = regime_of(scene)
    speed = regime.speed if regime.speed is not None else first_impact_speed(scene)
    if (adhesion is None and phys.adhesion_law == "auto") or (half_space is None and phys.half_space == "auto"):
        regime = with_estimate(regime, scene, speed)
    if adhesion is None:
        adhesion = adhesion_decision(scene, regime).law
    if half_space is None:
        half_space = half_space_decision(scene, regime).used
    if rough.mode != "discrete" and not half_space:
        regime = with_estimate(regime, scene, speed)         # sizes the rigid substrate's footprint tables
    est = regime.estimate
    w = surf.interface_work_of_adhesion if adhesion != "none" else 0.0
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    e_s = regime.e_star
    table = scene.numerics.table
    generic = branch_summits(adhesion)
    cost = slaw = None
    if rough.mode != "discrete" and not tables:
        if with_menisci:
            raise ValueError("rough_law: tables=False builds no law to put menisci on")
        slaw = summit_law(adhesion, scene, e_s) if generic else None
    elif rough.mode != "discrete":
        table, slaw, cost = _mean_field_cost(scene, adhesion, half_space, w, e_s, stats, datum, table, est, speed)
    surface = None
    if rough.mode == "discrete":
        # a seeded realisation of individual summits, same per-summit laws; no GW tables are built
        slaw = summit_law(adhesion, scene, e_s) if generic else None
        law = factory.discrete_roller(scene, stats, w, e_s, half_space, datum["footprint_half_width"], slaw)
        delta_c = law.delta_c
    elif not tables:
        # the summits' JKR separation approach, as the averaged surfaces define it (`GWBranchSurface.delta_c`)
        law, delta_c = None, float(jkr_ref.critical_approach(rough.summit_radius, w, e_s)) if w > 0 else 0.0
    else:
        surface = factory.averaged_surface(stats, summit_law=slaw, work_of_adhesion=w, summit_e_star=e_s,
                                           z_max=datum["z_max"], detachment=phys.detachment, resolution=table)
        delta_c = surface.delta_c
        # on a rigid substrate the footprint tables follow the GW tables' resolution: where adhesion dominates
        # (sigma/delta_c < 3) `fast` ones miss too (energy audit 1.1e-3 of the turnover at sigma/delta_c = 2.3),
        # so both are `standard`
        law = (factory.grid_roller(surface, scene) if half_space
               else factory.rigid_roller(surface, body.radius, body.length, resolution=table))
    record = rec.rough_law_record(
        scene, datum=datum, regime=rec.rough_regime_record(scene, regime, w, delta_c), surface=surface, cost=cost,
        table=table, fast_min_sigma_over_delta_c=FAST_TABLE_MIN_SIGMA_OVER_DELTA_C, law=law,
        summit_law_record=(slaw.describe() if slaw is not None else adhesion) if generic else None)
    if with_menisci and rough.mode == "discrete":
        law = discrete_menisci(scene, law, law, regime)             # a bridge on each summit of the realisation
    elif with_menisci:
        law = factory.with_menisci(law, scene, stats, dict(regime.meniscus_parameters()))
    return law, record


def _wet_solids_record(scene: Scene, plastic: bool, regime: Regime) -> dict:
    """How a smooth sphere's solids adhere inside its bridge (menisci.solid_adhesion): 'wet', at the work of
    adhesion under the liquid max(W_wet, 0) (continuum.wet.menisci.wet_work_of_adhesion, `Regime.meniscus`), their
    law rebuilt at it; 'additive', the dry law unchanged. The summits' DMT solid pull is not used: the sphere's own
    law carries it."""
    m = scene.menisci
    w_wet = max(regime.meniscus_parameters()["work_of_adhesion_wet"], 0.0)
    if m.solid_adhesion == "wet" and plastic:
        raise SceneError("menisci.solid_adhesion", "wet", "the wet solid adhesion rebuilds the sphere's law when "
                         "the bridge condenses, which would drop the Thornton-Ning flattening: set "
                         "menisci.solid_adhesion = 'additive' or physics.plasticity = 'off'", "scene")
    return {"solid_pull": 0.0,
            "solid_work_of_adhesion": w_wet if m.solid_adhesion == "wet" else regime.work_of_adhesion}


def _with_work_of_adhesion(scene: Scene, w: float) -> Scene:
    """`scene` with the contacting pair's work of adhesion `w` (J/m^2): the SAM's when both sides carry one."""
    from dataclasses import replace
    surf = scene.surfaces
    if surf.sam is not None:
        return replace(scene, surfaces=replace(surf, sam=replace(surf.sam, work_of_adhesion=w)))
    return replace(scene, surfaces=replace(surf, work_of_adhesion=w))


def plastic_member(member: Scene, law: ContactLaw, regime: Regime) -> ContactLaw:
    """An ensemble member's discrete roller `law` with Thornton-Ning summits where the scene's summits yield
    (`summit_plasticity`, decided as for the mean field, on the scene's `regime` that every member shares), else
    `law` itself."""
    surf = member.surfaces
    keys = (surf.body.yield_strength, surf.body.hardness, surf.substrate.yield_strength, surf.substrate.hardness)
    if member.contact != "rough" or member.physics.plasticity == "off" or all(k is None for k in keys):
        return law
    estimate = regime.estimate
    decision = plasticity_decision(member, regime, adhesion_decision(member, regime).law,
                                   half_space=half_space_decision(member, regime).used,
                                   depth=estimate.depth if estimate is not None else None)
    if not decision.used:
        return law
    return factory.plastic_discrete_roller(law, member, regime.e_star, decision.limiting_pressure,
                                           decision.summit_law)


def member_menisci(member: Scene, law: ContactLaw, elastic: ContactLaw, regime: Regime) -> ContactLaw:
    """An ensemble member's summit law `law` (elastic or plastic summits on the realisation of the elastic discrete
    roller `elastic`) with a capillary bridge growing on each summit where the member's humidity and contact angles
    let bridges pull (`menisci_decision` on the scene's `regime` not 'off'), else `law` itself.

    'auto' needs no dry run here: before t_a no bridge exists and the wet law is its dry law (compiled up to t_a,
    `continuum.laws.wet.WetRoughRoller.compiled`), so a member whose contacts all end sooner runs exactly dry."""
    if member.contact != "rough" or menisci_decision(member, regime).choice == "off":
        return law
    return discrete_menisci(member, law, elastic, regime)


def discrete_menisci(scene: Scene, law: ContactLaw, elastic, regime: Regime) -> ContactLaw:
    """`law` (summits on the realisation of the elastic `DiscreteRoughRoller` `elastic`) with a bridge on each summit,
    of the meniscus parameters of the scene's `regime`.

    menisci.solid_adhesion = 'wet' on a rigid substrate: the bridged summits adhere by their summit law rebuilt at
    the wet work of adhesion max(W_wet, 0), force and loop: elastic summits (`continuum.laws.wet_summits`; Hertz
    where W_wet <= 0) and Thornton-Ning plastic summits, each carrying its deepest approach across the class change
    (`continuum.laws.wet_plastic_summits`; Thornton-Ning without adhesion where W_wet <= 0). Otherwise (the additive
    choice, the half-space) the bridges carry the mean field's DMT solid pull and the summits keep their dry loop
    (`continuum.laws.discrete_bridges.wet_discrete`); the record says which."""
    params = dict(regime.meniscus_parameters())
    w_wet = max(params["work_of_adhesion_wet"], 0.0)
    if params["solid_adhesion"] != "wet" or elastic.use_half_space:
        why = ("menisci.solid_adhesion = 'additive'" if params["solid_adhesion"] != "wet" else
               "the half-space couples the summits")
        inside = f"dry summit law, DMT solid pull (loop dry: {why})"
        return factory.bridged_discrete_roller(law, elastic, {**params, "solids_inside_bridges": inside})
    wet_scene = _with_work_of_adhesion(scene, w_wet)
    if law is not elastic:                      # plastic summits
        wet = factory.wet_plastic_summit_law(law, wet_scene, w_wet)
        return factory.wet_plastic_summit_roller(law, wet, elastic, params)
    slaw = summit_law(elastic.slaw.name, wet_scene, regime.e_star) if elastic.slaw is not None and w_wet > 0 else None
    wet = factory.discrete_roller(wet_scene, elastic.stats, w_wet, elastic.summit_e_star, False,
                                  elastic.footprint_half_width, slaw, (elastic.sx, elastic.sy, elastic.sz))
    return factory.wet_summit_roller(elastic, wet, params)


def member_summit_law(member: Scene, law: ContactLaw, regime: Regime) -> ContactLaw:
    """An ensemble member's summits as every member runs them, whoever builds its realisation `law` (an elastic
    `DiscreteRoughRoller`): plastic where the scene's summits yield (`plastic_member`), with a bridge on each summit
    where the scene is humid (`member_menisci`); `regime`: the scene's, with its first-impact estimate, shared by
    every member (a realisation changes no number of it)."""
    return member_menisci(member, plastic_member(member, law, regime), law, regime)


def select_law(scene: Scene, first_impact_speed: float, menisci: bool | None = None,
               regime: Regime | None = None) -> tuple[ContactLaw, dict]:
    """The contact law for `scene` and a record of what runs, what is left out, and why.

    `regime` is the scene's, derived at `first_impact_speed` (m/s) (`regime_of`; derived here where not given).
    `menisci` overrides the meniscus decision (True/False); None decides it here, where 'auto'
    with a wet, hydrophilic scene is recorded as pending (`run_impact` settles it after a dry run).
    """
    if regime is None:
        regime = regime_of(scene, first_impact_speed)
    elif regime.speed != first_impact_speed:
        raise ValueError(f"select_law: the regime was derived at {regime.speed!r} m/s, the law asked for at "
                         f"{first_impact_speed!r} m/s")
    models: dict = {}
    m = menisci_decision(scene, regime)
    m_rec = m.record()
    if menisci is not None:
        m_rec = {**m_rec, "used": menisci}
    wet = menisci if menisci is not None else (m.choice == "on")
    adhesion = adhesion_decision(scene, regime)
    if scene.contact == "rough":
        estimate = regime.estimate
        hs = half_space_decision(scene, regime)
        plastic = plasticity_decision(scene, regime, adhesion.law, half_space=hs.used, menisci=wet,
                                      depth=estimate.depth if estimate is not None else None)
        discrete = scene.surfaces.roughness.mode == "discrete"
        # plastic summits in the mean field replace the elastic law, which is then neither built nor sized
        tables = not (plastic.used and not discrete and not wet)
        law, record = rough_law(scene, adhesion.law, hs.used, with_menisci=wet and not (plastic.used and discrete),
                                regime=regime, tables=tables)
        if plastic.used and discrete:
            elastic = law
            law = factory.plastic_discrete_roller(elastic, scene, regime.e_star, plastic.limiting_pressure,
                                                  plastic.summit_law)
            if wet:             # a bridge on each plastic summit, as on an ensemble member (`member_menisci`)
                law = discrete_menisci(scene, law, elastic, regime)
        elif plastic.used:
            law = factory.plastic_rigid_roller(scene, regime.e_star, plastic.limiting_pressure,
                                               record["datum"]["z_max"], plastic.summit_law)
            record["table"] = {"used": False, "why": "plastic summits: the mean field is summed state by state "
                               "(continuum.rough.plastic_summits), no footprint tables"}
        models["estimate"] = rec.estimate_record(estimate)
        models["contact_law"] = {**law.describe(), **record,
                                 "why": "contact = 'rough': GW summits on a grid under the roller"}
        models["adhesion"] = {"used": adhesion.used, **adhesion.record()}
        models["half_space"] = hs.record()
        models["plasticity"] = plastic.record()
        if wet:
            m_rec.update(regime.meniscus_parameters())
        models["menisci"] = m_rec
        models["sam"] = rec.sam_record(scene, regime)
        models["free_flight"] = rec.free_flight_record()
        return law, models
    plastic = plasticity_decision(scene, regime, adhesion.law)
    law, why = factory.smooth_law(scene, adhesion.law, first_impact_speed,
                                  plastic.limiting_pressure if plastic.used else None)
    if wet:
        params = {**regime.meniscus_parameters(), **_wet_solids_record(scene, plastic.used, regime)}
        wet_law = law
        if params["solid_adhesion"] == "wet":
            wet_scene = _with_work_of_adhesion(scene, params["solid_work_of_adhesion"])
            wet_law, _ = factory.smooth_law(wet_scene, adhesion.law if params["solid_work_of_adhesion"] > 0
                                            else "none", first_impact_speed)
        m_rec.update(params)
        law = factory.with_sphere_meniscus(law, wet_law, params)
        why += "; one capillary bridge at the contact (continuum.laws.sphere_meniscus)"
    a_rec = adhesion.record()
    if not adhesion.used and scene.surfaces.interface_work_of_adhesion > 0 and scene.physics.adhesion_law == "none":
        a_rec = {**a_rec, "why": "adhesion_law = 'none' (work_of_adhesion ignored)"}
    models["adhesion"] = {"used": adhesion.used, **a_rec}
    models["contact_law"] = {**law.describe(), "why": why}
    models["plasticity"] = plastic.record()
    models["menisci"] = m_rec
    models["half_space"] = SMOOTH_HALF_SPACE.record()
    models["sam"] = rec.sam_record(scene, regime)
    models["free_flight"] = rec.free_flight_record()
    return law, models
