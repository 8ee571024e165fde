"""Adhesion and pull-off protocols: dispersion beyond the cutoff, chained force-integration
windows reaching into compression and averaged over lateral registries, z0 and sigma0 from the flat-slab curve,
the pull-off thermostat and its residual drag, the OTS asperity's grafting density, and the calibration's use of
the flat-slab z0.

Tests marked ``md`` run LAMMPS at smoke fidelity (seconds each); the rest need no LAMMPS.
"""
from __future__ import annotations

import io
import json
import math
from contextlib import redirect_stdout

import numpy as np
import pytest

from md.recipe import load_recipe, parse_recipe


def _settings(name, fidelity="smoke", **override):
    s = dict(load_recipe(name).settings(fidelity))
    s.update(override)
    return s


def _recipe(name, fidelity="smoke", new_name=None, **override):
    t = json.loads(json.dumps(dict(load_recipe(name).raw), default=dict))
    t["fidelity"][fidelity].update(override)
    return parse_recipe(t, name=new_name or name)


def _run(recipe, cache, fidelity="smoke"):
    from md.workflows import run_recipe
    with redirect_stdout(io.StringIO()):
        return run_recipe(recipe, fidelity, cache=cache, out=None, progress=False)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("md-adhesion-cache")


# ------------------------------------------------------------------------------------ protocol (no LAMMPS)

def test_protocol_versions_enter_the_run_hash():
    """The lift-before-shift registry start applies to bare silica pairs only: they follow the workflow's version,
    SAM pairs (whose plans it does not change) the one before, so the hashes of their committed results hold."""
    from md import workflows
    from md.workflows import run_hash
    ad = workflows.get_workflow("adhesion")
    assert ad.protocol_version(_settings("adhesion_silica", "quick")) == ad.version
    for name in ("adhesion_ots", "adhesion_silica_ots"):
        assert ad.protocol_version(_settings(name, "quick")) == ad.version - 1
        _, doc = run_hash(name, "quick")
        assert doc["workflow_version"] == ad.version - 1


def test_windows_are_chains_reaching_into_compression_at_every_registry(tmp_path):
    """The generated commands: window 0 of every registry starts from the contact leg's last restart, moved
    laterally to the registry's offset; each further window reads its neighbour's last restart and moves the upper
    slab by the difference of the nominal separations -- inwards (compression) and outwards."""
    from md.workflows.adhesion import Adhesion
    from md.workflows.adhesion_legs import REGISTRY_LIFT_A, REGISTRY_LOWER_STEPS, _registry_offsets
    s = _settings("adhesion_silica", "quick")
    wf = Adhesion()
    plan = wf.plan(s, tmp_path)
    legs = {l.name: l for l in plan.legs}
    n_out, n_in, n_reg = s["pmf_windows"], s["pmf_compress_windows"], s["lateral_registries"]
    assert n_in >= 1 and n_reg >= 2
    assert sum(n.startswith("pmf_") for n in legs) == n_reg * (n_out + n_in)
    offsets = plan.system_info["registry_offsets_A"]
    assert offsets[0] == [0.0, 0.0] and len({tuple(o) for o in offsets}) == n_reg
    cell = (plan.system_info["box_A"][0] / s["nx"], plan.system_info["box_A"][1] / s["ny"])
    assert [list(o) for o in _registry_offsets(n_reg, cell)] == offsets
    nominal = dict((suf, d) for suf, d, _ in wf.chains(s))
    assert min(nominal.values()) == pytest.approx(-s["pmf_compress_A"])
    assert max(nominal.values()) == pytest.approx(s["separation_A"])
    for r, (dx, dy) in enumerate(offsets):
        for suf, d, prev in wf.chains(s):
            cmds = legs[f"pmf_r{r}_{suf}"].fresh(tmp_path / "x")
            head = cmds[0]
            move = [c for c in cmds if c.startswith("displace_atoms upper move")]
            if prev is None:
                assert "legs/contact/restart." in head
                if r == 0:
                    assert not move
                else:       # bare silica: lifted before the shift, lowered back quasi-statically
                    assert move == [f"displace_atoms upper move {dx:.6f} {dy:.6f} {REGISTRY_LIFT_A:.6f} units box"]
                    prep = legs[f"pmf_r{r}_{suf}"].prepare(tmp_path / "x")
                    down = [c for c in prep if c.startswith("displace_atoms upper move")]
                    assert len(down) == REGISTRY_LOWER_STEPS
                    assert sum(float(c.split()[5]) for c in down) == pytest.approx(-REGISTRY_LIFT_A, abs=1e-9)
                    assert sum(c.startswith("minimize") for c in prep) == REGISTRY_LOWER_STEPS
            else:
                assert f"legs/pmf_r{r}_{prev}/restart." in head
                assert move == [f"displace_atoms upper move 0.000000 0.000000 {d - nominal[prev]:.6f} units box"]
            assert not any(c.startswith("velocity") for st in legs[f"pmf_r{r}_{suf}"].stages for c in st.begin)
    # a SAM pair is shifted at contact: no lift, nothing before the stages
    so = _settings("adhesion_silica_ots", "quick")
    (tmp_path / "so").mkdir()
    plan_so = wf.plan(so, tmp_path / "so")
    legs_so = {l.name: l for l in plan_so.legs}
    off = plan_so.system_info["registry_offsets_A"][1]
    assert [c for c in legs_so["pmf_r1_o00"].fresh(tmp_path / "y") if c.startswith("displace_atoms")] == \
        [f"displace_atoms upper move {off[0]:.6f} {off[1]:.6f} 0.000000 units box"]
    assert legs_so["pmf_r1_o00"].prepare(tmp_path / "y") == ["reset_timestep 0"]
    # the chain order: every leg runs after the one it continues from
    order = [l.name for l in plan.legs]
    for l in plan.legs:
        src = l.info.get("continues")
        if src:
            assert order.index(src) < order.index(l.name)


