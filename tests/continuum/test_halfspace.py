"""The plane-strain half-space operator and its contact solvers reproduce the closed forms.

Tolerances follow the project's tiers: ~1e-12 for operator identities (FFT vs dense, exact
influence coefficients), ~1e-2 for discretised numerics against Hertz theory.
"""
import math

import numpy as np
import pytest

from continuum.elastic.halfspace import (
    LineHalfSpace,
    choose_grid,
    solve_coupled,
    solve_hard_contact,
    strip_displacement,
)
from continuum.reference import hertz

E_STAR, RADIUS, LOAD, LENGTH = 100e9, 5e-6, 1.0, 3.3e-3  # Pa, m, N/m, m (x_ref = roller length)


def wall(p_s, lam):
    """Exponential repulsion p_s exp(-h/lam) for h > 0, continued linearly (C1) into overlap."""
    def law(h):
        e = np.exp(-np.maximum(h, 0.0) / lam)
        return (np.where(h > 0, p_s * e, p_s * (1.0 - h / lam)),
                np.where(h > 0, -p_s * e / lam, -p_s / lam))
    return law


def wall_with_well(p_s, lam_r, p_a, lam_a):
    """Stiff repulsion minus a longer-ranged tensile exponential (Morse-like; tensile minimum -p_a-ish)."""
    rep, att = wall(p_s, lam_r), wall(p_a, lam_a)

    def law(h):
        (p1, d1), (p2, d2) = rep(h), att(h)
        return p1 - p2, d1 - d2
    return law


def hertz_grid(n, span=2.0):
    return choose_grid(RADIUS, LOAD, E_STAR, n_points=n, span=span).half_space(E_STAR, x_ref=LENGTH)


def moment_half_width(hs, p):
    """b from the second moment of the (cell-averaged) pressure: <x^2> = b^2/4 for Hertz."""
    m2 = np.sum(p * (hs.x**2 + hs.dx**2 / 12)) / np.sum(p)
    return 2.0 * math.sqrt(m2)


# Johnson's Hertz line contact (continuum.reference.hertz), the roller of length LENGTH under LOAD per length
HZ = {"half_width": float(hertz.line_half_width(LOAD * LENGTH, RADIUS, LENGTH, E_STAR)),
      "peak_pressure": float(hertz.line_peak_pressure(LOAD * LENGTH, RADIUS, LENGTH, E_STAR)),
      "approach": float(hertz.line_approach(LOAD * LENGTH, RADIUS, LENGTH, E_STAR))}


# ----------------------------------------------------------------------------- operator
@pytest.mark.parametrize("n", [2, 7, 64, 255, 1024])
def test_fft_convolution_equals_dense_influence_matrix(n):
    hs = LineHalfSpace(1e-9, n, E_STAR, x_ref=10 * n * 1e-9)
    p = np.random.default_rng(n).normal(size=(3, n)) * 1e8
    dense = p @ hs.dense_matrix().T
    fft = hs.displacement(p)
    assert fft.shape == (3, n)
    assert np.max(np.abs(fft - dense)) <= 1e-12 * np.max(np.abs(dense))


def test_uniform_strip_matches_johnson_closed_form_reference_free():
    hs = LineHalfSpace(2e-9, 200, E_STAR, x_ref=LENGTH)
    p = np.zeros(hs.n)
    p[80:120] = 3e8  # strip of 40 cells: exact for piecewise-constant pressure
    a, centre = 20 * hs.dx, 0.5 * (hs.x[80] + hs.x[119])
    exact = strip_displacement(hs.x, a, 3e8, E_STAR, LENGTH, center=centre)
    num = hs.displacement(p)
    # displacement differences between two points are independent of the reference
    diff_num, diff_exact = num - num[0], exact - exact[0]
    assert np.max(np.abs(diff_num - diff_exact)) <= 1e-12 * np.max(np.abs(diff_exact))
    # with the same x_ref the absolute values agree too
    assert np.max(np.abs(num - exact)) <= 1e-12 * np.max(np.abs(exact))


def test_changing_reference_adds_a_load_proportional_constant():
    p = np.random.default_rng(1).random(128) * 1e8
    a = LineHalfSpace(1e-9, 128, E_STAR, x_ref=1e-6).displacement(p)
    b = LineHalfSpace(1e-9, 128, E_STAR, x_ref=1e-3).displacement(p)
    shift = 2 * np.sum(p) * 1e-9 / (math.pi * E_STAR) * math.log(1e-3 / 1e-6)
    assert np.allclose(b - a, shift, rtol=1e-12, atol=0)


