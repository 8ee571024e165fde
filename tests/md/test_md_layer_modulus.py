"""md.analysis.layer_modulus against synthetic compression branches with known moduli (no LAMMPS needed)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from md.analysis import confined_layer_modulus, sam_layer_thickness_A, young_from_confined

KCAL_PER_MOL = 4184.0 / 6.02214076e23        # J (thermochemical kcal, SI 2019 Avogadro)
PA_PER_KCAL_MOL_A3 = KCAL_PER_MOL / 1e-30    # 1 kcal/mol/A^3 in Pa


def _spring_force(d, modulus_pa, thickness_A, area_A2, d0=0.0):
    """Mean force (kcal/mol/A, repulsion positive) of layers of confined modulus M and total thickness t pressed
    below their zero-force separation d0: sigma = M (d0 - d) / t; beyond d0 a weak attraction."""
    sigma = np.where(d < d0, modulus_pa * (d0 - d) / thickness_A, -2e7 * np.exp(-(d - d0)))
    return sigma / PA_PER_KCAL_MOL_A3 * area_A2


def test_a_linear_spring_gives_its_modulus_exactly():
    """Five repulsive windows of a linear layer (M = 5 GPa, t = 48 A) and an attractive tail: M is recovered to
    round-off, the zero-force point at d0 and the largest strain (d0 - d_min) / t."""
    d = np.array([-4.0, -3.2, -2.4, -1.6, -0.8, 0.3, 1.0, 2.0, 4.0])
    area, t, m = 530.0, 48.0, 5e9
    f = _spring_force(d, m, t, area, d0=0.05)
    r = confined_layer_modulus(d[::-1], f[::-1], np.full(d.size, 0.5), area, t)       # any order
    assert r["modulus_Pa"] == pytest.approx(m, rel=1e-9) and r["windows"] == 5
    assert r["zero_force_separation_A"] == pytest.approx(0.05, abs=1e-9)
    assert r["strain_max"] == pytest.approx(4.05 / 48.0, rel=1e-9) and r["note"] == ""
    # thickness enters linearly: the same curve read as one layer of half the thickness is half as stiff
    assert confined_layer_modulus(d, f, np.full(d.size, 0.5), area, t / 2)["modulus_Pa"] == pytest.approx(m / 2)


def test_a_noisy_spring_lies_within_its_stderr_and_the_stderr_is_calibrated():
    """Windows drawn with their stated stderrs around a 3 GPa spring: over 400 seeded draws the estimate's scatter
    matches the reported stderr (within 15 %) and |M - 3 GPa| <= 2 stderr in about 95 % of draws. Stderrs stated
    3x too small: the reduced chi^2 scales the error up so that coverage stays near 95 %."""
    d = np.linspace(-4.0, -0.5, 6)
    area, t, m = 530.0, 24.0, 3e9
    f = _spring_force(d, m, t, area)
    rng = np.random.default_rng(5)
    for stated, true in ((2.0, 2.0), (2.0 / 3.0, 2.0)):
        est, err = [], []
        for _ in range(400):
            r = confined_layer_modulus(d, f + rng.normal(0, true, d.size), np.full(d.size, stated), area, t)
            est.append(r["modulus_Pa"])
            err.append(r["stderr_Pa"])
        est, err = np.array(est), np.array(err)
        cover = np.mean(np.abs(est - m) <= 2 * err)
        assert 0.88 <= cover <= 0.99
        if stated == true:
            assert np.std(est) == pytest.approx(np.mean(err), rel=0.15)


def test_fewer_than_three_repulsive_windows_is_noted_and_fewer_than_two_refused():
    area, t = 500.0, 40.0
    d = np.array([-1.0, -0.3, 0.5, 1.5])
    f = _spring_force(d, 4e9, t, area, d0=0.0)
    r = confined_layer_modulus(d, f, np.full(4, 0.2), area, t)
    assert r["windows"] == 2 and "only 2 repulsive windows" in r["note"]
    assert r["modulus_Pa"] == pytest.approx(4e9, rel=1e-9) and math.isnan(r["chi2_per_dof"])
    with pytest.raises(ValueError, match="1 repulsive window"):
        confined_layer_modulus(d[1:], f[1:], np.full(3, 0.2), area, t)
    with pytest.raises(ValueError, match="do not stiffen"):
        confined_layer_modulus([-2.0, -1.0, 1.0], [1.0, 5.0, -1.0], [0.1, 0.1, 0.1], area, t)


def test_young_from_confined_inverts_the_uniaxial_strain_modulus():
    """M = E (1 - nu) / ((1 + nu)(1 - 2 nu)): nu = 0 gives E = M, nu = 0.25 gives E = (5/6) M; nu -> 1/2 is
    incompressible (E -> 0 for a finite M) and nu >= 1/2 refused."""
    assert young_from_confined(6e9, 0.0) == pytest.approx(6e9)
    assert young_from_confined(6e9, 0.25) == pytest.approx(5e9)
    e, nu = 2e9, 0.3
    m = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    assert young_from_confined(m, nu) == pytest.approx(e)
    with pytest.raises(ValueError, match="poisson_ratio"):
        young_from_confined(1e9, 0.5)


def test_sam_thickness_counts_every_sam_between_the_slabs():
    sam = {"builder": "ots_sam", "thickness_A": 24.0}
    assert sam_layer_thickness_A({"lower": sam, "upper": sam}) == (48.0, 2)
    assert sam_layer_thickness_A({"lower": {"builder": "silica_slab", "thickness_A": 13.0}, "upper": sam}) == (24.0, 1)
    with pytest.raises(ValueError, match="no SAM"):
        sam_layer_thickness_A({"lower": {"builder": "silica_slab"}, "upper": {"builder": "silica_slab"}})


# ------------------------------------------------------------- the adhesion workflow's conclude on synthetic windows

def _adhesion_ctx(recipe: str, curve, registry_scale=(1.0, 1.0), noise=0.3, drift=0.0, seed=0, stress=None):
    """A stand-in for the engine's context of an adhesion run at quick fidelity: the committed result's system
    record (its slabs, area, SAM thicknesses) without the dispersion tail, registry r's windows sampled from
    registry_scale[r] x curve(d) with white noise (and a linear drift over each window), contact and separated
    energies 10 kcal/mol apart. ``stress`` (d -> (sxx, syy, szz), atm A^3): the SAM atoms' summed stress columns
    (with white noise of 1 % of the largest)."""
    import json
    import types

    from md.recipe import load_recipe
    from md.workflows.adhesion import Adhesion
    from nanoimpact import data

    settings = dict(load_recipe(recipe).settings("quick"))
    res = json.loads((data.shipped_root() / "md" / "results" / f"{recipe}-quick" / "result.json").read_text())
    info = {**res["system"], "tail_applies": False, "tail_study": False,
            "registry_offsets_A": [[0.0, 0.0], [1.0, 2.0]][:len(registry_scale)]}
    nominal = {c[0]: c[1] for c in Adhesion.chains(Adhesion.typed(settings))}
    rng = np.random.default_rng(seed)
    n, zc = 400, 50.0

    def samples(leg, equilibrated=True):
        flat = {"step": np.arange(n) * 10, "stage": np.ones(n), "temp": np.full(n, 300.0)}
        if leg in ("contact", "separated"):
            pe = rng.normal(-1000.0 if leg == "contact" else -990.0, 0.5, n)
            return {**flat, "pe": pe, "z_back": np.full(n, zc), "fz": np.zeros(n)}
        _, reg, suf = leg.split("_")
        d = nominal[suf]
        fz = registry_scale[int(reg[1:])] * curve(d) + rng.normal(0, noise, n) + drift * np.linspace(-1, 1, n)
        out = {**flat, "fz": fz, "z_back": np.full(n, zc + d), "pe": np.zeros(n)}
        if stress is not None:
            sig = stress(d)
            scale = 0.01 * max(abs(x) for x in stress(-4.0))
            out.update({k: v + rng.normal(0, scale, n) for k, v in zip(("sam_sxx", "sam_syy", "sam_szz"), sig)})
        return out

    ctx = types.SimpleNamespace(settings=Adhesion.typed(settings), samples=samples, run_dir=None,
                                plan=types.SimpleNamespace(system_info=info, timestep_fs=1.0, legs=[]),
                                frames=lambda leg: (np.zeros(0), None, None, None))
    return Adhesion(), ctx


def _spring_and_well(slope_kcal_mol_A2):
    """Linear repulsion below d = 0 (slope per A of compression), a smooth attractive well beyond."""
    return lambda d: slope_kcal_mol_A2 * -d if d < 0 else -30.0 * math.sin(math.pi * min(d, 6.0) / 6.0) ** 2


def test_adhesion_conclude_reports_the_sam_layer_modulus_and_registry_zeros_entropic_term():
    """OTS/OTS windows with a linear compression branch (40 kcal/mol/A per A): sam_layer_modulus is
    slope x t / A with t the two SAMs' builder thickness, within its stderr; T dS is dE/A against registry 0's own
    W_F (registry 1 binds 30 % more), not against the registries' mean. Silica/silica: no SAM, no modulus."""
    from md.analysis import KCALMOL_PER_A2_TO_J_PER_M2
    wf, ctx = _adhesion_ctx("adhesion_ots", _spring_and_well(40.0), registry_scale=(1.0, 1.3))
    an = wf.analyse(ctx)
    info = ctx.plan.system_info
    t = info["lower"]["thickness_A"] + info["upper"]["thickness_A"]
    lm = an.quantities["sam_layer_modulus"]
    expect = 40.0 * 0.5 * (1.0 + 1.3) * t / info["area_A2"] * PA_PER_KCAL_MOL_A3
    assert lm["units"] == "Pa" and lm["layers"] == 2 and abs(lm["value"] - expect) <= 3 * lm["stderr"]
    de = 10.0 * KCALMOL_PER_A2_TO_J_PER_M2 / info["area_A2"]
    w0 = an.details["pmf_windows"]["registry_work_J_m2"][0]
    w_mean = an.quantities["work_of_adhesion_free_energy"]["value"]
    tds = an.quantities["entropic_term_TdS"]
    assert tds["value"] == pytest.approx(de - w0, abs=3 * tds["stderr"]) and tds["registry"] == 0
    assert abs(tds["value"] - (de - w_mean)) > 10 * tds["stderr"]
    wf2, ctx2 = _adhesion_ctx("adhesion_silica", _spring_and_well(400.0), registry_scale=(1.0, 1.0, 1.0))
    assert "sam_layer_modulus" not in wf2.analyse(ctx2).quantities


