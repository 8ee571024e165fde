"""Boundary-element reference for adhesive rough contact: Tamaas' FFT-based boundary elements with a cohesive law.

The rough surface (a periodic height map) is rigid; the counter-body is an elastic half-space of contact modulus
E* with a flat surface, held at rigid separation s above the mean plane of the heights (the periodic solution's
mean elastic displacement is zero, so the mean gap equals s for a map of zero mean). Tamaas (Frérot, Anciaux,
Rey, Pham-Ba & Molinari, J. Open Source Softw. 5 (2020) 2121; PyPI `tamaas`) solves each state by the
Polonsky-Keer conjugate-gradient method (Polonsky & Keer, Wear 231 (1999) 206) on the gap, with the adhesion
functional of Rey, Anciaux & Molinari, Comput. Mech. 60 (2017) 69. No summit idealisation: every contact grows,
merges and interacts elastically with the others through the half-space (and, the map being periodic, with
its periodic images: the cell's size is part of the reference).

Cohesive law: Tamaas' `MaugisAdhesionFunctional` is Dugdale's, a constant tension gamma/rho wherever the gap is
below rho, work of separation gamma. It is given the project's Maugis-Dugdale summit law exactly
(`continuum.rough.branch_laws`): sigma0 = 1.03 dgamma/z0 (Johnson & Greenwood, J. Colloid Interface Sci. 192
(1997) 326, matching the peak tension of the Lennard-Jones law of equilibrium spacing z0), so
`surface_energy` = dgamma and `rho` = dgamma/sigma0 = z0/1.03. The reference and the summit models then differ
only by the summit idealisation and the averaging, not by the cohesive law.

Quasi-static path: each state starts from the previous solution (the solver keeps its fields), so the
approach follows the metastable branch until the contact snaps in and the retraction until it snaps out, giving
the hysteresis. A state in which no point is within rho of the flat, reached from a free state, is free exactly
(zero traction, zero displacement) and is not solved (the solver's complementarity error is undefined without
contact). Convergence and the discretisation: the Dugdale zone's edge sits on the grid, so forces carry a
first-order error in the pixel size (measured against Maugis' closed form in tests/continuum/test_bem_reference.py); the
cohesive zone must span several pixels.

Lengths are passed to Tamaas in units of `length_unit` and stresses in units of E* (the solver's tolerances are
relative; this keeps its numbers of order one).
"""
from __future__ import annotations

import importlib
import logging
import time
from dataclasses import dataclass, field

import numpy as np

from nanoimpact.errors import InputError

from .branch_laws import DUGDALE_FACTOR
from .quasistatic import ForceCycle, path_turn

__all__ = ["BEMContact", "BEMStats", "bem_cycle", "dugdale_range", "require_solver"]

log = logging.getLogger(__name__)


def require_solver(key: str, value) -> None:
    """InputError naming `key` and `value` (the input that asked for the reference) when Tamaas, the boundary-element
    solver, cannot be imported here: one line instead of a traceback from the first solve."""
    try:
        importlib.import_module("tamaas")
    except ImportError as exc:
        raise InputError(key, value, "needs the boundary-element solver Tamaas (pip install tamaas; Linux/macOS "
                                     f"wheels), which is not importable here ({exc})") from None


def dugdale_range(work_of_adhesion: float, z0: float) -> tuple[float, float]:
    """(sigma0 (Pa), rho (m)) of the Dugdale law matching the project's summit law: sigma0 = 1.03 dgamma/z0,
    rho = dgamma/sigma0."""
    sigma0 = DUGDALE_FACTOR * work_of_adhesion / z0
    return sigma0, work_of_adhesion / sigma0


