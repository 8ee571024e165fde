"""OTS chains grafted on a silica asperity's dome (:func:`graft_dome`): the pull-off workflow's coated tip.

The chains stand along the pulling axis (:data:`DOME_CHAIN_TILT_DEG`), so their *lateral* packing is what limits
coverage: sites are a largest set of dome silanols no two closer than a chain spacing in projection
(:func:`_independent_sites`, exact branch and bound or randomised min-degree greedy), the ones nearest the apex
kept; where the dome's silanols pair up closer than chains pack, the chains lean off their sites
(:func:`_offset_sites`) within the disk :func:`md.build.sam.head_offset_disk` allows. Every chain is checked clear
of the dome above its site (:func:`_clearance_check`). The chains themselves are built by :func:`md.build.ots_sam`.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from md.build.sam import ots_sam
from md.system.atoms import as_system
from md.system.topology import System, minimum_image, with_groups

__all__ = ["graft_dome", "GRAFT_SPACINGS_A", "DOME_CHAIN_TILT_DEG", "HEAD_CLEARANCE_A"]


#: lateral spacing of grafted chains on the asperity: tried in this order until the cap holds the target coverage
#: (a crystalline dome's silanols pair up at 4.3-4.4 A in projection; polyethylene's nearest chains are 4.46 A
#: apart, TraPPE CH2 sigma 3.95 A); the builder's default for flat SAMs is 4.4 A
GRAFT_SPACINGS_A = (4.4, 4.35, 4.3)
#: the dome's chains stand along the pulling axis (the flat SAM's builder default is 15 deg off it)
DOME_CHAIN_TILT_DEG = 0.0
#: when a chain is added to the offset dome (:func:`_offset_sites`), the chains within this lateral distance of it
#: may move to make room (two spacings: farther chains would only pass on a push they have room to absorb)
LOCAL_SPREAD_A = 9.0
#: the pull-off cell is periodic in x and y
PBC_XY = (True, True, False)
#: least distance (A) of an offset chain's head atoms from any heavy atom but its anchor O (the flat SAM's builder
#: starts with none closer than 2.6 A)
HEAD_CLEARANCE_A = 1.7


def _independent_sites(xy: np.ndarray, cell_xy, spacing: float, order: np.ndarray, exact_max: int = 60,
                       restarts: int = 200, seed: int = 0) -> list[int]:
    """A largest set of sites (indices into ``xy``) no two closer than ``spacing`` laterally (periodic): exact
    branch and bound up to ``exact_max`` sites, else the best of ``restarts`` randomised min-degree greedy passes.
    Ties prefer sites early in ``order`` (nearest the apex)."""
    n = len(xy)
    d = xy[:, None, :] - xy[None, :, :]
    d -= np.asarray(cell_xy)[None, None, :] * np.round(d / np.asarray(cell_xy)[None, None, :])
    close = (np.hypot(d[..., 0], d[..., 1]) < spacing) & ~np.eye(n, dtype=bool)
    adj = [set(np.flatnonzero(close[i]).tolist()) for i in range(n)]
    rank = {int(i): r for r, i in enumerate(order)}
    if n <= exact_max:
        best: list[list[int]] = [[]]

        def rec(cand: set, chosen: list):
            if len(chosen) + len(cand) <= len(best[0]):
                return
            if not cand:
                best[0] = list(chosen)
                return
            v = max(cand, key=lambda u: (len(adj[u] & cand), -rank[u]))
            if not adj[v] & cand:
                rec(cand - {v}, chosen + [v])
                return
            rec(cand - adj[v] - {v}, chosen + [v])
            rec(cand - {v}, chosen)
        rec(set(range(n)), [])
        return sorted(best[0], key=lambda i: rank[i])
    rng = np.random.default_rng(seed)
    best_set: list[int] = []
    for it in range(restarts):
        cand = set(range(n))
        chosen = []
        noise = rng.random(n) if it else np.zeros(n)
        while cand:
            v = min(cand, key=lambda u: (len(adj[u] & cand) + noise[u], rank[u]))
            chosen.append(v)
            cand -= adj[v] | {v}
        if len(chosen) > len(best_set):
            best_set = chosen
    return sorted(best_set, key=lambda i: rank[i])


def _clearance_check(asp: System, chain_length: int, tilt_deg: float = 0.0, clearance_A: float = 2.6):
    """A function ``(sites, offsets=None) -> bool array``: True for the sites whose chain -- straight, ``tilt_deg``
    from +z towards +x, as :func:`md.build.ots_sam` grafts it, moved laterally by ``offsets`` (n x 2, A; see
    ``ots_sam(head_offsets=...)``) -- keeps ``clearance_A`` from every heavy atom of the asperity from 4 A above
    the anchor O to the chain's end. Near the rim of a stepped dome a chain along the pulling axis can run into the
    dome above its site (an 80 deg cap at smoke without this check: an overlap the minimiser cannot undo). The
    asperity's neighbour tree is built once per call of this factory."""
    from scipy.spatial import cKDTree

    t = math.radians(tilt_deg)
    axis = np.array([math.sin(t), 0.0, math.cos(t)])
    heavy = np.flatnonzero(~np.isin(asp.types, ["HOY"]))
    tree = cKDTree(asp.positions[heavy])
    length = 1.54 * math.cos(math.radians(33.0)) * (chain_length + 1)     # all-trans axial length, A
    line = np.arange(4.0, length + 0.5, 0.7)[:, None] * axis[None, :]

    def check(sites: np.ndarray, offsets: np.ndarray | None = None) -> np.ndarray:
        ok = np.ones(len(sites), bool)
        for k, site in enumerate(np.asarray(sites, int)):
            base = asp.positions[site].copy()
            if offsets is not None:
                base[:2] += offsets[k]
            hits = tree.query_ball_point(base + line, clearance_A)
            ok[k] = not any(heavy[h] != site for hs in hits for h in hs)
        return ok
    return check


