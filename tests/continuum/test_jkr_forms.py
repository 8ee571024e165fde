"""Every form of the JKR sphere against the others and against JKR (1971)'s closed forms.

The forms: the checked array root `continuum.physics.jkr_kernel.solve_s` (the reference's), its unchecked array root
`stable_root` and the scalar `stable_root_scalar` (Python: the discrete summits), the same scalar compiled by numba
(`continuum.numerics.kernel_laws._jkr_root`, the compiled discrete summits), the GW tables' compiled root and
JKR-minus-Hertz curve (`continuum.rough.gw_kernel._stable_s`, `_curve_minus_hertz`), the compiled discrete sum of
one summit (`kernel_laws._discrete_sum`), and the sphere law in u = sqrt(a) (`continuum.laws.jkr.JKRSphere`).

Tolerances follow the conditioning of s^4 - s = d: a residual of k eps (s^4 + s + |d|) moves a simple root by that
over |4 s^3 - 1|, and the double root at the fold d = -D_C by sqrt(2 k eps (...) / (12 s^2)). The closed-form
checks use JKR's P(a) = 4 E* a^3/(3 R) - sqrt(8 pi dgamma E* a^3), delta(a) = a^2/R - sqrt(2 pi dgamma a/E*),
written out here, not taken from the code under test.
"""
import math

import numpy as np
import pytest

from continuum.laws.jkr import JKRSphere
from continuum.numerics import kernel_laws as kl
from continuum.numerics.compiled_contact import EMPTY_TABLES
from continuum.physics import jkr_kernel as jk
from continuum.reference import jkr as ref
from continuum.rough import gw_kernel as gk

EPS = np.finfo(float).eps
K = 16.0                                  # ulps of residual each form may carry (a few roundings per step)
BETA, DGAMMA, ESTAR = 1e-7, 0.1, 50e9     # a silica-like asperity (m, J/m^2, Pa)


def _d_grid():
    """Reduced approaches from just above the fold to deep compression: the fold's neighbourhood on a log scale,
    then the branch up to d = 1e4."""
    near = -jk.D_C + jk.D_C * np.logspace(-14, 0, 60)
    return np.concatenate([[-jk.D_C], near, np.linspace(-0.4, 3.0, 200), np.logspace(0.5, 4, 60)])


def _root_tol(d, s):
    """|s - s_true| bound from a residual of K eps (s^4 + s + |d|): first order at a simple root, second order at
    the fold's double root (the smaller of the two)."""
    res = K * EPS * (s**4 + s + np.abs(d))
    first = res / np.maximum(np.abs(4.0 * s**3 - 1.0), 1e-300)
    second = np.sqrt(2.0 * res / (12.0 * s * s))
    return np.minimum(first, second) + 4 * EPS * s


def test_the_compiled_scalar_root_is_the_python_scalar_root():
    d = _d_grid()
    python = np.array([jk.stable_root_scalar(float(x)) for x in d])
    compiled = np.array([kl._jkr_root(float(x)) for x in d])
    np.testing.assert_array_equal(compiled[:, 0], python[:, 0])          # the clamp is exact arithmetic
    assert np.all(np.abs(compiled[:, 1] - python[:, 1]) <= _root_tol(d, python[:, 1]))


@pytest.mark.parametrize("form", ["stable_root", "stable_root_scalar", "compiled", "gw_compiled"])
def test_each_stable_root_is_the_checked_reference_root(form):
    d = _d_grid()
    s_ref, _ = jk.solve_s(d, "stable")
    if form == "stable_root":
        s = jk.stable_root(d.copy())
    elif form == "stable_root_scalar":
        s = np.array([jk.stable_root_scalar(float(x))[1] for x in d])
    elif form == "compiled":
        s = np.array([kl._jkr_root(float(x))[1] for x in d])
    else:
        s = np.array([gk._stable_s(float(x)) for x in d / jk.D_C])
    assert np.all(s >= jk.S_FOLD * (1.0 - 1e-7))                          # on the stable branch
    tol = _root_tol(d, s_ref) + _root_tol(d, s)
    bad = np.abs(s - s_ref) > tol
    assert not np.any(bad), (d[bad], s[bad], s_ref[bad])


def test_a_wrong_root_is_caught_by_the_tolerance():
    """Negative control: a root off by one part in 1e9 at d = 1 (a simple root) fails the bound."""
    s = jk.stable_root_scalar(1.0)[1]
    assert abs(s * (1 + 1e-9) - s) > _root_tol(np.array(1.0), np.array(s))


def test_the_compiled_jkr_minus_hertz_curve_is_the_python_curve():
    s = np.concatenate([[1.0], 1.0 + np.logspace(-8, 0, 40), np.linspace(2.0, 30.0, 60)])
    python = jk.reduced_curve_minus_hertz(s)
    for j in range(3):
        compiled = np.array([gk._curve_minus_hertz(j, float(x)) for x in s])
        # each quantity is a few terms of size up to ~(16/9) s^6 (force) or s^10 (energy): round-off scale
        scale = np.abs(python[j]) + (s**6 if j == 0 else s**10 if j == 1 else s)
        assert np.all(np.abs(compiled - python[j]) <= 64 * EPS * scale), j


# ------------------------------------------------------------------ against JKR (1971) in closed form
def _jkr_delta(a):
    return a * a / BETA - math.sqrt(2.0 * math.pi * DGAMMA * a / ESTAR)


def _jkr_force(a):
    return 4.0 * ESTAR * a**3 / (3.0 * BETA) - math.sqrt(8.0 * math.pi * DGAMMA * ESTAR * a**3)


