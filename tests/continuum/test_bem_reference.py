"""The boundary-element reference (continuum/rough/bem_reference.py, Tamaas) on a single paraboloid against the
closed forms: Hertz without adhesion, Maugis' pull-off with the Dugdale law. These check the setup (units, signs,
the z0 -> rho mapping, the quasi-static path), not Tamaas itself. Then the pixel-convergence logic
(bem_convergence), impacts through tabulated laws against Hertz and Fuller-Tabor (bem_impact), and the summit
cutoff matched to the reference's loss, with its cache (cutoff_match)."""
from __future__ import annotations

import tomllib

import numpy as np
import pytest

from continuum.reference import hertz, jkr
from continuum.reference import maugis as md_ref
from continuum.rough.bem_convergence import (
    GridRun,
    cohesive_zone_length,
    convergence,
    dugdale_crack_zone,
    single_summit_ladder,
)
from continuum.rough.bem_impact import impact_at_energy, impact_outcome, turn_for_energy
from continuum.rough.bem_reference import BEMContact, bem_cycle, dugdale_range
from continuum.rough.branch_laws import DUGDALE_FACTOR, make_summit_law
from continuum.rough.cutoff_match import cache_key, match_cutoff, measured_cutoff
from continuum.rough.quasistatic import discrete_cycle, separation_path
from nanoimpact import data
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
    assert sigma0 == pytest.approx(DUGDALE_FACTOR * w / z0, rel=1e-12)
    assert sigma0 == pytest.approx(law.extra["dugdale_stress"], rel=1e-12)
    assert rho == pytest.approx(law.extra["dugdale_range_h0"], rel=1e-12)
    assert sigma0 * rho == pytest.approx(w, rel=1e-12)


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


# --- the cohesive-zone criterion and the pixel-convergence logic (continuum/rough/bem_convergence.py) -------------

def test_cohesive_zone_length_is_e_star_dgamma_over_sigma0_squared():
    """l = E* dgamma / sigma0^2 with sigma0 = 1.03 dgamma/z0, i.e. E* z0^2 / (1.03^2 dgamma); the plane Dugdale
    crack's zone is pi/8 of it. Silica-like numbers: 88.8 GPa, 0.192 J/m^2, 0.207 nm give ~19 nm."""
    e, w, z0 = 88.8e9, 0.192, 0.207e-9
    length = cohesive_zone_length(e, w, z0)
    assert length == pytest.approx(e * z0**2 / (DUGDALE_FACTOR**2 * w), rel=1e-12)
    assert 15e-9 < length < 25e-9
    assert dugdale_crack_zone(e, w, z0) == pytest.approx(np.pi / 8 * length, rel=1e-12)
    with pytest.raises(InputError, match="z0"):
        cohesive_zone_length(e, w, 0.0)


def _ladder(loss_of_pixel, grids=(32, 64, 128), size=250e-9, seconds=(1.0, 8.0, 64.0)):
    return [GridRun(n, size / n, 2e-7, loss_of_pixel(size / n), t) for n, t in zip(grids, seconds)]


def test_convergence_of_a_first_order_ladder_is_refused_with_the_pixel_it_needs():
    """loss = L0 + c a exactly (the lattice-trapping form): the change between the two finest grids is c a/(L0 +
    c a), the measured order 1, the fit and both Richardson values L0 exactly, and the pixel that brings c a under
    10 % of L0 is 0.1 L0/c; the solve time grows as n^3 in this ladder, so the required grid costs (n/128)^3 x 64 s."""
    l0, c, size = 4e-18, 5e-8, 250e-9
    rec = convergence(_ladder(lambda a: l0 + c * a), 18.7e-9, size)
    fine = size / 128
    assert not rec["converged"] and rec["not_converged"]
    assert rec["loss_rel_change_last_two"] == pytest.approx(c * fine / (l0 + c * fine), rel=1e-12)
    assert rec["loss_observed_order"] == pytest.approx(1.0, rel=1e-9)
    assert rec["loss_first_order_fit"]["loss_at_zero_pixel_J"] == pytest.approx(l0, rel=1e-6)
    assert rec["loss_richardson_J"] == pytest.approx([l0, l0], rel=1e-6)
    assert rec["required_pixel_m"] == pytest.approx(0.1 * l0 / c, rel=1e-6)
    assert rec["required_grid"] == int(np.ceil(size / rec["required_pixel_m"])) == pytest.approx(31250, abs=1)
    assert rec["solve_time_exponent"] == pytest.approx(3.0, rel=1e-12)
    assert rec["required_seconds_estimate"] == pytest.approx(64.0 * (rec["required_grid"] / 128) ** 3, rel=1e-9)
    assert rec["zone_pixels_finest"] == pytest.approx(18.7e-9 / fine, rel=1e-12)


