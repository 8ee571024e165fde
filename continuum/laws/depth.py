"""How deep an impact can press a rough roller: sizes grids and tables before each contact."""
from __future__ import annotations

from typing import Callable

import numpy as np

#: The averaged model's range: deeper than this many sigma below the mean plane every summit is in
#: contact (the GW tables switch to slow exact quadrature there) and the contact is flat, not rough.
DEPTH_LIMIT_SIGMAS = 10.0


def absorbing_depth(forces: Callable[[np.ndarray], np.ndarray], energy: float, *, first_step: float,
                    max_depth: float, weight: float = 0.0, what: str = "rough contact") -> float:
    """Depth (m below the datum) at which the approach branch has absorbed `energy` (J).

    `forces(depths)` gives the upward force (N) of a monotonic first approach to each depth (an
    array). The work is summed by the trapezoidal rule in batches of 64 points, the step doubling
    after each batch, until it exceeds `energy` against `weight` (N) with a repulsive force.
    Beyond `max_depth` the scene is refused with a ValueError naming the limit.
    """
    step, depth, work = first_step, 0.0, 0.0
    last = float(forces(np.array([0.0]))[0]) - weight
    while depth <= max_depth:
        depths = depth + step * np.arange(1, 65)
        f = np.asarray(forces(depths), float) - weight
        for k in range(depths.size):
            work += 0.5 * (f[k] + last) * step
            last = f[k]
            if work >= energy and f[k] > 0.0:
                return float(depths[k])
        depth = float(depths[-1])
        step *= 2.0
    raise ValueError(f"{what} refused: the impact would press the roller deeper than {max_depth * 1e9:.3g} nm "
                     f"below the tallest summit, more than {DEPTH_LIMIT_SIGMAS:g} sigma below the summits' mean plane: "
                     "every summit in the footprint would be in contact and the surface acts as a flat adhesive "
                     "contact, outside the rough model's range; use contact = 'smooth' or a larger sigma")
