"""Specifications for the closed-form JKR reference (continuum/reference/jkr.py).

Tolerances: 1e-10 relative unless stated; looser ones are justified where they appear (near the
fold delta = -delta_c the inverse is conditioned like sqrt(eps), finite differences are limited by
truncation/rounding). Nothing here may depend on the last bits a given CPU's libm or SIMD paths
produce: at the fold those bits decide which side of -d_c the caller's delta/delta0 falls on.
"""
import numpy as np
import pytest
from scipy.integrate import quad

from continuum.reference import jkr


def approx(expected, **kw):
    """pytest.approx without its default absolute tolerance of 1e-12 (meaningless in SI units)."""
    kw.setdefault("abs", 0.0)
    return pytest.approx(expected, **kw)

RTOL = 1e-10
# At the fold delta = -delta_c, s^4 - s = d has a double root: an input error of k eps in
# d = delta/delta0 (critical_approach and delta0 are rounded separately, so -delta_c/delta0 sits a
# few eps either side of -d_c depending on the CPU's cbrt) moves the root by
# sqrt(2 k eps d_c / 12 s_f^2) = 0.45 sqrt(k eps), i.e. P by 1.7 sqrt(k eps) and a by
# 1.4 sqrt(k eps) relative (one ulp: 1.9e-8 in P). 8 sqrt(eps) = 1.2e-7 covers ~20 eps of input
# error; a constant wrong by 1e-6 still fails.
FOLD_RTOL = 8 * np.sqrt(np.finfo(float).eps)

# A silica-like asperity: beta = 100 nm, dgamma = 0.1 J/m^2, E* = 50 GPa
BETA, DGAMMA, ESTAR = 1e-7, 0.1, 50e9
P = (BETA, DGAMMA, ESTAR)


def random_parameter_sets(n=25, seed=1):
    rng = np.random.default_rng(seed)
    beta = 10 ** rng.uniform(-9, -5, n)       # 1 nm .. 10 um
    dgamma = 10 ** rng.uniform(-3, 0, n)      # 1e-3 .. 1 J/m^2
    estar = 10 ** rng.uniform(9, np.log10(200e9), n)  # 1 .. 200 GPa
    return beta, dgamma, estar


@pytest.fixture
def scales():
    pc = jkr.pull_off_force(BETA, DGAMMA)
    dc = jkr.critical_approach(*P)
    a0 = jkr.contact_radius_at_touch(*P)
    return pc, dc, a0


# ------------------------------------------------------------------ named points
def test_touch_force_is_minus_eight_ninths_pull_off(scales):
    pc, _, _ = scales
    assert jkr.force_from_approach(0.0, *P) == approx(-8 / 9 * pc, rel=RTOL)
    assert jkr.touch_force(BETA, DGAMMA) == approx(-8 / 9 * pc, rel=RTOL)
    assert jkr.force_from_radius(jkr.contact_radius_at_touch(*P), *P) == approx(-8 / 9 * pc, rel=RTOL)


def test_force_at_displacement_controlled_separation_is_minus_five_ninths_pull_off(scales):
    pc, dc, _ = scales
    # through the root at the fold: sqrt(eps)-conditioned (see FOLD_RTOL)
    assert jkr.force_from_approach(-dc, *P) == approx(-5 / 9 * pc, rel=FOLD_RTOL)
    # closed form: to rounding
    assert jkr.critical_approach_force(BETA, DGAMMA) == approx(-5 / 9 * pc, rel=RTOL)


def test_critical_approach_is_the_minimum_of_the_approach_radius_law(scales):
    _, dc, a0 = scales
    # d delta/da = 0 at a = 4^{-2/3} a0; delta there is -delta_c
    a_fold = 4 ** (-2 / 3) * a0
    assert jkr.approach_from_radius(a_fold, *P) == approx(-dc, rel=RTOL)
    a = a0 * np.linspace(0.01, 3, 20001)
    assert np.min(jkr.approach_from_radius(a, *P)) >= -dc * (1 + 1e-14)