def test_convergence_accepts_a_ladder_within_ten_per_cent_only():
    """Second-order error 5 % at the finest grid: converged; 12 %: not."""
    ok = convergence(_ladder(lambda a: 1e-17 * (1 + 0.05 * (a / (250e-9 / 128)) ** 2 / 4)), 18.7e-9, 250e-9)
    assert ok["converged"] and ok["not_converged"] is None
    bad = convergence(_ladder(lambda a: 1e-17 * (1 + 0.16 * (a / (250e-9 / 128)) ** 2 / 4)), 18.7e-9, 250e-9)
    assert not bad["converged"] and "upper bound" in bad["not_converged"]


def test_dugdale_sphere_loss_is_lattice_trapping_first_order_in_the_pixel():
    """The BEM on one paraboloid (R = 115 nm, the calibrated silica law, lambda ~ 0.5): the pull-off approaches
    Maugis-Dugdale's (the summit law's: first order in the pixel, within 20 % at 32 points across the cell), but the
    loss per cycle is dominated by the Dugdale step's lattice trapping: it halves with the pixel (ratio 1.6-2.4 from 16
    to 32 points) and is more than 10x the continuum loop of the summit law. This is why the ladder reports
    not_converged."""
    w, z0, e, r = 0.192, 0.207e-9, 88.8e9, 115e-9
    ladder = single_summit_ladder(r, e, w, z0, grids=(16, 32))
    coarse, fine = ladder["grids"]
    exact = ladder["summit_law_pull_off_N"]
    assert abs(fine["pull_off_force_N"] - exact) < abs(coarse["pull_off_force_N"] - exact)
    assert fine["pull_off_force_N"] == pytest.approx(exact, rel=0.2)
    assert 1.6 < coarse["hysteresis_energy_J"] / fine["hysteresis_energy_J"] < 2.4
    assert fine["loss_over_summit_law"] > 10
    runs = [GridRun(g["grid"], g["pixel_m"], g["pull_off_force_N"], g["hysteresis_energy_J"], 1.0)
            for g in ladder["grids"]]
    rec = convergence(runs, cohesive_zone_length(e, w, z0), ladder["cell_m"])
    assert not rec["converged"] and rec["loss_first_order_fit"]["slope_J_per_m"] > 0


# --- impacts through a tabulated hysteretic law (continuum/rough/bem_impact.py) ----------------------------------

def test_hertz_sphere_impact_through_the_bem_law_returns_its_energy():
    """No adhesion: the BEM's approach and retraction coincide (no loop), so a body turning anywhere on it leaves
    with all its energy (e = 1 to the trapezoids' error), and the turn of a body carrying exactly the work absorbed
    down to a tabulated state is that state. (The turn depth is not Hertz's: in a periodic cell the rigid
    separation carries the images' compliance, ~(4/3) a/L of the approach.)"""
    h, top = _paraboloid(64)
    d = 0.02 * L * L / R * 0.5                                  # contact radius sqrt(R d) = 0.1 L
    path = separation_path(top + 0.1 * d, top - 1.5 * d, d / 40)
    cycle, _ = bem_cycle(h, L, E, 0.0, 1e-9, path)
    out = impact_outcome(cycle)
    assert not out.stuck and out.restitution == pytest.approx(1.0, abs=2e-3)
    assert out.impact_energy > 0.5 * float(hertz.sphere_energy(d, R, E))
    k = cycle.turn - 7
    w = -np.sum(0.5 * (cycle.force[1:k + 1] + cycle.force[:k]) * np.diff(cycle.separation[:k + 1]))
    assert turn_for_energy(cycle, w) == pytest.approx(cycle.separation[k], rel=1e-9)


