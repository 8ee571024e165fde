"""Capillary bridges: closed forms, the GW/footprint integrals, energy books, and the wet impact."""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from continuum.dynamics.impact import run_impact
from continuum.laws.wet import MeniscusBridges
from continuum.rough.gw import SummitStatistics
from continuum.scene import resolve_scene
from continuum.wet import menisci as men

ROOT = Path(__file__).resolve().parents[2]
SIGMA, DENSITY, BETA = 6e-9, 1e13, 0.2e-6
R, L = 5e-6, 3.28e-3
Z_TOP = 4.07 * SIGMA
F0, DK = 1.7e-7, 1.0765e-9
WET = {"environment.relative_humidity": 0.4, "surfaces.body.contact_angle": 20.0,
       "surfaces.substrate.contact_angle": 20.0, "physics.half_space": "off",
       "surfaces.roughness.mode": "mean_field"}        # menisci are modelled on the averaged GW law


# ------------------------------------------------------------------------------ closed forms
def test_kelvin_length_of_water_is_israelachvilis_0p54_nm():
    # Israelachvili, Intermolecular and Surface Forces (2011) §17: gamma V / RT = 0.54 nm for water at 20 C
    r = men.kelvin_radius(math.exp(-1.0), 293.15, 0.0728, 1.805e-5)
    assert r == pytest.approx(0.54e-9, rel=0.01, abs=0)


def test_kelvin_radius_inverts_the_kelvin_equation():
    for rh in (0.1, 0.4, 0.9):
        r = men.kelvin_radius(rh, 300.0, 0.072, 1.807e-5)
        assert math.exp(-0.072 * 1.807e-5 / (men.R_GAS * 300.0 * r)) == pytest.approx(rh, rel=1e-12, abs=0)


def test_bridge_pull_at_touch_is_the_sphere_flat_capillary_force():
    # Israelachvili eq 17.23: F = 4 pi R gamma cos(theta) for equal angles
    theta = math.radians(30.0)
    assert men.bridge_pull_off(BETA, 0.072, theta, theta) == pytest.approx(
        4 * math.pi * BETA * 0.072 * math.cos(theta), rel=1e-14, abs=0)
    assert men.bridge_pull_off(BETA, 0.072, math.radians(110), math.radians(110)) == 0.0
    assert men.kelvin_gap(1e-9, math.radians(110), math.radians(110)) == 0.0


def test_bridge_force_is_minus_the_derivative_of_its_energy_and_vanishes_at_rupture():
    g = np.linspace(-2 * DK, 1.2 * DK, 301)
    h = 1e-6 * DK
    fd = (men.bridge_energy(g + h, F0, DK) - men.bridge_energy(g - h, F0, DK)) / (2 * h)
    inside = np.abs(g) > 2 * h
    inside &= np.abs(g - DK) > 2 * h
    np.testing.assert_allclose(fd[inside], men.bridge_force(g, F0, DK)[inside], rtol=1e-6, atol=1e-9 * F0)
    assert float(men.bridge_force(0.0, F0, DK)) == pytest.approx(F0, rel=1e-15, abs=0)
    assert float(men.bridge_energy(DK, F0, DK)) == 0.0
    assert float(men.bridge_force(1.0001 * DK, F0, DK)) == 0.0
    # work of one bridge from touch to rupture: F0 D_K / 2 (triangle)
    assert -float(men.bridge_energy(0.0, F0, DK)) == pytest.approx(0.5 * F0 * DK, rel=1e-15, abs=0)


def test_nucleation_time_reproduces_szoszkiewicz_and_riedo():
    # fitted at 299 K (4.2 ms, 40 % RH); their other end, 0.7 ms at 332 K, is an independent check
    assert men.nucleation_condensation_time(0.4, 299.0) == pytest.approx(4.2e-3, rel=1e-12, abs=0)
    assert men.nucleation_condensation_time(0.4, 332.0) == pytest.approx(0.7e-3, rel=0.1, abs=0)
    assert men.nucleation_condensation_time(0.6, 299.0) < men.nucleation_condensation_time(0.4, 299.0)


