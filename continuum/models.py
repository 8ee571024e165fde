"""Choose the models a scene needs, build its contact law, and say why (result.json -> models).

"Model only what a scene requires." Every physics entry (`physics.adhesion_law`,
`physics.half_space`, `physics.menisci`) defaults to `auto`, decided here per scene from numbers
recorded beside the choice; a scene can force any choice.

Summit law (rough contact). Tabor's parameter of the summits, mu = (beta dgamma^2/(E*^2 z0^3))^{1/3},
places them on Johnson & Greenwood's adhesion map (J. Colloid Interface Sci. 192 (1997) 326):
mu > 5 JKR, mu < 0.1 DMT, Maugis-Dugdale between. Adhesion is then left out only if it cannot
change a rebound: the estimated loss per impact (summits in contact at the quasi-static depth x
one summit's hysteresis loop) is below 1e-3 of the impact energy AND the summits' pull-off forces
add up to less than 1e-2 of the estimated peak force. The Fuller-Tabor parameter theta is
recorded but does not decide alone: the `paper` set has theta = 87 ("negligible" by Fuller &
Tabor's nominally flat criterion) yet loses 28 % per impact, because only ~3 summits touch and
each loop is a sizeable part of a 6e-16 J impact.

Half-space. Left out when the estimated deflection span across the footprint is below 1e-3 sigma
(`continuum.estimates`): the summits' gaps then move by less than a thousandth of their spread.

Menisci. Left out when the air is dry (RH = 0), when the faces are hydrophobic (cos t1 + cos t2
<= 0: no bridge pulls), for smooth contact and discrete summits (not modelled), and otherwise
decided after a dry run (`continuum.impact.run_impact`): bridges cannot form before t_a, so if no
contact of the dry run lasts t_a, the wet run is identical and the dry one is kept.
"""
from __future__ import annotations

import math

from . import menisci as men
from . import regimes
from .estimates import check_table_cost, rough_impact_estimate
from .laws.base import ContactLaw
from .laws.hertz import HertzLine, HertzSphere, LinearSpring, roller_constant_stiffness
from .laws.jkr import JKRSphere
from .reference import jkr as jkr_ref
from .scene import Scene, SceneError

#: Below this sigma/delta_c the `fast` GW tables miss 1e-6 (measured, docs/rough-gw.md).
FAST_TABLE_MIN_SIGMA_OVER_DELTA_C = 3.0
#: GW tables estimated to take longer than this (s) are built only after the adhesive approach has been
#: checked against the averaged model's range (`_adhesive_range_check`, < 1 s).
LARGE_TABLE_SECONDS = 2.0
#: Johnson & Greenwood (1997) adhesion map, Tabor parameter bounds of the JKR and DMT regimes.
TABOR_JKR, TABOR_DMT = 5.0, 0.1
#: Adhesion is negligible below these estimated fractions: loss per impact / impact energy, and
#: summed pull-off / peak force.
NEGLIGIBLE_LOSS, NEGLIGIBLE_PULL = 1e-3, 1e-2
#: The half-space is negligible when its deflection span across the footprint is below this * sigma.
NEGLIGIBLE_DEFLECTION = 1e-3
LAW_NAMES = {"jkr": "JKR with Fuller-Tabor hysteresis", "dmt": "DMT (no hysteresis)",
             "maugis_dugdale": "Maugis-Dugdale (jump-in and jump-out from its own solution)",
             "none": "Hertz (no adhesion)"}


# ----------------------------------------------------------------------------- summit laws
def summit_e_star(scene: Scene) -> float:
    """Contact modulus of the summits (Pa): surfaces.roughness.summit_modulus, else the bodies' E*."""
    rough = scene.surfaces.roughness
    return rough.summit_modulus if rough.summit_modulus is not None else scene.surfaces.e_star


def sam_layer(scene: Scene) -> tuple[float, float, float] | None:
    """(total thickness m, Young's modulus Pa, Poisson's ratio) of the SAM layers in series, or None.

    Both surfaces carry a layer of surfaces.sam.thickness, so a summit contact compresses two.
    """
    sam = scene.surfaces.sam
    if sam is None or sam.layer_modulus is None:
        return None
    return 2.0 * sam.thickness, sam.layer_modulus, sam.layer_poisson_ratio


