"""A roller on a rough, adhesive, elastic substrate: GW summits with JKR hysteresis on a 1-D grid.

Paper §4.2 and §4.4, eqs 9-11 and 13-17, with the corrections of the notes. Across the roller's
axis a grid of cells x_i carries the local separation between the summits' mean plane and the
roller surface (eq 16)

    d_i = z_max + gap + x_i^2/(2R) + delta_e,i

where `gap` is the driver's coordinate (height of the roller's lowest point above the datum, the
tallest summit expected in the footprint, z_max above the mean plane) and delta_e = D * p is the
elastic displacement of the half-space under the summit pressure p (eq 17; FFT influence
coefficients referenced at x_ref = l, so that a smooth roller recovers eq 1; `continuum.elastic.halfspace`).
Each cell keeps one history threshold zeta*_i (summits taller than it are attached; notes on
eq 11), updated on every accepted integration step and at every extremum of the motion. The
force on the roller is W = l * sum_i p_i dx (eq 14 without menisci).

Energy bookkeeping, all from the laws' own terms: stored = l dx sum_i e(d_i, zeta_i) (summits'
JKR energies) + (l dx / 2) sum_i p_i delta_e,i (half-space); dissipated = l dx sum_i of the
loop energy of every summit that let go (GW `dissipation`). Force = -d(stored)/d(gap) holds
exactly at equilibrium of the coupled solve because the influence matrix is symmetric.

The grid follows the footprint: before each contact, the deepest approach the impact can reach
is estimated from the quasi-static work of the rigid approach branch (the impact's kinetic
energy, with a safety factor), and the grid spans the region where summits can touch or stay
attached (x^2/2R <= depth + release stretch). If the contact reaches the grid's edge anyway the
law records it (`edge_touched`) and the result says so.
"""
from __future__ import annotations

import math

import numpy as np

from ..elastic.halfspace import solve_coupled
from ..rough.surface import SummitSurface
from .costs import MAX_RUN_SECONDS, SECONDS_PER_STATE
from .roller_base import RoughRollerBase


