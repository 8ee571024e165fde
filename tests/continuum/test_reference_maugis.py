"""Specifications for the DMT and Maugis-Dugdale references (continuum/reference/maugis.py).

Tolerances are stated per test. The pull-off limits are asymptotic in lambda, so their tolerances
are the brief's (2% at lambda = 0.01, 1% at lambda = 30); measured errors are far smaller.
"""
import numpy as np
import pytest

from continuum.reference import hertz, jkr, maugis


def approx(expected, **kw):
    """pytest.approx without its default absolute tolerance of 1e-12 (meaningless in SI units)."""
    kw.setdefault("abs", 0.0)
    return pytest.approx(expected, **kw)


# beta = 100 nm, dgamma = 0.1 J/m^2, E* = 50 GPa
BETA, DGAMMA, ESTAR = 1e-7, 0.1, 50e9


def sigma0_for(lam, beta=BETA, dgamma=DGAMMA, estar=ESTAR):
    """Dugdale stress giving Maugis parameter lam (inverse of md_parameter)."""
    return lam / np.cbrt(9.0 * beta / (2.0 * np.pi * dgamma * estar**2))


# ---------------------------------------------------------------------------------------------
# DMT
# ---------------------------------------------------------------------------------------------
def test_dmt_pull_off_is_two_pi_beta_dgamma():
    assert maugis.dmt_pull_off_force(BETA, DGAMMA) == approx(2 * np.pi * BETA * DGAMMA, rel=1e-15)
    # = the DMT force at delta = 0, magnitude
    assert -maugis.dmt_force_from_approach(0.0, BETA, DGAMMA, ESTAR) == approx(
        2 * np.pi * BETA * DGAMMA, rel=1e-15)


def test_dmt_force_is_hertz_minus_constant():
    d = np.geomspace(1e-12, 1e-8, 9)
    expected = hertz.sphere_force(d, BETA, ESTAR) - 2 * np.pi * BETA * DGAMMA
    assert maugis.dmt_force_from_approach(d, BETA, DGAMMA, ESTAR) == approx(expected, rel=1e-12)
    with pytest.raises(ValueError):
        maugis.dmt_force_from_approach(-1e-10, BETA, DGAMMA, ESTAR)


# ---------------------------------------------------------------------------------------------
# Maugis-Dugdale: parameter and normalisation
# ---------------------------------------------------------------------------------------------
def test_lambda_conventions_agree():
    """lambda = sigma0 (9 beta/(2 pi dgamma E*^2))^{1/3} = 2 sigma0 (beta/(pi dgamma K^2))^{1/3}."""
    s0 = 3e8
    k = 4.0 * ESTAR / 3.0
    lam = maugis.md_parameter(BETA, DGAMMA, ESTAR, s0)
    assert lam == approx(2 * s0 * np.cbrt(BETA / (np.pi * DGAMMA * k * k)), rel=1e-14)
    # ... and it is NOT 2 sigma0 (beta/(pi dgamma E*^2))^{1/3}: that is (16/9)^{1/3} larger.
    wrong = 2 * s0 * np.cbrt(BETA / (np.pi * DGAMMA * ESTAR**2))
    assert wrong / lam == approx(np.cbrt(16 / 9), rel=1e-14)
    assert maugis.md_parameter(BETA, DGAMMA, ESTAR, sigma0_for(0.7)) == approx(0.7, rel=1e-14)


@pytest.mark.parametrize("lam", [0.05, 0.5, 2.0, 20.0])
def test_curve_satisfies_dimensional_maugis_equations(lam):
    """md_curve (SI) satisfies Johnson & Greenwood's dimensional equations to 1e-10:
    P = 4E*a^3/(3beta) - 2 s0 a^2 [t + m^2 atan t], delta = a^2/beta - 2 s0 a t/E*,
    dgamma = s0 a^2/(pi beta) [t + (m^2-2) atan t] + 4 s0^2 a/(pi E*) [t atan t - m + 1].
    This checks every normalisation constant, lambda's included."""
    s0 = sigma0_for(lam)
    a, p, d = maugis.md_curve(BETA, DGAMMA, ESTAR, s0, n=15, A_min=0.05, A_max=2.5)
    a_s, _, _ = maugis.md_scales(BETA, DGAMMA, ESTAR)
    m = maugis.md_m_of_A(a / a_s, lam)
    assert np.all(m >= 1.0)
    t = np.sqrt(m * m - 1)
    at = np.arctan(t)
    p_dim = 4 * ESTAR * a**3 / (3 * BETA) - 2 * s0 * a * a * (t + m * m * at)
    d_dim = a * a / BETA - 2 * s0 * a * t / ESTAR
    g_dim = (s0 * a * a / (np.pi * BETA) * (t + (m * m - 2) * at)
             + 4 * s0**2 * a / (np.pi * ESTAR) * (t * at - m + 1))
    scale_p = np.pi * BETA * DGAMMA
    scale_d = np.max(np.abs(d_dim))
    assert np.max(np.abs(p - p_dim)) / scale_p < 1e-10
    assert np.max(np.abs(d - d_dim)) / scale_d < 1e-10
    assert g_dim == approx(np.full_like(g_dim, DGAMMA), rel=1e-10)


