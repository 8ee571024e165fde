"""A humid scene's sticking against the condensation time t_a, over the range its estimate allows.

Bridges cannot form before t_a, and no measurement fixes t_a for a given pair of surfaces better than the nucleation
estimate's spread (`continuum.model.regime.condensation_time_range`: the attempt frequency of Szoszkiewicz & Riedo,
PRL 95 (2005) 135502, known within 4-250 GHz, a factor 62 in t_a). So a humid scene reports how its outcome moves
with t_a across that range (result.json -> menisci_condensation_time, one line in the command's summary):

- the grid: `GRID_POINTS` log-spaced t_a from the range's shortest to its longest, and the scene's own t_a;
- each point's stick probability (an ensemble: the fraction of members held, at the first impact and within the
  run; a single run: 1 or 0);
- a point is run again only where it can differ: bridges form only in contacts that last t_a, so where no bridge
  formed in the scene's run and every contact of it ended before this t_a, the run at this t_a is the scene's run,
  step for step (the wet law is its dry law before t_a, `continuum.laws.wet.WetRoughRoller`), and it is reused
  (`how` says which). A contact that never ended (the body held, 'stuck' or 'rest') counts with its length so far.
"""
from __future__ import annotations

import logging
import math
from dataclasses import replace
from typing import Any, Callable

import numpy as np

from ..model.regime import condensation_time_range
from ..scene import ResolvedScene

log = logging.getLogger(__name__)

#: t_a values across the estimate's range (log-spaced, ends included), besides the scene's own.
GRID_POINTS = 5


def t_a_grid(scene_t_a: float, lo: float, hi: float, points: int = GRID_POINTS) -> list[float]:
    """`points` log-spaced t_a (s) from lo to hi and the scene's own `scene_t_a`, ascending, without repeats."""
    grid = set(float(x) for x in np.geomspace(lo, hi, points)) | {float(scene_t_a)}
    return sorted(grid)


def with_condensation_time(resolved: ResolvedScene, t_a: float) -> ResolvedScene:
    """`resolved` with a fixed condensation time `t_a` (s)."""
    sc = resolved.scene
    m = replace(sc.menisci, condensation_model="fixed", condensation_time=float(t_a))
    return replace(resolved, scene=replace(sc, menisci=m))


def _ensemble_point(ens: dict) -> dict:
    p = ens["stick_probability"]
    return {"stick_probability_first_impact": p["first_impact"]["value"],
            "interval_first_impact": p["first_impact"]["interval"],
            "stick_probability_within_run": p["within_run"]["value"],
            "interval_within_run": p["within_run"]["interval"], "censored_within_run": p["within_run"]["censored"]}


def _ensemble_contacts(ens: dict) -> tuple[float, bool]:
    """(longest contact of any member (s), whether any member grew a bridge)."""
    wet = [m["menisci"] for m in ens["member_runs"] if m.get("menisci")]
    longest = max((float(m["longest_contact_s"]) for m in wet), default=math.inf)
    return longest, any(m["contacts_with_bridges"] > 0 for m in wet)


def _single_contacts(result: dict) -> tuple[float, bool]:
    """(longest contact of the run (s), whether a bridge formed), the final held contact counted so far."""
    durations = [b["duration"] for b in result["bounces"] if b.get("duration") is not None]
    wet = (result["models"].get("diagnostics") or {}).get("menisci") or {}
    longest = max([*durations, float(wet.get("longest_contact_s", 0.0))], default=0.0)
    if result["status"] in ("stuck", "rest"):
        longest = max(longest, float(wet.get("longest_contact_s", math.inf)))
    return longest, bool(wet.get("contacts_with_bridges", 0))


def condensation_sweep(resolved: ResolvedScene, result: dict, executor=None, workers: int | None = None, *,
                       rerun: Callable[..., Any], regime=None) -> dict:
    """result.json -> menisci_condensation_time for the humid scene `resolved` whose run gave `result`: the scene's
    t_a, the range the estimate allows, and the stick probability at each t_a of the grid (`t_a_grid`). `rerun`
    runs a single (non-ensemble) scene again (`continuum.dynamics.impact.run_impact`, passed in by its caller);
    `regime`: the run's (`continuum.model.regime.Regime`), whose t_a it reads."""
    from .ensemble_run import run_ensemble
    run_impact = rerun

    scene = resolved.scene
    rng = condensation_time_range(scene, regime)
    t_scene = rng["condensation_time_s"]
    ens = result.get("ensemble")
    longest, bridged = _ensemble_contacts(ens) if ens else _single_contacts(result)
    here = _ensemble_point(ens) if ens else {"stick_probability_within_run": float(result["stuck"])}
    rows = []
    for t in t_a_grid(t_scene, *rng["range_s"]):
        if t == t_scene:
            rows.append({"condensation_time_s": t, **here, "how": "the scene's run"})
        elif not bridged and t > longest:
            rows.append({"condensation_time_s": t, **here, "how": f"the scene's run: no bridge formed and every "
                         f"contact ended within {longest:.3g} s < t_a"})
        else:
            log.info("menisci: run again at t_a = %.3g s", t)
            other = with_condensation_time(resolved, t)
            if ens:
                point = _ensemble_point(run_ensemble(other, executor=executor, workers=workers).to_record())
            else:
                rerun_ = run_impact(other, condensation_sweep=False, series=False)     # read for its verdict
                point = {"stick_probability_within_run": float(rerun_.stuck)}
            rows.append({"condensation_time_s": t, **point, "how": "run again at this t_a"})
    values = [r["stick_probability_within_run"] for r in rows]
    lo, hi = rng["range_s"]
    spread = (f"{min(values):.3g}-{max(values):.3g}" if max(values) > min(values)
              else f"{values[0]:.3g} at every t_a (no contact lasts t_a: humidity changes nothing here)")
    summary = (f"menisci: t_a = {t_scene:.3g} s ({rng['source']}); over the estimate's range {lo:.3g}-{hi:.3g} s "
               f"the stick probability within the run is {spread}")
    return {**rng, "grid_points": GRID_POINTS, "longest_contact_s": longest, "bridges_formed": bridged,
            "stick_probability": "fraction of ensemble members held (an ensemble), or 1/0 (a single run)",
            "points": rows, "summary": summary}
