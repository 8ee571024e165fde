"""Typed decisions: which adhesion law, whether the half-space, whether menisci; each carries the numbers
that decided it and writes its own record (result.json -> models.adhesion / half_space / menisci).

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
(`continuum.model.estimates`): the summits' gaps then move by less than a thousandth of their spread.

Menisci. Left out when the air is dry (RH = 0), when the faces are hydrophobic (cos t1 + cos t2
<= 0: no bridge pulls), for smooth contact and discrete summits (not modelled), and otherwise
decided after a dry run (`dry_run_verdict`; `continuum.dynamics.impact.run_impact` runs the two): bridges cannot
form before t_a, so if no contact of the dry run lasts t_a, the wet run is identical and the dry one is kept.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..reference import jkr as jkr_ref
from ..scene import Scene
from ..wet import menisci as men
from . import regimes
from .regime import Regime

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
def summit_law(name: str, scene: Scene, e_star: float):
    """The per-summit law (continuum.rough.branch_laws) for a law name, the scene's surfaces and the summits'
    contact modulus `e_star` (Pa, `Regime.e_star`).

    Tabulated to a compression of 30 sigma (the rough model refuses impacts deeper than 10 sigma
    below the mean plane; the tallest summit is < 6 sigma above it)."""
    from ..rough.branch_laws import make_summit_law

    surf = scene.surfaces
    beta, w, e_s = surf.roughness.summit_radius, surf.interface_work_of_adhesion, e_star
    return make_summit_law(name, beta, w, e_s, z0=surf.interface_interaction_range,
                           detachment=scene.physics.detachment, delta_max=30.0 * surf.roughness.sigma)


def loop_per_summit(name: str, scene: Scene, e_star: float) -> float:
    """Energy (J) one summit of contact modulus `e_star` (Pa) loses per approach-retreat cycle under `name`."""
    if name == "none":
        return 0.0
    if name == "jkr":
        surf = scene.surfaces
        return float(jkr_ref.loop_area(surf.roughness.summit_radius, surf.interface_work_of_adhesion,
                                       e_star, detachment=scene.physics.detachment))
    return float(summit_law(name, scene, e_star).loop_energy)


def pull_off_per_summit(name: str, scene: Scene, e_star: float) -> float:
    """Pull-off force (N) of one summit of contact modulus `e_star` (Pa) under `name`."""
    surf = scene.surfaces
    beta, w = surf.roughness.summit_radius, surf.interface_work_of_adhesion
    if name == "jkr":
        return float(jkr_ref.pull_off_force(beta, w))
    if name == "dmt":
        return 2.0 * math.pi * beta * w
    return float(summit_law(name, scene, e_star).pull_off_force)


# ----------------------------------------------------------------------------- adhesion
@dataclass(frozen=True)
class AdhesionDecision:
    """The adhesion law of the summits (or sphere) and the numbers that decided it (SI)."""

    law: str
    """'jkr', 'dmt', 'maugis_dugdale' or 'none': the law that runs."""
    decided_by: str
    why: str
    work_of_adhesion: float
    source: str
    """Where the work of adhesion comes from: 'SAM-SAM' or 'surfaces.work_of_adhesion'."""
    interaction_range_z0: float
    tabor_parameter: float | None = None
    fuller_tabor_theta: float | None = None
    on_the_map: bool = False
    """Decided on Johnson & Greenwood's map (the Tabor bounds are recorded)."""
    estimated_loss_fraction: float | None = None
    estimated_pull_fraction: float | None = None
    loop_energy_per_summit: float | None = None

    @property
    def used(self) -> bool:
        return self.law != "none"

    def record(self) -> dict:
        rec = {"work_of_adhesion": self.work_of_adhesion, "source": self.source,
               "interaction_range_z0": self.interaction_range_z0}
        if self.tabor_parameter is not None:
            rec["tabor_parameter"] = self.tabor_parameter
        if self.fuller_tabor_theta is not None:
            rec["fuller_tabor_theta"] = self.fuller_tabor_theta
        if self.on_the_map:
            rec["tabor_bounds"] = {"jkr_above": TABOR_JKR, "dmt_below": TABOR_DMT, "source": "Johnson & Greenwood 1997"}
        if self.estimated_loss_fraction is not None:
            rec.update({"estimated_loss_fraction": self.estimated_loss_fraction,
                        "estimated_pull_fraction": self.estimated_pull_fraction,
                        "loop_energy_per_summit": self.loop_energy_per_summit,
                        "negligible_below": {"loss": NEGLIGIBLE_LOSS, "pull": NEGLIGIBLE_PULL}})
        rec.update({"law": self.law, "decided_by": self.decided_by, "why": self.why})
        return rec