def _chain_clearance(asp: System, sites: np.ndarray, chain_length: int, tilt_deg: float = 0.0,
                     clearance_A: float = 2.6) -> np.ndarray:
    """:func:`_clearance_check` for the chains standing on their sites."""
    return _clearance_check(asp, chain_length, tilt_deg, clearance_A)(sites)


def _spread_chains(xy: np.ndarray, cell_xy, spacing: float, centre: np.ndarray, radius: float,
                   start: np.ndarray | None = None, free: np.ndarray | None = None,
                   iterations: int = 200) -> np.ndarray | None:
    """Lateral offsets (n x 2, A) inside the disk (``centre``, ``radius``) that put the chains standing on the
    sites ``xy`` at least ``spacing`` apart laterally (periodic), or None if ``iterations`` rounds of pairwise
    pushes (each chain pushed half the overlap away from every chain too close, then projected back onto the disk)
    do not get there. Starts from the offsets ``start`` (zero if None); only the chains flagged in ``free`` (all
    if None) move. Deterministic: no random numbers."""
    d = np.zeros(xy.shape, float) if start is None else np.array(start, float)
    idx = np.arange(len(xy)) if free is None else np.flatnonzero(free)
    target = spacing + 0.02                       # a little beyond, so that the last push does not stop short

    def gaps(p, rows):
        v = minimum_image(p[rows, None, :] - p[None, :, :], cell_xy, PBC_XY)
        r = np.hypot(v[..., 0], v[..., 1])
        r[np.arange(len(rows)), rows] = np.inf
        return v, r

    for _ in range(iterations):
        v, r = gaps(xy + d, idx)
        if r.min() >= spacing:
            break
        over = np.where(r < target, 0.5 * (target - r), 0.0)
        push = (over[..., None] * v / np.maximum(r, 1e-9)[..., None]).sum(axis=1)
        rel = d[idx] + push - centre
        n = np.hypot(rel[:, 0], rel[:, 1])
        d[idx] = centre + rel * np.minimum(1.0, radius / np.maximum(n, 1e-12))[:, None]
    _, r = gaps(xy + d, np.arange(len(xy)))
    return d if r.min() >= spacing else None


