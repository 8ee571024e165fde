"""Capillary bridges on the individual summits of a discrete realisation: the mean field's bridges, summit by summit.

The mean-field wet law (`continuum.laws.wet`) sums the bridge law of `continuum.wet.menisci` over the Gaussian density
of summits under the roller. A discrete realisation (`continuum.laws.discrete_roller`, one ensemble member, or a map
patch) has its own summits: each grows its own bridge, on the same clock and by the same law:

- summit i sits at u_i = e_i - z_top below the roller's datum parabola (e_i its effective height, z_top the
  realisation's tallest), so at the driver's gap h its gap is g_i = h - u_i (rigid geometry, as in the mean field);
- no bridge before t_a; after it the bridgeable gap is h_mw(t) = min(h1 ln(t/t_a), D_K) and every summit with
  g_i <= h_mw(t) carries a bridge until g_i > D_K. Lower summits bridge last and break first, so the bridged summits
  are those with u_i >= s, one offset for the realisation, updated exactly as the mean field's
  (`MeniscusBridges.offset`, `accept`): a prefix of the summits sorted by effective height;
- each bridge pulls F(g_i) and stores U(g_i) (`continuum.wet.menisci.bridge_force`, `bridge_energy`: constant Kelvin
  radius, rupture at D_K, U(D_K) = 0) with the wet solid-solid pull taken from compressed bridged summits (the
  `solid_pull` of `continuum.wet.menisci.solid_pull_inside_bridge`, the same DMT correction as the mean field);
- the formation work is booked as in the mean field: at t_a -sum U(g_i) over the summits bridged where they stand,
  after it -U at each summit's formation gap, interpolated linearly in u between the last accepted boundary and the
  trial one (`MeniscusBridges.pending_formation`, which this class inherits: only the sum changes).

So this class is `MeniscusBridges` with its Gaussian double integral (`_integral`) replaced by a sum over the kept
summits of the realisation; `continuum.laws.wet.WetRoughRoller` wraps it round the discrete law unchanged. The
summits are read from the dry law at every call (`source.eff`, `source.z_top`), so a kept set deepened mid-contact
is seen at once. A sum over the summits in range costs O(bridged summits) per evaluation, a few microseconds here.
"""
from __future__ import annotations

import math

import numpy as np

from ..numerics import kernel_laws as kl
from ..numerics import wet_discrete_kernel as wk
from ..numerics.compiled_contact import CompiledLaw
from .wet import MeniscusBridges, WetRoughRoller
from .wet_summits_compiled import bridge_block, bridge_state, take_back_bridges


class DiscreteBridges(MeniscusBridges):
    """Bridges on the summits of a discrete realisation `source` (an object with `eff`, the kept summits' effective
    heights sorted descending (m), and `z_top`, the tallest (m): `DiscreteRoughRoller`). f0 (N), d_k (m) per bridge;
    t_a (s) and growth length h1 (m) of h_mw(t); solid_pull (N): the solid pull taken from compressed bridged summits.
    """

    def __init__(self, source, f0: float, d_k: float, t_a: float, growth_length: float, solid_pull: float = 0.0):
        self.source = source
        self.f0, self.d_k, self.t_a, self.h1 = float(f0), float(d_k), float(t_a), float(growth_length)
        self.z_top = float(source.z_top)
        self._eff_for = None
        self.set_solid_pull(solid_pull)
        self.reset()

    def _summits(self, lo: float, hi: float) -> np.ndarray:
        """u_i (m, descending) of the kept summits with lo <= u_i <= hi."""
        eff = self.source.eff
        if eff is not self._eff_for:                          # the kept set changed (first call, or deepened)
            self._u = np.asarray(eff, float) - float(self.source.z_top)
            self._neg = -self._u                              # ascending, for searchsorted
            self._eff_for = eff
        u, neg = self._u, self._neg
        i0 = int(np.searchsorted(neg, -hi, side="left")) if math.isfinite(hi) else 0
        i1 = int(np.searchsorted(neg, -lo, side="right"))
        return u[i0:i1]

    def _integral(self, kind: str, gap: float, s_lo: float, s_hi: float = math.inf, formed_at=None) -> float:
        """Sum over the bridged summits with s_lo <= u_i <= s_hi (and g_i < D_K) of F (kind 'force', N), U ('energy',
        J) or their number ('count'); `formed_at` = (g_hi, g_lo): U at each summit's formation gap, linear in u from
        g_hi at u = s_hi to g_lo at u = s_lo (the mean field's rule, `MeniscusBridges._integral`)."""
        if s_hi <= s_lo:
            return 0.0
        d_k = self.d_k
        us = [x for x in self._summits(max(s_lo, gap - d_k), s_hi).tolist() if gap - x < d_k]
        if not us:
            return 0.0
        if kind == "count":
            return float(len(us))
        comp, stretch = self.coeffs[kind]
        scale = self.f0 if kind == "force" else self.f0 * d_k
        total = 0.0
        if formed_at is not None:                      # U at the formation gaps, all stretched (h_mw >= 0)
            g_hi, g_lo = formed_at
            k = (g_hi - g_lo) / (s_hi - s_lo)
            a0, a1, a2 = stretch
            for u in us:
                x = (g_hi + k * (u - s_hi)) / d_k
                total += a0 + x * (a1 + x * a2)
            return scale * total
        for u in us:                                   # the law of `continuum.wet.menisci` on its two pieces
            x = (gap - u) / d_k
            a0, a1, a2 = comp if x <= 0.0 else stretch
            total += a0 + x * (a1 + x * a2)
        return scale * total

    def prefix(self, gap: float, t: float) -> int:
        """Number of kept summits, in the source's order, that carry a bridge at a trial state (they are a prefix:
        u_i >= s; every one within D_K since s >= gap - D_K)."""
        s = self.offset(gap, t)
        if not math.isfinite(s):
            return 0
        self._summits(s, math.inf)                           # refresh the cached heights if the kept set changed
        return int(np.searchsorted(self._neg, -s, side="right"))

    def bridged(self, gap: float, t: float) -> int:
        """Number of summits carrying a bridge at a trial state (gap m, contact time t s)."""
        s = self.offset(gap, t)
        return int(self._integral("count", gap, s)) if math.isfinite(s) else 0


