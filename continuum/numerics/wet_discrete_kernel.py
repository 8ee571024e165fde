"""Compiled discrete summits with a capillary bridge on each: `continuum.laws.wet_summits` after t_a, in numba.

The Python law (`WetDiscreteRoller`: a `WetSummitRoller` whose bridged summits adhere at W_wet, wrapped with
`DiscreteBridges`, one bridge per summit) is evaluated at every stage of every step once bridges exist; in the
interpreter that is ~13x the cost of a dry ensemble (docs/benchmarks.md). This module is the same arithmetic,
summit by summit and in the same order, so the two forms agree to round-off
(`tests/continuum/test_wet_discrete_kernel.py`):

- summits: the kept ones of the realisation, u_i = e_i - z_top (descending, T[0]); summit i has approach
  delta_i = u_i - h at the driver's gap h (rigid substrate);
- bridges (`continuum.laws.discrete_bridges`, the mean field's rule `continuum.laws.wet.MeniscusBridges`): the
  bridged summits are those with u_i >= s_eff, s_eff = max(min(s, h - h_mw(t)), h - D_K) with h_mw(t) =
  min(h1 ln(t/t_a), D_K) (`continuum.wet.menisci.bridgeable_gap`); each pulls F(g_i) and stores U(g_i)
  (`continuum.wet.menisci.bridge_polynomials`, piecewise quadratic in g/D_K); formation work -U at each summit's
  formation gap, linear in u between the last accepted boundary and the trial one (`pending_formation`);
- summit laws: two classes, the first k_trial summits (the bridged prefix) on the wet law, the rest on the dry one;
  each class is JKR in closed form (`continuum.physics.jkr_kernel`, as `kernel_laws.LAW_DISCRETE`), Hertz, or the
  tabulated approach / retreat branches of a summit law (`continuum.rough.branch_laws`, as
  `kernel_laws.LAW_DISCRETE_BRANCH`). A summit attaches at delta >= delta_in and lets go below delta_out; one
  attached flag per summit (S) is the history, because with two release points the attached set is no longer a
  prefix. A summit that changes class keeps its delta and books its energy jump (`WetSummitRoller._books`).

Layout. P: two class blocks of CLASS_SIZE (dry at 0, wet at CLASS_SIZE), two slots (G_*), then the bridges' block
(B_*). T: T[0] the u_i; T[1], T[2], T[3] the branch tables' delta, force and energy, the four branches (dry
approach, dry retreat, wet approach, wet retreat) one after another, located by the class blocks' index slots. S:
the rigid-table laws' first five slots (so the kernel's checks read the same places), the books (S_*), the bridges'
block (SB_*), then one flag per kept summit.

Plastic mode (P[C_MODE] of the dry block = MODE_PLASTIC): both classes are Thornton-Ning summits
(`continuum.laws.wet_plastic_summits`); the summits are `continuum.numerics.wet_plastic_kernel`'s, with its own slots
after PARAMS and in S, the bridges this module's.

`LAW_BRIDGED` is the other discrete form of `continuum.laws.discrete_bridges` (`wet_discrete`: bridges with the
mean field's DMT solid pull round summits that keep their own law, e.g. plastic summits with menisci.solid_adhesion =
'additive'): any compiled discrete law of `continuum.numerics.kernel_laws` with its P and S followed by the bridges'
blocks.

The contact time is t - P[pb + B_T0] (t: the kernel's absolute time; the laws' `set_time` in Python).

Selectors passed from one compiled function to another are NumPy scalars (`np.int64(k)`, `np.bool_(b)`), not
Python constants: numba compiles the callee once for every literal constant a compiled caller passes
(`Literal[int](k)`), so constant selectors multiplied the kernels' cold compile (docs/benchmarks.md).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..rough.plastic_kernel import count_at_least
from . import wet_plastic_kernel as wp
from .kernel_laws import (
    _H_COEF,
    S_BEYOND_FLAG,
    S_H_MIN,
    S_MAX_CONTACTS,
    _jkr_root,
    _lin,
    law_accept,
    law_dissipated,
    law_force,
    law_stored,
)

#: This law's kind, and the bridges round any other compiled discrete law (`continuum.numerics.kernel_laws` numbers
#: the others 0-4).
LAW_WET_DISCRETE, LAW_BRIDGED = 5, 6
#: Summit-class modes (MODE_PLASTIC, set in the dry block: both classes are Thornton-Ning summits,
#: `continuum.numerics.wet_plastic_kernel`, with its own slots after PARAMS).
MODE_BRANCH, MODE_JKR, MODE_HERTZ, MODE_PLASTIC = 0, 1, 2, 3
#: Slots of a class block.
(C_MODE, C_IN, C_OUT, C_REACH, C_LOOP, C_INV_DELTA0, C_PSCALE, C_ESCALE, C_HERTZ_K, C_A_LO, C_A_HI, C_R_LO,
 C_R_HI) = range(13)
CLASS_SIZE = 13
DRY, WET = 0, CLASS_SIZE
#: The bridges' block of P (from its offset pb): touch time (absolute s), t_a (s), growth length h1, Kelvin gap D_K
#: (m), F0 (N), abort when a bridge forms (1: the contact went on without bridges, so its release gap would grow),
#: the coefficients of the bridge law (force on g <= 0, on 0 < g < D_K, energy the same); for LAW_BRIDGED the inner
#: law's kind and the offset of the bridges' block of S.
(B_T0, B_TA, B_H1, B_DK, B_F0, B_ABORT_ON_FORM) = range(6)
B_COEF = 6
B_INNER, B_S = 18, 19
BRIDGE_PARAMS = 20
#: The bridges' block of S (from its offset sb): offset s (m), formation work (J), contact time and boundary gap of
#: the last accepted state, most bridges, bridges formed this contact (0/1).
(SB_S, SB_FORMED, SB_T_ACC, SB_G_ACC, SB_MAX, SB_EVER) = range(6)
BRIDGE_STATE = 6
#: LAW_WET_DISCRETE: P holds the two class blocks, the end gap (every summit let go and out of reach) and the lowest
#: kept u, then the bridges' block; S the rigid-table laws' five slots, committed bridged prefix, loops booked (dry,
#: wet), switch work (J), 1 + last attached summit, the bridges' block, then one flag per kept summit.
G_END_GAP, G_LOWEST = 2 * CLASS_SIZE, 2 * CLASS_SIZE + 1
G_BRIDGES = 2 * CLASS_SIZE + 2
PARAMS = G_BRIDGES + BRIDGE_PARAMS
(S_K_WET, S_DET_DRY, S_DET_WET, S_SWITCHED, S_K_ATT) = range(5, 10)
S_BRIDGES = 10
S_FLAGS = S_BRIDGES + BRIDGE_STATE

#: What `_summits` returns.
_FORCE, _STORED, _BOOKS = 0, 1, 2


# ----------------------------------------------------------------------------- one summit of a class
@njit(cache=True)
def _value(c, dl, retreat, energy, P, T):
    """Force (N) or, `energy`, stored energy (J) of one summit of class block c at approach dl (m): attached
    (`retreat` True: the retreat branch, JKR's stable branch, Hertz) or free within reach (the approach branch)."""
    mode = P[c + C_MODE]
    if mode == MODE_BRANCH:
        lo, hi = (int(P[c + C_R_LO]), int(P[c + C_R_HI])) if retreat else (int(P[c + C_A_LO]), int(P[c + C_A_HI]))
        return _lin(dl, T[1][lo:hi], T[3][lo:hi] if energy else T[2][lo:hi])
    if not retreat:
        return 0.0
    if mode == MODE_JKR:
        d, s = _jkr_root(dl * P[c + C_INV_DELTA0])
        s3 = s * s * s
        if energy:
            h = _H_COEF[0]
            for j in range(1, _H_COEF.size):
                h = h * s + _H_COEF[j]
            return P[c + C_ESCALE] * d / (s * (s * s + s + 1.0)) * h
        return P[c + C_PSCALE] * s3 * (8.0 / 3.0 * s3 - 4.0)
    if dl > 0.0:
        return P[c + C_HERTZ_K] * dl * math.sqrt(dl) * (0.4 * dl if energy else 1.0)
    return 0.0


@njit(cache=True)
def _attached(c, was, dl, P):
    """The history rule of one summit of class c: attached before or jumped in, and not let go."""
    return (was or dl >= P[c + C_IN]) and dl >= P[c + C_OUT]


@njit(cache=True)
def _energy_in(c, was, dl, P, T):
    """Stored energy (J) of one summit under class c's rule (0 beyond its release and reach)."""
    if _attached(c, was, dl, P):
        return _value(c, dl, np.bool_(True), np.bool_(True), P, T)
    if P[c + C_MODE] == MODE_BRANCH and dl >= -P[c + C_REACH]:
        return _value(c, dl, np.bool_(False), np.bool_(True), P, T)
    return 0.0


# ----------------------------------------------------------------------------- the bridges
@njit(cache=True)
def _h_mw(tc, P, pb):
    """Bridgeable gap h_mw (m) at contact time tc: -inf before t_a (`continuum.wet.menisci.bridgeable_gap`)."""
    if tc < P[pb + B_TA]:
        return -math.inf
    return min(P[pb + B_H1] * math.log(tc / P[pb + B_TA]), P[pb + B_DK])


@njit(cache=True)
def _offset(gap, tc, S, P, pb, sb):
    """Trial offset s_eff (m): the bridged summits are those with u >= s_eff (`MeniscusBridges.offset`)."""
    h = _h_mw(tc, P, pb)
    s = min(S[sb + SB_S], gap - h) if math.isfinite(h) else S[sb + SB_S]
    return max(s, gap - P[pb + B_DK])


@njit(cache=True)
def _bridge_sum(kind, gap, s_lo, s_hi, formed, g_hi, g_lo, P, pb, u):
    """Sum over the summits u (descending) with s_lo <= u <= s_hi and g = gap - u < D_K of F (kind 0, N), U (1, J)
    or their number (2); `formed`: U at the formation gaps, linear in u from g_hi at s_hi to g_lo at s_lo
    (`DiscreteBridges._integral`, the same terms in the same order)."""
    if s_hi <= s_lo:
        return 0.0
    d_k = P[pb + B_DK]
    n = count_at_least(u, max(s_lo, gap - d_k))
    c0 = pb + B_COEF + (0 if kind == 0 else 6)
    k = (g_hi - g_lo) / (s_hi - s_lo) if formed else 0.0
    total = 0.0
    count = 0
    for i in range(n):
        ui = u[i]
        if ui > s_hi or not gap - ui < d_k:
            continue
        count += 1
        if kind == 2:
            continue
        if formed:
            x = (g_hi + k * (ui - s_hi)) / d_k
            c = c0 + 3
        else:
            x = (gap - ui) / d_k
            c = c0 if x <= 0.0 else c0 + 3
        total += P[c] + x * (P[c + 1] + x * P[c + 2])
    if kind == 2:
        return float(count)
    return (P[pb + B_F0] if kind == 0 else P[pb + B_F0] * d_k) * total


@njit(cache=True)
def _bridges(what, gap, tc, S, P, pb, sb, u):
    """The bridges' pull (N, what 0), stored energy (J, 1) or formation work booked this contact with the trial
    state's pending part (J, 2) (`MeniscusBridges.force`, `energy`, `formed + pending_formation`)."""
    s = _offset(gap, tc, S, P, pb, sb)
    if what < 2:
        if not math.isfinite(s):
            return 0.0
        return _bridge_sum(np.int64(what), gap, s, math.inf, np.bool_(False), 0.0, 0.0, P, pb, u)
    s_acc = S[sb + SB_S]
    pending = 0.0
    if s < s_acc:
        if s_acc == math.inf:
            pending = -_bridge_sum(np.int64(1), gap, s, math.inf, np.bool_(False), 0.0, 0.0, P, pb, u)
        else:
            g_acc = min(S[sb + SB_G_ACC], _h_mw(max(S[sb + SB_T_ACC], P[pb + B_TA]), P, pb))
            pending = -_bridge_sum(np.int64(1), gap, s, s_acc, np.bool_(True), g_acc, gap - s, P, pb, u)
    return S[sb + SB_FORMED] + pending


@njit(cache=True)
def _bridges_accept(gap, tc, S, P, pb, sb, u):
    """`MeniscusBridges.accept`; flags an abort where the first bridge forms in a contact that began without."""
    s = _offset(gap, tc, S, P, pb, sb)
    if s < S[sb + SB_S]:
        S[sb + SB_FORMED] = _bridges(np.int64(2), gap, tc, S, P, pb, sb, u)
        if P[pb + B_ABORT_ON_FORM] != 0.0 and S[sb + SB_EVER] == 0.0:
            S[S_BEYOND_FLAG] = 1.0               # the release gap grows to D_K: the Python stepper goes on
        S[sb + SB_EVER] = 1.0
    S[sb + SB_S] = s
    S[sb + SB_T_ACC] = tc
    S[sb + SB_G_ACC] = gap - s if math.isfinite(s) else 0.0
    if math.isfinite(s):
        bridged = _bridge_sum(np.int64(2), gap, s, math.inf, np.bool_(False), 0.0, 0.0, P, pb, u)
        S[sb + SB_MAX] = max(S[sb + SB_MAX], bridged)


@njit(cache=True)
def _prefix(gap, tc, S, P, pb, sb, u):
    """Number of summits bridged at a trial state (a prefix of the kept ones: `DiscreteBridges.prefix`)."""
    s = _offset(gap, tc, S, P, pb, sb)
    if not math.isfinite(s):
        return 0
    return count_at_least(u, s)


# ----------------------------------------------------------------------------- the summits
@njit(cache=True)
def _summits(what, gap, k_trial, S, P, T, out):
    """Force (N), stored energy (J) or the books of a trial state over the summits attached or in reach, the first
    k_trial on the wet class (`WetSummitRoller._summits_at`, `_books`). `out` (what = _BOOKS): loops let go dry,
    wet, switch work (J). Flags a state below the kept summits."""
    u = T[0]
    n = u.size
    reach = max(P[DRY + C_REACH], P[WET + C_REACH])
    level = gap - max(reach, -P[DRY + C_OUT], -P[WET + C_OUT])
    if level < P[G_LOWEST]:
        S[S_BEYOND_FLAG] = 1.0
    k = max(int(S[S_K_ATT]), count_at_least(u, gap - reach), min(k_trial, n))
    k_wet = int(S[S_K_WET])
    final = gap >= P[G_END_GAP]
    total = 0.0
    for i in range(k):
        dl = u[i] - gap
        was = S[S_FLAGS + i] != 0.0
        c = WET if i < k_trial else DRY
        att = _attached(c, was, dl, P)
        if what == _FORCE:
            if att:
                total += _value(c, dl, np.bool_(True), np.bool_(False), P, T)
            elif P[c + C_MODE] == MODE_BRANCH and dl >= -P[c + C_REACH]:
                total += _value(c, dl, np.bool_(False), np.bool_(False), P, T)
            continue
        if what == _STORED:
            total += _energy_in(c, was, dl, P, T) if not final else 0.0
            continue
        att = att and not final                  # at the release gap every summit has let go
        c_old = WET if i < k_wet else DRY
        if c_old == c:
            if was and not att:
                out[0 if c == DRY else 1] += 1.0
            continue
        held = was and dl >= P[c_old + C_OUT] and not final     # the committed state under the old class
        if was and not held:
            out[0 if c_old == DRY else 1] += 1.0
        old = 0.0
        if held:
            old = _value(c_old, dl, np.bool_(True), np.bool_(True), P, T)
        elif not was and P[c_old + C_MODE] == MODE_BRANCH and dl >= -P[c_old + C_REACH]:
            old = _value(c_old, dl, np.bool_(False), np.bool_(True), P, T)
        new = _energy_in(c, was, dl, P, T) if not final else 0.0
        out[2] += old - new
    return total


@njit(cache=True)
def wet_value(what, t, gap, S, P, T):
    """Upward force (N, what 0), stored energy (J, 1) or energy booked as lost this contact (J, 2) at `gap` (m)
    and absolute time t (s): the summits' minus the bridges' pull, their sum, and loops + switch work + formation
    work (`WetRoughRoller.force`, `stored_energy`, `dissipated`)."""
    pb, sb, u = np.int64(G_BRIDGES), np.int64(S_BRIDGES), T[0]
    tc = t - P[pb + B_T0]
    k_trial = _prefix(gap, tc, S, P, pb, sb, u)
    if P[DRY + C_MODE] == MODE_PLASTIC:
        own = wp.summits(np.int64(what), gap, k_trial, S, P, T, PARAMS)
        if what == 0:
            return own - _bridges(np.int64(0), gap, tc, S, P, pb, sb, u)
        return own + _bridges(np.int64(what), gap, tc, S, P, pb, sb, u)
    b = np.zeros(3)
    if what == 0:
        return _summits(np.int64(_FORCE), gap, k_trial, S, P, T, b) - _bridges(np.int64(0), gap, tc, S, P, pb, sb, u)
    if what == 1:
        return _summits(np.int64(_STORED), gap, k_trial, S, P, T, b) + _bridges(np.int64(1), gap, tc, S, P, pb, sb, u)
    _summits(np.int64(_BOOKS), gap, k_trial, S, P, T, b)
    return ((S[S_DET_DRY] + b[0]) * P[DRY + C_LOOP] + (S[S_DET_WET] + b[1]) * P[WET + C_LOOP] + S[S_SWITCHED]
            + b[2] + _bridges(np.int64(2), gap, tc, S, P, pb, sb, u))


@njit(cache=True)
def wet_accept(t, gap, S, P, T):
    """Commit a trial state (`WetDiscreteRoller.accept`: the summits with the bridged prefix the accepted bridges
    give, then the bridges)."""
    pb, sb, u = np.int64(G_BRIDGES), np.int64(S_BRIDGES), T[0]
    tc = t - P[pb + B_T0]
    k_trial = _prefix(gap, tc, S, P, pb, sb, u)
    if P[DRY + C_MODE] == MODE_PLASTIC:
        wp.summits(np.int64(wp.ACCEPT), gap, k_trial, S, P, T, PARAMS)
        _bridges_accept(gap, tc, S, P, pb, sb, u)
        return
    b = np.zeros(3)
    _summits(np.int64(_BOOKS), gap, k_trial, S, P, T, b)
    S[S_DET_DRY] += b[0]
    S[S_DET_WET] += b[1]
    S[S_SWITCHED] += b[2]
    reach = max(P[DRY + C_REACH], P[WET + C_REACH])
    k = max(int(S[S_K_ATT]), count_at_least(u, gap - reach), min(k_trial, u.size))
    last, count = 0, 0
    for i in range(k):
        c = WET if i < k_trial else DRY
        att = _attached(c, S[S_FLAGS + i] != 0.0, u[i] - gap, P)
        S[S_FLAGS + i] = 1.0 if att else 0.0
        if att:
            last = i + 1
            count += 1
    S[S_K_WET] = k_trial
    S[S_K_ATT] = last
    S[S_MAX_CONTACTS] = max(S[S_MAX_CONTACTS], float(count))
    S[S_H_MIN] = min(S[S_H_MIN], gap)
    _bridges_accept(gap, tc, S, P, pb, sb, u)


# ----------------------------------------------------------------------------- bridges round another law
@njit(cache=True)
def bridged_value(what, t, gap, S, P, T):
    """LAW_BRIDGED: the inner law (kind P[pb + B_INNER], its P, S and T from index 0, T[0] its summits' u) minus
    the bridges' pull; stored and booked energies add (`continuum.laws.discrete_bridges`, the additive form with
    the bridges' DMT solid pull)."""
    pb = P.size - BRIDGE_PARAMS
    sb = int(P[pb + B_S])
    inner = int(P[pb + B_INNER])
    tc = t - P[pb + B_T0]
    if what == 0:
        own = law_force(inner, gap, S, P, T)
        return own - _bridges(np.int64(0), gap, tc, S, P, pb, sb, T[0])
    if what == 1:
        return law_stored(inner, gap, S, P, T) + _bridges(np.int64(1), gap, tc, S, P, pb, sb, T[0])
    return law_dissipated(inner, gap, S, P, T) + _bridges(np.int64(2), gap, tc, S, P, pb, sb, T[0])


@njit(cache=True)
def bridged_accept(t, gap, S, P, T):
    pb = P.size - BRIDGE_PARAMS
    law_accept(int(P[pb + B_INNER]), gap, S, P, T)
    _bridges_accept(gap, t - P[pb + B_T0], S, P, pb, int(P[pb + B_S]), T[0])
