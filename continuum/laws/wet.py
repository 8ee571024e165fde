"""A rough roller with capillary bridges: any averaged dry rough law plus time-dependent menisci.

The dry law (GW summits, rigid substrate or elastic half-space) is unchanged; bridges add an
attraction that depends on the contact time t (from first touch of this impact) and on the gap.
Bridge physics: ``continuum.wet.menisci`` (force F(g), energy U(g), Kelvin gap D_K, h_mw(t)).

Geometry and history (rigid geometry for the bridges)
-----------------------------------------------------
A summit of height z at x across the roller has gap g = d(x) - z with d(x) = z_top + h + x^2/(2R)
(h: the driver's gap, measured from the tallest summit z_top). Write u = z - z_top - x^2/(2R), the
summit's height above the roller's datum parabola; then g = h - u. Bridges form at every summit
with g <= h_mw(t) and break at g > D_K, so the bridged summits at every x are exactly those with
u >= s, one offset s for the whole footprint, updated after each accepted step like the GW
threshold (paper notes on eq 11):

    s <- max(min(s, h - h_mw(t)), h - D_K),      s = +inf before the first bridge.

(Lower summits form bridges last and break first, so a single offset is exact for any path.)
Force, energy and formation work are double integrals over x and z done with Gauss-Legendre nodes
in x (panels split where the integrand has kinks) and closed-form Gaussian moments in z (the bridge
law is piecewise quadratic in g): about 8 us per evaluation compiled (`bridge_kernel`), nothing before t_a.

The bridges see the rigid geometry d(x): with the elastic half-space on, the half-space deflection
(femtometres under the paper's roller) is left out of the bridges' gaps; the record says so.

Energy books. The law's stored energy adds sum U(g) over bridges (negative). When bridges form at
gap g_f their energy U(g_f) appears at once: that is work the condensing liquid does, booked as
`formation` (positive, with the dissipation, so E_kin + E_pot + stored + booked stays constant).
At rupture U = 0: nothing to book. Over a contact the body loses exactly the formation work.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import special

from ..wet import menisci as men
from . import bridge_kernel as bk
from .base import ContactLaw

_SQRT2PI = math.sqrt(2.0 * math.pi)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)


def _coefficients(solid: float) -> dict:
    """The bridge law's coefficients per kind, as the compiled kernel takes them (`solid`: solid pull / F0)."""
    return {kind: tuple(np.array(c, dtype=float) for c in men.bridge_polynomials(kind, solid))
            for kind in ("force", "energy")}


def _moments(a, b):
    """int_a^b t^k phi(t) dt, k = 0, 1, 2 (standard normal; zero where b <= a)."""
    a = np.asarray(a, float)
    b = np.maximum(np.asarray(b, float), a)
    pa, pb = np.exp(-0.5 * a * a) / _SQRT2PI, np.exp(-0.5 * b * b) / _SQRT2PI
    m0 = np.where(a > 0, special.ndtr(-a) - special.ndtr(-b), special.ndtr(b) - special.ndtr(a))
    m1 = pa - pb
    with np.errstate(invalid="ignore"):
        ta = np.where(np.isfinite(a), a * pa, 0.0)
        tb = np.where(np.isfinite(b), b * pb, 0.0)
    return m0, m1, m0 + ta - tb


