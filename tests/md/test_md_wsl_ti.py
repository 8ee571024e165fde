"""W_SL by thermodynamic integration (md.workflows.wsl_ti, md.analysis.free_energy).

What must hold, each against a closed form or an exact identity, never against numbers a run produced:

* Gauss-Legendre on [0, 1] integrates polynomials of degree 2n - 1 exactly; its error estimate sees a kink;
* the signs of the assembly: a film bound by attraction has W_SL > 0, and W_SL A = I_q(ref) - I_q(film) - I_lj;
* Young-Dupre inverted is the inverse of md.analysis.work_of_adhesion_sl, and W_SL >= 2 gamma_lv is "wets";
* LAMMPS: ``compute fep`` central differences are the derivative of the energy (charges and soft-core lambda);
  the soft-core pair style at lambda = 1 gives the plain style's energy; and with the workflow's fixed PPPM mesh
  the film's charge-stage integrand minus the solid alone's is lambda-independent (U is quadratic in the solid's
  charges, so the difference is the solid-water Coulomb energy at unit charge): the held atoms' solid-solid share
  cancels exactly -- with LAMMPS's own charge-dependent PPPM estimates it does not;
* the plan: the charge stage scales only the solid's types, the LJ stage only solid-water pairs with the solid's
  charges at zero, the reference runs the charge nodes on the solid alone, and every leg uses one PPPM line.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import require_backend
from md.analysis import (
    KCALMOL_PER_A2_TO_J_PER_M2,
    angle_from_work_of_adhesion_sl,
    film_lower_dividing_plane,
    gauss_legendre_unit,
    tether_correction,
    ti_integral,
    ti_work_of_adhesion_sl,
    work_of_adhesion_sl,
)
from md.recipe import RecipeError, load_recipe, parse_recipe

# ------------------------------------------------------------------------------------ quadrature and assembly

@pytest.mark.parametrize("n", [1, 2, 5, 7])
def test_gauss_legendre_is_exact_to_degree_2n_minus_1(n):
    x, w = gauss_legendre_unit(n)
    assert np.all(np.diff(x) < 0) and 0 < x.min() and x.max() < 1          # descending, no end point
    for deg in range(2 * n):
        assert np.dot(w, x**deg) == pytest.approx(1.0 / (deg + 1), rel=1e-12, abs=1e-14)
    # and not beyond: x^(2n) is missed, by far more than round-off (so the test can fail)
    assert abs(np.dot(w, x**(2 * n)) - 1.0 / (2 * n + 1)) > 1e-12


def test_ti_integral_value_error_and_discretisation_estimate():
    x, _ = gauss_legendre_unit(5)
    f = 3.0 * x**2 - 2.0 * x + 1.0                                       # integral 1 - 1 + 1 = 1
    se = np.full_like(x, 0.5)
    r = ti_integral(x, f, se)
    assert r["value"] == pytest.approx(1.0, rel=1e-12)
    assert r["stderr"] == pytest.approx(0.5 * math.sqrt(np.sum(gauss_legendre_unit(5)[1] ** 2)), rel=1e-12)
    assert r["discretisation_error"] < 0.02                              # smooth: the two rules agree
    kinked = np.where(x < 0.3, 40.0, 0.0)                                # a step the nodes barely resolve
    assert ti_integral(x, kinked, se)["discretisation_error"] > 0.1
    with pytest.raises(ValueError, match="not the 5-point Gauss-Legendre nodes"):
        ti_integral(np.linspace(0.1, 0.9, 5), f, se)


def test_the_charge_quadrature_error_is_judged_on_film_minus_reference():
    """A huge term exactly quadratic in lambda (the held atoms' solid-solid share) sits in both charge integrands:
    Gauss-Legendre integrates it exactly, PCHIP does not, so judged apart each shows a large spurious error; their
    difference (what is integrated) is smooth and shows a small one."""
    x, _ = gauss_legendre_unit(5)
    se = np.full_like(x, 1.0)
    quad = -60000.0 * x**2                                              # the shared solid-solid term
    interface = -400.0 * x**1.5
    film, ref = ti_integral(x, quad + interface, se), ti_integral(x, quad, se)
    lj = ti_integral(x, np.zeros_like(x), se)
    assert film["discretisation_error"] > 30 and ref["discretisation_error"] > 30
    w = ti_work_of_adhesion_sl(film, lj, ref, 800.0)
    conv = KCALMOL_PER_A2_TO_J_PER_M2 / 800.0
    assert w["value"] == pytest.approx(400.0 / 2.5 * conv, rel=2e-3)      # int x^1.5 = 1/2.5
    assert w["discretisation_error"] < 1.0 * conv < film["discretisation_error"] * conv


def test_assembly_signs_and_units():
    area = 800.0
    one = lambda v, e=0.0: {"value": v, "stderr": e, "discretisation_error": 0.0}   # noqa: E731
    # film: charges give -500 more than the solid alone does, LJ -60 (attraction): W A = 500 + 60 kcal/mol
    w = ti_work_of_adhesion_sl(one(-30500.0, 3.0), one(-60.0, 4.0), one(-30000.0, 0.0), area)
    conv = KCALMOL_PER_A2_TO_J_PER_M2 / area
    assert w["value"] == pytest.approx(560.0 * conv) and w["value"] > 0
    assert w["electrostatic"] == pytest.approx(500.0 * conv) and w["dispersion"] == pytest.approx(60.0 * conv)
    assert w["stderr"] == pytest.approx(5.0 * conv)


def test_the_tether_adds_its_energy_at_full_coupling():
    """A film bound 1.7 A below the spring's anchor carries k/2 (1.7)^2 that decoupling releases: the integral is
    short by that much, so it is added (positive), whichever side of the anchor the film sits on."""
    rng = np.random.default_rng(3)
    for offset in (-1.7, 1.7):
        z = 33.0 + offset + 0.1 * rng.standard_normal(4000)
        tc = tether_correction(z, 33.0, 1.0, 800.0)
        assert tc["energy_kcal_mol"] == pytest.approx(0.5 * (1.7**2 + 0.01), rel=0.03)
        assert tc["value"] == pytest.approx(tc["energy_kcal_mol"] * KCALMOL_PER_A2_TO_J_PER_M2 / 800.0)
        assert tc["offset_A"] == pytest.approx(offset, abs=0.01) and tc["value"] > 0


@pytest.mark.parametrize("theta", [5.0, 30.0, 90.0, 125.0, 170.0])
def test_young_dupre_inversion_round_trip(theta):
    g = 0.0636
    wl = work_of_adhesion_sl(g, theta, None, 1.0)
    back = angle_from_work_of_adhesion_sl(wl["value"], wl["stderr"], g)
    assert back["status"] == "measured"
    assert back["theta_deg"] == pytest.approx(theta, abs=1e-9)
    assert back["stderr_deg"] == pytest.approx(1.0, rel=1e-9)            # first order both ways


def test_wetting_and_dewetting_marks():
    g = 0.0636
    wets = angle_from_work_of_adhesion_sl(0.140, 0.004, g)
    assert wets["status"] == "wets" and wets["theta_deg"] == 0.0 and wets["stderr_deg"] is None
    assert wets["spreading_coefficient"] == pytest.approx(0.140 - 2 * g)
    assert wets["theta_upper_deg"] == 0.0                                 # one stderr below is still >= 2 gamma
    near = angle_from_work_of_adhesion_sl(0.128, 0.005, g)
    assert near["status"] == "wets" and 0 < near["theta_upper_deg"] < 25
    assert angle_from_work_of_adhesion_sl(-0.001, 0.0, g)["status"] == "dewets"


def test_recipe_keys_and_the_silica_only_rule():
    s = load_recipe("wsl_silica").settings("quick")
    assert s["surface"] == "silica" and s["silica_face"] == "111" and s["water_model"] == "spce"
    assert s["slab_thickness_A"] == load_recipe("contact_angle_silica").settings("quick")["slab_thickness_A"]


def _with_system(name, **system):
    raw = load_recipe(name).raw
    t = {k: (dict(v) if isinstance(v, dict) else v) for k, v in raw.items()}
    t["system"] = dict(t["system"], **system)
    return parse_recipe(t, name=name)


def test_the_sam_keys_define_a_ti_run_only_on_ots():
    """On silica the SAM keys change nothing, so they stay out of the run's identity (the committed wsl_silica
    result keeps its hash); on OTS they are part of it, and a wrong one is refused by name."""
    silica = load_recipe("wsl_silica")
    assert "sam_coverage" not in silica.canonical("quick")["settings"]
    assert _with_system("wsl_silica", sam_coverage=3.0).canonical_sha256("quick") == silica.canonical_sha256("quick")
    ots = load_recipe("wsl_ots")
    assert ots.canonical("quick")["settings"]["sam_coverage"] == 4.5
    assert _with_system("wsl_ots", sam_coverage=3.0).canonical_sha256("quick") != ots.canonical_sha256("quick")
    with pytest.raises(RecipeError, match=r"system\.sam_coverage = 5\.0"):
        _with_system("wsl_ots", sam_coverage=5.0)
    # the other workflows hash their SAM keys on every surface, as their committed results were hashed
    assert "sam_coverage" in load_recipe("contact_angle_silica").canonical("quick")["settings"]


# ------------------------------------------------------------------------------------ the plan

def _plan(tmp_path, recipe="wsl_silica"):
    from md.workflows import get_workflow
    s = load_recipe(recipe).settings("smoke")
    return s, get_workflow("wsl_ti").plan(s, tmp_path)


#: recipe -> (the charged solid types the charge stage scales, every solid type the dispersion stage decouples)
_SOLIDS = {"wsl_silica": (("SC4", "OC23", "OC24", "HOY"), ("SC4", "OC23", "OC24", "HOY")),
           "wsl_ots": (("SC4", "OC23", "OC24", "HOY", "SIH"), ("SC4", "OC23", "OC24", "HOY", "SIH", "CH2", "CH3"))}


def _cmds(leg, tmp_path):
    d = tmp_path / "legs" / leg.name
    return leg.fresh(d) + leg.define(0) + leg.prepare(d)


@pytest.mark.parametrize("recipe", sorted(_SOLIDS))
def test_plan_legs_scale_the_right_things(tmp_path, recipe):
    s, plan = _plan(tmp_path, recipe)
    names = [leg.name for leg in plan.legs]
    nq, nl = s["ti_charge_nodes"], s["ti_lj_nodes"]
    assert names == (["substrate", "film"] + [f"q{k}" for k in range(nq)] + [f"lj{k}" for k in range(nl)]
                     + [f"ref_q{k}" for k in range(nq)])
    ids = plan.system_info["type_ids"]
    charged_types, all_types = _SOLIDS[recipe]
    solid = {str(ids[t]) for t in charged_types}
    every = {str(ids[t]) for t in all_types}
    water = {str(ids["OW"]), str(ids["HW"])}
    pppm = {c for leg in plan.legs for c in _cmds(leg, tmp_path) if c.startswith("kspace_modify slab 3.0 gewald")}
    assert len(pppm) == 1                                                 # one G and one mesh for every leg
    for leg in plan.legs[2:]:
        cmds = _cmds(leg, tmp_path)
        adapt = next(c for c in cmds if " adapt/fep " in c).split()
        charged = {adapt[i + 2] for i, w in enumerate(adapt) if w == "atom"}
        assert charged == solid                          # the solid's charged types, nothing else
        pairs = {(adapt[i + 3], adapt[i + 4]) for i, w in enumerate(adapt) if w == "pair"}
        fep = [c for c in cmds if " fep " in c and c.startswith("compute")]
        assert len(fep) == 2
        lam = {c.split()[1]: float(c.split()[-1]) for c in cmds if c.startswith("variable l")}
        if leg.name.startswith("ref"):
            text = " ".join(cmds)
            assert not pairs and "tether" not in text and "read_data" not in text and leg.n_atoms < plan.n_atoms
        else:
            assert pairs == {(i, j) for i in every for j in water}        # every solid-water pair, no other
        thermostats = [c.split()[2] for c in cmds if c.startswith("fix thermostat")]
        # the water and the solid's mobile atoms each have their own thermostat; the solid alone one
        assert thermostats == (["mobile"] if leg.name.startswith("ref") else ["water", "solidmobile"]), leg.name
        if leg.name.startswith("lj"):
            assert lam["lq"] == 0.0 and 0 < lam["ll"] < 1 and all(" pair " in c for c in fep)
        else:
            assert 0 < lam["lq"] < 1 and lam["ll"] == 1.0 and all(" atom charge " in c for c in fep)


@pytest.mark.parametrize("recipe", sorted(_SOLIDS))
def test_each_reference_node_starts_from_its_film_nodes_start_without_the_water(tmp_path, recipe):
    """The solid-alone node k reads the restart film node k reads and deletes the water, so both start from one
    solid configuration and the solid-solid share of dU/dlambda_q cancels in their difference."""
    s, plan = _plan(tmp_path, recipe)
    legs = {leg.name: leg for leg in plan.legs}
    reads = set()
    for k in range(s["ti_charge_nodes"]):
        film = legs[f"q{k}"].fresh(tmp_path / "legs" / f"q{k}")
        ref = legs[f"ref_q{k}"].fresh(tmp_path / "legs" / f"ref_q{k}")
        read = [c for c in film if c.startswith("read_restart")]
        assert len(read) == 1 and [c for c in ref if c.startswith("read_restart")] == read
        reads.add(read[0])
        i = ref.index(read[0])
        assert "delete_atoms group water mol yes bond yes compress no" in ref[i + 1:]
        assert legs[f"ref_q{k}"].info["start"].startswith(("film", "q"))
    assert len(reads) == s["ti_charge_nodes"] and not any("/substrate/" in r for r in reads)


def test_only_the_ots_film_leg_frames_the_water_and_the_trappe_sites(tmp_path):
    """OTS: the film leg's second half is sampled and frames the water O and CH2/CH3 (for the dispersion tail);
    silica keeps its single unsampled film stage and no frames (its plan, and committed result, unchanged)."""
    (tmp_path / "s").mkdir()
    (tmp_path / "o").mkdir()
    _, silica = _plan(tmp_path / "s")
    film = silica.legs[1]
    assert film.frames is None and [st.sampled for st in film.stages] == [False]
    assert not silica.system_info["tail_site_ids"]
    s, ots = _plan(tmp_path / "o", "wsl_ots")
    film = ots.legs[1]
    assert film.frames is not None and [st.sampled for st in film.stages] == [False, True]
    assert film.total_steps == s["equilibrate_steps"]
    ids = ots.system_info["type_ids"]
    group = next(c for c in _cmds(film, tmp_path / "o") if c.startswith("group framed")).split()
    assert group[2] == "type" and set(group[3:]) == {str(ids[t]) for t in ("OW", "CH2", "CH3")}
    n_sites = len(ots.system_info["tail_site_ids"])
    assert n_sites == len(ots.system_info["tail_site_c6_kcal_A6"]) > 0


class _Ctx:
    """the part of an analysis context leg_temperatures reads: legs and their samples"""
    def __init__(self, series):
        from md.engine.plan import Stage
        self.series = series
        self.legs = [type("L", (), {"name": n, "stages": [Stage("s", 1)]})() for n in series]

    def samples(self, name, sampled_only=True):
        return self.series[name]


def test_leg_temperatures_are_reported_and_an_off_target_leg_is_flagged():
    from md.workflows.common import TEMPERATURE_TOLERANCE_K, leg_temperatures
    ok = {"temp_water": np.full(40, 301.0), "temp_solid": np.full(40, 299.0)}
    hot = {"temp_water": np.r_[np.full(20, 500.0), np.full(20, 420.0)], "temp_solid": np.full(40, 165.0)}
    ctx = _Ctx({"film": hot, "q0": ok})
    r = leg_temperatures(ctx, ctx.legs, 300.0, second_half=("film",))
    assert r["per_leg"]["film"]["water"] == 420.0                     # the film leg: its second half only
    assert r["off_target_legs"] == ["film"] and "OFF TARGET on film (420 / 165 K)" in r["note"]
    assert r["max_deviation_K"]["solid"] == 135.0
    ctx = _Ctx({"film": ok, "q0": {"temp_water": np.full(40, 300.0 + TEMPERATURE_TOLERANCE_K - 0.5),
                                   "temp_solid": np.full(40, 300.0)}})
    r = leg_temperatures(ctx, ctx.legs, 300.0, second_half=("film",))
    assert not r["off_target_legs"] and "within" in r["note"]
    # not sampled: nothing
    assert leg_temperatures(_Ctx({"film": {"pe": np.ones(3)}}), _Ctx({"film": {}}).legs, 300.0) == {}


def test_film_dividing_plane_of_a_uniform_slab():
    """Molecules uniform between z = 10 and 30 A at 0.0334 /A^3: the plane at 10 (within half a bin), the bulk
    density and the thickness recovered; a denser first layer (wall layering) does not move the plane."""
    rng = np.random.default_rng(7)
    area, rho, frames = 400.0, 0.0334, 50
    n = int(rho * area * 20.0)
    z = rng.uniform(10.0, 30.0, size=(frames, n))
    r = film_lower_dividing_plane(z, area, frames)
    assert abs(r["z_A"] - 10.0) < 0.25 and abs(r["number_density_A3"] / rho - 1) < 0.02
    assert abs(r["film_thickness_A"] - 20.0) < 0.5
    layer = rng.uniform(10.0, 11.0, size=(frames, int(rho * area)))      # doubles the density of the first angstrom
    r2 = film_lower_dividing_plane(np.concatenate([z, layer], axis=1), area, frames)
    assert abs(r2["z_A"] - 10.0) < 0.25 and abs(r2["number_density_A3"] / rho - 1) < 0.03


# ------------------------------------------------------------------------------------ LAMMPS identities

def _smoke_film(tmp_path):
    """(settings, built system, force field) of the smoke recipe, the film's data file written to tmp_path"""
    require_backend("lammps", "LAMMPS")
    from md.system.lammps_data import write_data
    from md.workflows.common import forcefield_of
    from md.workflows.wsl_ti import WslTI
    s = load_recipe("wsl_silica").typed_settings("smoke")
    wf = WslTI()
    _, _, system = wf.build(wf.typed(s))
    ff = forcefield_of(wf.forcefield_files(s))
    write_data(system, ff, tmp_path / "film.data")
    return s, system, ff