def test_paper_eq7_form_equals_closed_form_critical_approach():
    beta, dgamma, estar = random_parameter_sets()
    np.testing.assert_allclose(jkr.critical_approach_eq7(beta, dgamma, estar),
                               jkr.critical_approach(beta, dgamma, estar), rtol=RTOL)


def test_minimum_force_is_minus_pull_off_at_the_load_controlled_point(scales):
    pc, dc, _ = scales
    d_load = jkr.load_controlled_detach_approach(*P)
    assert jkr.force_from_approach(d_load, *P) == approx(-pc, rel=RTOL)
    assert jkr.force_from_radius(jkr.load_controlled_detach_radius(*P), *P) == approx(-pc, rel=RTOL)
    # it is the minimum along the whole stable branch
    d = np.linspace(-dc, 2 * dc, 20001)
    assert np.min(jkr.force_from_approach(d, *P)) >= -pc * (1 + 1e-12)
    # and the tangent stiffness vanishes there (relative to the stiffness scale P_c/delta_c)
    assert abs(jkr.stiffness_from_approach(d_load, *P)) < 1e-6 * pc / dc


def test_load_controlled_detach_approach_is_minus_three_to_minus_two_thirds_delta_c(scales):
    _, dc, _ = scales
    assert jkr.load_controlled_detach_approach(*P) / dc == approx(-(3 ** (-2 / 3)), rel=RTOL)
    assert jkr.LOAD_DETACH_APPROACH_RATIO == approx(-(3 ** (-2 / 3)), rel=1e-14)
    assert round(jkr.LOAD_DETACH_APPROACH_RATIO, 4) == -0.4807  # paper notes


# ------------------------------------------------------------------ inverse and branches
def test_stable_branch_is_the_larger_contact_radius_root(scales):
    _, dc, _ = scales
    d = -dc * np.linspace(0.001, 0.999, 101)
    a_s = jkr.radius_from_approach(d, *P, branch="stable")
    a_u = jkr.radius_from_approach(d, *P, branch="unstable")
    assert np.all(a_s > a_u)
    # both are roots
    np.testing.assert_allclose(jkr.approach_from_radius(a_s, *P), d, rtol=1e-9)
    np.testing.assert_allclose(jkr.approach_from_radius(a_u, *P), d, rtol=1e-9)
    # stable under displacement control: d delta/da > 0 on the stable, < 0 on the unstable root
    c = np.sqrt(2 * np.pi * DGAMMA / ESTAR)
    ddelta_da = lambda a: 2 * a / BETA - 0.5 * c / np.sqrt(a)  # noqa: E731
    assert np.all(ddelta_da(a_s) > 0) and np.all(ddelta_da(a_u) < 0)


def test_radius_from_approach_inverts_approach_from_radius_over_six_decades(scales):
    _, _, a0 = scales
    a = a0 * np.logspace(-3, 3, 601)
    s = np.sqrt(a / a0)
    sf = 4 ** (-1 / 3)
    delta = jkr.approach_from_radius(a, *P)
    # Away from the fold (|s - s_f| > 1e-3, where the inverse is well conditioned) to 1e-10.
    far = np.abs(s - sf) > 1e-3
    stable = s >= sf
    a_st = jkr.radius_from_approach(delta[stable & far], *P, branch="stable")
    a_un = jkr.radius_from_approach(delta[~stable & far], *P, branch="unstable")
    np.testing.assert_allclose(a_st, a[stable & far], rtol=RTOL)
    np.testing.assert_allclose(a_un, a[~stable & far], rtol=RTOL)


def test_inverse_near_the_fold_is_limited_only_by_sqrt_eps_conditioning(scales):
    _, dc, a0 = scales
    sf = 4 ** (-1 / 3)
    s = sf * (1 + np.logspace(-7, -3, 9))
    a = a0 * s**2
    a_rec = jkr.radius_from_approach(jkr.approach_from_radius(a, *P), *P)
    # delta error ~ eps delta_c maps to a-error ~ sqrt(eps) near the double root (FOLD_RTOL)
    np.testing.assert_allclose(a_rec, a, rtol=FOLD_RTOL)
    assert jkr.radius_from_approach(-dc, *P) == approx(a0 * sf**2, rel=FOLD_RTOL)