def test_dispersion_tail_applies_to_trappe_pairs_only():
    """'trappe': every pair with a CH2/CH3 united atom (OTS-OTS, silica-OTS, water-OTS), never an IFF-IFF pair;
    the OTS head Si (IFF LJ) pairs with silica keep the cutoff."""
    from md.workflows.adhesion_legs import _tail_pair_table
    from md.workflows.common import TRAPPE_UA, forcefield_of
    ff = forcefield_of(["silica_interface", "ots_trappe_ua", "water_spce"])
    names, eps, sig, inc = _tail_pair_table(ff, "trappe")
    i = {n: k for k, n in enumerate(names)}
    assert inc[i["CH2"], i["CH3"]] and inc[i["CH2"], i["OC24"]] and inc[i["OW"], i["CH3"]]
    assert not inc[i["OC24"], i["OW"]] and not inc[i["SC4"], i["OC23"]] and not inc[i["SIH"], i["OC24"]]
    assert set(TRAPPE_UA) == {"CH2", "CH3"}
    p = ff.pair("CH2", "OW")
    assert eps[i["CH2"], i["OW"]] == p.epsilon and sig[i["CH2"], i["OW"]] == p.sigma
    assert _tail_pair_table(ff, "all")[3][i["OC24"], i["OW"]]


def _dome(fidelity):
    """The pulloff_ots asperity at ``fidelity`` with its chains grafted as the workflow grafts them."""
    from md.build import graft_dome, silica_asperity
    s = load_recipe("pulloff_ots").typed_settings(fidelity)
    asp = silica_asperity.system(radius=s.asperity_radius_A, holder_thickness=s.holder_thickness_A,
                                 margin=s.asperity_margin_A, silanol_density=4.5, face="111", seed=s.seed)
    return graft_dome(asp, radius_A=s.asperity_radius_A, max_polar_deg=s.graft_max_polar_deg,
                      coverage_nm2=s.sam_coverage, chain_length=s.chain_length, seed=s.seed + 30)


def test_ots_asperity_is_grafted_at_sam_density():
    """The quick dome carries the SAM's coverage (>= 4 chains per nm^2 of projected cap: a largest set of sites at
    >= 4.3 A lateral spacing; a random sequential choice of sites stops well short of it)."""
    sam, g = _dome("quick")
    assert g["chains_per_projected_nm2"] >= 4.0 and g["chains"] == g["requested_chains"]
    assert g["min_spacing_A"] >= 4.3
    anchors = sam.positions[sam.group("sam_anchor_O"), :2]
    dxy = anchors[:, None, :] - anchors[None, :, :]
    dxy -= sam.cell[:2] * np.round(dxy / sam.cell[:2])
    dist = np.hypot(dxy[..., 0], dxy[..., 1]) + np.eye(len(anchors)) * 99
    assert dist.min() >= g["min_spacing_A"] - 1e-6


