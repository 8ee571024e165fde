"""Summit statistics of a filtered height map by two routes: Nayak's spectral moments and a direct count.

Spectral route (isotropic Gaussian surface). SurfaceTopography gives the areal moments of the power spectrum,
M_a = (2 pi)^-2 \\int d^2q |q|^a C(q): M0 = <h^2>, M2 = <|grad h|^2>, M4 = <(lap h)^2>. Nayak's formulas are
written with the moments of a profile (one line across the surface), which for an isotropic surface are the
direction averages m0 = M0, m2 = M2 / 2, m4 = 3 M4 / 8 (the averages of cos^2 and cos^4 over the direction);
these profile moments are the ones used and recorded. With the bandwidth alpha = m0 m4 / m2^2 (>= 1.5):

- summit density            eta      = m4 / (6 pi sqrt(3) m2)           (Nayak, J. Lubr. Technol. 93 (1971) 398, exact)
- mean summit curvature     kappa    = (8/3) sqrt(m4 / pi), beta = 1/kappa
                                                                        (large-alpha limit; McCool, Wear 107 (1986) 37)
- summit-height variance    sigma_s^2 = (1 - 0.8968/alpha) m0              (McCool 1986)
- mean summit height        4 sqrt(m0 / (pi alpha)) above the mean plane    (McCool 1986)

Direct route: the summits `continuum.rough.topography.identify_summits` finds; eta = count / area, sigma_s
their heights' standard deviation and beta = 1 / mean curvature (the mean of the curvatures, as the spectral
kappa is, not of the radii: a nearly flat summit's radius is unbounded).

Greenwood & Williamson, Proc. R. Soc. Lond. A 295 (1966) 300, give every summit the one radius beta; their
sigma is the summit heights' standard deviation, which is what `surfaces.roughness.sigma` holds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["SpectralSummits", "DirectSummits", "spectral_summits", "spectral_from_moments", "areal_moments",
           "direct_summary", "profile_moments"]

_NAYAK = 6.0 * math.pi * math.sqrt(3.0)


@dataclass(frozen=True)
class SpectralSummits:
    """Summit statistics from the profile moments of the filtered map (SI)."""

    m0: float
    """Height variance (m^2)."""
    m2: float
    """Profile slope variance (1): half the mean square gradient."""
    m4: float
    """Profile curvature variance (1/m^2): 3/8 of the mean square Laplacian."""
    alpha: float
    """Nayak's bandwidth m0 m4 / m2^2."""
    summit_density: float
    summit_radius: float
    summit_height_std: float
    mean_summit_height: float
    moments: str = "profile (direction-averaged) moments from SurfaceTopography's areal moments"


@dataclass(frozen=True)
class DirectSummits:
    """Summit statistics counted on the filtered grid (SI)."""

    count: int
    area: float
    summit_density: float
    summit_radius: float
    summit_height_std: float
    mean_summit_height: float


def profile_moments(areal_m0: float, areal_m2: float, areal_m4: float) -> tuple[float, float, float]:
    """Profile moments (m0, m2, m4) of an isotropic surface from its areal moments <h^2>, <|grad h|^2>,
    <(lap h)^2>: a profile along any direction sees <h_x^2> = M2/2 and <h_xx^2> = 3 M4/8."""
    return areal_m0, 0.5 * areal_m2, 0.375 * areal_m4


def _filtered_periodic(topography, cutoff: float):
    """The topography low-pass filtered at wavelength `cutoff`, made periodic by mirror-stitching if it is not."""
    periodic = topography if topography.is_periodic else topography.mirror_stitch()
    return periodic.shortcut(cutoff_wavelength=cutoff)


def spectral_summits(topography, cutoff: float) -> SpectralSummits:
    """Nayak/McCool statistics of a SurfaceTopography map (metres) filtered at wavelength `cutoff` (m)."""
    return spectral_from_moments(*profile_moments(*areal_moments(topography, cutoff)))


def areal_moments(topography, cutoff: float) -> tuple[float, float, float]:
    """Areal moments <h^2>, <|grad h|^2>, <(lap h)^2> of a SurfaceTopography map filtered at `cutoff` (m)."""
    filtered = _filtered_periodic(topography, cutoff)
    return tuple(float(filtered.moment_power_spectrum(order, window=None, reliable=False)) for order in (0, 2, 4))


def spectral_from_moments(m0: float, m2: float, m4: float) -> SpectralSummits:
    """Nayak/McCool summit statistics from the profile moments (m0, m2, m4) (SI)."""
    alpha = m0 * m4 / m2**2
    kappa = 8.0 / 3.0 * math.sqrt(m4 / math.pi)
    return SpectralSummits(m0=m0, m2=m2, m4=m4, alpha=alpha, summit_density=m4 / (_NAYAK * m2),
                           summit_radius=1.0 / kappa,
                           summit_height_std=math.sqrt(max(1.0 - 0.8968 / alpha, 0.0) * m0),
                           mean_summit_height=4.0 * math.sqrt(m0 / (math.pi * alpha)))


def direct_summary(summits) -> DirectSummits:
    """Density, mean-curvature radius and height statistics of the summits found on a grid."""
    kappa = float(np.mean(summits.curvature))
    return DirectSummits(count=summits.count, area=summits.area, summit_density=summits.density,
                         summit_radius=1.0 / kappa if kappa > 0 else math.inf,
                         summit_height_std=float(np.std(summits.height)),
                         mean_summit_height=float(np.mean(summits.height)))