def summit_law(name: str, scene: Scene):
    """The per-summit law (continuum.rough.branch_laws) for a law name and the scene's surfaces.

    Tabulated to a compression of 30 sigma (the rough model refuses impacts deeper than 10 sigma
    below the mean plane; the tallest summit is < 6 sigma above it)."""
    from .rough.branch_laws import make_summit_law

    surf = scene.surfaces
    beta, w, e_s = surf.roughness.summit_radius, surf.interface_work_of_adhesion, summit_e_star(scene)
    return make_summit_law(name, beta, w, e_s, z0=surf.interface_interaction_range, layer=sam_layer(scene),
                           detachment=scene.physics.detachment, delta_max=30.0 * surf.roughness.sigma)


def loop_per_summit(name: str, scene: Scene) -> float:
    """Energy (J) one summit loses per approach-retreat cycle under `name`."""
    if name == "none":
        return 0.0
    if name == "jkr" and sam_layer(scene) is None:
        surf = scene.surfaces
        return float(jkr_ref.loop_area(surf.roughness.summit_radius, surf.interface_work_of_adhesion,
                                       summit_e_star(scene), detachment=scene.physics.detachment))
    return float(summit_law(name, scene).loop_energy)


def decide_adhesion(scene: Scene, estimate=None) -> tuple[str, dict]:
    """Summit (or sphere) adhesion law for `scene` and the record of why."""
    surf, phys = scene.surfaces, scene.physics
    w = surf.interface_work_of_adhesion
    source = "SAM-SAM" if surf.sam is not None else "surfaces.work_of_adhesion"
    rec = {"work_of_adhesion": w, "source": source, "interaction_range_z0": surf.interface_interaction_range}
    if scene.contact == "rough":
        beta, e_s = surf.roughness.summit_radius, summit_e_star(scene)
    else:
        beta, e_s = scene.body.radius, surf.e_star
    if w > 0:
        mu = regimes.tabor_parameter(beta, w, e_s, surf.interface_interaction_range)
        rec["tabor_parameter"] = mu
        if scene.contact == "rough":
            rec["fuller_tabor_theta"] = regimes.fuller_tabor_theta(surf.roughness.sigma, beta, w, e_s)
    if phys.adhesion_law != "auto":
        return phys.adhesion_law, {**rec, "law": phys.adhesion_law, "decided_by": "scene",
                                   "why": f"physics.adhesion_law = '{phys.adhesion_law}' set in the scene"}
    if w <= 0.0:
        return "none", {**rec, "law": "none", "decided_by": "work_of_adhesion",
                        "why": "auto: no work of adhesion, Hertz contact"}
    if scene.contact == "smooth":
        if scene.body.shape == "cylinder":
            return "none", {**rec, "law": "none", "decided_by": "geometry",
                            "why": "auto: a smooth roller has no adhesive line-contact law here (2-D JKR is not "
                                   "implemented); adhesion is left out and the result says so"}
        return "jkr", {**rec, "law": "jkr", "decided_by": "geometry",
                       "why": f"auto: smooth sphere, JKR (the only adhesive sphere law; Tabor mu = {mu:.3g})"}
    law = "jkr" if mu > TABOR_JKR else "dmt" if mu < TABOR_DMT else "maugis_dugdale"
    rec["tabor_bounds"] = {"jkr_above": TABOR_JKR, "dmt_below": TABOR_DMT, "source": "Johnson & Greenwood 1997"}
    loop = loop_per_summit(law, scene)
    n_pull = _pull_off_per_summit(law, scene)
    if estimate is not None:
        loss = estimate.contacts * loop / estimate.impact_energy
        pull = estimate.contacts * n_pull / estimate.peak_force if estimate.peak_force > 0 else math.inf
        rec.update({"estimated_loss_fraction": loss, "estimated_pull_fraction": pull,
                    "loop_energy_per_summit": loop, "negligible_below": {"loss": NEGLIGIBLE_LOSS,
                                                                         "pull": NEGLIGIBLE_PULL}})
        if loss < NEGLIGIBLE_LOSS and pull < NEGLIGIBLE_PULL:
            return "none", {**rec, "law": "none", "decided_by": "estimated_loss_fraction",
                            "why": f"auto: {LAW_NAMES[law]} summits (Tabor mu = {mu:.3g}) would lose {loss:.2g} of "
                                   f"the impact energy per impact and pull {pull:.2g} of the peak force: negligible, "
                                   "adhesion left out"}
    return law, {**rec, "law": law, "decided_by": "tabor_parameter",
                 "why": f"auto: Tabor mu = {mu:.3g} of the summits -> {LAW_NAMES[law]}"}


