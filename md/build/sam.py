"""OTS monolayers grafted on a silica substrate (:func:`ots_sam`).

OTS (``ots_trappe_ua.toml``): C18 united-atom chains CH3-(CH2)17- on a head Si (SIH) bonded to one surface O
(silanol O retyped OC24 -> OC23, its H deleted) and carrying two OH; no lateral cross-linking.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Mapping, Sequence

import numpy as np

from md.build.common import SOURCES, _angle_theta0, _bond_r0, _plain, _unit, atoms_builder, sam_forcefield
from md.build.silica import silica_slab
from md.system.atoms import as_system
from md.system.forcefield import ForceField
from md.system.topology import System, from_types, merge, minimum_image, remove_atoms, with_bonded_terms

# ================================================================================================ OTS monolayer

#: the largest angle between the anchor O -> head Si bond and the vertical that a laterally offset head may take
#: (``ots_sam(head_offsets=...)``); IFF's Si-O-Si theta0 is 149 deg, so a head up to 60 deg off a vertical surface
#: Si-O bond starts within 30 deg of it and the minimiser takes it the rest of the way
MAX_ANCHOR_TILT_DEG = 60.0


def chain_geometry(chain_length: int = 18, tilt_deg: float = 15.0, tilt_azimuth_deg: float = 0.0,
                   forcefield: ForceField | None = None) -> tuple[np.ndarray, list[str]]:
    """Positions (A, relative to the anchor O) and types of one chain as :func:`ots_sam` places it: head Si, two
    head OH, then the carbons."""
    tpos, types, _ = _chain_template(forcefield or sam_forcefield(), chain_length, tilt_deg, tilt_azimuth_deg)
    return tpos, types


def _disk(bond: np.ndarray) -> tuple[np.ndarray, float]:
    """centre and radius of :func:`head_offset_disk` for the template's anchor O -> head Si vector ``bond``"""
    return -bond[:2].copy(), float(np.linalg.norm(bond)) * math.sin(math.radians(MAX_ANCHOR_TILT_DEG))


def head_offset_disk(chain_length: int = 18, tilt_deg: float = 15.0, tilt_azimuth_deg: float = 0.0,
                     forcefield: ForceField | None = None) -> tuple[np.ndarray, float]:
    """The lateral offsets (A) a chain may take from its place above the anchor O in :func:`ots_sam` (its
    ``head_offsets``): the disk of centre ``-s_xy`` and radius ``r sin(MAX_ANCHOR_TILT_DEG)``, where ``s`` is the
    template's anchor O -> head Si bond (length r) -- the head Si stays on its bond sphere, at most
    :data:`MAX_ANCHOR_TILT_DEG` off the vertical."""
    return _disk(chain_geometry(chain_length, tilt_deg, tilt_azimuth_deg, forcefield)[0][0])


def head_shifts(offsets: np.ndarray, chain_length: int = 18, tilt_deg: float = 15.0, tilt_azimuth_deg: float = 0.0,
                forcefield: ForceField | None = None, *, template: np.ndarray | None = None) -> np.ndarray:
    """Rigid shifts (n x 3, A) of chains moved laterally by ``offsets`` (n x 2, A): the head Si turns on its bond
    sphere about the anchor O, so the shift's z keeps the O -> Si bond length. ValueError for an offset outside
    :func:`head_offset_disk`. ``template``: the positions :func:`chain_geometry` gives for these arguments, when the
    caller has them (they are then not rebuilt, nor the force field re-read)."""
    offsets = np.asarray(offsets, float).reshape(-1, 2)
    tpos = chain_geometry(chain_length, tilt_deg, tilt_azimuth_deg, forcefield)[0] if template is None else template
    s0 = tpos[0]
    centre, radius = _disk(s0)
    far = np.hypot(*(offsets - centre).T) > radius + 1e-9
    if far.any():
        d = offsets[np.flatnonzero(far)[0]]
        raise ValueError(f"head offset ({d[0]:.3f}, {d[1]:.3f}) A tilts the anchor bond beyond "
                         f"{MAX_ANCHOR_TILT_DEG:g} deg: allowed within {radius:.3f} A of ({centre[0]:.3f}, "
                         f"{centre[1]:.3f})")
    lateral = s0[:2] + offsets
    dz = np.sqrt(float(s0 @ s0) - (lateral ** 2).sum(axis=1)) - s0[2]
    return np.column_stack([offsets, dz])


def _xy_spacing_ok(p: np.ndarray, accepted: list[np.ndarray], cell: np.ndarray, dmin: float) -> bool:
    if not accepted:
        return True
    d = minimum_image(np.array(accepted)[:, :2] - p[:2], cell[:2], (True, True))
    return bool(np.min(np.hypot(d[:, 0], d[:, 1])) >= dmin)