def test_adhesion_window_length_check_flags_drifting_windows_whatever_the_registry_spread():
    """Every window's force drifts linearly by +-1.5 kcal/mol/A (10 x its noise) while two registries differ by
    30 %: the window-length check fails. The same windows without the drift pass (negative control)."""
    for drift, ok in ((1.5, False), (0.0, True)):
        wf, ctx = _adhesion_ctx("adhesion_ots", _spring_and_well(40.0), registry_scale=(1.0, 1.3), drift=drift)
        assert wf.analyse(ctx).details["window_length_check"]["converged"] is ok


# ---------------------------------------------------------------- tangent modulus, thickness at tilt, nu from stress
from md.analysis import (  # noqa: E402
    plane_strain_from_confined,
    poisson_spread,
    stress_ratio_poisson,
    tangent_confined_modulus,
    thickness_at_tilt_A,
)


def test_the_tangent_of_a_stiffening_branch_is_its_slope_at_the_zero_force_point():
    """sigma = M0 x + k x^2 with x = (d0 - d)/t (a branch that stiffens): the tangent at d0 is M0 exactly, the chord
    through the windows is stiffer, the innermost tangent is M0 + 2 k x_max, and the curvature is significant."""
    area, t, m0, k, d0 = 530.0, 44.0, 5e9, 4e10, -1.0
    d = np.array([-5.0, -4.2, -3.4, -2.6, -1.8, -1.2, 0.2, 1.5])
    x = (d0 - d) / t
    sigma = np.where(d < d0, m0 * x + k * x ** 2, -3e7)
    f = sigma / PA_PER_KCAL_MOL_A3 * area
    r = tangent_confined_modulus(d, f, np.full(d.size, 0.05), area, t)
    assert r["modulus_Pa"] == pytest.approx(m0, rel=1e-6)
    assert r["zero_force_separation_A"] == pytest.approx(d0, abs=1e-6) and r["windows"] == 6
    assert r["chord_modulus_Pa"] > 1.2 * m0
    assert r["innermost_tangent_Pa"] == pytest.approx(m0 + 2 * k * (d0 + 5.0) / t, rel=1e-6)
    assert r["curvature_delta_chi2"] > 100.0
    with pytest.raises(ValueError, match="at least four"):
        tangent_confined_modulus(d[3:], f[3:], np.full(5, 0.05), area, t)