def test_normalised_limits_jkr_and_dmt():
    """lambda -> inf: Pbar = A^3 - sqrt(6A^3), Dbar = A^2 - sqrt(8A/3) (JKR) -- 1e-6 at lambda=1e4;
    lambda -> 0: Pbar -> A^3 - 2 (DMT) -- 1e-3 at lambda = 1e-4 (error ~ lambda^{1/2} A^2...)."""
    A = np.array([0.3, 0.7, 1.0, 1.5, 2.0])
    p, d = maugis.md_force_and_approach(A, 1e4)
    assert np.max(np.abs(p - (A**3 - np.sqrt(6 * A**3)))) < 1e-6
    assert np.max(np.abs(d - (A**2 - np.sqrt(8 * A / 3)))) < 1e-6
    p, d = maugis.md_force_and_approach(A, 1e-4)
    assert np.max(np.abs(p - (A**3 - 2))) < 2e-3
    # approach offset tends to -(8/3) sqrt(lambda/pi)
    assert np.max(np.abs(d - (A**2 - 8 / 3 * np.sqrt(1e-4 / np.pi)))) < 1e-4


def test_small_A_end_point():
    """A -> 0: m A -> C, (pi lam/4) C^2 + (4 lam^2/3)(pi/2 - 1) C = 1, Pbar -> -(pi lam/2) C^2."""
    lam = 0.5
    q, r = 4 / 3 * lam**2 * (np.pi / 2 - 1), np.pi * lam / 4
    c = (-q + np.sqrt(q * q + 4 * r)) / (2 * r)
    p, d = maugis.md_force_and_approach(1e-7, lam)
    assert p == approx(-np.pi * lam / 2 * c * c, rel=1e-6)
    assert d == approx(-4 / 3 * lam * c, rel=1e-6)


# ---------------------------------------------------------------------------------------------
# Pull-off
# ---------------------------------------------------------------------------------------------
def test_pull_off_dmt_limit():
    """lambda = 0.01: within 2% of 2 pi beta dgamma (measured 0.086%)."""
    po = maugis.md_pull_off_force(BETA, DGAMMA, ESTAR, sigma0_for(0.01))
    assert po == approx(2 * np.pi * BETA * DGAMMA, rel=2e-2)
    assert po < 2 * np.pi * BETA * DGAMMA


def test_pull_off_jkr_limit():
    """lambda = 30: within 1% of 1.5 pi beta dgamma (measured 0.012%)."""
    po = maugis.md_pull_off_force(BETA, DGAMMA, ESTAR, sigma0_for(30.0))
    assert po == approx(jkr.pull_off_force(BETA, DGAMMA), rel=1e-2)
    assert po > jkr.pull_off_force(BETA, DGAMMA)


def test_pull_off_transition_monotone():
    lams = [0.1, 0.3, 1.0, 3.0, 10.0]
    pn = np.array([maugis.md_pull_off_force(BETA, DGAMMA, ESTAR, sigma0_for(x)) for x in lams])
    pn /= BETA * DGAMMA
    assert np.all((pn > 1.5 * np.pi) & (pn < 2 * np.pi))
    assert np.all(np.diff(pn) < 0)


def test_pull_off_is_minimum_of_dense_curve():
    """Refined minimum vs brute force on 4000 points: never above it, within 1e-6 relative."""
    s0 = sigma0_for(0.8)
    _, p, _ = maugis.md_curve(BETA, DGAMMA, ESTAR, s0, n=4000, A_min=1e-3, A_max=2.0)
    po = maugis.md_pull_off_force(BETA, DGAMMA, ESTAR, s0)
    assert po >= -p.min() * (1 - 1e-12)
    assert po == approx(-p.min(), rel=1e-6)
    with pytest.raises(ValueError):
        maugis.md_pull_off_force(BETA, DGAMMA, ESTAR, s0, control="displacement")


def test_large_lambda_curve_approaches_jkr():
    """lambda = 30: |P_MD(delta) - P_JKR(delta)| / P_c < 2e-2 on the JKR stable branch."""
    lam = 30.0
    a_s, p_s, d_s = maugis.md_scales(BETA, DGAMMA, ESTAR)
    A = np.array([0.8, 1.0, 1.5, 2.0, 3.0])
    pbar, dbar = maugis.md_force_and_approach(A, lam)
    p_jkr = jkr.force_from_approach(dbar * d_s, BETA, DGAMMA, ESTAR)
    pc = jkr.pull_off_force(BETA, DGAMMA)
    err = np.abs(pbar * p_s - p_jkr) / pc
    assert np.max(err) < 2e-2
