"""What the two workflows that put water on a substrate share (:mod:`~md.workflows.contact_angle`, a droplet;
:mod:`~md.workflows.wsl_ti`, a film): the force fields, the substrate slab the recipe names, the combined system
written as a reference beside its two parts (the legs read the parts), the held deep layer, the water O and the
SAM's TraPPE sites (for the dispersion beyond the cutoff), and the substrate leg -- the slab minimised with nothing
held, then its deep Si and bridging O held (silanol O-H by SHAKE) and equilibrated alone.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from md.engine.plan import Leg, Stage
from md.system.forcefield import ForceField
from md.system.lammps_data import write_data
from md.system.topology import System, remove_atoms
from md.workflows.common import (
    SILANOL_OH,
    Settings,
    common_define,
    derived_seed,
    fresh_from_data,
    held_deep,
    minimize_lines,
    shake_lines,
    silica_face_of,
    steps_of,
    surface_slab,
    trappe_tail_sites,
    water_forcefield_names,
)

#: what result.json's system block says is held
HELD = "deep Si and bridging O of the builder's bottom layer"


def substrate_water_forcefields(s: Settings) -> list[str]:
    """The force-field files: the silica interface, TraPPE-UA on OTS, the recipe's water model."""
    return ["silica_interface"] + (["ots_trappe_ua"] if s.surface == "ots" else []) + \
        water_forcefield_names(s.water_model)


def substrate_of(s: Settings) -> System:
    """The recipe's substrate: ``nx`` x ``ny`` cells of silica (``silica_face``) or the OTS SAM on (111) silica."""
    return surface_slab(s.surface, s.nx, s.ny, s.slab_thickness_A, s, int(s.seed),
                        silica_face_of((s.surface,), s.silica_face))


@dataclass(frozen=True)
class SubstrateWater:
    """A substrate with water on it, written for the legs: 0-based atom indices of the combined ``system``
    (``substrate``, ``water``, ``held`` the deep layer, ``water_o``, ``tail_sites`` the SAM's TraPPE sites with
    ``c6`` their C6 with the water O, kcal/mol A^6), the data files of the two parts and the SHAKE lines."""
    ff: ForceField
    system: System
    substrate: np.ndarray
    water: np.ndarray
    held: np.ndarray
    water_o: np.ndarray
    tail_sites: np.ndarray
    c6: list[float]
    sub_data: Path
    water_data: Path
    shake: list[str]

    @property
    def groups(self) -> dict[str, np.ndarray]:
        """The substrate leg's groups: the substrate and its held deep layer."""
        return {"substrate": self.substrate, "frozen": self.held}


def write_substrate_water(workflow: str, water_part: str, ff: ForceField, system: System,
                          run_dir: Path) -> SubstrateWater:
    """Write ``system`` (substrate group 'substrate', water 'adsorbate') to ``run_dir`` as the reference
    ``system.data`` and its two parts ``substrate.data`` and ``water.data`` (titles name the workflow and
    ``water_part``), and index what the legs and the analysis need."""
    substrate, water = system.group("substrate"), system.group("adsorbate")
    sub_data, water_data = run_dir / "substrate.data", run_dir / "water.data"
    write_data(system, ff, run_dir / "system.data", title=f"{workflow} system (reference; the legs read the two parts)")
    write_data(remove_atoms(system, water), ff, sub_data, title=f"{workflow} substrate")
    write_data(remove_atoms(system, substrate), ff, water_data, title=f"{workflow} {water_part}")
    water_o = np.intersect1d(system.group("water_O"), water)
    tail_sites, c6 = trappe_tail_sites(system, ff, water_o)
    return SubstrateWater(ff=ff, system=system, substrate=substrate, water=water,
                          held=np.intersect1d(held_deep(system), substrate), water_o=water_o, tail_sites=tail_sites,
                          c6=c6, sub_data=sub_data, water_data=water_data, shake=shake_lines(ff, also=SILANOL_OH))


def held_define(s: Settings, parts: SubstrateWater) -> list[str]:
    """Every leg's start: the common define on the mobile atoms, the held layer's pairs excluded, SHAKE, the held
    layer's forces zeroed."""
    return common_define(s, "mobile") + ["neigh_modify exclude group frozen frozen"] + parts.shake + \
        ["fix hold frozen setforce 0.0 0.0 0.0"]


def substrate_leg(s: Settings, parts: SubstrateWater, define: Callable[[int], list[str]],
                  restart_head: Callable[[Path], list[str]], n_atoms: int, pair: str = "long",
                  kspace: tuple[str, ...] = ()) -> Leg:
    """The substrate alone, minimised with nothing held (no setforce, no exclusions: the deep layer is held only
    afterwards, at its relaxed positions), then equilibrated (unsampled) from velocities drawn at the temperature."""
    def fresh_substrate(leg_dir: Path) -> list[str]:
        return fresh_from_data(parts.ff, parts.sub_data, s, parts.groups, pair=pair) + list(kspace) + \
            ["group mobile subtract all frozen"] + minimize_lines(s, leg_dir / "minimized.data")

    t = s.temperature_K
    return Leg(name="substrate", fresh=fresh_substrate, define=define, prepare=lambda d: [],
               restart_head=restart_head,
               stages=[Stage("equilibrate", steps_of(s.substrate_equilibrate_steps, s.sample_interval),
                             (f"velocity mobile create {t:g} {derived_seed(int(s.seed), 3, 0)} mom yes rot no "
                              f"dist gaussian",), sampled=False)],
               columns={"pe": "v_pe", "temp": "v_temp"}, sample_interval=s.sample_interval,
               chunk_steps=s.chunk_steps, n_atoms=n_atoms)