def test_the_tangent_stderr_covers_the_truth_in_about_95_percent_of_draws():
    area, t, m0, k, d0 = 530.0, 44.0, 5e9, 3e10, 0.0
    d = np.linspace(-5.0, -0.4, 7)
    x = (d0 - d) / t
    f = (m0 * x + k * x ** 2) / PA_PER_KCAL_MOL_A3 * area
    rng = np.random.default_rng(11)
    hits = [abs((r := tangent_confined_modulus(d, f + rng.normal(0, 0.6, d.size), np.full(d.size, 0.6), area, t))
                ["modulus_Pa"] - m0) <= 2 * r["stderr_Pa"] for _ in range(300)]
    assert 0.88 <= np.mean(hits) <= 0.99


def test_thickness_at_tilt_of_a_rigid_rod_is_its_length_times_cos_tilt():
    """A rod of length L standing on its anchor: height L cos(theta); two layers double it; the stderr is
    L sin(theta) x the spread in radians."""
    length = 22.0
    h = lambda th: length * math.cos(math.radians(th))
    t, e = thickness_at_tilt_A(h, 28.0, 1.0, layers=2)
    assert t == pytest.approx(2 * length * math.cos(math.radians(28.0)))
    assert e == pytest.approx(2 * length * math.sin(math.radians(28.0)) * math.radians(1.0), rel=1e-4)
    with pytest.raises(ValueError, match="tilt_deg"):
        thickness_at_tilt_A(h, 95.0, 1.0)