class BridgedDiscreteRoller(WetRoughRoller):
    """`WetRoughRoller` round a discrete summit law with `DiscreteBridges`, compiled after t_a too.

    The dry law's compiled form (`compiled`) runs the contact up to t_a and stops there; its history at that point
    (the dry kernel's S: the deepest gap of this contact, for plastic summits with their state before it) and its
    P and T are kept, so that after the driver has accepted the state at t_a the contact goes on in
    `continuum.numerics.wet_discrete_kernel.LAW_BRIDGED`: the same dry law, with the bridges' blocks after its own."""

    #: the dry law's compiled form issued at touch; which form was issued last ('dry', 'bridged'); the gap accepted
    #: at t_a (None: not reached in this contact)
    _inner: CompiledLaw | None = None
    _issued: str | None = None
    _gap_acc: float | None = None

    def reset(self):
        super().reset()
        self._inner, self._issued, self._gap_acc = None, None, None

    def accept(self, gap):
        super().accept(gap)
        self._gap_acc = gap

    def diagnostics(self):
        """The wet law's, with what the solids inside a bridge follow (each member's record says it)."""
        out = super().diagnostics()
        inside = self.record.get("solids_inside_bridges")
        if inside is not None:
            out["menisci"] = {**out["menisci"], "solids_inside_bridges": inside}
        return out

    def compiled(self, t0: float):
        if self.t == 0.0:                    # at touch: the dry form up to t_a
            form = super().compiled(t0)
            self._inner, self._issued = form, "dry"
            return form
        inner = self._inner
        if inner is None or self._gap_acc is None:
            return None
        u = inner.T[0]
        src = self.bridges.source
        if u.size != src.eff.size or not np.array_equal(u, src.eff - src.z_top):
            return None                     # the kept summits changed since the contact began: Python goes on
        S = inner.S.copy()
        kl.law_accept(inner.kind, self._gap_acc, S, inner.P, inner.T)      # the accepted state at t_a
        B = bridge_block(self.bridges, t0)
        B[wk.B_INNER], B[wk.B_S] = inner.kind, S.size
        self._issued = "bridged"
        return CompiledLaw(wk.LAW_BRIDGED, np.concatenate([inner.P, B]), inner.T,
                           np.concatenate([S, bridge_state(self.bridges)]))

    def compiled_commit(self, state, last_accept: float) -> None:
        if self._issued != "bridged":
            super().compiled_commit(state, last_accept)
            return
        n = self._inner.S.size
        self.dry.compiled_commit(state[:n], last_accept)
        take_back_bridges(self, state[n:], last_accept)


def wet_discrete(dry, source, parameters: dict):
    """`dry` (a discrete summit law: `DiscreteRoughRoller`, or plastic summits on its realisation) with a bridge on
    each of `source`'s summits (the elastic discrete law whose kept summits `dry` runs on), by the scene's meniscus
    `parameters` (`continuum.model.regime.meniscus_parameters`)."""
    p = parameters
    bridges = DiscreteBridges(source, p["bridge_pull_off"], p["kelvin_gap"], p["condensation_time"],
                              p["growth_length"], p.get("solid_pull", 0.0))
    return BridgedDiscreteRoller(dry, bridges, {**p, "bridges_on": "each summit of the realisation "
                                                "(continuum.laws.discrete_bridges)"})