def _pull_off_per_summit(name: str, scene: Scene) -> float:
    surf = scene.surfaces
    beta, w = surf.roughness.summit_radius, surf.interface_work_of_adhesion
    if name == "jkr" and sam_layer(scene) is None:
        return float(jkr_ref.pull_off_force(beta, w))
    if name == "dmt" and sam_layer(scene) is None:
        return 2.0 * math.pi * beta * w
    return float(summit_law(name, scene).pull_off_force)


def decide_half_space(scene: Scene, estimate) -> tuple[bool, dict]:
    """Whether the rough contact couples its summits to the elastic half-space, and why."""
    choice = scene.physics.half_space
    sigma = scene.surfaces.roughness.sigma
    rec = {"estimated_deflection_span": estimate.deflection_span if estimate else None,
           "deflection_over_sigma": estimate.deflection_span / sigma if estimate else None,
           "negligible_below": NEGLIGIBLE_DEFLECTION}
    if choice != "auto":
        return choice == "on", {**rec, "used": choice == "on", "decided_by": "scene",
                                "why": f"physics.half_space = '{choice}' set in the scene"}
    ratio = estimate.deflection_span / sigma
    used = ratio >= NEGLIGIBLE_DEFLECTION
    why = (f"auto: estimated deflection across the footprint {estimate.deflection_span:.3g} m = {ratio:.3g} sigma "
           + (">= " if used else "< ") + f"{NEGLIGIBLE_DEFLECTION:g} sigma: "
           + ("coupled (FFT influence coefficients)" if used else "left out, rigid substrate"))
    return used, {**rec, "used": used, "decided_by": "deflection_over_sigma", "why": why}


def decide_menisci(scene: Scene) -> tuple[str, dict]:
    """'off', 'on' or 'after_dry_run', with the record of why."""
    choice, surf, env = scene.physics.menisci, scene.surfaces, scene.environment
    rec: dict = {"relative_humidity": env.relative_humidity}
    if choice == "off":
        return "off", {**rec, "used": False, "decided_by": "scene", "why": "physics.menisci = 'off' set in the scene"}
    if scene.contact != "rough" or surf.roughness.mode != "averaged":
        return "off", {**rec, "used": False, "decided_by": "geometry",
                       "why": "menisci are modelled for averaged rough contact only"}
    if env.relative_humidity <= 0.0:
        return "off", {**rec, "used": False, "decided_by": "relative_humidity",
                       "why": "dry: environment.relative_humidity = 0"}
    t1, t2 = surf.contact_angles
    wet = men.wetting_sum(t1, t2)
    rec["cos_theta1_plus_cos_theta2"] = wet
    rec["contact_angles_deg"] = [math.degrees(t1), math.degrees(t2)]
    if wet <= 0.0:
        return "off", {**rec, "used": False, "decided_by": "contact_angles",
                       "why": f"hydrophobic: cos t1 + cos t2 = {wet:.3g} <= 0, no bridge pulls"}
    if choice == "on":
        return "on", {**rec, "used": True, "decided_by": "scene", "why": "physics.menisci = 'on' set in the scene"}
    return "after_dry_run", {**rec, "decided_by": "longest_contact_time",
                             "why": "auto: decided after a dry run (bridges cannot form before t_a)"}


def meniscus_parameters(scene: Scene) -> dict:
    """Kelvin radius and gap, bridge pull, t_a and growth length for the scene (SI), with their sources."""
    surf, env, m = scene.surfaces, scene.environment, scene.menisci
    t1, t2 = surf.contact_angles
    rh, temp = env.relative_humidity, env.temperature
    r_k = men.kelvin_radius(rh, temp, m.surface_tension, m.molar_volume)
    d_k = men.kelvin_gap(r_k, t1, t2)
    beta = surf.roughness.summit_radius
    if m.condensation_model == "nucleation":
        t_a, t_src = men.nucleation_condensation_time(rh, temp), "nucleation (Szoszkiewicz & Riedo 2005)"
    else:
        t_a, t_src = m.condensation_time, "menisci.condensation_time"
    h1 = m.growth_length if m.growth_length is not None else men.default_growth_length(rh)
    return {"kelvin_radius": r_k, "kelvin_gap": d_k, "kelvin_gap_over_summit_radius": d_k / beta,
            "bridge_pull_off": men.bridge_pull_off(beta, m.surface_tension, t1, t2),
            "condensation_time": t_a, "condensation_time_source": t_src, "growth_length": h1,
            "growth_length_source": "menisci.growth_length" if m.growth_length is not None
            else "1/(n_w^(1/3) ln(1/RH)) (one molecule's cross-section)",
            "surface_tension": m.surface_tension, "force_law": "constant Kelvin radius, F0 (1 - g/D_K), "
            "rupture at D_K (docs/model.md, Menisci)", "bridges_see": "rigid geometry (half-space deflection left "
            "out of the bridges' gaps)"}


