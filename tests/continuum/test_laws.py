"""The driver's scalar fast paths agree with the vectorised closed-form references."""
import numpy as np
import pytest

from continuum.laws.hertz import HertzLine
from continuum.laws.jkr import JKRSphere
from continuum.reference import hertz as href
from continuum.reference import jkr as jref


@pytest.mark.parametrize("beta,w,e", [(5e-6, 0.1, 37.6e9), (1e-7, 0.05, 100e9), (2e-9, 1.0, 1e9), (1e-3, 1e-3, 200e9)])
def test_jkr_law_matches_reference_along_the_whole_stable_branch(beta, w, e):
    law = JKRSphere(beta, w, e)
    dc = law.delta_c
    deltas = np.concatenate([-dc * (1 - np.logspace(-12, 0, 40)), dc * np.logspace(-3, 4, 60)])
    for order in (deltas, deltas[::-1], np.random.default_rng(1).permutation(deltas)):  # warm starts from anywhere
        for d in order:
            assert law.force(-d) == pytest.approx(float(jref.force_from_approach(d, beta, w, e)),
                                                  rel=1e-10, abs=1e-12 * law.pull_off_force)
            assert law.stored_energy(-d) == pytest.approx(float(jref.energy_from_approach(d, beta, w, e)),
                                                          rel=1e-9, abs=1e-10 * law.pull_off_force * dc)
    for d in deltas[1:]:
        assert law.stiffness(-d) == pytest.approx(float(jref.stiffness_from_approach(d, beta, w, e)), rel=1e-7, abs=0)


def test_hertz_line_law_matches_lambert_w_reference():
    r, l, e = 5e-6, 3.28e-3, 92.6e9
    law = HertzLine(r, l, e)
    for d in np.logspace(-16, -9, 30):
        assert law.force(-d) == pytest.approx(float(href.line_force(d, r, l, e)), rel=1e-12, abs=0)
        assert law.stiffness(-d) == pytest.approx(float(href.line_stiffness_tangent(d, r, l, e)), rel=1e-12, abs=0)
        assert law.stored_energy(-d) == pytest.approx(float(href.line_energy(d, r, l, e)), rel=1e-12, abs=0)
