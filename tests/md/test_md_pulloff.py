"""Pull-off: the surface-element integration (SEI) against the closed forms it must reduce to, Tabor's parameter,
and the pull-off workflow's protocol options (flat thermostat, several tip positions, two speeds) at plan level."""
from __future__ import annotations

import math

import numpy as np
import pytest

from md.analysis.pulloff import (
    surface_element_force,
    surface_element_pull_off,
    tabor_parameter,
    tabulated_traction,
    tip_height_map,
)


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


# ------------------------------------------------------------------------ protocol options (plans, no LAMMPS)

import json  # noqa: E402

from md import units as U  # noqa: E402
from md.recipe import RecipeError, load_recipe, parse_recipe  # noqa: E402
from md.workflows import get_workflow  # noqa: E402
from md.workflows.pulloff import _residual_drag, _speed_summary  # noqa: E402
from md.workflows.pulloff_protocol import leg_name, tip_offsets  # noqa: E402


def _table(name: str, fidelity: str = "smoke", **override) -> dict:
    t = json.loads(json.dumps(dict(load_recipe(name).raw), default=dict))
    t["fidelity"][fidelity].update(override)
    return t


def _plan(recipe, tmp_path, fidelity="smoke"):
    return get_workflow("pulloff").plan(recipe.settings(fidelity), tmp_path)


def _commands(leg, tmp_path) -> list[str]:
    d = tmp_path / "legs" / leg.name
    return leg.fresh(d) + leg.define(0) + leg.prepare(d)


@pytest.mark.parametrize("name", ["pulloff_silica", "pulloff_ots"])
def test_neutral_options_keep_the_run_identity(name):
    """The new options at their neutral values are today's protocol: written out explicitly they leave the
    canonical settings (hence the committed run hashes) unchanged; any other value enters them."""
    base = load_recipe(name)
    neutral = parse_recipe(_table(name, "quick", flat_thermostat="mobile", tip_positions=1), name=name)
    assert neutral.canonical_sha256("quick") == base.canonical_sha256("quick")
    assert "flat_thermostat" not in base.canonical("quick")["settings"]
    moved = parse_recipe(_table(name, "quick", flat_thermostat="silica"), name=name)
    assert moved.canonical_sha256("quick") != base.canonical_sha256("quick")


def _lattice_equivalent(a, b, cell) -> bool:
    """a and b differ by a translation of the centred rectangular lattice (cell vectors and the (1/2, 1/2)
    centring vector)."""
    f = (np.asarray(a) - np.asarray(b)) / np.asarray(cell)
    return any(np.allclose(np.round(f - c) + c, f, atol=1e-6) for c in (np.zeros(2), np.array([0.5, 0.5])))


def test_tip_offsets_are_distinct_registries_of_the_centred_cell():
    """No offset but the first is a lattice translation, and no two are the same registry."""
    cell = (5.063, 8.769)
    off = tip_offsets(8, cell)
    assert off[0] == (0.0, 0.0)
    for i in range(len(off)):
        for j in range(i):
            assert not _lattice_equivalent(off[i], off[j], cell), (i, j)
    assert _lattice_equivalent((2.5315, 4.3845), (0, 0), cell)      # negative control: the centring vector


def test_positions_plan_has_one_held_contact_per_position(tmp_path):
    """Each tip position has its own data file (the tip shifted laterally by its offset, the flat unmoved), its
    own approach leg (own equilibration seed) and retractions at both speeds from its own hold."""
    rec = load_recipe("pulloff_ots_positions")
    plan = _plan(rec, tmp_path)
    names = [leg.name for leg in plan.legs]
    assert names == ["approach", "retract_0", "retract_1", "approach_p1", "retract_p1_0", "retract_p1_1"]
    from md.system.lammps_data import read_atoms
    _, _, p0 = read_atoms(tmp_path / "system.data")
    _, _, p1 = read_atoms(tmp_path / "system_p1.data")
    n_flat = plan.system_info["n_flat"]
    assert np.allclose(p0[:n_flat], p1[:n_flat])
    box = np.array(plan.system_info["box_A"][:2])
    shift = np.mod(p1[n_flat:, :2] - p0[n_flat:, :2], box)
    assert np.allclose(shift, np.mod(plan.system_info["tip_offsets_A"][1], box), atol=1e-3)
    retract = {leg.name: leg for leg in plan.legs}
    assert "legs/approach_p1/restart." in " ".join(retract["retract_p1_1"].fresh(tmp_path))
    seeds = [c for leg in (retract["approach"], retract["approach_p1"]) for st in leg.stages for c in st.begin
             if c.startswith("velocity mobile create")]
    assert len(seeds) == 2 and seeds[0] != seeds[1]


