"""Compiled form of discrete adhesive elastic-plastic summits (`continuum.rough.plastic_branches` under a rigid flat
or roller, `continuum.laws.plastic_rough.PlasticSummitsPunch`): `continuum.numerics.kernel_laws.LAW_PLASTIC`.

Within one contact (one approach, one retreat: the law's `bound_is_final`) a summit's state is fixed by its state
before the contact (deepest approach dm0, hence R_p0, delta_p0) and the deepest gap of this contact, h_min
(S[S_H_MIN]): with delta = e - gap and delta_deep = e - min(gap, h_min) (e the summit's effective height below the
datum),

* it has jumped in iff delta_deep - delta_p0 >= delta_in(R_p0); then its deepest approach is dm = max(dm0,
  delta_deep), else dm0;
* it is on its retreat branch iff it has jumped in and delta - delta_p(dm) > delta_out(R_p(dm)) (on a monotonic
  retreat a summit that let go stays free); else on its approach branch (Maugis-Dugdale's attraction);
* on a new deepest approach beyond delta_y its force is Thornton-Ning's plastic line.

The loss booked at `gap` is the plastic work W_p(dm) - W_p(dm0), U_A - U_R at delta_in(R_p0) for each summit that
jumped in, and U_R - U_A at delta_out(R_p(dm)) for each that let go (all of them at the end gap), exactly as the
Python law books them. Curves on R_p are the blend of the tabulated node laws (`PlasticBranchSummitLaw._scaled`).

Tables (T): 0 e_i - z_top (descending); 1 dm0_i; 2 the flattening's D grid; 3 R_p(D); 4 delta_p(D); 5 per summit
(R_p0, delta_p0, W_p(dm0), delta_in(R_p0), delta_out(R_p0)) in five blocks; 6 per node (R_k, delta_in,
delta_out, approach points, retreat points); 7 per node six rows (approach delta, force, energy, retreat delta,
force, energy), padded. History S: the rigid
laws' five slots (h_min, unused, most summits attached, unused, beyond-the-tables flag).

Selectors passed from one compiled function to another are NumPy scalars (`np.int64(k)`, `np.bool_(b)`), not
Python constants: numba compiles the callee once for every literal constant a compiled caller passes
(`Literal[int](k)`), so constant selectors multiplied the kernels' cold compile (docs/benchmarks.md).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: P slots.
(P_P_END_GAP, P_P_REACH, P_P_LOWEST, P_P_BETA, P_P_D_Y, P_P_F_Y, P_P_U_Y, P_P_SLOPE, P_P_NODES, P_P_LOG_RATIO,
 P_P_D_TOP, P_P_SELF_SIMILAR) = range(12)
PLASTIC_PARAMS = 12
#: S slots (the rigid-table laws' layout, so the kernel's checks read the same places).
_S_H_MIN, _S_MAX_CONTACTS, _S_BEYOND_FLAG = 0, 2, 4


@njit(cache=True)
def count_at_least(e, level):
    """Number of entries of the descending array `e` that are >= level (the compiled laws share it)."""
    lo, hi = 0, e.size
    while lo < hi:
        mid = (lo + hi) // 2
        if e[mid] >= level:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True)
def _lin(x, xs, ys, n):
    """numpy.interp on the first n points (xs increasing), clamped to the ends."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[n - 1]:
        return ys[n - 1]
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if xs[mid] <= x:
            lo = mid
        else:
            hi = mid
    return ys[lo] + (x - xs[lo]) / (xs[hi] - xs[lo]) * (ys[hi] - ys[lo])


@njit(cache=True)
def _blend_a(what, eps, r, P, info, tab):
    """Node-blended value on the curve of radius r at eps (m): what 0/1 approach force/energy, 2/3 retreat
    force/energy, 4/5 delta_in/delta_out. `info`, `tab`: T[6], T[7], passed as arrays: a call that takes the tables'
    tuple costs more than a summit's evaluation, so the helpers take the arrays they read (and the summit sum, which
    needs the tuple once, is inlined into the kernel's law calls; inlining these helpers too would save ~5 % of a
    contact for ~50 % more compile time)."""
    nodes = int(P[P_P_NODES])
    k, t = 0, 0.0
    if r == P[P_P_BETA]:            # an unflattened summit: node 0's own curve, no scaling
        if what >= 4:
            return info[1 + (what - 4)]
        row = 3 if what >= 2 else 0
        n = int(info[4 if what >= 2 else 3])
        return _lin(eps, tab[row], tab[row + 1 + what % 2], n)
    if nodes > 1 and P[P_P_SELF_SIMILAR] == 0.0:
        x = math.log(max(r / P[P_P_BETA], 1.0)) / P[P_P_LOG_RATIO]
        k = min(int(math.floor(x)), nodes - 2)
        t = min(max(x - k, 0.0), 1.0)
    total = 0.0
    for j in range(k, k + 2):
        wgt = 1.0 - t if j == k else t
        if wgt == 0.0 or j >= nodes:
            continue
        s = r / info[5 * j]
        c = s ** (1.0 / 3.0)
        if what >= 4:
            total += wgt * c * info[5 * j + 1 + (what - 4)]
            continue
        retreat = what >= 2
        row = 6 * j + (3 if retreat else 0)
        n = int(info[5 * j + (4 if retreat else 3)])
        if what % 2 == 0:
            total += wgt * s * _lin(eps / c, tab[row], tab[row + 1], n)
        else:
            total += wgt * s * c * _lin(eps / c, tab[row], tab[row + 2], n)
    return total


