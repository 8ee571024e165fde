"""Escape velocity: the smallest impact speed from which the body still rebounds (paper Fig 8).

Bisection on the impact velocity (in log space) with single-impact runs: below the escape
velocity the body turns back while still attached (stuck), above it it leaves the surface.
"""
from __future__ import annotations

import math
from typing import Callable

from ..laws.base import ContactLaw
from .driver import DriverSettings, ImpactRun, simulate


def single_impact(law: ContactLaw, mass: float, gravity: float, speed: float, rtol: float = 1e-9, *,
                  series: bool = True) -> ImpactRun:
    """One impact at `speed` (m/s) from the datum on virgin surfaces (`ContactLaw.forget_history`); the run
    ends at release or when stuck. `series=False`, for a caller that reads the outcome (stuck, duration, rebound,
    peak force): no samples inside the integrator's steps (the trace holds the step ends and events only) and no
    profiles (`DriverSettings.profiles`); the steps, the events and so the outcome are the same, while the
    samples' law evaluations (a fifth of a Python-stepped contact) and a rough law's snapshots (footprint
    quadratures, a fifth of a wet sweep's CPU) are not made."""
    law.forget_history()
    return simulate(law, mass, gravity, impact_velocity=speed,
                    settings=DriverSettings(rtol=rtol, max_bounces=1, max_time=1.0, samples_per_flight=2,
                                            samples_per_step=DriverSettings.samples_per_step if series else 0,
                                            profiles=series))


def escape_velocity(law: ContactLaw, mass: float, gravity: float, v_low: float, v_high: float, *,
                    rel_tol: float = 1e-3, rtol: float = 1e-9,
                    on_run: Callable[[float, ImpactRun], None] | None = None, ends_known: bool = False) -> dict:
    """Bisect [v_low, v_high] (m/s) for the escape velocity to `rel_tol`.

    Returns dict(escape_velocity, lower, upper, runs) where `lower` sticks and `upper` rebounds;
    raises ValueError if the bracket does not straddle the transition. With `ends_known` the caller has run both
    ends already (they stick and rebound): they are not run again, so a bracket found on runs made in another
    order (a law whose tables were sized by deeper impacts in between) is not contradicted by its own rerun.
    """
    def escapes(v):
        run = single_impact(law, mass, gravity, v, rtol, series=on_run is not None)
        if on_run:
            on_run(v, run)
        return not run.stuck

    runs = 0
    if not ends_known:
        if escapes(v_low):
            raise ValueError(f"escape velocity below the bracket: the body already rebounds at {v_low:.3e} m/s")
        if not escapes(v_high):
            raise ValueError(f"escape velocity above the bracket: the body still sticks at {v_high:.3e} m/s")
        runs = 2
    lo, hi = v_low, v_high
    while hi / lo - 1.0 > rel_tol:
        mid = math.sqrt(lo * hi)
        runs += 1
        if escapes(mid):
            hi = mid
        else:
            lo = mid
    return {"escape_velocity": math.sqrt(lo * hi), "lower": lo, "upper": hi, "runs": runs}
