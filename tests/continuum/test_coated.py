"""Coated summits: Perriot & Barthel's equivalent modulus, its limits, the thin-layer physics it must agree with,
and the SAM layer entering the summit laws through the contact modulus."""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.physics import coated
from continuum.reference import jkr as jkr_ref
from continuum.scene import resolve_scene

E_F, E_S = 1.1e9, 178e9          # plane-strain moduli of an OTS-like layer and of silicon


def test_the_equivalent_modulus_runs_from_the_layer_to_the_substrate():
    k0 = coated.transition_ratio(E_F, E_S)
    # a/t -> 0 (the contact inside the layer): the layer; the fit's remainder is (E_s - E_f)(x/k0)^n
    x = 1e-6
    tol = (E_S - E_F) * (x / k0) ** coated.PB_EXPONENT / E_F
    assert coated.equivalent_modulus(x, E_F, E_S) == pytest.approx(E_F, rel=2 * tol + 1e-15, abs=0)
    # a/t -> inf (a thin layer under a wide contact): the substrate
    x = 1e7
    tol = (k0 / x) ** coated.PB_EXPONENT
    assert coated.equivalent_modulus(x, E_F, E_S) == pytest.approx(E_S, rel=2 * tol, abs=0)
    # monotonic in between, halfway at a/t = k0 (the fit's definition of k0)
    xs = np.logspace(-3, 5, 400)
    e = coated.equivalent_modulus(xs, E_F, E_S)
    assert np.all(np.diff(e) > 0) and e[0] > E_F and e[-1] < E_S
    assert coated.equivalent_modulus(k0, E_F, E_S) == pytest.approx(0.5 * (E_F + E_S), rel=1e-12, abs=0)
    # no mismatch: the homogeneous half-space at every radius
    assert np.allclose(coated.equivalent_modulus(xs, E_S, E_S), E_S, rtol=1e-14, atol=0)


@pytest.mark.parametrize("ratio", [10.0, 30.0, 100.0])
def test_the_fitted_transition_is_the_confined_thin_layer_in_series_with_the_substrate(ratio):
    """A compliant layer under a wide contact is a thin confined (Winkler) layer in series with the substrate:
    1/(2aE') = 1/(2aE'_s) + t/(M pi a^2), which halves the substrate's modulus at a/t = 2E'_s/(pi M), M the layer's
    confined modulus (Johnson, Contact Mechanics 5.8). Perriot & Barthel's k0 comes from exact numerical solutions,
    independently; the two agree to 10 % over moduli ratios 10-100 (nu = 0.3)."""
    nu = 0.3
    e_young = 1e9
    e_f = coated.plane_strain_modulus(e_young, nu)
    m = e_young * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    e_s = ratio * e_f
    winkler = 2 * e_s / (math.pi * m)
    assert coated.transition_ratio(e_f, e_s) == pytest.approx(winkler, rel=0.10, abs=0)


def test_two_coated_bodies_add_their_compliances():
    a, t = np.array([1e-10, 2e-9, 5e-8]), 2e-9
    one = coated.equivalent_modulus(a / t, E_F, E_S)
    assert np.allclose(coated.coated_pair_modulus(a, t, E_F, E_S, E_S), one / 2, rtol=1e-14, atol=0)
    other = coated.equivalent_modulus(a / t, E_F, 2 * E_S)
    both = coated.coated_pair_modulus(a, t, E_F, E_S, 2 * E_S)
    assert np.allclose(1 / both, 1 / one + 1 / other, rtol=1e-14, atol=0)


def test_the_summit_modulus_solves_the_zero_load_radius_and_has_both_limits():
    beta, w = 0.2e-6, 0.066
    e, a0 = coated.coated_summit_modulus(beta, w, 6e-9, 2e-9, E_F, E_S, E_S)
    assert a0 == pytest.approx(coated.jkr_zero_load_radius(beta, w, e), rel=1e-10, abs=0)
    assert E_F / 2 < e < E_S / 2
    # a layer far thinner than the contact: the bare summit; far thicker: the layer's own half-space
    thin, _ = coated.coated_summit_modulus(beta, w, 6e-9, 1e-16, E_F, E_S, E_S)
    thick, _ = coated.coated_summit_modulus(beta, w, 6e-9, 1.0, E_F, E_S, E_S)
    assert thin == pytest.approx(E_S / 2, rel=1e-4, abs=0) and thick == pytest.approx(E_F / 2, rel=1e-4, abs=0)
    # a layer of the substrate's own modulus changes nothing
    same, _ = coated.coated_summit_modulus(beta, w, 6e-9, 2e-9, E_S, E_S, E_S)
    assert same == pytest.approx(E_S / 2, rel=1e-13, abs=0)
    # without adhesion the reference radius is the Hertz radius of a summit pressed by one sigma
    e0, a_h = coated.coated_summit_modulus(beta, 0.0, 6e-9, 2e-9, E_F, E_S, E_S)
    assert a_h == pytest.approx(math.sqrt(beta * 6e-9), rel=1e-15, abs=0)
    assert e0 == pytest.approx(coated.coated_pair_modulus(a_h, 2e-9, E_F, E_S, E_S), rel=1e-15, abs=0)


def test_a_sam_layer_enters_the_summit_law_through_the_contact_modulus():
    """rough_ots with a layer: the summits' E* is the coated pair's; the JKR loop per summit follows it as
    E*^(-2/3) (Fuller-Tabor loop 0.9355 P_c delta_c, P_c independent of E*, delta_c ~ E*^(-2/3))."""
    from continuum.model import coated_summits, loop_per_summit, summit_e_star

    over = {"surfaces.roughness.summit_modulus": 80e9, "physics.adhesion_law": "jkr"}
    bare = resolve_scene("rough_silica", params="paper", overrides=over).scene             # no SAM
    soft = resolve_scene("rough_ots", params="paper", overrides={**over, "surfaces.sam.layer_modulus": 2e9}).scene
    assert coated_summits(bare) is None and summit_e_star(bare) == 80e9
    rec = coated_summits(soft)
    e_f = coated.plane_strain_modulus(2e9, soft.surfaces.sam.layer_poisson_ratio)
    want, a0 = coated.coated_summit_modulus(0.2e-6, soft.surfaces.sam.work_of_adhesion, 6e-9,
                                            soft.surfaces.sam.thickness, e_f, 160e9, 160e9)
    assert summit_e_star(soft) == rec["e_star"] == pytest.approx(want, rel=1e-12, abs=0)
    assert rec["reference_radius"] == pytest.approx(a0, rel=1e-12, abs=0)
    beta, w = 0.2e-6, soft.surfaces.sam.work_of_adhesion
    ratio = loop_per_summit("jkr", soft, summit_e_star(soft)) / float(jkr_ref.loop_area(beta, w, 80e9))
    assert ratio == pytest.approx((want / 80e9) ** (-2.0 / 3.0), rel=1e-9, abs=0)
    assert ratio > 1.0
