"""The speeds the paper's sweeps run at and the band-edge search on an impact time: shared by the nominal sweeps
(`run`) and the single-surface runs of each discrete seed (`seed_runs`), which must ask the same questions."""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..dynamics.escape import single_impact

#: Fig 8a velocity sweep: impact speeds as multiples of the 100 nm drop speed.
FIG8_SPEED_FACTORS = tuple(np.geomspace(0.05, 20.0, 10))
#: Relative bracket of the dry and the wet escape velocity in the wet sweep: the runs' own accuracy (an impact's
#: duration and rebound to ~1e-6 relative, `sampled_claims.RUN_RTOL`), never finer; far below the band of speeds
#: where dry impacts outlast t_a (0.02 to 11 of v_esc wide in the shipped sets), so the band is resolved.
WET_DRY_REL_TOL = 1e-6
WET_REL_TOL = 1e-6
#: Wet sweeps: impact speeds just above the dry escape velocity, v = v_esc (1 + eps), where the impact time grows
#: and may outlast t_a; from the escape bracket's own width up (closer speeds cannot be told from it).
WET_EPS = tuple(np.geomspace(WET_DRY_REL_TOL, 2.0, 10))
#: Largest v / v_esc - 1 the t_a band's scan is extended to when every scanned impact outlasts t_a (for a set
#: whose escape velocity is tens of um/s, impacts at several times it still last longer than t_a = 25 us).
MAX_BAND_EPS = 1e3
#: The t_a study scans bands up to this many times the declared t_a's band (`_t_a_study`), and bisects each band
#: edge to this width in ln eps: v_ta to ~1e-4 of the band, against the claim's 1 % band edge.
STUDY_BAND_FACTOR = 4.0
STUDY_LN_WIDTH = 1e-4
#: Speeds sampled inside the band where dry impacts outlast t_a.
BAND_POINTS = 6


def fastest_first(speeds):
    """Sweep speeds in the order they run: the fastest first. The rigid rough law sizes its footprint tables
    for the deepest impact it has seen and keeps them for impacts down to 1/20 of that depth
    (`RigidRoughRoller.prepare`), so a descending sweep builds them once (~1 s) instead of at every speed of
    an ascending one; the points move by the tables' and the integration's tolerance (< 1e-7 relative,
    docs/benchmarks.md). The results are reported in ascending order."""
    return sorted(speeds, reverse=True)



def t_a_band_edge(duration: Callable[[float], float], t_a: float, scan: tuple, eps_floor: float,
                  ln_width: float = 2e-8, max_eps: float = MAX_BAND_EPS) -> dict:
    """Where the dry impact time falls through t_a above the escape velocity: eps of v = v_esc (1 + eps).

    `duration(eps)` is the dry impact time (inf where it sticks), known to be >= t_a at eps = 0. The scan speeds
    (eps values `scan`, extended by factors of 4 up to `max_eps` while every impact outlasts t_a) bracket the
    crossing first; only a scan whose impacts outlast t_a up to one point and no further (one crossing, from long
    to short) is bisected, in ln eps, to `ln_width` (below the scan's first point the bracket's lower end is
    `eps_floor`, the escape velocity's own relative bracket). A scan that crosses t_a more than once (the impact
    time is not monotone in the speed there), that starts short and turns long, or that outlasts t_a up to
    `max_eps` gives no edge: {'eps': None, 'reason': ...}. Returns {'eps', 'rel_tol' (the bracket's width in
    eps plus eps_floor), 'scan': [[eps, outlasts], ...]}."""
    grid = sorted(scan)
    long = [duration(e) >= t_a for e in grid]
    while all(long) and grid[-1] < max_eps:               # the band reaches past the scan: extend it upwards
        grid.append(4.0 * grid[-1])
        long.append(duration(grid[-1]) >= t_a)
    record = [[e, bool(x)] for e, x in zip(grid, long)]
    crossings = sum(a != b for a, b in zip(long, long[1:]))
    if crossings > 1 or (crossings == 1 and not long[0]):
        where = ", ".join(f"{e:.3g}" for (e, a), (_, b) in zip(record, record[1:]) if a != b)
        return {"eps": None, "scan": record,
                "reason": f"the dry impact time crosses t_a {crossings} times in the scan (near eps = {where}): "
                          "not monotone in the speed, so no single band edge"}
    if all(long):
        return {"eps": None, "scan": record,
                "reason": f"dry impacts outlast t_a up to the scan's fastest speed, v_esc (1 + {grid[-1]:.3g})"}
    n_long = sum(long)
    lo = math.log(grid[n_long - 1]) if n_long else math.log(eps_floor)        # long at lo, short at hi
    hi = math.log(grid[n_long])
    while hi - lo > ln_width:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if duration(math.exp(mid)) >= t_a else (lo, mid)
    return {"eps": math.exp(lo), "rel_tol": math.exp(hi) - math.exp(lo) + eps_floor, "scan": record}


def outcome(law, mass, g, v, rtol) -> dict:
    """One impact at `v` on virgin surfaces: stuck, duration, rebound speed and restitution (read for its outcome
    only: no in-step samples, no profiles, `single_impact(series=False)`)."""
    run = single_impact(law, mass, g, v, rtol, series=False)
    b = run.bounces[0]
    return {"stuck": run.stuck, "duration": b.duration, "v_rebound": b.v_rebound, "restitution": b.restitution}