def test_offset_heads_keep_their_anchor_bond_and_refuse_to_lean_too_far():
    from md.build.sam import MAX_ANCHOR_TILT_DEG, chain_geometry, head_offset_disk, head_shifts
    tpos, _ = chain_geometry(18, 0.0, 0.0)
    centre, radius = head_offset_disk(18, 0.0, 0.0)
    ang = np.linspace(0.0, 2 * np.pi, 13)
    d = centre + 0.999 * radius * np.column_stack([np.cos(ang), np.sin(ang)])
    si = tpos[0] + head_shifts(d, 18, 0.0, 0.0)             # the head Si after the shift
    # sqrt(r^2 - l^2), l <= 0.87 r: well conditioned
    assert np.allclose(np.linalg.norm(si, axis=1), np.linalg.norm(tpos[0]), rtol=1e-10)
    assert np.degrees(np.arccos(si[:, 2] / np.linalg.norm(si, axis=1))).max() <= MAX_ANCHOR_TILT_DEG + 1e-6
    assert np.allclose(head_shifts(np.zeros((1, 2)), 18, 0.0, 0.0), 0.0, atol=1e-12)
    with pytest.raises(ValueError, match="tilts the anchor bond beyond 60 deg"):
        head_shifts(centre + [[1.01 * radius, 0.0]], 18, 0.0, 0.0)


def test_spread_chains_parts_a_close_pair_within_the_disk_or_says_it_cannot():
    from md.build.dome import _spread_chains
    cell = (40.0, 40.0)
    pair = np.array([[10.0, 10.0], [12.9, 10.0]])
    d = _spread_chains(pair, cell, 4.4, np.zeros(2), 1.0)
    p = pair + d
    assert np.hypot(*(p[0] - p[1])) >= 4.4 and np.hypot(d[:, 0], d[:, 1]).max() <= 1.0 + 1e-12
    # three sites 1 A apart cannot stand 4.4 A apart with offsets of at most 1 A
    assert _spread_chains(np.array([[10.0, 10.0], [11.0, 10.0], [10.5, 10.9]]), cell, 4.4, np.zeros(2), 1.0) is None


def test_production_ots_asperity_reaches_sam_density_with_leaning_chains():
    """The production dome (R = 3 nm) has its silanols in close pairs in projection, so chains standing on their
    sites cannot reach the SAM's coverage (the chains must lean: ``chain_offset_max_A`` > 0). Leaning heads (anchor bond
    up to 60 deg off the vertical) reach >= 4 per nm^2 with the chains 4.4 A apart and no head atom within 1.7 A of a
    heavy atom but its anchor O."""
    from scipy.spatial import cKDTree

    from md.build.dome import HEAD_CLEARANCE_A
    from md.build.sam import MAX_ANCHOR_TILT_DEG
    sam, g = _dome("production")
    assert g["chains_per_projected_nm2"] >= 4.0 and g["chain_offset_max_A"] > 0.0
    si = np.asarray(sam.group("sam_head_si"), int)
    anchor = np.asarray(sam.group("sam_anchor_O"), int)
    bond = sam.positions[si] - sam.positions[anchor]
    r = np.linalg.norm(bond, axis=1)
    assert np.allclose(r, 1.68, atol=1e-9)                           # IFF Si-O r0, kept while leaning
    assert np.degrees(np.arccos(bond[:, 2] / r)).max() <= MAX_ANCHOR_TILT_DEG + 1e-6
    ch3 = sam.positions[np.asarray(sam.group("sam_ch3"), int), :2]   # the chains stand 4.4 A apart
    v = ch3[:, None, :] - ch3[None, :, :]
    v -= sam.cell[:2] * np.round(v / sam.cell[:2])
    assert (np.hypot(v[..., 0], v[..., 1]) + 99 * np.eye(len(ch3))).min() >= g["min_spacing_A"] - 1e-6
    per = len(sam.group("sam")) // len(si)
    head = (si[:, None] + np.arange(7)[None, :]).ravel()              # head Si, 2 x (O, H), first two CH2
    head = head[sam.types[head] != "HOY"]
    heavy = np.flatnonzero(sam.types != "HOY")
    tree = cKDTree(sam.positions[heavy])
    own = {int(a): set(range(int(h), int(h) + per)) | {int(a)} for a, h in zip(anchor, si)}
    owner = {int(h) + k: int(a) for a, h in zip(anchor, si) for k in range(per)}
    for i, hits in zip(head, tree.query_ball_point(sam.positions[head], HEAD_CLEARANCE_A - 1e-6)):
        assert all(int(heavy[k]) in own[owner[int(i)]] for k in hits)


