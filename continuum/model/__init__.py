"""Which models a scene needs, the law that runs them, and why (result.json -> models).

"Model only what a scene requires." Every physics entry (`physics.adhesion_law`, `physics.half_space`,
`physics.menisci`, `physics.plasticity`) defaults to `auto`, decided per scene from numbers recorded beside
the choice; a scene can force any choice. The package works in four steps, one module each:

``regime``     the numbers that place the scene, computed once (`Regime`, `regime_of`): summit modulus,
               Tabor and Fuller-Tabor parameters, plasticity index, the first impact's estimate, and the
               menisci's parameters;
``decisions``  typed decisions (`AdhesionDecision`, `HalfSpaceDecision`, `MenisciDecision`,
               `PlasticityDecision` (a smooth sphere's Thornton-Ning law), and the
               `DryRunVerdict` that settles a pending meniscus decision), frozen, each with the numbers that
               decided it and its own record; the criteria are in its docstring;
``factory``    builds the law the decisions call for: the only module outside `continuum.laws` that
               imports a concrete law (`tests/test_architecture.py`);
``record``     what result.json's `models` says about the law, the estimate and the SAM;

and ``select`` runs them: `select_law` (the whole scene) and `rough_law` (the rough roller alone).
"""
from __future__ import annotations

from .decisions import (
                        LAW_NAMES,
                        NEGLIGIBLE_DEFLECTION,
                        NEGLIGIBLE_LOSS,
                        NEGLIGIBLE_PULL,
                        TABOR_DMT,
                        TABOR_JKR,
                        AdhesionDecision,
                        DryRunVerdict,
                        HalfSpaceDecision,
                        MenisciDecision,
                        PlasticityDecision,
                        adhesion_decision,
                        dry_run_verdict,
                        half_space_decision,
                        loop_per_summit,
                        menisci_decision,
                        plasticity_decision,
                        summit_law,
)
from .regime import Regime, coated_summits, meniscus_parameters, regime_of, summit_e_star
from .select import FAST_TABLE_MIN_SIGMA_OVER_DELTA_C, LARGE_TABLE_SECONDS, rough_law, select_law

__all__ = [
    "AdhesionDecision", "DryRunVerdict", "HalfSpaceDecision", "MenisciDecision", "PlasticityDecision", "Regime",
    "adhesion_decision", "dry_run_verdict", "half_space_decision", "menisci_decision", "plasticity_decision",
    "regime_of",
    "meniscus_parameters", "coated_summits", "summit_e_star", "summit_law", "loop_per_summit",
    "rough_law", "select_law",
    "FAST_TABLE_MIN_SIGMA_OVER_DELTA_C", "LARGE_TABLE_SECONDS", "LAW_NAMES", "NEGLIGIBLE_DEFLECTION",
    "NEGLIGIBLE_LOSS", "NEGLIGIBLE_PULL", "TABOR_DMT", "TABOR_JKR",
]
