"""Specifications for the closed-form Hertz reference (continuum/reference/hertz.py).

Tolerances: 1e-10 relative unless stated; ODE cross-checks use solve_ivp at rtol 1e-12 and compare
to 1e-8 (the integrator's accumulated error, not the closed form, limits those). Event times are
the exception: solve_ivp locates events by brentq with xtol = rtol = 4 eps, an absolute tolerance
in seconds, which for ns-scale contacts is ~1e-7 relative; they are compared at EVENT_ATOL and then
refined on the dense output (xtol ~ 0) and compared at the integrator's accuracy.
"""
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from continuum.reference import hertz


def approx(expected, **kw):
    """pytest.approx without its default absolute tolerance of 1e-12 (meaningless in SI units)."""
    kw.setdefault("abs", 0.0)
    return pytest.approx(expected, **kw)

RTOL = 1e-10
EPS = np.finfo(float).eps
# scipy's event location (solve_event_equation: brentq, xtol = 4 EPS seconds) stops with the root
# inside a bracket narrower than 4 EPS (1 + t); twice that leaves room for the integrator's own
# phase error (~1e-13 relative here). A closed-form time wrong by 1e-6 (1e-14 s) still fails.
EVENT_ATOL = 8 * EPS


def refine_event(sol, t_event, component):
    """The event time re-solved on the dense output to rtol 4 eps with no absolute floor."""
    half = 1e-6 * t_event
    return brentq(lambda t: sol.sol(t)[component], t_event - half, t_event + half, xtol=1e-300, rtol=4 * EPS)

# The paper's roller: R = 5 um, l = 3.3 mm (solid Si, 0.6 ug), Si on Si E* ~ 90 GPa
R, L, E = 5e-6, 3.3e-3, 90e9
M = 0.6e-9
G = 9.81
V = math.sqrt(2 * G * 100e-9)  # released from 100 nm
LINE = (R, L, E)


# ------------------------------------------------------------------ modulus convention
def test_effective_modulus_is_johnsons_contact_modulus():
    e, nu = 169e9, 0.28
    assert hertz.effective_modulus(e, nu, e, nu) == approx(e / (2 * (1 - nu**2)), rel=1e-15)
    # rigid counterface: E* = E/(1 - nu^2)
    assert hertz.effective_modulus(e, nu, np.inf, 0.3) == approx(e / (1 - nu**2), rel=1e-15)


def test_line_half_width_is_the_papers_eq1_with_hamrocks_modulus_twice_johnsons():
    w = np.logspace(-9, 1, 11)
    e_prime = 2 * E  # Hamrock's reduced modulus
    b_paper_form = np.sqrt(8 * w * R / (np.pi * e_prime * L))
    np.testing.assert_allclose(hertz.line_half_width(w, *LINE), b_paper_form, rtol=1e-15)
    b = hertz.line_half_width(w, *LINE)
    np.testing.assert_allclose(hertz.line_peak_pressure(w, *LINE), 2 * w / (np.pi * b * L), rtol=1e-14)
    # the mean pressure over the strip is pi/4 of the peak (semi-elliptical profile)
    np.testing.assert_allclose(w / (2 * b * L), np.pi / 4 * hertz.line_peak_pressure(w, *LINE), rtol=1e-14)


# ------------------------------------------------------------------ roller log law
def test_secant_stiffness_reproduces_the_load_of_its_own_approach():
    w = np.logspace(-12, 2, 30)
    k = hertz.line_stiffness(w, *LINE)
    np.testing.assert_allclose(k * hertz.line_approach(w, *LINE), w, rtol=1e-14)
    assert hertz.line_stiffness(0.0, *LINE) == 0.0


def test_line_force_inverts_line_approach_to_1e12_over_fourteen_decades_of_load():
    w = np.logspace(-12, 2, 141)
    np.testing.assert_allclose(hertz.line_force(hertz.line_approach(w, *LINE), *LINE), w, rtol=1e-12)
    # and for other geometries, broadcasting over parameter arrays
    rng = np.random.default_rng(2)
    r = 10 ** rng.uniform(-7, -2, 20)
    l = 10 ** rng.uniform(-4, -1, 20)
    e = 10 ** rng.uniform(9, 11.3, 20)
    w = 10 ** rng.uniform(-10, 0, 20)
    np.testing.assert_allclose(hertz.line_force(hertz.line_approach(w, r, l, e), r, l, e), w, rtol=1e-12)