def test_reference_below_quarter_span_is_refused():
    with pytest.raises(ValueError, match="quarter of the grid span"):
        LineHalfSpace(1e-9, 100, E_STAR, x_ref=20e-9)


# ----------------------------------------------------------------------------- hard contact
def test_hertz_half_width_and_peak_pressure_within_one_percent_at_256_points():
    for span in (2.0, 3.0):  # edge on a cell boundary, and not
        hs = hertz_grid(256, span)
        sol = solve_hard_contact(hs, hs.x**2 / (2 * RADIUS), LOAD)
        assert sol.converged
        assert abs(moment_half_width(hs, sol.p) / HZ["half_width"] - 1) < 1e-2
        assert abs(sol.p.max() / HZ["peak_pressure"] - 1) < 1e-2
        assert np.sum(sol.p) * hs.dx == pytest.approx(LOAD, rel=1e-12, abs=0)
        assert sol.p.min() >= 0 and sol.h.min() > -1e-9 * HZ["approach"] and not sol.touches_edge
    narrow = hertz_grid(256, 0.8)
    assert solve_hard_contact(narrow, narrow.x**2 / (2 * RADIUS), LOAD).touches_edge


def test_hertz_errors_fall_as_the_grid_is_refined():
    errs_b, errs_p = [], []
    for n in (64, 128, 256, 512):
        hs = hertz_grid(n)
        sol = solve_hard_contact(hs, hs.x**2 / (2 * RADIUS), LOAD)
        errs_b.append(abs(moment_half_width(hs, sol.p) / HZ["half_width"] - 1))
        errs_p.append(abs(sol.p.max() / HZ["peak_pressure"] - 1))
    assert all(e2 < e1 for e1, e2 in zip(errs_b, errs_b[1:])), errs_b
    assert all(e2 < e1 for e1, e2 in zip(errs_p, errs_p[1:])), errs_p
    assert errs_b[-1] < 1e-4 and errs_p[-1] < 1e-4


def test_hertz_pressure_profile_in_the_interior():
    hs = hertz_grid(256)
    sol = solve_hard_contact(hs, hs.x**2 / (2 * RADIUS), LOAD)
    b, p0 = HZ["half_width"], HZ["peak_pressure"]
    inner = np.abs(hs.x) < 0.95 * b
    assert np.max(np.abs(sol.p[inner] - p0 * np.sqrt(1 - hs.x[inner]**2 / b**2))) < 0.02 * p0
    assert np.all(sol.p[np.abs(hs.x) > b + hs.dx] == 0)


def test_rigid_approach_with_roller_length_reference_is_johnson_finite_length_result():
    # delta(0) = W'/(pi E*) (2 ln(2 l/b) + 1): Johnson eq 5.39, the paper's K of eq 1
    hs = hertz_grid(256)
    sol = solve_hard_contact(hs, hs.x**2 / (2 * RADIUS), LOAD)
    assert sol.approach == pytest.approx(HZ["approach"], rel=1e-3, abs=0)


# ----------------------------------------------------------------------------- coupled
@pytest.fixture(scope="module")
def hard256():
    hs = hertz_grid(256)
    return hs, solve_hard_contact(hs, hs.x**2 / (2 * RADIUS), LOAD)


def test_stiffening_repulsive_law_converges_to_hard_contact(hard256):
    hs, hard = hard256
    gap = hs.x**2 / (2 * RADIUS) + hard.h_ref
    p0 = HZ["peak_pressure"]
    load_err, centre_err = [], []
    for lam in (1e-12, 1e-13, 1e-14, 1e-15):
        sol = solve_coupled(hs, gap, wall(p0, lam))
        assert sol.converged and sol.method == "newton" and sol.residual < 1e-10
        assert np.allclose(sol.h, gap + hs.displacement(sol.p), rtol=0, atol=1e-12 * abs(hard.h_ref))
        load_err.append(abs(sol.load_per_length / LOAD - 1))
        centre_err.append(np.max(np.abs(sol.p - hard.p)[np.abs(hs.x) < 0.5 * HZ["half_width"]]) / p0)
    assert all(e2 < e1 for e1, e2 in zip(load_err, load_err[1:])), load_err
    assert all(e2 < e1 for e1, e2 in zip(centre_err, centre_err[1:])), centre_err
    assert load_err[-1] < 1e-4 and centre_err[-1] < 1e-3