@dataclass(frozen=True)
class BEMStats:
    """How the boundary-element cycle was solved."""

    solves: int
    """States solved by Tamaas."""
    free_states: int
    """States free exactly (nothing within rho of the flat), not solved."""
    unconverged: int
    """Solved states that are not equilibria: in contact with the solver's error above the tolerance, or without
    contact and a traction that is not Dugdale's for the gap."""
    max_error: float
    """Largest solver error among the solved states in contact."""
    seconds: float
    """Wall time of the whole cycle (s)."""
    grid: tuple[int, int]
    pixel_size: float
    """Grid spacing (m)."""
    rho: float
    """Dugdale range given to Tamaas (m)."""
    sigma0: float
    """Dugdale tension (Pa)."""
    notes: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"solves": self.solves, "free_states": self.free_states, "unconverged": self.unconverged,
                "max_error": self.max_error, "seconds": self.seconds, "grid": list(self.grid),
                "pixel_size_m": self.pixel_size, "rho_m": self.rho, "sigma0_Pa": self.sigma0,
                "solver": "tamaas PolonskyKeerRey (gap, gap) + MaugisAdhesionFunctional", **self.notes}


def _check(heights, physical_size, e_star, work_of_adhesion, z0):
    h = np.asarray(heights, float)
    if h.ndim != 2 or min(h.shape) < 8 or not np.all(np.isfinite(h)):
        raise InputError("heights", f"array of shape {h.shape}", "a finite 2-D map with >= 8 points per side")
    for key, v, low in (("e_star", e_star, 0.0), ("z0", z0, 0.0)):
        if not (np.isfinite(v) and v > low):
            raise InputError(key, v, "a positive finite number (SI)")
    if not (np.isfinite(work_of_adhesion) and work_of_adhesion >= 0):
        raise InputError("work_of_adhesion", work_of_adhesion, ">= 0 and finite (J/m^2; 0: no adhesion)")
    size = (float(physical_size),) * 2 if np.ndim(physical_size) == 0 else tuple(map(float, physical_size))
    return h, size


class BEMContact:
    """One periodic rigid height map against an elastic flat, solved state by state with warm starts.

    heights (m, shape (nx, ny); its mean is removed), physical_size (m, one number or (Lx, Ly)), e_star (Pa),
    work_of_adhesion (J/m^2; 0 leaves the adhesion functional out: Hertzian, frictionless contact), z0 (m)."""

    #: Further solver calls (each up to max_iter iterations, from the current fields) for a state in contact
    #: that has not converged: snap-outs of single contacts need more than Tamaas' default 1000 iterations.
    continuations = 8

    def __init__(self, heights, physical_size, e_star: float, work_of_adhesion: float, z0: float, *,
                 tolerance: float = 1e-8, length_unit: float = 1e-9):
        h, size = _check(heights, physical_size, e_star, work_of_adhesion, z0)
        self.e_star, self.unit, self.tolerance = float(e_star), float(length_unit), float(tolerance)
        self.work_of_adhesion = float(work_of_adhesion)
        self.size, self.shape = size, h.shape
        self.sigma0, self.rho = dugdale_range(work_of_adhesion, z0) if work_of_adhesion > 0 else (0.0, 0.0)
        self._h = np.ascontiguousarray((h - h.mean()) / length_unit)
        self._top = float(self._h.max())
        self.restarts = self.continued = 0
        self._build()

    def _build(self):
        """A fresh Tamaas model and solver (zero displacement): the cold start."""
        import tamaas as tm

        tm.set_log_level(tm.LogLevel.error)
        self._model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [s / self.unit for s in self.size],
                                                  list(self.shape))
        self._model.E, self._model.nu = 1.0, 0.0       # E* = E/(1 - nu^2) = 1: stresses in units of E*
        self._solver = tm.PolonskyKeerRey(self._model, self._h, self.tolerance, tm.PolonskyKeerRey.gap,
                                          tm.PolonskyKeerRey.gap)
        if self.work_of_adhesion > 0:
            self._adhesion = tm.MaugisAdhesionFunctional(self._h)
            self._adhesion.parameters = {"rho": self.rho / self.unit,
                                         "surface_energy": self.work_of_adhesion / (self.e_star * self.unit)}
            self._solver.addFunctionalTerm(self._adhesion)
        self.free = True

    def reaches(self, separation: float) -> bool:
        """Whether any point of the undeformed map is within the cohesive range of a flat at `separation` (m);
        without adhesion: whether the flat touches it."""
        return separation / self.unit - self._top < self.rho / self.unit

    def solve(self, separation: float) -> dict:
        """Equilibrium at rigid separation `separation` (m) from the previous state: force (N), contact area
        (m^2), solver error, whether it is free and an equilibrium, traction (Pa) and gap (m) fields.

        A state in contact that has not converged is solved on from where it stopped, up to `continuations`
        times (`continued` counts them).
        A state without contact that is no equilibrium (after a snap-out the warm start can stall: the solver's
        error is undefined without contact) is solved once more from a cold start, the unloaded flat, which
        is where a released surface goes; `restarts` counts these. A state that ends free of the cohesive range
        while the undeformed map is out of reach is the exact free state (zero traction)."""
        state = self._state(float(self._solver.solve(separation / self.unit)))
        for _ in range(self.continuations):
            if state["converged"] or state["area"] == 0.0:
                break
            self.continued += 1                         # more iterations from where the last call stopped
            state = self._state(float(self._solver.solve(separation / self.unit)))
        if not state["converged"] and state["area"] == 0.0:
            self.restarts += 1
            self._build()
            state = self._state(float(self._solver.solve(separation / self.unit)))
        if state["free"] and not self.reaches(separation):
            state.update(force=0.0, converged=True, traction=np.zeros_like(state["traction"]))
        return state

    def _state(self, err: float) -> dict:
        gap = np.asarray(self._model.displacement) - self._h
        traction = np.asarray(self._model.traction)
        cell = self.size[0] * self.size[1]
        rho = self.rho / self.unit
        touching = gap <= 1e-9 * max(rho, 1.0)
        self.free = bool(not touching.any() and np.min(gap) >= rho)
        return {"force": self.e_star * float(np.mean(traction)) * cell, "error": err, "free": self.free,
                "converged": bool(err <= self.tolerance or (not touching.any() and self._cohesive(gap, traction))),
                "area": cell * float(np.mean(touching)), "traction": self.e_star * traction, "gap": gap * self.unit}

    def _cohesive(self, gap, traction) -> bool:
        """Whether a state without contact is an equilibrium: the traction is Dugdale's for its own gap (-sigma0
        within rho, zero beyond, to 1e-6 sigma0). The solver's complementarity error is undefined without contact
        (it never falls below the tolerance there), but its displacement is the elastic response of its traction,
        so this is the remaining condition."""
        s0 = self.sigma0 / self.e_star
        expected = np.where(gap < self.rho / self.unit, -s0, 0.0)
        return bool(np.max(np.abs(traction - expected)) <= 1e-6 * max(s0, 1e-300))


