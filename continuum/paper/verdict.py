"""How a claim is judged: two kinds, three states, a margin against its numerical tolerance.

Kinds. *Verification*: the code solves its own equations (Hertz limits, closed forms, what holds by
construction). *Reproduction*: the paper's physical conclusions (SAM against bare silica, trends in
sigma, wet against dry, impact time against velocity), which a parameter set can fail.

States. ``pass``: the claim holds by more than its numerical tolerance. ``fail``: it is violated
by more than that tolerance. ``not_evaluable``: the margin lies inside the tolerance (the numerics
cannot tell), or the quantity the claim needs was not found (the entry gives the reason).

Margin. A signed number in the claim's own units (or relative, as the entry says): positive when
the claim holds. Tolerance: the numerical uncertainty of that margin (bisection bracket, integrator
and table tolerances), never a physical threshold.

One rule, decided before any result: every reproduction claim is judged on the model the paper
defines, the averaged (Greenwood-Williamson mean-field) surface of its eqs 10-11. A set without
uncertainty rows (`paper`, `silicon`) is judged on its nominal runs; a set with them (a calibrated
set's Latin hypercube) on the nominal run and each row, each an averaged-law sample:
``holds_fraction`` is the fraction of the decided ones on which it holds, and the claim passes when
the nominal run holds and that fraction is at least ``HOLDS_FRACTION``. Single discrete-summit
realisations are the project's extension beyond the paper: each claim reports them beside its
verdict (``single_surfaces``: the fraction that holds, its Wilson interval, the mechanism where it
departs), never as a reason it passes or fails.

Each reproduction entry records whose threshold it applies (``threshold_source``, ``sources``).
"""
from __future__ import annotations

import math

from ..output.proportions import wilson_interval
from .sources import threshold_source

PASS, FAIL, NOT_EVALUABLE = "pass", "fail", "not_evaluable"
VERIFICATION, REPRODUCTION = "verification", "reproduction"
#: A reproduction claim passes when it holds on at least this fraction of its decided samples.
HOLDS_FRACTION = 0.9
#: At most this fraction of the samples may be undecided (margin inside tolerance) for a verdict.
UNDECIDED_FRACTION = 0.1


def judge(margin: float | None, tolerance: float) -> str:
    """pass when margin > tolerance, fail when margin < -tolerance, else not_evaluable (also for None/NaN)."""
    if margin is None or math.isnan(margin):
        return NOT_EVALUABLE
    if margin > tolerance:
        return PASS
    if margin < -tolerance:
        return FAIL
    return NOT_EVALUABLE


def entry(name: str, set_name: str, kind: str, values: dict, threshold: str, margin, tolerance: float,
          units: str, reason: str | None = None, state: str | None = None) -> dict:
    """One checks.json entry. `state` defaults to judge(margin, tolerance); `reason` says why a claim is
    not evaluable (or what decided a fail that has no margin). `pass` mirrors state == 'pass' for readers that
    only want a yes."""
    state = state or judge(margin, tolerance)
    if state == NOT_EVALUABLE and reason is None:
        reason = (f"margin {margin:.3g} lies inside the numerical tolerance {tolerance:.3g}"
                  if margin is not None and math.isfinite(margin) else "the quantity was not found")
    out = {"name": name, "set": set_name, "kind": kind, "state": state, "pass": state == PASS,
           "margin": _finite_or_none(margin), "tolerance": tolerance, "units": units, "threshold": threshold,
           "values": values}
    if kind == REPRODUCTION:
        out["threshold_source"] = threshold_source(name)
    if reason is not None:
        out["reason"] = reason
    return out


def not_evaluable(name: str, set_name: str, kind: str, threshold: str, units: str, reason: str,
                  values: dict | None = None, tolerance: float = 0.0) -> dict:
    return entry(name, set_name, kind, values or {}, threshold, None, tolerance, units, reason, NOT_EVALUABLE)


def _finite_or_none(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else (None if math.isnan(x) else x)


def over_samples(nominal: dict, sample_states: list[str], sources: dict, bands: dict | None = None) -> dict:
    """A reproduction entry judged over its samples on the paper's model: the nominal run plus `sample_states` (one
    state per uncertainty row, each on the averaged law). `sources` says what was sampled ({'uncertainty': n, ...});
    without rows the verdict is the nominal run's."""
    states = [nominal["state"]] + list(sample_states)
    held = states.count(PASS)
    decided = held + states.count(FAIL)
    undecided = len(states) - decided
    fraction = held / decided if decided else None
    out = dict(nominal, holds_fraction=fraction, samples=len(states), samples_undecided=undecided,
               sampled=sources, nominal_state=nominal["state"])
    if bands:
        out["bands"] = bands
    if nominal["state"] != PASS:            # the set's own model decides first; the samples test robustness
        out["state"] = nominal["state"]
    elif undecided > UNDECIDED_FRACTION * len(states):
        out["state"] = NOT_EVALUABLE
        out["reason"] = f"{undecided} of {len(states)} samples undecided (margin inside tolerance or not found)"
    else:
        out["state"] = PASS if fraction is not None and fraction >= HOLDS_FRACTION else FAIL
        if out["state"] == FAIL and nominal["state"] == PASS:
            out["reason"] = f"holds on {held} of {decided} decided samples (< {HOLDS_FRACTION:g})"
    out["pass"] = out["state"] == PASS
    return out


def band(values) -> dict | None:
    """min, median, max and count of the finite values (a threshold shape reported as its spread)."""
    v = sorted(float(x) for x in values if x is not None and math.isfinite(float(x)))
    if not v:
        return None
    mid = v[len(v) // 2] if len(v) % 2 else 0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2])
    return {"min": v[0], "median": mid, "max": v[-1], "n": len(v)}


def proportion(flags) -> dict | None:
    """How often an outcome occurred over samples: k of n, the fraction, and its Wilson score 95 % interval
    (Wilson, J. Am. Stat. Assoc. 22 (1927) 209), which stays inside [0, 1] for a handful of samples."""
    f = [bool(x) for x in flags]
    n, k = len(f), sum(f)
    if n == 0:
        return None
    return {"fraction": k / n, "k": k, "n": n, "wilson95": list(wilson_interval(k, n))}


def single_text(c: dict) -> str:
    """The single-surfaces cell: holds on k of the decided surfaces (Wilson 95 %), and how many are undecided (with
    the interval of that fraction), or why none were judged."""
    ss = c.get("single_surfaces") or {}
    if not ss.get("n"):
        return "-"
    parts = []
    if ss.get("decided"):
        lo, hi = ss["wilson95"]
        parts.append(f"{ss['holds']} of {ss['decided']} ({lo:.2f}-{hi:.2f})")
    und = ss.get("undecided")
    if und:
        lo, hi = und["wilson95"]
        parts.append(f"undecided on {und['k']} of {und['n']} ({lo:.2f}-{hi:.2f})")
    return "; ".join(parts)