def adhesion_decision(scene: Scene, regime: Regime) -> AdhesionDecision:
    """Summit (or sphere) adhesion law for `scene` in `regime` (its estimate, if any, weighs the loss)."""
    surf, phys = scene.surfaces, scene.physics
    w = regime.work_of_adhesion
    base = dict(work_of_adhesion=w, source="SAM-SAM" if surf.sam is not None else "surfaces.work_of_adhesion",
                interaction_range_z0=regime.interaction_range, tabor_parameter=regime.tabor_parameter,
                fuller_tabor_theta=regime.fuller_tabor_theta)
    mu = regime.tabor_parameter
    if phys.adhesion_law != "auto":
        return AdhesionDecision(phys.adhesion_law, "scene", f"physics.adhesion_law = '{phys.adhesion_law}' given by "
                                "the scene or its parameter set (result.json -> scene.sources says which)", **base)
    if w <= 0.0:
        return AdhesionDecision("none", "work_of_adhesion", "auto: no work of adhesion, Hertz contact", **base)
    if scene.contact == "smooth":
        if scene.body.shape == "cylinder":
            return AdhesionDecision("none", "geometry", "auto: a smooth roller has no adhesive line-contact law here "
                                    "(2-D JKR is not implemented); adhesion is left out and the result says so", **base)
        if phys.detachment != "displacement":
            return AdhesionDecision("jkr", "detachment", f"auto: smooth sphere, JKR: the only sphere law with a "
                                    f"load-controlled release (Tabor mu = {mu:.3g})", **base)
        law = "jkr" if mu > TABOR_JKR else "dmt" if mu < TABOR_DMT else "maugis_dugdale"
        return AdhesionDecision(law, "tabor_parameter", f"auto: Tabor mu = {mu:.3g} of the smooth sphere -> "
                                f"{LAW_NAMES[law]}", **{**base, "on_the_map": True})
    law = "jkr" if mu > TABOR_JKR else "dmt" if mu < TABOR_DMT else "maugis_dugdale"
    base["on_the_map"] = True
    loop = loop_per_summit(law, scene, regime.e_star)
    n_pull = pull_off_per_summit(law, scene, regime.e_star)
    estimate = regime.estimate
    if estimate is not None and estimate.impact_energy > 0:        # no impact (a quasi-static curve): no loss to weigh
        loss = estimate.contacts * loop / estimate.impact_energy
        pull = estimate.contacts * n_pull / estimate.peak_force if estimate.peak_force > 0 else math.inf
        base.update(estimated_loss_fraction=loss, estimated_pull_fraction=pull, loop_energy_per_summit=loop)
        if loss < NEGLIGIBLE_LOSS and pull < NEGLIGIBLE_PULL:
            return AdhesionDecision("none", "estimated_loss_fraction",
                                    f"auto: {LAW_NAMES[law]} summits (Tabor mu = {mu:.3g}) would lose {loss:.2g} of "
                                    f"the impact energy per impact and pull {pull:.2g} of the peak force: negligible, "
                                    "adhesion left out", **base)
    return AdhesionDecision(law, "tabor_parameter", f"auto: Tabor mu = {mu:.3g} of the summits -> {LAW_NAMES[law]}",
                            **base)