# ----------------------------------------------------------------------------- rough laws
def _estimate(scene: Scene, speed: float):
    from .rough.datum import tallest_summit
    from .rough.gw import SummitStatistics

    body, rough = scene.body, scene.surfaces.roughness
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    # beyond the averaged model's range the depth search refuses the scene (SceneError, continuum.laws.rough_roller)
    return rough_impact_estimate(SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius),
                                 summit_e_star(scene), scene.surfaces.e_star, body.radius, body.length,
                                 datum["z_max"], body.mass, speed, scene.environment.gravity)


def _adhesive_range_check(scene: Scene, stats, z_max_sigma: float, speed: float) -> None:
    """Refuse (SceneError, continuum.laws.rough_roller.beyond_range) if the first impact's adhesive JKR
    approach, integrated by quadrature over the footprint on a rigid substrate, would press the roller
    beyond the averaged model's range; return otherwise."""
    from .laws.rough_rigid import RigidRoughRoller
    from .rough.gw_branches import GWBranchSurface

    surface = GWBranchSurface(stats, summit_law("jkr", scene), z_max=z_max_sigma)
    law = RigidRoughRoller(surface, scene.body.radius, scene.body.length, resolution="fast")
    law.quasi_static_depth(0.5 * scene.body.mass * speed * speed, scene.body.mass * scene.environment.gravity)


