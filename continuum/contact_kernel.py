"""Compiled contact phase: DOP853 with dense output and event location, for laws with a compiled form.

One contact of the event-driven driver (`continuum.driver._ContactRun`) is a 1-D ODE, h' = v,
v' = F(h)/M - g, integrated until the body leaves (release), turns back while attached (stuck or
at rest), reaches a time the law asks to stop at (capillary bridges condense at t_a), or the run's
time limit. Stepped in Python through `scipy.integrate.DOP853`, a rough impact costs ~0.05-0.2 s,
almost all of it interpreter overhead; here the same algorithm runs compiled by numba.

The algorithm is the driver's, step for step (so results agree to round-off, not just to the
tolerance; `tests/test_contact_kernel.py` checks both):

* Runge-Kutta: Dormand & Prince's explicit 8th-order method with its 5th- and 3rd-order error
  estimators and 7th-order dense output (E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary
  Differential Equations I*, 2nd ed., Springer 1993, section II.10 and the code dop853.f; coefficients
  in `continuum.dop853_tableau`). Step-size control, error norm and factor limits (safety 0.9,
  0.2-10) are those of SciPy's `DOP853`, which follows Hairer's code.
* Events (maximum approach, turning back, release, a stop time) are sign changes of the dense
  output between the ends of an accepted step, located by Brent's method (R. P. Brent, *Algorithms
  for Minimization without Derivatives*, Prentice-Hall 1973, ch. 4; the variant of SciPy's `brentq`,
  xtol 1e-30, rtol 4 eps).
* History laws are restarted at every extremum of the motion, so no stage after it uses the
  history from before it (Hairer, Norsett & Wanner, section II.6 on discontinuities).

Laws with a compiled form (`LAW_RIGID_TABLE`: the rigid rough roller's footprint tables, `continuum.laws.rough_rigid`;
`LAW_DISCRETE`: a realisation of closed-form JKR or Hertz summits on a rigid base (`continuum.laws.discrete_roller`)
or, `LAW_DISCRETE_BRANCH`, of tabulated branches of any summit law; `LAW_PLASTIC`: elastic-plastic summits,
`continuum.rough.plastic_kernel`; `LAW_POWER`: F = k (-h)^n, Hertz, to validate the integrator against closed forms)
give parameters `P`, tables `T` (a tuple of arrays) and a history `S` that the kernel updates in place.

Where the compiled law cannot evaluate a state (deeper than its tables, where the Python law
evaluates its integral directly) or a buffer is full, the kernel returns a status saying so, and
the caller (`continuum.compiled_contact`) integrates that contact with the Python stepper, the
same algorithm: an explicit, recorded path, never a different model.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .dop853_tableau import A, B, C, D, E3, E5
from .rough import plastic_kernel as pk

#: Law kinds.
LAW_RIGID_TABLE = 0
LAW_POWER = 1
LAW_DISCRETE = 2
LAW_DISCRETE_BRANCH = 3
LAW_PLASTIC = 4

#: Ends of a kernel call (info[END]).
END_RELEASE, END_STUCK, END_REST, END_MAX_TIME, END_STOP_TIME = 0, 1, 2, 3, 4
#: The compiled law met a state it cannot evaluate; the buffer filled up; the step size underflowed.
ABORT_BEYOND_TABLES, ABORT_BUFFER, ABORT_STEP = 10, 11, 12

#: info[] slots.
(I_END, I_T, I_GAP, I_V, I_PEAK, I_MAXPEN, I_BOOKED, I_NSAMPLES, I_MAX_T, I_MAX_GAP, I_HAS_MAX,
 I_PULL_T, I_PULL_GAP, I_PULL_F, I_HAS_PULL, I_LAST_ACCEPT_T, I_STEPS, I_EVALS) = range(18)
INFO_SIZE = 18

#: Sample columns: t, gap, v, force, stored, dissipated (booked this contact), kind (0 sample, 1 the
#: instant after release: nothing stored, the loss booked).
SAMPLE_COLUMNS = 7

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
#: JKR constants of `continuum.physics.jkr_kernel`: the fold d = -D_C and the Horner coefficients of h(s).
_D_C = 0.75 * 4.0 ** (-1.0 / 3.0)
_H_COEF = np.array((16.0 / 15.0, 16.0 / 15.0, 16.0 / 15.0, -1.6, -1.6, -1.6, -0.6, -0.6, -0.6, -0.6))

_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_ERROR_EXPONENT = -1.0 / 8.0          # -1/(error estimator order + 1), order 7 (Hairer's dop853.f)
_EPS = np.finfo(float).eps


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


@njit(cache=True)
def _basis3(t, l, x, h):
    """The 4 non-zero cubic B-splines at x in knot interval l (de Boor-Cox recursion, FITPACK fpbspl)."""
    hh = np.empty(3)
    h[0] = 1.0
    for j in range(1, 4):
        for i in range(j):
            hh[i] = h[i]
        h[0] = 0.0
        for i in range(1, j + 1):
            li = l + i
            lj = li - j
            if t[li] == t[lj]:
                h[i] = 0.0
                continue
            f = hh[i - 1] / (t[li] - t[lj])
            h[i - 1] += f * (t[li] - x)
            h[i] = f * (x - t[lj])


@njit(cache=True)
def bicubic(tx, ty, c, x, y):
    """Tensor-product cubic B-spline (FITPACK's tck as in scipy's RectBivariateSpline) at (x, y), clamped to its box."""
    x = min(max(x, tx[3]), tx[tx.size - 4])
    y = min(max(y, ty[3]), ty[ty.size - 4])
    lx, ly = _span(tx, 3, x), _span(ty, 3, y)
    hx, hy = np.empty(4), np.empty(4)
    _basis3(tx, lx, x, hx)
    _basis3(ty, ly, y, hy)
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
@njit(cache=True)
def _jkr_root(d):
    """(d clamped to the fold, stable root s of s^4 - s = d): `continuum.physics.jkr_kernel.stable_root_scalar`,
    the same closed form (Ferrari's resolvent by Cardano, one Newton polish) with np.cbrt for math.cbrt."""
    d = max(d, -_D_C)
    cc = np.cbrt(1.0 / 16.0 + math.sqrt(max(1.0 / 256.0 + d * d * d / 27.0, 0.0)))
    dd = -d / (3.0 * cc)
    w = math.sqrt(0.25 / (cc * cc + d / 3.0 + dd * dd))
    s = 0.5 * (w + math.sqrt(max(2.0 / w - w * w, 0.0)))
    s3 = s * s * s
    fp = 4.0 * s3 - 1.0
    if fp > 1e-3:
        s -= (s3 * s - s - d) / fp
    return d, s


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
    if gap >= P[P_END_GAP]:
        return 0.0
    if gap < P[P_H_LO]:
        S[S_BEYOND_FLAG] = 1.0
        return 0.0
    return bicubic(T[0], T[1], T[2], gap, _rigid_w(_rigid_window(gap, S, P), P))


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


# ----------------------------------------------------------------------------- DOP853
@njit(cache=True)
def _rhs(kind, gap, v, S, P, T, mass, gravity, out, row):
    out[row, 0] = v
    out[row, 1] = law_force(kind, gap, S, P, T) / mass - gravity


@njit(cache=True)
def _step(kind, S, P, T, mass, gravity, t, y, K, h_abs, max_step, rtol, atol, t_bound, y_new):
    """One accepted DOP853 step from (t, y) with K[0] = f(t, y) (SciPy `RungeKutta._step_impl`).

    Returns (t_new, h_used, h_abs_next, ok, evaluations); fills y_new and K[0:13] (K[12] = f(t_new, y_new))."""
    min_step = 10.0 * abs(np.nextafter(t, math.inf) - t)
    if h_abs > max_step:
        h_abs = max_step
    elif h_abs < min_step:
        h_abs = min_step
    rejected = False
    evals = 0
    while True:
        if h_abs < min_step:
            return t, 0.0, h_abs, False, evals
        t_new = t + h_abs
        if t_new - t_bound > 0.0:
            t_new = t_bound
        h = t_new - t
        h_abs = abs(h)
        for s in range(1, 12):
            d0 = 0.0
            d1 = 0.0
            for j in range(s):
                d0 += K[j, 0] * A[s, j]
                d1 += K[j, 1] * A[s, j]
            _rhs(kind, y[0] + d0 * h, y[1] + d1 * h, S, P, T, mass, gravity, K, s)
        b0 = 0.0
        b1 = 0.0
        for j in range(12):
            b0 += K[j, 0] * B[j]
            b1 += K[j, 1] * B[j]
        y_new[0] = y[0] + h * b0
        y_new[1] = y[1] + h * b1
        _rhs(kind, y_new[0], y_new[1], S, P, T, mass, gravity, K, 12)
        evals += 12
        e5n = 0.0
        e3n = 0.0
        for c in range(2):
            sc = atol[c] + max(abs(y[c]), abs(y_new[c])) * rtol
            e5 = 0.0
            e3 = 0.0
            for j in range(13):
                e5 += K[j, c] * E5[j]
                e3 += K[j, c] * E3[j]
            e5n += (e5 / sc) ** 2
            e3n += (e3 / sc) ** 2
        if e5n == 0.0 and e3n == 0.0:
            err = 0.0
        else:
            err = abs(h) * e5n / math.sqrt((e5n + 0.01 * e3n) * 2.0)
        if err < 1.0:
            if err == 0.0:
                factor = _MAX_FACTOR
            else:
                factor = min(_MAX_FACTOR, _SAFETY * err ** _ERROR_EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            return t_new, h, h_abs * factor, True, evals
        h_abs *= max(_MIN_FACTOR, _SAFETY * err ** _ERROR_EXPONENT)
        rejected = True


@njit(cache=True)
def _dense_coefficients(kind, S, P, T, mass, gravity, t_old, y_old, y_new, K, h, F):
    """Dense output of the last step (SciPy `DOP853._dense_output_impl`): 3 extra stages, 7 coefficient rows."""
    for s in range(13, 16):
        d0 = 0.0
        d1 = 0.0
        for j in range(s):
            d0 += K[j, 0] * A[s, j]
            d1 += K[j, 1] * A[s, j]
        _rhs(kind, y_old[0] + d0 * h, y_old[1] + d1 * h, S, P, T, mass, gravity, K, s)
    for c in range(2):
        dy = y_new[c] - y_old[c]
        F[0, c] = dy
        F[1, c] = h * K[0, c] - dy
        F[2, c] = 2.0 * dy - h * (K[12, c] + K[0, c])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += D[r, j] * K[j, c]
            F[3 + r, c] = h * acc


@njit(cache=True)
def _dense(F, t_old, h, y_old, t, c):
    """Component c of the dense output at t (SciPy `Dop853DenseOutput`)."""
    x = (t - t_old) / h
    y = 0.0
    for i in range(7):
        y += F[6 - i, c]
        if i % 2 == 0:
            y *= x
        else:
            y *= 1.0 - x
    return y + y_old[c]


@njit(cache=True)
def _brent(F, t_old, h, y_old, c, target, xa, xb):
    """Root of dense component c minus target in [xa, xb] (SciPy's brentq, xtol 1e-30, rtol 4 eps, 200 iterations)."""
    xtol, rtol = 1e-30, 4.0 * _EPS
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _dense(F, t_old, h, y_old, xpre, c) - target
    fcur = _dense(F, t_old, h, y_old, xcur, c) - target
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    for _ in range(200):
        if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
            xblk = xpre
            fblk = fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (xtol + rtol * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _dense(F, t_old, h, y_old, xcur, c) - target
    return xcur


@njit(cache=True)
def _root(F, t_old, h, y_old, c, target, a, b):
    """The driver's `_root`: a if it is a root, b if b is one or the ends do not bracket, else Brent."""
    fa = _dense(F, t_old, h, y_old, a, c) - target
    fb = _dense(F, t_old, h, y_old, b, c) - target
    if fa == 0.0:
        return a
    if fb == 0.0 or fa * fb > 0.0:
        return b
    return _brent(F, t_old, h, y_old, c, target, a, b)


# ----------------------------------------------------------------------------- the contact
@njit(cache=True)
def _sample(kind, S, P, T, buf, n, t, gap, v, pull, after_max):
    """Record a sample (the driver's `sample`); track the lowest force after the maximum approach."""
    if n >= buf.shape[0]:
        return n + 1
    f = law_force(kind, gap, S, P, T)
    buf[n, 0] = t
    buf[n, 1] = gap
    buf[n, 2] = v
    buf[n, 3] = f
    buf[n, 4] = law_stored(kind, gap, S, P, T)
    buf[n, 5] = law_dissipated(kind, gap, S, P, T)
    buf[n, 6] = 0.0
    if after_max and f < pull[2]:
        pull[0] = t
        pull[1] = gap
        pull[2] = f
        pull[3] = 1.0
    return n + 1


@njit(cache=True)
def _events(F, t_prev, h, y_old, y, t1, release, t_stop, ev_t, ev_k):
    """The events inside the step t_prev -> t1 into (ev_t, ev_k), sorted by time, ties in the driver's order
    (kinds: 0 maximum approach, 1 release, 2 the law's time event, 3 turning back). Returns their number and the
    time event still to come (inf once it is taken or passed)."""
    ne_ = 0
    if y_old[1] < 0.0 <= y[1]:
        ev_t[ne_] = _root(F, t_prev, h, y_old, 1, 0.0, t_prev, t1)
        ev_k[ne_] = 0
        ne_ += 1
    t_turn = math.nan
    if y_old[1] > 0.0 >= y[1]:
        t_turn = _root(F, t_prev, h, y_old, 1, 0.0, t_prev, t1)
        ev_t[ne_] = t_turn
        ev_k[ne_] = 3
        ne_ += 1
    if y_old[0] < release <= y[0]:
        ev_t[ne_] = _root(F, t_prev, h, y_old, 0, release, t_prev, t1)
        ev_k[ne_] = 1
        ne_ += 1
    elif y_old[0] < release and not math.isnan(t_turn) and _dense(F, t_prev, h, y_old, t_turn, 0) >= release:
        ev_t[ne_] = _root(F, t_prev, h, y_old, 0, release, t_prev, t_turn)
        ev_k[ne_] = 1
        ne_ += 1
    if t_stop <= t_prev:
        t_stop = math.inf
    if t_stop <= t1:
        ev_t[ne_] = t_stop
        ev_k[ne_] = 2
        ne_ += 1
        t_stop = math.inf
    for i in range(1, ne_):          # insertion sort on (time, kind)
        j = i
        while j > 0 and (ev_t[j] < ev_t[j - 1] or (ev_t[j] == ev_t[j - 1] and ev_k[j] < ev_k[j - 1])):
            ev_t[j], ev_t[j - 1] = ev_t[j - 1], ev_t[j]
            ev_k[j], ev_k[j - 1] = ev_k[j - 1], ev_k[j]
            j -= 1
    return ne_, t_stop


@njit(cache=True)
def _step_samples(kind, S, P, T, buf, n, F, t_prev, h, y_old, t1, samples_per_step, ne_, ev_t, pull, after_max):
    """Samples inside the step, up to its first event (the driver's np.linspace(t_prev, t1, m + 2)[1:-1])."""
    div = samples_per_step + 1
    dt = (t1 - t_prev) / div
    for i in range(1, samples_per_step + 1):
        s = t_prev + i * dt
        if ne_ > 0 and s >= ev_t[0]:
            break
        n = _sample(kind, S, P, T, buf, n, s, _dense(F, t_prev, h, y_old, s, 0), _dense(F, t_prev, h, y_old, s, 1),
                    pull, after_max)
    return n


@njit(cache=True)
def _release(kind, S, P, T, buf, n, te, release, v_e, pull, after_max, info):
    """The release event: a sample at the release gap, then the instant after (no force, nothing stored, the
    law's loss booked as dissipated); the end state and the loss go to `info`. Returns the sample count."""
    n = _sample(kind, S, P, T, buf, n, te, release, v_e, pull, after_max)
    loss = law_dissipated(kind, release, S, P, T)
    if n < buf.shape[0]:
        buf[n, 0] = te
        buf[n, 1] = release
        buf[n, 2] = v_e
        buf[n, 3] = 0.0
        buf[n, 4] = 0.0
        buf[n, 5] = loss
        buf[n, 6] = 1.0
    n += 1
    info[I_T], info[I_GAP], info[I_V] = te, release, v_e
    info[I_BOOKED] = loss
    return n


@njit(cache=True)
def _on_events(kind, S, P, T, mass, gravity, F, t_prev, h, y_old, ne_, ev_t, ev_k, release, bound_is_final,
               has_history, buf, n, pull, after_max, info, max_pen, peak, last_accept):
    """The step's events in order (the driver's `_on_events`): a time event stops the kernel; an extremum of the
    gap is sampled and accepted (a history law then restarts the step there); turning back while bound ends the
    contact stuck or at rest; a release ends it. Returns (end or -1, sample count, after_max, largest approach,
    peak force, last accepted time, restart, restart time, restart gap)."""
    end = -1
    restart = False
    rt, rg = 0.0, 0.0
    for e in range(ne_):
        te = ev_t[e]
        kind_e = ev_k[e]
        g_e = _dense(F, t_prev, h, y_old, te, 0)
        v_e = _dense(F, t_prev, h, y_old, te, 1)
        if kind_e == 2:
            end = END_STOP_TIME
            info[I_T], info[I_GAP], info[I_V] = te, g_e, v_e
            break
        if kind_e == 0 or kind_e == 3:
            max_pen = max(max_pen, -g_e)
            peak = max(peak, law_force(kind, g_e, S, P, T))
            n = _sample(kind, S, P, T, buf, n, te, g_e, 0.0, pull, after_max)
            if kind_e == 0 and info[I_HAS_MAX] == 0.0:
                info[I_MAX_T] = te
                info[I_MAX_GAP] = g_e
                info[I_HAS_MAX] = 1.0
            if kind_e == 0:
                after_max = True
            law_accept(kind, g_e, S, P, T)
            last_accept = te
            if has_history:
                restart = True
                rt, rg = te, g_e
        if kind_e == 3 and bound_is_final:
            if law_force(kind, g_e, S, P, T) < mass * gravity or gravity == 0.0:
                end = END_STUCK
            else:
                end = END_REST
            info[I_T], info[I_GAP], info[I_V] = te, g_e, 0.0
            info[I_BOOKED] = law_dissipated(kind, g_e, S, P, T)
            break
        if kind_e == 1:
            n = _release(kind, S, P, T, buf, n, te, release, v_e, pull, after_max, info)
            end = END_RELEASE
            break
        if restart:
            break
    return end, n, after_max, max_pen, peak, last_accept, restart, rt, rg


@njit(cache=True)
def integrate_contact(kind, S, P, T, mass, gravity, t0, gap0, v0, rtol, atol, first_step, max_step, t_bound,
                      release, bound_is_final, has_history, samples_per_step, t_stop, buf, info):
    """One contact from touch (t0, gap0, v0): the driver's `_contact` loop, compiled.

    Fills `buf` (samples, SAMPLE_COLUMNS) and `info` (INFO_SIZE slots: how it ended, where, peak force,
    largest approach, booked loss, the maximum approach and the pull-off sample); updates the law's
    history S. `t_stop` (absolute s, inf for none): a time at which the law's force jumps; the kernel
    returns END_STOP_TIME with the state there, unsampled and unaccepted (the caller's law does both).
    """
    K = np.zeros((16, 2))
    y = np.array([gap0, v0])
    y_new = np.empty(2)
    y_old = np.empty(2)
    F = np.empty((7, 2))
    pull = np.array([0.0, 0.0, math.inf, 0.0])
    for i in range(INFO_SIZE):
        info[i] = 0.0
    S[S_BEYOND_FLAG] = 0.0 if kind != LAW_POWER else S[S_BEYOND_FLAG]
    after_max = False
    t = t0
    _rhs(kind, y[0], y[1], S, P, T, mass, gravity, K, 0)
    evals = 1
    h_abs = min(first_step, max_step)
    peak = law_force(kind, gap0, S, P, T)
    max_pen = -gap0
    n = _sample(kind, S, P, T, buf, 0, t0, gap0, v0, pull, after_max)
    last_accept = t0
    steps = 0
    ev_t = np.empty(4)
    ev_k = np.empty(4, dtype=np.int64)
    end = -1
    while True:
        if kind != LAW_POWER and S[S_BEYOND_FLAG] != 0.0:
            end = ABORT_BEYOND_TABLES
            break
        if n > buf.shape[0]:
            end = ABORT_BUFFER
            break
        t_prev = t
        y_old[0] = y[0]
        y_old[1] = y[1]
        if t == t_bound:
            end = END_MAX_TIME
            info[I_T], info[I_GAP], info[I_V] = t, y[0], y[1]
            break
        t1, h, h_abs, ok, ne = _step(kind, S, P, T, mass, gravity, t, y, K, h_abs, max_step, rtol, atol, t_bound,
                                     y_new)
        evals += ne
        steps += 1
        if not ok:
            end = ABORT_STEP
            info[I_T] = t
            break
        finished = t1 - t_bound >= 0.0
        t = t1
        y[0] = y_new[0]
        y[1] = y_new[1]
        _dense_coefficients(kind, S, P, T, mass, gravity, t_prev, y_old, y, K, h, F)
        evals += 3
        ne_, t_stop = _events(F, t_prev, h, y_old, y, t1, release, t_stop, ev_t, ev_k)
        n = _step_samples(kind, S, P, T, buf, n, F, t_prev, h, y_old, t1, samples_per_step, ne_, ev_t, pull,
                          after_max)
        end, n, after_max, max_pen, peak, last_accept, restart, rt, rg = _on_events(
            kind, S, P, T, mass, gravity, F, t_prev, h, y_old, ne_, ev_t, ev_k, release, bound_is_final,
            has_history, buf, n, pull, after_max, info, max_pen, peak, last_accept)
        if end >= 0:
            break
        if restart:
            t = rt
            y[0] = rg
            y[1] = 0.0
            _rhs(kind, y[0], y[1], S, P, T, mass, gravity, K, 0)
            evals += 1
            h_abs = min(first_step, max_step)
            continue
        max_pen = max(max_pen, -y[0])
        peak = max(peak, law_force(kind, y[0], S, P, T))
        n = _sample(kind, S, P, T, buf, n, t1, y[0], y[1], pull, after_max)
        law_accept(kind, y[0], S, P, T)
        last_accept = t1
        # FSAL: the next step starts from f(t1, y1)
        K[0, 0] = K[12, 0]
        K[0, 1] = K[12, 1]
        if finished:
            end = END_MAX_TIME
            info[I_T], info[I_GAP], info[I_V] = t1, y[0], y[1]
            break
    return _close(kind, S, end, n, buf, info, peak, max_pen, pull, last_accept, steps, evals)


@njit(cache=True)
def _close(kind, S, end, n, buf, info, peak, max_pen, pull, last_accept, steps, evals):
    """How the contact ended (an abort outranks the end it reached) and its summary, into `info`; returns the end."""
    if kind != LAW_POWER and S[S_BEYOND_FLAG] != 0.0:
        end = ABORT_BEYOND_TABLES
    if n > buf.shape[0]:
        end = ABORT_BUFFER
    info[I_END] = end
    info[I_PEAK] = peak
    info[I_MAXPEN] = max_pen
    info[I_NSAMPLES] = min(n, buf.shape[0])
    info[I_PULL_T], info[I_PULL_GAP], info[I_PULL_F], info[I_HAS_PULL] = pull[0], pull[1], pull[2], pull[3]
    info[I_LAST_ACCEPT_T] = last_accept
    info[I_STEPS] = steps
    info[I_EVALS] = evals
    return end