def _lammps_pair(tmp_path, fixed_pppm: bool):
    """(film, solid alone) LAMMPS instances on the smoke build, soft-core pair style, nothing run yet."""
    from md.lammps_loader import new_lammps
    from md.system.lammps_data import lammps_setup_commands, write_data
    from md.system.topology import remove_atoms
    from md.workflows.wsl_ti import pppm_lines
    s, system, ff = _smoke_film(tmp_path)
    write_data(remove_atoms(system, system.group("adsorbate")), ff, tmp_path / "solid.data")
    out = []
    for name in ("film", "solid"):
        lmp = new_lammps()
        for c in lammps_setup_commands(ff, tmp_path / f"{name}.data", pair="long/soft", kspace_accuracy=1e-4):
            lmp.command(c)
        if fixed_pppm:
            lmp.command(pppm_lines(s, system.cell)[0])
        out.append(lmp)
    return out


def _dudl_q(lmp, lam, delta=0.002):
    """central-difference dU/dlambda_q by compute fep at solid charges lam x q0, as the workflow samples it"""
    q0 = {1: 1.1, 2: -0.55, 3: -0.675, 4: 0.4}
    for t, q in q0.items():
        lmp.command(f"set type {t} charge {q * lam:.12g}")
    plus = " ".join(f"atom charge {t} v_p{t}" for t in q0)
    minus = " ".join(f"atom charge {t} v_m{t}" for t in q0)
    for t, q in q0.items():
        lmp.command(f"variable p{t} equal {q * delta:.12g}")
        lmp.command(f"variable m{t} equal {-q * delta:.12g}")
    lmp.command(f"compute fp all fep 300 {plus}")
    lmp.command(f"compute fm all fep 300 {minus}")
    lmp.command("thermo_style custom step pe c_fp[1] c_fm[1]")
    lmp.command("run 0")
    d = (lmp.extract_compute("fp", 0, 1)[0] - lmp.extract_compute("fm", 0, 1)[0]) / (2 * delta)
    pe = lmp.get_thermo("pe")
    lmp.command("uncompute fp")
    lmp.command("uncompute fm")
    return d, pe