def test_line_force_is_zero_without_contact_and_refuses_beyond_the_validity_limit():
    assert hertz.line_force(0.0, *LINE) == 0.0
    np.testing.assert_array_equal(hertz.line_force([-1e-9, 0.0], *LINE), [0.0, 0.0])
    assert hertz.line_force(1e-300, *LINE) > 0.0  # underflowing Lambert argument handled
    dmax = hertz.line_max_approach(*LINE)
    # at the limit the half-width equals the roller length
    assert hertz.line_half_width(hertz.line_force(dmax, *LINE), *LINE) == approx(L, rel=1e-10)
    # ... for any geometry: the limit check must not rest on last bits (it once compared against
    # e^{C - q} q, whose rounding ~|C| eps, C up to ~40, exceeded its 1e-14 slack for 1 in 2e4 of these)
    rng = np.random.default_rng(0)
    r, l, e = (10 ** rng.uniform(-7, -2, 20000), 10 ** rng.uniform(-4, -1, 20000),
               10 ** rng.uniform(9, 11.3, 20000))
    w_lim = hertz.line_force(hertz.line_max_approach(r, l, e), r, l, e)
    np.testing.assert_allclose(hertz.line_half_width(w_lim, r, l, e), l, rtol=1e-10)
    with pytest.raises(ValueError, match="half-width"):
        hertz.line_force(1.01 * dmax, *LINE)
    with pytest.raises(ValueError, match="half-width"):
        hertz.line_approach(2 * float(hertz.line_force(dmax, *LINE)), *LINE)


def test_line_force_is_the_lower_lambert_branch_whose_stiffness_is_positive():
    d = np.logspace(-15, -6, 50)
    w = hertz.line_force(d, *LINE)
    assert np.all(np.diff(w) > 0)
    assert np.all(hertz.line_stiffness_tangent(d, *LINE) > 0)
    # the log factor 2 ln(2l/b) + 1 exceeds 1 (the other branch would have it below 1)
    b = hertz.line_half_width(w, *LINE)
    assert np.all(2 * np.log(2 * L / b) + 1 > 1)


def test_line_tangent_stiffness_equals_finite_difference_of_line_force():
    d = np.logspace(-14, -7, 15)
    h = 1e-3 * d
    f = lambda x: hertz.line_force(x, *LINE)  # noqa: E731
    fd = (45 * (f(d + h) - f(d - h)) - 9 * (f(d + 2 * h) - f(d - 2 * h)) + (f(d + 3 * h) - f(d - 3 * h))) / (60 * h)
    np.testing.assert_allclose(hertz.line_stiffness_tangent(d, *LINE), fd, rtol=1e-10)
    # tangent exceeds secant (W/delta grows with delta)
    assert np.all(hertz.line_stiffness_tangent(d, *LINE) > f(d) / d)


def test_line_energy_equals_quadrature_of_the_force():
    for d in (1e-15, 1e-12, 6e-12, 1e-9, 1e-6):
        ref, _ = quad(lambda x: hertz.line_force(x, *LINE), 0.0, d, epsabs=0, epsrel=1e-13, limit=200)
        assert hertz.line_energy(d, *LINE) == approx(ref, rel=RTOL)
    assert hertz.line_energy(-1e-9, *LINE) == 0.0


# ------------------------------------------------------------------ impact closed forms
def test_linear_oscillator_impact_without_gravity_is_paper_eq2():
    k = 3e7
    out = hertz.linear_oscillator_impact(M, k, V)
    assert out["max_approach"] == approx(V * math.sqrt(M / k), rel=1e-15)
    assert out["contact_time"] == approx(math.pi * math.sqrt(M / k), rel=1e-15)
    assert out["contact_time"] == approx(math.pi * out["max_approach"] / V, rel=1e-15)
    assert out["rebound_velocity"] == V


