"""Silica slabs and asperities (:func:`silica_slab`, :func:`silica_asperity`).

Silica (INTERFACE FF types, ``inputs/forcefields/silica_interface.toml``)
    Crystalline silica cut from an orthorhombic periodic supercell of the bulk crystal:

    * ``polymorph="cristobalite"``: idealised beta-cristobalite, space group Fd-3m, a = 7.16 A, Si on the
      diamond sites (8a), O midway between bonded Si (16c) -- Wyckoff, Z. Kristallogr. 62 (1925) 189;
      AFLOW prototype A2B_cF24_227_c_a (Mehl et al., Comput. Mater. Sci. 136 (2017) S1). The ideal cell has
      straight Si-O-Si (180 deg) and Si-O = a sqrt(3)/8 = 1.550 A; the IFF minimum (1.68 A, 149 deg) is reached
      by energy minimisation in LAMMPS. ``face="001"`` exposes geminal (Q2) silanols at 2/(a^2/2) = 7.80 OH/nm^2,
      reduced towards the requested density by condensing neighbouring silanol pairs (below); ``face="111"``
      exposes single (Q3) silanols at 4/(sqrt(3) a^2) = 4.50 OH/nm^2, one per surface Si, all pointing along
      the normal -- the face the OTS monolayer is grafted on.
    * ``polymorph="quartz"``: alpha-quartz P3_221, a = 4.916 A, c = 5.4054 A, Si (0.4697, 0, 0),
      O (0.4135, 0.2669, 0.1191) -- Levien, Prewitt, Weidner, Am. Mineral. 65 (1980) 920 -- shifted by
      (0, 0, 2/3) to the International Tables origin (the one ``ase.spacegroup`` uses); ``face="0001"``.

    Cutting rule (any polymorph and shape): keep the Si atoms inside the region; repeatedly drop kept Si with
    fewer than two kept Si neighbours (Q0/Q1) and, for asperities, add back removed Si with three or more (so
    the carved surface has no Q1 and few overhangs); keep every O bonded to a kept Si. An O with two kept Si
    is bridging (OC23); an O with one is a silanol O (OC24) and gets an H (HOY) at 0.945 A with Si-O-H =
    115 deg, tilted towards the local outward normal. Every Si is therefore 4-coordinated and every O is
    bridging or silanol.

    Condensation (lowers the silanol density): two silanol O on different Si that were bonded to the same
    removed Si are replaced by one bridging O at their midpoint (Si-OH + HO-Si -> Si-O-Si + H2O). Each Si
    takes part in at most one condensation (Q2 -> Q3, never Q4), pairs are drawn as a seeded random subset of a
    maximum matching. On cristobalite (001) the condensed Si are 5.06 A apart, so the new Si-O bonds start
    at ~2.7 A: minimise before dynamics.

    Neutrality, algebraically: every Si-O bond moves 0.275 e from Si to O (SC4 +1.1 = 4 x 0.275; OC23
    -0.55 = 2 x -0.275; OC24 + HOY = -0.675 + 0.4 = -0.275). With 4 N_Si = 2 N_OC23 + N_OH (bond count),
    Q = 1.1 N_Si - 0.55 N_OC23 - 0.275 N_OH = 0.275 (4 N_Si - 2 N_OC23 - N_OH) = 0 for any cut.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Mapping

import numpy as np
from scipy.spatial import cKDTree

from md.build.common import SOURCES, _angle_theta0, _bond_r0, _plain, _unit, atoms_builder, silica_forcefield
from md.system.forcefield import ForceField
from md.system.topology import System, from_types, minimum_image, with_bonded_terms

CRISTOBALITE_A = 7.16                     #: A, idealised cubic beta-cristobalite (Wyckoff 1925)
QUARTZ = {"a": 4.916, "c": 5.4054, "spacegroup": 154,     # P3_221
          "si": (0.4697, 0.0, 2.0 / 3.0), "o": (0.4135, 0.2669, 0.1191 + 2.0 / 3.0)}  # Levien et al. 1980
SIO_BOND_CUTOFF = 2.0                     #: A, Si-O bond search radius in the bulk crystals (bonds 1.55-1.61 A)
#: The silica surface of every recipe (contact angle, adhesion, pull-off): cristobalite (111), isolated Q3
#: silanols at 4.50 OH/nm^2 on a 5.06 A hexagonal lattice (nearest silanol O-O 5.06 A), the hydrophilic Q3
#: chemistry IFF was validated with (Emami et al., Chem. Mater. 26 (2014) 2647). The (001) face holds
#: geminal/vicinal silanol pairs 2.53 A apart, which H-bond to each other instead of to water.
SILICA_FACE = "111"
#: Default face of each polymorph when ``face`` is not given.
DEFAULT_FACE = {"cristobalite": SILICA_FACE, "quartz": "0001"}



# ================================================================================================ bulk crystals

class _Bulk:
    """A periodic orthorhombic supercell of a silica crystal, with its Si-O bond graph."""

    def __init__(self, pos: np.ndarray, is_si: np.ndarray, cell: np.ndarray, period_z: float, unit_xy: tuple,
                 polymorph: str, face: str, lattice_a: float):
        self.pos, self.cell, self.period_z, self.unit_xy = pos, cell, period_z, unit_xy
        self.polymorph, self.face, self.lattice_a = polymorph, face, lattice_a
        self.si = np.flatnonzero(is_si)
        self.o = np.flatnonzero(~is_si)
        tree = cKDTree(pos, boxsize=cell)
        pairs = tree.query_pairs(SIO_BOND_CUTOFF, output_type="ndarray")
        local = np.full(len(pos), -1)
        local[self.si] = np.arange(len(self.si))
        local[self.o] = np.arange(len(self.o))
        si_of_o = [[] for _ in self.o]
        o_of_si = [[] for _ in self.si]
        for i, j in pairs:
            if is_si[i] == is_si[j]:
                raise RuntimeError(f"unexpected {'Si-Si' if is_si[i] else 'O-O'} contact below {SIO_BOND_CUTOFF} A")
            s, o = (i, j) if is_si[i] else (j, i)
            si_of_o[local[o]].append(local[s])
            o_of_si[local[s]].append(local[o])
        if any(len(x) != 2 for x in si_of_o) or any(len(x) != 4 for x in o_of_si):
            raise RuntimeError("bulk crystal is not a fully connected SiO4 network (check lattice and box)")
        self.si_of_o = np.array(si_of_o, int)          # (n_o, 2) local Si indices
        self.o_of_si = np.array(o_of_si, int)          # (n_si, 4) local O indices
        other = np.where(self.si_of_o[self.o_of_si, 0] == np.arange(len(self.si))[:, None],
                         self.si_of_o[self.o_of_si, 1], self.si_of_o[self.o_of_si, 0])
        self.si_nb = other                             # (n_si, 4) Si neighbours through each O
        self.si_pos = pos[self.si]
        self.o_pos = pos[self.o]

    def si_planes(self) -> np.ndarray:
        return np.unique(np.round(self.si_pos[:, 2], 3))


def _fill_box(lattice: np.ndarray, frac: np.ndarray, is_si: np.ndarray, rot: np.ndarray, box: np.ndarray):
    """Atoms of the crystal (rows of ``lattice`` are the lattice vectors, crystal frame) rotated by ``rot`` (rows:
    new axes in the crystal frame) that fall in [0, box). The box vectors must be lattice translations."""
    corners = np.array([[x, y, z] for x in (0, box[0]) for y in (0, box[1]) for z in (0, box[2])])
    f = (corners @ rot) @ np.linalg.inv(lattice)
    lo, hi = np.floor(f.min(0)) - 1, np.ceil(f.max(0)) + 1
    grid = np.stack(np.meshgrid(*[np.arange(lo[k], hi[k] + 1) for k in range(3)], indexing="ij"), -1).reshape(-1, 3)
    cart = ((grid[:, None, :] + frac[None, :, :]).reshape(-1, 3)) @ lattice
    r = cart @ rot.T + 0.05            # tiny shift: no atom sits exactly on a box face
    sel = np.all((r >= 0) & (r < box), axis=1)
    n_expect = abs(np.prod(box) / np.linalg.det(lattice)) * len(frac)
    if abs(sel.sum() - n_expect) > 1e-6:
        raise RuntimeError(f"supercell holds {sel.sum()} atoms, expected {n_expect:.3f}: "
                           "box is not a lattice supercell")
    return r[sel], np.tile(is_si, len(grid))[sel]


def quartz_basis() -> tuple[np.ndarray, np.ndarray]:
    """Fractional coordinates (9, 3) and Si mask of alpha-quartz, P3_221 (No. 154), from the Wyckoff positions
    3a (x, 0, 2/3) and 6c (x, y, z) of :data:`QUARTZ` and the six symmetry operations of the group
    (International Tables setting, the one ``ase.spacegroup`` uses; a test checks the two agree)."""
    x = QUARTZ["si"][0]
    si = [(x, 0.0, 2 / 3), (0.0, x, 1 / 3), (-x, -x, 0.0)]
    X, Y, Z = QUARTZ["o"]
    o = [(X, Y, Z), (-Y, X - Y, Z + 2 / 3), (-X + Y, -X, Z + 1 / 3), (Y, X, -Z), (X - Y, -Y, -Z + 1 / 3),
         (-X, -X + Y, -Z + 2 / 3)]
    return np.mod(np.array(si + o, float), 1.0), np.r_[np.ones(3, bool), np.zeros(6, bool)]


def _bulk(polymorph: str, face: str, nx: int, ny: int, nz: int, lattice_a: float | None = None) -> _Bulk:
    if polymorph == "cristobalite":
        a = float(lattice_a or CRISTOBALITE_A)
        fcc = np.array([[0, 0, 0], [0, .5, .5], [.5, 0, .5], [.5, .5, 0]])
        si = np.concatenate([fcc, fcc + 0.25])
        o = np.concatenate([fcc + np.array(d) / 8.0 for d in ((1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1))])
        frac = np.concatenate([si, o])
        is_si = np.r_[np.ones(len(si), bool), np.zeros(len(o), bool)]
        lattice = a * np.eye(3)
        if face == "001":
            rot, unit = np.eye(3), (a, a, a)
        elif face == "111":
            rot = np.array([_unit(np.array(v, float)) for v in ((1, -1, 0), (1, 1, -2), (1, 1, 1))])
            unit = (a / math.sqrt(2), a * math.sqrt(6) / 2, a * math.sqrt(3))
        else:
            raise ValueError(f"cristobalite face must be '001' or '111', got {face!r}")
    elif polymorph == "quartz":
        if face != "0001":
            raise ValueError(f"quartz face must be '0001', got {face!r}")
        q = QUARTZ
        a = float(lattice_a or q["a"])
        frac, is_si = quartz_basis()
        lattice = np.array([[a, 0.0, 0.0], [-0.5 * a, 0.5 * math.sqrt(3) * a, 0.0], [0.0, 0.0, q["c"]]])
        rot, unit = np.eye(3), (a, a * math.sqrt(3), q["c"])
    else:
        raise ValueError(f"polymorph must be 'cristobalite' or 'quartz', got {polymorph!r}")
    box = np.array([nx * unit[0], ny * unit[1], nz * unit[2]])
    pos, si_mask = _fill_box(lattice, frac, is_si, rot, box)
    return _Bulk(pos, si_mask, box, unit[2], (unit[0], unit[1]), polymorph, face, a)


# ================================================================================================ cutting

def _clean(bulk: _Bulk, keep: np.ndarray, fill: bool, max_iter: int = 100) -> np.ndarray:
    """Drop kept Si with < 2 kept Si neighbours; with ``fill`` also add back removed Si with >= 3."""
    keep = keep.copy()
    for _ in range(max_iter):
        n_kept = keep[bulk.si_nb].sum(axis=1)
        changed = False
        if fill:
            add = ~keep & (n_kept >= 3)
            if add.any():
                keep |= add
                changed = True
                n_kept = keep[bulk.si_nb].sum(axis=1)
        drop = keep & (n_kept <= 1)
        if drop.any():
            keep &= ~drop
            changed = True
        if not changed:
            return keep
    raise RuntimeError("cutting did not converge (add/drop oscillation)")


def _choose_planes(bulk: _Bulk, thickness: float | None, layers: int | None) -> np.ndarray:
    """Boolean Si mask for a slab of whole Si planes, starting one period above the bulk box bottom at a plane
    whose Si have >= 2 neighbours above them (so the bottom face is Q2/Q3, not Q1)."""
    planes = bulk.si_planes()
    z = np.round(bulk.si_pos[:, 2], 3)
    per_period = int(np.sum(planes < planes[0] + bulk.period_z - 1e-3))
    p0 = None
    for p in range(per_period, len(planes)):
        members = np.flatnonzero(z == planes[p])
        above = (bulk.si_pos[bulk.si_nb[members], 2] - bulk.si_pos[members, 2][:, None])
        above = minimum_image(np.stack([np.zeros_like(above)] * 2 + [above], -1), bulk.cell, (0, 0, 1))[..., 2]
        if np.all((above > 0.01).sum(axis=1) >= 2):
            p0 = p
            break
    if p0 is None:
        raise RuntimeError("no suitable bottom Si plane found")
    if layers is not None:
        n = int(layers) * per_period
        if p0 + n > len(planes) - per_period:
            raise RuntimeError("bulk box too short for the requested layers")
        return np.isin(z, planes[p0:p0 + n])
    for n in range(1, len(planes) - p0 - per_period + 1):
        keep = _clean(bulk, np.isin(z, planes[p0:p0 + n]), fill=False)
        if keep.any() and np.ptp(bulk.si_pos[keep, 2]) >= thickness - 1e-6:
            return keep
    raise RuntimeError("bulk box too short for the requested thickness")


def _max_matching(edges: list[tuple[int, int]], rng: np.random.Generator) -> list[int]:
    """Indices of a (near-)maximum matching of ``edges`` (Karp-Sipser: degree-1 vertices first, ties at random).
    Exact on paths, cycles and trees -- the pair graphs met here have vertex degree <= 2 on flat faces."""
    alive = set(range(len(edges)))
    inc: dict[int, set[int]] = {}
    for e, (u, v) in enumerate(edges):
        inc.setdefault(u, set()).add(e)
        inc.setdefault(v, set()).add(e)
    chosen: list[int] = []
    while alive:
        leaves = sorted(e for e in alive if len(inc[edges[e][0]]) == 1 or len(inc[edges[e][1]]) == 1)
        pool = leaves if leaves else sorted(alive)
        e = pool[int(rng.integers(len(pool)))]
        chosen.append(e)
        for w in edges[e]:
            for f in list(inc[w]):
                alive.discard(f)
                for x in edges[f]:
                    inc[x].discard(f)
    return chosen


@dataclass(frozen=True)
class _Silanols:
    """The O of the kept Si that lost a partner Si (silanols), each with its kept Si (``own``), the removed partner
    (``gone``) and the face label of every Si; ``bridging`` the O whose two Si are both kept."""
    si_keep: np.ndarray
    silanol: np.ndarray
    own: np.ndarray
    gone: np.ndarray
    label_of_si: np.ndarray
    n_sil_of_si: np.ndarray
    bridging: np.ndarray


def _find_silanols(bulk: _Bulk, keep: np.ndarray, regions: Callable[[np.ndarray], np.ndarray]) -> _Silanols:
    si_keep = np.flatnonzero(keep)
    kept_of_o = keep[bulk.si_of_o]                           # (n_o, 2)
    o_keep = np.flatnonzero(kept_of_o.any(axis=1))
    silanol = o_keep[kept_of_o[o_keep].sum(axis=1) == 1]
    # per silanol: its kept Si and the removed partner Si
    first_kept = kept_of_o[silanol, 0]
    s_own = np.where(first_kept, bulk.si_of_o[silanol, 0], bulk.si_of_o[silanol, 1])
    s_gone = np.where(first_kept, bulk.si_of_o[silanol, 1], bulk.si_of_o[silanol, 0])
    label_of_si = np.full(len(bulk.si), "", dtype=object)
    label_of_si[si_keep] = regions(bulk.si_pos[si_keep])
    return _Silanols(si_keep=si_keep, silanol=silanol, own=s_own, gone=s_gone, label_of_si=label_of_si,
                     n_sil_of_si=np.bincount(s_own, minlength=len(bulk.si)),
                     bridging=o_keep[kept_of_o[o_keep].all(axis=1)])


def _condensation_candidates(bulk: _Bulk, sil: _Silanols) -> dict[tuple[int, int], tuple[int, int]]:
    """Silanol pairs (indices into ``sil.silanol``) that may condense, by the Si pair they would bridge: sharing a
    removed Si, on different Si of one face, both Si with >= 2 silanols, not already bridged (no two-membered
    rings). Pairs straddling two faces are not condensed (keeps the per-face bookkeeping exact)."""
    s_own, n_sil_of_si = sil.own, sil.n_sil_of_si
    bridged = {tuple(sorted(p)) for p in bulk.si_of_o[sil.bridging].tolist()}
    by_gone: dict[int, list[int]] = {}
    for k, g in enumerate(sil.gone.tolist()):
        by_gone.setdefault(g, []).append(k)
    cand: dict[tuple[int, int], tuple[int, int]] = {}
    for ks in by_gone.values():
        for x in range(len(ks)):
            for y in range(x + 1, len(ks)):
                a, b = ks[x], ks[y]
                sa, sb = int(s_own[a]), int(s_own[b])
                key = tuple(sorted((sa, sb)))
                if sa == sb or key in bridged or key in cand:
                    continue
                if n_sil_of_si[sa] < 2 or n_sil_of_si[sb] < 2:
                    continue
                cand[key] = (a, b)
    return {k: v for k, v in cand.items() if sil.label_of_si[k[0]] == sil.label_of_si[k[1]]}


def _condense(sil: _Silanols, cand: Mapping[tuple[int, int], tuple[int, int]], areas: Mapping[str, float],
              target_density: float, rng: np.random.Generator) -> tuple[list[tuple[int, int]], dict[str, dict]]:
    """Per face: as many condensations (drawn from a maximum matching of the candidates) as bring its silanols to
    ``target_density`` OH/nm^2; returns the condensed silanol pairs and the per-face record."""
    label_of_si, s_own = sil.label_of_si, sil.own
    used_si: set[int] = set()
    cond_pairs: list[tuple[int, int]] = []          # (silanol index a, silanol index b)
    per_region: dict[str, dict[str, Any]] = {}
    for name, area in areas.items():
        n_oh = int(np.sum(label_of_si[s_own] == name))
        keys = [k for k in sorted(cand) if label_of_si[k[0]] == name and not (set(k) & used_si)]
        match = [keys[e] for e in _max_matching(keys, rng)]
        want = (n_oh - target_density * area / 100.0) / 2.0
        k_needed = int(min(max(round(want), 0), len(match)))
        pick = sorted(rng.choice(len(match), size=k_needed, replace=False).tolist()) if k_needed else []
        for p in pick:
            used_si.update(match[p])
            cond_pairs.append(cand[match[p]])
        n_after = n_oh - 2 * k_needed
        per_region[name] = {"area_nm2": area / 100.0, "silanols_before": n_oh, "condensations": k_needed,
                            "silanols": n_after, "density_nm2": n_after / (area / 100.0),
                            "max_density_nm2": n_oh / (area / 100.0),
                            "min_density_nm2": (n_oh - 2 * len(match)) / (area / 100.0)}
    return cond_pairs, per_region


def _hydroxylated_silica(bulk: _Bulk, keep: np.ndarray, *, regions: Callable[[np.ndarray], np.ndarray],
                         areas: Mapping[str, float], target_density: float, normal: Callable, rng: np.random.Generator,
                         ff: ForceField, tolerance: float) -> tuple[System, dict[str, Any]]:
    """Kept Si + their O + silanol H, condensed region by region to ``target_density`` (OH/nm^2).

    ``regions(si_positions) -> region label per Si`` assigns each surface Si to a face ('top', 'bottom',
    'dome', ...) whose area (A^2) is in ``areas``. Returns the System (no bonded types yet) and an info dict.
    """
    sil = _find_silanols(bulk, keep, regions)
    cond_pairs, per_region = _condense(sil, _condensation_candidates(bulk, sil), areas, target_density, rng)
    removed_sil = {x for pair in cond_pairs for x in pair}
    atoms = _SilicaAtoms(bulk, sil)
    atoms.add_bridging(cond_pairs)
    atoms.add_silanols(removed_sil, ff, normal, rng)
    # Q-distribution of the kept Si
    n_oh_of_si = np.zeros(len(sil.si_keep), int)
    for k in range(len(sil.silanol)):
        if k not in removed_sil:
            n_oh_of_si[atoms.si_new[sil.own[k]]] += 1
    q_counts = {f"Q{4 - m}": int(np.sum(n_oh_of_si == m)) for m in range(0, 3)}
    geminal = int(np.sum(n_oh_of_si == 2))
    system = from_types(np.concatenate(atoms.positions), atoms.types, ff, cell=bulk.cell, pbc=(True, True, False),
                        bonds=atoms.bonds)
    groups = {}
    for lab, idx in atoms.sil_o_idx.items():
        groups[f"silanol_O_{lab}"] = idx
        groups[f"silanol_H_{lab}"] = atoms.sil_h_idx[lab]
    system = replace(system, groups=groups)
    _check_density(bulk, per_region, target_density, tolerance)
    return system, {"silanol_regions": per_region, "q_distribution": q_counts, "geminal_si": geminal,
                    "condensed_bridges": len(cond_pairs)}


class _SilicaAtoms:
    """The hydroxylated silica's atoms as they are assembled: kept Si, bridging O (the crystal's, then those made by
    condensation), silanol O and H; positions, type names, bonds and the silanol atoms per face."""

    def __init__(self, bulk: _Bulk, sil: _Silanols):
        self.bulk, self.sil = bulk, sil
        self.si_new = np.full(len(bulk.si), -1)
        self.si_new[sil.si_keep] = np.arange(len(sil.si_keep))
        self.positions = [bulk.si_pos[sil.si_keep]]
        self.types = ["SC4"] * len(sil.si_keep)
        self.bonds: list[tuple[int, int]] = []
        self.n = len(sil.si_keep)
        self.sil_o_idx: dict[str, list[int]] = {}
        self.sil_h_idx: dict[str, list[int]] = {}

    def add_bridging(self, cond_pairs: list[tuple[int, int]]) -> None:
        """The crystal's bridging O, then one O midway between each condensed silanol pair's O."""
        bulk, sil, si_new, pbc3 = self.bulk, self.sil, self.si_new, (True, True, True)
        for o in sil.bridging.tolist():
            s1, s2 = bulk.si_of_o[o]
            p = bulk.si_pos[s1] + minimum_image(bulk.o_pos[o] - bulk.si_pos[s1], bulk.cell, pbc3)
            self.positions.append(p[None])
            self.types.append("OC23")
            self.bonds += [(si_new[s1], self.n), (si_new[s2], self.n)]
            self.n += 1
        for a, b in cond_pairs:
            sa, sb = sil.own[a], sil.own[b]
            pa = bulk.si_pos[sa] + minimum_image(bulk.o_pos[sil.silanol[a]] - bulk.si_pos[sa], bulk.cell, pbc3)
            pb = pa + minimum_image(bulk.o_pos[sil.silanol[b]] - pa, bulk.cell, pbc3)
            self.positions.append((0.5 * (pa + pb))[None])
            self.types.append("OC23")
            self.bonds += [(si_new[sa], self.n), (si_new[sb], self.n)]
            self.n += 1

    def add_silanols(self, removed_sil: set[int], ff: ForceField, normal: Callable, rng: np.random.Generator) -> None:
        """Every silanol not condensed: its O where the crystal had it, its H at the force field's O-H length and
        Si-O-H angle, in the plane of the Si-O bond and the face normal (a random azimuth where they are parallel)."""
        bulk, sil, pbc3 = self.bulk, self.sil, (True, True, True)
        r_oh = _bond_r0(ff, "OC24", "HOY")
        bend = math.radians(180.0 - _angle_theta0(ff, "SC4", "OC24", "HOY"))
        for k in range(len(sil.silanol)):
            if k in removed_sil:
                continue
            s = sil.own[k]
            ps = bulk.si_pos[s]
            po = ps + minimum_image(bulk.o_pos[sil.silanol[k]] - ps, bulk.cell, pbc3)
            u = _unit(po - ps)
            nrm = normal(po, sil.label_of_si[s])
            perp = nrm - np.dot(nrm, u) * u
            if np.linalg.norm(perp) < 1e-6:
                perp = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
                phi = rng.uniform(0, 2 * math.pi)
                perp = _unit(perp)
                perp = math.cos(phi) * perp + math.sin(phi) * np.cross(u, perp)
            perp = _unit(perp)
            ph = po + r_oh * (math.cos(bend) * u + math.sin(bend) * perp)
            self.positions += [po[None], ph[None]]
            self.types += ["OC24", "HOY"]
            self.bonds += [(self.si_new[s], self.n), (self.n, self.n + 1)]
            lab = str(sil.label_of_si[s])
            self.sil_o_idx.setdefault(lab, []).append(self.n)
            self.sil_h_idx.setdefault(lab, []).append(self.n + 1)
            self.n += 2


def _check_density(bulk: _Bulk, per_region: Mapping[str, Mapping[str, Any]], target_density: float,
                   tolerance: float) -> None:
    """Raises ValueError (naming the face, what is reachable and the face that reaches it) where a face's silanol
    density misses ``target_density`` by more than ``tolerance`` of it."""
    for name, d in per_region.items():
        achieved, lo, hi = d["density_nm2"], d["min_density_nm2"], d["max_density_nm2"]
        if target_density > 0 and abs(achieved - target_density) > tolerance * target_density:
            raise ValueError(
                f"silanol density {target_density} OH/nm^2 is not reachable on the {name} face of "
                f"{bulk.polymorph}({bulk.face}): achievable {lo:.2f}..{hi:.2f} OH/nm^2 in steps of "
                f"{2 / d['area_nm2']:.3f} (condensation Q2->Q3 only); got {achieved:.2f}. "
                + ("Use face='001' for 3.9-7.8 OH/nm^2." if bulk.face == "111" else
                   "Use face='111' for 4.50 OH/nm^2 (Q3)." if bulk.face == "001" else ""))


def _finish_silica(system: System, ff: ForceField, vacuum: float, frozen_depth: float) -> System:
    """Wrap x, y; put the lowest atom ``vacuum`` above z = 0; box height = extent + 2 vacuum; type bonded terms."""
    p = system.positions.copy()
    p[:, 0] = np.mod(p[:, 0], system.cell[0])
    p[:, 1] = np.mod(p[:, 1], system.cell[1])
    p[:, 2] += vacuum - p[:, 2].min()
    cell = np.array([system.cell[0], system.cell[1], np.ptp(p[:, 2]) + 2.0 * vacuum])
    groups = dict(system.groups)
    groups["silica"] = np.arange(system.n_atoms)
    if frozen_depth > 0:
        groups["frozen"] = np.flatnonzero(p[:, 2] <= p[:, 2].min() + frozen_depth)
    out = replace(system, positions=p, cell=cell, groups=groups)
    return with_bonded_terms(out, ff)


@atoms_builder
def silica_slab(nx: int = 4, ny: int = 4, *, thickness: float | None = 25.0, layers: int | None = None,
                silanol_density: float = 4.7, polymorph: str = "cristobalite", face: str | None = None,
                seed: int = 0, vacuum: float = 10.0, frozen_depth: float = 5.0, density_tolerance: float = 0.10,
                lattice_a: float | None = None, forcefield: ForceField | None = None) -> System:
    """Hydroxylated crystalline silica slab, periodic in x and y, both faces hydroxylated.

    ``nx``, ``ny``: repeats of the surface cell (cristobalite (001): a x a; (111): a/sqrt2 x a sqrt(3/2);
    quartz (0001): a x a sqrt3). ``thickness`` (A): smallest distance between the outermost Si planes;
    or ``layers``: number of crystal periods along z (overrides ``thickness``). ``silanol_density``
    (OH/nm^2, per face): the cut face's natural density is lowered by condensation (module docstring); if the
    achieved value is more than ``density_tolerance`` (relative) from the request, ValueError states the
    achievable range. ``face`` defaults to :data:`SILICA_FACE` = '111' (cristobalite: isolated Q3 silanols, the
    surface every recipe uses) / '0001' (quartz); '001' gives 3.9-7.8 OH/nm^2 with geminal pairs. ``vacuum`` (A) is
    added below and above. ``frozen_depth`` (A): atoms this close to the bottom form the group 'frozen'.

    Groups: 'silica', 'slab', 'silanol_O_top', 'silanol_H_top', 'silanol_O_bottom', 'silanol_H_bottom',
    'frozen'. ``info``: counts, per-face silanol densities and achievable ranges, Q distribution, thicknesses.
    """
    ff = forcefield or silica_forcefield()
    face = face or DEFAULT_FACE.get(polymorph, "")
    rng = np.random.default_rng(seed)
    probe = _bulk(polymorph, face, 1, 1, 1, lattice_a)
    if layers is None and (thickness is None or thickness <= 0):
        raise ValueError("give thickness (A, > 0) or layers")
    nz = (int(layers) if layers is not None else int(math.ceil(thickness / probe.period_z))) + 3
    bulk = _bulk(polymorph, face, nx, ny, nz, lattice_a)
    keep = _clean(bulk, _choose_planes(bulk, thickness, layers), fill=False)
    zc = 0.5 * (bulk.si_pos[keep, 2].min() + bulk.si_pos[keep, 2].max())
    area = bulk.cell[0] * bulk.cell[1]
    system, sinfo = _hydroxylated_silica(
        bulk, keep, regions=lambda p: np.where(p[:, 2] > zc, "top", "bottom"),
        areas={"top": area, "bottom": area}, target_density=silanol_density,
        normal=lambda p, lab: np.array([0.0, 0.0, 1.0 if lab == "top" else -1.0]), rng=rng, ff=ff,
        tolerance=density_tolerance)
    system = _finish_silica(system, ff, vacuum, frozen_depth)
    si = system.select("SC4")
    reg = sinfo["silanol_regions"]
    info = {
        "builder": "silica_slab", "polymorph": polymorph, "face": face, "lattice_a_A": bulk.lattice_a,
        "surface_cells": (nx, ny), "area_nm2": area / 100.0, "seed": seed,
        "n_atoms": system.n_atoms, "counts": system.type_counts(),
        "silanol_density_requested_nm2": silanol_density,
        "silanol_density_top": reg["top"]["density_nm2"], "silanol_density_bottom": reg["bottom"]["density_nm2"],
        "silanol_density_range_nm2": (reg["top"]["min_density_nm2"], reg["top"]["max_density_nm2"]),
        "thickness_si_A": float(np.ptp(system.positions[si, 2])),
        "thickness_A": float(np.ptp(system.positions[:, 2])),
        "total_charge": system.total_charge(), "source": SOURCES[polymorph], **sinfo,
        "omitted_zero_dihedrals": system.info.get("omitted_zero_dihedrals", 0),
    }
    groups = dict(system.groups)
    groups["slab"] = np.arange(system.n_atoms)
    return replace(system, groups=groups, info=_plain(info))


@atoms_builder
def silica_asperity(radius: float = 15.0, holder_thickness: float = 10.0, *, nx: int | None = None,
                    ny: int | None = None, margin: float = 10.0, silanol_density: float = 4.7,
                    polymorph: str = "cristobalite", face: str | None = None, seed: int = 0, vacuum: float = 10.0,
                    frozen_depth: float = 5.0, lattice_a: float | None = None,
                    forcefield: ForceField | None = None) -> System:
    """Hemispherical crystalline silica asperity of ``radius`` (A) on a holder slab, pointing up (+z).

    Carved from the same crystal as :func:`silica_slab`: Si inside the hemisphere (centre on the holder's
    top Si plane, middle of the box) or inside the holder are kept, then cleaned (no Q0/Q1 Si, removed Si
    with >= 3 kept neighbours put back) and hydroxylated. Condensation lowers the silanol density separately
    on the dome (nominal area 2 pi R^2), the flat top of the holder (Lx Ly - pi R^2) and its back (Lx Ly);
    the dome value is nominal (the crystalline dome is stepped, its true area is larger) and is reported, not
    enforced. Lateral size: ``nx``, ``ny`` surface cells, default the smallest with L >= 2 R + 2 ``margin``.
    Use :func:`flip_upside_down` to point it down onto a flat.

    Groups: 'silica', 'asperity' (dome Si and their O/H), 'holder' (the rest), 'frozen' (atoms within
    ``frozen_depth`` of the holder's back), 'silanol_O_top'/'_dome'/'_bottom' and the matching H groups.
    """
    ff = forcefield or silica_forcefield()
    face = face or DEFAULT_FACE.get(polymorph, "")
    rng = np.random.default_rng(seed)
    probe = _bulk(polymorph, face, 1, 1, 1, lattice_a)
    ux, uy = probe.unit_xy
    nx = nx or int(math.ceil((2 * radius + 2 * margin) / ux))
    ny = ny or int(math.ceil((2 * radius + 2 * margin) / uy))
    nz = int(math.ceil((holder_thickness + radius) / probe.period_z)) + 4
    bulk = _bulk(polymorph, face, nx, ny, nz, lattice_a)
    holder = _clean(bulk, _choose_planes(bulk, holder_thickness, None), fill=False)
    z_top = bulk.si_pos[holder, 2].max()
    centre = np.array([0.5 * bulk.cell[0], 0.5 * bulk.cell[1], z_top])
    d = minimum_image(bulk.si_pos - centre, bulk.cell, (True, True, False))
    dome = (bulk.si_pos[:, 2] > z_top + 0.01) & (np.linalg.norm(d, axis=1) <= radius)
    keep = _clean(bulk, holder | dome, fill=True)
    # nothing may grow below the holder's bottom plane
    z_bot = bulk.si_pos[holder, 2].min()
    keep &= bulk.si_pos[:, 2] >= z_bot - 0.01
    keep = _clean(bulk, keep, fill=False)
    zc = 0.5 * (z_bot + z_top)
    area = bulk.cell[0] * bulk.cell[1]

    def regions(p):
        lab = np.where(p[:, 2] > zc, "top", "bottom").astype(object)
        lab[p[:, 2] > z_top + 0.01] = "dome"
        return lab

    def normal(p, lab):
        if lab == "dome":
            return _unit(minimum_image(p - centre, bulk.cell, (True, True, False)))
        return np.array([0.0, 0.0, 1.0 if lab == "top" else -1.0])

    areas = {"dome": 2 * math.pi * radius ** 2, "top": area - math.pi * radius ** 2, "bottom": area}
    system, sinfo = _hydroxylated_silica(bulk, keep, regions=regions, areas=areas, target_density=silanol_density,
                                         normal=normal, rng=rng, ff=ff, tolerance=math.inf)
    z_shift = vacuum - system.positions[:, 2].min()
    system = _finish_silica(system, ff, vacuum, frozen_depth)
    # asperity atoms: dome Si and every O/H bonded to them (O shared with the holder's top plane included)
    si = system.select("SC4")
    z_top_new = z_top + z_shift
    dome_si = si[system.positions[si, 2] > z_top_new + 0.01]
    asp_idx = _bonded_shell(system, dome_si)
    holder_idx = np.setdiff1d(np.arange(system.n_atoms), asp_idx)
    r_dome = np.linalg.norm(minimum_image(system.positions[dome_si] - (centre + [0, 0, z_shift]), system.cell,
                                          system.pbc), axis=1)
    reg = sinfo["silanol_regions"]
    info = {
        "builder": "silica_asperity", "polymorph": polymorph, "face": face, "lattice_a_A": bulk.lattice_a,
        "radius_requested_A": radius, "radius_max_si_A": float(r_dome.max()) if len(r_dome) else 0.0,
        "dome_height_si_A": float(system.positions[dome_si, 2].max() - z_top_new) if len(dome_si) else 0.0,
        "centre_A": (centre + [0, 0, z_shift]).tolist(), "holder_top_si_z_A": float(z_top_new),
        "holder_thickness_si_A": float(z_top - z_bot), "surface_cells": (nx, ny), "seed": seed,
        "n_atoms": system.n_atoms, "counts": system.type_counts(), "n_asperity_atoms": int(len(asp_idx)),
        "silanol_density_requested_nm2": silanol_density,
        "silanol_density_dome": reg["dome"]["density_nm2"], "silanol_density_top": reg["top"]["density_nm2"],
        "silanol_density_bottom": reg["bottom"]["density_nm2"],
        "total_charge": system.total_charge(), "source": SOURCES[polymorph], **sinfo,
        "omitted_zero_dihedrals": system.info.get("omitted_zero_dihedrals", 0),
    }
    return replace(system, groups={**system.groups, "asperity": asp_idx, "holder": holder_idx}, info=_plain(info))


def _bonded_shell(system: System, si: np.ndarray) -> np.ndarray:
    """The Si ``si``, every O bonded to them and those O's silanol H (sorted indices)."""
    nb = [[] for _ in range(system.n_atoms)]
    for i, j in system.bonds.tolist():
        nb[i].append(j)
        nb[j].append(i)
    shell = set(si.tolist())
    for s in si.tolist():
        for o in nb[s]:
            shell.add(o)
            shell.update(h for h in nb[o] if system.types[h] == "HOY")
    return np.array(sorted(shell), int)
