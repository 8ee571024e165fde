"""LAMMPS data files (``atom_style full``, ``units real``) for :class:`md.system.topology.System` (or the
``ase.Atoms`` a builder returns), and a read-back check.

ASE's LAMMPS writer drops bonds, angles and dihedrals; this one writes them. Type numbering is the force
field's own: atom types in the order of ``ForceField.atom_types`` (:func:`md.system.forcefield.lammps_type_ids`),
bond/angle/dihedral types in the order of ``ForceField.bond_types`` etc., the numbering that
:func:`md.system.forcefield.lammps_pair_coeffs`, :func:`~md.system.forcefield.lammps_bond_coeffs` and friends use --
so an input script built from the same force field matches the data file. Every type of the force field is declared
(also those the system does not use). Sections written: Masses, Bond/Angle/Dihedral Coeffs (from the force
field), Atoms (``id mol type q x y z``), Bonds, Angles, Dihedrals. Pair Coeffs are *not* written: the input
script sets ``pair_coeff`` from :func:`md.system.forcefield.lammps_pair_coeffs`.

Units at this edge: angstrom, kcal/mol, e, g/mol (LAMMPS ``real``), the units of :class:`System`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from md.system.atoms import as_system
from md.system.forcefield import ForceField, combine, lammps_pair_coeffs, lammps_type_ids, load_forcefield
from md.system.topology import System

__all__ = ["write_data", "read_atoms", "read_back_check", "ReadBack", "lammps_setup_commands", "style_of"]

_HEADER_TAG = "nanoimpact data file"


def style_of(terms: Sequence[Any]) -> str | None:
    """The LAMMPS style for a list of bonded types: their common style, ``hybrid ...`` if mixed, None if empty."""
    styles = list(dict.fromkeys(t.style for t in terms))
    if not styles:
        return None
    return styles[0] if len(styles) == 1 else "hybrid " + " ".join(styles)


def _coeff_section(title: str, terms: Sequence[Any]) -> list[str]:
    style = style_of(terms)
    hybrid = style is not None and style.startswith("hybrid")
    lines = [f"{title}  # {'hybrid' if hybrid else style}", ""]
    for k, t in enumerate(terms, start=1):
        coeffs = list(t.coeffs)
        if title.startswith("Dihedral") and t.style == "harmonic":   # K d n: d and n are integers
            text = f"{coeffs[0]:.10g} {int(coeffs[1])} {int(coeffs[2])}"
        else:
            text = " ".join(f"{c:.10g}" for c in coeffs)
        sub = f" {t.style}" if hybrid else ""
        lines.append(f"{k}{sub} {text}  # {t.name}")
    return lines + [""]


def write_data(system: System | Any, forcefield: ForceField, path: str | Path, *, title: str | None = None) -> Path:
    """Write ``system`` (a System, or the ``ase.Atoms`` a builder returns: :func:`md.system.atoms.as_system`) as a
    LAMMPS data file (atom_style full, units real); returns the path.

    Every atom type must be a force-field atom type and every bonded term must carry a force-field type name
    (build systems with :func:`md.system.topology.with_bonded_terms`); otherwise KeyError names the missing one.
    Periodic axes are wrapped into the box [0, L). The first line records the force-field name and the
    periodicity (``boundary p p f``), which :func:`read_back_check` reads.

    No image flags are written (LAMMPS takes them as 0). LAMMPS evaluates bonds, angles and dihedrals between
    the closest images, so a bond across a periodic boundary needs none; it only warns "Inconsistent image
    flags" for such bonds. For a slab bonded across x and y the warning cannot be avoided: a bond path around
    the box adds up to a box length, so no image flags make every bond's unwrapped length its minimum-image
    length. (tests/md/test_md_substrate_start.py checks that every bond is at its length under minimum image.)
    """
    system = as_system(system)
    path = Path(path)
    ids = lammps_type_ids(forcefield)
    missing = sorted(set(system.types.tolist()) - set(ids))
    if missing:
        raise KeyError(f"atom types {missing} are not in force field {forcefield.name!r}")
    kinds = (("bond", system.bonds, system.bond_types, forcefield.bond_types),
             ("angle", system.angles, system.angle_types, forcefield.angle_types),
             ("dihedral", system.dihedrals, system.dihedral_types, forcefield.dihedral_types))
    term_ids = _term_ids(kinds, forcefield)
    boundary = " ".join("p" if p else "f" for p in system.pbc)
    pos = system.wrapped_positions()
    for k in range(3):
        if not system.pbc[k] and (pos[:, k].min() < 0 or pos[:, k].max() > system.cell[k]):
            raise ValueError(f"atoms lie outside the non-periodic box along {'xyz'[k]} "
                             f"([{pos[:, k].min():.3f}, {pos[:, k].max():.3f}] vs [0, {system.cell[k]:.3f}])")
    n_types = {"bond": len(forcefield.bond_types), "angle": len(forcefield.angle_types),
               "dihedral": len(forcefield.dihedral_types)}
    head = title or str(system.info.get("builder", "system"))
    lines = [f"{_HEADER_TAG}: {head} | forcefield={forcefield.name} | boundary={boundary} | units=real "
             f"atom_style=full", ""]
    lines += _counts_and_box(system, kinds, n_types, len(ids), forcefield.name)
    lines += ["", "Masses", ""]
    for a in forcefield.atom_types:
        lines.append(f"{ids[a.name]} {a.mass:.6f}  # {a.name}")
    lines.append("")
    if n_types["bond"]:
        lines += _coeff_section("Bond Coeffs", forcefield.bond_types)
    if n_types["angle"]:
        lines += _coeff_section("Angle Coeffs", forcefield.angle_types)
    if n_types["dihedral"]:
        lines += _coeff_section("Dihedral Coeffs", forcefield.dihedral_types)
    lines += ["Atoms  # full", ""]
    types = system.types.tolist()
    for i in range(system.n_atoms):
        x, y, z = pos[i]
        lines.append(f"{i + 1} {int(system.mol_ids[i])} {ids[types[i]]} {system.charges[i]:.8f} "
                     f"{x:.6f} {y:.6f} {z:.6f}")
    lines.append("")
    for kind, terms, names, _ in kinds:
        if not len(terms):
            continue
        lines += [kind.capitalize() + "s", ""]
        table = term_ids[kind]
        for k, (row, name) in enumerate(zip(terms.tolist(), names.tolist()), start=1):
            lines.append(f"{k} {table[name]} " + " ".join(str(i + 1) for i in row))
        lines.append("")
    path.write_text("\n".join(lines))
    return path


def _term_ids(kinds, forcefield: ForceField) -> dict[str, dict[str, int]]:
    """Per bonded kind: force-field type name -> LAMMPS type id; KeyError where the system's terms carry no type
    names or a name the force field lacks."""
    term_ids: dict[str, dict[str, int]] = {}
    for kind, terms, names, fftypes in kinds:
        table = {t.name: k for k, t in enumerate(fftypes, start=1)}
        term_ids[kind] = table
        if len(terms) and len(names) != len(terms):
            raise KeyError(f"the system's {kind}s carry no type names; "
                           "build it with md.system.topology.with_bonded_terms")
        unknown = sorted(set(names.tolist()) - set(table))
        if unknown:
            raise KeyError(f"{kind} types {unknown} are not in force field {forcefield.name!r}")
    return term_ids


def _counts_and_box(system: System, kinds, n_types: Mapping[str, int], n_atom_types: int, ff_name: str) -> list[str]:
    """The data file's header: atom and term counts, type counts, box bounds."""
    lines = [f"{system.n_atoms} atoms"]
    for kind, terms, _, _ in kinds:
        if n_types[kind]:
            lines.append(f"{len(terms)} {kind}s")
        elif len(terms):
            raise KeyError(f"the system has {kind}s but force field {ff_name!r} defines no {kind} types")
    lines.append("")
    lines.append(f"{n_atom_types} atom types")
    for kind in ("bond", "angle", "dihedral"):
        if n_types[kind]:
            lines.append(f"{n_types[kind]} {kind} types")
    lines.append("")
    for k, ax in enumerate("xyz"):
        lines.append(f"0.0 {system.cell[k]:.8f} {ax}lo {ax}hi")
    return lines