def test_calibration_takes_z0_from_the_flat_slab_curve_with_its_stderr():
    from calibration.mdset import MAPPING, build_parameter_set, recipes_first, recipes_needed
    from calibration.validation import VALIDATION
    silica = next(s.recipe for s in MAPPING if s.key == "surfaces.work_of_adhesion")   # the mapping's choice
    pull_si = next(p for p, a in VALIDATION if a == silica)
    ots = next(s.recipe for s in MAPPING if s.key == "surfaces.sam.work_of_adhesion")
    pull_ots = next(p for p, a in VALIDATION if a == ots)

    def res(recipe, q):
        return {"recipe": recipe, "fidelity": "quick", "run_hash": f"{recipe:0<64}"[:64],
                "quantities": {k: dict(v) for k, v in q.items()}}
    adh_si = res(silica, {
        "work_of_adhesion": {"value": 0.12, "stderr": 0.002, "units": "J/m^2"},
        "work_of_adhesion_free_energy": {"value": 0.075, "stderr": 0.002, "units": "J/m^2",
                                         "discretisation_error": 0.001},
        "interaction_range_z0": {"value": 0.17e-9, "stderr": 0.02e-9, "units": "m", "dugdale_range_h0_m": 0.16e-9},
        "peak_traction_sigma0": {"value": 0.45e9, "stderr": 0.04e9, "units": "Pa"}})
    adh_ots = res(ots, {"work_of_adhesion_free_energy": {"value": 0.04, "stderr": 0.004,
                                                                     "units": "J/m^2"}})
    pull = {n: res(n, {"interaction_range_z0": {"value": z, "stderr": None, "units": "m"},
                       "work_of_adhesion_eff_dmt": {"value": w, "stderr": 0.01, "units": "J/m^2"},
                       "residual_drag_force": {"value": 1e-12, "stderr": 5e-11, "units": "N"}})
            for n, z, w in (("pulloff_silica", 0.49e-9, 0.054), (pull_si, 0.49e-9, 0.054),
                            ("pulloff_ots", 0.94e-9, 0.03), (pull_ots, 0.94e-9, 0.03))}
    table, rows = build_parameter_set({silica: adh_si, ots: adh_ots, **pull}, "paper", "cal")
    s = table["surfaces"]
    assert s["interaction_range"] == 0.17e-9                   # flat slab, not the pull-off's 0.49 nm
    cal = table["meta"]["calibration"]["surfaces.interaction_range"]
    assert cal["recipe"] == silica and cal["stderr"] == 0.02e-9
    assert cal["sigma0"]["value"] == 0.45e9 and cal["dugdale_range_h0"] == 0.16e-9
    # the OTS adhesion result predates the flat-slab z0: the pull-off's z0 is used and named as such
    assert s["sam"]["interaction_range"] == 0.94e-9
    sam = table["meta"]["calibration"]["surfaces.sam.interaction_range"]
    assert sam["recipe"] == "pulloff_ots" and "compliance" in sam["note"]
    assert "pull-off" in table["meta"]["origin"]["surfaces.sam.interaction_range"]["note"]
    val = table["meta"]["validation"][pull_si]
    assert val["ratio"] == pytest.approx(0.054 / 0.075) and val["adhesion_recipe"] == silica
    assert "pulloff_silica" in recipes_needed() and recipes_needed()[0] == silica and pull_si in recipes_first()


# ------------------------------------------------------------------------------------ LAMMPS (smoke)

