"""A molecular system as plain arrays: :class:`System`, and the operations the builders compose.

Units are LAMMPS ``real`` (the MD layer's edge): positions and cell in angstrom, charges in e, masses in g/mol.

* :class:`System` -- frozen: positions, force-field type names, charges, masses, molecule ids, bonds/angles/
  dihedrals as index arrays with the force field's bonded-type names, an orthorhombic cell ``[0, L)`` per
  axis, periodicity flags, named index groups and a free ``info`` dict saying what a builder made.
* :func:`from_types` -- a System whose charges and masses are looked up in a :class:`~md.system.forcefield.ForceField`.
* :func:`with_bonded_terms` -- types every bond and generates every angle and dihedral from the bond graph,
  looking each up in the force field; a term without parameters raises :class:`MissingParameterError`
  naming it. Dihedrals whose parameters are all zero (IFF's Si-O torsions) are left out by default.
* :func:`merge`, :func:`translate`, :func:`flip_upside_down`, :func:`with_cell` -- geometry and bookkeeping.

Nothing here needs LAMMPS.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from md.system.forcefield import WILDCARD, ForceField

__all__ = ["System", "MissingParameterError", "from_types", "with_bonded_terms", "merge", "translate",
           "flip_upside_down", "with_cell", "with_groups", "with_info", "remove_atoms", "neighbors",
           "minimum_image", "bonded_type_lookup"]


class MissingParameterError(KeyError):
    """A bonded term (bond, angle, dihedral) built from the bond graph has no parameters in the force field."""

    def __str__(self) -> str:  # KeyError would print the repr of the message
        return str(self.args[0]) if self.args else ""


def _frozen(a: Any, dtype=None, shape_tail: tuple[int, ...] | None = None) -> np.ndarray:
    arr = np.array(a, dtype=dtype, copy=True)
    if shape_tail is not None:
        arr = arr.reshape((-1,) + shape_tail) if arr.size else np.zeros((0,) + shape_tail, dtype=arr.dtype)
    arr.setflags(write=False)
    return arr


def _names(a: Iterable[str]) -> np.ndarray:
    arr = np.array([str(x) for x in a], dtype=object)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class System:
    """An all-atom (or united-atom) system ready for a LAMMPS ``atom_style full`` data file.

    Index arrays are 0-based into the atom arrays. Type names are :class:`~md.system.forcefield.ForceField` names
    (atom types; bond/angle/dihedral type ``name`` fields). Arrays are read-only; every operation returns a
    new System.
    """
    positions: np.ndarray                      #: (N, 3) angstrom
    types: np.ndarray                          #: (N,) force-field atom-type names
    charges: np.ndarray                        #: (N,) e
    masses: np.ndarray                         #: (N,) g/mol
    mol_ids: np.ndarray                        #: (N,) molecule ids (>= 1)
    cell: np.ndarray                           #: (3,) box lengths in angstrom; the box is [0, L) on each axis
    pbc: tuple[bool, bool, bool] = (True, True, False)
    bonds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), int))
    bond_types: np.ndarray = field(default_factory=lambda: _names(()))
    angles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), int))
    angle_types: np.ndarray = field(default_factory=lambda: _names(()))
    dihedrals: np.ndarray = field(default_factory=lambda: np.zeros((0, 4), int))
    dihedral_types: np.ndarray = field(default_factory=lambda: _names(()))
    groups: Mapping[str, np.ndarray] = field(default_factory=dict)
    info: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "positions", _frozen(self.positions, float, (3,)))
        n = len(self.positions)
        s(self, "types", _names(self.types))
        s(self, "charges", _frozen(self.charges, float))
        s(self, "masses", _frozen(self.masses, float))
        s(self, "mol_ids", _frozen(self.mol_ids, int))
        s(self, "cell", _frozen(self.cell, float))
        s(self, "pbc", tuple(bool(p) for p in self.pbc))
        for name, k in (("bonds", 2), ("angles", 3), ("dihedrals", 4)):
            s(self, name, _frozen(self.__dict__[name], int, (k,)))
        for name in ("bond_types", "angle_types", "dihedral_types"):
            s(self, name, _names(self.__dict__[name]))
        s(self, "groups", MappingProxyType({str(k): _frozen(v, int) for k, v in dict(self.groups).items()}))
        s(self, "info", MappingProxyType(dict(self.info)))
        for name in ("types", "charges", "masses", "mol_ids"):
            if len(self.__dict__[name]) != n:
                raise ValueError(f"System.{name} has {len(self.__dict__[name])} entries for {n} atoms")
        if self.cell.shape != (3,) or np.any(self.cell <= 0):
            raise ValueError(f"System.cell must be three positive lengths, got {self.cell}")
        for idx, typ in (("bonds", "bond_types"), ("angles", "angle_types"), ("dihedrals", "dihedral_types")):
            terms, names = self.__dict__[idx], self.__dict__[typ]
            if len(names) not in (0, len(terms)):
                raise ValueError(f"System.{typ} has {len(names)} names for {len(terms)} {idx}")
            if terms.size and (terms.min() < 0 or terms.max() >= n):
                raise ValueError(f"System.{idx} refers to atoms outside 0..{n - 1}")
        for g, ids in self.groups.items():
            if ids.size and (ids.min() < 0 or ids.max() >= n):
                raise ValueError(f"group {g!r} refers to atoms outside 0..{n - 1}")

    # ------------------------------------------------------------------------------------------ queries
    @property
    def n_atoms(self) -> int:
        return len(self.positions)

    def total_charge(self) -> float:
        """Sum of the atomic charges in e (exact summation)."""
        return math.fsum(self.charges.tolist())

    def count(self, type_name: str) -> int:
        return int(np.count_nonzero(self.types == type_name))

    def type_counts(self) -> dict[str, int]:
        names, counts = np.unique(self.types.astype(str), return_counts=True)
        return {str(a): int(b) for a, b in zip(names, counts)}

    def select(self, *type_names: str) -> np.ndarray:
        """Indices of atoms of the given types."""
        return np.flatnonzero(np.isin(self.types.astype(str), type_names))

    def group(self, name: str) -> np.ndarray:
        try:
            return self.groups[name]
        except KeyError:
            raise KeyError(f"no group {name!r}; groups: {sorted(self.groups)}") from None

    def wrapped_positions(self) -> np.ndarray:
        """Positions with periodic axes wrapped into [0, L)."""
        p = self.positions.copy()
        for k in range(3):
            if self.pbc[k]:
                p[:, k] = np.mod(p[:, k], self.cell[k])
                p[:, k] = np.where(p[:, k] >= self.cell[k], 0.0, p[:, k])
        return p

    def __repr__(self) -> str:
        return (f"System({self.n_atoms} atoms, {len(self.bonds)} bonds, {len(self.angles)} angles, "
                f"{len(self.dihedrals)} dihedrals, cell={np.round(self.cell, 3).tolist()}, "
                f"q={self.total_charge():+.2e}, groups={sorted(self.groups)})")


# ---------------------------------------------------------------------------------------------------- helpers

def minimum_image(d: np.ndarray, cell: np.ndarray, pbc: Sequence[bool]) -> np.ndarray:
    """Minimum-image displacement vectors (orthorhombic box)."""
    d = np.array(d, dtype=float, copy=True)
    for k in range(d.shape[-1]):
        if pbc[k]:
            d[..., k] -= cell[k] * np.round(d[..., k] / cell[k])
    return d


def neighbors(system: System) -> list[list[int]]:
    """Bonded neighbours of every atom (sorted)."""
    nb: list[list[int]] = [[] for _ in range(system.n_atoms)]
    for i, j in system.bonds.tolist():
        nb[i].append(j)
        nb[j].append(i)
    return [sorted(x) for x in nb]


def from_types(positions, types: Sequence[str], forcefield: ForceField, *, mol_ids=None, cell, pbc=(True, True, False),
               bonds=(), groups: Mapping[str, Any] | None = None, info: Mapping[str, Any] | None = None) -> System:
    """A System whose charges and masses come from ``forcefield`` (unknown type names raise KeyError)."""
    types = [str(t) for t in types]
    table = {t: forcefield.atom_type(t) for t in set(types)}
    n = len(types)
    return System(positions=positions, types=types, charges=[table[t].charge for t in types],
                  masses=[table[t].mass for t in types],
                  mol_ids=np.ones(n, int) if mol_ids is None else mol_ids, cell=cell, pbc=pbc,
                  bonds=np.asarray(bonds, int).reshape(-1, 2), groups=groups or {}, info=info or {})


# ---------------------------------------------------------------------------------------------------- bonded terms

def _canon(types: tuple[str, ...]) -> tuple[str, ...]:
    return min(types, tuple(reversed(types)))


def bonded_type_lookup(forcefield: ForceField):
    """Three callables (bond, angle, dihedral) mapping a tuple of atom-type names to the force-field term.

    Bonds and angles match exactly (either direction). Dihedrals match exactly first, then with the wildcard
    ``X`` in the outer positions (either direction). Each callable returns None when nothing matches.
    """
    bonds = {_canon(t.types): t for t in forcefield.bond_types}
    angles = {_canon(t.types): t for t in forcefield.angle_types}
    dih_exact = {_canon(t.types): t for t in forcefield.dihedral_types if WILDCARD not in t.types}
    dih_wild = [t for t in forcefield.dihedral_types if WILDCARD in t.types]

    def dihedral(types: tuple[str, str, str, str]):
        hit = dih_exact.get(_canon(types))
        if hit is not None:
            return hit
        for cand in (types, tuple(reversed(types))):
            for t in dih_wild:
                if all(p == WILDCARD or p == c for p, c in zip(t.types, cand)):
                    return t
        return None

    return (lambda t: bonds.get(_canon(tuple(t)))), (lambda t: angles.get(_canon(tuple(t)))), dihedral


def with_bonded_terms(system: System, forcefield: ForceField, *, angles: bool = True, dihedrals: bool = True,
                      omit_zero_dihedrals: bool = True) -> System:
    """Type every bond and (re)generate all angles and proper dihedrals from the bond graph.

    Every bond, every angle i-j-k (i, k bonded to j) and every dihedral i-j-k-l (j-k a bond, i on j, l on k,
    i != l) must have parameters in ``forcefield``; otherwise :class:`MissingParameterError` names the first
    missing term (e.g. ``angle HOY-OC24-SIH``). Dihedrals whose force-field coefficients are all zero
    (IFF sets every torsion about Si-O to zero) are omitted when ``omit_zero_dihedrals`` (their number is
    recorded in ``info['omitted_zero_dihedrals']``); they contribute nothing to energy or forces.
    Existing angles/dihedrals are discarded. No impropers are generated (none of our force fields has any).
    """
    bond_of, angle_of, dihedral_of = bonded_type_lookup(forcefield)
    types = [str(t) for t in system.types]
    b = np.asarray(system.bonds, int)
    # de-duplicate bonds and reject self-bonds
    if len(b):
        if np.any(b[:, 0] == b[:, 1]):
            raise ValueError("a bond joins an atom to itself")
        key = np.sort(b, axis=1)
        key, first = np.unique(key, axis=0, return_index=True)
        if len(key) != len(b):
            raise ValueError(f"{len(b) - len(key)} duplicate bonds")
    bond_names = []
    for i, j in b.tolist():
        t = bond_of((types[i], types[j]))
        if t is None:
            raise MissingParameterError(f"bond {types[i]}-{types[j]} (atoms {i}, {j}) has no parameters in force "
                                        f"field {forcefield.name!r}")
        bond_names.append(t.name)

    nb = neighbors(system)
    ang, ang_names = [], []
    if angles:
        for j, nj in enumerate(nb):
            for a in range(len(nj)):
                for c in range(a + 1, len(nj)):
                    i, k = nj[a], nj[c]
                    t = angle_of((types[i], types[j], types[k]))
                    if t is None:
                        raise MissingParameterError(
                            f"angle {types[i]}-{types[j]}-{types[k]} (atoms {i}, {j}, {k}) has no parameters in "
                            f"force field {forcefield.name!r}")
                    ang.append((i, j, k))
                    ang_names.append(t.name)
    dih, dih_names, omitted = [], [], 0
    if dihedrals:
        for j, k in b.tolist():
            for i in nb[j]:
                if i == k:
                    continue
                for l in nb[k]:
                    if l == j or l == i:
                        continue
                    tt = (types[i], types[j], types[k], types[l])
                    t = dihedral_of(tt)
                    if t is None:
                        raise MissingParameterError(
                            f"dihedral {'-'.join(tt)} (atoms {i}, {j}, {k}, {l}) has no parameters in force field "
                            f"{forcefield.name!r}")
                    if omit_zero_dihedrals and all(c == 0.0 for c in t.coeffs):
                        omitted += 1
                        continue
                    dih.append((i, j, k, l))
                    dih_names.append(t.name)
    info = dict(system.info)
    info["omitted_zero_dihedrals"] = omitted
    return replace(system, bond_types=bond_names, angles=np.array(ang, int).reshape(-1, 3), angle_types=ang_names,
                   dihedrals=np.array(dih, int).reshape(-1, 4), dihedral_types=dih_names, info=info)


# ---------------------------------------------------------------------------------------------------- geometry

def translate(system: System, shift: Sequence[float]) -> System:
    """The system moved by ``shift`` (angstrom). Nothing is wrapped."""
    return replace(system, positions=system.positions + np.asarray(shift, float).reshape(1, 3))


def with_cell(system: System, cell: Sequence[float], pbc: Sequence[bool] | None = None) -> System:
    return replace(system, cell=np.asarray(cell, float), pbc=tuple(system.pbc if pbc is None else pbc))


def with_groups(system: System, **groups: Any) -> System:
    g = dict(system.groups)
    g.update(groups)
    return replace(system, groups=g)


def with_info(system: System, **info: Any) -> System:
    d = dict(system.info)
    d.update(info)
    return replace(system, info=d)


def remove_atoms(system: System, indices: Iterable[int]) -> System:
    """The system without the given atoms; bonded terms touching them are dropped, groups are re-indexed."""
    drop = np.zeros(system.n_atoms, bool)
    drop[np.asarray(list(indices), int)] = True
    keep = ~drop
    new_index = np.full(system.n_atoms, -1, int)
    new_index[keep] = np.arange(int(keep.sum()))

    def terms(arr: np.ndarray, names: np.ndarray):
        if not len(arr):
            return arr, names
        ok = keep[arr].all(axis=1)
        return new_index[arr[ok]], (names[ok] if len(names) else names)

    b, bt = terms(system.bonds, system.bond_types)
    a, at = terms(system.angles, system.angle_types)
    d, dt = terms(system.dihedrals, system.dihedral_types)
    groups = {k: new_index[v[keep[v]]] for k, v in system.groups.items()}
    return replace(system, positions=system.positions[keep], types=system.types[keep], charges=system.charges[keep],
                   masses=system.masses[keep], mol_ids=system.mol_ids[keep], bonds=b, bond_types=bt, angles=a,
                   angle_types=at, dihedrals=d, dihedral_types=dt, groups=groups)


def _swap_top_bottom(name: str) -> str:
    if "top" in name:
        return name.replace("top", "bottom")
    if "bottom" in name:
        return name.replace("bottom", "top")
    return name


def flip_upside_down(system: System) -> System:
    """Rotate by 180 degrees about the x axis through the middle of the box: (x, y, z) -> (x, Ly - y, Lz - z).

    A proper rotation (no mirror), so chiral crystals keep their handedness. Group names containing ``top``
    and ``bottom`` are swapped, and so are info keys ending in ``_top``/``_bottom``.
    """
    p = system.positions.copy()
    p[:, 1] = system.cell[1] - p[:, 1]
    p[:, 2] = system.cell[2] - p[:, 2]
    groups = {_swap_top_bottom(k): v for k, v in system.groups.items()}
    info = {(_swap_top_bottom(k) if k.endswith(("_top", "_bottom")) else k): v for k, v in system.info.items()}
    info["flipped"] = not bool(system.info.get("flipped", False))
    return replace(system, positions=p, groups=groups, info=info)


def merge(systems: Sequence[System], *, cell: Sequence[float] | None = None,
          pbc: Sequence[bool] | None = None, info: Mapping[str, Any] | None = None) -> System:
    """Concatenate systems (no new bonds). Molecule ids are offset so they stay distinct.

    ``cell``/``pbc`` default to the first system's x, y and the largest z of all systems. Groups of the same
    name are concatenated. ``info['components']`` lists the components' info dicts.
    """
    systems = list(systems)
    if not systems:
        raise ValueError("merge() needs at least one system")
    offs = np.cumsum([0] + [s.n_atoms for s in systems])
    mol_off = 0
    parts: dict[str, list] = {k: [] for k in ("pos", "types", "q", "m", "mol", "b", "bt", "a", "at", "d", "dt")}
    groups: dict[str, list[np.ndarray]] = {}
    for s, o in zip(systems, offs):
        parts["pos"].append(s.positions)
        parts["types"].extend(s.types.tolist())
        parts["q"].append(s.charges)
        parts["m"].append(s.masses)
        mol = s.mol_ids - (s.mol_ids.min() if s.n_atoms else 0) + 1 + mol_off
        parts["mol"].append(mol)
        mol_off = int(mol.max()) if s.n_atoms else mol_off
        parts["b"].append(s.bonds + o)
        parts["a"].append(s.angles + o)
        parts["d"].append(s.dihedrals + o)
        for key, terms, names in (("bt", s.bonds, s.bond_types), ("at", s.angles, s.angle_types),
                                  ("dt", s.dihedrals, s.dihedral_types)):
            if len(terms) and len(names) != len(terms):
                raise ValueError("merge() needs typed bonded terms (run with_bonded_terms first) or none")
            parts[key].extend(names.tolist())
        for g, ids in s.groups.items():
            groups.setdefault(g, []).append(ids + o)
    if cell is None:
        cell = (systems[0].cell[0], systems[0].cell[1], max(s.cell[2] for s in systems))
    d = {"components": [dict(s.info) for s in systems]}
    d.update(info or {})
    return System(positions=np.concatenate(parts["pos"]), types=parts["types"], charges=np.concatenate(parts["q"]),
                  masses=np.concatenate(parts["m"]), mol_ids=np.concatenate(parts["mol"]), cell=cell,
                  pbc=tuple(systems[0].pbc if pbc is None else pbc),
                  bonds=np.concatenate(parts["b"]), bond_types=parts["bt"], angles=np.concatenate(parts["a"]),
                  angle_types=parts["at"], dihedrals=np.concatenate(parts["d"]), dihedral_types=parts["dt"],
                  groups={k: np.concatenate(v) for k, v in groups.items()}, info=d)
