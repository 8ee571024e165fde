"""Quasi-static approach and retraction of a rough surface under displacement control: force, real contact area
and the energy lost per cycle against the rigid separation, for the summit models.

A rigid flat counter-surface sits at height s (m) above the mean plane of the rough surface's heights; it moves
down from `start` to `deepest` and back (`separation_path`), slowly enough that every state is an equilibrium.
Each summit of height z has approach delta = z - s and follows the branches of its summit law
(`continuum.rough.branch_laws.SummitLaw`: the approach branch until it jumps in, the retreat branch until it jumps
out) with the one-threshold history of `continuum.rough.gw_branches`: after each state
zeta <- max(min(zeta, s + delta_in), s + delta_out), zeta = +inf before anything attached, and the summits at or
above zeta sit on the retreat branch. Two summit models:

* `gw_cycle`: the Greenwood-Williamson mean field, a `GWBranchSurface` (Gaussian summit heights about their own
  mean plane, all summits of one tip radius) times the nominal area (Greenwood & Williamson, Proc. R. Soc. Lond.
  A 295 (1966) 300);
* `discrete_cycle`: a given set of summits, each at its own height, summed one by one.

Both ignore the elastic coupling of neighbouring contacts and the bulk's deflection, exactly as the impact model
does; the boundary-element reference (`continuum.rough.bem_reference`) keeps both. Outputs (`ForceCycle`): the
pull-off force is the largest tension met on retraction (displacement control), the hysteresis energy the
area -closed_integral F ds of the force-separation loop (trapezoids along the sampled path; a force jump inside
a step of width h contributes an error of at most |jump| h / 2).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from nanoimpact.errors import InputError

__all__ = ["ForceCycle", "separation_path", "path_turn", "gw_cycle", "discrete_cycle", "thresholds"]


@dataclass(frozen=True, eq=False)
class ForceCycle:
    """Force and real contact area along a closed approach-retraction path (SI).

    `separation` runs from the start down to the deepest state (index `turn`) and back to the start."""

    separation: np.ndarray
    """Rigid separation s of the flat above the mean plane of the heights (m), one entry per state."""
    force: np.ndarray
    """Total force on the flat (N; + compressive, - adhesive)."""
    contact_area: np.ndarray
    """Real contact area (m^2)."""
    turn: int
    """Index of the deepest state."""

    @property
    def pull_off_force(self) -> float:
        """Largest tension on retraction (N, >= 0): the pull-off force under displacement control."""
        return float(max(0.0, -np.min(self.force[self.turn:])))

    @property
    def hysteresis_energy(self) -> float:
        """Energy lost per cycle, -closed_integral F ds (J), by trapezoids along the path."""
        s, f = self.separation, self.force
        return float(-np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(s)))

    def to_json(self) -> dict:
        return {"separation_m": self.separation.tolist(), "force_N": self.force.tolist(),
                "contact_area_m2": self.contact_area.tolist(), "turn": int(self.turn),
                "pull_off_force_N": self.pull_off_force, "hysteresis_energy_J": self.hysteresis_energy}


def separation_path(start: float, deepest: float, step: float) -> np.ndarray:
    """Separations (m) from `start` down to `deepest` in steps of at most `step`, then back up to `start`."""
    if not (np.isfinite(start) and np.isfinite(deepest) and deepest < start):
        raise InputError("separation_path.deepest", deepest, f"finite and below start = {start!r} (m)")
    if not step > 0:
        raise InputError("separation_path.step", step, "> 0 (m)")
    n = int(np.ceil((start - deepest) / step))
    down = np.linspace(start, deepest, n + 1)
    return np.concatenate([down, down[-2::-1]])


def path_turn(path: np.ndarray) -> int:
    """Index of the deepest state of a closed approach-retraction path; InputError for any other path."""
    k = int(np.argmin(path))
    if not (np.all(np.diff(path[:k + 1]) < 0) and np.all(np.diff(path[k:]) > 0) and path[0] == path[-1]):
        raise InputError("path", f"{path.size} separations", "must decrease strictly to its deepest state, then "
                                                             "increase strictly back to its start")
    return k


def thresholds(path: np.ndarray, delta_in: float, delta_out: float) -> np.ndarray:
    """History threshold zeta after each state of `path` (m; +inf while nothing has attached): summits at or
    above it are on the retreat branch. zeta <- max(min(zeta, s + delta_in), s + delta_out)."""
    zeta, out = np.inf, np.empty(path.size)
    for k, s in enumerate(path):
        zeta = max(min(zeta, s + delta_in), s + delta_out)
        out[k] = zeta
    return out


def gw_cycle(surface, area: float, path, summit_mean_height: float) -> ForceCycle:
    """Quasi-static cycle of a GW mean-field surface (`continuum.rough.gw_branches.GWBranchSurface`) of nominal
    area `area` (m^2) along `path` (separations above the heights' mean plane, m); the summits' own mean plane
    lies `summit_mean_height` (m) above that plane."""
    path = np.asarray(path, float)
    turn = path_turn(path)
    d = path - summit_mean_height
    zeta = thresholds(d, surface.delta_in, surface.delta_out)
    force = area * np.asarray(surface.pressure(d, zeta), float)
    contact = area * np.asarray(surface.contact_fraction(d, zeta), float)
    return ForceCycle(path, force, contact, turn)


def discrete_cycle(law, heights, path) -> ForceCycle:
    """Quasi-static cycle of discrete summits of heights `heights` (m, above the mean plane of the map), each
    following `law` (a `continuum.rough.branch_laws.SummitLaw`), along `path` (m)."""
    path = np.asarray(path, float)
    z = np.asarray(heights, float).ravel()
    turn = path_turn(path)
    deepest = float(np.max(z) - path[turn]) if z.size else 0.0
    if deepest > law.delta_max:
        raise InputError("path", f"deepest {path[turn]:.3g} m", f"compresses the tallest summit by {deepest:.3g} m, "
                                                                 f"beyond its law's table ({law.delta_max:.3g} m)")
    zeta = thresholds(path, law.delta_in, law.delta_out)
    x = z[None, :] - path[:, None]                               # (states, summits) approaches
    attached = z[None, :] >= zeta[:, None]
    force = np.where(attached, law.force(x, "retreat"), law.force(x, "approach")).sum(axis=1)
    radius = np.where(attached, law.contact_radius(x, "retreat"), law.contact_radius(x, "approach"))
    return ForceCycle(path, force, np.pi * np.sum(radius * radius, axis=1), turn)