def test_bridgeable_gap_grows_logarithmically_after_t_a_up_to_the_kelvin_gap():
    t_a, h1 = 25e-6, 0.3e-9
    assert men.bridgeable_gap(0.99 * t_a, t_a, h1, DK) == -math.inf
    assert men.bridgeable_gap(t_a, t_a, h1, DK) == 0.0
    assert men.bridgeable_gap(math.e * t_a, t_a, h1, DK) == pytest.approx(h1, rel=1e-14, abs=0)
    assert men.bridgeable_gap(1e6 * t_a, t_a, h1, DK) == DK


# ------------------------------------------------------------------------------ footprint integrals
def _bridges(t_a=25e-6):
    return MeniscusBridges(SummitStatistics(SIGMA, DENSITY, BETA), Z_TOP, R, L, F0, DK, t_a, 3.4e-10)


def _brute_force(fn, gap, s, *args):
    """The footprint sum of fn(gap of each summit) by trapezoids over x (across the roller) and, at each x, over the
    summit heights z from the attachment threshold (stretch u = s, summits below it hold no bridge) to the top, in two
    pieces split where the summit touches (u = gap: the law's kink, a step with a solid pull): Gaussian heights, the
    roller's parabola. With no step inside a piece the quadrature error falls as the square of the spacing (<= 3e-6 of
    the sum on this grid, 4x less at twice it)."""
    xmax = math.sqrt(2 * R * -s)
    x = np.linspace(-xmax, xmax, 1001)
    lift = x * x / (2 * R)
    z_lo = np.maximum(Z_TOP + s + lift, Z_TOP - 12e-9)
    z_touch = np.clip(Z_TOP + gap + lift, z_lo, Z_TOP)
    t = np.linspace(0.0, 1.0, 401)[None, :]
    total = np.zeros_like(x)
    # each piece evaluates its own side of the step at the touch point (stretched g > 0, compressed g <= 0)
    for a, b, side in ((z_lo, z_touch, lambda g: np.maximum(g, 1e-30)), (z_touch, np.full_like(x, Z_TOP),
                                                                          lambda g: np.minimum(g, 0.0))):
        Z = a[:, None] + (b - a)[:, None] * t
        u = Z - Z_TOP - lift[:, None]
        phi = np.exp(-0.5 * (Z / SIGMA) ** 2) / (SIGMA * math.sqrt(2 * math.pi))
        total += np.trapezoid(fn(side(gap - u), F0, DK, *args) * phi, Z, axis=1)
    return np.trapezoid(total, x) * L * DENSITY


@pytest.mark.parametrize("gap, s", [(-2e-9, -3e-9), (0.3e-9, -0.5e-9), (-5e-9, -5.5e-9), (-1e-9, -8e-9)])
def test_bridge_sum_matches_a_brute_force_grid_over_x_and_z(gap, s):
    b = _bridges()
    s = max(s, gap - DK)
    force, energy = _brute_force(men.bridge_force, gap, s), _brute_force(men.bridge_energy, gap, s)
    assert b._integral("force", gap, s) == pytest.approx(force, rel=2e-5, abs=0)
    assert b._integral("energy", gap, s) == pytest.approx(energy, rel=2e-5, abs=0)


def test_compiled_bridge_sum_is_the_numpy_sum_to_the_formulas_conditioning():
    """The compiled kernel (continuum.laws.bridge_kernel) against MeniscusBridges._integral_numpy on 3000 random
    states: every kind, open and closed ranges, formation-gap integrals. Both carry the closed form's cancellation
    (a thin strip of summits: c0 m0 + c1 m1 + c2 m2 with large terms); against 50-digit mpmath on the worst strips
    each erred by 2e-8 to 8e-6 of the strip's own value, the two forms each way round. So the tolerance is relative
    to the sum over every bridge within D_K of a deep contact (the scale the energy books see): measured 5e-9,
    bound 1e-7; and 1e-10 relative where the strip's value is itself that large."""
    b = _bridges()
    rng = np.random.default_rng(7)
    deep = {k: abs(b._integral_numpy(k, -2 * DK, -3 * DK)) for k in ("force", "energy", "count")}
    for _ in range(3000):
        gap = rng.uniform(-3, 1) * DK
        s_lo = gap - rng.uniform(0.0, 1.0) * DK
        kind = ("force", "energy", "count")[rng.integers(3)]
        formed = None
        if rng.random() < 0.3:
            kind, s_hi, formed = "energy", s_lo + rng.uniform(0, 1) * DK, tuple(rng.uniform(0, 1, 2) * DK)
        else:
            s_hi = math.inf if rng.random() < 0.7 else s_lo + rng.uniform(0, 2) * DK
        got = b._integral(kind, gap, s_lo, s_hi, formed)
        want = b._integral_numpy(kind, gap, s_lo, s_hi, formed)
        assert abs(got - want) <= 1e-7 * deep[kind] + 1e-10 * abs(want), (kind, gap, s_lo, s_hi, formed)
    assert b._integral("force", 2 * DK, DK) == 0.0 == b._integral_numpy("force", 2 * DK, DK)    # out of range