# ----------------------------------------------------------------------------- half-space
@dataclass(frozen=True)
class HalfSpaceDecision:
    """Whether the summits are coupled to the elastic half-space, and the deflection that decided it."""

    used: bool
    decided_by: str
    why: str
    estimated_deflection_span: float | None = None
    """Span of the estimated deflection across the footprint (m), rough contact."""
    deflection_over_sigma: float | None = None
    rough: bool = True
    """False for smooth contact, whose record carries no numbers (the closed form contains the half-space)."""

    def record(self) -> dict:
        if not self.rough:
            return {"used": self.used, "decided_by": self.decided_by, "why": self.why}
        return {"estimated_deflection_span": self.estimated_deflection_span,
                "deflection_over_sigma": self.deflection_over_sigma, "negligible_below": NEGLIGIBLE_DEFLECTION,
                "used": self.used, "decided_by": self.decided_by, "why": self.why}


#: Smooth contact: the closed-form laws contain the elastic half-space.
SMOOTH_HALF_SPACE = HalfSpaceDecision(False, "geometry", "smooth contact: the closed-form law already contains the "
                                                         "elastic half-space", rough=False)


def half_space_decision(scene: Scene, regime: Regime) -> HalfSpaceDecision:
    """Whether the rough contact couples its summits to the elastic half-space, and why."""
    choice = scene.physics.half_space
    sigma = scene.surfaces.roughness.sigma
    est = regime.estimate
    numbers = dict(estimated_deflection_span=est.deflection_span if est else None,
                   deflection_over_sigma=est.deflection_span / sigma if est else None)
    if choice != "auto":
        return HalfSpaceDecision(choice == "on", "scene", f"physics.half_space = '{choice}' set in the scene",
                                 **numbers)
    ratio = est.deflection_span / sigma
    used = ratio >= NEGLIGIBLE_DEFLECTION
    why = (f"auto: estimated deflection across the footprint {est.deflection_span:.3g} m = {ratio:.3g} sigma "
           + (">= " if used else "< ") + f"{NEGLIGIBLE_DEFLECTION:g} sigma: "
           + ("coupled (FFT influence coefficients)" if used else "left out, rigid substrate"))
    return HalfSpaceDecision(used, "deflection_over_sigma", why, **numbers)


# ----------------------------------------------------------------------------- menisci
@dataclass(frozen=True)
class MenisciDecision:
    """'off', 'on' or 'after_dry_run' (settled by `run_impact` after a dry run), and the numbers that decided it."""

    choice: str
    decided_by: str
    why: str
    relative_humidity: float
    wetting_sum: float | None = None
    """cos t1 + cos t2 of the faces (where the geometry and humidity let it matter)."""
    contact_angles_deg: tuple[float, float] | None = None

    @property
    def used(self) -> bool | None:
        """True or False, None while pending a dry run."""
        return None if self.choice == "after_dry_run" else self.choice == "on"

    def record(self) -> dict:
        rec: dict = {"relative_humidity": self.relative_humidity}
        if self.wetting_sum is not None:
            rec["cos_theta1_plus_cos_theta2"] = self.wetting_sum
            rec["contact_angles_deg"] = list(self.contact_angles_deg)
        if self.used is not None:
            rec["used"] = self.used
        rec.update({"decided_by": self.decided_by, "why": self.why})
        return rec