#: (name, contact radius a (m), force P (N)) at JKR's two named loads: zero load and the load-controlled pull-off.
POINTS = [("zero load", (4.5 * math.pi * DGAMMA * BETA**2 / ESTAR) ** (1 / 3), 0.0),
          ("pull-off", (9.0 / 8.0 * math.pi * DGAMMA * BETA**2 / ESTAR) ** (1 / 3), -1.5 * math.pi * DGAMMA * BETA)]


def _discrete_one_summit(delta: float, energy: bool) -> float:
    """The compiled discrete law with one JKR summit at the datum at approach `delta`, having been pressed at least to
    touch (the history that keeps a summit attached in tension)."""
    delta0 = float(ref.approach_scale(BETA, DGAMMA, ESTAR))
    pscale = math.pi * DGAMMA * BETA
    P = np.zeros(kl.DISCRETE_PARAMS)
    P[kl.P_D_INV_DELTA0], P[kl.P_D_PSCALE], P[kl.P_D_ESCALE] = 1.0 / delta0, pscale, pscale * delta0
    P[kl.P_D_ADHESIVE], P[kl.P_D_RELEASE], P[kl.P_D_LOWEST], P[kl.P_D_END_GAP] = 1.0, 1.0, -math.inf, math.inf
    S = np.array([min(-delta, 0.0), 0.0, 0.0, 0.0, 0.0])
    T = (np.array([0.0]),) + EMPTY_TABLES[1:]
    return kl._discrete_sum(-delta, S, P, T, energy)


@pytest.mark.parametrize("name,a,force", POINTS, ids=[p[0] for p in POINTS])
def test_every_form_meets_jkr_at_zero_load_and_at_pull_off(name, a, force):
    assert _jkr_force(a) == pytest.approx(force, abs=1e-12 * 1.5 * math.pi * DGAMMA * BETA)   # the closed form itself
    delta = _jkr_delta(a)
    pc = 1.5 * math.pi * DGAMMA * BETA
    a0 = (2.0 * math.pi * DGAMMA * BETA**2 / ESTAR) ** (1 / 3)
    d = delta / (a0 * a0 / BETA)
    tol = 1e-12 * pc if name == "zero load" else 1e-10 * pc      # pull-off is a minimum of P: flat in delta
    # the reference, the Python and compiled discrete summits, and the sphere law, force at this approach
    forces = {
        "reference": float(ref.force_from_approach(delta, BETA, DGAMMA, ESTAR)),
        "python summits": float(jk.stable_force_in_place(np.array([jk.stable_root_scalar(d)[1]]),
                                                         math.pi * DGAMMA * BETA)[0]),
        "compiled summits": _discrete_one_summit(delta, energy=False),
        "sphere law": JKRSphere(BETA, DGAMMA, ESTAR).force(-delta),
    }
    for form, value in forces.items():
        assert value == pytest.approx(force, abs=tol), form
    # the contact radius a = s^2 a0 of each root
    roots = (jk.stable_root_scalar(d)[1], kl._jkr_root(d)[1], gk._stable_s(d / jk.D_C),
             float(jk.solve_s(d, "stable")[0]))
    for s in roots:
        assert s * s * a0 == pytest.approx(a, rel=1e-12)


def test_the_compiled_summit_energy_is_the_reference_energy():
    """U(delta) of one compiled summit against the reference's closed form over the stable branch."""
    dc = float(ref.critical_approach(BETA, DGAMMA, ESTAR))
    deltas = np.concatenate([-dc * (1.0 - np.logspace(-6, 0, 20)), np.linspace(0.0, 20.0 * dc, 40)])
    expected = ref.energy_from_approach(deltas, BETA, DGAMMA, ESTAR)
    scale = 1.5 * math.pi * DGAMMA * BETA * dc * (1.0 + (np.maximum(deltas, 0.0) / dc) ** 2.5)
    got = np.array([_discrete_one_summit(float(x), energy=True) for x in deltas])
    assert np.all(np.abs(got - expected) <= 1e-11 * scale)
    sphere = JKRSphere(BETA, DGAMMA, ESTAR)
    got = np.array([sphere.stored_energy(-float(x)) for x in deltas[deltas > -dc * (1 - 1e-5)]])
    assert np.all(np.abs(got - expected[deltas > -dc * (1 - 1e-5)]) <= 1e-9 * scale[deltas > -dc * (1 - 1e-5)])


def test_the_compiled_jkr_minus_hertz_curve_meets_jkr_at_zero_load():
    """The GW kernel's JKR-minus-Hertz quantities (compressed summits, s >= 1) plus Hertz give JKR's zero load at
    JKR's zero-load radius (a^3 = 9 pi dgamma R^2/(2 E*)), in units of P_c and delta_c."""
    _, a, _ = POINTS[0]
    a0 = (2.0 * math.pi * DGAMMA * BETA**2 / ESTAR) ** (1 / 3)
    delta_c = 0.75 * (math.pi**2 * DGAMMA**2 * BETA / ESTAR**2) ** (1 / 3)
    s = math.sqrt(a / a0)
    x = _jkr_delta(a) / delta_c
    hertz_force = 16.0 / 9.0 * (x * jk.D_C) ** 1.5                        # 4/3 E* sqrt(R) delta^1.5 / P_c
    assert gk._curve_minus_hertz(0, s) + hertz_force == pytest.approx(0.0, abs=1e-12)
    assert gk._curve_minus_hertz(2, s) + x == pytest.approx(a * a / (BETA * delta_c), rel=1e-12)