@pytest.mark.md
def test_static_tail_equals_lammps_lj_sum_between_the_slabs(needs_lammps, tmp_path):
    """The Python tail (explicit pairs between 12 A and 30 A over all periodic images, TraPPE pairs only) is what
    LAMMPS gives for the two slabs' LJ interaction with lj/cut 30 minus lj/cut 12 (compute group/group, run 0),
    energy and force, on the smoke OTS/OTS system; and it is attractive."""
    from md.analysis import lj_tail_between
    from md.build import flip_upside_down, place_on
    from md.engine.plan import id_ranges
    from md.lammps_loader import new_lammps
    from md.system.forcefield import lammps_pair_coeffs
    from md.system.lammps_data import lammps_setup_commands, read_atoms, write_data
    from md.workflows.adhesion_legs import _tail_pair_table
    from md.workflows.common import forcefield_of, surface_slab
    s = load_recipe("adhesion_ots").typed_settings("smoke")
    ff = forcefield_of(["silica_interface", "ots_trappe_ua"])
    lower = surface_slab("ots", s.nx, s.ny, s.slab_thickness_A, s, 1, "111")
    upper = surface_slab("ots", s.nx, s.ny, s.slab_thickness_A, s, 11, "111")
    system = place_on.system(lower, flip_upside_down(upper), gap=3.0, vacuum=40.0)
    data = write_data(system, ff, tmp_path / "ots.data")
    names, eps, sig, inc = _tail_pair_table(ff, "trappe")
    n_low = len(system.group("substrate"))
    res = {}
    for rc in (12.0, 30.0):
        lmp = new_lammps(["-nocite", "-screen", "none", "-log", "none"])
        try:
            cmds = lammps_setup_commands(ff, data, pair="cut", cutoff=rc)
            cmds += [f"pair_style lj/cut {rc:g}", "neigh_modify one 20000 page 200000"]
            for line in lammps_pair_coeffs(ff, comments=False):
                _, i, j, e, sg = line.split()
                i, j = int(i), int(j)
                cmds.append(f"pair_coeff {i} {j} {float(e) if inc[i - 1, j - 1] else 0.0:.6f} {sg}")
            cmds += [f"group lower id {id_ranges(np.arange(n_low))}", "group upper subtract all lower",
                     "compute gg upper group/group lower", "thermo_style custom step c_gg c_gg[3]", "run 0"]
            for c in cmds:
                lmp.command(c)
            res[rc] = (lmp.extract_compute("gg", 0, 0), lmp.extract_compute("gg", 0, 1)[2])
        finally:
            lmp.close()
    ids, types, _ = read_atoms(data)
    low = ids <= n_low
    tail = lj_tail_between(system.positions[low], types[low] - 1, system.positions[~low], types[~low] - 1, eps, sig,
                           inc, system.cell[:2], 12.0, 30.0, smeared_beyond=False)
    assert tail["energy"] == pytest.approx(res[30.0][0] - res[12.0][0], rel=1e-6)
    assert tail["force_z"] == pytest.approx(res[30.0][1] - res[12.0][1], rel=1e-5)
    assert tail["energy"] < 0 and tail["force_z"] < 0


@pytest.mark.md
def test_adhesion_smoke_runs_the_chains_and_reports_z0_sigma0_and_the_tail(md_smoke):
    """adhesion_ots at smoke: the chain is continuous (each held back starts where its neighbour's was, moved by
    the nominal step), the inward chain is pressed into the contact, the dispersion tail is attractive (W grows)
    and a few mJ/m^2 for OTS-OTS, z0 and sigma0 carry stderrs, and the flag for a curve without a repulsive end is
    reported."""
    from md.engine.store import read_samples
    from md.workflows.adhesion import Adhesion
    outcome = md_smoke("adhesion_ots").outcome              # the session's smoke run, shared with test_md_workflows
    r = outcome.result
    s = r["settings"]
    legs = outcome.run_dir / "legs"
    nominal = {suf: d for suf, d, _ in Adhesion.chains(s)}
    contact = read_samples(legs / "contact" / "samples.csv")
    for suf, d, prev in Adhesion.chains(s):
        w = read_samples(legs / f"pmf_r0_{suf}" / "samples.csv")
        assert np.ptp(w["z_back"]) < 1e-6                       # held
        start = contact["z_back"][-1] if prev is None else \
            read_samples(legs / f"pmf_r0_{prev}" / "samples.csv")["z_back"][-1]
        step = 0.0 if prev is None else d - nominal[prev]
        assert w["z_back"][0] == pytest.approx(start + step, abs=1e-4)
    win = r["details"]["pmf_windows"]
    assert min(win["separation_A"]) < -0.5 * s["pmf_compress_A"]
    assert isinstance(win["repulsive_end"], bool) and len(win["n_eff"][0]) == len(win["separation_A"])
    q = r["quantities"]
    for k, unit in (("peak_traction_sigma0", "Pa"), ("interaction_range_z0", "m"),
                    ("work_of_adhesion_free_energy", "J/m^2"), ("dispersion_tail_work", "J/m^2")):
        assert q[k]["units"] == unit and math.isfinite(q[k]["value"]), k
    assert q["interaction_range_z0"]["stderr"] > 0 and q["peak_traction_sigma0"]["stderr"] > 0
    tail = r["details"]["dispersion_tail"]
    assert tail["applied"] and 0.004 < tail["static_work_J_m2"] < 0.02        # J/m^2, attractive
    assert q["dispersion_tail_work"]["value"] > 0
    # the static tail is in W: W exceeds the cutoff-only energy work by it (at least 4 mJ/m^2, so a W without the
    # tail fails)
    assert q["work_of_adhesion"]["value"] - r["details"]["energy"]["cutoff_only_J_m2"] == pytest.approx(
        tail["static_work_J_m2"], rel=1e-6)
    study = tail["cutoff_study_last_contact_frame"]
    assert study["trappe_20A_J_m2"] == pytest.approx(study["trappe_40A_J_m2"], rel=0.02)
    assert study["all_20A_J_m2"] >= study["trappe_20A_J_m2"] - 1e-9        # IFF pairs reported, not applied
    assert abs(tail["fep_minus_mean_J_m2"]) < 0.05 * tail["static_work_J_m2"]   # first order suffices
    # window length: W_F of each window's two halves; trapezoid integration is linear in the mean forces, so the
    # halves' average is the whole's but for the registries' weights and an odd sample count
    wl = r["details"]["window_length_check"]
    assert math.isfinite(wl["first_half_J_m2"]) and math.isfinite(wl["second_half_J_m2"])
    assert isinstance(wl["converged"], bool) and wl["difference_stderr_J_m2"] > 0
    assert 0.5 * (wl["first_half_J_m2"] + wl["second_half_J_m2"]) == pytest.approx(wl["whole_J_m2"], rel=0.02)
    assert any(n.startswith("window length: W_F") for n in r["notes"])