def test_silica_only_flat_thermostat(tmp_path):
    """'silica': the flat's SAM (all its chain atoms and head groups) is integrated NVE, only the rest of the flat's
    mobile atoms is thermostatted, and the flat's thermostat force is sampled; 'mobile' thermostats the whole flat."""
    rec = load_recipe("pulloff_ots_positions")
    plan = _plan(rec, tmp_path)
    cmds = _commands(plan.legs[0], tmp_path)
    assert any(c.startswith("fix thermo_flat flat_silica langevin") for c in cmds)
    assert "fix integrate_flat_sam flat_sam nve" in cmds
    assert "group flat_silica subtract flat_mobile flat_sam" in cmds
    assert {"f_flat", "p_flat"} <= set(plan.legs[0].columns)
    sys_, _ = get_workflow("pulloff").build(rec.typed_settings("smoke"))
    flat_sam = np.intersect1d(sys_.group("sam"), sys_.group("substrate"))
    assert flat_sam.size and set(sys_.types[flat_sam]) >= {"CH2", "CH3"}
    assert not set(sys_.types[np.setdiff1d(sys_.group("substrate"), flat_sam)]) & {"CH2", "CH3"}
    (tmp_path / "base").mkdir()
    base = _plan(load_recipe("pulloff_ots"), tmp_path / "base")
    bcmds = _commands(base.legs[0], tmp_path / "base")
    assert any(c.startswith("fix thermo_flat flat_mobile langevin") for c in bcmds)
    assert not any("flat_sam" in c for c in bcmds) and "f_flat" not in base.legs[0].columns


def test_recipe_checks_of_the_new_options():
    with pytest.raises(RecipeError, match="retract_speeds_m_s"):
        parse_recipe(_table("pulloff_silica", "quick", retract_speeds_m_s=[30.0, 10.0]), name="x")
    parse_recipe(_table("pulloff_silica", "quick", retract_speeds_m_s=[30.0, 10.0], tip_positions=3), name="x")
    with pytest.raises(RecipeError, match="flat_thermostat"):
        parse_recipe(_table("pulloff_silica", "quick", flat_thermostat="silica", tip_thermostat="lab"), name="x")


def test_leg_names():
    assert leg_name("approach", 0) == "approach" and leg_name("retract_1_2", 0) == "retract_1_2"
    assert leg_name("approach", 3) == "approach_p3" and leg_name("retract_1_2", 3) == "retract_p3_1_2"


def _pull(F, p):
    return {"max_tensile_force": F, "position": p, "local_noise": 0.01}


def test_speed_summary_positions_and_same_contact():
    """Over positions: the mean of the positions' means, stderr = spread / sqrt(n) x Student t(n-1) at one sigma
    (1.8373 for two); one position with repeats: their spread, marked 'same contact'."""
    s = _speed_summary(10.0, [_pull(1.0, 0), _pull(1.2, 0), _pull(2.0, 1)])
    assert s["force"] == pytest.approx(0.5 * (1.1 + 2.0))
    assert s["t_factor"] == pytest.approx(1.8373, abs=1e-4)
    assert s["stderr"] == pytest.approx(1.8373 * np.std([1.1, 2.0], ddof=1) / math.sqrt(2), rel=1e-4)
    one = _speed_summary(10.0, [_pull(1.0, 0), _pull(1.2, 0), _pull(1.4, 0)])
    assert "same contact" in one["how"] and one["stderr"] == pytest.approx(0.2 / math.sqrt(3))


def test_flat_thermostat_force_bookkeeping():
    """Newton for the flat's mobile atoms: F_thermostat = dP_flat/dt + F_gg + f_flat. With constant F_gg = a,
    f_flat = b and a momentum growing at rate c the thermostat force is a + b + c, for the flat as for the tip."""
    n, dt = 200, 1.0
    step = np.arange(n) * 10.0
    a, b, c = 3.0, -1.0, 0.5                       # kcal/mol/A
    c_units = c / U.g_per_mol_A_per_fs2_to_kcal_per_mol_A(1.0)
    rng = np.random.default_rng(1)
    d = {"step": step, "fz": a + 0 * step, "f_flat": b + 0 * step, "p_flat": c_units * step * dt
         + 1e-9 * rng.standard_normal(n), "f_holder": 0 * step, "p_tip": 0 * step}
    assert _residual_drag(d, dt, side="flat")["value"] == pytest.approx(a + b + c, rel=1e-6)
    assert _residual_drag(d, dt)["value"] == pytest.approx(-a, rel=1e-6)


