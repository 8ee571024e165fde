"""Adhesive elastic-plastic summits (Thornton & Ning 1998 on each summit), one by one and averaged (GW).

What it is
----------
A summit is a sphere of tip radius beta with the summits' contact modulus E* and the pair's work of adhesion w,
pressed by its approach delta against a flat (displacement control, as under a roller or a punch). Above its
limiting contact pressure p_y (`continuum.physics.limiting_pressure`) it follows the Thornton-Ning adhesive
elastic-plastic law of `continuum.reference.thornton_ning` (the same law as the smooth sphere's
`continuum.laws.plastic_sphere`):

* elastic loading is JKR on beta up to the yield approach delta_y (centre pressure = p_y);
* plastic loading is the line F = F_y + pi p_y beta (delta - delta_y);
* unloading and elastic reloading follow JKR about the flattened radius
  R_p = 4E*a*^3 / (3 (F* + sqrt(8 pi w E* a*^3))), shifted by the residual indentation delta_p, so that the
  branch passes through the deepest state (delta_max, F*);
* the summit lets go at the fold of that branch, delta = delta_p - delta_c(R_p) (displacement control), and
  meets the flattened summit again at delta = delta_p.

A summit's plastic state is a function of one number, its deepest approach delta_max (`PlasticSummitLaw.
flattening`): each summit carries (R_p, delta_p) into later contacts. With p_y = inf no summit yields and every
function is the elastic JKR summit's, evaluated by the same closed forms (`continuum.reference.jkr`).

Energy of a summit (exact, from the closed forms): stored U = the JKR energy of its current branch from that
branch's touch point (`jkr.energy_from_approach`); plastic work W_p(delta_max) = U_beta(a_y) + F_y D +
pi p_y beta D^2/2 - U_Rp(a*), D = delta_max - delta_y (work done along the loading path less what the new
branch stores); hysteresis at release = U_Rp at the fold (the Fuller-Tabor loop of the R_p branch).

Mean field (Greenwood & Williamson 1966): summit heights z are Gaussian (rms sigma_s, density n, truncated at
z_max). A summit of height z under a flat at separation d has delta = z - d; its plastic state depends only on the
deepest separation ever reached, d_p (delta_max = z - d_p), and whether it is attached in the present contact on
the deepest separation of this contact, d_c (>= d_p), and on d (monotonic approach, then monotonic retreat: the
driver ends a contact at its first turn while attached). With u = z - d_p:

    attached  <=>  u - delta_p(u) >= d_c - d_p     (met in this contact)
              and  u - delta_p(u) + delta_c(R_p(u)) > d - d_p     (not yet let go),

both left sides increasing in u (tested), so the attached summits are u > u_a(d, d_c, d_p), and

    p = n int_{u_a}^{z_max - d_p} F(u) phi(d_p + u) du,   E = n int U phi du,   W_p = n int W_p(u) phi du.

The integrals are Gauss-Legendre panels (8 nodes) in u, geometric from u_a (first width a tenth of the adhesive
length scale, at most sigma/4), the first panel in t with u = u_a + t^2 (the JKR force has a square-root
behaviour at the fold), split at delta_y. They run in NumPy: the summit states are not tabulated, so these
surfaces are evaluated state by state (a few hundred nodes), with no tables; the contact laws that use them are in
`continuum.laws.plastic_rough` (flat punch, rigid roller, discrete summits).

Plasticity index (Greenwood & Williamson 1966): psi = (E*/H) sqrt(sigma_s/beta); psi < 0.6 the summits stay
elastic under any practical load, psi > 1 most touching summits yield (`continuum.model.regimes.plasticity_index`).

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; J. A. Greenwood & J. B. P. Williamson,
Proc. R. Soc. Lond. A 295 (1966) 300; K. L. Johnson, K. Kendall & A. D. Roberts, Proc. R. Soc. Lond. A 324
(1971) 301; K. N. G. Fuller & D. Tabor, Proc. R. Soc. Lond. A 345 (1975) 327. Why Thornton-Ning and not
Mesarovic-Johnson or Kogut-Etsion: `continuum.reference.thornton_ning`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq
from scipy.special import ndtri

from ..reference import jkr
from ..reference import thornton_ning as tn

__all__ = ["PlasticSummitLaw", "PlasticGWSurface", "RollerFootprint"]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_SQRT2PI = math.sqrt(2.0 * math.pi)
#: Lowest summit height kept, in units of sigma: the fraction Phi(-K) of the Gaussian's summits below it is half
#: the double-precision epsilon (K = 8.21), so it stays below the round-off of the quadrature sums (see
#: `PlasticGWSurface`: the lower truncation and the bound it puts on the quadrature nodes).
LOWER_TAIL = float(-ndtri(np.finfo(float).eps / 2.0))


@dataclass(frozen=True)
class PlasticSummitLaw:
    """One summit's Thornton-Ning law: tip radius beta (m), work of adhesion w > 0 (J/m^2), contact modulus E* (Pa),
    limiting contact pressure p_y (Pa; math.inf: elastic JKR). Functions are vectorised over summits."""

    radius: float
    work_of_adhesion: float
    e_star: float
    limiting_pressure: float
    yield_radius: float = field(init=False)
    yield_force: float = field(init=False)
    yield_approach: float = field(init=False)
    plastic_slope: float = field(init=False)

    def __post_init__(self):
        if not self.work_of_adhesion > 0.0:
            raise ValueError(f"work_of_adhesion = {self.work_of_adhesion!r}: the adhesive plastic summit needs w > 0")
        p = (self.radius, self.work_of_adhesion, self.e_star)
        if math.isinf(self.limiting_pressure):
            a_y, f_y, d_y = math.inf, math.inf, math.inf
        else:
            tn.check_limiting_pressure(self.limiting_pressure, *p)
            a_y = float(tn.yield_radius(self.limiting_pressure, *p))
            f_y, d_y = float(jkr.force_from_radius(a_y, *p)), float(jkr.approach_from_radius(a_y, *p))
        set_ = object.__setattr__
        set_(self, "yield_radius", a_y)
        set_(self, "yield_force", f_y)
        set_(self, "yield_approach", d_y)
        set_(self, "plastic_slope", math.pi * self.limiting_pressure * self.radius)

    def flattening(self, delta_max):
        """(R_p, delta_p) (m) of the elastic branch after the deepest approach delta_max (m): (beta, 0) unyielded."""
        dm = np.asarray(delta_max, float)
        over = np.maximum(dm - self.yield_approach, 0.0) if math.isfinite(self.yield_approach) else np.zeros_like(dm)
        yielded = over > 0.0
        w, e, beta = self.work_of_adhesion, self.e_star, self.radius
        if not yielded.any():
            return np.full_like(dm, beta), np.zeros_like(dm)
        a = np.sqrt(self.yield_radius**2 + beta * over)
        f = self.yield_force + self.plastic_slope * over
        r_p = np.where(yielded, 4.0 * e * a**3 / (3.0 * (f + np.sqrt(8.0 * math.pi * w * e * a**3))), beta)
        d_p = np.where(yielded, dm - np.asarray(jkr.approach_from_radius(a, r_p, w, e), float), 0.0)
        return r_p, d_p

    def release_stretch(self, r_p):
        """delta_c(R_p) (m): the branch lets go at delta = delta_p - delta_c (displacement control)."""
        return np.asarray(jkr.critical_approach(r_p, self.work_of_adhesion, self.e_star), float)

    def branch(self, delta, delta_max):
        """(force N, stored energy J) of attached summits at approach delta (m), deepest approach delta_max (m,
        >= delta; the plastic line where delta = delta_max > delta_y)."""
        r_p, d_p = self.flattening(delta_max)
        # attached summits lie at or above the fold; the clamp only absorbs round-off at the release boundary
        e = np.maximum(np.asarray(delta, float) - d_p, -self.release_stretch(r_p))
        w, es = self.work_of_adhesion, self.e_star
        a = np.asarray(jkr.radius_from_approach(e, r_p, w, es), float)
        return (np.asarray(jkr.force_from_radius(a, r_p, w, es), float),
                np.asarray(jkr.energy_from_radius(a, r_p, w, es), float))

    def plastic_work(self, delta_max):
        """W_p (J): the work a summit loaded to delta_max absorbed plastically (0 unyielded)."""
        dm = np.asarray(delta_max, float)
        if not math.isfinite(self.yield_approach):
            return np.zeros_like(dm)
        d = np.maximum(dm - self.yield_approach, 0.0)
        p = (self.radius, self.work_of_adhesion, self.e_star)
        work = (float(jkr.energy_from_radius(self.yield_radius, *p)) + self.yield_force * d
                + 0.5 * self.plastic_slope * d * d)
        _, stored = self.branch(np.maximum(dm, self.yield_approach), np.maximum(dm, self.yield_approach))
        return np.where(d > 0.0, work - stored, 0.0)

    def loop_energy(self, delta_max):
        """Energy (J) a summit with deepest approach delta_max loses when it lets go (the R_p branch's loop)."""
        r_p, _ = self.flattening(delta_max)
        return np.asarray(jkr.energy_from_approach(-self.release_stretch(r_p), r_p, self.work_of_adhesion,
                                                   self.e_star), float)

    # ---- the interface every plastic summit law offers (`continuum.rough.plastic_branches`): JKR's closed forms
    #: no attraction before contact (zero-range adhesion); no bound on the release stretch over a contact (the
    #: law is not compiled: the Python stepper asks for the release gap at every step)
    approach_reach = 0.0
    max_stretch = None
    compiled_form = False

    def range_radius_ratio(self, delta_max):
        """a*/R_p at the deepest state delta_max (m) of yielded summits (a^2 = a_y^2 + beta (delta_max - delta_y))."""
        dm = np.asarray(delta_max, float)
        r_p, _ = self.flattening(dm)
        over = np.maximum(dm - self.yield_approach, 0.0) if math.isfinite(self.yield_approach) else np.zeros(dm.shape)
        a2 = np.where(over > 0.0, self.yield_radius**2 + self.radius * over, 0.0)
        return np.sqrt(a2) / r_p

    @property
    def reach(self) -> float:
        """Stretch (m) below delta_p at which a virgin summit still pulls: its fold delta_c(beta)."""
        return float(self.release_stretch(self.radius))

    def reach_of(self, r_p):
        """Stretch (m) below delta_p at which the approach branch starts to pull: 0 (zero-range adhesion)."""
        return np.zeros_like(np.asarray(r_p, float))

    def jump_in(self, r_p):
        """delta_in (m, relative to delta_p): a JKR summit snaps in on touching (zero-range adhesion)."""
        return np.zeros_like(np.asarray(r_p, float))

    def jump_out(self, r_p):
        """delta_out (m, relative to delta_p): the fold -delta_c(R_p)."""
        return -self.release_stretch(r_p)

    def in_switch(self, r_p):
        """U_A - U_R at the jump in: 0 (the JKR branch starts from its touch point with U = 0)."""
        return np.zeros_like(np.asarray(r_p, float))

    def out_switch(self, r_p):
        """U_R - U_A at the fold: the R_p branch's Fuller-Tabor loop."""
        r_p = np.asarray(r_p, float)
        return np.asarray(jkr.energy_from_approach(-self.release_stretch(r_p), r_p, self.work_of_adhesion,
                                                   self.e_star), float)

    def state(self, delta, delta_max, attached):
        """(force N, stored energy J): `branch` where attached, free (0, 0) otherwise (no force out of contact)."""
        delta, dm, att = np.broadcast_arrays(np.asarray(delta, float), np.asarray(delta_max, float),
                                             np.asarray(attached, bool))
        f, u = np.zeros(delta.shape), np.zeros(delta.shape)
        if np.any(att):
            f[att], u[att] = self.branch(delta[att], dm[att])
        return f, u

    def describe(self) -> dict:
        return {"name": "thornton_ning_summit", "radius": self.radius, "work_of_adhesion": self.work_of_adhesion,
                "e_star": self.e_star, "limiting_pressure": self.limiting_pressure,
                "yield_radius": self.yield_radius, "yield_force": self.yield_force,
                "yield_approach": self.yield_approach, "plastic_slope": self.plastic_slope,
                "source": "Thornton & Ning (1998) per summit: JKR to yield, plastic line pi p_y beta, JKR unloading "
                          "about R_p shifted by delta_p; Fuller-Tabor release at the fold"}


class PlasticGWSurface:
    """GW mean field of `PlasticSummitLaw` summits: Gaussian heights of rms sigma (m), density n (1/m^2), truncated
    at z_max sigma (the tallest summit, the datum of `PlasticGWPunch`). Values per unit nominal area, functions of
    the separation d, this contact's deepest separation d_c and the deepest ever d_p (m; d_p <= d_c).

    Lower truncation and the node bound: the summits below z = -K sigma (K = `LOWER_TAIL`, Phi(-K) = eps/2) are not
    kept. They are a fraction eps/2 of the summits and the least compressed ones (u = z - d_p is smallest there), so
    each carries no more than the loading force of the summits at the cut, and the values they leave out are
    below the round-off of the sums over the kept summits. Every value (force, stored energy, plastic work, loops)
    drops the same summits, so the law is exactly that of GW truncated at both ends and the energy audit holds
    unchanged. What it buys: the integrals in u run over at most (z_max + K) sigma whatever the separation, so
    the quadrature has at most `node_bound((z_max + K) sigma)` nodes (a footprint's, `RollerFootprint`, grow with
    the log of its depth). Without it a trial step of the integrator deep below the surface (a 1 TPa summit
    modulus gives forces that send DOP853's stages kilometres down) spanned its whole range in sigma/4 panels:
    1e11 nodes, tens of GB."""

    #: sums by a compiled kernel (`PlasticBranchGWSurface` where its summit law has tables); JKR's closed forms: NumPy
    compiled = False

    def __init__(self, law: PlasticSummitLaw, sigma: float, density: float, z_max: float):
        if not math.isfinite(z_max):
            raise ValueError("PlasticGWSurface needs a finite truncation z_max (units of sigma): the tallest summit")
        self.law, self.sigma, self.density = law, float(sigma), float(density)
        self.z_top = float(z_max) * self.sigma
        # the adhesive length scale of a virgin summit: its release stretch (JKR's delta_c) or its reach
        self.delta_c = max(-float(np.asarray(law.jump_out(np.array([law.radius])), float)[0]), law.approach_reach)
        self._first = 0.1 * max(self.delta_c, 1e-3 * self.sigma)
        self.z_floor = -LOWER_TAIL * self.sigma

    def node_bound(self, span: float) -> int:
        """Most quadrature nodes of an integral over `span` = hi - lo (m) in u (this surface's: span <= (z_max + K)
        sigma; a footprint's: up to the depth of its axis below z_top): 8 per panel; panels grow by 1.5 from the
        first (`_first`) to their cap, then (below the floor) halve the distance left until sigma/4, then sigma/4
        over (z_max + K) sigma, plus the split at delta_y and the end panels."""
        q = self.panel_width * self.sigma
        below = max(span - (self.z_top - self.z_floor), 0.0)
        ramp = math.ceil(math.log(max(max(q, 0.5 * below) / self._first, 1.0)) / math.log(1.5)) + 1
        descent = math.ceil(math.log2(max(below / q, 1.0))) + 1
        return 8 * (ramp + descent + math.ceil((self.z_top - self.z_floor) / q) + 4)

    # ------------------------------------------------------------------ summit sets
    def recovery(self, u):
        """g(u) = u - delta_p(u): a summit of deepest approach u (m) is met again at separation d_p + g(u)."""
        u = np.asarray(u, float)
        return u - self.law.flattening(u)[1]

    def hold(self, u):
        """h(u) = g(u) + delta_c(R_p(u)): a summit of deepest approach u lets go at separation d_p + h(u)."""
        u = np.asarray(u, float)
        r_p, d_p = self.law.flattening(u)
        return u - d_p + self.law.release_stretch(r_p)

    def _inverse(self, fn, value, offset):
        """The u (m) with fn(u) = value, fn(u) = u + offset up to delta_y and increasing beyond."""
        d_y = self.law.yield_approach
        if value - offset <= d_y:
            return value - offset
        hi = max(2.0 * (value - offset), d_y + self.sigma)
        while float(fn(hi)) < value:
            hi *= 2.0
        return brentq(lambda u: float(fn(u)) - value, d_y, hi, xtol=1e-15 * hi, rtol=1e-14)

    def bounds(self, d, d_c, d_p):
        """(u_met, u_held): summits met in this contact are u >= u_met, those not yet let go u > u_held (m)."""
        u_met = self._inverse(self.recovery, d_c - d_p, 0.0) if math.isfinite(d_c) else math.inf
        return u_met, self._inverse(self.hold, d - d_p, self.delta_c) if math.isfinite(d) else math.inf

    # ------------------------------------------------------------------ quadrature
    #: the weight has a square-root end at the top of the summits (a footprint's edge): last panel in u = hi - t^2
    _root_at_top = False

    #: widest panel (units of sigma): the JKR closed forms and the Gaussian are smooth on sigma/4
    panel_width = 0.25
    #: the weight is the Gaussian's, negligible below z_floor: the summits there are dropped (`RollerFootprint`
    #: keeps them: its axis height is not a summit's height)
    _clip_floor = True

    def _offsets(self):
        """Edges of the panels above the floor relative to their start (m): 0, then widths growing by 1.5 from
        `_first` to sigma/4 (`panel_width`), over (z_max + K) sigma."""
        if getattr(self, "_offsets_cache", None) is None:
            span, quarter = self.z_top - self.z_floor, self.panel_width * self.sigma
            out, x, width = [0.0], self._first, self._first
            while x < span:
                out.append(x)
                width = min(1.5 * width, quarter)
                x += width
            out.append(x)
            self._offsets_cache = np.array(out)
        return self._offsets_cache

    def _span(self, lo, d_p, hi=math.inf):
        """(lo, hi, floor) (m, in u = z - d_p) for `_nodes`: hi <= z_top - d_p, and lo >= floor = z_floor - d_p
        where `_clip_floor`."""
        floor = self.z_floor - d_p
        return (max(lo, floor) if self._clip_floor else lo), min(hi, self.z_top - d_p), floor

    def _nodes(self, lo, hi, floor=-math.inf, breaks=()):
        """Gauss-Legendre nodes and weights on [lo, hi] (m): geometric panels from lo (split at delta_y), the first in
        u = lo + t^2 (and with `_root_at_top` the last in u = hi - t^2), at most sigma/4 wide above `floor` and at
        most half their distance from it below (where the weight is smooth on that scale, `RollerFootprint`), so at
        most `node_bound(hi - lo)` nodes (plus one panel per point of `breaks`, where the integrand has a kink)."""
        if not hi > lo:
            return np.empty(0), np.empty(0)
        quarter = self.panel_width * self.sigma
        offsets = self._offsets()
        if floor <= lo and hi - lo < offsets[-1]:
            # the panels' edges from lo do not depend on lo above the floor: the template's
            edges = [*(lo + offsets[offsets < hi - lo]), hi]
        else:
            edges, x, width = [lo], lo + min(self._first, hi - lo), self._first
            while x < hi:
                edges.append(x)
                width = min(1.5 * width, max(quarter, 0.5 * (floor - x)))
                x += width
            edges.append(hi)
        d_y = self.law.yield_approach
        edges = np.unique(np.concatenate([edges, [b for b in (d_y, *breaks) if lo < b < hi]]))
        if self._root_at_top:
            # the last panel at least as wide as its neighbour: the plain panels keep their distance from the
            # square-root end, so the sums change smoothly when an edge appears as hi grows
            # (drop the interior edges from the top down while the gap to hi is narrower than the panel below)
            if edges.size > 3:
                keep = np.flatnonzero(hi - edges[1:-1] >= edges[1:-1] - edges[:-2])
                last = int(keep[-1]) + 1 if keep.size else 1
                edges = np.append(edges[:last + 1], hi)
            if edges.size == 2:
                edges = np.array([lo, 0.5 * (lo + hi), hi])
        xs, ws = [], []
        for start, end, sign in ((edges[0], edges[1], 1.0), (hi, edges[-2], -1.0)):
            if sign < 0.0 and not (self._root_at_top and edges.size > 2):
                break
            t1 = math.sqrt(abs(end - start))
            t = 0.5 * t1 * (_GL_X + 1.0)
            xs.append(start + sign * t * t)
            ws.append(0.5 * t1 * _GL_W * 2.0 * t)
        inner = edges[1:-1] if self._root_at_top and edges.size > 2 else edges[1:]
        a, b = inner[:-1, None], inner[1:, None]
        xs.append((0.5 * (a + b) + 0.5 * (b - a) * _GL_X).ravel())
        ws.append((0.5 * (b - a) * _GL_W).ravel())
        return np.concatenate(xs), np.concatenate(ws)

    def _weight(self, u, w, d_p):
        """Quadrature weights times the summits per unit height at z = d_p + u (per unit nominal area: n phi(z))."""
        z = (d_p + u) / self.sigma
        return self.density * w * np.exp(-0.5 * z * z) / (_SQRT2PI * self.sigma)

    def state(self, d, d_c, d_p):
        """(pressure Pa (+ compressive), stored energy J/m^2, contact density 1/m^2) at separation d (m)."""
        u_met, u_held = self.bounds(d, d_c, d_p)
        u, w = self._nodes(*self._span(max(u_met, u_held, 0.0), d_p))
        if u.size == 0:
            return 0.0, 0.0, 0.0
        f, en = self.law.branch(u - (d - d_p), u)
        q = self._weight(u, w, d_p)
        return float(q @ f), float(q @ en), float(q.sum())

    def axis_state(self, d, d_c, d_p):
        """(pressure Pa, contacts 1/m^2) per unit nominal area at separation d (m): `state` with the Gaussian density
        whatever this surface's weight (a footprint's: its nominal pressure on the axis)."""
        u_met, u_held = self.bounds(d, d_c, d_p)
        u, w = self._nodes(*self._span(max(u_met, u_held, 0.0), d_p))
        if u.size == 0:
            return 0.0, 0.0
        q = PlasticGWSurface._weight(self, u, w, d_p)
        return float(q @ self.law.branch(u - (d - d_p), u)[0]), float(q.sum())

    def plastic_work(self, d_p):
        """Plastic work (J/m^2) of all summits after the deepest separation d_p (m)."""
        u, w = self._nodes(*self._span(max(self.law.yield_approach, 0.0), d_p))
        return float(self._weight(u, w, d_p) @ self.law.plastic_work(u)) if u.size else 0.0

    def released(self, d, d_c, d_p):
        """Hysteresis (J/m^2) of the summits met in this contact that have let go at separation d (m)."""
        u_met, u_held = self.bounds(d, d_c, d_p)
        lo = max(u_met, 0.0)
        u, w = self._nodes(*self._span(lo, d_p, max(u_held, lo)))
        return float(self._weight(u, w, d_p) @ self.law.loop_energy(u)) if u.size else 0.0

    def jumps(self, d, d_c, d_p, d_0):
        """Losses (J/m^2) booked at the summits' jumps in this contact: the loops of those that let go (a JKR summit
        jumps in at no cost; d_0, the deepest separation before the contact, does not enter)."""
        return self.released(d, d_c, d_p)

    def release_separation(self, d_c, d_p):
        """d - d_p (m) beyond which no summit holds: the tallest's fold, or (d_c = inf, none met) its surface."""
        u_top = self.z_top - d_p
        return float((self.hold if math.isfinite(d_c) else self.recovery)(u_top))

    def touch_separation(self, d_p):
        """None: a JKR summit exerts nothing before it touches (the contact starts at the tallest summit)."""
        return None

    def check_depth(self, d_p):
        """The closed forms hold at any depth: nothing to refuse."""

    def plasticity_index(self, hardness: float) -> float:
        """Greenwood-Williamson psi = (E*/H) sqrt(sigma/beta) of these summits (hardness H in Pa)."""
        return self.law.e_star / hardness * math.sqrt(self.sigma / self.law.radius)


class RollerFootprint(PlasticGWSurface):
    """The same summits under a rigid roller of radius R and length l (m): values per roller (N, J), not per area.

    Under the roller the separation is d(x) = d + x^2/2R across the footprint, and so are d_c(x) and d_p(x): the
    differences d - d_p and d_c - d_p, hence the summit sets u > u_a and each summit's state as a function of
    u = z - d_p(x), are the same at every x. Only the number of summits at height z = d_p(x) + u changes, so the
    footprint integral l int dx n int du (...) phi(d_p(x) + u) is the mean field's with phi(z) replaced by

        K(z) = l int dx phi(z + x^2/2R) [z + x^2/2R <= z_max] = l sqrt(2R) int_0^{sqrt(z_max - z)} 2 phi(z + t^2) dt

    (x^2 = 2R t^2), evaluated by 24-node Gauss-Legendre in t; z, d, d_c, d_p are the values on the roller's axis.
    K falls to 0 as sqrt(z_max - z) at the top summit, so the last panel in u is taken in u = u_top - t^2.
    The roller is rigid and the substrate below the summits too (no half-space deflection), as in
    `continuum.laws.rough_rigid`, and it stays on the spot it flattened (repeated bounces, no rolling)."""

    def __init__(self, law: PlasticSummitLaw, sigma: float, density: float, z_max: float, radius: float,
                 length: float):
        super().__init__(law, sigma, density, z_max)
        self.roller_radius, self.length = float(radius), float(length)
        self._tx, self._tw = np.polynomial.legendre.leggauss(24)

    _root_at_top = True
    #: summits far below the axis height still touch the roller away from its axis (K(z) falls only as
    #: |z|^(-1/2)): none is dropped; below z_floor K is smooth on the scale of the distance to the heights' range
    #: (K(z) = l sqrt(2R) int phi(y) (y - z)^(-1/2) dy), where the panels grow with that distance
    _clip_floor = False

    def _weight(self, u, w, d_p):
        z = d_p + u
        top = np.sqrt(np.maximum(self.z_top - z, 0.0))
        t = 0.5 * top[:, None] * (self._tx + 1.0)
        y = (z[:, None] + t * t) / self.sigma
        k = (0.5 * top * (np.exp(-0.5 * y * y) @ self._tw)) * 2.0 / (_SQRT2PI * self.sigma)
        return self.density * w * self.length * math.sqrt(2.0 * self.roller_radius) * k
