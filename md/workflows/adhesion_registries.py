"""Lateral registries of two slabs in contact: the slabs' own lateral lattice, offsets over its primitive cell, and
which offsets repeat another.

Two crystalline slabs held in one lateral register measure that register's work of adhesion, so the adhesion
workflow averages chains of windows started at several lateral offsets of the upper slab. An offset that is a
lattice translation of the slabs (or differs from another offset by one) is the same registry again. The
rectangular surface cell of a (111) face (a/sqrt(2) x a sqrt(6)/2 for cristobalite) is centred: it holds two
lattice points, and its centring vector is a translation of the slab. Accepted practice samples the offset over the
*primitive* cell with random or quasi-random points, lattice vectors excluded (e.g. Chandross et al., Phys. Rev.
Lett. 93 (2004) 166103, on commensurate against incommensurate alkylsilane contacts).

The lattice is found from the built slabs themselves: a lateral shift is a translation when it maps every heavy
atom onto an atom of the same type (periodic in x and y). Silanol hydrogens (``HOY``) are left out: their azimuths
are drawn per site by the builder and rotate freely at 300 K, so they do not define the registry.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

#: atom types left out of the lattice test (silanol H: thermal azimuths)
LATTICE_SKIP_TYPES = ("HOY",)
#: a shift maps the slab onto itself when every heavy atom lands within this distance (A) of one of its type
LATTICE_TOL_A = 0.05
#: quasi-random offsets closer than this (A, modulo the lattice) to an accepted one, or to a lattice point, are
#: skipped
MIN_REGISTRY_SPACING_A = 1.0
#: the R2 sequence's generator: the plastic number, the unique real root of x^3 = x + 1 (M. Roberts, "The
#: unreasonable effectiveness of quasirandom sequences", 2018); its offsets (k alpha + 1/2) mod 1 fill the unit
#: square with the lowest known dispersion of the additive recurrences
_PLASTIC = 1.324717957244746
_R2_ALPHA = np.array([1.0 / _PLASTIC, 1.0 / _PLASTIC ** 2])


def maps_onto_itself(positions: np.ndarray, types: np.ndarray, box_xy, shift_xy, tol: float = LATTICE_TOL_A,
                     skip: tuple[str, ...] = LATTICE_SKIP_TYPES) -> bool:
    """True when the lateral shift ``shift_xy`` (A) moves every atom whose type is not in ``skip`` onto an atom of
    its own type (within ``tol``), periodic in x and y with box ``box_xy``."""
    box = np.asarray(box_xy, float)[:2]
    pos = np.asarray(positions, float)
    types = np.asarray(types)
    z0 = pos[:, 2].min() if len(pos) else 0.0
    for ty in np.unique(types):
        if ty in skip:
            continue
        p = pos[types == ty]
        ref = np.column_stack([p[:, :2] % box, p[:, 2] - z0])
        tree = cKDTree(ref, boxsize=[box[0], box[1], 1e9])
        moved = np.column_stack([(p[:, :2] + np.asarray(shift_xy, float)) % box, p[:, 2] - z0])
        if tree.query(moved)[0].max() > tol:
            return False
    return True


def surface_lattice(slabs, box_xy, cell_xy) -> np.ndarray:
    """The lateral lattice shared by every slab of ``slabs`` ((positions, types) pairs in one box): rows are its
    basis vectors (A). Starts from the rectangular surface cell ``cell_xy`` (the whole box when the cell is not a
    translation of every slab, e.g. randomly placed silanols) and halves it where a slab's centring vector,
    (b1 + b2)/2, b1/2 or b2/2, maps every slab onto itself (the first that does)."""
    def ok(t) -> bool:
        return all(maps_onto_itself(p, ty, box_xy, t) for p, ty in slabs)

    cx, cy = float(cell_xy[0]), float(cell_xy[1])
    b1, b2 = np.array([cx, 0.0]), np.array([0.0, cy])
    if not (ok(b1) and ok(b2)):
        b1, b2 = np.array([float(box_xy[0]), 0.0]), np.array([0.0, float(box_xy[1])])
    for c, basis in (((b1 + b2) / 2, (b1, (b1 + b2) / 2)), (b1 / 2, (b1 / 2, b2)), (b2 / 2, (b1, b2 / 2))):
        if ok(c):
            return np.array(basis)
    return np.array([b1, b2])


def lattice_distance(offset, basis) -> float:
    """Distance (A) from ``offset`` to the nearest point of the lattice spanned by the rows of ``basis``."""
    basis = np.asarray(basis, float)
    frac = np.linalg.solve(basis.T, np.asarray(offset, float))
    base = np.floor(frac)
    best = math.inf
    for i in (0, 1):
        for j in (0, 1):
            d = (frac - base - (i, j)) @ basis
            best = min(best, float(np.hypot(*d)))
    return best


def is_lattice_translation(offset, basis, tol: float = LATTICE_TOL_A) -> bool:
    """``offset`` (A) is a translation of the lattice ``basis`` within ``tol``: it repeats the zero offset."""
    return lattice_distance(offset, basis) <= tol


def primitive_offsets(n: int, basis, min_spacing: float = MIN_REGISTRY_SPACING_A) -> list[tuple[float, float]]:
    """n lateral offsets (A) over the primitive cell of ``basis``: (0, 0) first (the contact leg's own registry),
    then the R2 quasi-random sequence (k alpha + 1/2) mod 1 in the cell's fractional coordinates, skipping points
    within ``min_spacing`` of a lattice point or of an offset already taken (modulo the lattice). Raises
    ValueError when the cell cannot hold n offsets that far apart."""
    basis = np.asarray(basis, float)
    out = [(0.0, 0.0)]
    k = 0
    while len(out) < n:
        k += 1
        if k > 10_000:
            raise ValueError(f"the primitive cell ({abs(np.linalg.det(basis)):.1f} A^2) cannot hold {n} registries "
                             f"{min_spacing:g} A apart")
        frac = (0.5 + k * _R2_ALPHA) % 1.0
        cand = frac @ basis
        if all(lattice_distance(cand - np.array(o), basis) >= min_spacing for o in out):
            out.append((round(float(cand[0]), 6), round(float(cand[1]), 6)))
    return out


def degenerate_registries(offsets, basis, tol: float = LATTICE_TOL_A) -> list[list[int]]:
    """[r, r0] for every offset r that repeats an earlier offset r0 (their difference is a lattice translation):
    registry r samples registry r0 again."""
    out = []
    for r in range(1, len(offsets)):
        for r0 in range(r):
            if is_lattice_translation(np.subtract(offsets[r], offsets[r0]), basis, tol):
                out.append([r, r0])
                break
    return out
