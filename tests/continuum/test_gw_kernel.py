"""The GW surface's compiled values (continuum/rough/gw_kernel.py) against the NumPy reference
(`GWJKRSurface._integral_numpy`), branch by branch.

Norm: |X_kernel - X_numpy| / max(|X_numpy|, S), S = n P_c (pressure), n P_c delta_c (energy), n pi beta delta_c
(contact fraction), the natural scale of the adhesive terms (tests/continuum/test_rough_gw.py); S = 0 for Hertz summits,
where the norm is relative to the value itself. Tolerance 1e-12: the two forms do the same operations in the same
order and take the same exp (NumPy's), so what may differ is round-off only: a multiply-add a compiler fuses on
another CPU (1 ulp of a Horner partial sum, at most ~10x the value, or of the log-Hertz column, which exp turns
into |log F| < 500 ulps of the Hertz term), and below the tables the quadrature's pow and sums (a loop against
BLAS's order). Measured on AMD EPYC: 0 (bit for bit) within the tables, 1.5e-15 at worst below them.

Surfaces are built as the laws build them (`continuum.model.factory.averaged_surface`, and the rough_silica scene's
own through `select_law`): truncated and untruncated, displacement and load release, adhesive and Hertz summits,
sigma/delta_c from 0.3 to 13.7. States cover every branch of `_integral` (checked: the kernel records the branch
it took, the test checks it against the model's definitions and that each branch holds enough states).
"""
import functools
from pathlib import Path

import numpy as np
import pytest

from continuum.model.factory import averaged_surface
from continuum.reference import jkr
from continuum.rough import gw_kernel as gk
from continuum.rough.summits import SummitStatistics, expected_max_height

ROOT = Path(__file__).resolve().parents[2]
TOL = 1e-12
ZMAX = float(expected_max_height(1e5))
PAPER = SummitStatistics(6e-9, 1e13, 2e-7)                     # the `paper` set: sigma 6 nm, beta 0.2 um, n 10/um^2
STRESS_BETA, STRESS_GAMMA, STRESS_E = 1e-7, 0.1, 38e9
STRESS_DC = float(jkr.critical_approach(STRESS_BETA, STRESS_GAMMA, STRESS_E))

#: name -> (stats, work of adhesion, E*, z_max, detachment, resolution)
CASES = {
    "paper, truncated, displacement": (PAPER, 0.1, 10e9, ZMAX, "displacement", "standard"),
    "paper, untruncated, load, fast": (PAPER, 0.1, 10e9, None, "load", "fast"),
    "sigma/delta_c 0.3, truncated, load": (SummitStatistics(0.3 * STRESS_DC, 1e14, STRESS_BETA), STRESS_GAMMA,
                                           STRESS_E, ZMAX, "load", "standard"),
    "sigma/delta_c 3, untruncated, displacement": (SummitStatistics(3.0 * STRESS_DC, 1e14, STRESS_BETA),
                                                   STRESS_GAMMA, STRESS_E, None, "displacement", "standard"),
    "Hertz, truncated": (PAPER, 0.0, 10e9, ZMAX, "displacement", "standard"),
    "Hertz, untruncated, fast": (PAPER, 0.0, 10e9, None, "displacement", "fast"),
}
B = gk
ADHESIVE_BRANCHES = {B.BRANCH_APPROACH, B.BRANCH_RELEASE, B.BRANCH_WINDOW}
TOP_BRANCHES = {B.BRANCH_ABOVE_APPROACH, B.BRANCH_BAND_RELEASE, B.BRANCH_BAND_WINDOW, B.BRANCH_BAND_EMPTY,
                B.BRANCH_BAND_GONE}


@functools.lru_cache(maxsize=None)
def built(name):
    """The surface of CASES[name], or the rough_silica scene's own ("scene")."""
    if name == "scene":
        from continuum.dynamics.impact import first_impact_speed
        from continuum.model import select_law
        from continuum.scene import resolve_scene

        resolved = resolve_scene(ROOT / "inputs" / "scenes" / "rough_silica.toml", params="paper",
                                 overrides={"physics.half_space": "off"})
        return select_law(resolved.scene, first_impact_speed(resolved))[0].surface
    stats, work, e_star, z_max, detachment, resolution = CASES[name]
    return averaged_surface(stats, work_of_adhesion=work, summit_e_star=e_star, z_max=z_max, detachment=detachment,
                            resolution=resolution)