@pytest.mark.md
def test_compute_fep_is_the_energy_derivative_and_the_solid_solid_share_cancels(tmp_path):
    film, solid = _lammps_pair(tmp_path, fixed_pppm=True)
    # the derivative: U(lambda) is quadratic in the solid's charges, so a wide central difference of energies
    # must equal compute fep's narrow one
    d_mid, _ = _dudl_q(film, 0.5)
    _, u_hi = _dudl_q(film, 0.6)
    _, u_lo = _dudl_q(film, 0.4)
    assert d_mid == pytest.approx((u_hi - u_lo) / 0.2, rel=1e-6, abs=1e-3)
    # the cancellation: film minus solid alone is the solid-water Coulomb energy, the same at every lambda
    diffs = [_dudl_q(film, lam)[0] - _dudl_q(solid, lam)[0] for lam in (0.2, 0.5, 0.9)]
    big = abs(_dudl_q(solid, 0.9)[0])
    assert big > 100 * abs(diffs[0])                                       # what cancels is large
    assert np.ptp(diffs) < 1e-6 * big + 1e-3, diffs


@pytest.mark.md
def test_without_one_pppm_mesh_the_solid_solid_share_does_not_cancel(tmp_path):
    """The reason pppm_lines exists: LAMMPS's own G and mesh depend on the charges present (film vs solid alone),
    and the difference then drifts with lambda by more than it does with the fixed mesh."""
    film, solid = _lammps_pair(tmp_path, fixed_pppm=False)
    diffs = [_dudl_q(film, lam)[0] - _dudl_q(solid, lam)[0] for lam in (0.2, 0.9)]
    big = abs(_dudl_q(solid, 0.9)[0])
    assert abs(diffs[1] - diffs[0]) > 1e-6 * big + 1e-3, diffs


