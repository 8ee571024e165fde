"""Bridges on the summits of discrete realisations (continuum.laws.discrete_bridges), the wet work of adhesion from a
measured W_SL, and the condensation time from nucleation (continuum.wet.menisci, continuum.model.regime)."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import integrate

from continuum.dynamics.ensemble_run import run_ensemble
from continuum.dynamics.impact import run_impact
from continuum.laws.discrete_bridges import DiscreteBridges, wet_discrete
from continuum.laws.discrete_roller import DiscreteRoughRoller
from continuum.model.regime import condensation_time, meniscus_parameters
from continuum.rough.summits import SummitStatistics
from continuum.scene import resolve_scene
from continuum.wet import menisci as men

GAMMA = 0.072                       # N/m, water
THETA = math.radians(20.0)
BETA = 0.2e-6                       # summit radius (m)
R_K = 0.52e-9                       # Kelvin radius (m), water at ~40 % RH
D_K = 2.0 * R_K * math.cos(THETA)   # Kelvin gap of two faces at THETA
F0 = 4.0 * math.pi * BETA * GAMMA * math.cos(THETA)     # Israelachvili 2011 eq 17.23, both faces at THETA
T_A, H1 = 1e-6, 0.34e-9


def _one_summit(u: float = 0.0, solid_pull: float = 0.0) -> DiscreteBridges:
    """Bridges on a realisation holding one summit u m below the datum."""
    source = SimpleNamespace(eff=np.array([u]), z_top=0.0)
    return DiscreteBridges(source, F0, D_K, T_A, H1, solid_pull)


@pytest.mark.parametrize("g_over_dk", [-0.7, -0.2, 0.0, 0.1, 0.5, 0.93])
def test_a_single_bridged_summit_is_the_kelvin_laplace_bridge_on_a_sphere(g_over_dk):
    """One summit at gap g, bridged after t_a: F = 2 pi beta gamma (cos t1 + cos t2)(1 - g/D_K) stretched (the Laplace
    pressure -gamma/r_K over the wetted disc pi x^2 = 2 pi beta (D_K - g)), F0 (1 - g/(2 D_K)) compressed (the Hertz
    disc pi beta (-g) dry); U(g) = -int_g^{D_K} F, zero at rupture. Closed forms written here, not read from the
    code."""
    b = _one_summit()
    g = g_over_dk * D_K
    t = 2.0 * T_A                                 # after t_a every summit in contact is bridged; at g > 0 it bridges
    t = max(t, T_A * math.exp(max(g, 0.0) / H1) * 1.01)         # once h_mw(t) = h1 ln(t/t_a) reaches g
    b.accept(g, t)

    def laplace(gap):
        wetted = 2.0 * math.pi * BETA * (D_K - gap) if gap >= 0 else 2.0 * math.pi * BETA * (D_K - gap / 2.0)
        return GAMMA / R_K * wetted

    assert b.force(g, t) == pytest.approx(laplace(g), rel=1e-12)
    assert b.force(0.0, t) == pytest.approx(F0, rel=1e-12)      # the classical sphere-flat pull at touch
    energy = -integrate.quad(laplace, g, D_K, points=[0.0] if g < 0 else None, epsabs=0, epsrel=1e-13)[0]
    assert b.energy(g, t) == pytest.approx(energy, rel=1e-10)
    assert b.bridged(g, t) == 1 and b.bridged(1.01 * D_K, t) == 0       # broken beyond the Kelvin gap


def test_no_bridge_before_t_a_and_formation_books_the_energy_it_releases():
    """Energy continuity at formation: at a fixed gap the body does no work, so the bridges' stored energy plus what
    they book as formation work stays constant as the clock passes t_a (compressed summits bridge where they stand)
    and as h_mw(t) reaches the summits above contact one by one (their formation gap is their own gap)."""
    u = np.array([0.0, -0.3, -0.9, -1.6]) * D_K
    b = DiscreteBridges(SimpleNamespace(eff=u, z_top=0.0), F0, D_K, T_A, H1, solid_pull=0.3 * F0)
    gap = -0.4 * D_K                                # the first summit compressed, the others above contact
    ref = None
    formed_counts = []
    for t in np.concatenate([[0.5 * T_A, 0.999 * T_A], T_A * np.exp(np.linspace(0.0, 1.6 * D_K / H1, 40))]):
        total = b.energy(gap, t) + b.formed + b.pending_formation(gap, t)
        if t < T_A:
            assert b.force(gap, t) == 0.0 and b.energy(gap, t) == 0.0
        ref = total if ref is None else ref
        assert total == pytest.approx(ref, abs=1e-12 * F0 * D_K)
        b.accept(gap, t)
        formed_counts.append(b.bridged(gap, t))
    # at t_a the two compressed summits (gaps -0.4, -0.1 D_K) bridge; the summit 1.2 D_K away never does
    assert formed_counts[2] == 2 and formed_counts[-1] == 3
    assert b.formed == pytest.approx(-float(np.sum(men.bridge_energy(gap - u, F0, D_K, 0.3 * F0))), rel=1e-12)


def test_the_wet_work_of_adhesion_comes_from_the_measured_w_sl_under_complete_wetting():
    """Dupre in the liquid from interfacial energies (gamma_1L = gamma_1 + gamma_L - W_1L, gamma_12 = gamma_1 + gamma_2
    - dgamma): W_wet = gamma_1L + gamma_2L - gamma_12, for one solid and for two different ones; W_SL above 2 gamma_lv
    (spreading) counts in full, where the angle capped at 0 would lose it."""
    g1, g2, dgamma, gl = 0.30, 0.25, 0.192, 0.064           # any surface energies: they cancel
    for w1, w2 in ((0.1459, 0.1459), (0.1459, 0.0373)):
        gamma_1l, gamma_2l, gamma_12 = g1 + gl - w1, g2 + gl - w2, g1 + g2 - dgamma
        w_wet = men.wet_work_of_adhesion(dgamma, gl, 0.0, 0.0, (w1, w2))
        assert w_wet == pytest.approx(gamma_1l + gamma_2l - gamma_12, rel=1e-13)
    capped = men.wet_work_of_adhesion(dgamma, gl, 0.0, 0.0)
    measured = men.wet_work_of_adhesion(dgamma, gl, 0.0, 0.0, (0.1459, 0.1459))
    assert capped == pytest.approx(dgamma - 2 * gl) and measured < capped - 0.03
    # below complete wetting a W_SL consistent with the angle gives the Young form
    w_sl = gl * (1.0 + math.cos(THETA))
    assert men.wet_work_of_adhesion(dgamma, gl, THETA, THETA, (w_sl, w_sl)) == pytest.approx(
        men.wet_work_of_adhesion(dgamma, gl, THETA, THETA), rel=1e-13)


def test_the_calibrated_set_reads_its_measured_w_sl():
    scene = resolve_scene("wet_silica", params="calibrated").scene
    p = meniscus_parameters(scene)
    s = scene.surfaces
    expected = (s.work_of_adhesion + 2.0 * scene.menisci.surface_tension - s.body.work_of_adhesion_sl
                - s.substrate.work_of_adhesion_sl)
    assert s.body.work_of_adhesion_sl > 2.0 * scene.menisci.surface_tension          # the MD measured spreading
    assert p["work_of_adhesion_wet"] == pytest.approx(expected, rel=1e-13)
    assert p["solid_pull"] == pytest.approx(2 * math.pi * s.roughness.summit_radius * (s.work_of_adhesion - expected))


def test_the_nucleation_estimate_against_szoszkiewicz_and_riedo():
    """Their measured nucleation times at 40 % RH: 4.2 ms at 299 K (the estimate's anchor) and 0.7 ms at 332 K (from
    the barrier's Arrhenius slope): within a factor 1.2 of both, and inside the range the attempt frequency allows."""
    for temp, measured in men.NUCLEATION_MEASURED.items():
        t = men.nucleation_condensation_time(0.4, temp)
        assert measured / 1.2 < t < measured * 1.2
        lo, hi = men.nucleation_time_range(0.4, temp)
        assert lo < measured < hi and hi / lo == pytest.approx(250 / 4)
    # drier air raises the barrier (proportional to ln(1/RH)): longer times
    assert men.nucleation_condensation_time(0.2, 299.0) > 10 * men.nucleation_condensation_time(0.4, 299.0)


def test_calibrated_uses_nucleation_and_paper_keeps_its_declared_t_a():
    cal = resolve_scene("wet_silica", params="calibrated").scene
    t_a, source = condensation_time(cal)
    assert "nucleation" in source
    assert t_a == pytest.approx(men.nucleation_condensation_time(cal.environment.relative_humidity,
                                                                 cal.environment.temperature), rel=1e-14)
    paper = resolve_scene("wet_silica", params="paper").scene
    assert condensation_time(paper) == (25e-6, "menisci.condensation_time")


def test_a_humid_ensemble_carries_menisci_on_its_members():
    """Members of a humid scene grow bridges (t_a shortened so that its contacts reach it); a dry one carries none."""
    base = {"surfaces.roughness.mode": "ensemble", "surfaces.roughness.members": 2, "numerics.max_bounces": 3,
            "menisci.condensation_model": "fixed", "menisci.condensation_time": 1e-6}
    wet = run_ensemble(resolve_scene("wet_silica", params="calibrated", overrides=base)).to_record()
    assert wet["menisci"]["carried"] and wet["menisci"]["members_with_bridges"] == 2
    for m in wet["member_runs"]:
        assert m["menisci"]["contacts_with_bridges"] >= 1 and m["menisci"]["max_bridges"] >= 1
    assert wet["energy_audit_max_relative_error"] < 1e-3
    dry = run_ensemble(resolve_scene("wet_silica", params="calibrated",
                                     overrides={**base, "environment.relative_humidity": 0.0})).to_record()
    assert not dry["menisci"]["carried"] and all("menisci" not in m for m in dry["member_runs"])


def test_a_discrete_run_with_bridges_keeps_its_energy_books():
    """A single realisation, bridges on: E_kin + E_pot + stored + booked constant to the driver's tolerance."""
    from continuum.dynamics.driver import DriverSettings, simulate

    scene = resolve_scene("wet_silica", params="calibrated").scene
    stats = SummitStatistics(scene.surfaces.roughness.sigma, scene.surfaces.roughness.summit_density,
                             scene.surfaces.roughness.summit_radius)
    dry = DiscreteRoughRoller(stats, 0.2, 1e10, scene.body.radius, scene.body.length, 1e11, seed=3,
                              half_space=False)
    p = {**meniscus_parameters(scene), "condensation_time": 5e-7}
    law = wet_discrete(dry, dry, p)
    run = simulate(law, scene.body.mass, 9.81, release_height=5e-9,
                   settings=DriverSettings(rtol=1e-8, max_bounces=3))
    assert law.diagnostics()["menisci"]["contacts_with_bridges"] >= 1
    assert run.audit["max_relative_error"] < 1e-4


def _wet_summit_pair(w_dry: float = 0.192, w_wet: float = 0.028, e_star: float = 2e10):
    """One JKR summit under a roller, dry at w_dry, inside its bridge at w_wet (continuum.laws.wet_summits)."""
    from continuum.laws.wet_summits import wet_summit_roller

    stats = SummitStatistics(1e-9, 1e13, BETA)
    one = (np.array([0.0]), np.array([0.0]), np.array([0.0]))
    kw = dict(seed=0, half_space=False, summits=one)
    dry = DiscreteRoughRoller(stats, w_dry, e_star, 5e-6, 1e-3, 1e11, **kw)
    wet = DiscreteRoughRoller(stats, w_wet, e_star, 5e-6, 1e-3, 1e11, **kw)
    params = {"bridge_pull_off": F0, "kelvin_gap": D_K, "condensation_time": T_A, "growth_length": H1}
    return wet_summit_roller(dry, wet, params), dry, wet


def test_a_summit_inside_its_bridge_lets_go_with_the_wet_loop_and_the_books_close():
    """Quasi-static cycle of one JKR summit: pressed before t_a (dry), held past t_a (its bridge forms, the summit
    switches to W_wet where it stands), pulled off. It lets go at the wet release point and books one wet loop (the
    JKR closed form at W_wet, continuum.reference.jkr), no dry one; the work the roller does, -int F dgap, equals the
    change of stored + booked energy (trapezoid on a fine path; the force jumps only where a summit lets go)."""
    from continuum.reference import jkr as ref

    law, dry, wet = _wet_summit_pair()
    law.reset()
    books = lambda g: law.stored_energy(g) + law.dissipated(g)          # noqa: E731
    depth = 3.0 * dry.delta_c
    path = [(g, 0.0) for g in np.linspace(0.5 * D_K, -depth, 400)]                  # press, dry (t < t_a)
    path += [(-depth, t) for t in np.linspace(0.5 * T_A, 3.0 * T_A, 20)]            # hold: the bridge forms
    path += [(g, 3.0 * T_A) for g in np.linspace(-depth, 1.5 * D_K, 4000)]          # pull off, wet
    work, e0, prev = 0.0, None, None
    for g, t in path:
        law.set_time(t)
        f = law.force(g)
        if prev is not None:
            work += -0.5 * (f + prev[1]) * (g - prev[0]) if abs(f - prev[1]) < 0.05 * dry.pull_off_force else \
                -(prev[1] if g > prev[0] else f) * (g - prev[0])
            if prev[2] != t:                      # at a fixed gap the bridge's formation leaves the books unchanged
                assert books(g) == pytest.approx(prev[3], abs=1e-9 * dry.loop_energy)
        e = books(g)
        e0 = e if e0 is None else e0
        law.accept(g)
        prev = (g, f, t, e)
    d = law.dry
    assert d.detached_wet == 1 and d.detached == 0
    assert wet.loop_energy == pytest.approx(float(ref.loop_area(BETA, 0.028, 2e10)), rel=1e-9)
    assert wet.loop_energy < 0.1 * dry.loop_energy
    scale = max(wet.loop_energy, abs(d.switched), law.bridges.formed)
    assert prev[3] - e0 == pytest.approx(work, abs=2e-3 * scale)


def test_a_humid_member_runs_its_summits_at_the_wet_work_of_adhesion():
    """wet_silica (calibrated: measured W_SL, 'wet' solid adhesion) members: Maugis-Dugdale summits rebuilt at W_wet
    inside bridges, the bridges without the DMT pull (the summit law carries the solids' adhesion)."""
    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model.regime import first_impact_speed

    # elastic summits (plasticity off): the calibrated silicon's hardness makes psi > 0.6, and plastic summits keep
    # the dry loop inside a bridge (the next test)
    scene = resolve_scene("wet_silica", params="calibrated", overrides={"surfaces.roughness.mode": "ensemble",
                                                                        "physics.plasticity": "off"}).scene
    _, law = member_law(scene, 7, member_plan(scene, first_impact_speed(scene)))
    inside = law.describe()["inside_bridges"]
    assert inside["work_of_adhesion"] == pytest.approx(meniscus_parameters(scene)["work_of_adhesion_wet"])
    assert law.bridges.solid_pull == 0.0 and "maugis_dugdale" in inside["summit_law"]


def test_a_humid_plastic_member_runs_its_plastic_summits_at_the_wet_work_of_adhesion():
    """Where the summits yield (calibrated silicon, psi > 0.6) a member carries its bridges on plastic summits whose
    bridged ones follow the same Thornton-Ning law at W_wet (continuum.laws.wet_plastic_summits: same E*, radius,
    limiting pressure, range); the bridges take no DMT pull. With menisci.solid_adhesion = 'additive' they keep the
    dry law (the paper's additive bridges, no correction), and the record says why."""
    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model.regime import first_impact_speed

    scene = resolve_scene("wet_silica", params="calibrated", overrides={"surfaces.roughness.mode": "ensemble"}).scene
    _, law = member_law(scene, 7, member_plan(scene, first_impact_speed(scene)))
    inside = law.describe()["inside_bridges"]
    dry = law.describe()["summit_law"]
    assert inside["work_of_adhesion"] == pytest.approx(meniscus_parameters(scene)["work_of_adhesion_wet"])
    assert inside["summit_law"]["name"] == dry["name"] and "thornton_ning" in dry["name"]
    for key in ("e_star", "radius", "limiting_pressure"):
        assert inside["summit_law"][key] == dry[key]
    assert law.bridges.solid_pull == 0.0 and "W_wet" in law.record["solids_inside_bridges"]

    additive = resolve_scene("wet_silica", params="calibrated", overrides={
        "surfaces.roughness.mode": "ensemble", "menisci.solid_adhesion": "additive"}).scene
    _, law = member_law(additive, 7, member_plan(additive, first_impact_speed(additive)))
    assert "inside_bridges" not in law.describe() and "additive" in law.record["solids_inside_bridges"]
    assert law.bridges.solid_pull == 0.0


def test_a_humid_scene_reports_its_sticking_against_t_a():
    """result.json -> menisci_condensation_time: the scene's t_a and the estimate's range at its humidity and
    temperature, the stick probability at each t_a; at the paper's 40 % RH the range (ms) lies beyond every contact
    and no bridge formed, so every point is the scene's run, reused."""
    from continuum.dynamics.impact import run_impact

    over = {"surfaces.roughness.mode": "ensemble", "surfaces.roughness.members": 2, "numerics.max_bounces": 2}
    result = run_impact(resolve_scene("wet_silica", params="paper", overrides=over)).to_dict()
    block = result["menisci_condensation_time"]
    scene = resolve_scene("wet_silica", params="paper").scene
    lo, hi = block["range_s"]
    assert (lo, hi) == pytest.approx(men.nucleation_time_range(scene.environment.relative_humidity,
                                                               scene.environment.temperature), rel=1e-12)
    times = [p["condensation_time_s"] for p in block["points"]]
    assert times == sorted(times) and times[0] == 25e-6 and times[-1] == pytest.approx(hi) and len(times) == 6
    assert not block["bridges_formed"] and block["longest_contact_s"] < lo
    here = result["ensemble"]["stick_probability"]["within_run"]["value"]
    assert all(p["stick_probability_within_run"] == here and p["how"] != "run again at this t_a"
               for p in block["points"])


def test_the_t_a_sweep_runs_again_exactly_the_points_that_can_differ(monkeypatch):
    """Points at or below the longest contact, or any point once a bridge formed, are run again; the others reuse the
    scene's run (bridges cannot form before t_a: the run is the same step for step)."""
    from continuum.dynamics import ensemble_run, wet_sweep

    resolved = resolve_scene("wet_silica", params="paper")
    asked = []

    class Fake:
        def __init__(self, t):
            self.t = t

        def to_record(self):
            return {"stick_probability": {"first_impact": {"value": 0.5, "interval": [0.3, 0.7]},
                                         "within_run": {"value": 0.75, "interval": [0.6, 0.9], "censored": 0}}}

    monkeypatch.setattr(ensemble_run, "run_ensemble",
                        lambda r, **kw: (asked.append(r.scene.menisci.condensation_time), Fake(0))[1])
    lo, hi = men.nucleation_time_range(0.4, resolved.scene.environment.temperature)
    longest = math.sqrt(lo * hi)                      # between the range's ends
    member = {"menisci": {"longest_contact_s": longest, "contacts_with_bridges": 0}}
    ens = {"stick_probability": {"first_impact": {"value": 0.0, "interval": [0.0, 0.06]},
                                 "within_run": {"value": 0.0, "interval": [0.0, 0.06], "censored": 0}},
           "member_runs": [member, member]}
    block = wet_sweep.condensation_sweep(resolved, {"ensemble": ens}, rerun=run_impact)
    expect = [t for t in wet_sweep.t_a_grid(25e-6, lo, hi) if t != 25e-6 and t <= longest]
    assert asked == expect and len(expect) >= 2
    for p in block["points"]:
        rerun = p["condensation_time_s"] in expect
        assert (p["how"] == "run again at this t_a") == rerun
        assert p["stick_probability_within_run"] == (0.75 if rerun else 0.0)
    asked.clear()
    member["menisci"]["contacts_with_bridges"] = 1    # a bridge formed: every other point can differ
    wet_sweep.condensation_sweep(resolved, {"ensemble": ens}, rerun=run_impact)
    assert len(asked) == len(wet_sweep.t_a_grid(25e-6, lo, hi)) - 1


def test_a_humid_discrete_run_carries_its_bridges_on_plastic_summits_and_the_mean_field_says_why_not():
    """A single realisation (mode 'discrete') of the yielding calibrated summits with menisci on runs the same law as
    an ensemble member: plastic summits, bridged ones at W_wet. The mean field's bridges wrap elastic summits, so there
    the summits stay elastic and the plasticity record names that reason."""
    from continuum.model import select_law
    from continuum.model.regime import first_impact_speed

    wet = {"menisci.condensation_model": "fixed", "menisci.condensation_time": 1e-6}
    one = resolve_scene("wet_silica", params="calibrated", overrides={**wet, "surfaces.roughness.mode": "discrete"})
    law, models = select_law(one.scene, first_impact_speed(one.scene), menisci=True)
    assert models["plasticity"]["used"] is True
    assert law.describe()["inside_bridges"]["work_of_adhesion"] == pytest.approx(
        meniscus_parameters(one.scene)["work_of_adhesion_wet"])
    mean = resolve_scene("wet_silica", params="calibrated", overrides={**wet, "surfaces.roughness.mode": "mean_field"})
    _, models = select_law(mean.scene, first_impact_speed(mean.scene), menisci=True)
    assert models["plasticity"]["used"] is False and models["plasticity"]["summits_yield"] is True
    assert "mean field's bridges wrap elastic summits" in models["plasticity"]["why"]