def bem_cycle(heights, physical_size, e_star: float, work_of_adhesion: float, z0: float, path, *,
              tolerance: float = 1e-8, length_unit: float = 1e-9) -> tuple[ForceCycle, BEMStats]:
    """Quasi-static approach-retraction of a periodic height map (m, mean removed here) against an elastic flat
    of contact modulus `e_star` (Pa) with the Dugdale law of `work_of_adhesion` (J/m^2) and range `z0` (m),
    along `path` (rigid separations above the map's mean plane, m; `quasistatic.separation_path`)."""
    start, cpu = time.perf_counter(), time.process_time()
    contact = BEMContact(heights, physical_size, e_star, work_of_adhesion, z0, tolerance=tolerance,
                         length_unit=length_unit)
    path = np.asarray(path, float)
    turn = path_turn(path)
    force, area = np.zeros(path.size), np.zeros(path.size)
    solves = free = bad = 0
    max_err = 0.0
    for k, s in enumerate(path):
        if contact.free and not contact.reaches(s):
            free += 1                                   # exact: zero traction, zero displacement
            continue
        state = contact.solve(s)
        solves += 1
        if not state["free"]:
            bad += int(not state["converged"])
            if state["area"] > 0:
                max_err = max(max_err, state["error"])
        force[k], area[k] = state["force"], state["area"]
    stats = BEMStats(solves, free, bad, max_err, time.perf_counter() - start, contact.shape,
                     contact.size[0] / contact.shape[0], contact.rho, contact.sigma0,
                     notes={"cold_restarts": contact.restarts, "continued_solves": contact.continued,
                            "cpu_seconds": time.process_time() - cpu})
    log.info("BEM cycle: %d solves, %d free, %d unconverged, %.1f s", solves, free, bad, stats.seconds)
    return ForceCycle(path, force, area, turn), stats