def _hexagonal_face(a: float, n: int, depth: float):
    """A flat face: outermost sites on a hexagonal lattice (spacing a, at z = 0) and a subsurface atom at every
    hollow, ``depth`` above it (further from the flat), in a periodic box of n x n cells."""
    ux, uy = a, a * math.sqrt(3.0)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    base = np.column_stack([i.ravel() * ux, j.ravel() * uy])
    sites = np.vstack([base, base + [ux / 2, uy / 2]])
    hollows = np.vstack([base + [ux / 2, uy / 6], base + [0.0, 2 * uy / 3]])
    xy = np.vstack([sites, hollows])
    z = np.concatenate([np.zeros(len(sites)), np.full(len(hollows), depth)])
    return xy, z, (n * ux, n * uy)


def test_height_map_of_a_flat_face_is_flat_with_reach_at_the_covering_radius():
    """With reach = a / sqrt 3 (the hexagonal covering radius) a flat face maps to one height at a 0.5 A grid,
    so SEI returns the flat-slab law times the area; without reach the fine grid sees the subsurface atoms
    (negative control: the map has holes 1.5 A deep)."""
    a = 5.06
    xy, z, box = _hexagonal_face(a, 6, 1.5)
    m = tip_height_map(xy, z, box, 0.5, reach_A=a / math.sqrt(3.0) + 1e-6)
    assert np.all(m["heights"] == 0.0)
    law = lj93(0.2, 1.5)
    f = surface_element_force(m["heights"], m["cell_area"], law, np.array([2.0]))[0]
    assert f == pytest.approx(float(law(2.0)) * box[0] * box[1], rel=1e-9)
    holes = tip_height_map(xy, z, box, 0.5)
    assert holes["heights"].max() == pytest.approx(1.5)


# ------------------------------------------------------------------- the SEI prediction quoted in docs/md.md

from md.recipe import RECIPE_DIR  # noqa: E402

SEI_JSON = RECIPE_DIR.parent.parent / "docs" / "figures" / "pulloff_sei.json"
DOC = RECIPE_DIR.parent.parent / "docs" / "md.md"


def _sei_row(sei: dict) -> str:
    """The docs table row's cells after the first, formatted from the json (nN, two decimals)."""
    nn = lambda x: f"{x * 1e9:.2f}"
    cut = sei["laws"]["cut"]
    wide = next(v for k, v in cut["maps"].items() if v["bin_A"] == cut["central_map"]["bin_A"]
                and v["reach_A"] > cut["central_map"]["reach_A"])
    return (f"| {nn(sei['measured']['pull_off_force_N'])} ± {nn(sei['measured']['stderr_N'])} | "
            f"{nn(cut['pull_off_force_N'])}" + (f" ({nn(sei['laws']['full']['pull_off_force_N'])} with the tail)"
                                                 if "full" in sei["laws"] else "")
            + f" | {', '.join(nn(x) for x in cut['per_registry_N'])} | {nn(wide['pull_off_force_N'])} | "
            f"{nn(sei['dmt_2piRW_N'])}")


def test_the_sei_numbers_rest_on_the_committed_results_and_the_docs_quote_them():
    """docs/figures/pulloff_sei.json was computed from the committed adhesion and pull-off results (their run hashes
    match), and the docs' table quotes it: rerun benchmarks/pulloff_sei.py after a rerun of either. The adhesion
    recipe is the one the calibration reads for the surface's W, the pull-off the one it validates that W with
    (the json names both)."""
    from calibration.mdset import MAPPING, VALIDATION
    reads = {s.recipe for s in MAPPING if s.key.endswith("work_of_adhesion")}
    sei = json.loads(SEI_JSON.read_text())
    doc = DOC.read_text()
    results = RECIPE_DIR / "results"
    for surface, r in sei.items():
        adh = json.loads((results / f"{r['adhesion_recipe']}-quick" / "result.json").read_text())
        pull = json.loads((results / f"{r['pulloff_recipe']}-quick" / "result.json").read_text())
        assert r["adhesion_recipe"] in reads and (r["pulloff_recipe"], r["adhesion_recipe"]) in VALIDATION
        assert (r["adhesion_run_hash"], r["pulloff_run_hash"]) == (adh["run_hash"], pull["run_hash"])
        assert r["measured"]["pull_off_force_N"] == pull["quantities"]["pull_off_force"]["value"]
        per = [p["max_tensile_force_N"] for p in pull["details"].get("per_position", [])
               if p["speed_m_s"] == pull["quantities"]["pull_off_force"].get("speed_m_s")]
        assert r["measured"]["per_position_N"] == per
        assert _sei_row(r) in doc, _sei_row(r)
