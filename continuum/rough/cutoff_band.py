"""The cutoff band and the tail models of a measured map: what result.json records, warns and summarises.

Summit radius and density of a height map depend on the shortest wavelength kept (the summit cutoff): a factor 4
in the cutoff moves beta about 6x on a NanoScope scan (docs/model.md, "Summit statistics of a map"), and the
scan does not fix the cutoff. A run on a measured map therefore also evaluates its ensemble at half and twice the
cutoff it used (BAND_FACTORS) and reports the band (result.json -> surface.cutoff_band): each cutoff's beta, eta,
sigma_s, stick probability at the first impact (Wilson 95 %) and first-rebound median. Likewise the ensemble is
run under both tail models of `continuum.rough.tail` (result.json -> ensemble.tail_models). Where the band, or the
tail models, put the first impact on both sides of sticking, a warning names the scene: the outcome then rests on
an input the data cannot fix. Pure functions of the records; the runs are `continuum.dynamics.map_ensembles`'.
"""
from __future__ import annotations

from typing import Mapping, Sequence

__all__ = ["BAND_FACTORS", "band_entry", "band_crosses", "band_warning", "tail_warning", "band_summary",
           "tails_summary"]

#: Cutoffs evaluated, as multiples of the one the run used.
BAND_FACTORS = (0.5, 1.0, 2.0)
#: A stick probability at or above this is "sticking" for the crossing warnings (the majority outcome).
STICKING = 0.5


def band_entry(factor: float, cutoff: float, statistics: Mapping[str, float], summary: Mapping | None,
               why_not: str | None = None) -> dict:
    """One cutoff of the band: the cutoff (m, and its factor), the map's beta, eta and sigma_s there, and the
    first-impact summary of its ensemble (`continuum.rough.ensemble.first_impact_summary`), or why it was not
    evaluated (the map holds too few summits, or the cutoff is under its pixel limit)."""
    entry: dict = {"factor": factor, "cutoff": cutoff, **dict(statistics)}
    if summary is None:
        return {**entry, "evaluated": False, "why": why_not}
    p = summary["stick_probability_first_impact"]
    first = summary.get("first_rebound_over_h0") or summary["first_rebound_m"]
    return {**entry, "evaluated": True, "members": summary["members"],
            "stick_probability": {k: p[k] for k in ("count", "members", "value", "interval", "censored")},
            "first_rebound_median": first["p50"],
            "first_rebound_unit": "h0" if "first_rebound_over_h0" in summary else "m"}


def _sticks(p: Mapping) -> bool:
    return p["value"] >= STICKING


def band_crosses(band: Sequence[Mapping]) -> bool:
    """True where the evaluated cutoffs' first impacts lie on both sides of sticking (stick probability >= 1/2 at
    one cutoff, < 1/2 at another)."""
    sides = {_sticks(e["stick_probability"]) for e in band if e.get("evaluated")}
    return len(sides) == 2


def band_warning(scene: str, band: Sequence[Mapping]) -> str | None:
    """The warning of a band that crosses from sticking to rebounding, naming the scene; None otherwise."""
    if not band_crosses(band):
        return None
    parts = "; ".join(f"{e['cutoff']:.3g} m: {e['stick_probability']['value']:.2f}" for e in band if e.get("evaluated"))
    return (f"scene {scene}: over the summit-cutoff band the first impact goes from sticking to rebounding "
            f"(stick probability {parts}): the outcome rests on the cutoff, which the scan does not fix "
            "(result.json -> surface.cutoff_band)")


def tail_warning(scene: str, tails: Mapping[str, Mapping]) -> str | None:
    """The warning where the two tail models' first-impact stick probabilities have disjoint Wilson intervals or
    lie on both sides of sticking, naming the scene; None otherwise."""
    ps = {k: v["stick_probability_first_impact"] for k, v in tails.items() if "stick_probability_first_impact" in v}
    if len(ps) < 2:
        return None
    (a, pa), (b, pb) = list(ps.items())[:2]
    disjoint = pa["interval"][1] < pb["interval"][0] or pb["interval"][1] < pa["interval"][0]
    if not disjoint and _sticks(pa) == _sticks(pb):
        return None
    return (f"scene {scene}: the first-impact stick probability depends on the assumed summit-height tail ({a} "
            f"{pa['value']:.2f} [{pa['interval'][0]:.2f}-{pa['interval'][1]:.2f}], {b} {pb['value']:.2f} "
            f"[{pb['interval'][0]:.2f}-{pb['interval'][1]:.2f}]): the map does not reach the tail the impact "
            "samples (result.json -> ensemble.tail_models)")


def band_summary(band: Sequence[Mapping]) -> str:
    """One line per cutoff for the command line."""
    lines = []
    for e in band:
        head = f"  cutoff {e['cutoff']:.3g} m (x{e['factor']:g})"
        if e.get("summit_radius") is not None:
            head += f": beta {e['summit_radius']:.3g} m, eta {e['summit_density']:.3g} /m^2"
        if not e.get("evaluated"):
            lines.append(f"{head}: not evaluated ({e['why']})")
            continue
        p = e["stick_probability"]
        stick = (f"{p['count']}/{p['members']} ({p['interval'][0]:.3f}-{p['interval'][1]:.3f})"
                 if p.get("interval") else ("stuck" if p["count"] else "rebounds") + " (mean field)")
        lines.append(f"{head}: stick at 1st impact {stick}, first rebound median {e['first_rebound_median']:.3g} "
                     f"{e['first_rebound_unit']}")
    return "\n".join(lines)


def tails_summary(tails: Mapping[str, Mapping]) -> str:
    """One line per tail model for the command line."""
    lines = []
    for name, t in tails.items():
        if "stick_probability_first_impact" not in t:
            lines.append(f"  tail {name}: not run ({t.get('why', '')})")
            continue
        p = t["stick_probability_first_impact"]
        first = t.get("first_rebound_over_h0") or t["first_rebound_m"]
        lines.append(f"  tail {name}: stick at 1st impact {p['count']}/{p['members']} ({p['interval'][0]:.3f}-"
                     f"{p['interval'][1]:.3f}), first rebound median {first['p50']:.3g}")
    return "\n".join(lines)