def menisci_decision(scene: Scene, regime: Regime) -> MenisciDecision:
    """'off', 'on' or 'after_dry_run' for `scene` in `regime` (its Kelvin radius), with the numbers that decided
    it."""
    choice, surf, env = scene.physics.menisci, scene.surfaces, scene.environment
    rh = env.relative_humidity
    if choice == "off":
        return MenisciDecision("off", "scene", "physics.menisci = 'off' set in the scene", rh)
    sphere = scene.contact == "smooth" and scene.body.shape == "sphere"
    if scene.contact != "rough" and not sphere:
        return MenisciDecision("off", "geometry", "menisci are modelled for rough contact (every summit, mean field "
                               "or discrete) and the smooth sphere only", rh)
    if rh <= 0.0:
        return MenisciDecision("off", "relative_humidity", "dry: environment.relative_humidity = 0", rh)
    t1, t2 = surf.contact_angles
    wet = men.wetting_sum(t1, t2)
    numbers = dict(wetting_sum=wet, contact_angles_deg=(math.degrees(t1), math.degrees(t2)))
    if wet <= 0.0:
        return MenisciDecision("off", "contact_angles",
                               f"hydrophobic: cos t1 + cos t2 = {wet:.3g} <= 0, no bridge pulls", rh, **numbers)
    if sphere:
        r_k = regime.meniscus_parameters()["kelvin_radius"]
        cutoff, source = regime.min_kelvin_radius, regime.min_kelvin_radius_source
        if r_k < cutoff:
            return MenisciDecision("off", "kelvin_radius", f"Kelvin radius {r_k:.3g} m < {cutoff:.3g} m ({source}): "
                                   "no continuum meniscus condenses", rh, **numbers)
    if choice == "on":
        return MenisciDecision("on", "scene", "physics.menisci = 'on' set in the scene", rh, **numbers)
    return MenisciDecision("after_dry_run", "longest_contact_time",
                           "auto: decided after a dry run (bridges cannot form before t_a)", rh, **numbers)


@dataclass(frozen=True)
class DryRunVerdict:
    """How a pending meniscus decision ('after_dry_run') is settled: the longest contact of the dry run against
    the condensation time t_a (s). Bridges cannot form before t_a, so a dry run whose contacts all end sooner is
    the wet run; otherwise the scene is run again with menisci."""

    longest_contact_s: float
    condensation_time_s: float
    dry_run_bounces: int
    final_contact: str | None = None
    """Why the last contact does not count, when the run ended held ('stuck' or 'rest'); None otherwise."""

    @property
    def rerun(self) -> bool:
        """True when a contact of the dry run lasted t_a: run again with menisci."""
        return self.longest_contact_s >= self.condensation_time_s

    def record(self) -> dict:
        """What settles models.menisci (merged into the pending record, or the wet run's)."""
        longest, t_a = self.longest_contact_s, self.condensation_time_s
        rec: dict = {"longest_contact_s": longest, "condensation_time_s": t_a, "final_contact": self.final_contact}
        if self.rerun:
            rec["dry_run_bounces"] = self.dry_run_bounces
            rec["why"] = (f"auto: a contact of the dry run lasted {longest:.3g} s >= t_a = {t_a:.3g} s: "
                          "rerun with menisci")
        else:
            rec["used"] = False
            rec["why"] = (f"auto: the longest contact of the dry run lasted {longest:.3g} s < t_a = {t_a:.3g} s, so no "
                          "bridge can form: the dry run is the wet run")
        return rec


def dry_run_verdict(regime: Regime, durations, status: str) -> DryRunVerdict:
    """Settle 'after_dry_run' from the dry run's contact `durations` (s; None for a contact that never ended)
    and its final `status`, against the condensation time of the scene's `regime`."""
    released = [d for d in durations if d is not None]
    final = (None if status not in ("stuck", "rest") else
             f"the run ended '{status}': the last contact never ends, bridges would form in it after t_a but cannot "
             "change any rebound (the body is already held)")
    return DryRunVerdict(max(released, default=0.0), regime.condensation_time, len(durations), final)