@pytest.mark.parametrize("gravity_scale", [0.0, 1.0, 3e4])
def test_linear_oscillator_closed_form_solves_its_equation_of_motion(gravity_scale):
    k, g = 3e7, G * gravity_scale  # 3e4 g makes the static sag comparable to v/omega
    out = hertz.linear_oscillator_impact(M, k, V, gravity=g)

    def rhs(t, y):
        return [y[1], g - k / M * y[0]]

    def release(t, y):
        return y[0]
    release.terminal, release.direction = True, -1

    def turning(t, y):
        return y[1]
    turning.direction = -1

    sol = solve_ivp(rhs, (0, 10 * out["contact_time"]), [0.0, V], method="DOP853", rtol=1e-12, atol=1e-30,
                    events=(release, turning), dense_output=True)
    t_end = sol.t_events[0][0]
    t_max = sol.t_events[1][0]
    # event times carry scipy's absolute event xtol (EVENT_ATOL, ~1e-7 of these 10 ns times) ...
    assert t_end == approx(out["contact_time"], rel=1e-8, abs=EVENT_ATOL)
    assert t_max == approx(out["time_of_max"], rel=1e-8, abs=EVENT_ATOL)
    # ... re-solved on the dense output they match to the integrator's accuracy (~1e-13 measured)
    assert refine_event(sol, t_end, 0) == approx(out["contact_time"], rel=1e-10)
    assert refine_event(sol, t_max, 1) == approx(out["time_of_max"], rel=1e-10)
    # delta is flat at the turning point, so its value is far sharper than its time
    assert sol.sol(t_max)[0] == approx(out["max_approach"], rel=1e-10)
    # the ODE velocity vanishes at the closed-form time of maximum
    v_scale = np.hypot(V, out["omega"] * out["static_approach"])
    assert abs(sol.sol(out["time_of_max"])[1]) < 1e-8 * v_scale
    assert -sol.y_events[0][0][1] == approx(out["rebound_velocity"], rel=1e-8)
    # and the closed-form trajectory satisfies the ODE pointwise
    w, ds = out["omega"], out["static_approach"]
    t = np.linspace(0, out["contact_time"], 7)
    np.testing.assert_allclose(ds * (1 - np.cos(w * t)) + V / w * np.sin(w * t), sol.sol(t)[0],
                               rtol=0, atol=1e-8 * out["max_approach"])


def test_line_impact_max_approach_balances_energy_and_matches_the_integrated_impact():
    d = hertz.line_impact_max_approach(M, V, *LINE)
    assert hertz.line_energy(d, *LINE) == approx(0.5 * M * V**2, rel=1e-14)
    dg = hertz.line_impact_max_approach(M, V, *LINE, gravity=G)
    assert hertz.line_energy(dg, *LINE) == approx(0.5 * M * V**2 + M * G * dg, rel=1e-14)
    assert dg > d

    def rhs(t, y):
        return [y[1], G - float(hertz.line_force(y[0], *LINE)) / M]

    def turning(t, y):
        return y[1]
    turning.terminal, turning.direction = True, -1
    t_scale = math.pi * math.sqrt(M / float(hertz.line_stiffness_tangent(dg, *LINE)))
    sol = solve_ivp(rhs, (0, 10 * t_scale), [0.0, V], method="DOP853", rtol=1e-12, atol=1e-12 * dg,
                    events=turning)
    assert sol.y_events[0][0][0] == approx(dg, rel=1e-8)
    # the scale check of the paper notes: smooth Hertz roller, delta_max ~ 6 pm, t ~ 14 ns
    k = hertz.line_stiffness(hertz.line_force(d, *LINE), *LINE)
    assert 5e-12 < d < 7e-12
    assert 13e-9 < hertz.linear_oscillator_impact(M, k, V)["contact_time"] < 15e-9