@njit(cache=True)
def _flattening_a(dm, S, P, d, flat_r, flat_p):
    """(R_p, delta_p) after the deepest approach dm (d, flat_r, flat_p: T[2], T[3], T[4]); flags dm beyond the
    table."""
    over = dm - P[P_P_D_Y]
    if not over > 0.0:
        return P[P_P_BETA], 0.0
    if over > P[P_P_D_TOP] * (1.0 + 1e-12):
        S[_S_BEYOND_FLAG] = 1.0
    n = d.size
    return _lin(over, d, flat_r, n), _lin(over, d, flat_p, n)


@njit(cache=True)
def _plastic_work_a(dm, r, dp, P, info, tab):
    over = dm - P[P_P_D_Y]
    if not over > 0.0:
        return 0.0
    w_in = P[P_P_U_Y] + P[P_P_F_Y] * over + 0.5 * P[P_P_SLOPE] * over * over
    return w_in - _blend_a(np.int64(3), dm - dp, r, P, info, tab)


@njit(cache=True)
def _blend(what, eps, r, P, T):
    """`_blend_a` on the tables' tuple T (the mean-field kernel `plastic_gw_kernel` calls it so)."""
    return _blend_a(np.int64(what), eps, r, P, T[6], T[7])


@njit(cache=True)
def _flattening(dm, S, P, T):
    """`_flattening_a` on the tables' tuple T."""
    return _flattening_a(dm, S, P, T[2], T[3], T[4])


@njit(cache=True)
def _plastic_work(dm, r, dp, P, T):
    """`_plastic_work_a` on the tables' tuple T."""
    return _plastic_work_a(dm, r, dp, P, T[6], T[7])


@njit(cache=True, inline="always")
def plastic_value(gap, S, P, T, what):
    """Sum over the summits: what 0 force (N), 1 stored energy (J), 2 loss booked this contact (J), 3 summits on
    their retreat branch."""
    hm = min(gap, S[_S_H_MIN])
    end = gap >= P[P_P_END_GAP]
    if end and what < 2:
        return 0.0
    if hm - P[P_P_REACH] < P[P_P_LOWEST]:
        S[_S_BEYOND_FLAG] = 1.0
    e = T[0]
    # force, energy and count: the summits within reach of gap; the loss: every summit reached this contact
    k = count_at_least(e, (hm if what == 2 else gap) - P[P_P_REACH])
    if k == 0:
        return 0.0
    return _summit_sum(gap, hm, end, k, S, P, e, T[1], T[2], T[3], T[4], T[5], T[6], T[7], what)


@njit(cache=True, inline="always")
def _summit_sum(gap, hm, end, k, S, P, e, dm0s, d, flat_r, flat_p, per, info, tab, what):
    """`plastic_value` over the first k summits (the tables' arrays passed one by one)."""
    n = e.size
    total = 0.0
    for i in range(k):
        r0, dp0, wp0, din0, dout = per[i], per[n + i], per[2 * n + i], per[3 * n + i], per[4 * n + i]
        delta, deep = e[i] - gap, e[i] - hm
        jumped = deep - dp0 >= din0
        dm = dm0s[i]
        r, dp = r0, dp0
        if jumped and deep > dm:
            dm = deep
            r, dp = _flattening_a(dm, S, P, d, flat_r, flat_p)
            if r != r0:
                dout = _blend_a(np.int64(5), 0.0, r, P, info, tab)
        on_r = jumped and not end and delta - dp > dout
        if what == 3:
            total += 1.0 if on_r else 0.0
        elif what == 2:
            if jumped:
                total += _plastic_work_a(dm, r, dp, P, info, tab) - wp0
                total += _blend_a(np.int64(1), din0, r0, P, info, tab) - _blend_a(np.int64(3), din0, r0, P, info, tab)
                if not on_r:
                    total += _blend_a(np.int64(3), dout, r, P, info, tab) - _blend_a(np.int64(1), dout, r, P, info, tab)
        elif on_r and what == 0 and delta >= dm and dm > P[P_P_D_Y]:
            total += P[P_P_F_Y] + P[P_P_SLOPE] * (delta - P[P_P_D_Y])
        else:
            total += _blend_a((2 if on_r else 0) + what, delta - dp, r, P, info, tab)
    return total