# ----------------------------------------------------------------------------- realisation (few summits)
#: 'auto' runs an ensemble of discrete realisations below this many expected summits in contact at the first
#: impact (the Hertz estimate's count, continuum.model.estimates): above it the mean field's first-impact energy loss
#: lies within ENSEMBLE_TOLERANCE of the ensemble mean. Measured by benchmarks/bench_ensemble_threshold.py (the
#: departure falls like A / sqrt(N_c), N* = (A / tolerance)^2; A, its standard error and N* are the json's `fit` and
#: `threshold_expected_contacts`, docs/figures/ensemble_threshold.json; docs/model.md "Few summits: ensembles"),
#: rounded to an integer here and held to the json by tests/test_generated_docs.py.
ENSEMBLE_BELOW_CONTACTS = 80.0
#: The relative departure of the first impact's energy loss (mean field against the ensemble mean) that 'auto'
#: accepts. A declared choice: the departure decays only like 1/sqrt(N_c), so a tolerance at the solver's level
#: (1e-6) would ask for ensembles at every realistic N_c; 5 % keeps them wherever the mean field is biased by more
#: than that (the json also gives the threshold at 1 %).
ENSEMBLE_TOLERANCE = 0.05


@dataclass(frozen=True)
class RealisationDecision:
    """How the summits are realised: 'mean_field', 'discrete' or 'ensemble', and the count that decided it."""

    mode: str
    decided_by: str
    why: str
    expected_contacts: float | None
    members: int | None = None
    seed: int | None = None

    def record(self) -> dict:
        rec = {"mode": self.mode, "expected_contacts": self.expected_contacts,
               "ensemble_below_contacts": ENSEMBLE_BELOW_CONTACTS, "tolerance_over_h0": ENSEMBLE_TOLERANCE,
               "threshold_source": "benchmarks/bench_ensemble_threshold.py -> docs/figures/ensemble_threshold.json"}
        if self.mode == "ensemble":
            rec.update(members=self.members, master_seed=self.seed)
        rec.update(used=True, decided_by=self.decided_by, why=self.why)
        return rec


def realisation_decision(scene: Scene, regime: Regime) -> RealisationDecision:
    """Mean field or an ensemble of discrete realisations for a rough `scene` (its regime carries the estimate)."""
    rough = scene.surfaces.roughness
    n_c = regime.estimate.contacts if regime.estimate is not None else None
    ens = dict(members=rough.members, seed=rough.seed)
    if rough.mode != "auto":
        return RealisationDecision(rough.mode, "scene", f"surfaces.roughness.mode = '{rough.mode}' set in the scene",
                                   n_c, **(ens if rough.mode == "ensemble" else {}))
    if n_c >= ENSEMBLE_BELOW_CONTACTS:
        return RealisationDecision("mean_field", "expected_contacts",
                                   f"auto: {n_c:.3g} summits expected in contact >= {ENSEMBLE_BELOW_CONTACTS:g}: the "
                                   "mean field agrees with the ensemble mean within the measured tolerance", n_c)
    few = f"auto: {n_c:.3g} summits expected in contact < {ENSEMBLE_BELOW_CONTACTS:g}"
    # menisci do not change this: each member's summits grow their own bridges (continuum.laws.discrete_bridges)
    return RealisationDecision("ensemble", "expected_contacts",
                               f"{few}: the mean field describes no single impact; an ensemble of {rough.members} "
                               "discrete realisations gives the distribution", n_c, **ens)