def rough_law(scene: Scene, adhesion: str | None = None, half_space: bool | None = None,
              with_menisci: bool = False, speed: float | None = None, estimate=None) -> tuple[ContactLaw, dict]:
    """GW rough roller for `scene` and the record of its datum and regime numbers.

    `adhesion` (a law name) and `half_space` default to the scene's choices; where the scene says
    'auto' they are decided as `select_law` does (with the estimate at `speed`, m/s, if given, else
    at the scene's first impact). Before any table is built the tables' size is estimated and a
    scene beyond the bounds is refused with a `SceneError` (`continuum.estimates.check_table_cost`).
    """
    from .laws.rough_roller import RoughRoller
    from .rough.datum import tallest_summit
    from .rough.gw import GWJKRSurface, SummitStatistics

    body, surf, phys = scene.body, scene.surfaces, scene.physics
    rough = surf.roughness
    if speed is None:
        speed = (math.sqrt(2.0 * scene.environment.gravity * scene.release_height)
                 if scene.release_height is not None else scene.impact_velocity)
    est = estimate
    if adhesion is None or half_space is None:
        if est is None and "auto" in (phys.adhesion_law, phys.half_space):
            est = _estimate(scene, speed)
        if adhesion is None:
            adhesion = decide_adhesion(scene, est)[0]
        if half_space is None:
            half_space = decide_half_space(scene, est)[0]
    w = surf.interface_work_of_adhesion if adhesion != "none" else 0.0
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    e_s = summit_e_star(scene)
    table = scene.numerics.table
    generic = adhesion in ("dmt", "maugis_dugdale") or sam_layer(scene) is not None
    cost = None
    if rough.mode != "discrete":
        if not generic and table == "fast" and w > 0 and rough.sigma < FAST_TABLE_MIN_SIGMA_OVER_DELTA_C * float(
                jkr_ref.critical_approach(rough.summit_radius, w, e_s)):
            table = "standard"      # fast tables miss 1e-6 when adhesion dominates (docs/rough-gw.md)
        if not half_space and est is None:
            est = _estimate(scene, speed)
        if generic:
            slaw = summit_law(adhesion, scene)
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
                _adhesive_range_check(scene, stats, datum["z_max"], speed)
            raise
        if w > 0 and not generic and cost.get("gw_table", {}).get("estimated_seconds", 0.0) > LARGE_TABLE_SECONDS:
            # a large table (seconds, hundreds of MB) is worth building only if the impact stays in range
            _adhesive_range_check(scene, stats, datum["z_max"], speed)
    if rough.mode == "discrete":
        # a seeded realisation of individual summits, same per-summit laws; no GW tables are built
        from .laws.discrete_roller import DiscreteRoughRoller
        law = DiscreteRoughRoller(stats, w, e_s, body.radius, body.length, surf.e_star, seed=rough.seed,
                                  detachment=phys.detachment, half_space=half_space,
                                  grid_points=scene.numerics.grid_points,
                                  footprint_half_width=datum["footprint_half_width"])
        surface = law                                   # carries delta_c for the regime numbers
    else:
        if generic:
            from .rough.gw_branches import GWBranchSurface
            surface = GWBranchSurface(stats, slaw, z_max=datum["z_max"], resolution=table)
        else:
            surface = GWJKRSurface(stats, w, e_s, z_max=datum["z_max"], detachment=phys.detachment,
                                   resolution=table)
        if half_space:
            law = RoughRoller(surface, body.radius, body.length, surf.e_star, half_space=True,
                              grid_points=scene.numerics.grid_points)
        else:
            from .laws.rough_rigid import RigidRoughRoller
            # the footprint tables follow the GW tables' resolution: where adhesion dominates (sigma/delta_c < 3)
            # `fast` ones miss too (energy audit 1.1e-3 of the turnover at sigma/delta_c = 2.3), so both are `standard`
            law = RigidRoughRoller(surface, body.radius, body.length, resolution=table)
    regime = {
        "summit_e_star": e_s,
        "sigma_over_delta_c": rough.sigma / surface.delta_c if w > 0 else math.inf,
        "fuller_tabor_theta": regimes.fuller_tabor_theta(rough.sigma, rough.summit_radius, w, e_s),
        "tabor_parameter": regimes.tabor_parameter(rough.summit_radius, w, e_s, surf.interface_interaction_range)
        if w > 0 else 0.0,
        "tabor_z0": surf.interface_interaction_range,
    }
    if surf.hardness is not None:
        regime["plasticity_index"] = regimes.plasticity_index(e_s, surf.hardness, rough.sigma, rough.summit_radius)
    record = {"datum": {**datum, "z_max_m": datum["z_max"] * rough.sigma, "release_from": rough.datum},
              "regime": regime, "table": {"resolution": getattr(surface, "resolution", scene.numerics.table),
                                          "build_seconds": getattr(surface, "build_seconds", None)}}
    if cost is not None:
        record["table"]["cost_estimate"] = cost
    if rough.mode != "discrete" and table != scene.numerics.table:
        record["table"]["why"] = (f"the '{scene.numerics.table}' preset asked for '{scene.numerics.table}' tables, "
                                  f"but sigma/delta_c < {FAST_TABLE_MIN_SIGMA_OVER_DELTA_C:g}, where they miss their "
                                  "1e-6 accuracy: 'standard' tables were built (GW and, on a rigid substrate, footprint tables)")
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
    if generic:
        record["summit_law"] = surface.law.describe() if hasattr(surface, "law") else adhesion
    if with_menisci:
        from .laws.wet import MeniscusBridges, WetRoughRoller
        p = meniscus_parameters(scene)
        bridges = MeniscusBridges(stats, law.z_top, body.radius, body.length, p["bridge_pull_off"], p["kelvin_gap"],
                                  p["condensation_time"], p["growth_length"])
        law = WetRoughRoller(law, bridges, p)
    return law, record