def test_no_contact_exists_below_minus_delta_c(scales):
    _, dc, _ = scales
    with pytest.raises(ValueError, match="delta_c"):
        jkr.radius_from_approach(-1.001 * dc, *P)
    with pytest.raises(ValueError, match="unstable"):
        jkr.radius_from_approach(0.1 * dc, *P, branch="unstable")
    # rounding in the caller's delta_c is tolerated
    jkr.force_from_approach(-dc * (1 + 1e-14), *P)


def test_functions_broadcast_over_arrays_of_parameters():
    beta, dgamma, estar = random_parameter_sets(7)
    dc = jkr.critical_approach(beta, dgamma, estar)
    d = np.outer([-0.9, -0.3, 0.0, 2.0], dc)
    f = jkr.force_from_approach(d, beta, dgamma, estar)
    assert f.shape == (4, 7)
    assert np.isscalar(jkr.force_from_approach(0.0, *P)) or np.ndim(jkr.force_from_approach(0.0, *P)) == 0


# ------------------------------------------------------------------ normalised forms
def test_eq5_and_eq8_normalisations_agree_with_dimensional_jkr_for_random_parameters():
    beta, dgamma, estar = random_parameter_sets(40, seed=7)
    rng = np.random.default_rng(3)
    a0 = jkr.contact_radius_at_touch(beta, dgamma, estar)
    a = a0 * 10 ** rng.uniform(-1, 1, beta.size)
    abar = jkr.normalised_radius(a, beta, dgamma, estar)
    p = jkr.force_from_radius(a, beta, dgamma, estar)
    d = jkr.approach_from_radius(a, beta, dgamma, estar)
    pc = jkr.pull_off_force(beta, dgamma)
    dc = jkr.critical_approach(beta, dgamma, estar)
    np.testing.assert_allclose(jkr.eq5_force(abar), p / (3 * np.pi * dgamma * beta), rtol=RTOL)
    scale5 = np.cbrt(16 * estar**2 / (9 * np.pi**2 * dgamma**2 * beta))
    np.testing.assert_allclose(jkr.eq5_approach(abar), d * scale5, rtol=RTOL)
    np.testing.assert_allclose(jkr.eq8_force(abar), p / pc, rtol=RTOL)
    np.testing.assert_allclose(jkr.eq8_approach(abar), d / dc, rtol=RTOL)
    # eq 8's first (garbled) line is the conversion between the two normalisations
    np.testing.assert_allclose(jkr.eq5_force(abar), jkr.eq8_force(abar) / 2, rtol=RTOL)
    np.testing.assert_allclose(jkr.eq5_approach(abar), (3 / 4) ** (1 / 3) * jkr.eq8_approach(abar), rtol=RTOL)
    # the eq 8 prefactor 2.29 is 324^{1/3}/3 = 12^{1/3}
    assert np.cbrt(324) / 3 == approx(12 ** (1 / 3), rel=1e-15)
    assert round(12 ** (1 / 3), 2) == 2.29


