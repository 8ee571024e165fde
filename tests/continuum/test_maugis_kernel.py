"""The compiled root of Maugis' equation (`continuum.reference.maugis_kernel`) against the scipy form it replaces
(`continuum.reference.maugis._t_of_A_scipy`, scipy's brentq on the same residual, bracket and tolerances) and
against the equation itself.

The two forms run the same Brent iteration; they differ only where NumPy's and libm's arctan differ in the last
ulp, so the roots and the force and approach agree to a few ulp of the terms they are made of (asserted at 1e-12 of
those terms: Pbar = A^3 - lam A^2 B3 cancels near its zero, so the tolerance is on the terms, not on Pbar)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.reference import maugis as md_ref
from continuum.reference import maugis_kernel as mk

LAMBDAS = [1e-4, 1e-2, 0.3, 1.0, 3.0, 30.0, 1e3]
A_GRID = np.concatenate([np.geomspace(1e-6, 50.0, 120), np.random.default_rng(7).uniform(1e-3, 5.0, 60)])


@pytest.mark.parametrize("lam", LAMBDAS)
def test_compiled_root_is_scipys_brentq_on_the_same_equation(lam):
    ref = np.array([md_ref._pdt_scipy(float(a), lam) for a in A_GRID]).T
    p, d, t = mk.solution(A_GRID, lam)
    at = np.arctan(ref[2])
    p_terms = A_GRID**3 + lam * A_GRID**2 * (ref[2] + (1.0 + ref[2] ** 2) * at)
    d_terms = A_GRID**2 + 4.0 / 3.0 * lam * A_GRID * ref[2]
    np.testing.assert_allclose(t, ref[2], rtol=1e-12, atol=0.0)
    assert np.all(np.abs(p - ref[0]) <= 1e-12 * p_terms)
    assert np.all(np.abs(d - ref[1]) <= 1e-12 * d_terms)


@pytest.mark.parametrize("lam", LAMBDAS)
def test_the_root_satisfies_maugis_energy_equation(lam):
    """The residual at the root is rounding of its terms (the equation, not the other implementation)."""
    for a in A_GRID[::7]:
        t = mk.t_of_A(float(a), lam)
        m = math.sqrt(1.0 + t * t)
        terms = 0.5 * lam * a * a * abs(t + (m * m - 2.0) * math.atan(t)) + 4.0 / 3.0 * lam * lam * a * abs(
            t * math.atan(t) - m + 1.0) + 1.0
        assert abs(mk.energy_residual(t, float(a), lam)) <= 1e-13 * terms


def test_public_functions_use_one_root_and_keep_their_shapes():
    A = np.array([[0.01, 0.5], [1.0, 2.5]])
    p, d, m = md_ref.md_solution(A, 0.7)
    assert p.shape == d.shape == m.shape == (2, 2)
    p2, d2 = md_ref.md_force_and_approach(A, 0.7)
    np.testing.assert_array_equal(p, p2)
    np.testing.assert_array_equal(d, d2)
    np.testing.assert_array_equal(m, md_ref.md_m_of_A(A, 0.7))
    assert np.ndim(md_ref.md_m_of_A(0.5, 0.7)) == 0
    for i, a in enumerate(A.ravel()):
        assert (p.ravel()[i], d.ravel()[i]) == mk.pdt(float(a), 0.7)[:2]


@pytest.mark.parametrize("A, lam", [(0.0, 1.0), (-1.0, 1.0), (math.nan, 1.0), (1.0, 0.0), (1.0, -2.0),
                                    (math.inf, 1.0)])
def test_bad_input_is_refused_in_both_forms(A, lam):
    with pytest.raises(ValueError, match="lambda"):
        md_ref.md_solution(np.array([0.5, A]), lam)
    with pytest.raises(ValueError, match="lambda"):
        md_ref._t_of_A_scipy(A, lam)
    with pytest.raises(ValueError):
        mk.t_of_A(A, lam)


def test_compiled_scales_are_the_reference_scales():
    """`maugis_kernel.scales` is md_scales and md_parameter/sigma0 (same expressions; NumPy's and libm's cbrt may
    differ in the last ulp)."""
    beta, w, e, s0 = 0.2e-6, 0.192, 89e9, 1.03 * 0.192 / 0.207e-9
    a_s, p_s, d_s, per = mk.scales(beta, w, e)
    np.testing.assert_allclose((a_s, p_s, d_s), [float(x) for x in md_ref.md_scales(beta, w, e)], rtol=1e-14)
    assert s0 * per == pytest.approx(float(md_ref.md_parameter(beta, w, e, s0)), rel=1e-14)
