"""Compiled elastic-plastic summits inside and outside their bridges: `continuum.laws.wet_plastic_summits` in numba.

The summit part of `wet_discrete_kernel.LAW_WET_DISCRETE` in its plastic mode (P[C_MODE] of the dry block =
`MODE_PLASTIC`); the bridges are that kernel's (`wet_value`, `wet_accept` dispatch here for the summits). Two classes
of Thornton-Ning summits on the construction of `continuum.rough.plastic_branches.PlasticBranchSummitLaw` (dry at
dgamma, wet at W_wet), each evaluated by the dry plastic kernel's own functions (`continuum.rough.plastic_kernel`:
the flattening table, the node-blended branches, the plastic work), summit by summit in the Python law's rule
(`WetPlasticSummits._trial`): the first k_trial summits (the bridged prefix) on the wet class, the rest on the dry
one; one attached flag, one met flag and one deepest approach per summit are the history, carried across a class
change; a summit that changes class books the jump of its stored energy. The arithmetic is the Python law's term by
term (the sums in summit order, where NumPy sums by class), so the two agree to round-off
(`tests/continuum/test_wet_plastic_summits.py`).

Layout (plastic mode). P: the dry class block's mode slot (0), the bridges' block at G_BRIDGES (as the elastic mode),
then W_0 (the plastic work booked before this contact, J), the lowest kept u (m) and two class blocks of
CLASS (dry, wet): the dry plastic kernel's P slots (`plastic_kernel.P_P_*`) and the class's ranges in the tables.
T: 0 the summits' u_i = e_i - z_top (descending), 1-3 the flattening tables (D, R_p, delta_p) of both classes one after
the other, 4 both classes' node info, 5-6 unused, 7 both classes' node branch rows stacked. S: the rigid laws' five
slots, committed bridged prefix, loops and jumps booked this contact (J), plastic work booked in total (J), switch
work (J), 1 + last attached summit, the bridges' block, the largest stretch at which a summit can pull (m), then per
summit the attached flags, the deepest approaches (m) and the met flags.

Selectors passed from one compiled function to another are NumPy scalars (`np.int64(k)`, `np.bool_(b)`), not
Python constants: numba compiles the callee once for every literal constant a compiled caller passes
(`Literal[int](k)`), so constant selectors multiplied the kernels' cold compile (docs/benchmarks.md).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..rough import plastic_kernel as pk
from ..rough.plastic_kernel import count_at_least

#: Slots after the elastic mode's P (`wet_discrete_kernel.PARAMS`, passed in as `base`): W_0, the lowest kept u (m),
#: then the class blocks.
W0, LOWEST = 0, 1
#: A class block: the dry plastic kernel's P slots, then the class's table ranges (flattening, node info, rows).
(CB_F_LO, CB_F_HI, CB_I_LO, CB_I_HI, CB_R_LO, CB_R_HI) = range(pk.PLASTIC_PARAMS, pk.PLASTIC_PARAMS + 6)
CLASS = pk.PLASTIC_PARAMS + 6
DRY_BLOCK, WET_BLOCK = 2, 2 + CLASS
EXTRA = 2 + 2 * CLASS
#: S slots (with the elastic mode's 0-9 and its bridges' block at 10-15).
(S_K_WET, S_LOOPS, S_W_TOTAL, S_SWITCHED, S_K_ATT) = range(5, 10)
S_REACH = 16
S_FLAGS = 17
_S_H_MIN, _S_MAX_CONTACTS, _S_BEYOND_FLAG = 0, 2, 4

#: What `summits` returns.
FORCE, STORED, BOOKED, ACCEPT = 0, 1, 2, 3


@njit(cache=True)
def _lin(x, xs, ys, lo, n):
    """numpy.interp on xs[lo:lo + n] (increasing), ys[lo:lo + n], clamped to the ends (`plastic_kernel._lin` at an
    offset)."""
    if x <= xs[lo]:
        return ys[lo]
    if x >= xs[lo + n - 1]:
        return ys[lo + n - 1]
    a, b = lo, lo + n - 1
    while b - a > 1:
        mid = (a + b) // 2
        if xs[mid] <= x:
            a = mid
        else:
            b = mid
    return ys[a] + (x - xs[a]) / (xs[b] - xs[a]) * (ys[b] - ys[a])


@njit(cache=True)
def _blend(what, eps, r, P, T, c):
    """`plastic_kernel._blend` for the class block at P[c:] (its node info and rows at their offsets in T[4], T[7]):
    the node-blended value on the curve of radius r at eps (m), what 0/1 approach force/energy, 2/3 retreat
    force/energy, 4/5 delta_in/delta_out."""
    info, tab = T[4], T[7]
    i0, r0 = int(P[c + CB_I_LO]), int(P[c + CB_R_LO])
    nodes = int(P[c + pk.P_P_NODES])
    k, t = 0, 0.0
    if r == P[c + pk.P_P_BETA]:
        if what >= 4:
            return info[i0 + 1 + (what - 4)]
        row = r0 + (3 if what >= 2 else 0)
        n = int(info[i0 + (4 if what >= 2 else 3)])
        return pk._lin(eps, tab[row], tab[row + 1 + what % 2], n)
    if nodes > 1 and P[c + pk.P_P_SELF_SIMILAR] == 0.0:
        x = math.log(max(r / P[c + pk.P_P_BETA], 1.0)) / P[c + pk.P_P_LOG_RATIO]
        k = min(int(math.floor(x)), nodes - 2)
        t = min(max(x - k, 0.0), 1.0)
    total = 0.0
    for j in range(k, k + 2):
        wgt = 1.0 - t if j == k else t
        if wgt == 0.0 or j >= nodes:
            continue
        s = r / info[i0 + 5 * j]
        cb = s ** (1.0 / 3.0)
        if what >= 4:
            total += wgt * cb * info[i0 + 5 * j + 1 + (what - 4)]
            continue
        retreat = what >= 2
        row = r0 + 6 * j + (3 if retreat else 0)
        n = int(info[i0 + 5 * j + (4 if retreat else 3)])
        if what % 2 == 0:
            total += wgt * s * pk._lin(eps / cb, tab[row], tab[row + 1], n)
        else:
            total += wgt * s * cb * pk._lin(eps / cb, tab[row], tab[row + 2], n)
    return total


@njit(cache=True)
def _flattening(dm, S, P, T, c):
    """`plastic_kernel._flattening` for the class block at P[c:]: (R_p, delta_p) after the deepest approach dm;
    flags dm beyond the table."""
    over = dm - P[c + pk.P_P_D_Y]
    if not over > 0.0:
        return P[c + pk.P_P_BETA], 0.0
    if over > P[c + pk.P_P_D_TOP] * (1.0 + 1e-12):
        S[_S_BEYOND_FLAG] = 1.0
    f0 = int(P[c + CB_F_LO])
    n = int(P[c + CB_F_HI]) - f0
    return _lin(over, T[1], T[2], f0, n), _lin(over, T[1], T[3], f0, n)


@njit(cache=True)
def _plastic_work(dm, r, dp, P, T, c):
    """`plastic_kernel._plastic_work` for the class block at P[c:]."""
    over = dm - P[c + pk.P_P_D_Y]
    if not over > 0.0:
        return 0.0
    w_in = P[c + pk.P_P_U_Y] + P[c + pk.P_P_F_Y] * over + 0.5 * P[c + pk.P_P_SLOPE] * over * over
    return w_in - _blend(np.int64(3), dm - dp, r, P, T, c)


@njit(cache=True)
def _value(energy, delta, dm, att, r, dp, P, T, c):
    """Force (N) or stored energy (J) of one summit at approach delta with deepest approach dm (flattening r, dp),
    on its retreat branch (`att`) or approach branch (`PlasticBranchSummitLaw.state`: Thornton-Ning's plastic line on
    a new deepest approach)."""
    if not energy and att and delta >= dm and dm > P[c + pk.P_P_D_Y]:
        return P[c + pk.P_P_F_Y] + P[c + pk.P_P_SLOPE] * (delta - P[c + pk.P_P_D_Y])
    return _blend((2 if att else 0) + (1 if energy else 0), delta - dp, r, P, T, c)


@njit(cache=True)
def _span(what, gap, lo, hi, wet, k_wet, S, P, T, c, co, acc):
    """Summits lo <= i < hi, all of the class block at P[c:] at the trial state (`wet`: the wet class), whose other
    class is at P[co:]: their force or stored energy, or their books, or their accepted state (`summits`); the sums
    in `acc` (total, loops, plastic work new, old, switch work, 1 + last attached, attached, reach). An unyielded
    summit's flattening and jump points are read as they are (beta, 0, node 0's delta_in, delta_out), without the
    calls that would return them."""
    u = T[0]
    n = u.size
    fl, dms, met = S_FLAGS, S_FLAGS + n, S_FLAGS + 2 * n
    beta, d_y = P[c + pk.P_P_BETA], P[c + pk.P_P_D_Y]
    i0 = int(P[c + CB_I_LO])
    din_b, dout_b = T[4][i0 + 1], T[4][i0 + 2]
    total = 0.0
    for i in range(lo, hi):
        delta = u[i] - gap
        dm0 = S[dms + i]
        held = S[fl + i] != 0.0
        changed = wet != (i < k_wet)
        e_old = 0.0
        if changed and what != FORCE and what != STORED:
            # under the old class to the trial approach (let go there: the old loop), then the class change
            ro, dpo = _flattening(dm0, S, P, T, co)
            douto = _blend(np.int64(5), 0.0, ro, P, T, co)
            h_o = held and delta - dpo > douto
            if held and not h_o:
                acc[1] += _blend(np.int64(3), douto, ro, P, T, co) - _blend(np.int64(1), douto, ro, P, T, co)
            e_old = _blend(3 if h_o else 1, delta - dpo, ro, P, T, co)
            held = h_o
        elif changed:
            ro, dpo = _flattening(dm0, S, P, T, co)
            held = held and delta - dpo > _blend(np.int64(5), 0.0, ro, P, T, co)
        r, dp = _flattening(dm0, S, P, T, c) if dm0 > d_y else (beta, 0.0)
        eps = delta - dp
        if r == beta:
            din, dout = din_b, dout_b
        else:
            din, dout = _blend(np.int64(4), 0.0, r, P, T, c), _blend(np.int64(5), 0.0, r, P, T, c)
        att = eps >= din or (held and eps > dout)
        dm = max(dm0, delta) if att else dm0
        if dm != dm0 and dm > d_y:
            r2, dp2 = _flattening(dm, S, P, T, c)
        else:
            r2, dp2 = r, dp
        if what == FORCE or what == STORED:
            total += _value(what == STORED, delta, dm, att, r2, dp2, P, T, c)
            continue
        if changed:
            acc[4] += e_old - _value(np.bool_(True), delta, dm0, held, r, dp, P, T, c)
        if held and not att:
            acc[1] += _blend(np.int64(3), dout, r, P, T, c) - _blend(np.int64(1), dout, r, P, T, c)
        elif att and not held:
            acc[1] += _blend(np.int64(1), din, r, P, T, c) - _blend(np.int64(3), din, r, P, T, c)
        if dm > dm0:
            acc[2] += _plastic_work(dm, r2, dp2, P, T, c)
            acc[3] += _plastic_work(dm0, r, dp, P, T, c)
        if what == ACCEPT:
            S[fl + i] = 1.0 if att else 0.0
            S[dms + i] = dm
            if att:
                S[met + i] = 1.0
                acc[5] = i + 1
                acc[6] += 1.0
                acc[7] = max(acc[7], -(dout_b if r2 == beta else _blend(np.int64(5), 0.0, r2, P, T, c)))
    acc[0] += total


@njit(cache=True)
def summits(what, gap, k_trial, S, P, T, base):
    """Force (N, FORCE), stored energy (J, STORED) or energy booked this contact (J, BOOKED: plastic work, loops and
    jumps, switch work) of the trial state at `gap` with the first k_trial summits bridged; ACCEPT commits it
    (`WetPlasticSummits._trial`, `dissipated`, `accept`). `base`: the offset of this mode's slots in P."""
    u = T[0]
    n = u.size
    cd, cw = base + DRY_BLOCK, base + WET_BLOCK
    reach = S[S_REACH]
    if gap - reach < P[base + LOWEST]:
        S[_S_BEYOND_FLAG] = 1.0
    k = max(count_at_least(u, gap - reach), int(S[S_K_ATT]), min(k_trial, n))
    k_wet = int(S[S_K_WET])
    kw = min(k_trial, k)
    acc = np.zeros(8)
    acc[7] = reach
    _span(np.int64(what), gap, np.int64(0), kw, np.bool_(True), k_wet, S, P, T, cw, cd, acc)
    _span(np.int64(what), gap, kw, k, np.bool_(False), k_wet, S, P, T, cd, cw, acc)
    dw = acc[2] - acc[3]
    if what == BOOKED:
        return S[S_W_TOTAL] + dw - P[base + W0] + S[S_LOOPS] + acc[1] + S[S_SWITCHED] + acc[4]
    if what == ACCEPT:
        S[S_LOOPS] += acc[1]
        S[S_W_TOTAL] += dw
        S[S_SWITCHED] += acc[4]
        S[S_K_WET] = k_trial
        S[S_K_ATT] = acc[5]
        S[S_REACH] = acc[7]
        S[_S_MAX_CONTACTS] = max(S[_S_MAX_CONTACTS], acc[6])
        S[_S_H_MIN] = min(S[_S_H_MIN], gap)
    return acc[0]
