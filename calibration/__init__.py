"""nanoimpact calibration layer: MD results -> continuum parameters, pipelines and the command line.

From Python: ``calibration.calibrate(recipe, out, md_fidelity="quick", ...)`` runs the pipeline and returns a
typed :class:`CalibrationReport` (imported lazily: importing the package costs nothing).
"""
from __future__ import annotations

__all__ = ["calibrate", "CalibrationReport", "ValueRow", "run_sweep"]

_LAZY = {"calibrate": "calibration.pipeline", "CalibrationReport": "calibration.report",
         "ValueRow": "calibration.report", "run_sweep": "calibration.sweep"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'calibration' has no attribute {name!r}")