def _chain_template(ff: ForceField, chain_length: int, tilt_deg: float, azimuth_deg: float):
    """Positions (relative to the anchor O at the origin) and types of SIH, 2 x (OC24, HOY), CH2 x (n-1), CH3.

    All-trans zigzag: anchor O, head Si and the carbons lie in one plane containing the chain axis, which is
    tilted ``tilt_deg`` from +z towards azimuth ``azimuth_deg``; every backbone angle is the TraPPE C-C-C
    theta0 (114 deg), bond lengths are the force field's r0. The two head OH take the remaining tetrahedral
    directions at the head Si, with Si-O-H = IFF theta0 and H tilted upwards.
    """
    t, phi = math.radians(tilt_deg), math.radians(azimuth_deg)
    axis = np.array([math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)])
    up = np.array([0.0, 0.0, 1.0])
    w = up - np.dot(up, axis) * axis
    if np.linalg.norm(w) < 1e-9:  # untilted: any perpendicular in the azimuth plane
        w = np.array([math.cos(phi), math.sin(phi), 0.0])
    w = _unit(w)
    half = math.radians(0.5 * (180.0 - _angle_theta0(ff, "CH2", "CH2", "CH2")))
    r = {"O-S": _bond_r0(ff, "SIH", "OC23"), "S-C": _bond_r0(ff, "CH2", "SIH"), "C-C": _bond_r0(ff, "CH2", "CH2"),
         "C-C3": _bond_r0(ff, "CH3", "CH2"), "S-OH": _bond_r0(ff, "SIH", "OC24"), "O-H": _bond_r0(ff, "OC24", "HOY")}
    lengths = [r["O-S"], r["S-C"]] + [r["C-C"]] * (chain_length - 2) + [r["C-C3"]]
    backbone = [np.zeros(3)]
    for k, length in enumerate(lengths):
        sign = 1.0 if k % 2 == 0 else -1.0
        backbone.append(backbone[-1] + length * (math.cos(half) * axis + sign * math.sin(half) * w))
    backbone = np.array(backbone)            # 0: anchor O, 1: SIH, 2..: carbons
    s = backbone[1]
    a, b = _unit(backbone[0] - s), _unit(backbone[2] - s)
    m, nrm = _unit(a + b), _unit(np.cross(a, b))
    half_tet = math.acos(-1.0 / 3.0) / 2.0
    bend = math.radians(180.0 - _angle_theta0(ff, "SIH", "OC24", "HOY"))
    head = []
    for sign in (1.0, -1.0):
        d = -math.cos(half_tet) * m + sign * math.sin(half_tet) * nrm
        o = s + r["S-OH"] * d
        p = up - np.dot(up, d) * d
        p = _unit(p) if np.linalg.norm(p) > 1e-6 else _unit(np.cross(d, axis))
        head.append((o, o + r["O-H"] * (math.cos(bend) * d + math.sin(bend) * p)))
    pos = [backbone[1], head[0][0], head[0][1], head[1][0], head[1][1], *backbone[2:]]
    types = ["SIH", "OC24", "HOY", "OC24", "HOY"] + ["CH2"] * (chain_length - 1) + ["CH3"]
    # local bonds (indices into pos); the anchor bond O-SIH is added by the caller
    bonds = [(0, 1), (1, 2), (0, 3), (3, 4), (0, 5)] + [(5 + k, 6 + k) for k in range(chain_length - 1)]
    return np.array(pos), types, bonds


