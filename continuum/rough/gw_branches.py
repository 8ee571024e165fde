"""Greenwood-Williamson surface of summits with any two-branch law (DMT, Maugis-Dugdale, layered JKR).

Same model, units and public API as ``continuum.rough.gw.GWJKRSurface`` (per unit nominal area,
separations d and thresholds zeta in metres, vectorised), for a ``continuum.rough.branch_laws.
SummitLaw``: summits with z >= zeta_eff sit on the retreat branch R, the others on the approach
branch A (including their attraction out of contact, delta > -reach), with the one-threshold
history generalised to the law's own jump points:

    zeta_eff = max(min(zeta, d + delta_in), d + delta_out),       after a step zeta <- zeta_eff,

    p(d, zeta) = n [ int_{d - reach}^{zeta_eff} P_A(z - d) phi dz + int_{zeta_eff}^{z_max} P_R(z - d) phi dz ].

This is exact for a monotonic approach followed by a monotonic retreat (what the rigid-substrate
law needs) and for any path of a one-loop law; a Maugis-Dugdale curve with two separate loops
(none met in the tested range) would be reduced to its outermost jumps. Dissipation when the
threshold rises: n * loop * [Phi_t(zeta_new) - Phi_t(zeta_old)].

Evaluation: fixed Gauss-Legendre panels in delta = z - d (8 nodes), with edges at the law's jump
points, at 0 and at -reach, geometric from there (first width a tenth of the adhesive length scale,
at most sigma/4), split per state at the threshold and cut at z_max. The sums are compiled
(`continuum.rough.branch_kernel`: one state at a time over its own panels, several quantities in one
pass, ~5x faster than the NumPy form `_integrals_numpy`, which sorts states by separation and sums
chunks of 512 over the panels their deepest member needs; the two agree to round-off).
No tables: the rigid-substrate law tabulates the footprint integral of this surface once per set.
Accuracy against adaptive quadrature is measured in tests/continuum/test_branch_laws.py.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from ..reference import jkr as _jkr
from . import branch_kernel as _bk
from .summits import SummitStatistics, _gauss_mass

_SQRT2PI = math.sqrt(2.0 * math.pi)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_CHUNK = 512
#: (what, part) -> (row of the branch tables, mode) of `branch_kernel.integrals`
_KINDS = {("pressure", "total"): (0, 0), ("pressure", "compressive"): (0, 1), ("pressure", "tensile"): (0, 2),
          ("energy", "total"): (1, 0), ("area", "total"): (2, 3)}


class GWBranchSurface:
    """GW average of a SummitLaw over Gaussian summit heights, truncated at z_max (units of sigma).

    A `continuum.rough.surface.SummitSurface`, evaluated by quadrature."""

    kind = "generic"

    def __init__(self, stats: SummitStatistics, law, z_max=None, resolution="standard"):
        start = time.perf_counter()
        self.stats, self.law = stats, law
        self.sigma, self.density, self.radius = stats.sigma, stats.density, stats.radius
        self.work_of_adhesion, self.e_star = law.work_of_adhesion, law.e_star
        self.resolution = resolution
        self.law_name = law.name
        self._tmax = math.inf if z_max is None or not math.isfinite(z_max) else float(z_max)
        self.truncated = math.isfinite(self._tmax)
        self.z_max = self._tmax * self.sigma
        self.adhesive = self.work_of_adhesion > 0.0
        self.delta_in, self.delta_out, self.reach = law.delta_in, law.delta_out, law.reach
        #: same meanings as GWJKRSurface: release stretch -delta_out, jump-in before touch -delta_in
        self.release_stretch = max(-self.delta_out, 0.0)
        self.attach_stretch = max(-self.delta_in, 0.0)
        self.loop_energy = law.loop_energy
        self.pull_off_force = law.pull_off_force
        # the JKR delta_c of these summits (the one kernel, continuum.reference.jkr): the scale of the panels
        self.delta_c = (float(_jkr.critical_approach(self.radius, self.work_of_adhesion, self.e_star))
                        if self.adhesive else 0.0)
        self._edges = self._panel_edges()
        # the branch tables as the compiled quadrature reads them: delta, and rows force, energy, contact radius
        self._tables = tuple(np.ascontiguousarray(a, float) for br in (law.approach, law.retreat)
                             for a in (br.delta, np.vstack([br.force, br.energy, br.contact])))
        self.build_seconds = time.perf_counter() - start

    def _panel_edges(self) -> np.ndarray:
        sig = self.sigma
        scale = max(self.delta_c, self.reach, self.release_stretch, 1e-3 * sig)
        lo = min(-self.reach, self.delta_out, 0.0)
        hi = self.law.delta_max
        marks = sorted({lo, self.delta_out, self.delta_in, 0.0, -self.reach})
        edges = list(marks)
        width = 0.1 * scale
        x = marks[-1]
        while x < hi:
            x = min(x + min(width, 0.5 * sig), hi)
            edges.append(x)
            width *= 1.5
        # refine the adhesive region between the marks
        fine = []
        for a, b in zip(marks[:-1], marks[1:]):
            k = max(1, int(math.ceil((b - a) / (0.1 * scale))))
            fine.extend(np.linspace(a, b, k + 1)[1:-1])
        return np.unique(np.array(edges + fine))

    # ------------------------------------------------------------------ core
    def effective_threshold(self, d, zeta):
        """zeta_eff = max(min(zeta, d + delta_in), d + delta_out) (m); also the history update."""
        d = np.asarray(d, float)
        out = np.maximum(np.minimum(np.asarray(zeta, float), d + self.delta_in), d + self.delta_out)
        return out[()] if out.ndim == 0 else out

    def _integral(self, what, d, zeta, part="total"):
        out = self._integrals(((what, part),), d, zeta)[0]
        return out[()] if out.ndim == 0 else out

    def _integrals(self, quantities, d, zeta):
        """The footprint sums of several (what, part) quantities at once, shape (len(quantities),) + d's shape:
        one pass over the panels (compiled: `continuum.rough.branch_kernel.integrals`)."""
        d, zeta = np.broadcast_arrays(np.asarray(d, float), np.asarray(zeta, float))
        shape = d.shape
        d, zeta = np.ascontiguousarray(d.ravel()), zeta.ravel()
        x_th, x_top = self._limits(d, zeta)
        kinds = np.array([_KINDS[q] for q in quantities], np.int64)
        out = np.zeros((len(quantities), d.size))
        _bk.integrals(d, np.ascontiguousarray(x_th[:, 0]), np.ascontiguousarray(x_top[:, 0]), self._edges, _GL_X,
                      _GL_W, self.sigma, *self._tables, kinds, out)
        return (self.density * out).reshape((len(quantities),) + shape)

    def _integrals_numpy(self, quantities, d, zeta):
        """`_integrals` in NumPy, states sorted by separation and summed in chunks (the compiled form's reference)."""
        d, zeta = np.broadcast_arrays(np.asarray(d, float), np.asarray(zeta, float))
        shape = d.shape
        d, zeta = d.ravel(), zeta.ravel()
        out = np.empty((len(quantities), d.size))
        # a chunk integrates every state over the panels up to its deepest state's compression:
        # states sorted by separation make the chunks' panel counts follow their own depths
        order = np.argsort(d, kind="stable") if d.size > _CHUNK else None
        for i in range(0, d.size, _CHUNK):
            k = order[i:i + _CHUNK] if order is not None else slice(i, i + _CHUNK)
            out[:, k] = self._chunk(quantities, d[k], zeta[k])
        return out.reshape((len(quantities),) + shape)

    def _limits(self, d, zeta):
        """Threshold x_th and top x_top of the summits in delta (m), shape (N, 1); refuses states whose summits
        would be compressed beyond the law's table."""
        ze = np.maximum(np.minimum(zeta, d + self.delta_in), d + self.delta_out)
        x_th = (ze - d)[:, None]
        if self.truncated:
            x_top = (self.z_max - d)[:, None]
        else:   # untruncated: summits above d + delta_max carry no mass if that is beyond 8.5 sigma
            x_top = np.full((d.size, 1), self.law.delta_max)
            if np.any(d + self.law.delta_max < 8.5 * self.sigma):
                raise ValueError("GW branch surface (untruncated): separations so deep that summits beyond the law's "
                                 f"table ({self.law.delta_max:.3g} m) carry mass")
        if np.any(x_top > self.law.delta_max):
            raise ValueError(f"GW branch surface: a summit would be compressed by {float(np.max(x_top)):.3g} m, beyond "
                             f"its law's table ({self.law.delta_max:.3g} m)")
        return x_th, x_top

    def _chunk(self, quantities, d, zeta):
        x_th, x_top = self._limits(d, zeta)
        reach_top = float(np.max(np.minimum(x_top, self.law.delta_max)))
        j_end = int(np.searchsorted(self._edges, reach_top)) + 1
        edges = self._edges[:max(j_end, 2)]
        e0, e1 = edges[None, :-1], edges[None, 1:]
        total = np.zeros((len(quantities), d.size))
        for branch, (a, b) in (("approach", (e0, np.minimum(np.minimum(e1, x_th), x_top))),
                               ("retreat", (np.maximum(e0, x_th), np.minimum(e1, x_top)))):
            half = 0.5 * np.maximum(b - a, 0.0)
            mid = 0.5 * (a + b)
            x = mid[..., None] + half[..., None] * _GL_X                   # (N, J, 8) deltas
            w = half[..., None] * _GL_W
            z = (d[:, None, None] + x) / self.sigma
            phi = np.exp(-0.5 * z * z) / (_SQRT2PI * self.sigma)
            values = {}
            for n, (what, part) in enumerate(quantities):
                if what not in values:
                    values[what] = self._summit_values(what, x, branch)
                q = values[what]
                if what == "pressure" and part == "compressive":
                    q = np.maximum(q, 0.0)
                elif what == "pressure" and part == "tensile":
                    q = np.minimum(q, 0.0)
                total[n] += np.sum(q * phi * w, axis=(1, 2))
        return self.density * total

    def _summit_values(self, what, x, branch):
        """One summit's force (N), stored energy (J) or real contact area (m^2) at approaches x on a branch."""
        if what == "pressure":
            return self.law.force(x, branch)
        if what == "energy":
            return self.law.energy(x, branch)
        a_c = self.law.contact_radius(x, branch)
        return math.pi * a_c * a_c

    # ------------------------------------------------------------------ public API (as GWJKRSurface)
    def pressure(self, d, zeta):
        """Nominal pressure p(d, zeta) (Pa; + = compressive)."""
        return self._integral("pressure", d, zeta)

    def stiffness(self, d, zeta):
        """dp/dd (Pa/m) at fixed stored zeta (central difference, step 1e-7 sigma)."""
        h = 1e-7 * self.sigma
        return (self._integral("pressure", np.asarray(d) + h, zeta)
                - self._integral("pressure", np.asarray(d) - h, zeta)) / (2 * h)

    def pressure_and_stiffness(self, d, zeta):
        return self.pressure(d, zeta), self.stiffness(d, zeta)

    def pressure_parts(self, d, zeta):
        """(compressive, tensile) parts of p (Pa)."""
        return self._integral("pressure", d, zeta, "compressive"), self._integral("pressure", d, zeta, "tensile")

    def values(self, names, d, zeta):
        """Pressure (Pa), energy (J/m^2) or contact fraction (names 'pressure', 'energy', 'area') stacked in the
        order of `names`, summed in one pass: each the same sum as `pressure`, `energy`, `contact_fraction`."""
        return self._integrals(tuple((n, "total") for n in names), d, zeta)

    def values_by_threshold(self, names, d, r):
        """`values` at every separation d (1-D, m) for every window r (1-D, m), the threshold zeta = d - r: shape
        (len(names), d.size, r.size), the same sums as `values` (to round-off). The states of a grid share every panel's
        sum but the one each threshold cuts, so those are taken once per separation
        (`branch_kernel.integrals_by_threshold`); a rigid roller's footprint tables evaluate their deep states this
        way."""
        d = np.ascontiguousarray(np.asarray(d, float).ravel())
        r = np.asarray(r, float).ravel()
        _, x_top = self._limits(d, d)
        x_th = np.ascontiguousarray(np.maximum(np.minimum(-r, self.delta_in), self.delta_out))
        kinds = np.array([_KINDS[(n, "total")] for n in names], np.int64)
        out = np.zeros((len(names), d.size, r.size))
        _bk.integrals_by_threshold(d, np.ascontiguousarray(x_top[:, 0]), x_th, self._edges, _GL_X, _GL_W, self.sigma,
                                   *self._tables, kinds, out)
        return self.density * out

    def profile(self, d, zeta):
        """(p, compressive part, tensile part, contact fraction) at once: what a footprint snapshot records,
        each the same sum as `pressure`, `pressure_parts` and `contact_fraction` give."""
        p, comp, tens, area = self._integrals((("pressure", "total"), ("pressure", "compressive"),
                                               ("pressure", "tensile"), ("area", "total")), d, zeta)
        return p, comp, tens, area

    def energy(self, d, zeta):
        """Stored energy per nominal area (J/m^2), zero for free summits."""
        return self._integral("energy", d, zeta)

    def contact_fraction(self, d, zeta):
        """Real contact area / nominal area (1)."""
        return self._integral("area", d, zeta)

    def contacts(self, d, zeta):
        """Summits on the retreat branch per unit nominal area (1/m^2)."""
        te = np.asarray(self.effective_threshold(d, zeta), float) / self.sigma
        out = self.density * _gauss_mass(te, self._tmax)
        return out[()] if np.ndim(out) == 0 else out

    def dissipation(self, zeta_old, zeta_new):
        """Energy lost per nominal area (J/m^2) when the threshold rises from zeta_old to zeta_new (m)."""
        zo = np.asarray(zeta_old, float) / self.sigma
        zn = np.asarray(zeta_new, float) / self.sigma
        up = zn > zo
        top = self._tmax
        m = _gauss_mass(np.where(up, np.minimum(zo, top), 0.0), np.where(up, np.minimum(zn, top), 0.0))
        out = np.where(up, self.density * self.loop_energy * m, 0.0)
        return out[()] if out.ndim == 0 else out

    def describe(self) -> dict:
        return {"sigma": self.sigma, "density": self.density, "radius": self.radius, "z_max": self.z_max,
                "summit_law": self.law.describe(), "release_stretch": self.release_stretch,
                "attach_stretch": self.attach_stretch, "reach": self.reach, "panels": int(self._edges.size - 1),
                "build_seconds": self.build_seconds}


def quadrature_pressure(d, zeta, surface: GWBranchSurface, what="pressure"):
    """Reference p (or energy) by scipy.integrate.quad over z, split at the law's jump points (slow; tests)."""
    from scipy import integrate

    law, sig = surface.law, surface.sigma
    ze = float(surface.effective_threshold(d, zeta))
    fn = law.force if what == "pressure" else law.energy

    def f(z, branch):
        return float(fn(z - d, branch)) * math.exp(-0.5 * (z / sig) ** 2) / (_SQRT2PI * sig)

    top = surface.z_max if surface.truncated else d + law.delta_max
    total = 0.0
    for branch, (a, b) in (("approach", (d - surface.reach - 1e-3 * sig, min(ze, top))), ("retreat", (ze, top))):
        if b <= a:
            continue
        pts = sorted(p for p in (d, d + law.delta_in, d + law.delta_out, d - surface.reach) if a < p < b)
        with warnings.catch_warnings():       # round-off near the jump points only; the result is checked at 5e-5
            warnings.simplefilter("ignore", integrate.IntegrationWarning)
            v, _ = integrate.quad(f, a, b, args=(branch,), points=pts or None, limit=400, epsabs=0, epsrel=1e-10)
        total += v
    return surface.density * total


__all__ = ["GWBranchSurface", "quadrature_pressure"]
