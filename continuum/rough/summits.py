"""Greenwood-Williamson summit statistics and the closed forms the GW surface is built from.

`SummitStatistics` (sigma, density, tip radius), the characteristic largest summit height, the exact
GW integral F_nu(h) (parabolic-cylinder functions), the standard-normal mass between two heights, and
the stable JKR root in the reduced variable s = sqrt(a/a0) (delta/delta0 = s^4 - s; the other JKR
closed forms are in `continuum.physics.jkr_kernel`). Used by the tabulated surface
(`continuum.rough.gw`), its slow reference (`gw_reference`) and the branch laws.

Sources: J. A. Greenwood & J. B. P. Williamson, Proc. R. Soc. Lond. A 295 (1966) 300-319; Abramowitz &
Stegun ch. 19 / DLMF §12.5; E. J. Gumbel, *Statistics of Extremes* (1958) §3.1; K. L. Johnson, K. Kendall &
A. D. Roberts, Proc. R. Soc. Lond. A 324 (1971) 301-313.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from ..physics import jkr_kernel as jk
from ..reference import jkr as _jkr

__all__ = ["SummitStatistics", "expected_max_height", "gw_integral", "TENSILE_ONSET"]

_SQRT2PI = math.sqrt(2.0 * math.pi)
# JKR in the reduced variable s = sqrt(a/a0): delta/delta0 = s^4 - s, delta_c/delta0 = _DC
# (continuum.physics.jkr_kernel).
_DC = jk.D_C
_S_ZERO = jk.S_ZERO                    # P = 0 on the stable branch
#: delta/delta_c at which the stable JKR branch changes sign (P < 0 below): 1.2114...
TENSILE_ONSET = (_S_ZERO**4 - _S_ZERO) / _DC
_GH_X, _GH_W = np.polynomial.hermite_e.hermegauss(60)   # weight exp(-t^2/2)


@dataclass(frozen=True)
class SummitStatistics:
    """Greenwood-Williamson summit statistics of a rough surface (composite of both surfaces)."""

    sigma: float
    """Standard deviation of summit heights about the summit mean plane (m); paper eq 9's sigma.
    Summit sigma is smaller than the RMS of surface heights."""
    density: float
    """Summits per unit nominal area n (1/m^2)."""
    radius: float
    """Tip radius beta of every summit (m); the paper's R in eqs 4-8."""

    def __post_init__(self):
        for name in ("sigma", "density", "radius"):
            v = getattr(self, name)
            try:
                ok = math.isfinite(float(v)) and float(v) > 0.0
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ValueError(f"SummitStatistics.{name} = {v!r}: must be a positive finite number")


def expected_max_height(n_summits) -> float:
    """Characteristic largest of N Gaussian summit heights, in units of sigma: Phi^{-1}(1 - 1/N).

    Extreme-value statistics (Gumbel, *Statistics of Extremes*, 1958, §3.1): the characteristic
    largest value u_N of N independent draws is defined by N [1 - Phi(u_N)] = 1, i.e. one summit is
    expected above it. It is the mode of the Gumbel limit of the maximum (the mean is larger by
    about 0.577/u_N). We truncate the summit distribution there: the model then holds exactly
    N - 1 expected summits, one less than the footprint, and first touch / last release are at a
    finite, well-defined height. Computed as -ndtri(1/N) (no cancellation for large N).
    """
    n = np.asarray(n_summits, float)
    if np.any(~(n > 1.0)):
        raise ValueError(f"expected_max_height: need more than one summit (got {n_summits!r})")
    return _out(-special.ndtri(1.0 / n))


def _out(x):
    x = np.asarray(x)
    return x[()] if x.ndim == 0 else x


def _phi(t):
    return np.exp(-0.5 * t * t) / _SQRT2PI


def gw_integral(nu, h):
    """F_nu(h) = (1/sqrt(2 pi)) int_h^inf (s - h)^nu exp(-s^2/2) ds, exactly (nu > -1).

    = Gamma(nu+1)/sqrt(2 pi) exp(-h^2/4) D_{-nu-1}(h) (DLMF 12.5.1 with U(a, z) = D_{-a-1/2}(z);
    Abramowitz & Stegun 19.5.3), scipy.special.pbdv. For h < -12 (pbdv loses ~1e-13 relative and
    would overflow further out) the integral is E[(Z - h)^nu], evaluated by 60-point Gauss-Hermite
    quadrature (the integrand is smooth there; P(Z < -12) ~ 2e-33). Vectorised; slow (~6 us/point):
    the surface tabulates it.
    """
    h = np.asarray(h, float)
    out = np.zeros_like(h)
    mid = (h >= -12.0) & (h <= 38.0)
    if np.any(mid):
        d, _ = special.pbdv(-nu - 1.0, h[mid])
        out[mid] = special.gamma(nu + 1.0) / _SQRT2PI * np.exp(-0.25 * h[mid] ** 2) * d
    low = h < -12.0
    if np.any(low):
        z = _GH_X[None, :] - h[low, None]
        out[low] = (np.maximum(z, 0.0) ** nu) @ _GH_W / _SQRT2PI
    return _out(out)


def _gauss_mass(a, b):
    """int_a^{b} phi (standard normal), a, b may be +-inf; 0 if b <= a. Cancellation-free tails."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    m = np.where(a > 0, special.ndtr(-a) - special.ndtr(-b), special.ndtr(b) - special.ndtr(a))
    return np.where(b > a, np.maximum(m, 0.0), 0.0)


# ---------------------------------------------------------------------------- JKR in s = sqrt(a/a0)
def _s_of_x(x):
    """Stable-branch s for delta/delta_c = x >= -1 (closed-form quartic inverse of reference.jkr)."""
    # with beta = 1, dgamma = 1/(2 pi), E* = 1: a0 = delta0 = 1, so a = s^2 and delta = x d_c.
    a = _jkr.radius_from_approach(np.asarray(x, float) * _DC, 1.0, 0.5 / math.pi, 1.0)
    return np.sqrt(a)
