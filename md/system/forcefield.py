"""Force-field parameter sets (TOML in inputs/forcefields/) and their LAMMPS pair-coefficient table.

Units are LAMMPS ``real`` throughout: kcal/mol, angstrom, elementary charge, degrees, g/mol.

* :func:`load_forcefield` reads one parameter file, checks it (units, source notes, that the LAMMPS sigma
  matches the published size parameter, that bonded terms refer to known atom types) and returns a
  frozen :class:`ForceField`.
* :func:`combine` merges several families into one :class:`ForceField` whose pair table
  (``pair_coeff i j``) is explicit: every entry records the rule that produced it.
* :func:`lammps_pair_coeffs` writes that table as LAMMPS ``pair_coeff`` lines.

Nothing here needs LAMMPS.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Iterable, Mapping, Sequence

from md.units import KJ_PER_KCAL, R_KCAL_PER_MOL_K
from nanoimpact import data

#: The shipped force-field files (inputs/forcefields, installed as package data).
FORCEFIELD_DIR = data.shipped_root() / "forcefields"

TWO_TO_ONE_SIXTH = 2.0 ** (1.0 / 6.0)

SIGMA_TOLERANCE = 5e-4      # angstrom: stored sigma vs. sigma recomputed from the published value
EPSILON_REL_TOLERANCE = 1e-4

#: Combination rules for 12-6 Lennard-Jones cross terms. ``lorentz_berthelot`` is LAMMPS ``mix arithmetic``
#: (CHARMM, TraPPE); ``geometric`` is LAMMPS ``mix geometric`` (OPLS-AA).
MIXING_RULES = ("lorentz_berthelot", "geometric")
WILDCARD = "X"

_REQUIRED_UNITS = {"lammps_units": "real", "energy": "kcal/mol", "length": "angstrom", "charge": "e"}
_RADIUS_KINDS = ("sigma", "rmin", "rmin_half")
_EPSILON_UNITS = ("kcal/mol", "K", "kJ/mol")
_ARITY = {"bond": 2, "angle": 3, "dihedral": 4}
_STYLE_NCOEFFS = {("bond", "harmonic"): 2, ("angle", "harmonic"): 2, ("dihedral", "opls"): 4,
                  ("dihedral", "harmonic"): 3, ("dihedral", "charmm"): 4}


class ForceFieldError(ValueError):
    """A parameter file or a combination of files is inconsistent."""


# ----------------------------------------------------------------------------------------------------------------
# Conversions
# ----------------------------------------------------------------------------------------------------------------

def sigma_from_published(value: float, kind: str) -> float:
    """LAMMPS/12-6 sigma (A) from a published size parameter.

    ``sigma``: already sigma.  ``rmin``: position of the LJ minimum r0 = 2^(1/6) sigma (IFF papers' "sigma").
    ``rmin_half``: CHARMM's Rmin/2, so sigma = 2 (Rmin/2) / 2^(1/6).
    """
    if kind == "sigma":
        return float(value)
    if kind == "rmin":
        return float(value) / TWO_TO_ONE_SIXTH
    if kind == "rmin_half":
        return 2.0 * float(value) / TWO_TO_ONE_SIXTH
    raise ForceFieldError(f"unknown published_radius_kind {kind!r}; expected one of {_RADIUS_KINDS}")


def epsilon_from_published(value: float, unit: str) -> float:
    """Well depth in kcal/mol from a published value in kcal/mol, K (eps/k_B) or kJ/mol."""
    if unit == "kcal/mol":
        return float(value)
    if unit == "K":
        return float(value) * R_KCAL_PER_MOL_K
    if unit == "kJ/mol":
        return float(value) / KJ_PER_KCAL
    raise ForceFieldError(f"unknown published_epsilon_unit {unit!r}; expected one of {_EPSILON_UNITS}")


def mix(eps_i: float, sigma_i: float, eps_j: float, sigma_j: float, rule: str) -> tuple[float, float]:
    """(epsilon_ij, sigma_ij) by the named combination rule."""
    if rule == "lorentz_berthelot":
        return math.sqrt(eps_i * eps_j), 0.5 * (sigma_i + sigma_j)
    if rule == "geometric":
        return math.sqrt(eps_i * eps_j), math.sqrt(sigma_i * sigma_j)
    raise ForceFieldError(f"unknown mixing rule {rule!r}; expected one of {MIXING_RULES}")


# ----------------------------------------------------------------------------------------------------------------
# Data classes
# ----------------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class AtomType:
    name: str
    element: str
    mass: float                      # g/mol
    charge: float                    # e
    epsilon: float                   # kcal/mol (LAMMPS value)
    sigma: float                     # angstrom (LAMMPS value)
    source_note: str
    family: str = ""
    published_epsilon: float | None = None
    published_epsilon_unit: str = "kcal/mol"
    published_radius: float | None = None
    published_radius_kind: str = "sigma"
    charge_derivation: str = ""


@dataclass(frozen=True)
class BondType:
    name: str
    types: tuple[str, str]
    style: str
    coeffs: tuple[float, ...]        # LAMMPS order (harmonic: K kcal/mol/A^2, r0 A; E = K (r - r0)^2)
    source_note: str
    constraint: str = ""             # "shake" when the bond is rigid
    family: str = ""


@dataclass(frozen=True)
class AngleType:
    name: str
    types: tuple[str, str, str]
    style: str
    coeffs: tuple[float, ...]        # LAMMPS order (harmonic: K kcal/mol/rad^2, theta0 deg)
    source_note: str
    constraint: str = ""
    family: str = ""


@dataclass(frozen=True)
class DihedralType:
    name: str
    types: tuple[str, str, str, str]  # "X" is a wildcard
    style: str
    coeffs: tuple[float, ...]        # LAMMPS order (opls: K1 K2 K3 K4 kcal/mol)
    source_note: str
    family: str = ""


@dataclass(frozen=True)
class PairCoeff:
    """One ``pair_coeff i j`` entry. ``rule`` is "self" for i == j, else the combination rule or "explicit"."""
    type_i: str
    type_j: str
    epsilon: float
    sigma: float
    rule: str
    note: str = ""


@dataclass(frozen=True)
class SpecialBonds:
    lj: tuple[float, float, float]       # LAMMPS special_bonds factors for 1-2, 1-3, 1-4 pairs
    coul: tuple[float, float, float]
    note: str = ""
    has_14_pairs: bool = True            # False for rigid 3/4-site water: its 1-4 factor is irrelevant

    def lammps(self) -> str:
        f = " ".join
        return (f"special_bonds lj {f(format(x, 'g') for x in self.lj)} "
                f"coul {f(format(x, 'g') for x in self.coul)}")


@dataclass(frozen=True)
class ChargeGroup:
    """A neutral unit (molecule, or a surface/graft unit with shared bridging atoms counted fractionally)."""
    name: str
    composition: tuple[tuple[str, float], ...]
    note: str = ""
    family: str = ""


@dataclass(frozen=True)
class ForceField:
    name: str
    families: tuple[str, ...]
    sources: tuple[Mapping[str, Any], ...]
    units: Mapping[str, Any]
    mixing_rule: str
    special_bonds: SpecialBonds
    atom_types: tuple[AtomType, ...]
    bond_types: tuple[BondType, ...] = ()
    angle_types: tuple[AngleType, ...] = ()
    dihedral_types: tuple[DihedralType, ...] = ()
    pair_coeffs: tuple[PairCoeff, ...] = ()
    charge_groups: tuple[ChargeGroup, ...] = ()
    requires: tuple[str, ...] = ()
    pair_overrides: tuple[PairCoeff, ...] = ()   # explicit entries declared by the files (rule "explicit")
    notes: tuple[str, ...] = ()
    extras: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    # -- look-ups --------------------------------------------------------------------------------------------
    def atom_type(self, name: str) -> AtomType:
        for t in self.atom_types:
            if t.name == name:
                return t
        raise KeyError(f"no atom type {name!r} in force field {self.name!r}")

    @property
    def type_names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.atom_types)

    def pair(self, a: str, b: str) -> PairCoeff:
        for p in self.pair_coeffs:
            if (p.type_i, p.type_j) in ((a, b), (b, a)):
                return p
        raise KeyError(f"no pair coefficient {a}-{b} in force field {self.name!r}")

    def total_charge(self, composition: Mapping[str, float] | Iterable[tuple[str, float]]) -> float:
        items = composition.items() if isinstance(composition, Mapping) else composition
        return math.fsum(self.atom_type(name).charge * count for name, count in items)


# ----------------------------------------------------------------------------------------------------------------
# Loading
# ----------------------------------------------------------------------------------------------------------------

def _resolve(name_or_path: str | Path, search_dir: Path | None) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" and p.exists():
        return p
    d = Path(search_dir) if search_dir is not None else FORCEFIELD_DIR
    cand = d / (p.name if p.suffix == ".toml" else f"{p.name}.toml")
    if cand.exists():
        return cand
    raise FileNotFoundError(f"force field {name_or_path!r} not found (looked for {p} and {cand})")


def _require(table: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in table:
        raise ForceFieldError(f"{where}: missing key {key!r}")
    return table[key]


def _note(table: Mapping[str, Any], where: str) -> str:
    note = str(table.get("source_note", "")).strip()
    if not note:
        raise ForceFieldError(f"{where}: every entry needs a non-empty source_note")
    return note


def _freeze(obj: Any) -> Any:
    if isinstance(obj, Mapping):
        return MappingProxyType({k: _freeze(v) for k, v in obj.items()})
    if isinstance(obj, list):
        return tuple(_freeze(v) for v in obj)
    return obj


def _parse_atom(d: Mapping[str, Any], family: str, where: str) -> AtomType:
    name = str(_require(d, "name", where))
    where = f"{where} atom type {name}"
    at = AtomType(
        name=name,
        element=str(_require(d, "element", where)),
        mass=float(_require(d, "mass", where)),
        charge=float(_require(d, "charge", where)),
        epsilon=float(_require(d, "epsilon", where)),
        sigma=float(_require(d, "sigma", where)),
        source_note=_note(d, where),
        family=family,
        published_epsilon=None if d.get("published_epsilon") is None else float(d["published_epsilon"]),
        published_epsilon_unit=str(d.get("published_epsilon_unit", "kcal/mol")),
        published_radius=None if d.get("published_radius") is None else float(d["published_radius"]),
        published_radius_kind=str(d.get("published_radius_kind", "sigma")),
        charge_derivation=str(d.get("charge_derivation", "")),
    )
    if at.mass <= 0 or at.epsilon < 0 or at.sigma < 0:
        raise ForceFieldError(f"{where}: mass must be > 0, epsilon and sigma >= 0")
    if at.published_radius is not None:
        expect = sigma_from_published(at.published_radius, at.published_radius_kind)
        if abs(expect - at.sigma) > SIGMA_TOLERANCE:
            raise ForceFieldError(f"{where}: sigma {at.sigma} disagrees with published {at.published_radius_kind} "
                                  f"{at.published_radius} -> {expect:.5f} A")
    if at.published_epsilon is not None:
        expect = epsilon_from_published(at.published_epsilon, at.published_epsilon_unit)
        if (abs(expect - at.epsilon) > EPSILON_REL_TOLERANCE * max(abs(expect), 1e-12)
                and abs(expect - at.epsilon) > 1e-9):
            raise ForceFieldError(f"{where}: epsilon {at.epsilon} disagrees with published {at.published_epsilon} "
                                  f"{at.published_epsilon_unit} -> {expect:.6f} kcal/mol")
    return at


def _parse_bonded(kind: str, d: Mapping[str, Any], family: str, where: str):
    name = str(_require(d, "name", where))
    where = f"{where} {kind} type {name}"
    types = tuple(str(t) for t in _require(d, "types", where))
    if len(types) != _ARITY[kind]:
        raise ForceFieldError(f"{where}: needs {_ARITY[kind]} atom types, got {types}")
    style = str(_require(d, "style", where))
    coeffs = tuple(float(c) for c in _require(d, "coeffs", where))
    n = _STYLE_NCOEFFS.get((kind, style))
    if n is not None and len(coeffs) != n:
        raise ForceFieldError(f"{where}: {kind}_style {style} takes {n} coefficients, got {len(coeffs)}")
    note = _note(d, where)
    if kind == "bond":
        return BondType(name, types, style, coeffs, note, str(d.get("constraint", "")), family)
    if kind == "angle":
        return AngleType(name, types, style, coeffs, note, str(d.get("constraint", "")), family)
    return DihedralType(name, types, style, coeffs, note, family)


def _bonded_type_names(ff_or_lists) -> set[str]:
    names: set[str] = set()
    for group in ff_or_lists:
        for t in group:
            names.update(t.types)
    names.discard(WILDCARD)
    return names


def load_forcefield(name_or_path: str | Path, *, search_dir: Path | None = None) -> ForceField:
    """Load ``inputs/forcefields/<name>.toml`` (or a path) into a checked, frozen :class:`ForceField`.

    The returned object already carries a pair table built with the file's own mixing rule.
    Files listing ``requires`` (e.g. the OTS head group uses the silica O/H types) are checked against the
    atom types of the required files, which are looked up in the same directory.
    """
    path = _resolve(name_or_path, search_dir)
    with path.open("rb") as fh:
        raw = tomllib.load(fh)
    where = path.name

    source = _require(raw, "source", where)
    for key in ("name", "citation", "doi"):
        if not str(source.get(key, "")).strip():
            raise ForceFieldError(f"{where}: [source] needs a non-empty {key!r}")
    if not (str(source.get("table", "")).strip() or str(source.get("file", "")).strip()):
        raise ForceFieldError(f"{where}: [source] needs 'table' or 'file'")
    name = str(source["name"])
    family = str(source.get("family", name))

    units = _require(raw, "units", where)
    for key, val in _REQUIRED_UNITS.items():
        if units.get(key) != val:
            raise ForceFieldError(f"{where}: [units] {key} must be {val!r}, got {units.get(key)!r}")

    mixing = _require(raw, "mixing", where)
    rule = str(_require(mixing, "rule", f"{where} [mixing]"))
    if rule not in MIXING_RULES:
        raise ForceFieldError(f"{where}: unknown mixing rule {rule!r}")

    sb = _require(raw, "special_bonds", where)
    special = SpecialBonds(tuple(float(x) for x in sb["lj"]), tuple(float(x) for x in sb["coul"]),
                           str(sb.get("note", "")), bool(sb.get("has_14_pairs", True)))
    if len(special.lj) != 3 or len(special.coul) != 3:
        raise ForceFieldError(f"{where}: special_bonds lj/coul need three factors (1-2, 1-3, 1-4)")

    atoms = tuple(_parse_atom(d, family, where) for d in raw.get("atom_types", []))
    if not atoms:
        raise ForceFieldError(f"{where}: no atom types")
    names = [a.name for a in atoms]
    if len(set(names)) != len(names):
        raise ForceFieldError(f"{where}: duplicate atom type names")
    if WILDCARD in names:
        raise ForceFieldError(f"{where}: {WILDCARD!r} is reserved as the dihedral wildcard")

    bonds = tuple(_parse_bonded("bond", d, family, where) for d in raw.get("bond_types", []))
    angles = tuple(_parse_bonded("angle", d, family, where) for d in raw.get("angle_types", []))
    dihedrals = tuple(_parse_bonded("dihedral", d, family, where) for d in raw.get("dihedral_types", []))

    requires = tuple(str(r) for r in source.get("requires", []))
    known = set(names)
    for req in requires:
        known.update(load_forcefield(req, search_dir=path.parent).type_names)
    missing = _bonded_type_names((bonds, angles, dihedrals)) - known
    if missing:
        raise ForceFieldError(f"{where}: bonded terms use undefined atom types {sorted(missing)} "
                              f"(define them or list their file in [source] requires)")

    groups = []
    for g in raw.get("charge_groups", []):
        comp = tuple((str(k), float(v)) for k, v in _require(g, "composition", f"{where} charge group").items())
        unknown = {k for k, _ in comp} - known
        if unknown:
            raise ForceFieldError(f"{where}: charge group {g.get('name')!r} uses unknown types {sorted(unknown)}")
        groups.append(ChargeGroup(str(_require(g, "name", where)), comp, str(g.get("note", "")), family))

    extras = {k: v for k, v in raw.items() if k not in
              {"source", "units", "mixing", "special_bonds", "atom_types", "bond_types", "angle_types",
               "dihedral_types", "charge_groups", "pair_overrides"}}
    extras["mixing"] = mixing
    explicit = tuple(_parse_override(o, where) for o in raw.get("pair_overrides", []))

    ff = ForceField(name=name, families=(family,), sources=(_freeze(dict(source)),), units=_freeze(dict(units)),
                    mixing_rule=rule, special_bonds=special, atom_types=atoms, bond_types=bonds,
                    angle_types=angles, dihedral_types=dihedrals, charge_groups=tuple(groups),
                    requires=requires, pair_overrides=explicit, extras=_freeze(extras))
    return _with_pair_table(ff, rule, explicit)


def _parse_override(o: Mapping[str, Any], where: str) -> PairCoeff:
    types = tuple(_require(o, "types", f"{where} pair_override"))
    if len(types) != 2:
        raise ForceFieldError(f"{where}: pair_override needs two types")
    return PairCoeff(str(types[0]), str(types[1]), float(_require(o, "epsilon", where)),
                     float(_require(o, "sigma", where)), "explicit", _note(o, f"{where} pair_override"))


# ----------------------------------------------------------------------------------------------------------------
# Pair table and combination
# ----------------------------------------------------------------------------------------------------------------

def _with_pair_table(ff: ForceField, rule: str, explicit: Sequence[PairCoeff] = ()) -> ForceField:
    atoms = ff.atom_types
    index = {a.name: k for k, a in enumerate(atoms)}
    table: dict[tuple[int, int], PairCoeff] = {}
    for i, a in enumerate(atoms):
        for j in range(i, len(atoms)):
            b = atoms[j]
            if i == j:
                table[(i, j)] = PairCoeff(a.name, a.name, a.epsilon, a.sigma, "self", a.family)
            else:
                eps, sig = mix(a.epsilon, a.sigma, b.epsilon, b.sigma, rule)
                table[(i, j)] = PairCoeff(a.name, b.name, eps, sig, rule,
                                          f"{a.family} x {b.family}" if a.family != b.family else a.family)
    for o in explicit:
        if o.type_i not in index or o.type_j not in index:
            continue  # override for a type that is not (yet) present: kept for a later combine
        i, j = sorted((index[o.type_i], index[o.type_j]))
        table[(i, j)] = PairCoeff(atoms[i].name, atoms[j].name, o.epsilon, o.sigma, "explicit", o.note)
    pairs = tuple(table[k] for k in sorted(table))
    return ForceField(**{**ff.__dict__, "pair_coeffs": pairs, "mixing_rule": rule})


def _canonical(types: tuple[str, ...]) -> tuple[str, ...]:
    return min(types, tuple(reversed(types)))


def _merge_unique(kind: str, lists: Iterable[Sequence[Any]], key) -> tuple[Any, ...]:
    out: dict[Any, Any] = {}
    for seq in lists:
        for item in seq:
            k = key(item)
            if k in out:
                prev = out[k]
                if (prev.style, prev.coeffs) != (item.style, item.coeffs):
                    raise ForceFieldError(f"conflicting {kind} parameters for {k}: {prev.coeffs} vs {item.coeffs}")
                continue
            out[k] = item
    return tuple(out.values())


def _resolve_special(ffs: Sequence[ForceField], special_bonds: SpecialBonds | None) -> tuple[SpecialBonds, list[str]]:
    """One global special_bonds setting for the combined system (LAMMPS has only one).

    Families without 1-4 pairs (rigid water) do not vote. If the remaining families agree, that setting is
    used. Otherwise: LJ factors = element-wise minimum (never switch on a 1-4 LJ term that a family
    excludes), Coulomb factors = element-wise maximum (keep a 1-4 Coulomb term that a family needs). The
    choice and its consequence are recorded in ``notes``; pass ``special_bonds`` to override.
    """
    if special_bonds is not None:
        return special_bonds, ["special_bonds set explicitly by the caller"]
    voters = [f for f in ffs if f.special_bonds.has_14_pairs] or list(ffs)
    settings = {(f.special_bonds.lj, f.special_bonds.coul) for f in voters}
    if len(settings) == 1:
        sb = voters[0].special_bonds
        return SpecialBonds(sb.lj, sb.coul, sb.note, any(f.special_bonds.has_14_pairs for f in ffs)), []
    lj = tuple(min(f.special_bonds.lj[k] for f in voters) for k in range(3))
    coul = tuple(max(f.special_bonds.coul[k] for f in voters) for k in range(3))
    per = "; ".join(f"{f.name}: lj {f.special_bonds.lj} coul {f.special_bonds.coul}" for f in voters)
    dropped = [f.name for f in voters if f.special_bonds.lj != lj]
    raised = [f.name for f in voters if f.special_bonds.coul != coul]
    note = (f"special_bonds differ between families ({per}); resolved to lj {lj} coul {coul} "
            "(LJ: element-wise minimum, Coulomb: element-wise maximum). "
            + (f"1-4 LJ that {dropped} include is dropped. " if dropped else "")
            + (f"1-4 Coulomb that {raised} exclude is switched on: only acceptable if their 1-4 partners "
               "are uncharged or the pair is of the other family's kind. " if raised else "")
            + "See inputs/forcefields/README.md.")
    return SpecialBonds(lj, coul, "resolved by combine(); see notes", True), [note]


def combine(*forcefields: ForceField | str | Path, rule: str | None = None,
            overrides: Iterable[PairCoeff | tuple[str, str, float, float, str]] = (),
            special_bonds: SpecialBonds | None = None, name: str | None = None) -> ForceField:
    """Merge force-field families into one with an explicit pair table.

    ``rule``: combination rule for every unlike pair not overridden. If None, all families must declare the
    same rule (IFF-CHARMM, TraPPE and the water models here all declare ``lorentz_berthelot``); a mixture
    (e.g. with OPLS-AA, geometric) raises unless ``rule`` is given, and the choice is recorded on each pair.
    ``overrides``: explicit (type_i, type_j, epsilon, sigma, note) entries; recorded with rule "explicit".
    Atom types with the same name must be identical across families; so must duplicated bonded types.
    """
    ffs = [f if isinstance(f, ForceField) else load_forcefield(f) for f in forcefields]
    if not ffs:
        raise ForceFieldError("combine() needs at least one force field")
    for f in ffs:
        for key, val in _REQUIRED_UNITS.items():
            if f.units.get(key) != val:
                raise ForceFieldError(f"{f.name}: units {key}={f.units.get(key)!r}, expected {val!r}")

    rule, notes = _combined_rule(ffs, rule)
    atoms = _merged_atom_types(ffs)

    bonds = _merge_unique("bond", (f.bond_types for f in ffs), lambda t: (_canonical(t.types), t.style))
    angles = _merge_unique("angle", (f.angle_types for f in ffs), lambda t: (_canonical(t.types), t.style))
    dihedrals = _merge_unique("dihedral", (f.dihedral_types for f in ffs), lambda t: (_canonical(t.types), t.style))

    missing = _bonded_type_names((bonds, angles, dihedrals)) - set(atoms)
    if missing:
        needed = sorted({r for f in ffs for r in f.requires} - {f.name for f in ffs})
        raise ForceFieldError(f"bonded terms use atom types {sorted(missing)} that no combined family defines"
                              + (f"; also combine {needed}" if needed else ""))

    special, sb_notes = _resolve_special(ffs, special_bonds)
    notes.extend(sb_notes)

    explicit = _explicit_overrides(overrides, atoms)
    file_overrides = [o for f in ffs for o in f.pair_overrides]
    explicit = file_overrides + explicit  # caller's overrides win (applied last)

    extras = {f.name: f.extras for f in ffs}
    ff = ForceField(
        name=name or "+".join(f.name for f in ffs),
        families=tuple(fam for f in ffs for fam in f.families),
        sources=tuple(s for f in ffs for s in f.sources),
        units=ffs[0].units, mixing_rule=rule, special_bonds=special, atom_types=tuple(atoms.values()),
        bond_types=bonds, angle_types=angles, dihedral_types=dihedrals,
        charge_groups=tuple(g for f in ffs for g in f.charge_groups),
        requires=tuple(sorted({r for f in ffs for r in f.requires} - {f.name for f in ffs})),
        pair_overrides=tuple(explicit),
        notes=tuple(n for f in ffs for n in f.notes) + tuple(notes), extras=MappingProxyType(extras))
    return _with_pair_table(ff, rule, explicit)


def _combined_rule(ffs: Sequence[ForceField], rule: str | None) -> tuple[str, list[str]]:
    """The mixing rule of the combination (the families' common one, or ``rule``) and a note where ``rule``
    overrides a family's own."""
    rules = {f.mixing_rule for f in ffs}
    notes: list[str] = []
    if rule is None:
        if len(rules) != 1:
            raise ForceFieldError(f"families declare different mixing rules {sorted(rules)}; pass rule=...")
        rule = rules.pop()
    elif rule not in MIXING_RULES:
        raise ForceFieldError(f"unknown mixing rule {rule!r}")
    else:
        differing = [f.name for f in ffs if f.mixing_rule != rule]
        if differing:
            notes.append(f"rule {rule!r} applied to cross terms although {differing} declare another rule "
                         "(their own like-pair parameters are kept)")
    return rule, notes


def _merged_atom_types(ffs: Sequence[ForceField]) -> dict[str, AtomType]:
    """Every family's atom types by name; a name defined differently in two families raises."""
    atoms: dict[str, AtomType] = {}
    for f in ffs:
        for a in f.atom_types:
            if a.name in atoms:
                b = atoms[a.name]
                if (b.mass, b.charge, b.epsilon, b.sigma) != (a.mass, a.charge, a.epsilon, a.sigma):
                    raise ForceFieldError(f"atom type {a.name!r} defined differently in {b.family!r} and {a.family!r}")
                continue
            atoms[a.name] = a
    return atoms


def _explicit_overrides(overrides, atoms: Mapping[str, AtomType]) -> list[PairCoeff]:
    """The caller's pair overrides as PairCoeff with rule 'explicit'; each needs a source note and known types."""
    explicit: list[PairCoeff] = []
    for o in overrides:
        if isinstance(o, PairCoeff):
            explicit.append(PairCoeff(o.type_i, o.type_j, o.epsilon, o.sigma, "explicit", o.note))
        else:
            ti, tj, eps, sig, note = o
            if not str(note).strip():
                raise ForceFieldError(f"override {ti}-{tj} needs a source note")
            explicit.append(PairCoeff(ti, tj, float(eps), float(sig), "explicit", str(note)))
    for o in explicit:
        if o.type_i not in atoms or o.type_j not in atoms:
            raise ForceFieldError(f"override {o.type_i}-{o.type_j}: unknown atom type")
    return explicit


# ----------------------------------------------------------------------------------------------------------------
# LAMMPS text
# ----------------------------------------------------------------------------------------------------------------

def lammps_type_ids(ff: ForceField) -> dict[str, int]:
    """Default LAMMPS atom-type numbering: order of ``ff.atom_types``, starting at 1."""
    return {a.name: k + 1 for k, a in enumerate(ff.atom_types)}


def lammps_pair_coeffs(ff: ForceField, type_ids: Mapping[str, int] | None = None, *,
                       substyle: str | None = None, comments: bool = True, soft_core: bool = False) -> list[str]:
    """``pair_coeff I J eps sigma`` lines (I <= J) for every pair of atom types in ``type_ids``.

    ``type_ids`` maps atom-type name -> LAMMPS type number (default :func:`lammps_type_ids`); types not in
    it are skipped. ``substyle`` inserts a pair sub-style name (for ``pair_style hybrid``). The same two
    coefficients serve lj/cut, lj/cut/coul/long, lj/charmm/coul/long and lj/cut/tip4p/long. ``soft_core`` adds
    lambda = 1 for the soft-core styles (``lj/cut/coul/long/soft``) and gives sigma = 1 A to the pairs with
    epsilon = sigma = 0 (the soft-core form is 0/0 there; epsilon = 0 keeps them without LJ).
    """
    ids = dict(type_ids) if type_ids is not None else lammps_type_ids(ff)
    for n in ids:
        ff.atom_type(n)  # raises on an unknown name
    lines: list[tuple[int, int, str]] = []
    for p in ff.pair_coeffs:
        if p.type_i not in ids or p.type_j not in ids:
            continue
        i, j = ids[p.type_i], ids[p.type_j]
        ti, tj = p.type_i, p.type_j
        if i > j:
            i, j, ti, tj = j, i, tj, ti
        style = f" {substyle}" if substyle else ""
        sigma = 1.0 if soft_core and p.epsilon == 0.0 and p.sigma == 0.0 else p.sigma
        text = f"pair_coeff {i} {j}{style} {p.epsilon:.6f} {sigma:.6f}" + (" 1.0" if soft_core else "")
        if comments:
            text += f"  # {ti}-{tj} {p.rule}"
        lines.append((i, j, text))
    return [t for _, _, t in sorted(lines)]


def _coeff_lines(command: str, terms: Sequence[Any]) -> list[str]:
    styles = {t.style for t in terms}
    hybrid = len(styles) > 1
    out = []
    for k, t in enumerate(terms, start=1):
        style = f" {t.style}" if hybrid else ""
        coeffs = " ".join(format(c, "g") for c in t.coeffs)
        if command == "dihedral_coeff" and t.style == "harmonic":  # K d n: d and n are integers
            coeffs = f"{t.coeffs[0]:g} {int(t.coeffs[1])} {int(t.coeffs[2])}"
        out.append(f"{command} {k}{style} {coeffs}  # {t.name}")
    return out


def lammps_bond_coeffs(ff: ForceField) -> list[str]:
    """``bond_coeff`` lines, numbered in the order of ``ff.bond_types`` (sub-style names added if mixed)."""
    return _coeff_lines("bond_coeff", ff.bond_types)


def lammps_angle_coeffs(ff: ForceField) -> list[str]:
    return _coeff_lines("angle_coeff", ff.angle_types)


def lammps_dihedral_coeffs(ff: ForceField) -> list[str]:
    return _coeff_lines("dihedral_coeff", ff.dihedral_types)


def available_forcefields(search_dir: Path | None = None) -> list[str]:
    d = Path(search_dir) if search_dir is not None else FORCEFIELD_DIR
    return sorted(p.stem for p in d.glob("*.toml"))