def test_poisson_ratio_from_the_stress_of_an_isotropic_layer_under_uniaxial_strain():
    """An isotropic layer (E = 4 GPa, nu = 0.38) held laterally and compressed along z: sigma_xx = lambda eps,
    sigma_zz = (lambda + 2 mu) eps; the ratio of the slopes is nu / (1 - nu) and nu comes back; noise with its
    stated stderr gives a stderr that covers nu."""
    e_mod, nu, t = 4e9, 0.38, 44.0
    lam, mu = e_mod * nu / ((1 + nu) * (1 - 2 * nu)), e_mod / (2 * (1 + nu))
    d = np.linspace(-5.0, -1.0, 6)
    eps = (-0.5 - d) / t
    r = stress_ratio_poisson(d, lam * eps, (lam + 2 * mu) * eps, np.full(6, 1e6), np.full(6, 1e6))
    assert r["c13_over_c33"] == pytest.approx(nu / (1 - nu), rel=1e-9)
    assert r["poisson_ratio"] == pytest.approx(nu, rel=1e-9)
    rng = np.random.default_rng(2)
    hits = []
    for _ in range(300):
        q = stress_ratio_poisson(d, lam * eps + rng.normal(0, 2e7, 6), (lam + 2 * mu) * eps + rng.normal(0, 2e7, 6),
                                 np.full(6, 2e7), np.full(6, 2e7))
        hits.append(abs(q["poisson_ratio"] - nu) <= 2 * q["poisson_ratio_stderr"])
    assert np.mean(hits) >= 0.88
    with pytest.raises(ValueError, match="normal stress does not change"):
        stress_ratio_poisson(d, lam * eps, np.zeros(6), np.full(6, 1e6), np.full(6, 1e6))