def read_atoms(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ids, LAMMPS type numbers, positions (N, 3) in A) from the Atoms section of an ``atom_style full`` data
    file (ours, or LAMMPS's ``write_data``), sorted by id."""
    lines = Path(path).read_text().splitlines()
    start = next(i for i, l in enumerate(lines) if l.strip().startswith("Atoms"))
    ids, types, xyz = [], [], []
    for l in lines[start + 2:]:
        s = l.split("#")[0].split()
        if not s:
            if ids:
                break
            continue
        ids.append(int(s[0]))
        types.append(int(s[2]))
        xyz.append((float(s[4]), float(s[5]), float(s[6])))
    ids_a = np.array(ids, int)
    order = np.argsort(ids_a)
    return ids_a[order], np.array(types, int)[order], np.array(xyz, float).reshape(-1, 3)[order]


# ------------------------------------------------------------------------------------------------ read back

@dataclass(frozen=True)
class ReadBack:
    """What LAMMPS saw after ``read_data`` (and ``run 0``)."""
    natoms: int
    nbonds: int
    nangles: int
    ndihedrals: int
    total_charge: float                   #: e
    energies: Mapping[str, float]         #: kcal/mol: pe, ebond, eangle, edihed, evdwl, ecoul, elong
    box: tuple[float, ...]                #: xlo xhi ylo yhi zlo zhi (A)
    atom_type_counts: Mapping[int, int]
    pair_coeffs: tuple[str, ...]
    commands: tuple[str, ...] = field(default=())

    @property
    def finite(self) -> bool:
        return all(math.isfinite(v) for v in self.energies.values())


def _header(path: Path) -> dict[str, str]:
    first = path.open().readline()
    if _HEADER_TAG not in first:
        return {}
    return dict(re.findall(r"(\w+)=([^|]+?)\s*(?:\||$)", first))


def _forcefield_from_name(name: str) -> ForceField:
    parts = [p for p in name.split("+") if p]
    return load_forcefield(parts[0]) if len(parts) == 1 else combine(*parts)


#: soft core of ``pair="long/soft"``: (n, alpha_LJ, alpha_C in A^2) -- Beutler et al., Chem. Phys. Lett. 222 (1994)
#: 529 (n = 1, alpha = 0.5); alpha_C only matters for charged pairs at lambda < 1, which no workflow uses
SOFT_CORE = (1, 0.5, 10.0)


def lammps_setup_commands(forcefield: ForceField, data_path: str | Path, *, boundary: str = "p p f",
                          pair: str = "long", cutoff: float = 12.0, kspace_accuracy: float = 1e-5) -> list[str]:
    """Commands that define the styles, read the data file and set pair coefficients from ``forcefield``.

    ``pair="long"``: ``lj/cut/coul/long`` + ``pppm`` (``kspace_modify slab 3.0`` if z is not periodic);
    ``pair="long/soft"``: ``lj/cut/coul/long/soft`` with every pair's lambda = 1 (the same energies as "long" to
    the real-space table's precision; a free-energy run scales chosen pairs' lambda with ``fix adapt/fep``), soft
    core n = 1, alpha_LJ = 0.5, alpha_C = 10 A^2 (:data:`SOFT_CORE`); pairs with epsilon = 0 get sigma = 1 A there
    (sigma = 0 makes the soft-core form 0/0);
    ``pair="cut"``: ``lj/cut/coul/cut`` (quick check, no k-space).
    """
    cmds = ["units real", "atom_style full", f"boundary {boundary}"]
    for kind, terms in (("bond", forcefield.bond_types), ("angle", forcefield.angle_types),
                        ("dihedral", forcefield.dihedral_types)):
        style = style_of(terms)
        if style:
            cmds.append(f"{kind}_style {style}")
    if pair == "long":
        cmds.append(f"pair_style lj/cut/coul/long {cutoff:g}")
    elif pair == "long/soft":
        n, a_lj, a_c = SOFT_CORE
        cmds.append(f"pair_style lj/cut/coul/long/soft {n:g} {a_lj:g} {a_c:g} {cutoff:g}")
    elif pair == "cut":
        cmds.append(f"pair_style lj/cut/coul/cut {cutoff:g}")
    else:
        raise ValueError(f"pair must be 'long', 'long/soft' or 'cut', got {pair!r}")
    cmds.append(f"read_data {Path(data_path).as_posix()}")
    cmds += lammps_pair_coeffs(forcefield, soft_core=pair == "long/soft")
    cmds.append(forcefield.special_bonds.lammps())
    if pair in ("long", "long/soft"):
        cmds.append(f"kspace_style pppm {kspace_accuracy:g}")
        if boundary.split()[2] != "p":
            cmds.append("kspace_modify slab 3.0")
    return cmds


def read_back_check(path: str | Path, forcefield: ForceField | None = None, *, pair: str = "long",
                    cutoff: float = 12.0, kspace_accuracy: float = 1e-4, run0: bool = True) -> ReadBack:
    """Load a data file written by :func:`write_data` into LAMMPS (in process) and report what LAMMPS sees.

    The force field defaults to the one named in the file's first line (``combine`` of the '+'-joined names).
    Styles come from the force field; ``pair_coeff`` lines from :func:`md.system.forcefield.lammps_pair_coeffs`;
    ``special_bonds`` from the force field. With ``run0`` a ``run 0`` evaluates the energy terms.
    """
    from md.lammps_loader import new_lammps  # noqa: PLC0415  (LAMMPS only when asked for)

    path = Path(path)
    meta = _header(path)
    if forcefield is None:
        if "forcefield" not in meta:
            raise ValueError(f"{path}: no force-field name in the first line; pass forcefield=")
        forcefield = _forcefield_from_name(meta["forcefield"])
    boundary = meta.get("boundary", "p p f")
    cmds = lammps_setup_commands(forcefield, path, boundary=boundary, pair=pair, cutoff=cutoff,
                                 kspace_accuracy=kspace_accuracy)
    cmds += ["variable qtot equal charge(all)",
             "thermo_style custom step pe ebond eangle edihed evdwl ecoul elong",
             "thermo_modify norm no"]
    if run0:
        cmds.append("run 0")
    lmp = new_lammps()
    try:
        for c in cmds:
            lmp.command(c)
        energies = {}
        if run0:
            for key in ("pe", "ebond", "eangle", "edihed", "evdwl", "ecoul", "elong"):
                energies[key] = float(lmp.get_thermo(key))
        boxlo, boxhi, *_ = lmp.extract_box()
        ntypes = len(forcefield.atom_types)
        counts = {}
        types = np.asarray(lmp.numpy.extract_atom("type"))[: lmp.extract_global("nlocal")]
        for t in range(1, ntypes + 1):
            counts[t] = int(np.count_nonzero(types == t))
        return ReadBack(
            natoms=int(lmp.get_natoms()), nbonds=int(lmp.extract_global("nbonds")),
            nangles=int(lmp.extract_global("nangles")), ndihedrals=int(lmp.extract_global("ndihedrals")),
            total_charge=float(lmp.extract_variable("qtot")), energies=energies,
            box=(boxlo[0], boxhi[0], boxlo[1], boxhi[1], boxlo[2], boxhi[2]), atom_type_counts=counts,
            pair_coeffs=tuple(c for c in cmds if c.startswith("pair_coeff")), commands=tuple(cmds))
    finally:
        lmp.close()
