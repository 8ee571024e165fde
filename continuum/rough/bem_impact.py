"""A body dropped on a rough patch whose contact force is a tabulated hysteretic law: the approach branch and the
retraction branch of a quasi-static cycle (`continuum.rough.quasistatic.ForceCycle`, from the boundary-element
reference or from a summit level): the quasi-static energy balance of such an impact, and the short roller the
benchmark drops (`Roller`, `roller_gw_cycle`). The impact itself is integrated by the project's driver on the table
as a contact law (`continuum.dynamics.tabulated_cycle`, benchmarks/accuracy_impact.py); the balance here is its check.

The contact force is rate-independent (each state an equilibrium: the impact model's own assumption, Johnson,
*Contact Mechanics* (1985) 11.1, valid while the impact lasts much longer than the elastic waves take to cross the
contact), so the motion conserves K + the work of the tabulated force exactly (gravity's work across the contact
range, m g times a few nm, aside):

* approach: K(s) = K0 - W_app(s), W_app(s) = int_s^{s_start} F_app ds' (F > 0 compressive); the body turns where
  K = 0 (`turn_for_energy`);
* retraction from the turn s_t: K(s) = K0 - W_app(s_t) + int_{s_t}^s F_ret ds'. The body leaves with
  K1 = K0 - W_loop and restitution e = sqrt(K1 / K0) (e^2 = 1 - W_loop/K0) unless K reaches zero on the way out:
  then the adhesive tension holds it (stuck, the capture of Thornton & Ning, Powder Technol. 99 (1998) 154).

The retraction depends on where the body turns, so a level's cycle must turn at the body's turn: the reference's
cycle fixes K0 (the body turns at its deepest state), and a cheap level is rerun to its own turn
(`impact_at_energy`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from nanoimpact.errors import InputError

from .quasistatic import ForceCycle, gw_cycle, separation_path

__all__ = ["ImpactOutcome", "approach_work", "turn_for_energy", "impact_outcome", "impact_at_energy", "STANDARD_G",
           "Roller", "roller_gw_cycle"]

#: Standard gravity (m/s^2), for drop and rebound heights.
STANDARD_G = 9.80665


@dataclass(frozen=True)
class ImpactOutcome:
    """One quasi-static impact through a tabulated cycle (SI)."""

    impact_energy: float
    """Kinetic energy at the start of the force range, K0 (J)."""
    turn_separation: float
    """Separation at which the body turns (m)."""
    loss: float
    """Energy the loop took, K0 - K1 for a rebound (J); for a stuck body the energy it was short of leaving with."""
    rebound_energy: float
    """Kinetic energy leaving the force range, K1 (J); 0 when stuck."""
    stuck: bool
    """Whether the adhesive tension stops the body on its way out."""
    least_retraction_energy: float
    """Smallest kinetic energy met on the way out (J); <= 0 when stuck."""

    @property
    def restitution(self) -> float:
        """e = sqrt(K1/K0); 0 when stuck."""
        return math.sqrt(self.rebound_energy / self.impact_energy) if self.impact_energy > 0 else math.nan

    def rebound_height(self, drop_height: float) -> float:
        """First-rebound height (m) of a body dropped from `drop_height` (m) above the force range: e^2 h0."""
        return drop_height * self.rebound_energy / self.impact_energy

    def to_json(self) -> dict:
        return {"impact_energy_J": self.impact_energy, "turn_separation_m": self.turn_separation,
                "loss_J": self.loss, "rebound_energy_J": self.rebound_energy, "restitution": self.restitution,
                "stuck": self.stuck, "least_retraction_energy_J": self.least_retraction_energy}


def _cumulative(s: np.ndarray, f: np.ndarray) -> np.ndarray:
    """int_{s[0]}^{s[k]} f ds by trapezoids, k = 0..n-1."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(s))])


def approach_work(cycle: ForceCycle) -> np.ndarray:
    """W_app at each approach state (J): the work the body does against the contact force from the start down to
    that state (the separation decreases, so W_app = -int F ds along the path)."""
    k = cycle.turn + 1
    return -_cumulative(cycle.separation[:k], cycle.force[:k])


def turn_for_energy(cycle: ForceCycle, energy: float) -> float:
    """Separation (m) at which a body arriving with kinetic energy `energy` (J) turns on the cycle's approach branch:
    the first state where W_app reaches it, linear between tabulated states. InputError when the table's approach
    does not absorb that much (its deepest state is too shallow)."""
    if not (np.isfinite(energy) and energy > 0):
        raise InputError("impact_energy", energy, "a positive finite energy (J)")
    w = approach_work(cycle)
    s = cycle.separation[:cycle.turn + 1]
    hit = np.nonzero(w >= energy)[0]
    if hit.size == 0:
        raise InputError("impact_energy", energy, f"<= {w.max():.4g} J, the work the tabulated approach absorbs "
                                                  f"down to its deepest state {s[-1]:.4g} m")
    k = int(hit[0])
    if k == 0:
        return float(s[0])
    frac = (energy - w[k - 1]) / (w[k] - w[k - 1])
    return float(s[k - 1] + frac * (s[k] - s[k - 1]))