@njit(cache=True)
def plastic_accept(gap, S, P, T):
    if gap < S[_S_H_MIN]:
        S[_S_H_MIN] = gap
    S[_S_MAX_CONTACTS] = max(S[_S_MAX_CONTACTS], plastic_value(gap, S, P, T, 3))


def compiled_tables(law, heights_below_datum, delta_max, end_gap, reach, lowest, rows=None):
    """(P, T) of `law` (a `PlasticBranchSummitLaw`) for summits at heights e_i - z_top (m, descending) with
    deepest approaches delta_max (m) before this contact; `end_gap` (m): where every summit has let go and is out
    of reach; `reach` (m): the largest stretch at which a summit can pull; `lowest` (m): the kept summits' floor.
    `rows` (5, n): the summits' block 5 (R_p0, delta_p0, W_p(dm0), delta_in(R_p0), delta_out(R_p0)) where the
    caller keeps it from contact to contact (`PlasticSummitsPunch._rows`); evaluated here otherwise."""
    e = np.ascontiguousarray(heights_below_datum, float)
    dm0 = np.ascontiguousarray(delta_max, float)
    n = e.size
    if rows is not None:
        per = np.ascontiguousarray(rows, float).reshape(5 * n)     # a view: the kernel reads it only
    else:
        per = np.empty(5 * n)
        # unyielded summits share beta's values; only the yielded ones are evaluated one by one
        base = np.array([law.radius])
        per[:n], per[n:2 * n], per[2 * n:3 * n] = law.radius, 0.0, 0.0
        per[3 * n:4 * n], per[4 * n:] = law.jump_in(base)[0], law.jump_out(base)[0]
        yielded = np.flatnonzero(dm0 > law.yield_approach)
        if yielded.size:
            r0, dp0 = law.flattening(dm0[yielded])
            for block, values in enumerate((r0, dp0, law.plastic_work(dm0[yielded]), law.jump_in(r0),
                                            law.jump_out(r0))):
                per[block * n + yielded] = values
    P, T = _law_tables(law)
    P = P.copy()
    P[P_P_END_GAP], P[P_P_REACH], P[P_P_LOWEST] = end_gap, reach, lowest
    return P, (e, dm0) + T[:3] + (per,) + T[3:]


def _law_tables(law):
    """The law's own part of (P, T), built once per law: the flattening table and the node laws' branches."""
    cached = getattr(law, "_kernel_tables", None)
    if cached is not None:
        return cached
    laws = law._laws
    width = max(max(x.approach.delta.size, x.retreat.delta.size) for x in laws)
    tab = np.zeros((6 * len(laws), width))
    info = np.zeros(5 * len(laws))
    for j, x in enumerate(laws):
        for row, arr in enumerate((x.approach.delta, x.approach.force, x.approach.energy,
                                   x.retreat.delta, x.retreat.force, x.retreat.energy)):
            tab[6 * j + row, :arr.size] = arr
        info[5 * j:5 * j + 5] = (x.radius_tip, x.delta_in, x.delta_out, x.approach.delta.size, x.retreat.delta.size)
    P = np.zeros(PLASTIC_PARAMS)
    P[P_P_BETA] = law.radius
    finite = math.isfinite(law.yield_approach)
    P[P_P_D_Y] = law.yield_approach if finite else math.inf
    P[P_P_F_Y] = law.yield_force if finite else 0.0
    P[P_P_U_Y] = law._u_y if finite else 0.0
    P[P_P_SLOPE] = law.plastic_slope if finite else 0.0
    P[P_P_NODES], P[P_P_LOG_RATIO] = len(laws), math.log(law.node_ratio)
    P[P_P_D_TOP] = float(law._d[-1])
    P[P_P_SELF_SIMILAR] = 1.0 if law.self_similar else 0.0
    d = np.ascontiguousarray(law._d, float)
    flat_r = np.ascontiguousarray(law._r_p if finite else np.full(1, law.radius), float)
    flat_p = np.ascontiguousarray(law._d_p if finite else np.zeros(1), float)
    law._kernel_tables = (P, (d, flat_r, flat_p, info, tab))
    return law._kernel_tables