@pytest.mark.md
def test_pulloff_drag_and_repeats(md_smoke, cache):
    """A lab-frame thermostat drags the moving asperity by about gamma M v (measured here from the holder's
    reaction and the asperity's momentum); the comoving thermostat leaves no drag beyond noise. Two repeated pulls
    give the pull-off force its spread. The comoving run is the session's pulloff_silica smoke run (its smoke
    preset pulls twice); only the lab-frame one runs here."""
    new = md_smoke("pulloff_silica").outcome.result
    assert new["settings"]["tip_thermostat"] == "comoving"
    old = _run(_recipe("pulloff_silica", tip_thermostat="lab", retract_repeats=1, new_name="pulloff_silica_lab"),
               cache).result
    lab = old["quantities"]["residual_drag_force"]
    assert lab["lab_frame_drag_N"] < 0
    assert 0.5 < lab["value"] / lab["lab_frame_drag_N"] < 1.3
    d = new["quantities"]["residual_drag_force"]
    assert abs(d["value"]) < 0.15 * abs(d["lab_frame_drag_N"]) and abs(d["value"]) < 4 * d["stderr"] + 1e-11
    pulls = new["details"]["pulls"]
    assert len(pulls) == new["settings"]["retract_repeats"] == 2
    f = [p["max_tensile_force_N"] for p in pulls]
    assert min(f) <= new["quantities"]["pull_off_force"]["value"] <= max(f)
    assert new["quantities"]["pull_off_force"]["stderr"] > 0
    assert new["quantities"]["interaction_range_z0"]["stderr"] is not None


# ------------------------------------------------------------------------------------ protocol options (no LAMMPS)

def _plan(name, fidelity, tmp_path, **override):
    from md.workflows.adhesion import Adhesion
    s = _settings(name, fidelity, **override)
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
    s = _settings("adhesion_ots", "quick")
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
    info = {"registry_offsets_A": [[0.0, 0.0], [2.531442, 4.384587]], "degenerate_registries": [[1, 0]],
            "surface_lattice_A": [[5.06, 0.0], [2.53, 4.38]]}
    (note,) = degenerate_note(info)
    assert note.startswith("REGISTRIES DEGENERATE") and "2 chains sample 1 distinct registry" in note
    assert degenerate_note({**info, "degenerate_registries": []}) == []


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
        assert _recipe(name, fid, registry_sampling="rank1", pmf_return=False).canonical_sha256(fid) == base
        for key, value in (("registry_sampling", "primitive"), ("registry_contact_steps", 1000),
                           ("sam_anneal_steps", 1000), ("pmf_return", True), ("pmf_extra_windows_A", [2.3]),
                           ("sam_stress", True)):
            assert _recipe(name, fid, **{key: value}).canonical_sha256(fid) != base, (key, fid)