@atoms_builder
def ots_sam(substrate: System | None = None, coverage: float = 4.5, *, tilt_deg: float = 15.0,
            tilt_azimuth_deg: float = 0.0, chain_length: int = 18, seed: int = 0, min_spacing: float = 4.4,
            site_group: str = "silanol_O_top", vacuum: float = 10.0, forcefield: ForceField | None = None,
            head_offsets: Mapping[int, Sequence[float]] | None = None) -> System:
    """Graft an OTS monolayer (C``chain_length`` united-atom chains on Si(OH)2 heads) onto a flat silica slab.

    Grafting sites are drawn (seeded, random order) from the substrate's top silanol O (group ``site_group``)
    with a lateral minimum spacing ``min_spacing`` (A) until ``coverage`` chains/nm^2 (of the x-y area) is
    reached; if the sites cannot hold it, ValueError says how many fit (cristobalite (111), one Q3 silanol per
    4.50 nm^-2 on a 5.06 A hexagonal lattice, holds 4.50 chains/nm^2; the (001) face at most 3.9).

    Each graft is the condensation Si-OH + HO-Si(OH)2R -> Si-O-Si(OH)2R: the surface silanol H is deleted and
    its O retyped OC24 -> OC23 (charge -0.675 -> -0.55); the head Si (SIH, +0.825) is bonded to that O, to two
    OH (OC24/HOY) and to the alpha-CH2. Charge per graft: substrate -0.4 + 0.125 = -0.275, chain
    0.825 + 2 (-0.675 + 0.4) = +0.275, net 0 (inputs/forcefields/README.md). No lateral Si-O-Si cross-links
    between heads (simplification).
    Chains start all-trans with their axis tilted ``tilt_deg`` towards ``tilt_azimuth_deg``.

    ``head_offsets`` (substrate atom index of a site -> lateral offset in A) moves a chain sideways from its place
    above the anchor O: the head Si turns on its bond sphere about the O (the bond keeps its length) and the chain
    follows rigidly; the spacing rule applies to the offset chains. Offsets must lie in :func:`head_offset_disk`
    (ValueError otherwise). Used where a curved surface's silanols sit closer than chains pack (the pull-off dome).

    Groups added: 'sam' (all chain atoms incl. head OH), 'sam_head_si', 'sam_ch3', 'sam_anchor_O'.
    ``info``: chains, coverage (nm^-2), thickness (mean CH3 height above the mean anchor-O plane, A), sites.

    ``substrate=None`` grafts onto a small cristobalite (111) slab, ``silica_slab(3, 2, thickness=10.0,
    face="111", silanol_density=4.5, seed=seed)`` (the smoke SAM's).
    """
    substrate = (silica_slab.system(3, 2, thickness=10.0, face="111", silanol_density=4.5, seed=seed)
                 if substrate is None else as_system(substrate))
    ff = forcefield or sam_forcefield()
    rng = np.random.default_rng(seed)
    if chain_length < 2:
        raise ValueError("chain_length must be >= 2")
    sites = np.asarray(substrate.group(site_group), int)
    if not len(sites):
        raise ValueError(f"substrate group {site_group!r} is empty: nothing to graft on")
    area = float(substrate.cell[0] * substrate.cell[1])
    offsets = {int(i): np.asarray(v, float) for i, v in (head_offsets or {}).items()}
    accepted = _pick_sites(substrate, sites, coverage, min_spacing, offsets, rng)
    base = _condense_anchors(substrate, accepted, ff)
    anchors = np.asarray(base.group("sam_anchor_O"), int)
    # chains
    tpos, ttypes, tbonds = _chain_template(ff, chain_length, tilt_deg, tilt_azimuth_deg)
    shifts = np.zeros((len(accepted), 3))
    if offsets:                              # anchors keep the order of ``accepted`` through remove_atoms
        shifts = head_shifts(np.array([offsets.get(i, np.zeros(2)) for i in accepted]), template=tpos)
    merged = _attach_chains(base, anchors, (tpos, ttypes, tbonds), shifts, ff, vacuum)
    per = len(ttypes)
    ch3 = base.n_atoms + np.arange(len(anchors)) * per + per - 1
    p = merged.positions
    thickness = float(p[ch3, 2].mean() - p[anchors, 2].mean())
    top_sil = merged.groups.get("silanol_O_top", np.array([], int))
    sub_info = dict(substrate.info)
    info = {
        "builder": "ots_sam", "chains": int(len(anchors)), "chain_length": chain_length,
        "coverage_requested_nm2": coverage, "coverage_nm2": len(anchors) / (area / 100.0),
        "area_nm2": area / 100.0, "tilt_deg": tilt_deg, "tilt_azimuth_deg": tilt_azimuth_deg,
        "min_spacing_A": min_spacing, "seed": seed,
        "thickness_A": thickness,
        "thickness_definition": "mean CH3 height minus mean anchor-O height (initial all-trans geometry)",
        "unreacted_top_silanols": int(len(top_sil)),
        "unreacted_top_silanol_density_nm2": len(top_sil) / (area / 100.0),
        "cross_linking": "none: each head keeps two Si-OH (simplification)",
        "n_atoms": merged.n_atoms, "counts": merged.type_counts(), "total_charge": merged.total_charge(),
        "source": SOURCES["ots"], "substrate": sub_info,
        "omitted_zero_dihedrals": merged.info.get("omitted_zero_dihedrals", 0),
    }
    if offsets:
        info["head_offset_max_A"] = float(np.hypot(shifts[:, 0], shifts[:, 1]).max())
    return replace(merged, info=_plain(info))