def test_jkr_impact_through_a_tabulated_law_loses_the_fuller_tabor_loop():
    """JKR summit law tabulated by the quasi-static cycle: a body turning below the jump-in loses exactly the
    displacement-controlled Fuller-Tabor loop (closed form), e^2 = 1 - W/K0 (within the trapezoids' jump error,
    P_c h); with K0 below the loop it stays stuck."""
    r, w, e = 1e-6, 0.1, 50e9
    loop = float(jkr.loop_area(r, w, e))
    dc = float(jkr.critical_approach(r, w, e))
    law = make_summit_law("jkr", r, w, e, delta_max=200 * dc)
    step = dc / 400
    for k0, stuck in ((3 * loop, False), (0.8 * loop, True)):
        out, cycle = impact_at_energy(lambda p: discrete_cycle(law, [0.0], p), k0, 2 * dc, step, -100 * dc)
        assert out.stuck is stuck
        assert out.loss == pytest.approx(loop, rel=0.01)
        assert out.turn_separation == pytest.approx(cycle.separation[cycle.turn], rel=1e-12)
    out, _ = impact_at_energy(lambda p: discrete_cycle(law, [0.0], p), 3 * loop, 2 * dc, step, -100 * dc)
    assert out.restitution**2 == pytest.approx(1 - loop / (3 * loop), rel=0.01)
    assert out.rebound_height(1e-3) == pytest.approx(1e-3 * out.restitution**2, rel=1e-12)
    with pytest.raises(InputError, match="impact_energy"):
        turn_for_energy(cycle, 1e6)


# --- the summit cutoff matched to the reference's loss (continuum/rough/cutoff_match.py) -------------------------

def test_cutoff_match_interpolates_a_power_law_exactly_and_says_when_nothing_brackets():
    """L_d = A c^2 on the ladder: the crossing of L_ref is sqrt(L_ref/A) exactly (log-log interpolation), the match
    error is the nearest rung's; a reference above every rung gives no cutoff and says so."""
    a = 1e-2
    ladder = [{"cutoff_m": c, "loss_J": a * c * c} for c in (10e-9, 20e-9, 40e-9, 80e-9)]
    target = a * (30e-9) ** 2
    m = match_cutoff(ladder, target, 2 * target, converged=False)
    assert m.cutoff == pytest.approx(30e-9, rel=1e-12)
    assert m.cutoff_at_upper_bound == pytest.approx(30e-9 * np.sqrt(2), rel=1e-12)
    assert m.match_error == pytest.approx((a * (40e-9) ** 2 - target) / target, rel=1e-12)
    assert m.origin()["kind"] == "bem" and m.origin()["reference_converged"] is False
    none = match_cutoff(ladder, 1.0, 2.0, converged=True)
    assert none.cutoff is None and "no cutoff" in none.reason


