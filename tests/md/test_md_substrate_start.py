"""How the silica substrates start: the periodic build every silica recipe shares, and the FIRE minimisation.

The builds start strained (the builder's ideal cristobalite: Si-O 1.55 A against IFF's 1.68 A, straight Si-O-Si
against 149 deg), so every workflow minimises first. FIRE grows its step to 10 x the timestep, and nothing is
constrained while it runs: at a SHAKE recipe's 2 fs it reaches 20 fs, two periods of the free silanol O-H, and in
a large slab FIRE's global power test does not see one H diverging until it collapses onto its O and is shot away
("Bond atoms missing"); a small slab recovers from the same force spikes. FIRE therefore runs at 1 fs
(``md.workflows.common.FIRE_TIMESTEP_FS``), and the quick silica substrate is minimised here by the plan's own
commands.

The build-level checks below (every silica recipe, every fidelity) guard the other suspects: each bond's
minimum-image length is at its force-field r0 (within the builder's documented strain), and the lateral box is
a whole number of (111) surface cells. Image flags: ``write_data`` writes none (all 0), so LAMMPS warns
"Inconsistent image flags" for the bonds that cross x or y. That warning is inherent to a slab bonded across
its periodic boundaries -- a bond path around the box adds up to a box length, so no choice of image flags can
make every bond's unwrapped length its minimum-image length -- and harmless: LAMMPS evaluates bonded terms
between the closest images.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

from md.build import CRISTOBALITE_A
from md.recipe import load_recipe

ROOT = Path(__file__).resolve().parents[2]
RECIPES = sorted(p.stem for p in (ROOT / "inputs" / "md").glob("*.toml"))
SILICA_RECIPES = ["contact_angle_silica", "contact_angle_ots", "adhesion_silica", "adhesion_silica_ots",
                  "pulloff_silica"]
FIDELITIES = ["smoke", "quick", "production"]
#: (111) surface cell of cristobalite: a/sqrt2 along [1-10], a sqrt(3/2) along [11-2]
CELL_111 = (CRISTOBALITE_A / math.sqrt(2), CRISTOBALITE_A * math.sqrt(6) / 2)
#: every built bond lies this close to its r0 (the ideal cell's Si-O is 1.550 A against IFF's 1.680 A)
BOND_TOL_A = 0.3
#: condensation bridges (Si-OH + HO-Si -> Si-O-Si on the asperity's dome) start at ~2.7 A: the builder says so
BRIDGE_MAX_A = 2.75
#: the FIRE timestep the flexible silanol O-H tolerates (FIRE's steps reach 10 x this)
FIRE_DT_MAX_FS = 1.0


# ------------------------------------------------------------------------------------ FIRE timestep

def _fire_timesteps(cmds: list[str], dt: float | None = None) -> tuple[list[float | None], float | None]:
    """The timestep in effect at every FIRE ``minimize`` of ``cmds``, and the one left in effect at the end."""
    style, at_fire = None, []
    for c in cmds:
        w = c.split()
        if not w:
            continue
        if w[0] == "timestep":
            dt = float(w[1])
        elif w[0] == "min_style":
            style = w[1]
        elif w[0] == "minimize" and style == "fire":
            at_fire.append(dt)
    return at_fire, dt


@pytest.mark.parametrize("name", ["contact_angle_silica", "contact_angle_ots"])
def test_the_substrate_is_minimised_by_fire_at_1_fs_and_run_at_the_recipes_timestep(name, tmp_path):
    """The plan's own commands: FIRE at <= 1 fs (silica's recipe timestep is 2 fs), then the recipe's timestep
    again before any dynamics."""
    from md.workflows import get_workflow
    s = load_recipe(name).settings("smoke")
    plan = get_workflow("contact_angle").plan(s, tmp_path)
    leg = plan.legs[0]
    d = tmp_path / "legs" / leg.name
    at_fire, dt = _fire_timesteps(leg.fresh(d) + leg.define(0) + leg.prepare(d))
    assert at_fire, "the substrate leg has no FIRE minimisation"
    assert all(x is not None and x <= FIRE_DT_MAX_FS for x in at_fire), at_fire
    assert dt == s["timestep_fs"]


@pytest.mark.parametrize("fidelity", FIDELITIES)
def test_no_recipe_minimises_with_fire_above_1_fs(fidelity):
    """Every recipe at every fidelity, through the helper every workflow minimises with (FIRE for the solids,
    cg for rigid water): FIRE never above 1 fs, the recipe's timestep restored after it."""
    from md.workflows.common import minimize_lines
    for name in RECIPES:
        s = load_recipe(name).typed_settings(fidelity)
        at_fire, dt = _fire_timesteps(minimize_lines(s), dt=s.timestep_fs)
        assert all(x <= FIRE_DT_MAX_FS for x in at_fire), (name, at_fire)
        assert dt == s.timestep_fs, name