def _offset_sites(asp: System, sites: np.ndarray, order: np.ndarray, n_target: int, chain_length: int,
                  spacing: float) -> tuple[list[int], np.ndarray]:
    """Sites (indices into ``sites``, apex first) and lateral chain offsets for a dome whose silanols sit closer
    than chains pack: sites are taken apex first and kept when the chains so far, the ones within
    :data:`LOCAL_SPREAD_A` of the new one moved within :func:`md.build.sam.head_offset_disk`
    (:func:`_spread_chains`), still stand ``spacing`` apart, clear of the dome (:func:`_clearance_check`), with
    every head atom (head Si, its two O, the first two CH2) :data:`HEAD_CLEARANCE_A` from every heavy atom but its
    anchor O -- until ``n_target`` chains stand."""
    from scipy.spatial import cKDTree

    from md.build.sam import chain_geometry, head_offset_disk, head_shifts

    L = chain_length
    tpos, ttypes = chain_geometry(L, DOME_CHAIN_TILT_DEG, 0.0)
    centre, radius = head_offset_disk(L, DOME_CHAIN_TILT_DEG, 0.0)
    head = tpos[[k for k, t in enumerate(ttypes) if t in ("SIH", "OC24")] +
                [k for k, t in enumerate(ttypes) if t == "CH2"][:2]]
    clear = _clearance_check(asp, L, DOME_CHAIN_TILT_DEG)
    heavy = np.flatnonzero(asp.types != "HOY")
    tree = cKDTree(asp.positions[heavy])
    cell = np.asarray(asp.cell[:2], float)

    def heads(trial, d):
        return asp.positions[sites[trial]][:, None, :] + head[None, :, :] + head_shifts(d, template=tpos)[:, None, :]

    def head_room(trial, d, moved) -> bool:
        h = heads(trial, d)
        for m in moved:                                   # against the dome
            site = int(sites[trial[m]])
            for hit in tree.query_ball_point(h[m], HEAD_CLEARANCE_A):
                if any(int(heavy[k]) != site for k in hit):
                    return False
        v = minimum_image(h[moved][:, :, None, None, :] - h[None, None, :, :, :], asp.cell, PBC_XY)  # other heads
        r = np.linalg.norm(v, axis=-1)
        r[np.arange(len(moved)), :, moved, :] = np.inf
        return bool(r.min() >= HEAD_CLEARANCE_A)

    xy = asp.positions[sites, :2]
    chosen: list[int] = []
    offsets = np.zeros((0, 2))
    for k in order.tolist():
        trial = chosen + [int(k)]
        near = minimum_image(xy[trial] - xy[k], cell, PBC_XY)
        d = _spread_chains(xy[trial], cell, spacing, centre, radius, start=np.vstack([offsets, [0.0, 0.0]]),
                           free=np.hypot(near[:, 0], near[:, 1]) < LOCAL_SPREAD_A)
        if d is None:
            continue
        moved = np.flatnonzero(np.hypot(*(d - np.vstack([offsets, [np.inf, np.inf]])).T) > 1e-9)
        if not clear(sites[np.array(trial)[moved]], d[moved]).all() or not head_room(trial, d, moved):
            continue
        chosen, offsets = trial, d
        if len(chosen) == n_target:
            break
    return chosen, offsets