def select_law(scene: Scene, first_impact_speed: float, menisci: bool | None = None) -> tuple[ContactLaw, dict]:
    """The contact law for `scene` and a record of what runs, what is left out, and why.

    `menisci` overrides the meniscus decision (True/False); None decides it here, where 'auto'
    with a wet, hydrophilic scene is recorded as pending (`run_impact` settles it after a dry run).
    """
    body, surf, phys = scene.body, scene.surfaces, scene.physics
    e_star = surf.e_star
    models: dict = {}
    m_choice, m_rec = decide_menisci(scene)
    if scene.contact == "rough":
        estimate = _estimate(scene, first_impact_speed)
        adhesion, a_rec = decide_adhesion(scene, estimate)
        if surf.roughness.mode == "discrete" and adhesion in ("dmt", "maugis_dugdale"):
            a_rec = {**a_rec, "map_suggests": adhesion, "why": a_rec["why"] + "; discrete summits are JKR or Hertz "
                     "only: JKR used (force 'averaged' mode for this law)"}
            adhesion = "jkr"
        use_hs, hs_rec = decide_half_space(scene, estimate)
        wet = menisci if menisci is not None else (m_choice == "on")
        law, record = rough_law(scene, adhesion, use_hs, with_menisci=wet, estimate=estimate)
        models["estimate"] = {**estimate.to_json(), "what": "quasi-static first approach of Hertz summits on a "
                              "rigid substrate absorbing the first impact's energy (continuum.estimates)"}
        models["contact_law"] = {**law.describe(), **record,
                                 "why": "contact = 'rough': GW summits on a grid under the roller"}
        models["adhesion"] = {"used": adhesion != "none", **a_rec}
        models["half_space"] = hs_rec
        if menisci is not None:
            m_rec = {**m_rec, "used": menisci}
        elif m_choice == "on":
            m_rec = {**m_rec, "used": True}
        if wet:
            m_rec.update(meniscus_parameters(scene))
        models["menisci"] = m_rec
        models["sam"] = _sam_record(scene)
        models["free_flight"] = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}
        return law, models
    adhesion, a_rec = decide_adhesion(scene)
    if adhesion == "none":
        if body.shape == "sphere":
            law = HertzSphere(body.radius, e_star)
            why = "smooth sphere, no adhesion: Hertz point contact"
        elif phys.line_stiffness == "implicit":
            law = HertzLine(body.radius, body.length, e_star)
            why = "smooth cylinder, no adhesion: Hertz line contact with b(W) solved exactly"
        else:
            k, load = roller_constant_stiffness(body.mass, first_impact_speed, body.radius, body.length, e_star)
            law = LinearSpring(k, {"reference_load": load, "reference_speed": first_impact_speed})
            why = ("smooth cylinder, line_stiffness = 'constant': K of eq 1 frozen at the first impact's "
                   "peak load (paper eq 2)")
        if surf.interface_work_of_adhesion > 0 and phys.adhesion_law == "none":
            a_rec = {**a_rec, "why": "adhesion_law = 'none' (work_of_adhesion ignored)"}
        models["adhesion"] = {"used": False, **a_rec}
    else:  # jkr; scene validation admits only a sphere for smooth contact
        law = JKRSphere(body.radius, surf.interface_work_of_adhesion, e_star, phys.detachment)
        why = f"smooth sphere, JKR with Fuller-Tabor hysteresis, {phys.detachment}-controlled release"
        models["adhesion"] = {"used": True, **a_rec}
    models["contact_law"] = {**law.describe(), "why": why}
    models["menisci"] = m_rec
    models["half_space"] = {"used": False, "decided_by": "geometry",
                            "why": "smooth contact: the closed-form law already contains the elastic half-space"}
    models["sam"] = _sam_record(scene)
    models["free_flight"] = {"used": True, "why": "closed form under gravity (no time steps spent in flight)"}
    return law, models


def _sam_record(scene: Scene) -> dict:
    sam = scene.surfaces.sam
    if sam is None:
        return {"used": False, "why": "surfaces.sam.coverage = 'none'"}
    rec = {"used": True, "thickness": sam.thickness, "work_of_adhesion": sam.work_of_adhesion,
           "contact_angle_deg": math.degrees(sam.contact_angle) if sam.contact_angle is not None else None}
    if sam.layer_modulus is None:
        rec["layer"] = {"used": False, "why": "no surfaces.sam.layer_modulus: a rigid uniform layer conforming to "
                                              "the summits shifts all gaps equally and does not enter the mechanics"}
    else:
        rec["layer"] = {"used": True, "total_thickness": 2.0 * sam.thickness, "modulus": sam.layer_modulus,
                        "poisson_ratio": sam.layer_poisson_ratio,
                        "why": "compliant layers on both surfaces in series with every summit contact "
                               "(thin-layer limit, continuum.rough.summit_laws)"}
    rec["why"] = "both surfaces covered: SAM-SAM work of adhesion and contact angle"
    return rec
