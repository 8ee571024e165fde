"""md.analysis against synthetic inputs with known answers (no LAMMPS needed): surface tension, density profiles,
pull-off and traction-law fits, contact angles.

The contact-angle tests build fake MDAnalysis universes (MDAnalysis is part of the md extra): without it
they skip -- except when CI is "true", where a missing MDAnalysis is a failure.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import require_backend
from md.analysis import (
    ContactAngle,
    density_profile,
    fit_contact_angle,
    fit_traction_law,
    lj_tail_correction,
    pull_off_analysis,
    rate_extrapolation,
    slab_density,
    surface_tension,
)

N_A = 6.02214076e23          # CODATA 2018 / SI 2019, exact
KCAL = 4184.0                # J, thermochemical
ATM = 101325.0               # Pa


def rel(x, r):
    return pytest.approx(x, rel=r, abs=0)


# ------------------------------------------------------------------------------------ surface tension

def test_surface_tension_of_known_anisotropy_is_exact():
    rng = np.random.default_rng(7)
    common = rng.normal(0.0, 300.0, 5000)                  # isotropic fluctuation: cancels exactly
    pzz = 12.0 + common
    pxx = -480.0 + common
    pyy = -520.0 + common
    lz = 80.0
    expected = 0.5 * lz * (12.0 + 500.0) * ATM * 1e-10     # N/m
    out = surface_tension(pxx, pyy, pzz, lz)
    assert out["value"] == rel(expected, 1e-12)
    assert out["stderr"] < 1e-12 * expected
    tail = 1.5e-3
    out2 = surface_tension(pxx, pyy, pzz, np.full(5000, lz), tail_correction_N_per_m=tail)
    assert out2["value"] == rel(expected + tail, 1e-12)
    assert out2["tail_correction"] == tail and out2["units"] == "N/m"


def test_surface_tension_error_reflects_independent_noise():
    rng = np.random.default_rng(8)
    n, sd, lz = 50000, 200.0, 60.0
    pxx, pyy, pzz = (rng.normal(0.0, sd, n) for _ in range(3))
    out = surface_tension(pxx, pyy, pzz, lz)
    exact = 0.5 * lz * sd * math.sqrt(1.5) / math.sqrt(n) * ATM * 1e-10
    assert exact / 1.5 < out["stderr"] < 1.5 * exact
    assert abs(out["value"]) < 4 * exact


def test_lj_tail_correction_sharp_limit_and_width_dependence():
    eps, sig, rho, rc = 0.1553, 3.166, 0.0334, 10.0            # SPC/E oxygens, 10 A cutoff
    sharp = lj_tail_correction(eps, sig, rho, rc)
    closed = 1.5 * math.pi * eps * sig**6 * rho**2 / rc**2 * KCAL / (N_A * 1e-20)
    assert sharp == rel(closed, 1e-12)
    assert lj_tail_correction(eps, sig, rho, rc, width_A=1e-3) == rel(sharp, 1e-3)
    wide = lj_tail_correction(eps, sig, rho, rc, width_A=2.0)
    assert 0 < wide < sharp                                       # a diffuse interface lowers the tail
    assert lj_tail_correction(eps, sig, rho, 2 * rc) == rel(sharp / 4, 1e-12)


# ------------------------------------------------------------------------------------------- densities

def test_density_profile_conserves_mass():
    rng = np.random.default_rng(1)
    z = rng.uniform(0, 50, (4, 300))
    m = rng.uniform(1, 20, 300)
    area = 900.0
    prof = density_profile(z, m, area, np.linspace(0, 50, 101))
    dz = np.diff(prof["edges_A"]) * 1e-10
    mass = np.sum(prof["density"] * dz * area * 1e-20)           # kg per frame
    assert mass == rel(m.sum() * 1e-3 / N_A, 1e-12)


@pytest.mark.parametrize("centre", [40.0, 2.0])                  # 2.0: the slab straddles z = 0
def test_slab_density_recovers_water_density(centre):
    rng = np.random.default_rng(4)
    lx = ly = 30.0
    lz, half, rho = 100.0, 20.0, 997.0                            # kg/m^3
    n = int(rho / (18.015e-3 / N_A) * lx * ly * 2 * half * 1e-30)
    frames = []
    for _ in range(50):
        zz = rng.normal(0, 1.0, n) + rng.uniform(-half, half, n)   # smeared slab edges
        frames.append((zz + centre + rng.normal(0, 1.0)) % lz)
    out = slab_density(np.array(frames), np.full(n, 18.015), lx * ly, lz_A=lz)
    assert out["value"] == rel(rho, 0.01)
    assert out["half_thickness_A"] == pytest.approx(half, abs=0.3)
    assert 0 < out["stderr"] < 10.0


# -------------------------------------------------------------------------------------------- pull-off

def lj93_force(d, amp, z0):
    return amp * ((z0 / d) ** 9 - (z0 / d) ** 3)


def test_pull_off_of_lj93_force_curve_is_analytic():
    amp, z0 = 2.0, 3.0                                             # kcal/mol/A, A
    d = np.linspace(2.5, 15.0, 2501)
    out = pull_off_analysis(d, lj93_force(d, amp, z0), radius_m=5e-9)
    fmax = amp * 2.0 / (3.0 * math.sqrt(3.0)) * KCAL / (N_A * 1e-10)   # N
    assert out["max_tensile_force"] == rel(fmax, 1e-6)
    assert out["separation_at_max"] == rel(3 ** (1 / 6) * z0 * 1e-10, 1e-5)
    assert out["zero_force_separation"] == rel(z0 * 1e-10, 1e-5)
    assert out["z0_zero_to_min"] == rel((3 ** (1 / 6) - 1) * z0 * 1e-10, 1e-4)
    assert out["z0"] == rel(z0 * 1e-10, 1e-6)                          # the fitted law's z0
    fit = out["traction_fit"]
    assert fit["w"] == rel(3 * z0 * amp / 8 * KCAL / N_A, 1e-6)      # J (force x length)
    assert fit["offset"] == pytest.approx(0.0, abs=1e-15)
    assert fit["h0_maugis"] == rel(9 * math.sqrt(3) / 16 * z0 * 1e-10, 1e-6)
    f = out["max_tensile_force"]
    assert out["eff_work_jkr"] == rel(f / (1.5 * math.pi * 5e-9), 1e-12)
    assert out["eff_work_dmt"] == rel(f / (2.0 * math.pi * 5e-9), 1e-12)


def test_traction_law_fit_stderr_matches_the_scatter_of_repeated_fits():
    rng = np.random.default_rng(12)
    amp, z0, off = 1.5, 2.8, 4.0
    d = np.linspace(off + 2.4, off + 14.0, 120)
    clean = lj93_force(d - off, amp, z0)
    fits = [fit_traction_law(d, clean + rng.normal(0, 0.05, d.size), offset=True) for _ in range(40)]
    zs = np.array([f["z0"] for f in fits])
    es = np.array([f["stderr"]["z0"] for f in fits])
    assert 0.6 < np.median(es) / zs.std() < 1.6
    w = fit_traction_law(d, clean + rng.normal(0, 0.05, d.size), offset=True, force_stderr=np.full(d.size, 0.05))
    assert abs(w["z0"] - z0) < 4 * w["stderr"]["z0"] and w["stderr"]["w"] > 0



def test_traction_law_fit_recovers_an_offset_origin():
    amp, z0, off = 1.5, 2.8, 4.0
    d = np.linspace(off + 2.4, off + 14.0, 600)
    fit = fit_traction_law(d, lj93_force(d - off, amp, z0), offset=True)
    assert fit["z0"] == rel(z0, 1e-5)
    assert fit["offset"] == pytest.approx(off, abs=1e-4)
    assert fit["w"] == rel(3 * z0 * amp / 8, 1e-5)


def test_traction_law_fit_works_when_separations_start_below_zero():
    """A compressed MD contact reports separations below zero (the rigid-holder gap); the law's origin is then
    negative and the curve includes a stiff wall, which the fit must leave out and still recover the law."""
    amp, z0, off = 1.5, 2.8, -5.0
    d = np.linspace(off + 1.6, off + 14.0, 800)
    f = lj93_force(d - off, amp, z0)
    assert f.max() > 3 * abs(f.min()) and d.min() < 0
    fit = fit_traction_law(d, f, offset=True)
    assert fit["z0"] == rel(z0, 1e-5) and fit["offset"] == pytest.approx(off, abs=1e-4)
    with pytest.raises(ValueError, match="positive"):
        fit_traction_law(d, f, offset=False)


def test_sphere_law_gives_dmt_work_for_rigid_sphere():
    r_m, w_si, z0 = 4e-9, 0.1, 3.2                                     # m, J/m^2, A
    fc = 2 * math.pi * r_m * w_si / (KCAL / (N_A * 1e-10))           # kcal/mol/A
    d = np.linspace(2.7, 20.0, 3000)
    f = fc * ((z0 / d) ** 8 / 3 - 4 * (z0 / d) ** 2 / 3)
    out = pull_off_analysis(d, f, radius_m=r_m, law="sphere_lj93", fit_offset=False)
    assert out["eff_work_dmt"] == rel(w_si, 1e-6)
    assert out["separation_at_max"] == rel(z0 * 1e-10, 1e-5)
    assert out["z0"] == rel(z0 * 1e-10, 1e-6)
    assert out["traction_fit"]["w"] == rel(w_si, 1e-6)


def test_pull_off_of_noisy_curve_with_smoothing():
    rng = np.random.default_rng(9)
    amp, z0 = 2.0, 3.0
    d = np.linspace(2.6, 12.0, 1000)
    f = lj93_force(d, amp, z0) + rng.normal(0, 0.05 * amp, d.size)
    out = pull_off_analysis(d, f, smooth=51)
    fmax = amp * 2.0 / (3.0 * math.sqrt(3.0)) * KCAL / (N_A * 1e-10)
    assert out["max_tensile_force"] == rel(fmax, 0.03)
    assert out["z0"] == rel(z0 * 1e-10, 0.03)


def test_rate_extrapolation_recovers_bell_evans_line():
    rates = np.array([1.0, 3.0, 10.0, 30.0, 100.0])                  # m/s
    kt, xb, f_ref = 1.380649e-23 * 300.0, 2e-10, 1e-9
    forces = f_ref + kt / xb * np.log(rates)
    out = rate_extrapolation(rates, forces, target_rate=1e-3, temperature_K=300.0)
    assert out["F0"] == rel(f_ref + kt / xb * math.log(1e-3), 1e-9)
    assert out["slope"] == rel(kt / xb, 1e-9)
    assert out["x_beta"] == rel(xb, 1e-9)
    assert out["stderr"] < 1e-6 * abs(out["F0"])
    rng = np.random.default_rng(2)
    noisy = rate_extrapolation(rates, forces + rng.normal(0, 1e-12, 5), target_rate=1e-3,
                               forces_stderr=np.full(5, 1e-12))
    assert abs(noisy["F0"] - out["F0"]) < 4 * noisy["stderr"]
    assert noisy["stderr"] > 1e-12


# --------------------------------------------------------------------------------------- contact angle

@pytest.fixture
def mda():
    require_backend("MDAnalysis", "MDAnalysis")
    import MDAnalysis

    return MDAnalysis


WATER_N = 0.0334                  # water molecules per A^3
WATER_G_CM3 = WATER_N * 18.015 / N_A * 1e24


def cap_universe(mda, theta_deg, radius, box, surface_z, n_frames, x_centre, rng, width=0.0,
                 layering=False, vapour=0.0):
    """A cylindrical cap (axis along y) of water oxygens, uniform in the cap, one frame per draw.

    ``width`` > 0 smears the interface with a tanh profile of that width; ``layering`` adds decaying
    density oscillations next to the wall; ``vapour`` (1/A^3) scatters atoms over the whole box.  The
    droplet is placed at ``x_centre`` (wrapped into the box) with a 2 A random drift per frame.
    """
    from MDAnalysis.coordinates.memory import MemoryReader

    lx, ly, lz = box
    th = math.radians(theta_deg)
    zc = surface_z - radius * math.cos(th)
    xw = (radius if theta_deg >= 90 else radius * math.sin(th)) + 4 * width
    ztop = zc + radius + 4 * width
    pmax = 1.8 if layering else 1.0

    def accept(x, z):
        p = 0.5 * (1 - np.tanh((np.hypot(x, z - zc) - radius) / width)) if width > 0 else \
            (np.hypot(x, z - zc) < radius).astype(float)
        if layering:
            p *= 1 + 0.8 * np.exp(-(z - surface_z) / 2.0) * np.cos(2 * np.pi * (z - surface_z) / 2.8)
        return p

    n_box = int(WATER_N * 2 * xw * (ztop - surface_z) * ly * pmax)
    n_vap = int(vapour * lx * ly * (lz - surface_z))
    expected = None
    frames = []
    for _ in range(n_frames):
        x, z = rng.uniform(-xw, xw, n_box), rng.uniform(surface_z, ztop, n_box)
        keep = rng.uniform(0, pmax, n_box) < accept(x, z)
        if expected is None:
            expected = int(0.9 * keep.sum())            # fixed atom count: thin every frame to it
        p = np.column_stack([x[keep], z[keep]])[:expected]
        assert len(p) == expected
        if n_vap:
            vap = np.column_stack([rng.uniform(0, lx, n_vap), rng.uniform(surface_z, lz, n_vap)])
            p = np.vstack([p[:expected - n_vap], vap])
        xs = (p[:, 0] + x_centre + 2.0 * rng.standard_normal()) % lx
        frames.append(np.column_stack([xs, rng.uniform(0, ly, expected), p[:, 1]]))
    u = mda.Universe.empty(expected, trajectory=True)
    u.load_new(np.array(frames, dtype=np.float32), format=MemoryReader,
               dimensions=np.array([lx, ly, lz, 90.0, 90.0, 90.0]))
    return u


CAPS = {30: (150.0, 260.0), 90: (40.0, 120.0), 120: (30.0, 110.0)}     # theta: (radius, box x) in A


@pytest.mark.parametrize("straddle", [False, True], ids=["centred", "straddling"])
@pytest.mark.parametrize("theta", sorted(CAPS))
def test_contact_angle_of_uniform_circular_cap(mda, theta, straddle):
    radius, lx = CAPS[theta]
    rng = np.random.default_rng(theta + 7 * straddle)
    s = 10.0
    u = cap_universe(mda, theta, radius, (lx, 50.0, 120.0), s, 60, 1.0 if straddle else lx / 2, rng)
    res = ContactAngle(u.atoms, surface_z=s, axis="y").run().results
    assert res.angle_deg == pytest.approx(theta, abs=1.0)
    assert 0 < res.stderr_deg < 1.0
    xc, zc, r = res.circle
    assert r == rel(radius, 0.01)
    assert xc == pytest.approx(0.0, abs=1.0)                      # centred on the droplet
    if theta != 90:
        assert (zc < s) == (theta < 90)                            # centre below the wall: theta < 90
    assert res.bulk_density == rel(0.9 * WATER_G_CM3, 0.03)
    assert res.density_map.shape == (len(res.edges[0]) - 1, len(res.edges[1]) - 1)
    assert np.all(res.interface_points[:, 1] > s + 5.0)


def wobbling_cap(mda, theta_series, area, box, s, rng):
    """A cylindrical cap of fixed cross-section ``area`` (A^2) whose angle follows ``theta_series`` frame by frame:
    a droplet whose shape relaxes over many frames. A fixed number of uniform atoms per frame."""
    from MDAnalysis.coordinates.memory import MemoryReader

    lx, ly, lz = box
    n_atoms = int(0.9 * WATER_N * area * ly)
    frames = []
    for th_deg in theta_series:
        th = math.radians(th_deg)
        radius = math.sqrt(area / (th - math.sin(th) * math.cos(th)))
        zc = s - radius * math.cos(th)
        xw = radius if th_deg >= 90 else radius * math.sin(th)
        pts = np.zeros((0, 2))
        while len(pts) < n_atoms:
            x, z = rng.uniform(-xw, xw, 4 * n_atoms), rng.uniform(s, zc + radius, 4 * n_atoms)
            inside = np.hypot(x, z - zc) < radius
            pts = np.vstack([pts, np.column_stack([x[inside], z[inside]])])
        p = pts[:n_atoms]
        frames.append(np.column_stack([(p[:, 0] + lx / 2) % lx, rng.uniform(0, ly, n_atoms), p[:, 1]]))
    u = mda.Universe.empty(n_atoms, trajectory=True)
    u.load_new(np.array(frames, dtype=np.float32), format=MemoryReader,
               dimensions=np.array([lx, ly, lz, 90.0, 90.0, 90.0]))
    return u


def test_contact_angle_blocks_are_sized_by_how_often_the_droplet_shape_decorrelates(mda):
    """Frames whose angle is independent keep the recipe's 5 blocks; a droplet still relaxing through the run
    (its angle a half sine over 120 frames, +-6 deg, under 1 deg of noise) gets the fewest blocks (3), and the
    run says they are not independent: its stderr is then a lower bound, not an error bar."""
    box, area = (160.0, 30.0, 100.0), math.pi * 35.0 ** 2 / 2
    rng = np.random.default_rng(3)
    free = ContactAngle(wobbling_cap(mda, 90.0 + rng.normal(0, 2.0, 60), area, box, 10.0, rng).atoms,
                        surface_z=10.0, n_blocks=5).run().results
    assert free.n_blocks_used == 5 and free.blocks_independent and free.shape_statistical_inefficiency < 2.0
    assert free.angle_deg == pytest.approx(90.0, abs=1.5) and len(free.block_angles_deg) == 5
    theta = 90.0 + 6.0 * np.cos(np.pi * np.arange(120) / 119) + rng.normal(0, 1.0, 120)
    slow = ContactAngle(wobbling_cap(mda, theta, area, box, 10.0, rng).atoms, surface_z=10.0,
                        n_blocks=5).run().results
    assert slow.n_blocks_used == 3 and not slow.blocks_independent
    assert slow.shape_statistical_inefficiency > 10.0 and len(slow.shape_series_A) == 120


def test_contact_angle_with_diffuse_interface_wall_layering_and_vapour(mda):
    rng = np.random.default_rng(21)
    s = 10.0
    u = cap_universe(mda, 120, 30.0, (110.0, 50.0, 120.0), s, 60, 3.0, rng, width=1.5, layering=True,
                     vapour=2e-5)
    res = ContactAngle(u.atoms, surface_z=s).run().results
    assert res.angle_deg == pytest.approx(120.0, abs=1.0)


def test_contact_angle_along_x_axis(mda):
    """A droplet periodic along x: the map is in (y, z)."""
    rng = np.random.default_rng(4)
    u = cap_universe(mda, 90, 40.0, (120.0, 50.0, 120.0), 10.0, 30, 60.0, rng)
    pos = u.trajectory.coordinate_array
    u.trajectory.coordinate_array[:] = pos[:, :, [1, 0, 2]]        # swap x and y
    u.trajectory.dimensions_array[:, [0, 1]] = u.trajectory.dimensions_array[:, [1, 0]]
    res = ContactAngle(u.atoms, surface_z=10.0, axis="x").run().results
    assert res.angle_deg == pytest.approx(90.0, abs=1.0)


def test_fit_contact_angle_on_exact_coverage_map():
    """Bins filled with the exact area fraction of a 60 deg cap: the half-density contour is the circle."""
    radius, s, th = 50.0, 0.0, math.radians(60)
    zc = s - radius * math.cos(th)
    ue, ze = np.arange(-60, 60.01, 0.5), np.arange(s, 40.01, 0.5)
    sub = (np.arange(8) + 0.5) / 8 * 0.5                               # 8 x 8 samples per bin
    uu, zz = ue[:-1, None] + sub, ze[:-1, None] + sub
    cov = (np.hypot(uu[:, None, :, None], zz[None, :, None, :] - zc) < radius).mean(axis=(2, 3))
    fit = fit_contact_angle(cov, ue, ze, surface_z=s, exclude_layer=3.0)
    assert fit["angle_deg"] == pytest.approx(60.0, abs=0.1)
    assert fit["bulk_density"] == rel(1.0, 1e-9)
    assert fit["fit_rms_A"] < 0.1


def test_contact_angle_needs_a_box(mda):
    from MDAnalysis.coordinates.memory import MemoryReader

    u = mda.Universe.empty(10, trajectory=True)
    u.load_new(np.zeros((2, 10, 3), np.float32), format=MemoryReader)
    with pytest.raises(ValueError, match="box"):
        ContactAngle(u.atoms, surface_z=0.0).run()
    with pytest.raises(ValueError, match="axis"):
        ContactAngle(u.atoms, surface_z=0.0, axis="z")


def test_fit_circle_is_unbiased_on_a_short_noisy_arc():
    """A 30 deg arc with 1 A noise: the algebraic (Kasa) fit alone returns about half the radius."""
    from md.analysis import fit_circle

    rng = np.random.default_rng(3)
    radius = 100.0
    t = np.radians(np.linspace(75, 105, 400))
    radii = [fit_circle(radius * np.cos(t) + rng.normal(0, 1.0, t.size),
                        radius * np.sin(t) + rng.normal(0, 1.0, t.size))[2] for _ in range(5)]
    assert np.mean(radii) == rel(radius, 0.05)
    xc, zc, r = fit_circle([1.0, -1.0, 0.0], [2.0, 2.0, 3.0])      # exact circle through 3 points
    assert (xc, zc, r) == pytest.approx((0.0, 2.0, 1.0), abs=1e-9)