@pytest.mark.md
def test_soft_core_at_lambda_one_is_the_plain_pair_style(tmp_path):
    from md.lammps_loader import new_lammps
    from md.system.lammps_data import lammps_setup_commands
    _, _, ff = _smoke_film(tmp_path)
    e = {}
    for pair in ("long", "long/soft"):
        lmp = new_lammps()
        for c in lammps_setup_commands(ff, tmp_path / "film.data", pair=pair, kspace_accuracy=1e-5):
            lmp.command(c)
        lmp.command("thermo_style custom step pe evdwl ecoul elong")
        lmp.command("run 0")
        e[pair] = {k: lmp.get_thermo(k) for k in ("evdwl", "ecoul", "elong")}
    # the same algebra evaluated two ways: round-off of ~1e-16 per pair, summed with cancellation over the pairs,
    # stays far below 1e-8 of the total on any CPU; a wrong lambda or sigma moves it by percents
    assert e["long/soft"]["evdwl"] == pytest.approx(e["long"]["evdwl"], rel=1e-8, abs=1e-8)
    assert e["long/soft"]["elong"] == pytest.approx(e["long"]["elong"], rel=1e-8, abs=1e-8)
    # real-space Coulomb: the plain style tabulates erfc (pair_modify table 12), the soft style does not
    assert e["long/soft"]["ecoul"] == pytest.approx(e["long"]["ecoul"], rel=1e-5)


