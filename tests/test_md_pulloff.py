"""Pull-off: the surface-element integration (SEI) against the closed forms it must reduce to, Tabor's parameter,
and the pull-off workflow's protocol options (flat thermostat, several tip positions, two speeds) at plan level."""
from __future__ import annotations

import math

import numpy as np
import pytest

from md.analysis.pulloff import (surface_element_force, surface_element_pull_off, tabor_parameter,
                                 tabulated_traction, tip_height_map)


def lj93(w: float, z0: float):
    """LJ 9-3 traction law (positive = repulsive) with work w and equilibrium separation z0 (Maugis 1992)."""
    return lambda d: 8.0 * w / (3.0 * z0) * ((z0 / np.asarray(d, float)) ** 9 - (z0 / np.asarray(d, float)) ** 3)


def paraboloid(R: float, cell: float, half_width: float) -> np.ndarray:
    """Heights r^2 / (2R) at the centres of a square grid of spacing ``cell``."""
    c = (np.arange(int(2 * half_width / cell)) + 0.5) * cell - half_width
    x, y = np.meshgrid(c, c, indexing="ij")
    return (x ** 2 + y ** 2) / (2.0 * R)


def test_sei_paraboloid_lj93_gives_the_derjaguin_pull_off():
    """Derjaguin/DMT: a rigid paraboloid on a flat with the LJ 9-3 law pulls off at 2 pi R w (at D = z0).
    The contact zone's radius sqrt(2 R z0) = 20 cells, so the midpoint rule's error is far below 1 %."""
    R, z0, w, cell = 200.0, 1.0, 0.3, 1.0
    h = paraboloid(R, cell, 120.0)          # h reaches 18 z0 at the edge: the law's tail there is (1/18)^3 of it
    r = surface_element_pull_off(h, cell * cell, lj93(w, z0), (0.8, 2.0))
    assert r["pull_off_force"] == pytest.approx(2 * math.pi * R * w, rel=5e-3)
    assert r["apex_separation_at_max"] == pytest.approx(z0, rel=1e-2)


def test_sei_paraboloid_dugdale_gives_the_dmt_pull_off():
    """Dugdale law (sigma0 over h0, a hard wall below contact): F(0) = -sigma0 pi a^2, a^2 = 2 R h0, i.e.
    2 pi R sigma0 h0 = 2 pi R w. Counting cells inside a circle of 40 cells' radius: error of order 1/40."""
    R, h0, s0, cell = 400.0, 2.0, 0.5, 1.0
    law = lambda d: np.where(np.asarray(d) < 0, 1e6, np.where(np.asarray(d) < h0, -s0, 0.0))
    h = paraboloid(R, cell, 60.0)
    r = surface_element_pull_off(h, cell * cell, law, (0.0, 3.0), n_grid=301)
    assert r["pull_off_force"] == pytest.approx(2 * math.pi * R * s0 * h0, rel=2e-2)


def test_sei_flat_punch_gives_peak_traction_times_area():
    """A flat punch of N cells (the rest far away): F = A sigma(D), pull-off = A * 1.026 w / z0."""
    w, z0 = 0.2, 1.5
    h = np.full((30, 30), 500.0)
    h[5:15, 8:20] = 0.0
    r = surface_element_pull_off(h, 4.0, lj93(w, z0), (1.0, 3.0))
    peak = 16.0 / (9.0 * math.sqrt(3.0)) * w / z0
    assert r["pull_off_force"] == pytest.approx(120 * 4.0 * peak, rel=1e-6)
    assert r["apex_separation_at_max"] == pytest.approx(3 ** (1 / 6) * z0, rel=1e-4)


def test_sei_can_fail_on_a_wrong_radius():
    """Negative control: a paraboloid of twice the radius does not give 2 pi R w of the first."""
    R, z0, w = 200.0, 1.0, 0.3
    r = surface_element_pull_off(paraboloid(2 * R, 1.0, 160.0), 1.0, lj93(w, z0), (0.8, 2.0))
    assert abs(r["pull_off_force"] / (2 * math.pi * R * w) - 1) > 0.5


def test_tabulated_traction_interpolates_and_vanishes_beyond_the_table():
    s = tabulated_traction([2.0, 0.0, 1.0], [-1.0, 3.0, -2.0])
    assert s(np.array([0.5, 1.5, 5.0, -1.0])) == pytest.approx([0.5, -1.5, 0.0, 8.0])


def test_tip_height_map_of_a_paraboloid_and_its_empty_bins():
    """Atoms on a paraboloid at 2 A spacing, binned at 2 A: the map is the paraboloid at the bins (to the bin's
    height spread); binned at 1 A, 3/4 of the bins are empty and take their neighbours' heights."""
    R = 30.0
    g = np.arange(0.0, 40.0, 2.0) + 1.0
    x, y = np.meshgrid(g, g, indexing="ij")
    z = ((x - 21.0) ** 2 + (y - 21.0) ** 2) / (2 * R) + 7.0
    m = tip_height_map(np.column_stack([x.ravel(), y.ravel()]), z.ravel(), (40.0, 40.0), 2.0)
    assert m["bins"] == (20, 20) and m["filled"] == 0 and m["cell_area"] == pytest.approx(4.0)
    assert m["heights"] == pytest.approx(z - z.min())
    fine = tip_height_map(np.column_stack([x.ravel(), y.ravel()]), z.ravel(), (40.0, 40.0), 1.0)
    assert fine["filled"] == 1200 and np.all(np.isfinite(fine["heights"]))


def test_tabor_parameter_closed_form():
    """mu = (R W^2 / (E*^2 z0^3))^(1/3); Maugis lambda = 1.157 mu for the LJ 9-3 sigma0."""
    t = tabor_parameter(1.5e-9, 0.196, 37e9, 0.21e-9)
    assert t["mu"] == pytest.approx((1.5e-9 * 0.196 ** 2 / (37e9 ** 2 * 0.21e-9 ** 3)) ** (1 / 3), rel=1e-12)
    assert t["lambda"] / t["mu"] == pytest.approx(1.157, rel=1e-3)
    with pytest.raises(ValueError):
        tabor_parameter(1e-9, -0.1, 37e9, 2e-10)