def test_formation_books_balance_the_work_of_the_bridges_on_a_prescribed_path():
    """dU_bridges = int F dgap - formation work, to second order in the step."""
    errors = []
    for steps in (40, 160):
        b = _bridges(t_a=5e-6)
        ts = np.linspace(5e-6, 10e-6, steps + 1)
        hs = -2.7e-9 - 4.2e-9 * ((ts - 5e-6) / 5e-6) ** 1.5
        b.accept(hs[0], ts[0])
        u0, formed0, work = b.energy(hs[0], ts[0]), b.formed, 0.0
        for i in range(steps):
            tt, hh = np.linspace(ts[i], ts[i + 1], 41), np.linspace(hs[i], hs[i + 1], 41)
            work += np.trapezoid([b.force(h, t) for h, t in zip(hh, tt)], hh)
            b.accept(hs[i + 1], ts[i + 1])
        du = b.energy(hs[-1], ts[-1]) - u0
        errors.append(abs(du - work + (b.formed - formed0)) / abs(du))
    assert errors[1] < 2e-4
    assert errors[1] < errors[0] / 8.0          # second order: 4x the steps, >= 8x smaller


# ------------------------------------------------------------------------------ wet impacts
def _scene(**ov):
    table = tomllib.loads((ROOT / "inputs" / "scenes" / "rough_silica.toml").read_text())
    del table["release_height"]
    return resolve_scene(table=table, overrides={**WET, "numerics.max_bounces": 1, **ov})


def test_bridges_cut_a_rebound_whose_contact_outlasts_t_a_and_the_books_close():
    dry = run_impact(_scene(impact_velocity=5.2e-4, **{"physics.menisci": "off"})).to_dict()
    wet = run_impact(_scene(impact_velocity=5.2e-4, **{"physics.menisci": "on",
                                                          "menisci.condensation_time": 15e-6})).to_dict()
    d, w = dry["bounces"][0], wet["bounces"][0]
    assert d["duration"] > 15e-6 and d["restitution"] > 0.3
    assert w["restitution"] < 0.8 * d["restitution"]
    assert wet["energy_audit"]["max_relative_error"] < 1e-4
    assert wet["models"]["diagnostics"]["menisci"]["max_bridges"] > 0


def test_many_bridges_pulling_the_roller_in_keep_the_energy_books():
    wet = run_impact(_scene(impact_velocity=5.2e-4, **{"physics.menisci": "on",
                                                          "menisci.condensation_time": 5e-6})).to_dict()
    assert wet["status"] == "stuck"
    assert wet["models"]["diagnostics"]["menisci"]["max_bridges"] > 10
    assert wet["energy_audit"]["max_relative_error"] < 1e-3
    assert wet["energy_audit"]["max_error_over_turnover"] < 1e-4


def test_contact_shorter_than_t_a_is_exactly_the_dry_impact():
    dry = run_impact(_scene(impact_velocity=1.4e-3, **{"physics.menisci": "off"})).to_dict()
    wet = run_impact(_scene(impact_velocity=1.4e-3, **{"physics.menisci": "on"})).to_dict()
    assert dry["bounces"][0]["duration"] < 25e-6
    # no bridge can form: the only difference is the table spacing (the wet law sizes its tables
    # for the bridges' pull as well), whose interpolation error is ~1e-7 (docs/rough-gw.md)
    assert wet["bounces"][0]["rebound_height"] == pytest.approx(dry["bounces"][0]["rebound_height"], rel=1e-6, abs=0)
    assert wet["models"]["diagnostics"]["menisci"]["max_bridges"] == 0.0


