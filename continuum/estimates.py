"""Before a rough impact runs: how deep it presses, how many summits it touches, how far the
half-space under it deflects. `continuum.models` uses these numbers to decide which models a
scene needs (`auto`), and records them.

The estimate is the quasi-static first approach of the roller onto non-adhesive (Hertz) summits
on a rigid substrate, pressed until it has absorbed the impact's kinetic energy against its
weight (the same estimate that sizes the tables and grids, `continuum.laws.depth`). From the
pressure profile at that depth, the plane-strain half-space (FFT influence coefficients,
`continuum.halfspace.LineHalfSpace`, referenced at x_ref = l) gives the deflection across the
footprint; its span (largest minus smallest over the loaded cells) is what changes the summits'
gaps relative to the rigid geometry. Cost: ~10-50 ms.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from .halfspace import LineHalfSpace


@dataclass(frozen=True)
class RoughImpactEstimate:
    """Quasi-static estimate of one rough impact (SI)."""

    impact_energy: float
    """Kinetic energy at touch, 1/2 M v^2 (J)."""
    depth: float
    """Approach below the tallest summit at which the Hertz approach branch absorbs it (m)."""
    contacts: float
    """Summits in contact at that depth."""
    peak_force: float
    """Force at that depth (N)."""
    footprint_half_width: float
    """Half-width of the loaded strip (m)."""
    deflection_span: float
    """Largest minus smallest half-space deflection over the loaded strip (m)."""
    seconds: float
    """Wall time of the estimate (s)."""

    def to_json(self) -> dict:
        return asdict(self)


def rough_impact_estimate(stats, summit_e_star: float, e_star: float, radius: float, length: float,
                          z_max_sigma: float, mass: float, speed: float, gravity: float,
                          samples: int = 513) -> RoughImpactEstimate:
    """Estimate a rough roller impact (see the module docstring).

    stats: SummitStatistics (sigma m, density 1/m^2, summit radius m); summit_e_star and e_star (Pa):
    the summits' and the bodies' contact moduli; radius, length (m) of the roller; z_max_sigma: the
    truncation (tallest summit, units of sigma); mass (kg), speed (m/s) at touch, gravity (m/s^2).
    """
    from .laws.rough_rigid import RigidRoughRoller
    from .rough.gw import GWJKRSurface

    start = time.perf_counter()
    surface = GWJKRSurface(stats, 0.0, summit_e_star, z_max=z_max_sigma, resolution="fast")
    law = RigidRoughRoller(surface, radius, length, resolution="fast")
    energy = 0.5 * mass * speed * speed
    depth = law.quasi_static_depth(energy, mass * gravity)
    half = math.sqrt(2.0 * radius * depth)
    x = np.linspace(-half, half, samples)
    d = surface.z_max - depth + x * x / (2.0 * radius)
    zeta = np.full_like(d, np.inf)
    p = surface.pressure(d, zeta)
    force = float(length * np.trapezoid(p, x))
    contacts = float(length * np.trapezoid(surface.contacts(d, zeta), x))
    dx = x[1] - x[0]
    hs = LineHalfSpace(dx, samples, e_star, x_ref=length)
    u = hs.displacement(p)
    loaded = p > 0.0
    span = float(np.max(u[loaded]) - np.min(u[loaded])) if np.count_nonzero(loaded) > 1 else 0.0
    return RoughImpactEstimate(energy, depth, contacts, force, half, span, time.perf_counter() - start)