def test_normalised_force_from_approach_matches_dimensional_stable_branch():
    beta, dgamma, estar = random_parameter_sets(30, seed=11)
    x = np.linspace(-1, 3, 30)
    dc = jkr.critical_approach(beta, dgamma, estar)
    pc = jkr.pull_off_force(beta, dgamma)
    pn = jkr.normalised_force_from_approach(x)
    pd = jkr.force_from_approach(x * dc, beta, dgamma, estar) / pc
    # x = -1 is the fold: x d_c and x delta_c / delta0 differ by rounding there, and the double
    # root turns that into sqrt(eps) (FOLD_RTOL); elsewhere both are well-conditioned roots.
    np.testing.assert_allclose(pn[1:], pd[1:], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(pn[0], pd[0], rtol=FOLD_RTOL, atol=0)


def test_both_branches_at_half_delta_c_match_the_paper_notes():
    assert jkr.normalised_force_from_approach(-0.5) == approx(-0.9998, abs=5e-5)
    assert jkr.normalised_force_from_approach(-0.5, branch="unstable") == approx(-0.036, abs=5e-4)


# ------------------------------------------------------------------ energy, stiffness, loops
def test_energy_derivative_equals_force_by_complex_step(scales):
    _, _, a0 = scales
    a = a0 * np.linspace(4 ** (-2 / 3) * 1.01, 5.0, 50)
    h = 1e-30 * a0
    du = np.imag(jkr.energy_from_radius(a + 1j * h, *P)) / h
    dd = np.imag(jkr.approach_from_radius(a + 1j * h, *P)) / h
    np.testing.assert_allclose(du / dd, jkr.force_from_radius(a, *P), rtol=1e-12)


def test_energy_derivative_equals_force_by_sixth_order_finite_difference(scales):
    pc, dc, _ = scales
    d = dc * np.array([-0.9, -0.6, -0.3, -0.05, 0.2, 1.0, 4.0])
    h = 2e-3 * dc
    u = lambda x: jkr.energy_from_approach(x, *P)  # noqa: E731
    du = (45 * (u(d + h) - u(d - h)) - 9 * (u(d + 2 * h) - u(d - 2 * h)) + (u(d + 3 * h) - u(d - 3 * h))) / (60 * h)
    # truncation ~ h^6 f^(7) and rounding ~ eps U/h keep this at ~1e-11 of P_c
    np.testing.assert_allclose(du, jkr.force_from_approach(d, *P), rtol=0, atol=1e-10 * pc)


def test_energy_is_zero_at_touch_and_equals_quadrature_of_the_force(scales):
    pc, dc, _ = scales
    assert jkr.energy_from_approach(0.0, *P) == 0.0
    for d in (-dc, -0.5 * dc, -1e-6 * dc, 1e-6 * dc, 0.7 * dc, 5 * dc):
        ref, _ = quad(lambda x: jkr.force_from_approach(x, *P), 0.0, d, epsabs=0, epsrel=1e-13, limit=200)
        assert jkr.energy_from_approach(d, *P) == approx(ref, rel=RTOL)
    # small |delta|: U = P(0) delta to first order, kept at full relative precision
    d = 1e-9 * dc
    assert jkr.energy_from_approach(d, *P) == approx(-8 / 9 * pc * d, rel=1e-8)


def test_energy_from_radius_equals_energy_from_approach_on_the_stable_branch(scales):
    _, dc, _ = scales
    d = dc * np.linspace(-0.99, 3, 41)
    a = jkr.radius_from_approach(d, *P)
    np.testing.assert_allclose(jkr.energy_from_radius(a, *P), jkr.energy_from_approach(d, *P),
                               rtol=1e-9, atol=1e-14 * jkr.loop_area(*P))


def test_tangent_stiffness_equals_finite_difference_of_force(scales):
    pc, dc, _ = scales
    d = dc * np.array([-0.8, -0.4807, -0.2, 0.0, 0.5, 2.0])
    h = 1e-4 * dc
    f = lambda x: jkr.force_from_approach(x, *P)  # noqa: E731
    fd = (8 * (f(d + h) - f(d - h)) - (f(d + 2 * h) - f(d - 2 * h))) / (12 * h)
    np.testing.assert_allclose(jkr.stiffness_from_approach(d, *P), fd, rtol=0, atol=1e-8 * pc / dc)


def test_tangent_stiffness_is_infinite_at_minus_delta_c(scales):
    """The singular value is tested as a limit from the valid side, delta -> -delta_c^+.

    With x = 1 + delta/delta_c, delta + delta_c = 6 s_f^2 delta0 (s - s_f)^2 and
    4 s^3 - 1 = 12 s_f^2 (s - s_f), so dP/d delta = -(sqrt(2)/3) (P_c/delta_c) / sqrt(x) (1 + O(sqrt x))
    on the stable branch and +(sqrt(2)/3) ... on the unstable one: |k| exceeds any bound. The
    computed s carries an error ~ eps/(2x) relative to s - s_f, so the coefficient is checked to
    1e-3 for 1e-12 <= x <= 1e-6 (conditioning <= 1.1e-4 at 1e-12, truncation 1.2e-4 at 1e-6).
    """
    pc, dc, _ = scales
    coef = np.sqrt(2) / 3 * pc / dc
    x = np.logspace(-3, -12, 10)
    k = jkr.stiffness_from_approach(-dc * (1 - x), *P)
    ku = jkr.stiffness_from_approach(-dc * (1 - x), *P, branch="unstable")
    assert np.all(np.isfinite(k)) and np.all(np.isfinite(ku))
    assert np.all(np.diff(k) < 0) and np.all(np.diff(ku) > 0)  # |k| grows monotonically
    assert np.all(-k > 0.4 * pc / dc / np.sqrt(x)) and np.all(ku > 0.4 * pc / dc / np.sqrt(x))
    near = x <= 1e-6
    np.testing.assert_allclose(k[near] * np.sqrt(x[near]), -coef, rtol=1e-3)
    np.testing.assert_allclose(ku[near] * np.sqrt(x[near]), coef, rtol=1e-3)
    # At the fold itself (the caller's delta_c, whichever side of the exact fold rounding puts it,
    # and within the documented slack below it) the function returns the limit, +-inf.
    assert jkr.stiffness_from_approach(-dc, *P) == -np.inf
    assert jkr.stiffness_from_approach(-dc, *P, branch="unstable") == np.inf
    assert jkr.stiffness_from_approach(-dc * (1 + 1e-14), *P) == -np.inf
    beta, dgamma, estar = random_parameter_sets(500, seed=13)
    dcs = jkr.critical_approach(beta, dgamma, estar)
    assert np.all(jkr.stiffness_from_approach(-dcs, beta, dgamma, estar) == -np.inf)
    assert np.isfinite(jkr.stiffness_from_approach(-0.999 * dc, *P))


def test_loop_area_coefficients_equal_quadrature_of_the_stable_branch(scales):
    pc, dc, _ = scales
    for detach, coef, d_end in (("displacement", jkr.LOOP_AREA_DISPLACEMENT, -dc),
                                ("load", jkr.LOOP_AREA_LOAD, jkr.load_controlled_detach_approach(*P))):
        ref, _ = quad(lambda x: -jkr.force_from_approach(x, *P), d_end, 0.0, epsabs=0, epsrel=1e-13, limit=200)
        assert jkr.loop_area(*P, detachment=detach) == approx(ref, rel=RTOL)
        assert coef * pc * dc == approx(ref, rel=RTOL)


def test_loop_area_coefficients_match_their_algebraic_closed_forms_and_the_notes():
    c4, c3 = 4 ** (1 / 3), 3 ** (1 / 3)
    assert jkr.LOOP_AREA_DISPLACEMENT == approx(8 / 90 + 8 / 15 * c4, rel=1e-14)
    assert jkr.LOOP_AREA_LOAD == approx(8 / 15 * c4 - 4 / 15 * c3, rel=1e-14)
    assert round(jkr.LOOP_AREA_DISPLACEMENT, 5) == 0.93550
    assert round(jkr.LOOP_AREA_LOAD, 5) == 0.46201


def test_loop_area_scales_as_pull_off_force_times_delta_c_for_random_parameters():
    beta, dgamma, estar = random_parameter_sets(20, seed=5)
    pc = jkr.pull_off_force(beta, dgamma)
    dc = jkr.critical_approach(beta, dgamma, estar)
    np.testing.assert_allclose(jkr.loop_area(beta, dgamma, estar), jkr.LOOP_AREA_DISPLACEMENT * pc * dc, rtol=RTOL)
    np.testing.assert_allclose(jkr.energy_from_approach(-dc, beta, dgamma, estar),
                               jkr.LOOP_AREA_DISPLACEMENT * pc * dc, rtol=1e-9)
    with pytest.raises(ValueError, match="detachment"):
        jkr.loop_area(*P, detachment="force")
