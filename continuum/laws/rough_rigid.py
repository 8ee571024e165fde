"""Averaged rough roller on a rigid substrate: the whole contact state in two numbers, tabulated.

On a rigid substrate every cell's separation is d(x) = z_max + h + x^2/2R (h: the driver's gap,
measured from the tallest summit z_max). After a first approach to h_min the history threshold is
zeta*(x) = z_max + h_min + x^2/2R, and on the retreat the effective threshold is
max(zeta*, d - Delta) = d - r with the same window r = min(h - h_min, Delta) at every x (paper
notes on eq 11). So the force, the stored energy and the dissipation depend on (h, r) only:

    W(h, r) = l int p(z_max + h + x^2/2R, r) dx = 2 l sqrt(2R) int_0^{sqrt(r - h)} p(z_max + h + s^2, r) ds,

with p the GW pressure per nominal area (`GWJKRSurface.pressure` with threshold d - r), and the
same for the stored energy E(h, r). The integral over s is done by Gauss-Legendre panels split at
the kink s = sqrt(-h) where the separation passes the truncation height, and tabulated once per
parameter set on a grid in h and in w = sqrt((Delta - r)/(Delta - r_in)) (which removes the
square-root behaviour of the force at the release stretch and puts a first approach, r = r_in, on
the node w = 1: off a node the bicubic spline of the force and of the energy disagree by ~5 % for
Maugis-Dugdale summits, which snap in before touching); bicubic splines evaluate it in microseconds.
Dissipation needs no table of its own: summits that let go are those between the two thresholds,
D = loop * [S(h_min) - S(h - r + r_in)], S(a) = summits attached on a first approach to a (1-D table).

Summit laws that snap in before touching (Maugis-Dugdale: jump-in at delta_in = -r_in < 0) and
attract out of contact (range `reach`) fit the same reduction: on approach the threshold is
d + delta_in, so r = r_in; after h_min, r = min(h - h_min + r_in, Delta). The footprint integral
runs to x^2/2R = max(r, reach) - h, the contact starts at gap `reach` and ends at max(Delta, reach).
For JKR and DMT summits r_in = reach = 0.

The driver stops a contact at the first turn while attached (stuck), so within a contact the path
is one monotonic approach and one monotonic retreat and (h, h_min) describe it exactly. This law
is the half-space-off counterpart of `RoughRoller` (which keeps a grid because the elastic
deflection makes d - zeta vary across x); `tests/continuum/test_rough_laws.py` compares the two.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline, RectBivariateSpline

from ..rough.surface import SummitSurface
from .costs import _BLOCK_STATES, RESOLUTION, table_cost_refusal, table_shape
from .roller_base import RoughRollerBase

#: Footprint tables of quadrature surfaces shared by the rollers of one process ((`_table_key`, depth) -> tables):
#: the runs of a parameter set meet the same summits and impact speeds again (sweeps, bundles, figures).
_SHARED_TABLES: dict = {}


class RigidRoughRoller(RoughRollerBase):
    """Roller of radius R and length l (m) on averaged GW/JKR summits over a rigid substrate."""

    name = "rough_roller_gw_jkr_rigid"

    def __init__(self, surface: SummitSurface, radius: float, length: float, *, resolution: str = "standard",
                 depth_safety: float = 1.5):
        self._take_surface(surface)
        self.radius, self.length = radius, length
        self.res = RESOLUTION[resolution]
        self.resolution = resolution
        self.depth_safety = depth_safety
        self.attach_stretch = float(surface.attach_stretch)   # r_in = -delta_in (m)
        self._r_in = min(self.attach_stretch, self.release_stretch)
        self.table_depth = 0.0
        self.build_seconds = 0.0
        self._start_run_counters()
        self.depth_history: list[dict] = []
        #: accepted states deeper than the tables (evaluated by the integral itself)
        self.beyond_tables = 0
        self.table_points = 0
        self._kept_tables: dict = {}
        self._approach_memo: dict = {}
        self._compiled_for = None
        self._shared_key = self._table_key()
        self.reset()

    def _table_key(self):
        """What the footprint tables are a function of, besides the design depth, for a quadrature surface
        (`GWBranchSurface`: its summit law, one shared object per set of arguments, and its statistics and
        truncation); None for other surfaces (their tables are kept by this law only)."""
        s = self.surface
        if s.kind != "generic":
            return None
        return (s.law, s.sigma, s.density, s.radius, s.z_max, s.truncated, s.resolution, self.radius, self.length,
                self.resolution)

    # ------------------------------------------------------------------ tables
    def _gauss(self, h: np.ndarray, r: np.ndarray):
        """Nodes s (shape (..., k)) and weights for int_0^{sqrt(r - h)} ds, split at sqrt(-h)."""
        nodes, weights = np.polynomial.legendre.leggauss(self.res[3])
        top = np.sqrt(np.maximum(np.maximum(r, self.reach) - h, 0.0))
        kink = np.minimum(np.sqrt(np.maximum(-h, 0.0)), top)
        parts = []
        for a, b in ((np.zeros_like(kink), kink), (kink, top)):
            half = 0.5 * (b - a)
            parts.append(((a + b)[..., None] * 0.5 + half[..., None] * nodes, half[..., None] * weights))
        s = np.concatenate([parts[0][0], parts[1][0]], axis=-1)
        w = np.concatenate([parts[0][1], parts[1][1]], axis=-1)
        return s, w

    def _integrate(self, what, h: np.ndarray, r: np.ndarray) -> np.ndarray:
        """2 l sqrt(2R) int_0^{sqrt(r-h)} q(z_max + h + s^2, threshold d - r) ds for q = pressure/energy/contacts;
        `what` a name, or a tuple of names (the results stacked on a first axis, each as it would be alone).

        Evaluated in blocks of at most `_BLOCK_STATES` surface states, so that the surface's own
        temporaries (a few dozen arrays per state) stay bounded whatever the table size."""
        names = (what,) if isinstance(what, str) else tuple(what)
        h, r = np.broadcast_arrays(np.asarray(h, float), np.asarray(r, float))
        shape = h.shape
        hf, rf = h.reshape(-1), r.reshape(-1)
        out = np.empty((len(names), hf.size))
        per = 2 * self.res[3]
        step = max(1, _BLOCK_STATES // per)
        fun = self._surface_values(names)
        for i in range(0, hf.size, step):
            hb, rb = hf[i:i + step], rf[i:i + step]
            s, w = self._gauss(hb, rb)
            d = self.z_top + hb[:, None] + s * s
            zeta = d - rb[:, None]
            q = fun(d.ravel(), zeta.ravel()).reshape((len(names),) + d.shape)
            out[:, i:i + step] = np.sum(q * w, axis=-1)
        out = 2.0 * self.length * math.sqrt(2.0 * self.radius) * out.reshape((len(names),) + shape)
        return out[0] if isinstance(what, str) else out

    def _surface_values(self, names: tuple):
        """(d, zeta) -> the surface's quantities `names` stacked; a quadrature surface (`GWBranchSurface`) sums
        pressure and energy in one pass over its panels."""
        if self.surface_kind == "generic" and "contacts" not in names:
            return lambda d, zeta: self.surface.values(names, d, zeta)
        funs = [{"pressure": self.surface.pressure, "energy": self.surface.energy,
                 "contacts": self.surface.contacts}[n] for n in names]
        return lambda d, zeta: np.stack([f(d, zeta) for f in funs])

    def _table_values(self, h: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Force and energy tables, shape (2, h.size, r.size): `_integrate` at every (h, r) of the grid.

        On a quadrature surface (`GWBranchSurface`) the footprint's deep part, s in [0, sqrt(-h)] where the
        separation is below the tallest summit, has the same nodes for every window, so its states are evaluated
        for all windows at once (`GWBranchSurface.values_by_threshold`); the part beyond the tallest summit,
        s in [sqrt(-h), sqrt(max(r, reach) - h)], only meets summits within reach and is summed as `_integrate`
        does. Both are `_integrate`'s Gauss-Legendre sums (to round-off: tests/continuum/test_rough_laws.py); a
        Maugis-Dugdale table of 1e4 nodes builds in ~0.4 s instead of ~0.7 s."""
        if self.surface_kind != "generic":
            H, R = np.meshgrid(h, r, indexing="ij")
            return self._integrate(("pressure", "energy"), H, R)
        nodes, weights = np.polynomial.legendre.leggauss(self.res[3])
        names = ("pressure", "energy")
        out = np.zeros((2, h.size, r.size))
        # deep part: rows with h < 0 (above the tallest summit it is empty), in blocks of bounded size
        deep = np.flatnonzero(h < 0.0)
        step = max(1, _BLOCK_STATES // (nodes.size * r.size))
        for i in range(0, deep.size, step):
            rows = deep[i:i + step]
            half = 0.5 * np.sqrt(-h[rows])
            s = half[:, None] + half[:, None] * nodes
            d = self.z_top + h[rows, None] + s * s
            q = self.surface.values_by_threshold(names, d.ravel(), r).reshape(2, rows.size, nodes.size, r.size)
            out[:, rows] = np.einsum("qhkw,hk->qhw", q, half[:, None] * weights)
        # beyond the tallest summit: each window its own top
        H, R = np.meshgrid(h, r, indexing="ij")
        top = np.sqrt(np.maximum(np.maximum(R, self.reach) - H, 0.0))
        kink = np.minimum(np.sqrt(np.maximum(-H, 0.0)), top)
        half = 0.5 * (top - kink)
        s = (kink + top)[..., None] * 0.5 + half[..., None] * nodes
        d = self.z_top + H[..., None] + s * s
        q = self._surface_values(names)(d.ravel(), (d - R[..., None]).ravel()).reshape((2,) + d.shape)
        out += np.sum(q * (half[..., None] * weights), axis=-1)
        return 2.0 * self.length * math.sqrt(2.0 * self.radius) * out

    #: Nodes and surface states of the footprint tables for a design depth (`continuum.laws.costs.table_shape`).
    table_shape = staticmethod(table_shape)

    #: Table sets kept per law (by design depth): a sweep or bisection that comes back to an impact speed
    #: finds its tables instead of building them again (~1 s each); the same depth gives the same tables.
    MAX_KEPT_TABLES = 24

    def _build(self, depth: float) -> None:
        import time

        kept = self._kept_tables
        if depth not in kept and self._shared_key is not None and (self._shared_key, depth) in _SHARED_TABLES:
            kept[depth] = _SHARED_TABLES[(self._shared_key, depth)]
        if depth in kept:
            (self._force, self._energy, self._count, self._h_lo, self._h_hi, self.table_depth,
             self.table_points) = kept[depth]
            return
        start = time.perf_counter()
        refusal = table_cost_refusal(self.sigma, self.table_shape(self.sigma, self.release_stretch, self.end_gap, depth,
                                                                  self.resolution),
                                     self.surface_kind, self.release_stretch, depth)
        if refusal is not None:
            raise refusal
        per_delta, per_sigma, n_w, _ = self.res
        # the spacing follows the smallest length in play: sigma, the release stretch, and the
        # depth this impact can reach (a 1 nm drop on sigma = 100 nm penetrates picometres)
        step = min(self.sigma / per_sigma, depth / (4 * per_sigma))
        if self.release_stretch > 0.0:
            step = min(step, self.release_stretch / per_delta)
        h = np.arange(-depth, self.end_gap + 2 * step, step)
        w = np.linspace(0.0, 1.0, n_w)
        r = self.release_stretch - (self.release_stretch - self._r_in) * w * w
        force, energy = self._table_values(h, r)
        self._force = RectBivariateSpline(h, w, force, kx=3, ky=3)
        self._energy = RectBivariateSpline(h, w, energy, kx=3, ky=3)
        contacts = self._integrate("contacts", h, np.full_like(h, self.attach_stretch))
        self._count = CubicSpline(h, contacts)
        self._h_lo, self._h_hi = h[0], h[-1]
        self.table_depth = depth
        self.build_seconds += time.perf_counter() - start
        self.table_points = force.size
        if len(kept) >= self.MAX_KEPT_TABLES:
            kept.pop(next(iter(kept)))
        kept[depth] = (self._force, self._energy, self._count, self._h_lo, self._h_hi, depth, self.table_points)
        if self._shared_key is not None:
            if len(_SHARED_TABLES) >= 4 * self.MAX_KEPT_TABLES:
                _SHARED_TABLES.pop(next(iter(_SHARED_TABLES)))
            _SHARED_TABLES[(self._shared_key, depth)] = kept[depth]

    def size_for(self, depth: float, speed: float) -> None:
        """Extend the tables if this impact can reach deeper than they do."""
        self.depth_history.append({"design_depth": depth, "speed": speed})
        if depth > self.table_depth or depth < 0.05 * self.table_depth:
            # deeper than the tables, or so much shallower that their spacing is too coarse
            self._build(depth)

    @property
    def sized_depth(self) -> float:
        return self.table_depth

    def first_depth_step(self) -> float:
        """1/32 of sigma or of the release stretch (sigma where there is none)."""
        return min(self.sigma, self.release_stretch if self.release_stretch > 0 else self.sigma) / 32.0

    def approach_forces(self, depths: np.ndarray) -> np.ndarray:
        """First-approach forces (N) at `depths` (m below the datum), remembered: the depth search walks the same
        batches of depths for every impact (its steps depend on the law only), so each contact after the first
        re-reads them instead of re-integrating (~20 ms per contact)."""
        memo = self._approach_memo
        key = depths.tobytes()
        if key not in memo:
            memo[key] = self._integrate("pressure", -depths, np.zeros_like(depths))
        return memo[key].copy()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        self.h_min = math.inf
        self.booked = 0.0
        self.count_min = 0.0

    def _window(self, gap: float) -> float:
        if gap <= self.h_min:
            return min(self.attach_stretch, self.release_stretch)
        return min(gap - self.h_min + self.attach_stretch, self.release_stretch)

    def _w(self, r: float) -> float:
        """Table coordinate of the window r in [r_in, Delta]: w = sqrt((Delta - r)/(Delta - r_in)), so that a
        first approach (r = r_in) is the node w = 1 and the release (r = Delta) is w = 0."""
        span = self.release_stretch - self._r_in
        return math.sqrt(min(max((self.release_stretch - r) / span, 0.0), 1.0)) if span > 0 else 0.0

    def _exact(self, what: str, gap: float, r: float) -> float:
        """The footprint integral at one state by its Gauss-Legendre quadrature (what the tables hold)."""
        return float(self._integrate(what, np.array([gap]), np.array([r]))[0])

    def force(self, gap):
        if gap >= self.end_gap:
            return 0.0
        r = self._window(gap)
        if gap < self._h_lo:
            # deeper than the tables (an integrator's trial stage, or an impact deeper than its estimate):
            # the same integral, evaluated directly
            return self._exact("pressure", gap, r)
        return float(self._force.ev(gap, self._w(r)))

    def stiffness(self, gap):
        if gap >= self.end_gap:
            return 0.0
        r = self._window(gap)
        if gap < self._h_lo:
            e = 1e-6 * self.sigma
            return -(self._exact("pressure", gap + e, r) - self._exact("pressure", gap - e, r)) / (2.0 * e)
        dh = float(self._force.ev(gap, self._w(r), dx=1))
        return -dh

    def stored_energy(self, gap):
        if gap >= self.end_gap or self.h_min == math.inf and gap >= self.reach:
            return 0.0
        r = self._window(gap)
        if gap < self._h_lo:
            return self._exact("energy", gap, r)
        return float(self._energy.ev(gap, self._w(r)))

    def _first_approach_count(self, a: float) -> float:
        """Summits attached on a first approach to `a` (table, or the integral itself beyond it)."""
        if a < self._h_lo:
            return self._exact("contacts", a, self.attach_stretch)
        return float(self._count(a))

    def _attached(self, gap: float) -> float:
        """Summits attached at `gap` on the current path."""
        a = gap - self._window(gap) + self.attach_stretch
        return self._first_approach_count(a) if a < self.attach_stretch else 0.0

    def dissipated(self, gap):
        if self.h_min == math.inf:
            return 0.0
        return self.surface.loop_energy * max(self.count_min - self._attached(gap), 0.0)

    def accept(self, gap):
        if gap < self._h_lo:
            self.beyond_tables += 1           # the impact went deeper than the tables (exact integral used; recorded)
        if gap < self.h_min:
            self.h_min = gap
            self.count_min = self._first_approach_count(gap) if gap < self.attach_stretch else 0.0
        self.max_contacts = max(self.max_contacts, self._attached(gap))

    # ------------------------------------------------------------------ compiled form
    def compiled(self, t0: float):
        """The tables as the compiled kernel reads them (`continuum.numerics.kernel_laws.LAW_RIGID_TABLE`)."""
        from ..numerics import kernel_laws as kl
        from ..numerics.compiled_contact import CompiledLaw

        # the splines these arrays came from are kept with them (an identity test on live objects)
        if self._compiled_for != (self._force, self._energy, self._count):
            (ftx, fty, fc), (etx, ety, ec) = self._force.tck, self._energy.tck
            if self._force.degrees != (3, 3) or self._energy.degrees != (3, 3):
                raise ValueError("the compiled footprint law evaluates bicubic tables only")
            P = np.zeros(7)
            P[kl.P_END_GAP], P[kl.P_REACH], P[kl.P_ATTACH] = self.end_gap, self.reach, self.attach_stretch
            P[kl.P_RELEASE], P[kl.P_R_IN], P[kl.P_H_LO] = self.release_stretch, self._r_in, self._h_lo
            P[kl.P_LOOP] = float(self.surface.loop_energy)
            tables = tuple(np.ascontiguousarray(a, float) for a in (ftx, fty, fc, etx, ety, ec, self._count.x))
            self._compiled_tables = (P, tables + (np.ascontiguousarray(self._count.c, float),))
            self._compiled_for = (self._force, self._energy, self._count)
        P, T = self._compiled_tables
        S = np.array([self.h_min, self.count_min, self.max_contacts, float(self.beyond_tables), 0.0])
        return CompiledLaw(kl.LAW_RIGID_TABLE, P, T, S)

    def compiled_commit(self, state, last_accept: float) -> None:
        self.h_min, self.count_min, self.max_contacts = float(state[0]), float(state[1]), float(state[2])
        self.beyond_tables = int(state[3])

    def snapshot(self, gap: float) -> dict:
        """Pressure across the footprint at `gap` (rigid substrate: no deflection)."""
        r = self._window(gap)
        half = math.sqrt(2.0 * self.radius * max(max(r, self.reach) - gap, self.end_gap))
        x = np.linspace(-half, half, 257)
        d = self.z_top + gap + x * x / (2.0 * self.radius)
        zeta = d - r
        if self.surface_kind == "generic":
            # quadrature surfaces (GWBranchSurface) sum the four profiles in one pass over their panels
            p, comp, tens, area = self.surface.profile(d, zeta)
        else:
            p, (comp, tens), area = (self.surface.pressure(d, zeta), self.surface.pressure_parts(d, zeta),
                                     self.surface.contact_fraction(d, zeta))
        self.max_pressure = max(self.max_pressure, float(np.max(p)))
        return {"x": x, "pressure": p, "compressive": comp, "tensile": tens, "deflection": np.zeros_like(x),
                "separation": d - self.z_top, "contact_fraction": area}

    def diagnostics(self):
        return {"max_contacts": self.max_contacts, "edge_touched": self.edge_touched,
                "max_nominal_pressure": self.max_pressure, "table_depth": self.table_depth,
                "table_points": self.table_points, "table_build_seconds": self.build_seconds,
                "contacts_seen": len(self.depth_history), "accepted_states_beyond_tables": self.beyond_tables}

    def describe(self):
        return {"name": self.name, "source": f"GW (1966) summits ({self.surface.law_name}); paper eqs 9-15; "
                "rigid substrate, exact footprint integral tabulated in (gap, window)",
                "radius": self.radius, "length": self.length, "half_space": False, "resolution": self.resolution,
                **self._averaged_summits_record()}