def test_adhesive_law_converges_with_tensile_rim_and_net_force_is_the_pressure_integral(hard256):
    _, hard = hard256
    p0, lam_a = HZ["peak_pressure"], 3e-12
    law = wall_with_well(p0, 1e-13, 0.3 * p0, lam_a)
    # the grid must hold the whole tensile rim: size it by the law's range, not the Hertz width
    grid = choose_grid(RADIUS, LOAD, E_STAR, n_points=512, h_ref=0.5 * hard.h_ref, gap_height=10 * lam_a)
    assert "gap" in grid.why
    hs = grid.half_space(E_STAR, x_ref=LENGTH)
    for h_ref in (0.5 * hard.h_ref, 0.0, 5e-12):  # compressive, near zero load, beyond touch (snap-in)
        gap = hs.x**2 / (2 * RADIUS) + h_ref
        sol = solve_coupled(hs, gap, law)
        assert sol.converged and sol.residual < 1e-10, sol.history[-3:]
        p_law, _ = law(sol.h)
        assert np.max(np.abs(sol.p - p_law)) <= 1e-10 * np.max(np.abs(sol.p))
        assert np.allclose(sol.h, gap + hs.displacement(sol.p), rtol=0, atol=1e-12 * abs(hard.h_ref))
        assert sol.p.min() < -0.2 * p0  # tensile rim around the footprint
        assert abs(sol.p[0]) < 1e-6 * p0 and abs(sol.p[-1]) < 1e-6 * p0  # rim fully on the grid
        tensile = np.sum(np.minimum(sol.p, 0)) * hs.dx
        assert tensile < -0.02 * LOAD
        # net force per length: cell sums (exact for cell-constant pressure) = a trapezoid quadrature
        assert sol.load_per_length == pytest.approx(hs.load_per_length(sol.p), rel=1e-12, abs=0)
        assert sol.load_per_length == pytest.approx(np.trapezoid(sol.p, hs.x), abs=1e-3 * abs(tensile))
    # beyond touch the surfaces have snapped in (Newton's branch ended; PTC found the jump) and
    # the net force is tensile
    assert sol.load_per_length < 0 and sol.method == "ptc"
    gap = hs.x**2 / (2 * RADIUS) + 0.5 * hard.h_ref
    assert solve_coupled(hs, gap, law).load_per_length < solve_coupled(hs, gap, wall(p0, 1e-13)).load_per_length


def test_newton_and_fixed_point_agree_under_weak_coupling_and_newton_needs_fewer_iterations(hard256):
    hs, hard = hard256
    gap = hs.x**2 / (2 * RADIUS) + hard.h_ref
    law = wall(HZ["peak_pressure"], 1e-10)
    newton = solve_coupled(hs, gap, law, method="newton", fallback=False)
    fixed = solve_coupled(hs, gap, law, method="fixed_point", fallback=False)
    assert newton.converged and fixed.converged
    assert np.max(np.abs(newton.p - fixed.p)) < 1e-9 * np.max(newton.p)
    assert newton.iterations < fixed.iterations


def test_warm_start_from_the_answer_needs_no_iterations(hard256):
    hs, hard = hard256
    gap = hs.x**2 / (2 * RADIUS) + hard.h_ref
    law = wall(HZ["peak_pressure"], 1e-13)
    sol = solve_coupled(hs, gap, law)
    again = solve_coupled(hs, gap, law, p_init=sol.p, tol=1e-9)
    assert again.converged and again.iterations == 0


# ----------------------------------------------------------------------------- grid
def test_grid_follows_the_hertz_footprint_and_the_law_range():
    small = choose_grid(RADIUS, 0.25 * LOAD, E_STAR, n_points=128, span=2.0)
    large = choose_grid(RADIUS, LOAD, E_STAR, n_points=128, span=2.0)
    assert large.half_span == pytest.approx(2.0 * HZ["half_width"])
    assert small.half_span == pytest.approx(0.5 * large.half_span)  # b grows as sqrt(W')
    assert large.x[-1] - large.x[0] == pytest.approx(2 * large.half_span - large.x_spacing)
    wide = choose_grid(RADIUS, LOAD, E_STAR, n_points=128, h_ref=-1e-9, gap_height=30e-9)
    assert wide.half_span == pytest.approx(1.25 * math.sqrt(2 * RADIUS * 31e-9)) and "gap" in wide.why
