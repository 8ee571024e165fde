"""The boundary-element reference (continuum/rough/bem_reference.py, Tamaas) on a single paraboloid against the
closed forms: Hertz without adhesion, Maugis' pull-off with the Dugdale law. These check the setup (units, signs,
the z0 -> rho mapping, the quasi-static path), not Tamaas itself."""
from __future__ import annotations

import numpy as np
import pytest

from continuum.reference import hertz
from continuum.reference import maugis as md_ref
from continuum.rough.bem_reference import BEMContact, bem_cycle, dugdale_range
from continuum.rough.branch_laws import DUGDALE_FACTOR, make_summit_law
from continuum.rough.quasistatic import separation_path
from nanoimpact.errors import InputError

R, L, E = 1e-6, 1e-6, 1e9          # paraboloid radius, periodic cell, contact modulus (SI)


def _paraboloid(n):
    x = (np.arange(n) - n // 2) * L / n
    xx, yy = np.meshgrid(x, x, indexing="ij")
    h = -(xx**2 + yy**2) / (2 * R)
    return h, float((h - h.mean()).max())


def test_hertz_central_pressure():
    """No adhesion, 64^2 grid, contact radius a = 0.1 L (7 pixels): the central pressure at the computed load
    must be Hertz's p0 = 3F/(2 pi a^2), a = (3FR/(4E*))^(1/3). The centre is smooth, so the grid error is of order
    (pixel/a)^2 = 2 %; the periodic images change the local curvature by (4/3)(a/L)^3 = 0.13 %."""
    h, top = _paraboloid(64)
    contact = BEMContact(h, L, E, 0.0, 1e-9)
    state = contact.solve(top - 0.01 * L)
    force = state["force"]
    delta = (3 * force / (4 * E * np.sqrt(R))) ** (2 / 3)            # inverse of hertz.sphere_force
    assert float(hertz.sphere_force(delta, R, E)) == pytest.approx(force, rel=1e-12)
    a = float(hertz.sphere_contact_radius(delta, R))
    assert state["converged"] and a / (L / 64) > 6
    assert float(state["traction"].max()) == pytest.approx(3 * force / (2 * np.pi * a * a), rel=0.02)


def test_dugdale_law_is_the_summit_laws():
    """The BEM's Dugdale law is the project's Maugis-Dugdale summit law: sigma0 = 1.03 dgamma/z0, range
    h0 = dgamma/sigma0 (so sigma0 * rho = dgamma, the work of separation)."""
    w, z0 = 0.2, 0.3e-9
    sigma0, rho = dugdale_range(w, z0)
    law = make_summit_law("maugis_dugdale", 0.2e-6, w, 38e9, z0=z0, delta_max=1e-8)
    assert sigma0 == pytest.approx(DUGDALE_FACTOR * w / z0, rel=1e-15)
    assert sigma0 == pytest.approx(law.extra["dugdale_stress"], rel=1e-15)
    assert rho == pytest.approx(law.extra["dugdale_range_h0"], rel=1e-15)
    assert sigma0 * rho == pytest.approx(w, rel=1e-15)


def _maugis_pull_off(n, lam):
    """Pull-off of the paraboloid on an n^2 grid with Maugis parameter lam, relative to Maugis' closed form."""
    a_s = 0.1 * L                                                  # Maugis' radius scale: 0.1 L
    w = 4 / (3 * np.pi) * a_s**3 * E / R**2
    sigma0 = lam / np.cbrt(9 * R / (2 * np.pi * w * E**2))
    assert float(md_ref.md_parameter(R, w, E, sigma0)) == pytest.approx(lam, rel=1e-12)
    h, top = _paraboloid(n)
    d_s = a_s**2 / R
    cycle, stats = bem_cycle(h, L, E, w, DUGDALE_FACTOR * w / sigma0, separation_path(top + 2 * d_s, top - 0.5 * d_s,
                                                                                     d_s / 20))
    return cycle.pull_off_force / float(md_ref.md_pull_off_force(R, w, E, sigma0)), stats


def test_maugis_pull_off_converges_to_the_closed_form():
    """Dugdale law, lambda = 1: the retraction's largest tension is Maugis' load-controlled pull-off (under
    displacement control the minimum of P lies on the stable branch). The Dugdale zone's edge sits on the grid,
    so the force error is first order in the pixel size, and the contact at pull-off spans only a few pixels
    (a_s = 3.2 and 6.4 pixels on 32^2 and 64^2): the error must fall with the pixel, and the first-order
    Richardson extrapolation 2 F(64) - F(32) must meet the closed form within 5 %."""
    coarse, _ = _maugis_pull_off(32, 1.0)
    fine, stats = _maugis_pull_off(64, 1.0)
    assert stats.unconverged == 0 and stats.solves > 10
    assert abs(fine - 1) < abs(coarse - 1) and abs(fine - 1) < 0.25
    assert 2 * fine - coarse == pytest.approx(1.0, abs=0.05)


def test_bad_input_is_refused_before_any_solve():
    h, top = _paraboloid(16)
    with pytest.raises(InputError, match="work_of_adhesion"):
        BEMContact(h, L, E, -0.1, 1e-9)
    with pytest.raises(InputError, match="heights"):
        BEMContact(np.full((16, 16), np.nan), L, E, 0.1, 1e-9)
    with pytest.raises(InputError, match="e_star"):
        BEMContact(h, L, 0.0, 0.1, 1e-9)