class MeniscusBridges:
    """Bridges on the summits under a roller (rigid geometry): state, force, energy, formation work.

    stats: SummitStatistics (sigma m, density 1/m^2, radius m); z_top: tallest summit (m above the
    summit mean plane); radius R and length l of the roller (m); f0 (N) and d_k (m) per bridge; t_a (s)
    and growth length h1 (m) of h_mw(t); solid_pull (N): the solid-solid pull a bridge takes from each
    compressed summit it wets (``continuum.wet.menisci.solid_pull_inside_bridge``; 0 = the paper's additive eq 14).
    """

    def __init__(self, stats, z_top: float, radius: float, length: float, f0: float, d_k: float,
                 t_a: float, growth_length: float, solid_pull: float = 0.0):
        self.sigma, self.density = stats.sigma, stats.density
        self.z_top, self.radius, self.length = z_top, radius, length
        self.f0, self.d_k, self.t_a, self.h1 = f0, d_k, t_a, growth_length
        self.set_solid_pull(solid_pull)
        self.reset()

    def set_solid_pull(self, solid_pull: float) -> None:
        """Take `solid_pull` (N) from every compressed bridged summit (the wet solid-solid adhesion)."""
        self.solid_pull = float(solid_pull)
        self.solid = self.solid_pull / self.f0 if self.f0 > 0.0 else 0.0
        self.coeffs = _coefficients(self.solid)

    def reset(self) -> None:
        self.s = math.inf                 # bridged summits: u >= s
        self.formed = 0.0                 # formation work booked this contact (J)
        self.t_acc = 0.0                  # contact time of the last accepted state (s)
        self.g_acc = 0.0                  # gap of the boundary summit u = s at that state (m)
        self.max_bridges = 0.0
        self.ever = False

    def offset(self, gap: float, t: float) -> float:
        """Trial offset s_eff at (gap, contact time t)."""
        h_mw = men.bridgeable_gap(t, self.t_a, self.h1, self.d_k)
        s = min(self.s, gap - h_mw) if math.isfinite(h_mw) else self.s
        return max(s, gap - self.d_k)

    def _integral(self, kind: str, gap: float, s_lo: float, s_hi: float = math.inf, formed_at=None) -> float:
        """sum over bridged summits with s_lo <= u <= s_hi of F (kind 'force', N) or U ('energy', J),
        or their count ('count'). `formed_at` = (g_hi, g_lo): evaluate U not at the summits' present
        gaps but at their formation gaps, linear in u from g_hi at u = s_hi to g_lo at u = s_lo.

        Compiled (`continuum.laws.bridge_kernel`, ~30x faster); `_integral_numpy` is the same sum in NumPy,
        the reference the kernel is tested against."""
        g_hi, g_lo = formed_at if formed_at is not None else (0.0, 0.0)
        comp, stretch = self.coeffs["energy" if kind == "count" else kind]
        return bk.bridge_integral(bk.KINDS[kind], float(gap), float(s_lo), float(s_hi), formed_at is not None,
                                  float(g_hi), float(g_lo), self.z_top, self.radius, self.length, self.density,
                                  self.sigma, self.f0, self.d_k, comp, stretch, _GL_X, _GL_W)

    def _integral_numpy(self, kind: str, gap: float, s_lo: float, s_hi: float = math.inf, formed_at=None) -> float:
        """`_integral` in NumPy: the reference for the compiled kernel."""
        q_top = min(-s_lo, self.d_k - gap)             # x^2/2R beyond which no summit is in range
        if not q_top > 0.0 or s_hi <= s_lo:
            return 0.0
        two_r = 2.0 * self.radius
        x_top = math.sqrt(two_r * q_top)
        kinks = sorted(math.sqrt(two_r * q) for q in (-gap, -s_hi) if 0.0 < q < q_top)
        edges = [0.0, *kinks, x_top]
        xs, ws = [], []
        for a, b in zip(edges[:-1], edges[1:]):
            xs.append(0.5 * (a + b) + 0.5 * (b - a) * _GL_X)
            ws.append(0.5 * (b - a) * _GL_W)
        x, w = np.concatenate(xs), np.concatenate(ws)
        q = x * x / two_r
        d = self.z_top + gap + q                       # local separation (m)
        lo = np.maximum(self.z_top + q + s_lo, d - self.d_k)
        hi = np.minimum(self.z_top, self.z_top + q + s_hi)
        sig = self.sigma
        total = np.zeros_like(x)
        if kind == "count":
            total = _moments(lo / sig, hi / sig)[0]
        else:
            comp, stretch = men.bridge_polynomials(kind, self.solid)
            scale = self.f0 if kind == "force" else self.f0 * self.d_k
            alpha, beta = d / self.d_k, -sig / self.d_k      # g/D_K = alpha + beta t, t = z/sigma
            pieces = ((comp, (np.maximum(lo, d), hi)), (stretch, (lo, np.minimum(hi, d))))
            if formed_at is not None:                       # g = g_hi + k (u - s_hi), all stretched
                g_hi, g_lo = formed_at
                k = (g_hi - g_lo) / (s_hi - s_lo)
                alpha = (g_hi - k * (self.z_top + q + s_hi)) / self.d_k
                beta = k * sig / self.d_k
                pieces = ((stretch, (lo, hi)),)
            for (a0, a1, a2), (za, zb) in pieces:
                c0 = a0 + a1 * alpha + a2 * alpha * alpha
                c1 = (a1 + 2.0 * a2 * alpha) * beta
                c2 = a2 * beta * beta
                m0, m1, m2 = _moments(za / sig, zb / sig)
                total += scale * (c0 * m0 + c1 * m1 + c2 * m2)
        return float(2.0 * self.length * self.density * np.dot(total, w))

    def full_force(self, gap: float) -> float:
        """Attraction (N, >= 0) at `gap` with every summit within D_K bridged (a bound on the bridges' pull)."""
        return self._integral("force", gap, gap - self.d_k)

    def force(self, gap: float, t: float) -> float:
        """Total attraction of the bridges (N, >= 0) at a trial state."""
        s = self.offset(gap, t)
        return self._integral("force", gap, s) if math.isfinite(s) else 0.0

    def energy(self, gap: float, t: float) -> float:
        """Stored energy of the bridges (J, <= 0) at a trial state."""
        s = self.offset(gap, t)
        return self._integral("energy", gap, s) if math.isfinite(s) else 0.0

    def pending_formation(self, gap: float, t: float) -> float:
        """Formation work (J, >= 0) of the bridges a trial state would form beyond the accepted ones.

        At t_a every summit in contact bridges where it stands: -sum U(g) over them. After that,
        bridges form one by one as the bridgeable gap h_mw(t) reaches them (by its growth or by the
        roller's approach), so each forms at gap h_mw(t_f) exactly and books -U(h_mw(t_f)). Between
        the last accepted state and this one the boundary moved from u = s (gap g_acc) to u = s_eff
        (gap h_mw(t)); each summit's formation gap is interpolated linearly in u between the two and
        -U integrated exactly against the Gaussian (second order in the step; booking every new
        bridge at the step's end is first order, and with F0 * dh_mw per bridge comparable to a
        nanoscale impact energy that is not good enough).
        """
        s = self.offset(gap, t)
        if not s < self.s:
            return 0.0
        if not math.isfinite(self.s):
            return -self._integral("energy", gap, s)
        g_now = gap - s                                           # = h_mw(t): the new boundary's gap
        g_acc = min(self.g_acc, men.bridgeable_gap(max(self.t_acc, self.t_a), self.t_a, self.h1, self.d_k))
        return -self._integral("energy", gap, s, self.s, formed_at=(g_acc, g_now))

    def accept(self, gap: float, t: float) -> None:
        s = self.offset(gap, t)
        if s < self.s:
            self.formed += self.pending_formation(gap, t)
            self.ever = True
        self.s = s
        self.t_acc = t
        self.g_acc = gap - s if math.isfinite(s) else 0.0
        if math.isfinite(s):
            self.max_bridges = max(self.max_bridges, self._integral("count", gap, s))


