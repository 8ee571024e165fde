"""Where Fig 8a's t_a claim flips as the condensation time moves, both ways (the wet sweep's t_a study).

The claim (``wet_checks``): with menisci the dry impacts that outlast t_a stick, i.e. the wet escape velocity
reaches v_esc,dry + (1 - BAND_EDGE) (v_ta - v_esc,dry), where v_ta is the band edge (dry duration = t_a). The
wet escape velocity's stick/rebound outcome is monotone in the speed, so at a given t_a the claim holds exactly
when the wet impact at that speed, v*, sticks: one wet run per t_a instead of a bisection, with the band edge
found on the dry law's impact time (compiled runs, cached across t_a).

States per t_a: ``holds``, ``fails``, ``no_subject`` (no dry impact that rebounds lasts t_a: above the
longest dry rebound menisci change nothing; or no band edge), ``refused`` (the band reaches speeds whose
impacts the law refuses to tabulate at its cost bound) or ``band_beyond_scan`` (the band reaches past the
study's scan, a few times the declared t_a's band): not judged there. A geometric grid
of t_a around the declared value is evaluated and every change of state between neighbours is bisected in
ln t_a to T_A_REL_TOL, a reporting resolution far coarser than the runs' accuracy (1e-6 relative in an impact's
duration, ``sampled_claims.RUN_RTOL``).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..model import factory

#: The outermost part of the t_a band (as a fraction of its width) left out of Fig 8a's t_a claim: there dry
#: impacts outlast t_a by a vanishing time, and no finite bridge force captures an impact that ends an instant
#: after its bridges form. A declared choice (the paper states the t_a line without a width).
BAND_EDGE = 0.01
#: Relative resolution of a flip in t_a (the bisection stops when the bracket's ratio is below 1 + this).
T_A_REL_TOL = 1e-2
#: The t_a grid (down to a quarter of the reference): the reference (declared t_a, or the longest dry rebound when
#: that is lower) times
#: T_A_DOWN_FACTORS, T_A_UP_POINTS points between it and the longest dry rebound, and that rebound times
#: T_A_NEAR_LONGEST (the claim can fail just below it, where bridges form an instant before the impacts end).
T_A_DOWN_FACTORS = tuple(2.0 ** (-k / 2) for k in range(0, 5))
T_A_UP_POINTS = 2
T_A_NEAR_LONGEST = (0.9, 1.0 - T_A_REL_TOL, 1.0, 1.0 + T_A_REL_TOL)
HOLDS, FAILS, NO_SUBJECT, REFUSED, BEYOND_SCAN = "holds", "fails", "no_subject", "refused", "band_beyond_scan"


def at_condensation_time(wet, t_a: float, rebuild: Callable[[float], object]):
    """The wet law `wet` with its condensation time set to `t_a`: a copy sharing the dry law's tables where it is
    the averaged wet roller, else `rebuild(t_a)` (the law selected again from the scene)."""
    law = factory.wet_roller_with_condensation_time(wet, t_a)
    return rebuild(t_a) if law is None else law


def t_a_flips(state_at: Callable[[float], tuple[str, dict]], t_a: float, upper: float | None) -> dict:
    """The t_a study of the claim: `state_at(t)` -> (state, details) at condensation time t; `t_a` the declared
    value; `upper` the longest dry impact that rebounds (None: none rebounds). Returns {'scan': [[t, state], ...],
    'flips': [{'t_a_s', 'from', 'to', 'bracket_s'}, ...] (ascending t_a), 'lower_flip_s' and 'upper_flip_s' (the
    nearest flips below and above the declared t_a), 'holds_in_s': [lo, hi] (the range around the declared t_a in
    which it holds, None where it does not hold there; an end None where the scan never left the holding state that
    way), 'holds_anywhere_s': every such range in the scan, 'state_at_t_a', 'rel_tol', 'grid_s'}."""
    ref = min(t_a, upper) if upper else t_a
    grid = {ref * f for f in T_A_DOWN_FACTORS} | {t_a}
    if upper:
        grid |= {upper * f for f in T_A_NEAR_LONGEST}
        if upper > ref * (1 + T_A_REL_TOL):
            grid |= set(np.geomspace(ref, upper, T_A_UP_POINTS + 2)[1:-1])
    memo: dict[float, str] = {}

    def state(t: float) -> str:
        if t not in memo:
            memo[t] = state_at(t)[0]
        return memo[t]

    ts = sorted(grid)
    states = [state(t) for t in ts]
    flips = []
    for (a, sa), (b, sb) in zip(zip(ts, states), zip(ts[1:], states[1:])):
        while sa != sb:                 # a third state between two grid points: each change bisected in turn
            lo, hi = a, b
            while hi / lo - 1.0 > T_A_REL_TOL:
                mid = math.sqrt(lo * hi)
                if state(mid) == sa:
                    lo = mid
                else:
                    hi = mid
            flips.append({"t_a_s": math.sqrt(lo * hi), "from": sa, "to": state(hi), "bracket_s": [lo, hi]})
            a, sa = hi, state(hi)
    here = state(t_a)
    below = [f for f in flips if f["t_a_s"] < t_a]
    above = [f for f in flips if f["t_a_s"] > t_a]
    holds_in = None
    if here == HOLDS:
        holds_in = [below[-1]["t_a_s"] if below else None, above[0]["t_a_s"] if above else None]
    edges = [None] + [f["t_a_s"] for f in flips] + [None]
    runs = [states[0]] + [f["to"] for f in flips]
    holds_anywhere = [[edges[i], edges[i + 1]] for i, st in enumerate(runs) if st == HOLDS]
    return {"scan": [[t, memo[t]] for t in sorted(memo)], "flips": flips, "holds_anywhere_s": holds_anywhere,
            "lower_flip_s": below[-1]["t_a_s"] if below else None,
            "upper_flip_s": above[0]["t_a_s"] if above else None,
            "holds_in_s": holds_in, "state_at_t_a": here, "rel_tol": T_A_REL_TOL,
            "grid_s": [ts[0], ts[-1]]}