@pytest.mark.md
def test_the_ots_result_adds_the_dispersion_tail_into_w_sl(md_smoke):
    """On OTS the water-TraPPE dispersion beyond the cutoff is positive (it only attracts), reported apart and
    included in W_SL: W_SL = electrostatic + dispersion + tether + tail (J/m^2); silica has no such part."""
    r = md_smoke("wsl_ots").outcome.result
    q, d = r["quantities"], r["details"]
    tail = q["dispersion_tail_work_sl"]["value"]
    assert tail > 0 and d["dispersion_tail"]["frames"] >= 1 and d["dispersion_tail"]["sites"] > 0
    parts = d["parts_J_m2"]
    total = parts["electrostatic"] + parts["dispersion"] + parts["tether_correction"]["value"] + tail
    # the same four floats summed in another grouping: a few roundings of terms within 10x of the sum, so 1e-12
    # relative holds on any IEEE-754 CPU; the negative control: without the tail the sum misses W_SL by far more
    w = q["work_of_adhesion_sl"]["value"]
    assert w == pytest.approx(total, rel=1e-12, abs=1e-15)
    assert w != pytest.approx(total - tail, rel=1e-6)
    assert any("beyond the 12 A cutoff" in n for n in r["notes"])
    assert "dispersion_tail_work_sl" not in md_smoke("wsl_silica").outcome.result["quantities"]