class WetRoughRoller(ContactLaw):
    """`dry` (an averaged rough roller law with z_top, radius, length) plus MeniscusBridges."""

    has_history = True
    bound_is_final = True
    time_dependent = True

    def __init__(self, dry: ContactLaw, bridges: MeniscusBridges, record: dict):
        self.dry, self.bridges, self.record = dry, bridges, record
        if record.get("solid_pull"):
            bridges.set_solid_pull(record["solid_pull"])
        self.name = dry.name + "+menisci"
        self.touch_gap = dry.touch_gap
        self.z_top = dry.z_top
        self.t = 0.0
        self.longest_contact = 0.0
        self.contacts_with_bridges = 0

    # -- time
    def set_time(self, t_contact: float) -> None:
        self.t = t_contact

    #: While bridges can form, the roller may move at most this fraction of D_K per step at twice
    #: the impact speed: formation gaps are interpolated linearly within a step (second order).
    STEP_FRACTION_OF_KELVIN_GAP = 0.05

    def max_step(self, speed: float) -> float:
        if self.t < self.bridges.t_a:
            return float("inf")
        return self.STEP_FRACTION_OF_KELVIN_GAP * self.bridges.d_k / (2.0 * speed)

    def time_events(self) -> list[float]:
        """Contact times at which the force jumps (bridges appear on every summit in contact at t_a)."""
        return [self.bridges.t_a]

    # -- ContactLaw
    def prepare(self, mass, speed, gravity):
        """Size the dry law for this impact with the bridges' pull added to the weight.

        Bridges can pull the roller deeper than the dry estimate; their force at twice the dry
        quasi-static depth with every summit within D_K bridged bounds the pull over the contact.
        """
        if not self.dry.has_rigid_approach:
            # a summit law without a rigid approach branch (plastic summits keep every summit they may reach)
            self.dry.prepare(mass, speed, gravity)
            return
        depth = self.dry.quasi_static_depth(0.5 * mass * speed * speed, mass * gravity)
        deep = -2.0 * depth
        pull = self.bridges.full_force(deep)
        self.dry.prepare(mass, speed, gravity + pull / mass)

    def forget_history(self):
        self.dry.forget_history()

    def reset(self):
        if self.bridges.ever:
            self.contacts_with_bridges += 1
        self.longest_contact = max(self.longest_contact, self.t)
        self.dry.reset()
        self.bridges.reset()
        self.t = 0.0

    def force(self, gap):
        return self.dry.force(gap) - self.bridges.force(gap, self.t)

    def stiffness(self, gap):
        h = 1e-6 * max(self.bridges.d_k, abs(gap))
        k_b = (self.bridges.force(gap + h, self.t) - self.bridges.force(gap - h, self.t)) / (2.0 * h)
        return self.dry.stiffness(gap) + k_b

    def stored_energy(self, gap):
        return self.dry.stored_energy(gap) + self.bridges.energy(gap, self.t)

    def dissipated(self, gap):
        return (self.dry.dissipated(gap) + self.bridges.formed
                + self.bridges.pending_formation(gap, self.t))

    def on_release(self):
        return self.dry.on_release() + self.bridges.formed

    def accept(self, gap):
        self.dry.accept(gap)
        self.bridges.accept(gap, self.t)
        self.longest_contact = max(self.longest_contact, self.t)

    def compiled(self, t0: float):
        """Before t_a no bridge exists and this law is its dry law: the dry law's compiled form, stopping at t_a
        (where bridges condense on every summit in contact and this law goes on in Python). Asked again after that
        stop (contact time t > 0; t_a itself up to rounding), it has no compiled form: None."""
        if self.t > 0.0:
            return None
        dry = self.dry.compiled(t0)
        if dry is None:
            return None
        dry.t_stop = t0 + self.bridges.t_a
        return dry

    def compiled_commit(self, state, last_accept: float) -> None:
        # what `accept` does before t_a at every accepted state: the dry history, the contact time seen
        self.dry.compiled_commit(state, last_accept)
        self.bridges.t_acc = last_accept
        self.bridges.g_acc = 0.0
        self.longest_contact = max(self.longest_contact, last_accept)

    def release_gap(self):
        dry = self.dry.release_gap()
        return max(dry, self.bridges.d_k) if self.bridges.ever else dry

    def length_scale(self, mass, speed):
        return self.dry.length_scale(mass, speed)

    def snapshot(self, gap):
        return self.dry.snapshot(gap)

    def diagnostics(self):
        out = dict(self.dry.diagnostics())
        out["menisci"] = {"longest_contact_s": max(self.longest_contact, self.t),
                          "condensation_time_s": self.bridges.t_a,
                          "contacts_with_bridges": self.contacts_with_bridges + (1 if self.bridges.ever else 0),
                          "max_bridges": self.bridges.max_bridges}
        return out

    def describe(self):
        return {**self.dry.describe(), "name": self.name, "menisci": self.record}
