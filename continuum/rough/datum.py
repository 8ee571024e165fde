"""The datum of a rough surface: the tallest summit expected in the roller's nominal footprint.

With a Gaussian of summit heights a finite footprint holds a finite tallest summit, and with
sigma = 30 nm summits taller than 100 nm exist in a mm-long footprint (paper notes). We truncate
the distribution at the tallest summit expected in the footprint and measure release heights from
it, so "first touch" and "last release" are real events.

Nominal footprint (our definition): the strip |x| <= x_f along the whole roller length l where the
rigid roller, touching the tallest summit, lies within the band of summit heights down to 3 sigma
below the mean plane: x_f^2/(2R) = (z_max + 3) sigma. It holds N = 2 x_f l n summits, and z_max is
their characteristic largest value Phi^-1(1 - 1/N) (Gumbel, Statistics of Extremes, 1958). The two
depend on each other only logarithmically; a fixed-point iteration converges in a few steps.
"""
from __future__ import annotations

import math

from .summits import expected_max_height

#: Depth of the summit band below the mean plane that defines the nominal footprint (units of sigma).
FOOTPRINT_BAND = 3.0


def tallest_summit(sigma: float, summit_density: float, radius: float, length: float) -> dict:
    """z_max (units of sigma), footprint half-width (m) and expected summits in the footprint."""
    z = 4.0
    for _ in range(100):
        half = math.sqrt(2.0 * radius * (z + FOOTPRINT_BAND) * sigma)
        n_summits = 2.0 * half * length * summit_density
        if n_summits < 2.0:
            raise ValueError(f"rough contact: only {n_summits:.2g} summits expected in the footprint "
                             f"(summit_density {summit_density:.3g} /m^2 is too low for this roller)")
        z_new = float(expected_max_height(n_summits))
        if abs(z_new - z) < 1e-12:
            break
        z = z_new
    return {"z_max": z, "footprint_half_width": half, "summits_in_footprint": n_summits,
            "definition": f"tallest of N summits in |x| <= x_f, x_f^2/2R = (z_max + {FOOTPRINT_BAND:g}) sigma"}