# ----------------------------------------------------------------------------- plasticity (smooth sphere)
@dataclass(frozen=True)
class PlasticityDecision:
    """Whether a smooth sphere (or the summits of rough contact, `summit_plasticity`) runs the Thornton-Ning adhesive
    elastic-plastic law, and the numbers that decided it: the softer partner's limiting contact pressure (Pa,
    `continuum.physics.limiting_pressure`) and the yield velocity (m/s,
    `continuum.reference.thornton_ning.yield_velocity`) against the first impact's speed (m/s), or the summits'
    plasticity index."""

    used: bool
    decided_by: str
    why: str
    limiting_pressure: float | None = None
    from_key: str | None = None
    yield_velocity: float | None = None
    impact_speed: float | None = None
    partners: tuple = ()
    """Each partner with a yield key: `continuum.physics.limiting_pressure.PartnerLimit`."""
    plasticity_index: float | None = None
    """Rough contact: the summits' Greenwood-Williamson psi = (E*/p_y) sqrt(sigma/beta) (`summit_plasticity`)."""
    summits_yield: bool | None = None
    """Rough contact: what 'auto' decides from psi or the depth (True: plastic summits matter), run or not."""
    summit_yield_approach: float | None = None
    """Rough contact: the approach (m) at which a summit yields (JKR centre pressure = p_y)."""
    estimated_depth: float | None = None
    """Rough contact: the first impact's estimated depth below the tallest summit (m), where estimated."""
    summit_law: str | None = None
    """Rough contact: the elastic summit law the plastic summits are built on ('jkr', 'maugis_dugdale', 'dmt')."""

    def record(self) -> dict:
        rec: dict = {}
        if self.partners:
            rec["partners"] = [{"key": p.key, "value": p.value, "limiting_pressure": p.limiting_pressure}
                               for p in self.partners]
        if self.plasticity_index is not None:
            rec.update(plasticity_index=self.plasticity_index, summits_yield=self.summits_yield,
                       summit_yield_approach=self.summit_yield_approach, estimated_depth=self.estimated_depth,
                       limiting_pressure=self.limiting_pressure, from_key=self.from_key, summit_law=self.summit_law,
                       thresholds={"elastic_below": PSI_ELASTIC, "plastic_above": PSI_PLASTIC},
                       source="Greenwood & Williamson, Proc. R. Soc. Lond. A 295 (1966) 300")
        if self.yield_velocity is not None:
            rec.update(limiting_pressure=self.limiting_pressure, from_key=self.from_key,
                       yield_velocity=self.yield_velocity, impact_speed=self.impact_speed,
                       source="Thornton & Ning, Powder Technol. 99 (1998) 154")
        rec.update(used=self.used, decided_by=self.decided_by, why=self.why)
        return rec


def _yield_values(scene: Scene) -> dict:
    """The yield keys and moduli of both partners, keyed by scene path (SI)."""
    out = {}
    for prefix, mat in (("surfaces.body", scene.surfaces.body), ("surfaces.substrate", scene.surfaces.substrate)):
        out.update({f"{prefix}.yield_strength": mat.yield_strength, f"{prefix}.hardness": mat.hardness,
                    f"{prefix}.youngs_modulus": mat.youngs_modulus})
    return out


#: Greenwood & Williamson (1966): psi below 0.6 the summits stay elastic under any practical load; above 1 most
#: touching summits yield. 'auto' counts plastic summits as mattering from psi = PSI_ELASTIC on.
PSI_ELASTIC, PSI_PLASTIC = 0.6, 1.0


def _summit_yield_approach(scene: Scene, limiting_pressure: float, e_s: float) -> float:
    """Approach (m) at which a summit's JKR centre pressure reaches p_y (`thornton_ning.yield_radius`)."""
    from ..reference import thornton_ning as tn
    beta, w = scene.surfaces.roughness.summit_radius, scene.surfaces.interface_work_of_adhesion
    a_y = float(tn.yield_radius(limiting_pressure, beta, w, e_s))
    return float(jkr_ref.approach_from_radius(a_y, beta, w, e_s))