def test_auto_menisci_records_why_they_are_left_out():
    hydrophobic = run_impact(_scene(impact_velocity=1.4e-3, **{"surfaces.body.contact_angle": 110.0,
                                                                  "surfaces.substrate.contact_angle": 110.0})).to_dict()
    assert hydrophobic["models"]["menisci"]["used"] is False
    assert hydrophobic["models"]["menisci"]["decided_by"] == "contact_angles"
    short = run_impact(_scene(impact_velocity=1.4e-3)).to_dict()
    m = short["models"]["menisci"]
    assert m["used"] is False and m["decided_by"] == "longest_contact_time"
    assert m["longest_contact_s"] < m["condensation_time_s"] == 25e-6
    long = run_impact(_scene(impact_velocity=5.2e-4, **{"menisci.condensation_time": 15e-6})).to_dict()
    assert long["models"]["menisci"]["used"] is True
    assert long["models"]["menisci"]["longest_contact_s"] >= 15e-6


def test_wet_scene_without_contact_angles_is_refused_naming_the_key():
    from continuum.scene import SceneError
    table = tomllib.loads((ROOT / "inputs" / "scenes" / "rough_silica.toml").read_text())
    table["params"] = "silica"              # a set without water contact angles
    table["surfaces"] = {"work_of_adhesion": 0.1,
                         "roughness": {"sigma": 6e-9, "summit_density": 1e13, "summit_radius": 0.2e-6}}
    with pytest.raises(SceneError, match="surfaces.body.contact_angle = None: is required when environment"):
        resolve_scene(table=table, overrides={"environment.relative_humidity": 0.4})
    resolve_scene(table=table, overrides={"environment.relative_humidity": 0.4, "physics.menisci": "off"})


@pytest.mark.parametrize("rh", [0.0, 0.4, 1.0])
def test_condensation_time_is_computed_once_for_every_record(rh):
    """t_a comes from one function (continuum.model.regime.condensation_time) for the menisci's parameters and the
    regime record; with nucleation it is infinite without vapour and the attempt time at saturation (the barrier
    goes as ln(1/RH)); the regime record once guarded RH = 1 to infinity while the menisci did not."""
    from types import SimpleNamespace

    from continuum.dynamics.impact import regime_numbers
    from continuum.model.regime import condensation_time, regime_of

    scene = _scene(**{"menisci.condensation_model": "nucleation", "environment.relative_humidity": rh,
                      "impact_velocity": 1e-3,          # saturation is refused with menisci on (Kelvin radius)
                      **({"physics.menisci": "off"} if rh == 1.0 else {})}).scene
    t_a, source = condensation_time(scene)
    assert source.startswith("nucleation")
    if rh == 0.0:
        assert t_a == math.inf
    else:
        assert t_a == men.nucleation_condensation_time(rh, scene.environment.temperature) and math.isfinite(t_a)
    run = SimpleNamespace(bounces=[])
    assert regime_of(scene).condensation_time == t_a
    assert regime_numbers(scene, regime_of(scene), {}, run)["condensation_time_s"] == t_a
    if rh > 0.0 and rh < 1.0:
        from continuum.model.regime import meniscus_parameters
        assert meniscus_parameters(scene)["condensation_time"] == t_a


# ------------------------------------------------------------------------------ solid adhesion inside a bridge
def test_wet_work_of_adhesion_is_dupre_in_the_liquid():
    # Israelachvili 2011 §17.7 (combining relation): W_132 = W_12 + W_33 - W_13 - W_23 with W_33 = 2 gamma_lv and
    # the Young-Dupre W_i3 = gamma_lv (1 + cos theta_i); the formula under test writes it dgamma - gamma (c1 + c2)
    w12, gamma, t1, t2 = 0.12, 0.072, math.radians(20.0), math.radians(60.0)
    w132 = w12 + 2 * gamma - gamma * (1 + math.cos(t1)) - gamma * (1 + math.cos(t2))
    assert men.wet_work_of_adhesion(w12, gamma, t1, t2) == pytest.approx(w132, rel=1e-14, abs=0)
    # from the surface and interfacial energies directly: gamma_iL = gamma_i - gamma cos(theta_i) (Young)
    g1, g2 = 0.25, 0.20
    g12 = g1 + g2 - w12
    w_direct = (g1 - gamma * math.cos(t1)) + (g2 - gamma * math.cos(t2)) - g12
    assert men.wet_work_of_adhesion(w12, gamma, t1, t2) == pytest.approx(w_direct, rel=1e-14, abs=0)