def _pick_sites(substrate: System, sites: np.ndarray, coverage: float, min_spacing: float,
                offsets: Mapping[int, np.ndarray], rng: np.random.Generator) -> list[int]:
    """Grafting sites (substrate atom indices, sorted) drawn in seeded random order from ``sites``, each at least
    ``min_spacing`` laterally from those taken (where the chains stand: sites moved by ``offsets``), until
    ``coverage`` chains/nm^2; ValueError if the sites cannot hold it."""
    area = float(substrate.cell[0] * substrate.cell[1])
    target = int(round(coverage * area / 100.0))
    pos = substrate.positions.copy()
    for i, v in offsets.items():
        pos[i, :2] += v                      # the spacing rule applies to where the chains stand
    accepted: list[int] = []
    acc_pos: list[np.ndarray] = []
    for k in rng.permutation(len(sites)).tolist():
        i = int(sites[k])
        if len(accepted) == target:
            break
        if _xy_spacing_ok(pos[i], acc_pos, substrate.cell, min_spacing):
            accepted.append(i)
            acc_pos.append(pos[i])
    if len(accepted) < target:
        raise ValueError(
            f"only {len(accepted)} of {target} grafting sites fit at {min_spacing} A spacing on this substrate "
            f"({len(accepted) / area * 100:.2f} chains/nm^2 < requested {coverage}); cristobalite face='111' "
            f"offers 4.50 sites/nm^2 on a 5.06 A lattice")
    accepted.sort()
    return accepted


def _condense_anchors(substrate: System, accepted: list[int], ff: ForceField) -> System:
    """The substrate with each anchor silanol condensed: its H deleted, its O retyped OC24 -> OC23 (and charged as
    one), recorded in group 'sam_anchor_O' (so remove_atoms re-indexes it) and out of the silanol groups."""
    nb = [[] for _ in range(substrate.n_atoms)]
    for i, j in substrate.bonds.tolist():
        nb[i].append(j)
        nb[j].append(i)
    h_del = []
    for o in accepted:
        hs = [h for h in nb[o] if substrate.types[h] == "HOY"]
        if len(hs) != 1 or substrate.types[o] != "OC24":
            raise ValueError(f"site atom {o} is not a silanol O (type {substrate.types[o]}, H neighbours {hs})")
        h_del.append(hs[0])
    types = substrate.types.copy().astype(object)
    charges = substrate.charges.copy()
    types[accepted] = "OC23"
    charges[accepted] = ff.atom_type("OC23").charge
    groups = {k: (np.setdiff1d(v, accepted) if k.startswith("silanol_O") else v) for k, v in substrate.groups.items()}
    groups["sam_anchor_O"] = np.array(accepted, int)
    return remove_atoms(replace(substrate, types=types, charges=charges, groups=groups), h_del)


def _attach_chains(base: System, anchors: np.ndarray, template, shifts: np.ndarray, ff: ForceField,
                   vacuum: float) -> System:
    """One chain (``template`` = positions relative to the anchor O, types, bonds) on every anchor O, moved by its
    ``shifts``, bonded head Si - anchor O; the box ``vacuum`` above the highest atom; the SAM's groups; bonded
    terms typed."""
    tpos, ttypes, tbonds = template
    n0 = base.n_atoms
    per = len(ttypes)
    mol0 = int(base.mol_ids.max())
    all_pos, all_types, all_mol, bonds = [], [], [], []
    for c, o in enumerate(anchors.tolist()):
        off = n0 + c * per
        all_pos.append(base.positions[o] + tpos + shifts[c])
        all_types += ttypes
        all_mol += [mol0 + 1 + c] * per
        bonds += [(off + i, off + j) for i, j in tbonds]
        bonds.append((o, off))                        # anchor O - head Si
    chains = from_types(np.concatenate(all_pos), all_types, ff, mol_ids=all_mol, cell=base.cell, pbc=base.pbc)
    merged = merge([base, chains], cell=base.cell)
    merged = replace(merged, bonds=np.concatenate([merged.bonds, np.array(bonds, int)]), bond_types=[])
    zmax = merged.positions[:, 2].max()
    cell = np.array([base.cell[0], base.cell[1], zmax + vacuum])
    head_si = n0 + np.arange(len(anchors)) * per
    groups = {k: v for k, v in merged.groups.items()}
    groups.update(sam=np.arange(n0, n0 + len(anchors) * per), sam_head_si=head_si, sam_ch3=head_si + per - 1,
                  sam_anchor_O=anchors)
    return with_bonded_terms(replace(merged, cell=cell, groups=groups, info={}), ff)