def impact_outcome(cycle: ForceCycle, energy: float | None = None) -> ImpactOutcome:
    """The impact of a body that turns at the cycle's deepest state. `energy` (J): its kinetic energy at the start
    (default: exactly the approach work to the deepest state); the difference K0 - W_app(turn) carries into the
    retraction, so pass the energy only for a cycle rerun to the turn `turn_for_energy` found."""
    w_turn = float(approach_work(cycle)[-1])
    k0 = w_turn if energy is None else float(energy)
    if not (np.isfinite(k0) and k0 > 0):
        raise InputError("impact_energy", k0, "a positive finite energy (J): the tabulated approach must push back")
    t = cycle.turn
    s, f = cycle.separation[t:], cycle.force[t:]
    k_out = k0 - w_turn + _cumulative(s, f)
    least = float(np.min(k_out[1:])) if k_out.size > 1 else float(k_out[0])
    stuck = bool(least <= 0.0)
    k1 = 0.0 if stuck else float(k_out[-1])
    return ImpactOutcome(k0, float(cycle.separation[t]), float(k0 - k_out[-1]), k1, stuck, least)


def impact_at_energy(cycle_to: Callable[[np.ndarray], ForceCycle], energy: float, start: float, step: float,
                     deepest: float) -> tuple[ImpactOutcome, ForceCycle]:
    """Impact of kinetic energy `energy` (J) on a level whose cycle along any path `cycle_to(path)` is cheap: the
    cycle to `deepest` (m) locates the turn, and the level is rerun from `start` to that turn in steps of at most
    `step` (m), so its retraction starts where the body turns. (outcome, the rerun cycle)."""
    first = cycle_to(separation_path(start, deepest, step))
    turn = turn_for_energy(first, energy)
    if turn >= start:
        raise InputError("impact_energy", energy, "> 0 J of approach work within the first step")
    cycle = cycle_to(separation_path(start, turn, step))
    return impact_outcome(cycle, energy), cycle


# --- a short roller lying across the patch -------------------------------------------------------------------------

@dataclass(frozen=True)
class Roller:
    """A short rigid roller (a cylinder of `radius` R, m) lying across a square periodic patch of side `size` L (m):
    its axis along the patch's second coordinate y, over x = L/2, its length the patch's side. Near its lowest line
    the roller's surface lies drop(x) = (x - L/2)^2 / (2R) above it (the paraboloidal approximation of Hertz's
    theory, Johnson, *Contact Mechanics* (1985) 4.1, for |x - L/2| << R). The patch is periodic across the roller's
    length, so the roller has no ends: it is one cell of an infinite row (what a boundary element on a periodic
    cell can hold). Against the rough patch it counts as the composite surface heights(x, y) - drop(x), the
    rough surface and the roller's curvature in one gap; R is chosen so that the band within reach at the deepest
    state stays inside the cell (`reach_band`), which keeps the periodic images of the contact apart."""

    radius: float
    size: float

    def drop(self, x, grid: int) -> np.ndarray:
        """drop(x) (m) less its mean over the cell's `grid` columns, so the composite surface keeps the rough
        map's zero mean (the reference removes each map's mean: the same plane then holds for every level)."""
        cols = np.arange(grid) * self.size / grid
        mean = float(np.mean((cols - 0.5 * self.size) ** 2)) / (2 * self.radius)
        return (np.asarray(x, float) - 0.5 * self.size) ** 2 / (2 * self.radius) - mean

    def heights(self, h: np.ndarray) -> np.ndarray:
        """The composite surface (m) of a rough map `h` (zero mean, axis 0 = x) under the roller."""
        n = h.shape[0]
        return np.asarray(h, float) - self.drop(np.arange(n) * self.size / n, n)[:, None]

    def mass(self, density: float) -> float:
        """Mass (kg) of the roller at `density` (kg/m^3): pi R^2 L."""
        return density * math.pi * self.radius**2 * self.size

    def reach_band(self, h: np.ndarray, separation: float, reach: float) -> tuple[float, float]:
        """(x_min/L, x_max/L) of the columns of the composite surface within `reach` (m) of a flat at `separation`."""
        c = self.heights(h)
        cols = np.nonzero((c > separation - reach).any(axis=1))[0]
        n = h.shape[0]
        return (float(cols.min()) / n, float(cols.max()) / n) if cols.size else (math.nan, math.nan)


def roller_gw_cycle(surface, roller: Roller, grid: int, path, summit_mean_height: float) -> ForceCycle:
    """The GW mean field (`quasistatic.gw_cycle`) under the roller: the patch cut into `grid` strips parallel to its
    axis, strip j of nominal area L^2/grid at separation path + drop(x_j) from the flat, the strips summed (no elastic
    coupling between strips, as between summits)."""
    path = np.asarray(path, float)
    drops = roller.drop(np.arange(grid) * roller.size / grid, grid)
    area = roller.size * roller.size / grid
    cycles = [gw_cycle(surface, area, path + d, summit_mean_height) for d in drops]
    return ForceCycle(path, np.sum([c.force for c in cycles], axis=0),
                      np.sum([c.contact_area for c in cycles], axis=0), cycles[0].turn)
