"""Whose threshold each reproduction claim applies: the paper's (its sentence and section) or the project's (why).

checks.json carries the entry as `threshold_source`. The paper: M. Teodorescu and H. Rahnejat, Proc. IMechE Part N
221 (2007) 49-58 (docs/paper-notes.md); sections numbered as there (5 = Results and discussion).
"""
from __future__ import annotations


def _paper(section: str, quote: str, *project: str) -> dict:
    out = {"source": "paper", "section": section, "quote": quote}
    if project:
        out["project_choices"] = list(project)
    return out


def _project(reason: str, quote: str | None = None, section: str | None = None) -> dict:
    out = {"source": "project", "reason": reason}
    if quote:
        out.update(paper_says=quote, section=section)
    return out


STICK = ("'sticks' = no rebound above 1e-3 h0: the paper gives no height; 1e-3 h0 is below every rebound its "
         "figures show")
MEAN_FIELD = ("'average asperity height' read as the summits' sigma of the GW model (docs/paper-notes.md)")

THRESHOLD_SOURCES = {
    "fig4_ots_loop_smaller_than_silica": _paper(
        "5, Fig. 4", "Fig. 4(b), showing the same characteristics for SAM (based on OTS), indicates significantly "
        "lower differences"),
    "fig5a_ots_outbounces_silica": _paper(
        "5, Fig. 5(a)", "the impact behaviour of the OTS monolayer on the silicon substrate closely follows the "
        "Hertzian model ... with a very gradual loss of rebound potential energy", STICK),
    "fig5a_silica_impacts_weaken_until_it_sticks": _paper(
        "5, Figs 5(a), 5(b)", "the rebound height progressively reduces with successive impacts ... the impact time "
        "lengthens with progressive impacts with decreasing W ... Eventually, an insufficient energy exists for the "
        "roller to leave the surface", STICK, "'within 20 impacts': the paper's Fig. 5(a) shows a handful of "
        "bounces; 20 bounds the run, not a number the paper gives"),
    "fig7_sigma3_sticks_at_first_impact": _paper(
        "5, Fig. 7", "for the case of silicon, the asperity height of 3 nm Ra shows no rebound", STICK, MEAN_FIELD),
    "fig7_rebounds_rise_with_sigma": _paper(
        "5, Fig. 7", "Shorter asperities of the same material act stiffer in extension (produce a greater adhesion "
        "force), thus both the number of bounces and the rebound heights are reduced", MEAN_FIELD),
    "fig8a_rough_impact_time_rises_as_velocity_falls": _paper(
        "5, Fig. 8(a)", "With higher average asperity heights, the rebound velocity decreases with increasing impact "
        "time"),
    "fig8a_escape_velocity_falls_as_sigma_rises": _paper(
        "5, Fig. 8(a)", "A surface with a shorter average asperity height exhibits stiction at a higher rebound "
        "velocity (i.e. demands a higher escape velocity)", MEAN_FIELD),
    "fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a": _paper(
        "5, Fig. 8(a)", "until the latter becomes long enough for meniscus action ... This limiting impact time "
        "(25 us) is shown by the horizontal dotted line in the figure. Thereupon, increased resistance due to "
        "adhesion and meniscus action prohibits any further rebounds",
        "the band's outer 1 % left out (wet_flips.BAND_EDGE): the paper draws the t_a line without a width",
        "40 % RH: the paper gives no humidity (inputs/scenes/wet_silica.toml)"),
    "fig8b_ots_lower_escape_velocity": _paper(
        "5, Fig. 8(b)", "the exposed surface would stick at the limit of adhesion governed here by meniscus action "
        "in a larger gap than that with a monolayer", "compared dry (escape velocities), where the paper's larger "
        "gap of bare silica is set by its menisci: menisci only raise silica's escape velocity"),
    "fig8b_ots_impact_shorter_at_the_same_low_velocity": _paper(
        "5, Fig. 8(b)", "the exposed silicon surface shows progressively longer impact times with reduced impact "
        "momentum compared to that with a layer of OTS", "'low velocity' = 1.2 x bare silica's escape velocity: "
        "the paper names no speed; 1.2 keeps silica rebounding on every set"),
}


def threshold_source(name: str) -> dict:
    """The claim's `threshold_source`; a claim without one says so (a test requires one for every claim)."""
    return THRESHOLD_SOURCES.get(name, _project("no source recorded for this claim"))