def states(s, seed, n=150):
    """(d, zeta) in m: separations deep below the tables, across them, above z_max (band and beyond it) or past the
    untruncated tables' end, each with thresholds approaching (inf, above d, = d), inside the window, on the release
    join (= d - Delta), releasing and -inf; with truncation also thresholds above z_max; and footprint states as the
    rigid roller's tables ask them (d = z_max + h + x^2/2R, zeta = d - r, r in [0, Delta])."""
    rng = np.random.default_rng(seed)
    dn = s.release_stretch / s.sigma
    top = s.z_max / s.sigma if s.truncated else 6.0
    regions = [(-30.0, -20.001, n // 3), (-20.0, top, 6 * n)]
    if s.truncated:
        if s.adhesive:
            regions += [(top + 1e-9, top + dn * (1.0 - 1e-9), 3 * n)]
        regions += [(top + dn * 1.001 + 1e-6, top + dn + 2.0, n // 3)]
    else:
        regions += [(25.0, 40.0, n // 3)]
    h, z = [], []
    for lo, hi, m in regions:
        hh = rng.uniform(lo, hi, m)
        thresholds = [np.full(m, np.inf), hh + rng.uniform(0.0, 2.0, m), hh, hh - dn * rng.uniform(0.02, 0.98, m),
                      hh - dn, hh - dn - rng.uniform(1e-6, 3.0, m), np.full(m, -np.inf)]
        if s.truncated:
            thresholds += [np.full(m, top), top + (hh - top) * rng.uniform(0.0, 1.0, m)]
        for zz in thresholds:
            h.append(hh)
            z.append(zz)
    # footprint states
    r = dn * rng.uniform(0.0, 1.0, 4 * n)
    r[::7], r[1::7] = 0.0, dn
    gap = rng.uniform(-3.0, 0.5, r.size)
    dd = top + gap + (r - gap).clip(0.0) * rng.uniform(0.0, 1.0, r.size)
    h += [dd]
    z += [dd - r]
    return np.concatenate(h) * s.sigma, np.concatenate(z) * s.sigma


def expected_branch(s, d, zeta):
    """The branch each state belongs to, from the model's definitions (gw.py's docstring), independently of the
    kernel: deeper than the tables (d < -20 sigma); approach (zeta_eff = d: zeta >= d), release (zeta <= d - Delta),
    window; above z_max only stretched summits: none beyond z_max + Delta or when zeta >= z_max."""
    h, zt = d * s._inv_sigma, zeta * s._inv_sigma          # as the surface scales them (a join is a join)
    out = np.where(h < -20.0, B.BRANCH_DEEP, 0)
    if not s.adhesive:
        return out + B.BRANCH_HERTZ
    dn = s._dn
    rel, app = zt <= h - dn, zt >= h
    code = np.where(rel, B.BRANCH_RELEASE, np.where(app, B.BRANCH_APPROACH, B.BRANCH_WINDOW))
    if s.truncated:
        t = s._tmax
        band = np.where(h >= t + dn, B.BRANCH_BAND_GONE,
                        np.where(rel, B.BRANCH_BAND_RELEASE, np.where(zt >= t, B.BRANCH_BAND_EMPTY,
                                                                       B.BRANCH_BAND_WINDOW)))
        code = np.where(h > t, np.where(app, B.BRANCH_ABOVE_APPROACH, band), code)
    return out + code


def worst_error(s, j, d, zeta, got):
    """Worst |got - reference| / max(|reference|, S) per recorded branch code, and the reference."""
    want = s._integral_numpy(j, d, zeta)[0]
    scale = np.maximum(np.abs(want), s._as[j] if s.adhesive else 0.0)
    err = np.abs(got - want)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(err == 0.0, 0.0, err / scale)
    return rel, want


@pytest.mark.parametrize("name", [*CASES, "scene"])
def test_kernel_is_the_numpy_reference_on_every_branch(name):
    s = built(name)
    d, zeta = states(s, seed=len(name))
    branch = np.full(d.size, -1, np.int8)
    codes = expected_branch(s, d, zeta)
    for j in range(3):
        got = s._kernel_values(j, d, zeta, branch)
        assert np.array_equal(branch, codes), "the kernel took another branch than the definitions say"
        rel, want = worst_error(s, j, d, zeta, got)
        for code in np.unique(codes):
            m = codes == code
            assert rel[m].max() <= TOL, (name, j, B.BRANCH_NAMES[code % B.BRANCH_DEEP], code >= B.BRANCH_DEEP,
                                         rel[m].max())
        # the public API is the kernel, shapes kept
        public = (s.pressure, s.energy, s.contact_fraction)[j]
        m = d.size - d.size % 6
        assert np.array_equal(public(d[:m].reshape(-1, 6), zeta[:m].reshape(-1, 6)), got[:m].reshape(-1, 6))
    # every branch the surface has holds enough states to be tested
    counts = {int(c): int(k) for c, k in zip(*np.unique(codes, return_counts=True))}
    if s.adhesive:
        wanted = ADHESIVE_BRANCHES | (TOP_BRANCHES if s.truncated else set())
        wanted |= {B.BRANCH_DEEP + c for c in ADHESIVE_BRANCHES}
    else:
        wanted = {B.BRANCH_HERTZ, B.BRANCH_DEEP + B.BRANCH_HERTZ}
    assert set(counts) == wanted, sorted(set(counts) ^ wanted)
    assert min(counts.values()) >= 40, {B.BRANCH_NAMES[c % 16] + (" deep" if c >= 16 else ""): k
                                        for c, k in counts.items()}


@pytest.mark.parametrize("name", ["paper, truncated, displacement", "sigma/delta_c 0.3, truncated, load"])
def test_a_wrong_table_is_caught_on_its_branch(name):
    """The comparison can fail: the kernel run on tables with 1e-9 S added to one table (every cell's constant term:
    the window table, its release column, the band table, the 1-D table's G column) differs from the reference by
    more than the tolerance on every branch that reads that table, and on no other (those stay bit for bit)."""
    s = built(name)
    d, zeta = states(s, seed=5)
    codes = expected_branch(s, d, zeta)
    reads = {"window": (2, {B.BRANCH_WINDOW, B.BRANCH_BAND_WINDOW}),
             "release column": (3, {B.BRANCH_WINDOW, B.BRANCH_BAND_WINDOW}),
             "band": (4, {B.BRANCH_BAND_RELEASE, B.BRANCH_BAND_WINDOW}),
             "G": (1, {B.BRANCH_APPROACH, B.BRANCH_RELEASE, B.BRANCH_WINDOW, B.BRANCH_ABOVE_APPROACH})}
    for table, (arg, branches) in reads.items():
        args = [a.copy() for a in s._kernel_tables(0)]
        if table == "G":
            args[arg][0, :, 1] += 1e-9
        elif table == "window":
            args[arg][:, 0] += 1e-9
        else:
            args[arg][0, :] += 1e-9
        e = np.exp(gk.log_hertz(d, args[0], args[1]))
        got = gk.integral(0, d, zeta, e, *args, np.zeros(0, np.int8))
        rel, _ = worst_error(s, 0, d, zeta, got)
        for code in branches:
            assert rel[codes == code].max() > 100 * TOL, (table, B.BRANCH_NAMES[code])
        untouched = ~np.isin(codes, list(branches)) & (codes < B.BRANCH_DEEP)
        assert np.array_equal(got[untouched], s._kernel_values(0, d[untouched], zeta[untouched])), table


def test_nan_in_nan_out_and_derivatives_stay_numpy():
    """NaN separations (and NaN thresholds of adhesive surfaces) give NaN (the NumPy form raises on some); the
    stiffness and the pressure's parts come from the NumPy form, whose pressure is the kernel's to round-off."""
    s = built("paper, truncated, displacement")
    d = np.array([np.nan, 1e-9, np.nan, 2e-9])
    z = np.array([0.0, np.nan, np.nan, np.inf])
    assert np.array_equal(np.isnan(s.pressure(d, z)), [True, True, True, False])
    assert np.array_equal(np.isnan(built("Hertz, truncated").pressure(d, z)), [True, False, True, False])
    dd, zz = states(s, seed=11)
    p, k = s.pressure_and_stiffness(dd, zz)
    assert np.array_equal(k, s._integral_numpy(0, dd, zz, deriv=True)[1])
    comp, tens = s.pressure_parts(dd, zz)
    assert np.array_equal(tens, s._integral_numpy(0, dd, zz, parts=True)[1])
    scale = np.maximum(np.abs(p), s._as[0])
    assert np.max(np.abs(p - s.pressure(dd, zz)) / scale) <= TOL
    assert np.max(np.abs(comp + tens - p) / scale) <= TOL
    assert s.pressure(dd[3], zz[3]).shape == ()


def test_warm_up_loads_the_specialisation_the_surfaces_use():
    """`continuum.numerics.compiled_contact.warm_up` compiles (or loads) the kernel with the argument types a surface
    passes, so a forked worker never compiles it again."""
    from continuum.numerics.compiled_contact import warm_up

    warm_up()
    s = built("paper, untruncated, load, fast")
    s.pressure(np.linspace(-1e-8, 1e-8, 5), 0.0)
    built("Hertz, truncated").energy(1e-9, np.inf)
    assert len(gk.integral.signatures) == 1, gk.integral.signatures
    assert len(gk.log_hertz.signatures) == 1, gk.log_hertz.signatures