def summit_plasticity(scene: Scene, regime: Regime, adhesion: str = "jkr", half_space: bool = False,
                      menisci: bool = False, depth: float | None = None, choice: str = "auto") -> PlasticityDecision:
    """Rough contact: do the summits yield? Greenwood & Williamson's plasticity index psi = (E*/p_y) sqrt(sigma/beta)
    (the summits' E*, `Regime.e_star`; the softer partner's limiting pressure p_y, H or 2.8 Y) decides for the
    surface under any practical load; the first impact's estimated depth below the tallest summit (`depth`, m,
    `continuum.model.estimates`) beyond a summit's yield approach delta_y decides for an impact hard enough to yield
    the tallest summits of an otherwise elastic surface.

    Where they yield, adhesive elastic-plastic summits under a rigid roller run (`continuum.laws.plastic_rough`):
    Thornton-Ning's construction on the summit law that runs (`adhesion`: JKR, Maugis-Dugdale or DMT,
    `continuum.rough.plastic_branches`), on each summit of the realisation (mode 'discrete', and every ensemble
    member: `continuum.model.select.plastic_member`) or on their GW mean field (`continuum.rough.plastic_summits`
    for JKR, `continuum.rough.plastic_gw_branches` for Maugis-Dugdale and DMT). They sit on a rigid substrate, so
    under the half-space the summits stay elastic; a realisation's plastic summits carry bridges
    (`continuum.laws.wet_plastic_summits`), the mean field's bridges wrap elastic summits; the record says why.
    Plastic Maugis-Dugdale and DMT summits run compiled (`continuum.rough.plastic_kernel`; their cost against the
    elastic members: benchmarks/bench_plastic_summits.py, docs/benchmarks.md). `choice` is physics.plasticity
    ('on' and 'auto' decide alike for rough contact; 'off' is handled by `plasticity_decision`).
    A p_y below the summits' adhesive stress scale (they would yield on snap-in, outside Thornton-Ning) is refused
    naming its key."""
    from ..physics.limiting_pressure import partner_limits, softer_partner

    limits = tuple(partner_limits(_yield_values(scene)))
    soft = softer_partner(list(limits))
    if soft is None:
        return PlasticityDecision(False, "yield_strength", "no yield key (surfaces.body or surfaces.substrate "
                                  "yield_strength or hardness): the summits are elastic")
    rough = scene.surfaces.roughness
    e_s = regime.e_star
    psi = regimes.plasticity_index(e_s, soft.limiting_pressure, rough.sigma, rough.summit_radius)
    d_y = _summit_yield_approach(scene, soft.limiting_pressure, e_s)
    by_psi, by_depth = psi >= PSI_ELASTIC, depth is not None and depth > d_y
    yields = by_psi or by_depth
    state = ("most summits yield" if psi > PSI_PLASTIC else "some summits yield") if by_psi else "summits stay elastic"
    why = (f"auto: plasticity index psi = {psi:.3g} " + (">=" if by_psi else "<") + f" {PSI_ELASTIC} "
           f"(limiting contact pressure {soft.limiting_pressure:.3g} Pa from {soft.key}): {state}")
    if depth is not None:
        why += (f"; the first impact's estimated depth {depth:.3g} m " + (">" if by_depth else "<=")
                + f" the summits' yield approach {d_y:.3g} m")
    blockers = [text for cond, text in (
        (adhesion == "none", "the summits are not adhesive (the plastic summit laws are adhesive)"),
        (half_space, "the half-space roller carries elastic summits only"),

        (menisci and rough.mode != "discrete", "the mean field's bridges wrap elastic summits (a discrete "
                                               "realisation or an ensemble carries plastic summits in its bridges)"),
    ) if cond]
    used = yields and not blockers
    if used:
        _check_summit_limit(scene, soft, e_s)
        why += (f": Thornton-Ning's construction on the {adhesion} summits under a rigid roller, "
                + ("each summit of the realisation" if rough.mode == "discrete" else "their GW mean field"))
        if rough.mode in ("auto", "ensemble"):
            why += " (and each ensemble member's realisation, where an ensemble runs)"
    elif yields:
        why += "; " + "; ".join(blockers) + ": this run is elastic and overestimates the rebound"
    return PlasticityDecision(used, "plasticity_index" if by_psi or not by_depth else "estimated_depth", why,
                              limiting_pressure=soft.limiting_pressure, from_key=soft.key, partners=limits,
                              plasticity_index=psi, summits_yield=yields, summit_yield_approach=d_y,
                              estimated_depth=depth, summit_law=adhesion)


