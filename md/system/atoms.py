"""A :class:`~md.system.topology.System` as an :class:`ase.Atoms`, and back.

ASE is the structure currency for looking at and exchanging what the builders make: ``to_atoms(system)`` gives an
``Atoms`` that :func:`ase.visualize.view` shows and :func:`ase.io.write` writes (extxyz, cif, xyz, ...), with the
per-atom force-field types (``ff_types``), molecule ids (``mol-id``, the name ASE's LAMMPS readers use), charges
(``initial_charges``) and masses (united atoms keep their own) as ``Atoms`` arrays, the orthorhombic box as the
cell and the periodicity as ``pbc``. The bonded topology and the groups travel in ``atoms.info`` (``bonds``,
``bond_types``, ``angles``, ... as lists; ``groups``), so :func:`from_atoms` gives back the same System. The LAMMPS
data file stays :func:`md.system.lammps_data.write_data`'s: ASE's ``lammps-data`` writer drops angles and
dihedrals.
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from md.system.forcefield import available_forcefields, load_forcefield
from md.system.topology import System

__all__ = ["to_atoms", "from_atoms", "as_system", "element_of"]

_TERMS = ("bonds", "bond_types", "angles", "angle_types", "dihedrals", "dihedral_types")


@lru_cache(maxsize=1)
def _elements() -> dict[str, str]:
    """Force-field atom-type name -> chemical element, from every shipped force-field file."""
    table: dict[str, str] = {}
    for name in available_forcefields():
        for t in load_forcefield(name).atom_types:
            table.setdefault(t.name, t.element)
    return table


def element_of(type_name: str) -> str:
    """The chemical element of a force-field atom type (a united atom CH2 is carbon)."""
    try:
        return _elements()[str(type_name)]
    except KeyError:
        raise KeyError(f"atom type {type_name!r} is in no shipped force field; known: {sorted(_elements())}") from None


def to_atoms(system: System):
    """``system`` as an :class:`ase.Atoms` (positions in A, the box as an orthorhombic cell)."""
    from ase import Atoms

    atoms = Atoms(symbols=[element_of(t) for t in system.types.astype(str)], positions=system.positions,
                  cell=np.diag(system.cell), pbc=system.pbc)
    atoms.set_masses(system.masses)
    atoms.set_initial_charges(system.charges)
    atoms.new_array("ff_types", system.types.astype(str))
    atoms.new_array("mol-id", np.asarray(system.mol_ids, int))
    atoms.info.update({k: system.__dict__[k].tolist() for k in _TERMS})
    atoms.info["groups"] = {name: idx.tolist() for name, idx in system.groups.items()}
    atoms.info["system_info"] = dict(system.info)
    return atoms


def from_atoms(atoms) -> System:
    """The System :func:`to_atoms` made (an ``Atoms`` without ``ff_types`` has no force-field types: KeyError)."""
    if "ff_types" not in atoms.arrays:
        raise KeyError("atoms carry no 'ff_types' array (force-field atom types): build them with md.build, or "
                       "set atoms.new_array('ff_types', [...])")
    info: dict[str, Any] = atoms.info
    cell = atoms.cell.array
    if not np.allclose(cell, np.diag(np.diag(cell))):
        raise ValueError("only orthorhombic cells map onto a System box [0, L) per axis")
    mol = atoms.arrays.get("mol-id")
    terms = {k: np.asarray(info[k]) for k in _TERMS if k in info}
    for k, width in (("bonds", 2), ("angles", 3), ("dihedrals", 4)):
        if k in terms:
            terms[k] = terms[k].astype(int).reshape(-1, width)
    return System(positions=atoms.positions, types=atoms.arrays["ff_types"], charges=atoms.get_initial_charges(),
                  masses=atoms.get_masses(), mol_ids=np.ones(len(atoms), int) if mol is None else mol,
                  cell=np.diag(cell), pbc=tuple(bool(p) for p in atoms.pbc), **terms,
                  groups={k: np.asarray(v, int) for k, v in info.get("groups", {}).items()},
                  info=dict(info.get("system_info", {})))


def as_system(structure) -> System:
    """``structure`` as a System: a System as it is, an ``ase.Atoms`` through :func:`from_atoms`."""
    return structure if isinstance(structure, System) else from_atoms(structure)
