"""The old name of `continuum.model` (regime, decisions, factory, record): its public names, re-exported.

New code imports from `continuum.model`; this module stays so that `from continuum.models import
select_law` (the impact runner, the paper runner, calibration, benchmarks, tests) keeps working.
"""
from __future__ import annotations

from .model import (FAST_TABLE_MIN_SIGMA_OVER_DELTA_C, LARGE_TABLE_SECONDS, LAW_NAMES, NEGLIGIBLE_DEFLECTION,
                    NEGLIGIBLE_LOSS, NEGLIGIBLE_PULL, TABOR_DMT, TABOR_JKR, decide_adhesion, decide_half_space,
                    decide_menisci, loop_per_summit, meniscus_parameters, rough_law, sam_layer, select_law,
                    summit_e_star, summit_law)

__all__ = ["FAST_TABLE_MIN_SIGMA_OVER_DELTA_C", "LARGE_TABLE_SECONDS", "LAW_NAMES", "NEGLIGIBLE_DEFLECTION",
           "NEGLIGIBLE_LOSS", "NEGLIGIBLE_PULL", "TABOR_DMT", "TABOR_JKR", "decide_adhesion", "decide_half_space",
           "decide_menisci", "loop_per_summit", "meniscus_parameters", "rough_law", "sam_layer", "select_law",
           "summit_e_star", "summit_law"]
