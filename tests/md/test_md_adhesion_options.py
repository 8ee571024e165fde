"""Adhesion protocol options: registries (rank-1 offsets, degenerate pairs, each registry's own zero-load contact),
the silica lattice key, neutral options and the run hash, extra outward windows, the SAM anneal leg and stress
sampling, the return chain; then their LAMMPS smoke runs.

Tests marked ``md`` run LAMMPS at smoke fidelity (seconds each); the rest need no LAMMPS.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from recipe_helpers import recipe_with, run_quiet, settings_with

from md.recipe import load_recipe, parse_recipe


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("md-adhesion-cache")



# ------------------------------------------------------------------------------------ protocol options (no LAMMPS)

def _plan(name, fidelity, tmp_path, **override):
    from md.workflows.adhesion import Adhesion
    s = settings_with(name, fidelity, **override)
    return s, Adhesion().plan(s, tmp_path)




def test_rank1_second_offset_is_a_lattice_translation_and_primitive_offsets_never_are(tmp_path):
    """The rank-1 generator's second offset for n = 2 on the centred (111) cell, (a/2 sqrt 2, a sqrt 6/4) =
    (2.531, 4.385) A, maps both built slabs onto themselves (every heavy atom onto one of its type): it repeats
    registry 0, and the plan names it degenerate. The primitive-cell generator's offsets never map a slab onto
    itself, nor onto each other, for any n up to 12, and lie at least MIN_REGISTRY_SPACING_A apart modulo the
    lattice, whose cell is half the rectangular one (the centring vector found from the slabs)."""
    from md.workflows.adhesion import Adhesion
    from md.workflows.adhesion_legs import _AdhesionLegs
    from md.workflows.adhesion_registries import (
        MIN_REGISTRY_SPACING_A,
        degenerate_registries,
        lattice_distance,
        maps_onto_itself,
        primitive_offsets,
    )
    s = settings_with("adhesion_ots", "quick")
    legs = _AdhesionLegs(Adhesion(), Adhesion.typed(s), tmp_path)
    plan = Adhesion().plan(s, tmp_path)
    info = plan.system_info
    sysm = legs.system
    slabs = [(sysm.positions[g], sysm.types[g]) for g in (legs.groups["lower"], legs.groups["upper"])]
    box = sysm.cell[:2]
    assert info["registry_sampling"] == "rank1" and s["lateral_registries"] == 2
    off = info["registry_offsets_A"][1]
    assert off == pytest.approx([2.531442, 4.384587], abs=1e-6)
    assert all(maps_onto_itself(p, t, box, off) for p, t in slabs)
    assert info["degenerate_registries"] == [[1, 0]]
    # a shift that is no translation is refused by the same test (it can fail)
    assert not maps_onto_itself(*slabs[0], box, (1.0, 0.5))
    lattice = np.array(info["surface_lattice_A"])
    cell = (box[0] / s["nx"], box[1] / s["ny"])
    assert abs(np.linalg.det(lattice)) == pytest.approx(cell[0] * cell[1] / 2, rel=1e-9)
    for n in range(2, 13):
        offs = primitive_offsets(n, lattice)
        assert offs[0] == (0.0, 0.0) and len(offs) == n
        assert degenerate_registries(offs, lattice) == []
        for r in range(1, n):
            assert not any(maps_onto_itself(p, t, box, offs[r]) for p, t in slabs)
            for r0 in range(r):
                assert lattice_distance(np.subtract(offs[r], offs[r0]), lattice) >= MIN_REGISTRY_SPACING_A - 1e-6
    (tmp_path / "p").mkdir()
    plan_p = Adhesion().plan({**s, "registry_sampling": "primitive"}, tmp_path / "p")
    assert plan_p.system_info["degenerate_registries"] == []
    assert plan_p.system_info["registry_offsets_A"] == [list(o) for o in primitive_offsets(2, lattice)]


def test_degenerate_registries_are_named_in_the_notes():
    from md.workflows.adhesion_protocol import degenerate_note
    from md.workflows.plan_records import AdhesionPlanRecord
    info = {"registry_offsets_A": [[0.0, 0.0], [2.531442, 4.384587]], "degenerate_registries": [[1, 0]],
            "surface_lattice_A": [[5.06, 0.0], [2.53, 4.38]]}
    common = {"area_A2": 100.0, "n_lower": 10}
    (note,) = degenerate_note(AdhesionPlanRecord.from_system({**common, **info}))
    assert note.startswith("REGISTRIES DEGENERATE") and "2 chains sample 1 distinct registry" in note
    assert degenerate_note(AdhesionPlanRecord.from_system({**common, **info, "degenerate_registries": []})) == []


def _system(name, **override):
    """The shipped recipe ``name`` with keys of its [system] table replaced."""
    t = json.loads(json.dumps(dict(load_recipe(name).raw), default=dict))
    t["system"].update(override)
    return parse_recipe(t, name=name)


def test_the_silica_lattice_key_is_neutral_at_the_builders_cell_and_builds_any_other(tmp_path):
    """silica_lattice_A: its neutral value is the builder's own constant, so every shipped recipe of every
    workflow that builds silica keeps its hash; another value enters the hash and builds both slabs (and an OTS
    substrate) with that cell: the (111) surface cell is a/sqrt2 x a sqrt(3/2)."""
    from md.build.silica import CRISTOBALITE_A
    from md.recipe import BUILDER_LATTICE_A, NEUTRAL_KEYS, RECIPE_DIR
    from md.workflows import get_workflow
    assert BUILDER_LATTICE_A == CRISTOBALITE_A
    for path in sorted(RECIPE_DIR.glob("*.toml")):
        r = load_recipe(path.stem)
        if r.workflow in NEUTRAL_KEYS and "silica_lattice_A" in NEUTRAL_KEYS[r.workflow]:
            assert "silica_lattice_A" not in r.canonical("quick")["settings"], path.stem
            assert _system(path.stem, silica_lattice_A=BUILDER_LATTICE_A).canonical_sha256("quick") == \
                r.canonical_sha256("quick")
    base = load_recipe("adhesion_silica_ots").canonical_sha256("smoke")
    rec = _system("adhesion_silica_ots", silica_lattice_A=7.02)
    assert rec.canonical_sha256("smoke") != base
    s = rec.settings("smoke")
    plan = get_workflow("adhesion").plan(s, tmp_path)
    box = plan.system_info["box_A"]
    assert box[0] == pytest.approx(s["nx"] * 7.02 / math.sqrt(2.0), rel=1e-9)
    assert box[1] == pytest.approx(s["ny"] * 7.02 * math.sqrt(1.5), rel=1e-9)


@pytest.mark.parametrize("name", ["adhesion_silica", "adhesion_ots", "adhesion_silica_ots"])
def test_protocol_options_at_their_neutral_values_leave_the_run_hash_alone(name):
    """The shipped calibration recipes do not set the protocol options, so their canonical settings (hence the
    hashes of the committed results) are what they were; any non-neutral value enters the hash."""
    from md.recipe import NEUTRAL_KEYS
    neutral = NEUTRAL_KEYS["adhesion"]
    for fid in ("smoke", "quick", "production"):
        r = load_recipe(name)
        assert not set(neutral) & set(r.canonical(fid)["settings"])
        base = r.canonical_sha256(fid)
        assert recipe_with(name, fid, registry_sampling="rank1", pmf_return=False).canonical_sha256(fid) == base
        for key, value in (("registry_sampling", "primitive"), ("registry_contact_steps", 1000),
                           ("sam_anneal_steps", 1000), ("pmf_return", True), ("pmf_extra_windows_A", [2.3]),
                           ("sam_stress", True)):
            assert recipe_with(name, fid, **{key: value}).canonical_sha256(fid) != base, (key, fid)


def test_extra_windows_enter_the_outward_grid_and_are_checked():
    from md.recipe import RecipeError
    from md.workflows.adhesion import Adhesion
    from md.workflows.adhesion_legs import outward_grid
    s = settings_with("adhesion_ots", "quick")
    base = outward_grid(Adhesion.typed(s))
    extra = [3.6, 4.9]
    s2 = {**s, "pmf_extra_windows_A": extra}
    grid = outward_grid(Adhesion.typed(s2))
    assert np.all(np.diff(grid) > 0) and len(grid) == len(base) + 2
    assert set(np.round(grid, 9)) == set(np.round(np.concatenate([base, extra]), 9))
    rows = Adhesion.chains(Adhesion.typed(s2))
    out = [d for suf, d, _ in rows if suf.startswith("o")]
    assert out == pytest.approx(list(grid))
    assert Adhesion().windows(Adhesion.typed(s2))[-len(grid):] == pytest.approx(grid)
    with pytest.raises(RecipeError, match=r"pmf_extra_windows_A.*strictly between 0 and separation_A"):
        recipe_with("adhesion_ots", "quick", pmf_extra_windows_A=[25.0])
    with pytest.raises(RecipeError, match=r"pmf_extra_windows_A.*within 0.05 A of another window"):
        recipe_with("adhesion_ots", "quick", pmf_extra_windows_A=[float(base[3]) + 0.01])


def test_sam_anneal_leg_runs_the_separated_pair_before_the_contact(tmp_path):
    """sam_anneal_steps: the first leg holds both backs with the upper slab separation_A away, draws velocities at
    T and stores the chain axes (head Si -> CH3 of one molecule each); the contact leg starts from its last
    state, moved back down by separation_A."""
    s, plan = _plan("adhesion_ots", "quick", tmp_path, sam_anneal_steps=5000)
    legs = {l.name: l for l in plan.legs}
    assert plan.legs[0].name == "anneal" and plan.legs[1].name == "contact"
    an = legs["anneal"]
    cmds = an.fresh(tmp_path / "x")
    assert cmds[-1] == f"displace_atoms upper move 0.0 0.0 {s['separation_A']:.6f} units box"
    define = an.define(0)
    assert "fix hold_upper upper_back setforce 0.0 0.0 0.0" in define and not any("rigid" in c for c in define)
    assert an.total_steps == 5000 and an.stages[0].begin[0].startswith("velocity mobile create 300")
    assert an.frames.group == "chain_axes"
    from md.system.lammps_data import read_atoms
    ids, types, _ = read_atoms(tmp_path / "system.data")
    axes = np.array(an.info["chain_axes"])
    assert len(axes) == 2 * s["nx"] * s["ny"] * 2      # two chains per (111) cell, two SAMs
    assert all(types[h] != types[e] for h, e in axes)
    head = [c for c in legs["contact"].fresh(tmp_path / "x") if c.startswith(("read_restart", "displace_atoms"))]
    assert "legs/anneal/restart.5000" in head[0]
    assert head[1] == f"displace_atoms upper move 0.000000 0.000000 {-s['separation_A']:.6f} units box"
    # without the option there is no anneal leg and the contact leg reads the build
    (tmp_path / "n").mkdir()
    _, plan0 = _plan("adhesion_ots", "quick", tmp_path / "n")
    assert plan0.legs[0].name == "contact" and "read_data" in " ".join(plan0.legs[0].fresh(tmp_path / "n"))


def test_sam_stress_samples_the_sam_atoms_summed_stress_in_every_leg(tmp_path):
    """sam_stress: the group of both SAMs' atoms, a stress/atom compute summed over it, and its xx, yy, zz columns
    in every leg (the compression windows' C13/C33); off (the default): none of it."""
    from md.workflows.adhesion_legs import SAM_STRESS_COLUMNS, SAM_STRESS_LINES
    s, plan = _plan("adhesion_ots", "quick", tmp_path, sam_stress=True)
    for leg in plan.legs:
        define = leg.define(0)
        assert all(line in define for line in SAM_STRESS_LINES), leg.name
        assert all(leg.columns[c].startswith("c_sam_stress[") for c in SAM_STRESS_COLUMNS)
    assert any(c.startswith("group sam_layers id") for c in plan.legs[0].fresh(tmp_path / "x"))
    (tmp_path / "n").mkdir()
    _, plan0 = _plan("adhesion_ots", "quick", tmp_path / "n")
    assert not any("sam_stress" in c for c in plan0.legs[0].define(0)) and "sam_szz" not in plan0.legs[0].columns


@pytest.mark.parametrize("name", ["adhesion_silica", "adhesion_ots"])
def test_every_registry_gets_its_own_zero_load_contact(tmp_path, name):
    """registry_contact_steps: registry r >= 1 has a leg contact_rN from the contact leg's last state moved to its
    offset (bare silica: lifted, then lowered in minimisation steps), with the upper back one rigid body free
    along z; its chain starts from that leg's last state, not moved."""
    from md.workflows.adhesion_legs import _BACK_RIGID, REGISTRY_LIFT_A, REGISTRY_LOWER_STEPS
    s, plan = _plan(name, "quick", tmp_path, registry_contact_steps=20000, registry_sampling="primitive",
                    lateral_registries=3)
    legs = {l.name: l for l in plan.legs}
    order = [l.name for l in plan.legs]
    offsets = plan.system_info["registry_offsets_A"]
    assert "contact_r0" not in legs
    lift = REGISTRY_LIFT_A if name == "adhesion_silica" else 0.0
    for r in (1, 2):
        leg = legs[f"contact_r{r}"]
        dx, dy = offsets[r]
        assert leg.total_steps == 20000 and _BACK_RIGID in leg.define(0)
        move = [c for c in leg.fresh(tmp_path / "x") if c.startswith("displace_atoms")]
        assert move == [f"displace_atoms upper move {dx:.6f} {dy:.6f} {lift:.6f} units box"]
        prep = leg.prepare(tmp_path / "x")
        assert prep[:2] == ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"]
        assert prep[-3:] == ["unfix back_min", _BACK_RIGID, "reset_timestep 0"]
        down = [c for c in prep if c.startswith("displace_atoms")]
        assert len(down) == (REGISTRY_LOWER_STEPS if lift else 0)
        w0 = legs[f"pmf_r{r}_o00"]
        head = w0.fresh(tmp_path / "x")
        assert f"legs/contact_r{r}/restart.20000" in head[0]
        assert not any(c.startswith("displace_atoms") for c in head)
        assert w0.info["continues"] == f"contact_r{r}" and order.index(f"contact_r{r}") < order.index(w0.name)


def test_return_chain_runs_back_through_the_same_windows(tmp_path):
    """pmf_return: from the outermost outward window back through every outward window and into compression,
    each from its outer neighbour's last state moved by the difference of the nominal separations; every return
    window sits at its outward partner's separation."""
    from md.workflows.adhesion import Adhesion
    s, plan = _plan("adhesion_ots", "quick", tmp_path, pmf_return=True)
    legs = {l.name: l for l in plan.legs}
    out = {suf: d for suf, d, _ in Adhesion.chains(Adhesion.typed(s))}
    rows = Adhesion.return_chain(Adhesion.typed(s))
    n, m = s["pmf_windows"], s["pmf_compress_windows"]
    assert len(rows) == (n - 1) + m and rows[0][2] == f"o{n - 1:02d}"
    nominal = dict(out)
    for suf, d, prev, rep in rows:
        assert d == pytest.approx(out[rep])
        leg = legs[f"pmf_r0_{suf}"]
        head = leg.fresh(tmp_path / "x")
        assert f"legs/pmf_r0_{prev}/restart." in head[0]
        assert [c for c in head if c.startswith("displace_atoms")] == \
            [f"displace_atoms upper move 0.000000 0.000000 {d - nominal[prev]:.6f} units box"]
        nominal[suf] = d
    assert rows[-1][1] == pytest.approx(-s["pmf_compress_A"])
    assert Adhesion.return_chain(Adhesion.typed(settings_with("adhesion_ots", "quick"))) == []
    assert sum(k.startswith("pmf_r") for k in legs) == s["lateral_registries"] * (n + m + len(rows))


# ------------------------------------------------------------------------------------ protocol options (smoke)

@pytest.mark.md
def test_equilibrated_ots_smoke_anneals_contacts_each_registry_and_pulls_out_and_back(md_smoke):
    """adhesion_ots_equilibrated at smoke: the anneal's energy and tilt series with their drift tests, a contact
    leg per further registry whose chain starts at its last back height, distinct (non-degenerate) primitive
    registries, the return windows held at their outward partners' heights, and W_F = the mean of out and back
    with half the hysteresis as its systematic."""
    from md.engine.store import read_samples
    from md.workflows.adhesion import Adhesion
    outcome = md_smoke("adhesion_ots_equilibrated").outcome
    r, legs = outcome.result, outcome.run_dir / "legs"
    s = r["settings"]
    assert s["registry_sampling"] == "primitive" and s["pmf_return"]
    an = r["details"]["anneal"]
    assert len(an["mean_tilt_deg"]) >= 8 and all(5.0 < t < 60.0 for t in an["mean_tilt_deg"])
    for key in ("potential_energy_kcal", "mean_tilt_deg"):
        c = an["drift_second_half"][key]
        assert isinstance(c["drifting"], bool) and c["slope_stderr"] > 0
    assert any(n.startswith(("SAM anneal", "ANNEAL STILL DRIFTING")) for n in r["notes"])
    assert r["details"]["pmf_windows"]["registry_offsets_A"][1] != [0.0, 0.0]
    assert not any(n.startswith("REGISTRIES DEGENERATE") for n in r["notes"])
    rc = r["details"]["registry_contacts"]["1"]
    assert math.isfinite(rc["energy_work_J_m2"]) and rc["stderr_J_m2"] > 0
    c1 = read_samples(legs / "contact_r1" / "samples.csv")
    assert read_samples(legs / "pmf_r1_o00" / "samples.csv")["z_back"][0] == pytest.approx(c1["z_back"][-1], abs=1e-4)
    for suf, _d, _prev, rep in Adhesion.return_chain(Adhesion.typed(s)):
        back = read_samples(legs / f"pmf_r0_{suf}" / "samples.csv")["z_back"]
        assert back[0] == pytest.approx(read_samples(legs / f"pmf_r0_{rep}" / "samples.csv")["z_back"][0], abs=1e-4)
    q = r["quantities"]
    w = q["work_of_adhesion_free_energy"]
    assert w["value"] == pytest.approx(0.5 * (w["value_out"] + w["value_back"]))
    assert w["systematic_hysteresis"] == pytest.approx(0.5 * abs(q["adhesion_hysteresis"]["value"]))
    assert q["adhesion_hysteresis"]["value"] == pytest.approx(w["value_out"] - w["value_back"])
    assert any(n.startswith("out and back") for n in r["notes"])
    # T dS per registry: each registry's dE/A from its own contact leg against its own chain's W_F, averaged
    tds = q["entropic_term_TdS"]
    assert tds["registries"] == [0, 1]
    assert tds["per_registry"]["1"][0] == pytest.approx(rc["energy_work_J_m2"] -
                                                        r["details"]["pmf_windows"]["registry_work_J_m2"][1])


@pytest.mark.md
def test_silica_registries_smoke_lowers_each_registry_into_its_own_contact(md_smoke):
    """adhesion_silica_registries at smoke: registry 1's contact leg (lifted, shifted, lowered in minimisation
    steps, then free along z at zero load) sits within an angstrom of registry 0's contact, and the extra window
    is in the grid."""
    from md.engine.store import read_samples
    outcome = md_smoke("adhesion_silica_registries").outcome
    r, legs = outcome.result, outcome.run_dir / "legs"
    rc = r["details"]["registry_contacts"]["1"]
    assert abs(rc["back_z_minus_contact_A"]) < 1.0
    c1 = read_samples(legs / "contact_r1" / "samples.csv")
    assert np.ptp(c1["z_back"]) > 0                       # free along z
    n_out = r["settings"]["pmf_windows"] + len(r["settings"]["pmf_extra_windows_A"])
    assert sum(w.startswith("o") for w in r["details"]["pmf_windows"]["window"]) == n_out


@pytest.mark.md
def test_rank1_two_registries_are_reported_degenerate(needs_lammps, cache):
    """adhesion_silica_ots at smoke with the shipped quick recipes' rank-1 n = 2 registries: the result names the
    second registry as a repeat of the first (its offset is the (111) cell's centring vector)."""
    r = run_quiet(recipe_with("adhesion_silica_ots", lateral_registries=2), cache).result
    assert r["details"]["pmf_windows"]["registry_offsets_A"][1] == pytest.approx([2.531442, 4.384587], abs=1e-6)
    (note,) = [n for n in r["notes"] if n.startswith("REGISTRIES DEGENERATE")]
    assert "1 repeats 0" in note and "2 chains sample 1 distinct registry" in note