def graft_dome(asp: System, *, radius_A: float, max_polar_deg: float, coverage_nm2: float, chain_length: int,
               seed: int) -> tuple[System, dict[str, Any]]:
    """OTS chains of ``chain_length`` CH2 on the dome silanols of the asperity ``asp`` (tip up, dome radius
    ``radius_A``) within ``max_polar_deg`` of the apex, at ``coverage_nm2`` chains per nm^2 of the cap's projected
    area (the chains point along the pulling axis, so
    their lateral packing is what counts): the sites are a largest set no two closer than the spacing laterally
    (:data:`GRAFT_SPACINGS_A`, tried in order until one holds the target), the ones nearest the apex kept.
    Where chains standing on their sites fall short of the target (dome silanols come in close pairs), the
    chains lean off their sites (:func:`_offset_sites`, at 4.4 A) if that holds more. Sites are chosen as a
    largest independent set, not in random order: a random sequential choice packs well below the target."""
    R = float(radius_A)
    centre = np.array(asp.info["centre_A"])
    dome = np.asarray(asp.group("silanol_O_dome"), int)
    p = asp.positions[dome] - centre
    cosang = p[:, 2] / np.maximum(np.linalg.norm(p, axis=1), 1e-9)
    keep = cosang >= math.cos(math.radians(max_polar_deg))
    sites, cos_k = dome[keep], cosang[keep]
    all_sites, all_cos = sites, cos_k
    clear = _chain_clearance(asp, sites, chain_length, DOME_CHAIN_TILT_DEG)
    n_blocked = int((~clear).sum())
    sites, cos_k = sites[clear], cos_k[clear]
    if not len(sites):
        raise ValueError(f"no dome silanols within {max_polar_deg:g} deg (graft_max_polar_deg) of the apex: "
                         "nothing to graft on")
    cap = math.pi * (R * math.sin(math.radians(max_polar_deg))) ** 2      # projected area, A^2
    cell_area = float(asp.cell[0] * asp.cell[1])
    n_target = max(1, int(round(coverage_nm2 * cap / 100.0)))
    order = np.argsort(-cos_k, kind="stable")               # apex first
    xy = asp.positions[sites, :2]
    chosen, spacing = [], GRAFT_SPACINGS_A[0]
    for spacing in GRAFT_SPACINGS_A:
        chosen = _independent_sites(xy, asp.cell[:2], spacing, order, seed=seed)
        if len(chosen) >= n_target:
            break
    chosen = chosen[:n_target]
    grafts = [sites[np.array(chosen[:n], int)] for n in range(len(chosen), 0, -1)]
    offsets: dict[int, np.ndarray] = {}
    if len(chosen) < n_target:
        # the dome's silanols pair up closer than chains pack: let the chains lean off their sites
        picked, d = _offset_sites(asp, all_sites, np.argsort(-all_cos, kind="stable"), n_target, chain_length,
                                  GRAFT_SPACINGS_A[0])
        if len(picked) > len(chosen):
            grp = all_sites[np.array(picked, int)]
            grafts, spacing = [grp], GRAFT_SPACINGS_A[0]
            offsets = {int(i): d[k] for k, i in enumerate(grp)}
    last = None
    for grp in grafts:
        n = len(grp)
        try:
            sam = as_system(ots_sam(with_groups(asp, graft_sites=grp), coverage=(n + 0.49) / (cell_area / 100.0),
                                    chain_length=chain_length, seed=seed, site_group="graft_sites",
                                    min_spacing=spacing - 1e-6, tilt_deg=DOME_CHAIN_TILT_DEG,
                                    head_offsets=offsets or None))
            break
        except ValueError as exc:
            last = exc
    else:
        raise ValueError(f"no OTS chain fits on the dome: {last}")
    chains = int(sam.info["chains"])
    return sam, {"chains": chains, "requested_chains": n_target, "cap_projected_area_nm2": cap / 100.0,
                 "chains_per_projected_nm2": chains / (cap / 100.0), "sites": int(len(sites)),
                 "sites_blocked_by_the_dome": n_blocked, "min_spacing_A": float(spacing),
                 "chain_offset_max_A": float(sam.info.get("head_offset_max_A", 0.0))}