class RoughRoller(RoughRollerBase):
    """Roller (radius R, length l, m) on a GW/JKR rough surface, optionally on an elastic half-space.

    Parameters
    ----------
    surface : SummitSurface
        Summit statistics and laws (pressure per nominal area as a function of separation).
    radius, length : float
        Roller radius R and length l (m).
    e_star : float
        Effective modulus of the half-space under the summits (Pa).
    half_space : bool
        Couple the summits to the elastic half-space (eq 17) or treat the substrate as rigid.
    grid_points : int
        Cells across the footprint.
    mass : float
        Roller mass (kg), used to size the grid from the impact's energy.
    """

    name = "rough_roller_gw_jkr"

    def __init__(self, surface: SummitSurface, radius: float, length: float, e_star: float, *,
                 half_space: bool = True, grid_points: int = 256, depth_safety: float = 1.5,
                 coupling_tol: float = 1e-11):
        self._take_surface(surface)
        self.radius, self.length, self.e_star = radius, length, e_star
        self.use_half_space = half_space
        self.n = grid_points
        self.depth_safety = depth_safety
        self.coupling_tol = coupling_tol
        self._start_run_counters()
        self.max_deflection = 0.0                # largest |delta_e| seen (m)
        self.grid_history: list[dict] = []
        #: coupled pressure-deflection solves: how many, which solver produced each, worst residual
        #: (relative to the pressure scale max(max|p|, n P_c))
        self.solve_record = {"solves": 0, "by_method": {}, "fixed_point_iterations": 0,
                             "fallback_iterations": 0, "max_residual": 0.0, "tolerance": coupling_tol,
                             "scale": "max(max|p|, n P_c)"}
        #: surface states evaluated so far (a stiffness or a compressive/tensile split counts twice)
        self.work_states = 0
        self._set_grid(max(4.0 * surface.stats.sigma, 4.0 * self.release_stretch))

    # ------------------------------------------------------------------ work budget
    def _count_work(self, states: int) -> None:
        """Add `states` surface evaluations to the run's work; beyond MAX_RUN_SECONDS stop with a SceneError."""
        self.work_states += int(states)
        seconds = self.work_states * SECONDS_PER_STATE[self.surface_kind]
        if seconds > MAX_RUN_SECONDS:
            from ..scene import SceneError

            way = ("physics.adhesion_law = 'jkr' (tabulated summits, ~10x cheaper), "
                   if self.surface_kind == "generic" else "")
            raise SceneError(
                "physics.half_space", "on",
                f"the grid law ({self.n} cells, {self.surface_kind} summits) has evaluated {self.work_states:.3g} "
                f"surface states (~{seconds:.3g} s) after {len(self.grid_history)} contact(s), above its "
                f"{MAX_RUN_SECONDS:g} s budget; use {way}physics.half_space = 'off' (tabulated footprint), fewer "
                "numerics.max_bounces, or numerics.fidelity = 'fast'")

    def work_seconds(self) -> float:
        """Estimated seconds of surface evaluations so far (work_states x SECONDS_PER_STATE)."""
        return self.work_states * SECONDS_PER_STATE[self.surface_kind]

    # ------------------------------------------------------------------ grid and state
    def _set_grid(self, depth: float) -> None:
        """Grid spanning |x| <= sqrt(2R (depth + 2 * release stretch))."""
        self._line_grid(math.sqrt(2.0 * self.radius * (depth + 2.0 * self.end_gap)))
        self.parabola = self.x**2 / (2.0 * self.radius)
        self.depth = depth
        self.reset()

    def reset(self) -> None:
        self.zeta = np.full(self.n, np.inf)
        self.booked = 0.0
        self.p_last = np.zeros(self.n)
        self._cache_gap = None

    def size_for(self, depth: float, speed: float) -> None:
        """A grid for a design depth `depth` (m), at least twice the release stretch."""
        self._set_grid(max(depth, 2.0 * self.release_stretch))
        self._record_grid(depth, speed)

    @property
    def sized_depth(self) -> float:
        return self.depth

    def approach_forces(self, depths) -> np.ndarray:
        """Forces (N) of a monotonic first approach to each depth (m below the datum) on a rigid substrate.

        2 l sqrt(2R) int_0^sqrt(depth) p(z_max - depth + s^2) ds (x = sqrt(2R) s), by 24-point
        Gauss-Legendre for all depths at once (grid sizing; the integrand is smooth in s up to the
        truncation kink at the end point)."""
        depths = np.maximum(np.asarray(depths, float), 0.0)
        nodes, weights = np.polynomial.legendre.leggauss(24)
        top = np.sqrt(depths)[:, None]
        s = 0.5 * top * (nodes + 1.0)
        d = self.z_top - depths[:, None] + s * s
        p = self.surface.pressure(d.ravel(), np.full(d.size, np.inf)).reshape(d.shape)
        self._count_work(d.size)
        return 2.0 * self.length * math.sqrt(2.0 * self.radius) * np.sum(p * (0.5 * top * weights), axis=-1)

    def approach_force(self, gap: float) -> float:
        """Force (N) of a monotonic first approach to `gap` on a rigid substrate (for grid sizing)."""
        return float(self.approach_forces(np.array([-gap]))[0])

    def _evaluate(self, gap: float):
        """(d, zeta_eff, p, delta_e) at a trial gap with the stored history (`_state` caches it)."""
        d_rigid = self.z_top + gap + self.parabola
        if self.hs is None:
            zeta = self.surface.effective_threshold(d_rigid, self.zeta)
            p = self.surface.pressure(d_rigid, self.zeta)
            self._count_work(self.n)
            return d_rigid, zeta, p, np.zeros(self.n)
        return self._coupled(d_rigid)

    def _coupled(self, d_rigid):
        """Self-consistent p and delta_e: warm-started fixed point, then `solve_coupled` if that stalls.

        Under a light roller the coupling |dp/dd| * compliance is ~1e-4 - 1e-7 (halfspace.md), so the
        fixed point from the previous step's pressure gains four or more digits per iteration; where
        the coupling is strong (heavy rollers, stiff summits) or the iteration oscillates, Newton-Krylov
        (then pseudo-transient continuation, then a damped fixed point) takes over: other solvers of
        the same equations, counted in `solve_record` and reported in the result's diagnostics.

        Convergence is measured on the law's own pressure scale, max(max|p|, n P_c): the GW tables are
        accurate relative to that scale, and under a nearly free roller the net pressure is a
        cancellation of compressive and tensile summits far below it, where a test relative to max|p|
        asks for digits that rounding in the parts (~1e-16 n P_c) does not hold.
        """
        surf, zeta = self.surface, self.zeta
        p = self.p_last
        rec = self.solve_record
        rec["solves"] += 1
        floor = surf.density * surf.pull_off_force
        change = np.inf
        its = 0
        n = self.n
        for its in range(1, 31):
            delta = self.hs.displacement(p)
            p_new = surf.pressure(d_rigid + delta, zeta)
            self._count_work(n)
            last, change = change, float(np.max(np.abs(p_new - p)))
            p = p_new
            scale = self._pressure_scale(p, floor)
            if change <= self.coupling_tol * scale or change > 0.5 * last:
                break
        rec["fixed_point_iterations"] += its
        if change > self.coupling_tol * scale:
            def law(h):
                self._count_work(3 * n)
                return surf.pressure(h, zeta), surf.stiffness(h, zeta)

            sol = solve_coupled(self.hs, d_rigid, law, p_init=p, tol=self.coupling_tol, pressure_scale=scale)
            rec["by_method"][sol.method] = rec["by_method"].get(sol.method, 0) + 1
            rec["fallback_iterations"] += sol.iterations
            if not sol.converged:
                from nanoimpact.errors import RunFailed

                raise RunFailed(f"rough contact: coupled pressure-deflection solve did not converge "
                                   f"(residual {sol.residual:.2e} of the pressure scale {scale:.3g} Pa after "
                                   f"{sol.iterations} iterations of newton, ptc and fixed_point)")
            rec["max_residual"] = max(rec["max_residual"], float(sol.residual))
            p = sol.p
        else:
            rec["by_method"]["warm_fixed_point"] = rec["by_method"].get("warm_fixed_point", 0) + 1
            rec["max_residual"] = max(rec["max_residual"], change / scale)
        delta = self.hs.displacement(p)
        d = d_rigid + delta
        return d, surf.effective_threshold(d, zeta), p, delta

    @staticmethod
    def _pressure_scale(p, floor):
        """The pressure scale of a coupled solve (Pa): max(max|p|, n P_c), or 1 Pa if both vanish."""
        s = max(float(np.max(np.abs(p))), floor)
        return s if s > 0.0 else 1.0

    # ------------------------------------------------------------------ ContactLaw
    def force(self, gap):
        return float(self.length * self.dx * np.sum(self._state(gap)[2]))

    def stiffness(self, gap):
        d, _, _, _ = self._state(gap)
        self._count_work(2 * self.n)
        return float(self.length * self.dx * np.sum(self.surface.stiffness(d, self.zeta)))

    def stored_energy(self, gap):
        d, _, p, delta = self._state(gap)
        self._count_work(self.n)
        summits = np.sum(self.surface.energy(d, self.zeta))
        elastic = 0.5 * np.sum(p * delta)
        return float(self.length * self.dx * (summits + elastic))

    def dissipated(self, gap):
        _, zeta_eff, _, _ = self._state(gap)
        pending = np.sum(self.surface.dissipation(self.zeta, zeta_eff))
        return float(self.booked + self.length * self.dx * pending)

    def accept(self, gap):
        d, zeta_eff, p, delta = self._state(gap)
        self.booked += float(self.length * self.dx * np.sum(self.surface.dissipation(self.zeta, zeta_eff)))
        self.zeta = zeta_eff
        self.p_last = p
        self._cache_gap = None
        attached = np.isfinite(zeta_eff) & (zeta_eff < self.z_top)
        if attached[0] or attached[-1]:
            self.edge_touched = True
        if self.hs is not None:
            self.max_deflection = max(self.max_deflection, float(np.max(np.abs(delta))))
        self.max_pressure = max(self.max_pressure, float(np.max(p)))
        self.max_contacts = max(self.max_contacts,
                                float(self.length * self.dx * np.sum(self.surface.contacts(d, zeta_eff))))

    def snapshot(self, gap: float) -> dict:
        """Pressure, deflection and gap across the grid at `gap` (for Fig 6); SI arrays."""
        d, zeta_eff, p, delta = self._state(gap)
        compressive, tensile = self.surface.pressure_parts(d, self.zeta)
        return {"x": self.x.copy(), "pressure": p.copy(), "compressive": compressive, "tensile": tensile,
                "deflection": delta.copy(), "separation": d - self.z_top,
                "contact_fraction": self.surface.contact_fraction(d, self.zeta)}

    def diagnostics(self):
        return {"max_contacts": self.max_contacts, "edge_touched": self.edge_touched,
                "max_deflection": self.max_deflection, "max_nominal_pressure": self.max_pressure,
                **self._grid_record(),
                "surface_work": {"states": self.work_states, "estimated_seconds": self.work_seconds(),
                                 "budget_seconds": MAX_RUN_SECONDS, "surface": self.surface_kind},
                **({"coupled_solve": {**self.solve_record, "by_method": dict(self.solve_record["by_method"])}}
                   if self.hs is not None else {})}

    def describe(self):
        return {"name": self.name, "source": "GW (1966) summits with JKR + Fuller-Tabor hysteresis; paper eqs 9-17",
                "radius": self.radius, "length": self.length, "e_star": self.e_star,
                "half_space": self.use_half_space, "grid_points": self.n, **self._averaged_summits_record()}