@pytest.mark.md
def test_the_window_length_check_leaves_the_tail_error_out_of_its_tolerance(md_smoke, tmp_path, monkeypatch):
    """Both halves of the nodes' samples get the same tail (and tether) added, so the tail's error cancels in
    their difference and must stay out of the check's tolerance, 2 x 2 x the nodes' statistical stderr. The smoke
    OTS run is analysed again with its tail given a stderr three times the nodes' (at smoke the tail has none):
    W_SL's stderr takes it in quadrature, the tolerance does not (with W_SL's whole stderr it would be 3.2 x
    wider)."""
    import md.workflows.wsl_ti as wsl
    from md.engine.store import RunContext
    from md.recipe import load_recipe
    from md.workflows import get_workflow
    from md.workflows.facade import job_for
    out = md_smoke("wsl_ots").outcome
    assert out.result["details"]["dispersion_tail"]["stderr"] == 0.0
    nodes = out.result["quantities"]["work_of_adhesion_sl"]["stderr"]      # the nodes' own, with no tail error
    job = job_for(load_recipe("wsl_ots"), "smoke")
    wf = get_workflow(job.workflow)
    plan = wf.plan(job.settings, tmp_path)                                  # the same build, written aside
    real = wsl._dispersion_tail

    def noisy_tail(ctx, info, s):
        tail = dict(real(ctx, info, s))
        tail["stderr"] = 3.0 * nodes
        return tail
    monkeypatch.setattr(wsl, "_dispersion_tail", noisy_tail)
    an = wf.analyse(RunContext(out.run_dir, plan, job.settings))
    assert an.quantities["work_of_adhesion_sl"]["stderr"] == pytest.approx(math.hypot(nodes, 3.0 * nodes), rel=1e-9)
    assert an.details["window_halves_J_m2"]["difference_sigma"] == pytest.approx(4.0 * nodes, rel=1e-9)