def test_line_impact_max_approach_with_gravity_only_is_below_twice_static_and_broadcasts():
    d = hertz.line_impact_max_approach(M, 0.0, *LINE, gravity=G)
    d_static = hertz.line_approach(M * G, *LINE)
    assert d_static < d < 2 * d_static  # stiffening spring: less than the linear 2x
    ds = hertz.line_impact_max_approach(M, np.array([0.5, 1.0, 2.0]) * V, *LINE)
    assert ds.shape == (3,) and np.all(np.diff(ds) > 0)
    assert hertz.line_impact_max_approach(M, 0.0, *LINE) == 0.0


# ------------------------------------------------------------------ sphere
def test_sphere_impact_time_constant_equals_quadrature():
    # 2 int_0^1 (1 - x^{5/2})^{-1/2} dx, with the (1 - x)^{-1/2} end singularity as a quad weight
    ref, _ = quad(lambda x: np.sqrt((1 - x) / (1 - x**2.5)) if x < 1 else np.sqrt(0.4), 0, 1,
                  weight="alg", wvar=(0, -0.5), epsabs=0, epsrel=1e-13)
    assert hertz.SPHERE_IMPACT_TIME_CONSTANT == approx(2 * ref, rel=RTOL)
    assert round(hertz.SPHERE_IMPACT_TIME_CONSTANT, 4) == 2.9433


def test_sphere_force_stiffness_energy_are_consistent_derivatives():
    r, e = 1e-6, 70e9
    d = np.logspace(-12, -8, 9)
    h = 1e-4 * d
    u = lambda x: hertz.sphere_energy(x, r, e)  # noqa: E731
    f = lambda x: hertz.sphere_force(x, r, e)  # noqa: E731
    np.testing.assert_allclose((8 * (u(d + h) - u(d - h)) - (u(d + 2 * h) - u(d - 2 * h))) / (12 * h), f(d), rtol=1e-10)
    np.testing.assert_allclose((8 * (f(d + h) - f(d - h)) - (f(d + 2 * h) - f(d - 2 * h))) / (12 * h),
                               hertz.sphere_stiffness(d, r, e), rtol=1e-10)
    np.testing.assert_allclose(hertz.sphere_stiffness(d, r, e), 2 * e * hertz.sphere_contact_radius(d, r), rtol=1e-15)
    assert hertz.sphere_force(-1e-9, r, e) == 0.0 and hertz.sphere_energy(-1e-9, r, e) == 0.0


def test_sphere_impact_closed_form_matches_the_integrated_impact():
    r, e, m, v = 1e-6, 70e9, 1e-12, 0.1
    out = hertz.sphere_impact(m, v, r, e)
    assert hertz.sphere_energy(out["max_approach"], r, e) == approx(0.5 * m * v**2, rel=1e-14)
    assert out["peak_force"] == approx(hertz.sphere_force(out["max_approach"], r, e), rel=1e-14)

    def rhs(t, y):
        return [y[1], -float(hertz.sphere_force(y[0], r, e)) / m]

    def release(t, y):
        return y[0]
    release.terminal, release.direction = True, -1

    def turning(t, y):
        return y[1]
    turning.direction = -1
    # start just inside contact (delta = 0 is a root of the event): the force ~ delta^{3/2} is
    # negligible over t0, so delta(t0) = v t0 to ~1e-15 relative
    t0 = 1e-6 * out["contact_time"]
    sol = solve_ivp(rhs, (t0, 2 * out["contact_time"]), [v * t0, v], method="DOP853", rtol=1e-12,
                    atol=1e-14 * out["max_approach"], events=(release, turning), dense_output=True)
    # event times: scipy's absolute event xtol (EVENT_ATOL) is 2e-8 of this 50 ns contact
    assert sol.t_events[0][0] == approx(out["contact_time"], rel=1e-8, abs=EVENT_ATOL)
    assert sol.y_events[1][0][0] == approx(out["max_approach"], rel=1e-10)
    assert sol.t_events[1][0] == approx(out["contact_time"] / 2, rel=1e-8, abs=EVENT_ATOL)
    # refined on the dense output: integrator-limited
    assert refine_event(sol, sol.t_events[0][0], 0) == approx(out["contact_time"], rel=1e-10)
    assert refine_event(sol, sol.t_events[1][0], 1) == approx(out["contact_time"] / 2, rel=1e-10)
