"""Closed-form Hertz reference solutions: sphere, roller (line contact), and impact closed forms.

All quantities are SI (m, N, Pa, J, kg, s). Every function is pure NumPy and vectorised: array
arguments broadcast against each other; a 0-d result is returned as a NumPy scalar.

Convention for the contact modulus
----------------------------------
``e_star`` is Johnson's contact modulus (Johnson, *Contact Mechanics*, 1985, eq 4.22)::

    1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.

Hamrock's reduced modulus E' = 2 E* is *not* used. The founding paper's eq 1 writes the
half-width as b = sqrt(8 W R / (pi E* l)), which is Hamrock's form with E' replaced by E*; with
Johnson's E* the half-width is b = sqrt(4 W R / (pi E* l)) (Johnson §4.2, eq 4.43 with the load
per unit length W/l), and the peak pressure is p_max = 2 W / (pi b l).

Sphere on a flat (Johnson §4.2, eqs 4.22-4.23; impact §11.4)
-------------------------------------------------------------
P = (4/3) E* R^{1/2} delta^{3/2},  a = sqrt(R delta),  U = (8/15) E* R^{1/2} delta^{5/2}.
Impact of a mass M at speed v: delta_max = (15 M v^2 / (16 E* R^{1/2}))^{2/5},
contact time t = c delta_max / v with c = 2 int_0^1 (1 - x^{5/2})^{-1/2} dx = (4/5) B(2/5, 1/2)
(= 2.9432..., computed here from the Beta function, see ``SPHERE_IMPACT_TIME_CONSTANT``).

Roller of radius R and length l on a half-space (paper eq 1; Johnson §5.6)
---------------------------------------------------------------------------
The approach of a cylinder of finite length is logarithmic in the load W::

    delta = W (2 ln(2 l / b) + 1) / (pi l E*),   b = sqrt(4 W R / (pi E* l)).

Nondimensionalisation used for its inverse: with x = W (N) and
C = 2 ln(2 l) + 1 - ln(4 R / (pi E* l)) (lengths in metres inside the logarithms; C is
dimensionless once combined with ln x), the log factor is 2 ln(2l/b) + 1 = C - ln x, so

    x (C - ln x) = pi l E* delta =: D   (D in newtons).

Writing x = -D / t with t = -(C - ln x) gives t e^t = -D e^{-C}, i.e. t = W_{-1}(-D e^{-C}) with the
Lambert W function on its lower branch k = -1 (t <= -1, the branch on which dW/d delta > 0 and
W -> 0 as delta -> 0). The energy U = int_0^delta W d delta' follows from
d delta = (C - 1 - ln x) dx / (pi l E*):  U = x^2 [(C - ln x)/2 - 1/4] / (pi l E*).

Range of validity (a documented choice): the log formula is an asymptotic result for a long,
narrow strip b << l. The lower Lambert branch exists up to b = 2 l (log factor 1, where
dW/d delta diverges), but the formula has lost its meaning long before. The line-contact functions
that use the log factor raise ``ValueError`` when the half-width exceeds ``LINE_MAX_HALF_WIDTH_RATIO
* l`` with ratio 1 (b <= l: the footprint 2b x l is at most square; log factor >= 1 + 2 ln 2).

Impact of a constant-stiffness contact
--------------------------------------
With constant K (the paper's linearisation "W ~ K delta", eq 2) a body of mass M hitting at speed v
with gravity g pulling it into contact is a shifted harmonic oscillator:
omega = sqrt(K/M), delta_s = M g / K, delta(t) = delta_s (1 - cos omega t) + (v/omega) sin omega t.

Sources: K. L. Johnson, *Contact Mechanics*, Cambridge University Press (1985), §4.2 (Hertz
sphere and cylinders), §5.6 (approach of a cylinder of finite length), §11.4 (impact of spheres);
B. J. Hamrock, *Fundamentals of Fluid Film Lubrication* (1994) for the E' = 2E* convention.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.special import beta as _beta_fn
from scipy.special import lambertw

__all__ = [
    "SPHERE_IMPACT_TIME_CONSTANT",
    "LINE_MAX_HALF_WIDTH_RATIO",
    "effective_modulus",
    "sphere_force",
    "sphere_stiffness",
    "sphere_energy",
    "sphere_contact_radius",
    "sphere_impact",
    "line_half_width",
    "line_peak_pressure",
    "line_stiffness",
    "line_approach",
    "line_force",
    "line_stiffness_tangent",
    "line_energy",
    "line_max_approach",
    "linear_oscillator_impact",
    "line_impact_max_approach",
]

#: Dimensionless Hertz sphere impact-duration constant c in t = c delta_max / v:
#: c = 2 int_0^1 (1 - x^{5/2})^{-1/2} dx = (4/5) B(2/5, 1/2) = 2.9432...
SPHERE_IMPACT_TIME_CONSTANT = float(0.8 * _beta_fn(0.4, 0.5))

#: Largest admitted half-width of the roller contact, as a fraction of the roller length l.
LINE_MAX_HALF_WIDTH_RATIO = 1.0


def _out(x):
    """Return a NumPy scalar for 0-d results, the array otherwise."""
    x = np.asarray(x)
    return x[()] if x.ndim == 0 else x


# ----------------------------------------------------------------------------------------------
# Contact modulus
# ----------------------------------------------------------------------------------------------
def effective_modulus(youngs_1, poisson_1, youngs_2, poisson_2):
    """Johnson's contact modulus E* (Pa): 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.

    youngs_1, youngs_2: Young's moduli (Pa); poisson_1, poisson_2: Poisson ratios (-).
    Hamrock's reduced modulus is E' = 2 E*.
    """
    youngs_1, poisson_1 = np.asarray(youngs_1, float), np.asarray(poisson_1, float)
    youngs_2, poisson_2 = np.asarray(youngs_2, float), np.asarray(poisson_2, float)
    return _out(1.0 / ((1.0 - poisson_1**2) / youngs_1 + (1.0 - poisson_2**2) / youngs_2))


# ----------------------------------------------------------------------------------------------
# Sphere
# ----------------------------------------------------------------------------------------------
def sphere_force(delta, radius, e_star):
    """Hertz sphere force P = (4/3) E* sqrt(R) delta^{3/2} (N); 0 for delta <= 0.

    delta: approach (m); radius: sphere radius R (m); e_star: contact modulus (Pa).
    """
    d = np.maximum(np.asarray(delta, float), 0.0)
    return _out(4.0 / 3.0 * np.asarray(e_star, float) * np.sqrt(np.asarray(radius, float)) * d**1.5)


def sphere_stiffness(delta, radius, e_star):
    """Hertz sphere tangent stiffness dP/d delta = 2 E* sqrt(R delta) = 2 E* a (N/m); 0 for delta <= 0.

    delta (m), radius (m), e_star (Pa).
    """
    d = np.maximum(np.asarray(delta, float), 0.0)
    return _out(2.0 * np.asarray(e_star, float) * np.sqrt(np.asarray(radius, float) * d))


def sphere_energy(delta, radius, e_star):
    """Hertz sphere elastic energy U = (8/15) E* sqrt(R) delta^{5/2} (J); 0 for delta <= 0.

    delta (m), radius (m), e_star (Pa).
    """
    d = np.maximum(np.asarray(delta, float), 0.0)
    return _out(8.0 / 15.0 * np.asarray(e_star, float) * np.sqrt(np.asarray(radius, float)) * d**2.5)


def sphere_contact_radius(delta, radius):
    """Hertz contact radius a = sqrt(R delta) (m); 0 for delta <= 0. delta (m), radius (m)."""
    d = np.maximum(np.asarray(delta, float), 0.0)
    return _out(np.sqrt(np.asarray(radius, float) * d))


def sphere_impact(mass, velocity, radius, e_star):
    """Classical elastic Hertz impact of a sphere on a flat (Johnson §11.4), no gravity.

    mass: (effective) mass M (kg); velocity: impact speed v (m/s); radius: R (m); e_star (Pa).
    Returns dict with ``max_approach`` delta_max = (15 M v^2 / (16 E* sqrt(R)))^{2/5} (m),
    ``contact_time`` t = c delta_max / v with c = ``SPHERE_IMPACT_TIME_CONSTANT`` (s), and
    ``peak_force`` (4/3) E* sqrt(R) delta_max^{3/2} (N).
    """
    m = np.asarray(mass, float)
    v = np.abs(np.asarray(velocity, float))
    r = np.asarray(radius, float)
    e = np.asarray(e_star, float)
    dmax = (15.0 * m * v**2 / (16.0 * e * np.sqrt(r))) ** 0.4
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(v > 0.0, SPHERE_IMPACT_TIME_CONSTANT * dmax / np.where(v > 0.0, v, 1.0), 0.0)
    return {
        "max_approach": _out(dmax),
        "contact_time": _out(t),
        "peak_force": _out(4.0 / 3.0 * e * np.sqrt(r) * dmax**1.5),
    }


# ----------------------------------------------------------------------------------------------
# Roller (line contact) of finite length
# ----------------------------------------------------------------------------------------------
def line_half_width(load, radius, length, e_star):
    """Hertz line-contact half-width b = sqrt(4 W R / (pi E* l)) (m), Johnson's E* convention.

    load: total load W (N); radius: roller radius R (m); length: roller length l (m); e_star (Pa).
    (The paper's eq 1 has 8 instead of 4: Hamrock's E' = 2 E*.)
    """
    w = np.maximum(np.asarray(load, float), 0.0)
    return _out(np.sqrt(4.0 * w * np.asarray(radius, float)
                        / (np.pi * np.asarray(e_star, float) * np.asarray(length, float))))


def line_peak_pressure(load, radius, length, e_star):
    """Hertz line-contact peak pressure p_max = 2 W / (pi b l) = sqrt(W E* / (pi R l)) (Pa).

    load W (N), radius R (m), length l (m), e_star (Pa). Zero at zero load.
    """
    w = np.maximum(np.asarray(load, float), 0.0)
    return _out(np.sqrt(w * np.asarray(e_star, float)
                        / (np.pi * np.asarray(radius, float) * np.asarray(length, float))))


def _line_c(radius, length, e_star):
    """C = 2 ln(2 l) + 1 - ln(4 R / (pi E* l)) so that 2 ln(2l/b) + 1 = C - ln W (W in N)."""
    r = np.asarray(radius, float)
    l = np.asarray(length, float)
    e = np.asarray(e_star, float)
    return 2.0 * np.log(2.0 * l) + 1.0 - np.log(4.0 * r / (np.pi * e * l))


def _log_factor_min():
    """Smallest admitted log factor 2 ln(2l/b) + 1, at b = LINE_MAX_HALF_WIDTH_RATIO * l."""
    return 2.0 * math.log(2.0 / LINE_MAX_HALF_WIDTH_RATIO) + 1.0


def _check_log_factor(factor, what):
    factor = np.asarray(factor)
    bad = factor < _log_factor_min() * (1.0 - 1e-14)
    if np.any(bad):
        raise ValueError(
            f"{what} beyond the line-contact limit: half-width b exceeds "
            f"{LINE_MAX_HALF_WIDTH_RATIO:g} x roller length l (log factor 2 ln(2l/b) + 1 = "
            f"{float(np.min(factor)):.6g} < {_log_factor_min():.6g}); the logarithmic approach "
            "formula (Johnson §5.6) assumes b << l"
        )


def _line_log_factor_from_load(load, radius, length, e_star):
    """2 ln(2l/b) + 1 at load W (> 0)."""
    b = np.asarray(line_half_width(load, radius, length, e_star))
    with np.errstate(divide="ignore"):
        return 2.0 * np.log(2.0 * np.asarray(length, float) / b) + 1.0


def line_max_approach(radius, length, e_star):
    """Largest approach (m) admitted by the line-contact functions: delta at b = l (see module doc).

    radius R (m), length l (m), e_star (Pa).
    """
    l = np.asarray(length, float)
    r = np.asarray(radius, float)
    e = np.asarray(e_star, float)
    b = LINE_MAX_HALF_WIDTH_RATIO * l
    w = np.pi * e * l * b**2 / (4.0 * r)
    return _out(w * _log_factor_min() / (np.pi * l * e))


def _checked_load_factor(load, radius, length, e_star):
    """(W > 0 mask, W with non-positive entries replaced by 1, log factor 2 ln(2l/b) + 1, pi l E*).

    Raises ValueError if the half-width of a positive load exceeds the roller length.
    """
    w = np.asarray(load, float)
    pos = w > 0.0
    wsafe = np.where(pos, w, 1.0)
    factor = _line_log_factor_from_load(wsafe, radius, length, e_star)
    _check_log_factor(np.where(pos, factor, np.inf), "load")
    return pos, wsafe, factor, np.pi * np.asarray(length, float) * np.asarray(e_star, float)


def line_stiffness(load, radius, length, e_star):
    """Secant ("constant K") roller stiffness of paper eq 1 at load W (N/m).

    K = pi l E* / (2 ln(2l/b) + 1) with b = line_half_width(W): the linearisation W ~ K delta
    evaluated at the half-width of that load. load W (N), radius R (m), length l (m), e_star (Pa).
    K -> 0 as W -> 0 (returns 0 for W <= 0). Raises ValueError if b > l.
    """
    pos, wsafe, factor, ple = _checked_load_factor(load, radius, length, e_star)
    return _out(np.where(pos, ple / factor, 0.0))


def line_approach(load, radius, length, e_star):
    """Roller approach delta = W (2 ln(2l/b) + 1) / (pi l E*) (m) at load W (paper eq 1, Johnson §5.6).

    load W (N), radius R (m), length l (m), e_star (Pa). 0 for W <= 0. Raises ValueError if b > l.
    """
    pos, wsafe, factor, ple = _checked_load_factor(load, radius, length, e_star)
    return _out(np.where(pos, wsafe * factor / ple, 0.0))


def _line_solve(delta, radius, length, e_star):
    """Exact inverse of line_approach. Returns (x = W in N, q = 2 ln(2l/b) + 1 = C - ln x, D = pi l E* delta).

    For delta <= 0 returns x = 0, q = inf.
    """
    d = np.asarray(delta, float)
    l = np.asarray(length, float)
    e = np.asarray(e_star, float)
    c = _line_c(radius, length, e_star)
    d, l, e, c = np.broadcast_arrays(d, l, e, c)
    big_d = np.pi * l * e * np.where(d > 0.0, d, 0.0)
    pos = big_d > 0.0
    # lower branch of Lambert W: t = W_{-1}(-D e^{-C}) <= -1; q = -t is the log factor.
    # Evaluate the argument in log form so that e^{-C} cannot overflow/underflow on its own.
    with np.errstate(divide="ignore", over="ignore"):
        log_arg = np.log(np.where(pos, big_d, 1.0)) - c
    arg = -np.exp(log_arg)
    limit = -np.exp(-1.0)
    # The admitted range (b <= l) keeps the argument well inside (-1/e, 0); check it first.
    q_min = _log_factor_min()
    # D at the limit, x q with x the load at b = ratio l, computed as line_max_approach does: the
    # equivalent e^{C - q_min} q_min carries a relative rounding of ~|C| eps (C reaches ~40), more
    # than the 1e-14 slack, and refused line_max_approach's own value for some geometries.
    b_lim = LINE_MAX_HALF_WIDTH_RATIO * l
    d_lim = np.pi * e * l * b_lim**2 / (4.0 * np.asarray(radius, float)) * q_min
    if np.any(pos & (big_d > d_lim * (1.0 + 1e-14))):
        _check_log_factor(np.where(pos & (big_d > d_lim * (1.0 + 1e-14)), 0.0, np.inf), "approach")
    arg = np.maximum(arg, limit)
    with np.errstate(invalid="ignore"):
        t = np.real(lambertw(np.where(pos, arg, -0.1), k=-1))
    q = np.where(pos, -t, np.inf)
    # Tiny arguments underflow to 0 (W_{-1} -> -inf): use the asymptotic fixed point directly.
    tiny = pos & ~np.isfinite(q)
    if np.any(tiny):
        # q = C - ln x and x = D/q  =>  q = C - ln D + ln q  (fixed point, converges fast for large q)
        qq = np.where(tiny, c - np.log(np.where(tiny, big_d, 1.0)), 1.0)
        for _ in range(60):
            qq = np.where(tiny, c - np.log(np.where(tiny, big_d, 1.0)) + np.log(qq), qq)
        q = np.where(tiny, qq, q)
    # One Newton polish on g(q) = q - C + ln D - ln q = 0 (g' = 1 - 1/q), exact for the k=-1 root.
    with np.errstate(invalid="ignore", divide="ignore"):
        lnd = np.log(np.where(pos, big_d, 1.0))
        for _ in range(2):
            g = q - c + lnd - np.log(q)
            step = g / (1.0 - 1.0 / q)
            q = np.where(pos & np.isfinite(step) & (q > 1.0), q - step, q)
    x = np.where(pos, big_d / np.where(pos, q, 1.0), 0.0)
    return x, q, big_d


def line_force(delta, radius, length, e_star):
    """Exact inverse of ``line_approach``: load W (N) at approach delta (m), via Lambert W_{-1}.

    With x = W: x (C - ln x) = pi l E* delta, C = 2 ln(2l) + 1 - ln(4R/(pi E* l)); the solution on
    the physical branch is x = -D / W_{-1}(-D e^{-C}), D = pi l E* delta. radius R (m), length l
    (m), e_star (Pa). Returns 0 for delta <= 0; raises ValueError if the half-width would exceed l.
    """
    x, _, _ = _line_solve(delta, radius, length, e_star)
    return _out(x)


def line_stiffness_tangent(delta, radius, length, e_star):
    """Exact tangent stiffness dW/d delta of the roller contact (N/m).

    From d delta/dW = (C - 1 - ln W)/(pi l E*) = 2 ln(2l/b)/(pi l E*):
    dW/d delta = pi l E* / (2 ln(2l/b)), with b the half-width at the load of that approach. delta (m), radius R (m),
    length l (m), e_star (Pa). 0 for delta <= 0 (the log stiffness vanishes at first touch).
    """
    _, q, _ = _line_solve(delta, radius, length, e_star)
    l = np.asarray(length, float)
    e = np.asarray(e_star, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(np.isfinite(q), np.pi * l * e / (q - 1.0), 0.0)
    return _out(k)


def line_energy(delta, radius, length, e_star):
    """Elastic energy of the roller contact U = int_0^delta W d delta' (J), closed form.

    U = x^2 [(C - ln x)/2 - 1/4] / (pi l E*) with x = W(delta) and C - ln x = 2 ln(2l/b) + 1.
    delta (m), radius R (m), length l (m), e_star (Pa). 0 for delta <= 0.
    """
    x, q, _ = _line_solve(delta, radius, length, e_star)
    l = np.asarray(length, float)
    e = np.asarray(e_star, float)
    with np.errstate(invalid="ignore"):
        u = np.where(x > 0.0, x**2 * (0.5 * np.where(np.isfinite(q), q, 0.0) - 0.25) / (np.pi * l * e), 0.0)
    return _out(u)


# ----------------------------------------------------------------------------------------------
# Impact closed forms
# ----------------------------------------------------------------------------------------------
def linear_oscillator_impact(mass, stiffness, velocity, gravity=0.0):
    """Impact of a body on a constant-stiffness contact (paper eq 2 with gravity).

    mass M (kg), stiffness K (N/m), velocity: impact speed v >= 0 towards the surface (m/s),
    gravity g (m/s^2) pulling the body into contact. With omega = sqrt(K/M) and
    delta_s = M g / K the approach is delta(t) = delta_s (1 - cos wt) + (v/w) sin wt while
    delta > 0. Returns dict:
      ``max_approach`` delta_s + sqrt(delta_s^2 + (v/w)^2) (m),
      ``contact_time`` (pi + 2 atan(delta_s w / v)) / w (s), the next time delta = 0,
      ``time_of_max`` (pi/2 + atan(delta_s w / v)) / w (s), half the contact time,
      ``rebound_velocity`` v (m/s) (energy is conserved),
      ``omega`` w (rad/s), ``static_approach`` delta_s (m).
    With g = 0 this is delta_max = v sqrt(M/K), t = pi sqrt(M/K) (paper eq 2).
    For v = 0 and g > 0 the body rests on the spring: contact_time = 2 pi / w (one full swing).
    """
    m = np.asarray(mass, float)
    k = np.asarray(stiffness, float)
    v = np.asarray(velocity, float)
    g = np.asarray(gravity, float)
    w = np.sqrt(k / m)
    ds = m * g / k
    phase = np.arctan2(ds * w, v)  # atan(delta_s w / v), = pi/2 for v = 0
    return {
        "max_approach": _out(ds + np.hypot(ds, v / w)),
        "contact_time": _out((np.pi + 2.0 * phase) / w),
        "time_of_max": _out((0.5 * np.pi + phase) / w),
        "rebound_velocity": _out(v + 0.0 * w),
        "omega": _out(w),
        "static_approach": _out(ds),
    }


def line_impact_max_approach(mass, velocity, radius, length, e_star, gravity=0.0):
    """Maximum approach (m) of a roller impact on the log-stiffness line contact, with gravity.

    Solves U(delta) = (1/2) M v^2 + M g delta (energy balance at the turning point) with brentq
    at full double precision. mass M (kg), velocity v (m/s), radius R (m), length l (m),
    e_star (Pa), gravity g (m/s^2). Returns 0 if v = 0 and g = 0.
    """
    m, v, r, l, e, g = np.broadcast_arrays(*(np.asarray(a, float) for a in
                                             (mass, velocity, radius, length, e_star, gravity)))
    out = np.empty(m.shape)
    for idx in np.ndindex(m.shape):
        out[idx] = _line_impact_scalar(m[idx], v[idx], r[idx], l[idx], e[idx], g[idx])
    return _out(out)


def _line_impact_scalar(m, v, r, l, e, g):
    ek = 0.5 * m * v * v
    if ek <= 0.0 and g <= 0.0:
        return 0.0

    def f(d):
        return float(line_energy(d, r, l, e)) - ek - m * g * d

    # Lower bracket: the static approach under M g (U < M g delta there), or 0.
    lo = float(line_approach(m * g, r, l, e)) if g > 0.0 else 0.0
    dlim = float(line_max_approach(r, l, e))
    k0 = float(line_stiffness(max(m * g, 0.0) + v * math.sqrt(m * math.pi * l * e / 40.0), r, l, e))
    hi = max(lo, 0.0) + v * math.sqrt(m / k0) + 2.0 * m * g / k0
    hi = min(max(hi, lo * 2.0, 1e-300), dlim)
    while f(hi) < 0.0:
        if hi >= dlim:
            raise ValueError("impact energy drives the roller contact beyond its validity limit b <= l")
        hi = min(2.0 * hi, dlim)
    if f(lo) >= 0.0:
        return lo
    return brentq(f, lo, hi, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)