@pytest.mark.parametrize("w12", [0.196, 0.05])
def test_wet_sphere_flat_pull_at_touch_is_the_dry_dmt_pull_not_dry_plus_the_bridge(w12):
    """r_K << beta: the solid pull under the liquid 2 pi beta max(W_wet, 0) plus the bridge's F0 (Israelachvili 2011
    eq 17.25: the wet pull-off equals the dry 2 pi beta dgamma when the liquid leaves the solids adhering)."""
    gamma, theta = 0.064, 0.0
    f0 = men.bridge_pull_off(BETA, gamma, theta, theta)
    solid = men.solid_pull_inside_bridge(BETA, w12, gamma, theta, theta, "wet")
    dry_dmt = 2 * math.pi * BETA * w12
    total = dry_dmt + float(men.bridge_force(0.0, f0, DK, solid))
    w_wet = w12 - 2 * gamma
    want = dry_dmt if w_wet >= 0 else f0      # W_wet < 0: no solid adhesion left, the bridge alone pulls
    assert total == pytest.approx(want, rel=1e-12, abs=0)
    assert men.solid_pull_inside_bridge(BETA, w12, gamma, theta, theta, "additive") == 0.0
    with pytest.raises(ValueError, match="solid_adhesion"):
        men.solid_pull_inside_bridge(BETA, w12, gamma, theta, theta, "both")


def test_bridge_force_with_solid_pull_is_the_derivative_of_its_energy():
    solid = 0.9 * F0
    g = np.linspace(-2 * DK, 1.2 * DK, 301)
    h = 1e-6 * DK
    fd = (men.bridge_energy(g + h, F0, DK, solid) - men.bridge_energy(g - h, F0, DK, solid)) / (2 * h)
    away = (np.abs(g) > 2 * h) & (np.abs(g - DK) > 2 * h)
    np.testing.assert_allclose(fd[away], men.bridge_force(g, F0, DK, solid)[away], rtol=1e-6, atol=1e-9 * F0)
    # energy continuous at touch: the solid term only acts on compressed summits
    assert float(men.bridge_energy(-1e-15 * DK, F0, DK, solid)) == pytest.approx(
        float(men.bridge_energy(1e-15 * DK, F0, DK, solid)), rel=1e-12, abs=0)


@pytest.mark.parametrize("gap, s", [(-2e-9, -3e-9), (-1e-9, -8e-9)])
def test_bridge_sum_with_solid_pull_matches_a_brute_force_grid(gap, s):
    solid = 0.8 * F0
    b = _bridges()
    b.set_solid_pull(solid)
    s = max(s, gap - DK)
    for kind, fn in (("force", men.bridge_force), ("energy", men.bridge_energy)):
        want = _brute_force(fn, gap, s, solid)
        assert b._integral(kind, gap, s) == pytest.approx(want, rel=2e-5, abs=0)
        assert b._integral_numpy(kind, gap, s) == pytest.approx(want, rel=2e-5, abs=0)


def test_a_set_that_declares_nothing_uses_the_wet_solid_adhesion_and_the_paper_set_declares_additive():
    from continuum.model import meniscus_parameters

    rec = {p: meniscus_parameters(resolve_scene(ROOT / "inputs" / "scenes" / "wet_silica.toml", params=p).scene)
           for p in ("paper", "silicon")}
    assert rec["paper"]["solid_adhesion"] == "additive" and rec["paper"]["solid_pull"] == 0.0
    assert rec["silicon"]["solid_adhesion"] == "wet" and rec["silicon"]["solid_pull"] > 0.0
