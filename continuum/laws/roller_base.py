"""What the three rough rollers share: the depth an impact can reach, the release and the length scale.

`RoughRoller` (averaged summits on a grid, optionally on the elastic half-space), `RigidRoughRoller`
(averaged summits on a rigid substrate, footprint tables) and `DiscreteRoughRoller` (a seeded
realisation of individual summits) hold the contact state in different ways; around it they do the
same things, written here once:

- before each contact (`prepare`) they estimate the deepest approach the impact can reach, the depth
  at which the rigid approach branch has absorbed the impact's kinetic energy against its weight
  (`quasi_static_depth`, `continuum.laws.depth.absorbing_depth`), times `depth_safety`, and size
  their grid or tables for it (`size_for`);
- the contact ends at `end_gap`, where the law books what is left of its losses (`on_release`);
- the length that scales the driver's tolerances is the sized depth without its safety factor, or
  the release stretch where that is larger (`length_scale`);
- the grid laws cache the trial state of one gap (`_state`), lay the same line grid with its
  half-space (`_line_grid`) and record each contact's grid the same way (`_record_grid`).

The hooks, where the rollers differ:

- `approach_forces(depths)`: first-approach forces (N) at depths (m below the datum), an array;
- `first_depth_step()`: the depth search's first step (m);
- `depth_search_name`: what a refused depth search calls the contact (a too-deep approach refuses the
  scene, a `SceneError` naming surfaces.roughness.sigma, for every roller);
- `size_for(depth, speed)`: size the grid or the tables for a design depth (m);
- `sized_depth`: the design depth the grid or tables were sized for (m);
- `_evaluate(gap)`: the trial state at a gap (grid laws; `_state` caches it).

Every law sets `sigma`, `z_top`, `release_stretch`, `end_gap` and `depth_safety`; the averaged
laws take them from their `SummitSurface` (`_take_surface`).
"""
from __future__ import annotations

from abc import abstractmethod

import numpy as np

from ..elastic.halfspace import LineHalfSpace
from .base import ContactLaw
from .costs import beyond_range
from .depth import DEPTH_LIMIT_SIGMAS, absorbing_depth


class RoughRollerBase(ContactLaw):
    """A roller of radius R and length l (m) on rough summits: the scaffolding, not the contact state."""

    touch_gap = 0.0
    bound_is_final = True
    has_history = True
    has_rigid_approach = True

    #: the name a refused depth search gives the contact
    depth_search_name = "rough contact"

    # ------------------------------------------------------------------ hooks
    @abstractmethod
    def approach_forces(self, depths: np.ndarray) -> np.ndarray:
        """Forces (N) of a monotonic first approach to each depth (m below the datum) on a rigid substrate."""

    def first_depth_step(self) -> float:
        """First step (m) of the depth search: 1/32 of sigma or of the release stretch (at least 1e-3 sigma)."""
        return min(self.sigma, max(self.release_stretch, 1e-3 * self.sigma)) / 32.0

    @abstractmethod
    def size_for(self, depth: float, speed: float) -> None:
        """Size the grid or the tables for an impact at `speed` (m/s) that can reach `depth` (m)."""

    @property
    @abstractmethod
    def sized_depth(self) -> float:
        """The design depth (m) the grid or the tables were last sized for."""

    def _evaluate(self, gap: float):
        """The trial state at `gap` with the stored history (the grid laws, which read it through `_state`)."""
        raise NotImplementedError(f"{type(self).__name__} keeps no cached trial state")

    # ------------------------------------------------------------------ shared
    def _start_run_counters(self, contact_count: type = float) -> None:
        """The run-wide counters every roller's record reports, at their start: the most summits attached at once
        (`contact_count`: float, an expected number, for the averaged laws; int, a count, for the discrete one),
        the largest nominal pressure (Pa), and whether a contact reached the edge of the grid or footprint."""
        self.max_contacts = contact_count(0)
        self.max_pressure = 0.0
        self.edge_touched = False

    def _take_surface(self, surface) -> None:
        """The lengths an averaged law reads from its `SummitSurface`."""
        self.surface = surface
        self.sigma = surface.stats.sigma
        self.z_top = float(surface.z_max)                     # tallest summit above the mean plane (m)
        self.release_stretch = float(surface.release_stretch)
        self.reach = float(surface.reach)                     # non-contact attraction range (m)
        self.touch_gap = self.reach
        self.end_gap = max(self.release_stretch, self.reach)
        #: "tabulated" (GW tables of JKR or Hertz summits) or "generic" (quadrature of any summit law)
        self.surface_kind = surface.kind

    def prepare(self, mass: float, speed: float, gravity: float) -> None:
        """Size the grid or the tables for an impact of `mass` (kg) at `speed` (m/s) before the contact starts."""
        self.size_for(self.depth_safety * self.quasi_static_depth(0.5 * mass * speed**2, mass * gravity), speed)

    def quasi_static_depth(self, energy: float, weight: float = 0.0) -> float:
        """Approach (m, below the datum) at which the rigid approach branch has absorbed `energy` (J)
        against `weight` (N); beyond the model's range (`DEPTH_LIMIT_SIGMAS`) it is refused."""
        first = self.first_depth_step()

        def search():
            return absorbing_depth(self.approach_forces, energy, first_step=first, weight=weight,
                                   max_depth=self.z_top + DEPTH_LIMIT_SIGMAS * self.sigma, what=self.depth_search_name)

        return beyond_range(search, self.sigma)

    def release_gap(self):
        return self.end_gap

    def on_release(self):
        return self.dissipated(self.end_gap)

    def length_scale(self, mass, speed):
        return max(self.sized_depth / self.depth_safety, self.release_stretch)

    def _state(self, gap: float):
        """The trial state at `gap` (`_evaluate`), cached on the gap until `accept` or a reset clears it."""
        if self._cache_gap == gap:
            return self._cache
        state = self._evaluate(gap)
        self._cache_gap, self._cache = gap, state
        return state

    # ------------------------------------------------------------------ the grid laws
    def _line_grid(self, half: float) -> None:
        """n cells across |x| <= half (m) and, with the half-space on, its influence coefficients."""
        self.dx = 2.0 * half / self.n
        self.x = (np.arange(self.n) - (self.n - 1) / 2.0) * self.dx
        self.hs = LineHalfSpace(self.dx, self.n, self.e_star, x_ref=self.length) if self.use_half_space else None

    def _record_grid(self, depth: float, speed: float) -> None:
        """Record the grid laid for a contact with design depth `depth` (m) at `speed` (m/s)."""
        self.grid_history.append({"half_width": float(self.x[-1] + self.dx / 2), "dx": self.dx,
                                  "design_depth": depth, "speed": speed})

    def _grid_record(self) -> dict:
        """The diagnostics' record of the grids: the last three laid, and how many contacts."""
        return {"grids": self.grid_history[-3:], "contacts_seen": len(self.grid_history)}

    def _averaged_summits_record(self) -> dict:
        """describe()'s summit statistics and per-summit scales of an averaged law (SI)."""
        s = self.surface
        return {"sigma": s.stats.sigma, "summit_density": s.stats.density, "summit_radius": s.stats.radius,
                "z_max": self.z_top, "delta_c": s.delta_c, "release_stretch": self.release_stretch,
                "pull_off_force_per_summit": s.pull_off_force, "loop_energy_per_summit": s.loop_energy}