def test_extra_windows_enter_the_outward_grid_and_are_checked():
    from md.recipe import RecipeError
    from md.workflows.adhesion import Adhesion
    from md.workflows.adhesion_legs import outward_grid
    s = _settings("adhesion_ots", "quick")
    base = outward_grid(Adhesion.typed(s))
    extra = [3.6, 4.9]
    s2 = {**s, "pmf_extra_windows_A": extra}
    grid = outward_grid(Adhesion.typed(s2))
    assert np.all(np.diff(grid) > 0) and len(grid) == len(base) + 2
    assert set(np.round(grid, 9)) == set(np.round(np.concatenate([base, extra]), 9))
    rows = Adhesion.chains(s2)
    out = [d for suf, d, _ in rows if suf.startswith("o")]
    assert out == pytest.approx(list(grid))
    assert Adhesion().windows(s2)[-len(grid):] == pytest.approx(grid)
    with pytest.raises(RecipeError, match=r"pmf_extra_windows_A.*strictly between 0 and separation_A"):
        _recipe("adhesion_ots", "quick", pmf_extra_windows_A=[25.0])
    with pytest.raises(RecipeError, match=r"pmf_extra_windows_A.*within 0.05 A of another window"):
        _recipe("adhesion_ots", "quick", pmf_extra_windows_A=[float(base[3]) + 0.01])


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
    out = {suf: d for suf, d, _ in Adhesion.chains(s)}
    rows = Adhesion.return_chain(s)
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
    assert Adhesion.return_chain(_settings("adhesion_ots", "quick")) == []
    assert sum(k.startswith("pmf_r") for k in legs) == s["lateral_registries"] * (n + m + len(rows))


# ------------------------------------------------------------------------------------ drift, tilt, hysteresis

def _ar1(rng, n, phi):
    x = np.zeros(n)
    e = rng.normal(size=n)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_linear_drift_flags_a_drifting_series_and_its_stderr_is_calibrated():
    """On stationary AR(1) series (phi = 0.9, g = 19) the slope's stderr matches the scatter of the slopes over
    300 seeds (ratio within 0.7-1.3) and at most about 5 % are flagged (1-13 %: the binomial scatter plus the bias
    of an estimated g; both tests must agree, so fewer than either alone); a trend of 0.01 per step (1 sd of the
    noise every 230 steps) is flagged on every seed."""
    from md.analysis.drift import linear_drift
    rng = np.random.default_rng(7)
    t = np.arange(1000.0)
    res = [linear_drift(t, _ar1(rng, 1000, 0.9)) for _ in range(300)]
    slopes = np.array([r["slope"] for r in res])
    assert np.median([r["slope_stderr"] for r in res]) / slopes.std() == pytest.approx(1.0, abs=0.3)
    assert 0.01 <= np.mean([r["drifting"] for r in res]) <= 0.13
    for _ in range(20):
        r = linear_drift(t, _ar1(rng, 1000, 0.9) + 0.01 * t)
        assert r["drifting"] and r["drift"] == pytest.approx(10.0, abs=4 * r["drift_stderr"])
    with pytest.raises(ValueError):
        linear_drift([0.0, 1.0], [1.0, 2.0])


def test_linear_drift_is_not_fooled_by_a_fast_oscillation_over_a_slow_fluctuation():
    """An MD energy's shape: a fast oscillation (AR(2), period 8 samples, its autocorrelation negative within 3
    samples) over a slow AR(1) (phi = 0.98, correlation time 50 samples, a fifth of a 250-sample block). The ACF
    stderr stops at the oscillation's first zero and is under half the slopes' true scatter over 300 seeds, so the
    ACF test alone flags over a quarter of these stationary series; the block-means stderr tracks the scatter
    (0.7-1.3) and the combined test flags about its nominal 5 % (at most 12 %: binomial scatter over 300 seeds
    plus blocks that are only five correlation times long). A trend of 5 block-stderrs is still caught on 9 seeds in
    10."""
    from scipy.signal import lfilter

    from md.analysis.drift import linear_drift
    rng = np.random.default_rng(11)
    n, t = 2000, np.arange(2000.0)
    w = 2.0 * np.pi / 8.0

    def series():
        fast = lfilter([3.0], [1.0, -1.9 * np.cos(w), 0.95 ** 2], rng.normal(size=n))
        return fast + lfilter([1.0], [1.0, -0.98], rng.normal(size=n))

    res = [linear_drift(t, series()) for _ in range(300)]
    slopes = np.array([r["slope"] for r in res])
    assert np.median([r["slope_stderr_acf"] for r in res]) / slopes.std() < 0.5
    assert np.mean([abs(r["slope"]) > r["z_max"] * r["slope_stderr_acf"] for r in res]) > 0.25
    assert np.median([r["slope_stderr"] for r in res]) / slopes.std() == pytest.approx(1.0, abs=0.3)
    assert np.mean([r["drifting"] for r in res]) <= 0.12
    trend = 5.0 * np.median([r["slope_stderr_blocks"] for r in res])
    assert np.mean([linear_drift(t, series() + trend * t)["drifting"] for _ in range(50)]) >= 0.9