def _check_summit_limit(scene: Scene, soft, e_s: float) -> None:
    """Raise InputError naming the partner's key unless p_y lies above the summits' adhesive stress scale E* a0/(pi
    beta) (below it they would yield on snap-in, outside the Thornton-Ning law) and below their E*."""
    from nanoimpact.errors import InputError

    from ..reference import thornton_ning as tn
    beta, w = scene.surfaces.roughness.summit_radius, scene.surfaces.interface_work_of_adhesion
    try:
        tn.check_limiting_pressure(soft.limiting_pressure, beta, w, e_s, key=soft.key)
    except InputError as err:
        raise InputError(soft.key, soft.value, f"gives a limiting contact pressure of {soft.limiting_pressure:.4g} "
                         f"Pa for the summits; {err.allowed}") from None


def plasticity_decision(scene: Scene, regime: Regime, adhesion: str, *, half_space: bool = False,
                        menisci: bool = False, depth: float | None = None) -> PlasticityDecision:
    """Elastic-plastic smooth sphere or not, for the adhesion law that runs (`adhesion`) and the first impact's
    speed (m/s, `regime.speed`). 'auto': on when it exceeds the yield velocity; off (recorded) without a yield
    key. Rough contact: `summit_plasticity` (with the half-space and menisci decisions and the first impact's estimated
    `depth`, m)."""
    from ..physics.limiting_pressure import partner_limits, softer_partner
    from ..reference import thornton_ning as tn

    choice = scene.physics.plasticity
    if choice == "off":
        off = PlasticityDecision(False, "scene", "physics.plasticity = 'off' set in the scene")
        if scene.contact == "rough":     # psi is still evaluated and recorded, for the reader
            from nanoimpact.errors import InputError
            try:
                rough = summit_plasticity(scene, regime, adhesion, half_space, menisci, depth, "auto")
            except InputError:
                return off
            if rough.plasticity_index is not None:
                state = "summits would yield" if rough.summits_yield else "summits stay elastic"
                return replace(rough, used=False, decided_by="scene", why=off.why + f" (plasticity index psi = "
                               f"{rough.plasticity_index:.3g}: {state})")
        return off
    if scene.contact == "rough":
        return summit_plasticity(scene, regime, adhesion, half_space, menisci, depth, choice)
    if scene.body.shape != "sphere":
        return PlasticityDecision(False, "geometry", "the elastic-plastic law is for a smooth sphere; a smooth "
                                  "roller stays elastic (the line-contact yield warning says where it would yield)")
    limits = tuple(partner_limits(_yield_values(scene)))
    soft = softer_partner(list(limits))
    if soft is None:
        return PlasticityDecision(False, "yield_strength", "no yield key (surfaces.body or surfaces.substrate "
                                  "yield_strength or hardness): the sphere is elastic")
    if adhesion != "jkr":
        return PlasticityDecision(False, "adhesion_law", "the elastic-plastic law here is Thornton & Ning's (1998), "
                                  f"built on JKR; under adhesion law '{adhesion}' the sphere stays elastic",
                                  partners=limits)
    body, speed = scene.body, regime.speed
    if speed is None:
        raise ValueError("plasticity_decision needs the regime of a first impact (regime_of(scene, speed))")
    density = body.mass / (4.0 / 3.0 * math.pi * body.radius**3)
    v_y = float(tn.yield_velocity(soft.limiting_pressure, body.radius, regime.work_of_adhesion, regime.e_star,
                                  density))
    numbers = dict(limiting_pressure=soft.limiting_pressure, from_key=soft.key, yield_velocity=v_y,
                   impact_speed=speed, partners=limits)
    if choice == "on":
        return PlasticityDecision(True, "scene", "physics.plasticity = 'on' set in the scene", **numbers)
    used = speed > v_y
    why = (f"auto: first impact at {speed:.3g} m/s " + ("> " if used else "<= ") + f"the yield velocity {v_y:.3g} "
           f"m/s (limiting contact pressure {soft.limiting_pressure:.3g} Pa from {soft.key}): "
           + ("Thornton-Ning elastic-plastic law" if used else "the contact stays elastic"))
    return PlasticityDecision(used, "yield_velocity", why, **numbers)