@pytest.mark.md
@pytest.mark.slow
def test_quick_silica_substrate_survives_fire(needs_lammps, tmp_path):
    """The failing case itself: the quick contact_angle_silica substrate, minimised by the plan's own commands.
    This is the substrate on which FIRE at the recipe's 2 fs loses a silanol H ("Bond atoms missing"); at 1 fs 60
    steps leave every silanol O-H at its length and the energy lower."""
    from md.lammps_loader import new_lammps
    from md.workflows import get_workflow
    from md.workflows.common import forcefield_of
    s = dict(load_recipe("contact_angle_silica").settings("quick"))
    s["minimize_steps"] = 60
    wf = get_workflow("contact_angle")
    plan = wf.plan(s, tmp_path)
    leg = plan.legs[0]
    d = tmp_path / "legs" / leg.name
    d.mkdir(parents=True)
    oh = next(k for k, t in enumerate(forcefield_of(wf.forcefield_files(s)).bond_types, 1)
              if sorted(t.types) == ["HOY", "OC24"])
    lmp = new_lammps()
    try:
        for c in leg.fresh(d):
            if c.startswith("min_style"):
                lmp.command("run 0")
                e0 = float(lmp.get_thermo("pe"))
            lmp.command(c)
        lmp.command("run 0")
        e1 = float(lmp.get_thermo("pe"))
        lmp.command("compute b all bond/local dist")
        lmp.command("compute bt all property/local btype")
        lmp.command("run 0")
        dist = np.asarray(lmp.numpy.extract_compute("b", 2, 1))
        btype = np.asarray(lmp.numpy.extract_compute("bt", 2, 1)).astype(int)
    finally:
        lmp.close()
    assert np.isfinite(e1) and e1 < e0 - 1e4
    assert np.all(np.abs(dist[btype == oh] - 0.945) < 0.1)
    assert dist.max() < 2.0


# ------------------------------------------------------------------------------------ periodic build

def _substrates(name: str, fidelity: str):
    """The periodic silica (with its SAM) the recipe's workflow builds, and the cell counts it asked for."""
    from md.workflows.common import silica_face_of, surface_slab
    from md.workflows.pulloff import PullOff
    s = load_recipe(name).typed_settings(fidelity)
    if name.startswith("pulloff"):
        system, _ = PullOff().build(PullOff.typed(s))
        return [system], None
    kinds = s.surfaces if name.startswith("adhesion") else [s.surface]
    slabs = [surface_slab(k, s.nx, s.ny, s.slab_thickness_A, s, s.seed + 10 * i, silica_face_of(kinds, s.silica_face))
             for i, k in enumerate(kinds)]
    return slabs, (s.nx, s.ny)


def _forcefield_r0(system) -> np.ndarray:
    from md.workflows.common import forcefield_of
    names = ["silica_interface"] + (["ots_trappe_ua"] if "CH3" in set(system.types.tolist()) else []) \
        + (["water_spce"] if "OW" in set(system.types.tolist()) else [])
    r0 = {t.name: float(t.coeffs[1]) for t in forcefield_of(names).bond_types}
    return np.array([r0[n] for n in system.bond_types])


def _condensed_bridges(info) -> int:
    """Condensation bridges the builders report, summed over the nested build records of ``info``."""
    if not isinstance(info, Mapping):
        return 0
    return int(info.get("condensed_bridges", 0) or 0) + sum(_condensed_bridges(v) for v in info.values())


def bond_defects(system) -> dict:
    """Minimum-image bond lengths of ``system`` (positions wrapped into the box, as the data file has them)
    against r0: the bonds off by more than BOND_TOL_A, and how many cross a periodic boundary."""
    from md.system.topology import minimum_image
    p = system.wrapped_positions()
    b = np.asarray(system.bonds)
    d = p[b[:, 1]] - p[b[:, 0]]
    r = np.linalg.norm(minimum_image(d, system.cell, system.pbc), axis=1)
    dev = r - _forcefield_r0(system)
    off = np.abs(dev) > BOND_TOL_A
    return {"r": r, "dev": dev, "off": off, "crossing": int(np.sum(np.abs(np.linalg.norm(d, axis=1) - r) > 1e-6))}


