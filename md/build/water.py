"""Water films, cylinders and caps (:func:`water_slab`, :func:`water_cylinder`, :func:`water_cap`).

Water (``water_spce.toml``): SPC/E molecules (geometry from the force field: O-H 1.0 A, H-O-H 109.47 deg) on a
lattice at 0.997 g/cm^3 with random orientations.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Sequence

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from md.build.common import _angle_theta0, _bond_r0, _plain, atoms_builder, water_forcefield
from md.system.forcefield import ForceField
from md.system.topology import System, from_types, minimum_image, with_bonded_terms
from md.units import AVOGADRO, WATER_DENSITY

# ================================================================================================ water

def _water_geometry(ff: ForceField) -> tuple[str, str, np.ndarray]:
    """(O type, H type, (3, 3) molecule-frame positions O, H1, H2) of the rigid 3-site model in ``ff``."""
    o = next(t for t in ff.atom_types if t.element == "O" and t.name.startswith("OW"))
    h = next(t for t in ff.atom_types if t.element == "H" and t.name.startswith("HW"))
    r = _bond_r0(ff, o.name, h.name)
    half = math.radians(_angle_theta0(ff, h.name, o.name, h.name)) / 2.0
    frame = np.array([[0, 0, 0], [r * math.sin(half), 0, r * math.cos(half)],
                      [-r * math.sin(half), 0, r * math.cos(half)]], float)
    return o.name, h.name, frame


def _number_density(ff: ForceField, density: float) -> tuple[float, float]:
    """(molecules per A^3, g/mol per molecule) at ``density`` g/cm^3."""
    o_name, h_name, _ = _water_geometry(ff)
    m = ff.atom_type(o_name).mass + 2 * ff.atom_type(h_name).mass
    return density * AVOGADRO / m * 1e-24, m


def _place_waters(sites: np.ndarray, cell: np.ndarray, pbc: Sequence[bool], ff: ForceField,
                  rng: np.random.Generator, min_dist: float = 1.7, tries: int = 24) -> np.ndarray:
    """Positions (3N, 3) of waters with O on ``sites`` and random orientations, redrawn (up to ``tries``)
    while any intermolecular distance to an already placed molecule is below ``min_dist`` (A)."""
    _, _, frame = _water_geometry(ff)
    n = len(sites)
    lo = sites.min(axis=0) - 5.0
    box = np.where(pbc, cell, np.ptp(sites, axis=0) + 1e4)
    wrapped = sites - np.where(pbc, 0.0, lo)
    wrapped = np.where(pbc, np.mod(wrapped, cell), wrapped)
    tree = cKDTree(wrapped, boxsize=box)
    neigh = tree.query_ball_point(wrapped, r=4.5)
    out = np.zeros((n, 3, 3))
    placed = np.zeros(n, bool)
    pbc_t = tuple(bool(x) for x in pbc)
    for i in range(n):
        rots = Rotation.random(tries, random_state=rng).as_matrix()        # (tries, 3, 3)
        cand = sites[i] + np.einsum("tab,kb->tka", rots, frame)           # (tries, 3 atoms, 3)
        others = [j for j in neigh[i] if placed[j]]
        if not others:
            out[i] = cand[0]
        else:
            other = out[others].reshape(-1, 3)                            # (m, 3)
            d = minimum_image(cand[:, :, None, :] - other[None, None, :, :], cell, pbc_t)
            dmin = np.linalg.norm(d, axis=-1).reshape(tries, -1).min(axis=1)
            ok = np.flatnonzero(dmin >= min_dist)
            out[i] = cand[ok[0]] if len(ok) else cand[int(np.argmax(dmin))]
        placed[i] = True
    return out.reshape(-1, 3)


def _water_system(sites: np.ndarray, cell: np.ndarray, ff: ForceField, rng, info: dict) -> System:
    o_name, h_name, _ = _water_geometry(ff)
    pos = _place_waters(sites, cell, (True, True, False), ff, rng)
    n = len(sites)
    types = [o_name, h_name, h_name] * n
    mol = np.repeat(np.arange(1, n + 1), 3)
    bonds = [(3 * k, 3 * k + j) for k in range(n) for j in (1, 2)]
    s = from_types(pos, types, ff, mol_ids=mol, cell=cell, pbc=(True, True, False), bonds=bonds,
                   groups={"water": np.arange(3 * n), "water_O": np.arange(0, 3 * n, 3)})
    s = with_bonded_terms(s, ff)
    info = {**info, "n_molecules": n, "n_atoms": s.n_atoms, "counts": s.type_counts(),
            "total_charge": s.total_charge(), "model": ff.name, "seed": info.get("seed")}
    return replace(s, info=_plain(info))


@atoms_builder
def water_slab(lx: float = 20.0, ly: float = 20.0, thickness: float = 30.0, *, density: float = WATER_DENSITY,
               vacuum: float = 15.0, seed: int = 0, forcefield: ForceField | None = None) -> System:
    """A water film periodic in x, y (box ``lx`` x ``ly`` A), ``thickness`` A thick, centred in z with
    ``vacuum`` above and below (for gamma_lv and density profiles, or to put on a substrate).

    N = round(rho V N_A / M) molecules fill the film at ``density`` g/cm^3: O on a rectangular lattice
    (spacing ~3.1 A, commensurate with lx, ly) with the surplus sites removed at random; orientations random
    (seeded), redrawn to keep intermolecular distances >= 1.7 A where possible.
    """
    ff = forcefield or water_forcefield()
    rng = np.random.default_rng(seed)
    rho_n, m = _number_density(ff, density)
    n = int(round(rho_n * lx * ly * thickness))
    s0 = rho_n ** (-1.0 / 3.0)
    nx, ny = max(1, round(lx / s0)), max(1, round(ly / s0))
    nz = int(math.ceil(n / (nx * ny)))
    dx, dy, dz = lx / nx, ly / ny, thickness / nz
    g = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"), -1).reshape(-1, 3)
    keep = np.sort(rng.choice(len(g), size=n, replace=False))
    sites = (g[keep] + 0.5) * [dx, dy, dz] + [0.0, 0.0, vacuum]
    cell = np.array([lx, ly, thickness + 2 * vacuum])
    info = {"builder": "water_slab", "thickness_A": thickness, "area_nm2": lx * ly / 100.0,
            "density_g_cm3": n * m / AVOGADRO / (lx * ly * thickness * 1e-24), "density_requested_g_cm3": density,
            "lattice": (nx, ny, nz), "lattice_spacing_A": (dx, dy, dz), "z_range_A": (vacuum, vacuum + thickness),
            "periodic_axes": "xy", "seed": seed}
    return _water_system(sites, cell, ff, rng, info)


@atoms_builder
def water_cylinder(radius: float = 11.0, length: float = 20.0, *, box_x: float | None = None,
                   density: float = WATER_DENSITY, vacuum: float = 15.0, seed: int = 0,
                   forcefield: ForceField | None = None) -> System:
    """A quasi-2-D droplet: a water cylinder of ``radius`` (A) with its axis along y, periodic along y with
    period ``length`` (A, the box y length), circular cross-section in x-z.

    Molecules sit on a lattice: ny = round(length / 3.1) planes along y; in x-z a square grid whose cell area
    times the y spacing is one molecular volume at ``density``; the grid columns nearest the axis are filled
    first until N = round(rho pi R^2 L N_A / M). Box: x = ``box_x`` (default 2R + 2 vacuum), z = 2R + 2 vacuum,
    axis at (box_x/2, vacuum + R).
    """
    ff = forcefield or water_forcefield()
    rng = np.random.default_rng(seed)
    rho_n, m = _number_density(ff, density)
    n = int(round(rho_n * math.pi * radius ** 2 * length))
    s0 = rho_n ** (-1.0 / 3.0)
    ny = max(1, round(length / s0))
    dy = length / ny
    d = math.sqrt(1.0 / (rho_n * dy))
    k = int(math.ceil(radius / d)) + 2
    ij = np.stack(np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1), indexing="ij"), -1).reshape(-1, 2)
    cols = (ij + 0.5) * d                              # offset grid: symmetric about the axis
    r2 = np.round((cols ** 2).sum(axis=1), 6)
    order = np.lexsort((rng.permutation(len(cols)), r2))
    box_x = float(box_x) if box_x is not None else 2 * radius + 2 * vacuum
    if box_x < 2 * radius + 6.0:
        raise ValueError(f"box_x = {box_x} A is too narrow for a cylinder of radius {radius} A")
    cx, cz = 0.5 * box_x, vacuum + radius
    sites = []
    for c in order.tolist():
        for j in rng.permutation(ny).tolist():
            sites.append((cx + cols[c, 0], (j + 0.5) * dy, cz + cols[c, 1]))
        if len(sites) >= n:
            break
    sites = np.array(sites[:n])
    cell = np.array([box_x, length, 2 * radius + 2 * vacuum])
    r_eff = math.sqrt(n / (rho_n * math.pi * length))
    info = {"builder": "water_cylinder", "radius_A": radius, "length_A": length, "axis": "y",
            "axis_xz_A": (cx, cz), "density_g_cm3": n * m / AVOGADRO / (math.pi * radius ** 2 * length * 1e-24),
            "density_requested_g_cm3": density, "radius_effective_A": r_eff,
            "radius_outermost_site_A": float(np.sqrt(((sites[:, [0, 2]] - [cx, cz]) ** 2).sum(axis=1)).max()),
            "lattice_spacing_A": (d, dy, d), "periodic_axes": "y", "seed": seed}
    return _water_system(sites, cell, ff, rng, info)


def cap_radius(radius_equivalent: float, contact_angle_deg: float) -> float:
    """Radius R (A) of the circular cap (a circular segment with contact angle theta on its chord) whose area
    equals that of a circle of ``radius_equivalent`` R0: R^2 (theta - sin theta cos theta) = pi R0^2."""
    th = math.radians(float(contact_angle_deg))
    if not 0.0 < th <= math.pi:
        raise ValueError(f"contact angle must be in (0, 180] deg, got {contact_angle_deg}")
    return float(radius_equivalent) * math.sqrt(math.pi / (th - math.sin(th) * math.cos(th)))


@atoms_builder
def water_cap(radius: float = 11.0, length: float = 20.0, *, contact_angle_deg: float = 90.0,
              box_x: float | None = None, density: float = WATER_DENSITY, vacuum: float = 15.0, seed: int = 0,
              forcefield: ForceField | None = None) -> System:
    """A quasi-2-D droplet started near its resting shape: a cylindrical cap, periodic along y (period
    ``length`` A), whose flat base lies on the plane z = ``vacuum`` and meets the circular surface at
    ``contact_angle_deg`` (90 = a half-cylinder). Its cross-section holds as much water as a full circle of
    ``radius`` R0 (the droplet's equivalent radius): cap radius R = :func:`cap_radius` (R0, theta).

    Molecules sit on the lattice of :func:`water_cylinder` (ny planes along y, a square x-z grid whose cell times
    the y spacing is one molecular volume at ``density``); the grid cells above the base plane nearest the
    circle's centre (0, -R cos theta) are filled first until N = round(rho pi R0^2 L N_A / M), so the filled
    region is the cap. Box: x = ``box_x`` (default the base width + 2 vacuum), z = cap height + 2 vacuum.
    """
    ff = forcefield or water_forcefield()
    rng = np.random.default_rng(seed)
    rho_n, m = _number_density(ff, density)
    n = int(round(rho_n * math.pi * radius ** 2 * length))
    th = math.radians(float(contact_angle_deg))
    R = cap_radius(radius, contact_angle_deg)
    zc = -R * math.cos(th)                             # circle centre relative to the base plane
    half = R if th >= math.pi / 2 else R * math.sin(th)
    height = R + zc
    s0 = rho_n ** (-1.0 / 3.0)
    ny = max(1, round(length / s0))
    dy = length / ny
    d = math.sqrt(1.0 / (rho_n * dy))
    kx, kz = int(math.ceil(half / d)) + 3, int(math.ceil(height / d)) + 3
    ij = np.stack(np.meshgrid(np.arange(-kx, kx), np.arange(0, kz), indexing="ij"), -1).reshape(-1, 2)
    cols = (ij + 0.5) * d                              # offset grid: symmetric about x = 0, first row d/2 up
    r2 = np.round(cols[:, 0] ** 2 + (cols[:, 1] - zc) ** 2, 6)
    order = np.lexsort((rng.permutation(len(cols)), r2))
    box_x = float(box_x) if box_x is not None else 2 * half + 2 * vacuum
    if box_x < 2 * half + 6.0:
        raise ValueError(f"box_x = {box_x} A is too narrow for a cap of base width {2 * half:.1f} A")
    cx = 0.5 * box_x
    sites = []
    for c in order.tolist():
        for j in rng.permutation(ny).tolist():
            sites.append((cx + cols[c, 0], (j + 0.5) * dy, vacuum + cols[c, 1]))
        if len(sites) >= n:
            break
    sites = np.array(sites[:n])
    cell = np.array([box_x, length, height + 2 * vacuum])
    info = {"builder": "water_cap", "radius_equivalent_A": radius, "length_A": length, "axis": "y",
            "contact_angle_initial_deg": float(contact_angle_deg), "cap_radius_A": R,
            "base_half_width_A": R * math.sin(th), "cap_height_A": height, "base_z_A": vacuum,
            "centre_xz_A": (cx, vacuum + zc), "density_requested_g_cm3": density,
            "density_g_cm3": n * m / AVOGADRO / (math.pi * radius ** 2 * length * 1e-24),
            "lattice_spacing_A": (d, dy, d), "periodic_axes": "y", "seed": seed}
    return _water_system(sites, cell, ff, rng, info)