def test_anneal_figure_draws_the_drift_tests_line_and_says_what_it_concluded():
    """The anneal figure plots energy and tilt with the second half's fitted line: the dashed energy line has the
    drift test's slope, and the title names the drifting series (energy trends, tilt is flat) or says none."""
    from matplotlib.figure import Figure

    from md.analysis.drift import linear_drift
    from md.workflows.adhesion_protocol import draw_anneal
    rng = np.random.default_rng(3)
    t, tt = np.linspace(0.0, 150.0, 1500), np.linspace(3.0, 150.0, 50)

    def det(trend):
        pe, tilt = -6e4 + _ar1(rng, 1500, 0.5) - trend * t, 25.0 + rng.normal(size=50)
        h, k = len(t) // 2, len(tt) // 2
        return {"time_ps": t, "potential_energy_kcal": pe, "tilt_time_ps": tt, "mean_tilt_deg": tilt,
                "drift_second_half": {"potential_energy_kcal": linear_drift(t[h:], pe[h:]),
                                      "mean_tilt_deg": linear_drift(tt[k:], tilt[k:])}}

    for trend, title in ((0.5, "still drifting: potential_energy_kcal"), (0.0, "no drift")):
        d = det(trend)
        ax = Figure().subplots()
        draw_anneal(ax, d)
        assert title in ax.get_title()
        x, y = ax.lines[1].get_data()
        assert ax.lines[1].get_linestyle() == "--" and x[0] == pytest.approx(t[len(t) // 2])
        assert np.polyfit(x, y, 1)[0] == pytest.approx(d["drift_second_half"]["potential_energy_kcal"]["slope"])


def test_chain_tilt_follows_an_axis_that_reaches_further_sideways_than_half_the_box():
    """Two chains (one on the upper slab, pointing down) tilting from 15 to 40 deg over 26 frames in a 12 A box,
    positions wrapped: a 20 A axis at 40 deg reaches 12.9 A sideways, beyond the minimum image; the tilt is the
    exact angle in every frame."""
    from md.workflows.adhesion_protocol import chain_tilts_deg
    box = np.array([[12.0, 12.0, 80.0]] * 26)
    L = 20.0
    angles = np.radians(np.linspace(15.0, 40.0, 26))
    heads = np.array([[9.5, 5.0, 0.0], [2.0, 2.0, 50.0]])
    pos = []
    for t in angles:
        ends = np.array([[9.5 + L * math.sin(t), 5.0, L * math.cos(t)],
                         [2.0, 2.0 - L * math.sin(t), 50.0 - L * math.cos(t)]])
        frame = np.vstack([heads, ends])
        frame[:, :2] %= 12.0
        pos.append(frame)
    tilts = chain_tilts_deg(np.array([1, 2, 3, 4]), np.array(pos), box, np.array([[0, 2], [1, 3]]))
    assert tilts == pytest.approx(np.degrees(angles), abs=1e-9)


def test_hysteresis_is_the_difference_and_the_estimate_the_mean():
    from md.analysis import hysteresis
    h = hysteresis(0.066, 0.004, 0.046, 0.003)
    assert h["hysteresis"] == pytest.approx(0.020) and h["value"] == pytest.approx(0.056)
    assert h["systematic"] == pytest.approx(0.010) and h["stderr"] == pytest.approx(0.0025)
    assert h["hysteresis_stderr"] == pytest.approx(0.005)


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
    for suf, _d, _prev, rep in Adhesion.return_chain(s):
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
    r = _run(_recipe("adhesion_silica_ots", lateral_registries=2), cache).result
    assert r["details"]["pmf_windows"]["registry_offsets_A"][1] == pytest.approx([2.531442, 4.384587], abs=1e-6)
    (note,) = [n for n in r["notes"] if n.startswith("REGISTRIES DEGENERATE")]
    assert "1 repeats 0" in note and "2 chains sample 1 distinct registry" in note