def assert_periodic_build_is_whole(system, cells=None):
    nx, ny = system.cell[0] / CELL_111[0], system.cell[1] / CELL_111[1]
    assert nx == pytest.approx(round(nx), abs=1e-6) and ny == pytest.approx(round(ny), abs=1e-6), (nx, ny)
    if cells is not None:
        assert (round(nx), round(ny)) == tuple(cells)
    d = bond_defects(system)
    assert d["crossing"] > 0                                            # the slab is bonded across x and y
    n_bridges = _condensed_bridges(system.info)
    long = d["off"] & (d["dev"] > 0)
    # only the asperity's condensation bridges are off r0, two Si-O bonds each, and none longer than ~2.7 A
    assert not (d["off"] & (d["dev"] < 0)).any()
    assert long.sum() == 2 * n_bridges, (long.sum(), n_bridges, np.sort(d["r"][long])[-5:])
    assert d["r"].max() < BRIDGE_MAX_A


@pytest.mark.parametrize("fidelity", [f if f != "production" else pytest.param(f, marks=pytest.mark.slow)
                                      for f in FIDELITIES])
@pytest.mark.parametrize("name", SILICA_RECIPES)
def test_every_silica_build_is_whole_cells_with_every_bond_at_its_length(name, fidelity):
    slabs, cells = _substrates(name, fidelity)
    for system in slabs:
        assert_periodic_build_is_whole(system, cells)


def test_the_check_sees_a_box_that_is_not_a_whole_number_of_cells():
    """The check is sensitive to the suspected bug: the same slab in a box 0.3 (111) cells shorter along x (or y)
    has the bonds that crossed that boundary displaced by 0.3 cells, and is not a whole number of cells."""
    from dataclasses import replace
    slab = _substrates("contact_angle_silica", "smoke")[0][0]
    assert_periodic_build_is_whole(slab)
    for k in (0, 1):
        cell = slab.cell.copy()
        cell[k] -= 0.3 * CELL_111[k]
        bad = replace(slab, cell=cell)
        d = bond_defects(bad)
        assert d["off"].sum() >= 2 and np.abs(d["dev"]).max() > BOND_TOL_A
        with pytest.raises(AssertionError):
            assert_periodic_build_is_whole(bad)


def test_the_contact_angle_box_is_the_substrates_and_the_data_file_keeps_the_bonds(tmp_path):
    """The droplet never sets the box: the data files the legs read have the substrate's lateral cell, and the
    written (wrapped) coordinates give every bond at its length under minimum image."""
    from md.workflows import get_workflow
    s = load_recipe("contact_angle_silica").settings("smoke")
    wf = get_workflow("contact_angle")
    sub, _, system = wf.build(wf.typed(s))
    np.testing.assert_allclose(system.cell[:2], sub.cell[:2])
    wf.plan(s, tmp_path)
    for f in ("substrate.data", "system.data"):
        box, pos, btype, pairs, r0 = _read_data(tmp_path / f)
        np.testing.assert_allclose(box[:2], sub.cell[:2], atol=1e-6)
        d = pos[pairs[:, 1]] - pos[pairs[:, 0]]
        d[:, :2] -= box[:2] * np.round(d[:, :2] / box[:2])
        r = np.linalg.norm(d, axis=1)
        assert np.all(np.abs(r - r0[btype]) < BOND_TOL_A), f


def _read_data(path: Path):
    lines = path.read_text().splitlines()
    box = np.array([float(l.split()[1]) - float(l.split()[0]) for l in lines[:40] if l.endswith("hi")])

    def section(title):
        i = next(i for i, l in enumerate(lines) if l.split("#")[0].strip() == title)
        rows = []
        for l in lines[i + 2:]:
            f = l.split("#")[0].split()
            if not f:
                break
            rows.append(f)
        return rows

    r0 = {int(f[0]): float(f[2]) for f in section("Bond Coeffs")}
    atoms = section("Atoms")
    ids = np.array([int(f[0]) for f in atoms])
    pos = np.empty((ids.max() + 1, 3))
    pos[ids] = [[float(x) for x in f[4:7]] for f in atoms]
    bonds = np.array([[int(x) for x in f[1:4]] for f in section("Bonds")])
    table = np.zeros(max(r0) + 1)
    for k, v in r0.items():
        table[k] = v
    return box, pos, bonds[:, 0], bonds[:, 1:], table