def test_measured_cutoff_is_cached_by_map_and_law(tmp_path):
    """The match runs once per map and law: the second call reads the cache; another z0 is another key."""
    n, size = 32, 100e-9
    x = np.arange(n) * size / n
    xx, yy = np.meshgrid(x, x, indexing="ij")
    h = 1e-9 * (np.cos(2 * np.pi * 2 * xx / size) * np.cos(2 * np.pi * 2 * yy / size)
                + 0.3 * np.cos(2 * np.pi * 3 * (xx + yy) / size))
    kw = dict(grids=(16, 32), cutoffs_pixels=(4, 8), cache=tmp_path)
    first = measured_cutoff(h, size, 88.8e9, 0.192, 0.207e-9, **kw)
    again = measured_cutoff(h, size, 88.8e9, 0.192, 0.207e-9, **kw)
    assert not first["cached"] and again["cached"]
    assert again["origin"] == first["origin"] and first["origin"]["kind"] == "bem"
    assert len(list(tmp_path.iterdir())) == 1
    assert cache_key(h, size, 88.8e9, 0.192, 0.207e-9, {}) != cache_key(h, size, 88.8e9, 0.192, 0.21e-9, {})


# --- a scene asking for the measured cutoff (surfaces.roughness.summit_cutoff_from = "bem") ----------------------

_SMALL = {"surfaces.roughness.synthetic.size": 0.25e-6, "surfaces.roughness.synthetic.rms_height": 1.2e-9,
          "surfaces.roughness.synthetic.short_cutoff": 0.25e-6 / 8,
          "surfaces.roughness.synthetic.long_cutoff": 0.25e-6 / 2, "surfaces.roughness.synthetic.grid_points": 64}


@pytest.mark.parametrize("extra, message", [
    ({}, "needs the cohesive zone"),                                        # 5 um map: 78 nm pixels, zone 19 nm
    ({"surfaces.roughness.summit_cutoff": 1e-7}, "measures the cutoff"),    # two sources for one cutoff
])
def test_a_scene_asking_for_the_bem_cutoff_is_refused_where_the_reference_cannot_stand(extra, message):
    from continuum.scene import SceneError, resolve_scene
    with pytest.raises(SceneError, match=rf"surfaces.roughness.summit_cutoff_from = 'bem': .*{message}"):
        resolve_scene("rough_synthetic", params="calibrated",
                      overrides={"surfaces.roughness.summit_cutoff_from": "bem", **extra})


def test_the_bem_cutoff_of_a_small_patch_reaches_the_scene(tmp_path, monkeypatch):
    """The benchmark's patch on its own 64^2 grid: the reference's ladder (16, 32, 64) runs once, the discrete
    summits' loss meets the extrapolated reference loss inside the ladder's cutoffs (origin kind "bem", the
    reference's loss not converged), and the scene asking for it reads the cached match, whose cutoff leaves this
    0.25 um patch fewer summits than statistics need: refused with the key and the count."""
    from continuum.rough.cutoff_match import scene_cutoff
    from continuum.rough.topography import Synthesis, synthesise_height_map
    from continuum.scene import SceneError, resolve_scene
    monkeypatch.setenv("NANOIMPACT_CACHE", str(tmp_path))
    hmap = synthesise_height_map(Synthesis(hurst=0.8, rms_height=1.2e-9, short_cutoff=0.25e-6 / 8, size=0.25e-6,
                                           grid_points=64, long_cutoff=0.25e-6 / 2, seed=1))
    raw = tomllib.loads(data.find("params", "calibrated").read_text())["surfaces"]
    e_star = float(hertz.effective_modulus(raw["body"]["youngs_modulus"], raw["body"]["poisson_ratio"],
                                           raw["substrate"]["youngs_modulus"], raw["substrate"]["poisson_ratio"]))
    cutoff, origin = scene_cutoff(hmap.heights, hmap.physical_size[0], True, e_star, raw["work_of_adhesion"],
                                  raw["interaction_range"])
    pixel = hmap.physical_size[0] / 64
    assert 4 * pixel < cutoff < 32 * pixel
    assert origin["kind"] == "bem" and origin["bem_loss_converged"] is False and not origin["cached"]
    with pytest.raises(SceneError, match=r"holds \d summits at summit_cutoff .*need >= 20"):
        resolve_scene("rough_synthetic", params="calibrated",
                      overrides={**_SMALL, "surfaces.roughness.summit_cutoff_from": "bem"})
    assert len(list((tmp_path / "bem").iterdir())) == 1                     # the scene reused the match
