"""What the builders share: the Atoms-returning wrapper (:func:`atoms_builder`), the force fields they type with,
bonded-term geometry from a force field, and the sources they cite."""
from __future__ import annotations

import functools
from typing import Any, Callable, Mapping

import numpy as np

from md.system.atoms import to_atoms
from md.system.forcefield import ForceField, combine, load_forcefield
from md.system.topology import System


def atoms_builder(build_system: Callable[..., System]):
    """The public form of a builder: the same arguments, an :class:`ase.Atoms` back (:func:`md.system.atoms.to_atoms`:
    force-field types, molecule ids, charges and masses as arrays; bonds, angles, dihedrals and groups in
    ``info``). ``builder.system(...)`` is the same build as a :class:`md.system.topology.System` -- what the
    builders pass each other; :func:`md.system.atoms.from_atoms` turns the Atoms back into exactly that System."""
    @functools.wraps(build_system)
    def build(*args, **kwargs):
        return to_atoms(build_system(*args, **kwargs))
    build.system = build_system
    build.__annotations__ = {**build_system.__annotations__, "return": "ase.Atoms"}
    build.__doc__ = (build_system.__doc__ or "").rstrip() + (
        "\n\n    Returns an ``ase.Atoms``; ``.system(...)`` takes the same arguments and returns the "
        ":class:`md.system.topology.System`.\n    ")
    return build


SOURCES = {
    "cristobalite": "idealised beta-cristobalite Fd-3m, a = 7.16 A: R. W. G. Wyckoff, Z. Kristallogr. 62 (1925) 189; "
                    "AFLOW prototype A2B_cF24_227_c_a (M. J. Mehl et al., Comput. Mater. Sci. 136 (2017) S1)",
    "quartz": "alpha-quartz P3_221: L. Levien, C. T. Prewitt, D. J. Weidner, Am. Mineral. 65 (1980) 920",
    "silanol_density": "4.6-4.9 OH/nm^2 on fully hydroxylated amorphous silica: L. T. Zhuravlev, Colloids Surf. A "
                       "173 (2000) 1",
    "surface_models": "Q2/Q3 silica surface models: F. S. Emami et al., Chem. Mater. 26 (2014) 2647",
    "ots": "OTS monolayer ~2.5 nm thick, ~4.5-4.7 chains/nm^2: S. R. Wasserman et al., Langmuir 5 (1989) 1074",
}


# ================================================================================================ force fields

def silica_forcefield() -> ForceField:
    return load_forcefield("silica_interface")


def sam_forcefield() -> ForceField:
    return combine("silica_interface", "ots_trappe_ua")


def water_forcefield(model: str = "water_spce") -> ForceField:
    return load_forcefield(model)


def _bond_r0(ff: ForceField, a: str, b: str) -> float:
    for t in ff.bond_types:
        if tuple(t.types) in ((a, b), (b, a)):
            return float(t.coeffs[-1] if t.style == "harmonic" else t.coeffs[1])
    raise KeyError(f"no bond {a}-{b} in force field {ff.name!r}")


def _angle_theta0(ff: ForceField, a: str, b: str, c: str) -> float:
    for t in ff.angle_types:
        if tuple(t.types) in ((a, b, c), (c, b, a)):
            return float(t.coeffs[1])
    raise KeyError(f"no angle {a}-{b}-{c} in force field {ff.name!r}")


def _plain(obj: Any) -> Any:
    """numpy scalars/arrays inside an info dict -> plain Python (JSON-friendly)."""
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return type(obj)(_plain(v) for v in obj)
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)
