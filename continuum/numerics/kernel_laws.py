"""The compiled contact laws: force, stored and dissipated energy, and the accept step of each law kind the
compiled contact phase (`continuum.numerics.contact_kernel`) integrates, with the spline evaluators their tables need.

Each law is a pure function of the gap and the law's parameters `P`, tables `T` and history `S` (arrays the Python
law fills: `compiled()` of `continuum.laws.rough_rigid`, `continuum.laws.discrete_roller`,
`continuum.laws.plastic_rough`); `law_force`, `law_stored`, `law_dissipated` and `law_accept` dispatch on the law
kind. The closed forms are those of the Python laws (JKR: `continuum.physics.jkr_kernel`, whose scalar root is
compiled here from its one source; Maugis-Dugdale and DMT branches: `continuum.rough.branch_laws`; elastic-plastic
summits: `continuum.rough.plastic_kernel`), which the tests compare point by point
(`tests/continuum/test_contact_kernel.py`, `tests/continuum/test_jkr_forms.py`).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import overload

from ..physics import jkr_kernel as jk
from ..rough import plastic_gw_kernel as pgk
from ..rough import plastic_kernel as pk

#: Law kinds.
LAW_RIGID_TABLE = 0
LAW_POWER = 1
LAW_DISCRETE = 2
LAW_DISCRETE_BRANCH = 3
LAW_PLASTIC = 4
#: (5 and 6: `continuum.numerics.wet_discrete_kernel`.) The GW mean field of plastic summits under a flat punch or a
#: roller (`continuum.laws.plastic_rough.PlasticGWPunch`, `continuum.rough.plastic_gw_kernel.law_value`).
LAW_PLASTIC_GW = 7

#: Rigid-table law: P slots and S slots.
(P_END_GAP, P_REACH, P_ATTACH, P_RELEASE, P_R_IN, P_H_LO, P_LOOP) = range(7)
(S_H_MIN, S_COUNT_MIN, S_MAX_CONTACTS, S_BEYOND_ACCEPTED, S_BEYOND_FLAG) = range(5)
#: Power law: P = (k, n).
P_K, P_N = 0, 1
#: Discrete law: P slots (its S slots are the rigid-table law's); T[0] holds the kept summits' effective heights
#: below the datum, e_i - z_top (m, descending, T[0][0] = 0).
(P_D_END_GAP, P_D_RELEASE, P_D_LOOP, P_D_INV_DELTA0, P_D_PSCALE, P_D_ESCALE, P_D_HERTZ_K, P_D_ADHESIVE,
 P_D_LOWEST) = range(9)
DISCRETE_PARAMS = 9
#: Discrete summits with tabulated branches (`continuum.rough.branch_laws.SummitLaw`: Maugis-Dugdale, DMT): P slots;
#: T = (e_i - z_top, approach delta, force, energy, retreat delta, force, energy, unused 2-D).
(P_B_END_GAP, P_B_IN, P_B_OUT, P_B_REACH, P_B_LOOP, P_B_LOWEST) = range(6)
BRANCH_PARAMS = 6
#: The Horner coefficients of JKR's h(s) (`continuum.physics.jkr_kernel.H_COEF`) as an array numba can index.
_H_COEF = np.array(jk.H_COEF)



# ----------------------------------------------------------------------------- splines
@njit(cache=True)
def _span(t, k, x):
    """Knot interval l (0-based) with t[l] <= x < t[l+1], k <= l <= len(t) - k - 2 (x clamped, FITPACK fpbisp)."""
    n = t.size
    lo, hi = k, n - k - 2
    if x >= t[hi]:
        return hi
    if x <= t[lo]:
        return lo
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if t[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def _dbc(t, l, i, j, hh, h_prev, x):
    """One term of the de Boor-Cox recursion at order j: (h[i-1] after it, h[i]) from hh = h[i-1] of order j - 1."""
    li = l + i
    lj = li - j
    if t[li] == t[lj]:
        return h_prev, 0.0
    f = hh / (t[li] - t[lj])
    return h_prev + f * (t[li] - x), f * (x - t[lj])


@njit(cache=True, inline="always")
def _basis3(t, l, x):
    """The 4 non-zero cubic B-splines at x in knot interval l (de Boor-Cox recursion, FITPACK fpbspl), as a tuple:
    the recursion's operations in FITPACK's order on scalars (no arrays allocated per evaluation, which cost more
    than the arithmetic)."""
    h0, h1 = _dbc(t, l, 1, 1, 1.0, 0.0, x)
    a0, a1 = h0, h1
    h0, h1 = _dbc(t, l, 1, 2, a0, 0.0, x)
    h1, h2 = _dbc(t, l, 2, 2, a1, h1, x)
    a0, a1, a2 = h0, h1, h2
    h0, h1 = _dbc(t, l, 1, 3, a0, 0.0, x)
    h1, h2 = _dbc(t, l, 2, 3, a1, h1, x)
    h2, h3 = _dbc(t, l, 3, 3, a2, h2, x)
    return h0, h1, h2, h3


@njit(cache=True)
def bicubic(tx, ty, c, x, y):
    """Tensor-product cubic B-spline (FITPACK's tck as in scipy's RectBivariateSpline) at (x, y), clamped to its box."""
    x = min(max(x, tx[3]), tx[tx.size - 4])
    y = min(max(y, ty[3]), ty[ty.size - 4])
    lx, ly = _span(tx, 3, x), _span(ty, 3, y)
    hx = _basis3(tx, lx, x)
    hy = _basis3(ty, ly, y)
    ny = ty.size - 4
    total = 0.0
    for i in range(4):
        row = (lx - 3 + i) * ny + ly - 3
        acc = 0.0
        for j in range(4):
            acc += c[row + j] * hy[j]
        total += acc * hx[i]
    return total


@njit(cache=True)
def ppoly3(x, c, a):
    """Piecewise cubic (scipy PPoly coefficients c[4, n-1], breakpoints x) at a, end pieces extrapolated."""
    n = x.size
    if a < x[1]:
        i = 0
    elif a >= x[n - 2]:
        i = n - 2
    else:
        lo, hi = 1, n - 2
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if x[mid] <= a:
                lo = mid
            else:
                hi = mid
        i = lo
    d = a - x[i]
    return ((c[0, i] * d + c[1, i]) * d + c[2, i]) * d + c[3, i]


# ----------------------------------------------------------------------------- discrete summits
@overload(math.cbrt)
def _math_cbrt(x):
    """numba (0.68) has no math.cbrt; np.cbrt is the same libm cube root, so Python scalar code that calls
    math.cbrt compiles as written."""
    return lambda x: np.cbrt(x)


#: (d clamped to the fold, stable root s of s^4 - s = d): `continuum.physics.jkr_kernel.stable_root_scalar`
#: compiled, one source for the Python and the compiled discrete summits (`tests/continuum/test_jkr_forms.py`).
_jkr_root = njit(cache=True)(jk.stable_root_scalar)


_count_at_least = pk.count_at_least     # entries of a descending array >= a level (binary search)


@njit(cache=True)
def _discrete_attached(gap, S, P, T):
    """Summits attached at `gap`: a prefix of T[0]. On a rigid substrate the history rule (attach at delta >= 0,
    let go below -Delta) leaves attached exactly the summits with e_i >= gap on a new deepest approach, else those
    reached (e_i >= h_min) that have not let go (e_i >= gap - Delta). Flags a level below the kept summits."""
    level = gap if gap <= S[S_H_MIN] else max(S[S_H_MIN], gap - P[P_D_RELEASE])
    if level < P[P_D_LOWEST]:
        S[S_BEYOND_FLAG] = 1.0
    return _count_at_least(T[0], level)


@njit(cache=True)
def _discrete_sum(gap, S, P, T, energy):
    """Sum over the attached summits of the force (N) or, `energy` True, the stored energy (J) of each: JKR on its
    stable branch in s = sqrt(a/a0) (`continuum.physics.jkr_kernel`), or Hertz without adhesion."""
    e = T[0]
    k = _discrete_attached(gap, S, P, T)
    total = 0.0
    for i in range(k):
        dl = e[i] - gap
        if P[P_D_ADHESIVE] != 0.0:
            d, s = _jkr_root(dl * P[P_D_INV_DELTA0])
            s3 = s * s * s
            if energy:
                h = _H_COEF[0]
                for c in range(1, _H_COEF.size):
                    h = h * s + _H_COEF[c]
                total += P[P_D_ESCALE] * d / (s * (s * s + s + 1.0)) * h
            else:
                total += P[P_D_PSCALE] * s3 * (8.0 / 3.0 * s3 - 4.0)
        elif dl > 0.0:
            total += P[P_D_HERTZ_K] * dl * math.sqrt(dl) * (0.4 * dl if energy else 1.0)
    return total


@njit(cache=True)
def _lin(x, xs, ys):
    """Linear interpolation of the table (xs increasing, ys) at x, clamped to its ends (numpy.interp)."""
    n = xs.size
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
    w = (x - xs[lo]) / (xs[hi] - xs[lo])
    return ys[lo] + w * (ys[hi] - ys[lo])


@njit(cache=True)
def _branch_counts(gap, S, P, T):
    """(summits on the retreat branch, summits within reach, summits jumped in) at `gap`: prefixes of T[0]. On a
    rigid substrate a summit has jumped in iff its deepest approach e_i - h_min reached delta_in, and it follows
    its retreat branch R until delta = e_i - gap falls below delta_out; every other summit within reach
    (delta >= -reach) is on its approach branch A (A = R above delta_in)."""
    e = T[0]
    h = min(gap, S[S_H_MIN])
    jumped = _count_at_least(e, h + P[P_B_IN])
    on_r = _count_at_least(e, max(h + P[P_B_IN], gap + P[P_B_OUT]))
    level = gap - P[P_B_REACH]
    if min(level, gap + P[P_B_OUT]) < P[P_B_LOWEST]:
        S[S_BEYOND_FLAG] = 1.0
    return on_r, _count_at_least(e, level), jumped


@njit(cache=True)
def _branch_sum(gap, S, P, T, energy):
    """Force (N) or, `energy` True, stored energy (J) of the summits in reach, each on its branch."""
    e = T[0]
    on_r, reach, _ = _branch_counts(gap, S, P, T)
    total = 0.0
    for i in range(max(on_r, reach)):
        dl = e[i] - gap
        if i < on_r:
            total += _lin(dl, T[4], T[6]) if energy else _lin(dl, T[4], T[5])
        else:
            total += _lin(dl, T[1], T[3]) if energy else _lin(dl, T[1], T[2])
    return total


@njit(cache=True)
def _branch_dissipated(gap, S, P, T):
    """One loop per summit that jumped in and then out; at the release gap every summit has let go."""
    if S[S_H_MIN] == math.inf:
        return 0.0
    on_r, _, jumped = _branch_counts(gap, S, P, T)
    if gap >= P[P_B_END_GAP]:
        on_r = 0
    return P[P_B_LOOP] * max(jumped - on_r, 0)


@njit(cache=True)
def _discrete_dissipated(gap, S, P, T):
    """One loop per summit reached and let go; at the release gap every summit has let go."""
    if S[S_H_MIN] == math.inf:
        return 0.0
    if gap >= P[P_D_END_GAP]:
        return P[P_D_LOOP] * S[S_COUNT_MIN]
    return P[P_D_LOOP] * max(S[S_COUNT_MIN] - _discrete_attached(gap, S, P, T), 0.0)


@njit(cache=True)
def _discrete_accept(gap, S, P, T):
    if gap < S[S_H_MIN]:
        S[S_H_MIN] = gap
        S[S_COUNT_MIN] = _count_at_least(T[0], gap)
    S[S_MAX_CONTACTS] = max(S[S_MAX_CONTACTS], float(_discrete_attached(gap, S, P, T)))


# ----------------------------------------------------------------------------- laws
@njit(cache=True)
def _rigid_window(gap, S, P):
    if gap <= S[S_H_MIN]:
        return min(P[P_ATTACH], P[P_RELEASE])
    return min(gap - S[S_H_MIN] + P[P_ATTACH], P[P_RELEASE])


@njit(cache=True)
def _rigid_w(r, P):
    span = P[P_RELEASE] - P[P_R_IN]
    if span > 0.0:
        return math.sqrt(min(max((P[P_RELEASE] - r) / span, 0.0), 1.0))
    return 0.0


@njit(cache=True)
def _rigid_count(a, S, P, T):
    if a < P[P_H_LO]:
        S[S_BEYOND_FLAG] = 1.0
        return 0.0
    return ppoly3(T[6], T[7], a)


@njit(cache=True)
def _rigid_attached(gap, S, P, T):
    a = gap - _rigid_window(gap, S, P) + P[P_ATTACH]
    if a < P[P_ATTACH]:
        return _rigid_count(a, S, P, T)
    return 0.0


@njit(cache=True)
def law_force(kind, gap, S, P, T):
    """Upward contact force (N) at `gap` (m) on the current branch (S: the law's history)."""
    if kind == LAW_POWER:
        return P[P_K] * (-gap) ** P[P_N] if gap < 0.0 else 0.0
    if kind == LAW_DISCRETE:
        return _discrete_sum(gap, S, P, T, False)
    if kind == LAW_DISCRETE_BRANCH:
        return _branch_sum(gap, S, P, T, False) if gap < P[P_B_END_GAP] else 0.0
    if kind == LAW_PLASTIC:
        return pk.plastic_value(gap, S, P, T, 0)
    if kind == LAW_PLASTIC_GW:
        return pgk.law_value(pgk.LAW_FORCE, gap, S, P, T)
    if gap >= P[P_END_GAP]:
        return 0.0
    if gap < P[P_H_LO]:
        S[S_BEYOND_FLAG] = 1.0
        return 0.0
    return bicubic(T[0], T[1], T[2], gap, _rigid_w(_rigid_window(gap, S, P), P))


#: `law_force` inlined where the stepper evaluates its stages (`contact_kernel._rhs`: 12 to 15 evaluations a step):
#: a compiled call that passes the tables' tuple costs ~0.1 us, as much as a summit's evaluation. One function, so
#: one source of every law's force; the other call sites (samples, events) call `law_force` itself, so the law's
#: code is compiled a few times, not at every site.
law_force_inline = njit(inline="always")(law_force.py_func)


@njit(cache=True)
def law_stored(kind, gap, S, P, T):
    """Energy (J) stored in the contact relative to touch."""
    if kind == LAW_POWER:
        return P[P_K] * (-gap) ** (P[P_N] + 1.0) / (P[P_N] + 1.0) if gap < 0.0 else 0.0
    if kind == LAW_DISCRETE:
        return _discrete_sum(gap, S, P, T, True) if gap < P[P_D_END_GAP] else 0.0
    if kind == LAW_DISCRETE_BRANCH:
        return _branch_sum(gap, S, P, T, True) if gap < P[P_B_END_GAP] else 0.0
    if kind == LAW_PLASTIC:
        return pk.plastic_value(gap, S, P, T, 1)
    if kind == LAW_PLASTIC_GW:
        return pgk.law_value(pgk.LAW_STORED, gap, S, P, T)
    if gap >= P[P_END_GAP] or (S[S_H_MIN] == math.inf and gap >= P[P_REACH]):
        return 0.0
    if gap < P[P_H_LO]:
        S[S_BEYOND_FLAG] = 1.0
        return 0.0
    return bicubic(T[3], T[4], T[5], gap, _rigid_w(_rigid_window(gap, S, P), P))


@njit(cache=True)
def law_dissipated(kind, gap, S, P, T):
    """Energy (J) this contact would have booked as lost at `gap`."""
    if kind == LAW_DISCRETE:
        return _discrete_dissipated(gap, S, P, T)
    if kind == LAW_DISCRETE_BRANCH:
        return _branch_dissipated(gap, S, P, T)
    if kind == LAW_PLASTIC:
        return pk.plastic_value(gap, S, P, T, 2)
    if kind == LAW_PLASTIC_GW:
        return pgk.law_value(pgk.LAW_DISSIPATED, gap, S, P, T)
    if kind == LAW_POWER or S[S_H_MIN] == math.inf:
        return 0.0
    return P[P_LOOP] * max(S[S_COUNT_MIN] - _rigid_attached(gap, S, P, T), 0.0)


@njit(cache=True)
def law_accept(kind, gap, S, P, T):
    """History update after an accepted state (`RigidRoughRoller.accept`)."""
    if kind == LAW_POWER:
        return
    if kind == LAW_DISCRETE:
        _discrete_accept(gap, S, P, T)
        return
    if kind == LAW_PLASTIC:
        pk.plastic_accept(gap, S, P, T)
        return
    if kind == LAW_PLASTIC_GW:
        pgk.law_accept(gap, S, P, T)
        return
    if kind == LAW_DISCRETE_BRANCH:
        if gap < S[S_H_MIN]:
            S[S_H_MIN] = gap
        on_r, reach, jumped = _branch_counts(gap, S, P, T)
        S[S_COUNT_MIN] = jumped
        S[S_MAX_CONTACTS] = max(S[S_MAX_CONTACTS], float(on_r))
        return
    if gap < P[P_H_LO]:
        S[S_BEYOND_ACCEPTED] += 1.0
    if gap < S[S_H_MIN]:
        S[S_H_MIN] = gap
        S[S_COUNT_MIN] = _rigid_count(gap, S, P, T) if gap < P[P_ATTACH] else 0.0
    S[S_MAX_CONTACTS] = max(S[S_MAX_CONTACTS], _rigid_attached(gap, S, P, T))


@njit(cache=True)
def law_release_gap(kind, S, P, T, release):
    """The release gap (m) on the accepted history: the law's `release_gap`, which grows with the history for the
    plastic mean field (the flattened summits hold longer); `release`, the one given at touch, for the others."""
    if kind == LAW_PLASTIC_GW:
        return pgk.law_release_gap(S, P, T)
    return release


@njit(cache=True)
def law_release_loss(kind, gap, S, P, T):
    """The loss (J) booked at release (the law's `on_release`): `law_dissipated` at the release gap, or, for the
    plastic mean field, with every summit met let go."""
    if kind == LAW_PLASTIC_GW:
        return pgk.law_value(pgk.LAW_RELEASE_LOSS, gap, S, P, T)
    return law_dissipated(kind, gap, S, P, T)