def test_plane_strain_modulus_at_fixed_confined_modulus_and_the_nu_spread():
    """E' = M (1 - 2 nu)/(1 - nu)^2 equals E / (1 - nu^2) with E from young_from_confined; at nu = 0 it is M. A
    zero-width nu interval has no spread; [0.25, 0.45] about 0.3 spans E'(0.45)/E'(0.3) to E'(0.25)/E'(0.3)."""
    m = 8e9
    for nu in (0.0, 0.2, 0.3, 0.45):
        assert plane_strain_from_confined(m, nu) == pytest.approx(young_from_confined(m, nu) / (1 - nu ** 2))
    assert poisson_spread(0.3, 0.3, 0.3)["relative_stderr"] == pytest.approx(0.0, abs=1e-12)
    s = poisson_spread(0.25, 0.45, 0.3)
    ep = lambda nu: (1 - 2 * nu) / (1 - nu) ** 2
    assert s["ratio_min"] == pytest.approx(ep(0.45) / ep(0.3)) and s["ratio_max"] == pytest.approx(ep(0.25) / ep(0.3))
    assert s["nu_stderr"] == pytest.approx(0.2 / math.sqrt(12)) and 0.1 < s["relative_stderr"] < 0.6


def test_adhesion_conclude_measures_the_layers_poisson_ratio_from_its_own_stress_and_the_tangent_modulus():
    """OTS/OTS windows of a linear branch whose SAM stress is that of an isotropic layer with nu = 0.38 under
    uniaxial strain (lateral = nu/(1 - nu) x normal, compression below d = 0): the workflow reports nu within its
    stderr and C13/C33 = nu/(1 - nu); for a linear branch the small-strain tangent equals the chord (no anneal in
    this context: the builder's thickness). Without the stress columns: no Poisson ratio (negative control)."""
    nu = 0.38
    stress = lambda d: (nu / (1 - nu) * 2e6 * min(d, 0.0), nu / (1 - nu) * 2e6 * min(d, 0.0), 2e6 * min(d, 0.0))
    wf, ctx = _adhesion_ctx("adhesion_ots", _spring_and_well(40.0), registry_scale=(1.0, 1.0), stress=stress)
    an = wf.analyse(ctx)
    pr = an.quantities["sam_poisson_ratio"]
    assert abs(pr["value"] - nu) <= 3 * pr["stderr"] and pr["stderr"] < 0.02
    assert pr["c13_over_c33"] == pytest.approx(nu / (1 - nu), abs=3 * pr["c13_over_c33_stderr"])
    tg, chord = an.quantities["sam_layer_tangent_modulus"], an.quantities["sam_layer_modulus"]
    assert abs(tg["value"] - chord["value"]) <= 3 * tg["stderr"]
    info = ctx.plan.system_info
    assert tg["thickness_m"] == pytest.approx((info["lower"]["thickness_A"] + info["upper"]["thickness_A"]) * 1e-10)
    wf2, ctx2 = _adhesion_ctx("adhesion_ots", _spring_and_well(40.0), registry_scale=(1.0, 1.0))
    assert "sam_poisson_ratio" not in wf2.analyse(ctx2).quantities
