"""Adhesion and pull-off protocols: dispersion beyond the cutoff, chained force-integration
windows reaching into compression and averaged over lateral registries, z0 and sigma0 from the flat-slab curve,
the pull-off thermostat and its residual drag, the OTS asperity's grafting density, and the calibration's use of
the flat-slab z0.

Tests marked ``md`` run LAMMPS at smoke fidelity (seconds each); the rest need no LAMMPS.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from recipe_helpers import recipe_with, run_quiet, settings_with

from md.recipe import load_recipe


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
    assert ad.protocol_version(settings_with("adhesion_silica", "quick")) == ad.version
    for name in ("adhesion_ots", "adhesion_silica_ots"):
        assert ad.protocol_version(settings_with(name, "quick")) == ad.version - 1
        _, doc = run_hash(name, "quick")
        assert doc["workflow_version"] == ad.version - 1


def test_windows_are_chains_reaching_into_compression_at_every_registry(tmp_path):
    """The generated commands: window 0 of every registry starts from the contact leg's last restart, moved
    laterally to the registry's offset; each further window reads its neighbour's last restart and moves the upper
    slab by the difference of the nominal separations -- inwards (compression) and outwards."""
    from md.workflows.adhesion import Adhesion
    from md.workflows.adhesion_legs import REGISTRY_LIFT_A, REGISTRY_LOWER_STEPS, _registry_offsets
    s = settings_with("adhesion_silica", "quick")
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
    nominal = dict((suf, d) for suf, d, _ in wf.chains(wf.typed(s)))
    assert min(nominal.values()) == pytest.approx(-s["pmf_compress_A"])
    assert max(nominal.values()) == pytest.approx(s["separation_A"])
    for r, (dx, dy) in enumerate(offsets):
        for suf, d, prev in wf.chains(wf.typed(s)):
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
    so = settings_with("adhesion_silica_ots", "quick")
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
    nominal = {suf: d for suf, d, _ in Adhesion.chains(Adhesion.typed(s))}
    contact = read_samples(legs / "contact" / "samples.csv")
    for suf, d, prev in Adhesion.chains(Adhesion.typed(s)):
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
    old = run_quiet(recipe_with("pulloff_silica", tip_thermostat="lab", retract_repeats=1,
                                new_name="pulloff_silica_lab"), cache).result
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
