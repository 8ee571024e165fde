"""Compiled contact phase: DOP853 with dense output and event location, for laws with a compiled form.

One contact of the event-driven driver (`continuum.dynamics.driver._ContactRun`) is a 1-D ODE, h' = v,
v' = F(h)/M - g, integrated until the body leaves (release), turns back while attached (stuck or
at rest), reaches a time the law asks to stop at (capillary bridges condense at t_a), or the run's
time limit. Stepped in Python through `scipy.integrate.DOP853`, a rough impact costs ~0.05-0.2 s,
almost all of it interpreter overhead; here the same algorithm runs compiled by numba.

The algorithm is the driver's, step for step (so results agree to round-off, not just to the
tolerance; `tests/continuum/test_contact_kernel.py` checks both):

* Runge-Kutta: Dormand & Prince's explicit 8th-order method with its 5th- and 3rd-order error
  estimators and 7th-order dense output (E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary
  Differential Equations I*, 2nd ed., Springer 1993, section II.10 and the code dop853.f; coefficients
  in `continuum.numerics.dop853_tableau`). Step-size control, error norm and factor limits (safety 0.9,
  0.2-10) are those of SciPy's `DOP853`, which follows Hairer's code.
* Events (maximum approach, turning back, release, a stop time) are sign changes of the dense
  output between the ends of an accepted step, located by Brent's method (R. P. Brent, *Algorithms
  for Minimization without Derivatives*, Prentice-Hall 1973, ch. 4; the variant of SciPy's `brentq`,
  xtol 1e-30, rtol 4 eps).
* History laws are restarted at every extremum of the motion, so no stage after it uses the
  history from before it (Hairer, Norsett & Wanner, section II.6 on discontinuities).
* A step's dense output (three more stages) is built only where it is read: a step that holds an event or
  samples inside it (SciPy builds it on request too); the force at a step's end is evaluated once for the peak
  force and the sample; the thin dispatchers between the stepper and the laws are inlined (a compiled call that
  passes the tables' tuple costs ~0.1 us, as much as a summit's evaluation). None of this changes a number.

Laws with a compiled form (`LAW_RIGID_TABLE`: the rigid rough roller's footprint tables, `continuum.laws.rough_rigid`;
`LAW_DISCRETE`: a realisation of closed-form JKR or Hertz summits on a rigid base (`continuum.laws.discrete_roller`)
or, `LAW_DISCRETE_BRANCH`, of tabulated branches of any summit law; `LAW_PLASTIC`: elastic-plastic summits,
`continuum.rough.plastic_kernel`; `LAW_PLASTIC_GW`: their GW mean field, `continuum.rough.plastic_gw_kernel`, whose
release gap grows with the history, so the kernel takes it from the law before every step as the driver does;
`LAW_POWER`: F = k (-h)^n, Hertz, to validate the integrator against closed forms)
give parameters `P`, tables `T` (a tuple of arrays) and a history `S` that the kernel updates in place; their
compiled force and energies live in `continuum.numerics.kernel_laws` (re-exported here). One law depends on time:
`wet_discrete_kernel.LAW_WET_DISCRETE` (discrete summits with a capillary bridge each, after t_a), so the kernel
evaluates every law at the stage's time (`_force`, ..., as SciPy's stepper calls the driver's right-hand side).

Where the compiled law cannot evaluate a state (deeper than its tables, where the Python law
evaluates its integral directly) or a buffer is full, the kernel returns a status saying so, and
the caller (`continuum.numerics.compiled_contact`) integrates that contact with the Python stepper, the
same algorithm: an explicit, recorded path, never a different model.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.brent import brent_step
from . import wet_discrete_kernel as wk
from .dop853_tableau import E3, E5, A, B, C, D
from .kernel_laws import (
    LAW_POWER,
    S_BEYOND_FLAG,
    law_accept,
    law_dissipated,
    law_force,
    law_force_inline,
    law_release_gap,
    law_release_loss,
    law_stored,
)

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
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_ERROR_EXPONENT = -1.0 / 8.0          # -1/(error estimator order + 1), order 7 (Hairer's dop853.f)
_EPS = np.finfo(float).eps


# ----------------------------------------------------------------------------- the law at time t
@njit(cache=True, inline="always")
def _force(kind, t, gap, S, P, T):
    """`kernel_laws.law_force`, and the time-dependent law (`wet_discrete_kernel`) at absolute time t."""
    if kind == wk.LAW_WET_DISCRETE:
        return wk.wet_value(0, t, gap, S, P, T)
    if kind == wk.LAW_BRIDGED:
        return wk.bridged_value(0, t, gap, S, P, T)
    return law_force(kind, gap, S, P, T)


@njit(cache=True, inline="always")
def _stage_force(kind, t, gap, S, P, T):
    """`_force` with the law's force inlined (`kernel_laws.law_force_inline`): the stepper's stages only."""
    if kind == wk.LAW_WET_DISCRETE:
        return wk.wet_value(0, t, gap, S, P, T)
    if kind == wk.LAW_BRIDGED:
        return wk.bridged_value(0, t, gap, S, P, T)
    return law_force_inline(kind, gap, S, P, T)


@njit(cache=True, inline="always")
def _stored(kind, t, gap, S, P, T):
    if kind == wk.LAW_WET_DISCRETE:
        return wk.wet_value(1, t, gap, S, P, T)
    if kind == wk.LAW_BRIDGED:
        return wk.bridged_value(1, t, gap, S, P, T)
    return law_stored(kind, gap, S, P, T)


@njit(cache=True, inline="always")
def _dissipated(kind, t, gap, S, P, T):
    if kind == wk.LAW_WET_DISCRETE:
        return wk.wet_value(2, t, gap, S, P, T)
    if kind == wk.LAW_BRIDGED:
        return wk.bridged_value(2, t, gap, S, P, T)
    return law_dissipated(kind, gap, S, P, T)


@njit(cache=True, inline="always")
def _accept(kind, t, gap, S, P, T):
    if kind == wk.LAW_WET_DISCRETE:
        wk.wet_accept(t, gap, S, P, T)
    elif kind == wk.LAW_BRIDGED:
        wk.bridged_accept(t, gap, S, P, T)
    else:
        law_accept(kind, gap, S, P, T)


# ----------------------------------------------------------------------------- DOP853
@njit(cache=True, inline="always")
def _rhs(kind, t, gap, v, S, P, T, mass, gravity, out, row):
    """A stage's slope into out[row] (inlined into the stepper and the dense output's stages)."""
    out[row, 0] = v
    out[row, 1] = _stage_force(kind, t, gap, S, P, T) / mass - gravity


@njit(cache=True)
def _first_slope(kind, t, gap, v, S, P, T, mass, gravity, out):
    """The slope at a step's start (a contact's touch, a restart), into out[0], through `_force` (the law called,
    not a third inlined copy of it)."""
    out[0, 0] = v
    out[0, 1] = _force(kind, t, gap, S, P, T) / mass - gravity


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
            _rhs(kind, t + C[s] * h, y[0] + d0 * h, y[1] + d1 * h, S, P, T, mass, gravity, K, s)
        b0 = 0.0
        b1 = 0.0
        for j in range(12):
            b0 += K[j, 0] * B[j]
            b1 += K[j, 1] * B[j]
        y_new[0] = y[0] + h * b0
        y_new[1] = y[1] + h * b1
        _rhs(kind, t_new, y_new[0], y_new[1], S, P, T, mass, gravity, K, 12)
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
        _rhs(kind, t_old + C[s] * h, y_old[0] + d0 * h, y_old[1] + d1 * h, S, P, T, mass, gravity, K, s)
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
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre,
                                                                    scur, xtol, rtol)
        if done:
            return xcur
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
    return _sample_f(kind, S, P, T, buf, n, t, gap, v, _force(kind, t, gap, S, P, T), pull, after_max)


@njit(cache=True)
def _sample_f(kind, S, P, T, buf, n, t, gap, v, f, pull, after_max):
    """`_sample` with the force at (t, gap) already evaluated (`f`, N): where the caller needs it too (the peak
    force at a step's end or an extremum), the law is evaluated once."""
    if n >= buf.shape[0]:
        return n + 1
    buf[n, 0] = t
    buf[n, 1] = gap
    buf[n, 2] = v
    buf[n, 3] = f
    buf[n, 4] = _stored(kind, t, gap, S, P, T)
    buf[n, 5] = _dissipated(kind, t, gap, S, P, T)
    buf[n, 6] = 0.0
    if after_max and f < pull[2]:
        pull[0] = t
        pull[1] = gap
        pull[2] = f
        pull[3] = 1.0
    return n + 1


@njit(cache=True)
def _needs_dense(y_old, y, release, t_prev, t1, t_stop):
    """Whether the step t_prev -> t1 holds an event (`_events`' tests on the step's ends): only then, or to sample
    inside the step, is its dense output (3 more stages) built; a step without either does not read it."""
    return (y_old[1] < 0.0 <= y[1] or y_old[1] > 0.0 >= y[1] or y_old[0] < release <= y[0]
            or t_prev < t_stop <= t1)


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
    if kind == wk.LAW_WET_DISCRETE or kind == wk.LAW_BRIDGED:
        loss = _dissipated(kind, te, release, S, P, T)
    else:
        loss = law_release_loss(kind, release, S, P, T)
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
            f_e = _force(kind, te, g_e, S, P, T)
            peak = max(peak, f_e)
            n = _sample_f(kind, S, P, T, buf, n, te, g_e, 0.0, f_e, pull, after_max)
            if kind_e == 0 and info[I_HAS_MAX] == 0.0:
                info[I_MAX_T] = te
                info[I_MAX_GAP] = g_e
                info[I_HAS_MAX] = 1.0
            if kind_e == 0:
                after_max = True
            _accept(kind, te, g_e, S, P, T)
            last_accept = te
            if has_history:
                restart = True
                rt, rg = te, g_e
        if kind_e == 3 and bound_is_final:
            if _force(kind, te, g_e, S, P, T) < mass * gravity or gravity == 0.0:
                end = END_STUCK
            else:
                end = END_REST
            info[I_T], info[I_GAP], info[I_V] = te, g_e, 0.0
            info[I_BOOKED] = _dissipated(kind, te, g_e, S, P, T)
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
                      release, bound_is_final, has_history, samples_per_step, t_stop, buf, info, after_max0):
    """One contact from touch (t0, gap0, v0): the driver's `_contact` loop, compiled.

    Fills `buf` (samples, SAMPLE_COLUMNS) and `info` (INFO_SIZE slots: how it ended, where, peak force,
    largest approach, booked loss, the maximum approach and the pull-off sample); updates the law's
    history S. `t_stop` (absolute s, inf for none): a time at which the law's force jumps; the kernel
    returns END_STOP_TIME with the state there, unsampled and unaccepted (the caller's law does both).
    `after_max0`: the contact went through its maximum approach before t0 (a contact continued after a stop).
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
    after_max = after_max0
    t = t0
    _first_slope(kind, t, y[0], y[1], S, P, T, mass, gravity, K)
    evals = 1
    h_abs = min(first_step, max_step)
    peak = _force(kind, t0, gap0, S, P, T)
    max_pen = -gap0
    n = _sample_f(kind, S, P, T, buf, 0, t0, gap0, v0, peak, pull, after_max)
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
        release = law_release_gap(kind, S, P, T, release)     # on the history accepted so far, as the driver's
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
        if samples_per_step > 0 or _needs_dense(y_old, y, release, t_prev, t1, t_stop):
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
            _first_slope(kind, t, y[0], y[1], S, P, T, mass, gravity, K)
            evals += 1
            h_abs = min(first_step, max_step)
            continue
        max_pen = max(max_pen, -y[0])
        f1 = _force(kind, t1, y[0], S, P, T)
        peak = max(peak, f1)
        n = _sample_f(kind, S, P, T, buf, n, t1, y[0], y[1], f1, pull, after_max)
        _accept(kind, t1, y[0], S, P, T)
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
