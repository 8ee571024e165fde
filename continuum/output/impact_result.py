"""What one impact run gives back: `ImpactResult`, a frozen record of the run (exactly what result.json holds) with
typed views of it (bounces, model decisions, energy audit, regime numbers, ensemble) and the time series in SI, and
the one place that writes a run to disk (`write_impact`: result.json, timeseries.csv and the figures).

`continuum.dynamics.impact.run_impact` returns it (with the run's `Regime`, `continuum.model.regime`, derived once);
`continuum.api.read_result` rebuilds it from a written run (without a regime: that is not stored).
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..model.regime import Regime
from ..rough.ensemble import EnsembleResult
from . import plots
from .bounce import Bounce
from .results import TIMESERIES_COLUMNS, write_result_files, write_run

#: Keys of a model record that say what was decided and why; every other key is a number behind it.
_DECISION_KEYS = ("used", "decided_by", "why")


@dataclass(frozen=True)
class ModelDecision:
    """One model choice (adhesion, contact law, menisci, half-space, SAM, free flight): whether it was
    used, what decided it (`scene`, `estimate`, `geometry`, ...), why in words, and the numbers behind
    it (Tabor parameter, estimated loss, deflection, ... in SI) as recorded in result.json."""

    name: str
    used: bool | None
    decided_by: str | None
    why: str
    numbers: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def from_record(cls, name: str, record: Mapping[str, Any]) -> "ModelDecision":
        numbers = {k: v for k, v in record.items() if k not in _DECISION_KEYS}
        return cls(name=name, used=record.get("used"), decided_by=record.get("decided_by"),
                   why=str(record.get("why", "")), numbers=numbers)


@dataclass(frozen=True)
class EnergyAudit:
    """The run's energy books: the largest error of (kinetic + stored + dissipated) against the first
    impact's kinetic energy (`max_relative_error`) and against the largest energy turned over."""

    max_relative_error: float
    reference: str
    reference_energy: float
    dissipated_booked: float
    max_error_over_turnover: float | None = None
    turnover: float | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def from_record(cls, record: Mapping[str, Any]) -> "EnergyAudit":
        known = {f.name for f in fields(cls)} - {"extra"}
        return cls(**{k: record.get(k) for k in known}, extra={k: v for k, v in record.items() if k not in known})


@dataclass(frozen=True)
class ImpactResult:
    """One impact run. `record` is exactly what result.json holds; the other fields are typed views. `ensemble`:
    the discrete realisations' distributions where the run had an ensemble (surfaces.roughness.mode), else None;
    the bounces and trace are then the mean-field run's. `regime`: the numbers that placed the scene, derived once
    by the run (None for a result read from disk)."""

    record: Mapping[str, Any]
    bounces: tuple[Bounce, ...]
    models: Mapping[str, ModelDecision]
    regimes: Mapping[str, Any]
    energy_audit: EnergyAudit
    warnings: tuple[str, ...]
    release_height: float | None
    """The scene's release height h0 (m, SI), None for a scene given an impact velocity."""
    input_hash: str | None
    """Hash of the resolved scene (result.json -> provenance.input_hash)."""
    trace: Mapping[str, np.ndarray] | None = None
    ensemble: EnsembleResult | None = None
    regime: Regime | None = None

    @classmethod
    def from_record(cls, record: Mapping[str, Any], trace: Mapping[str, np.ndarray] | None = None,
                    regime: Regime | None = None) -> "ImpactResult":
        models = {name: ModelDecision.from_record(name, rec) for name, rec in record["models"].items()
                  if name != "regimes" and isinstance(rec, Mapping)}
        return cls(record=record, bounces=tuple(Bounce(**b) for b in record["bounces"]), models=models,
                   regimes=dict(record["models"].get("regimes", {})),
                   energy_audit=EnergyAudit.from_record(record["energy_audit"]),
                   warnings=tuple(record.get("warnings", ())),
                   release_height=record["scene"]["si"].get("release_height"),
                   input_hash=record.get("provenance", {}).get("input_hash"), trace=trace,
                   ensemble=(EnsembleResult.from_record(record["ensemble"], record["ensemble"].get("release_height_m"))
                             if record.get("ensemble") else None), regime=regime)

    @property
    def n_bounces(self) -> int:
        return len(self.bounces)

    @property
    def status(self) -> str:
        """How the run ended: max_bounces, stuck, rest, max_time, escaped."""
        return self.record["status"]

    @property
    def stuck(self) -> bool:
        return bool(self.record["stuck"])

    @property
    def scene_name(self) -> str:
        return self.record["scene"]["values"].get("name", "scene")

    def rebound_heights(self) -> list[float]:
        """Each bounce's rebound height (m) in order, 0 where the body did not leave the surface."""
        return [b.rebound_height or 0.0 for b in self.bounces]

    def timeseries(self) -> dict[str, np.ndarray]:
        """t, gap, velocity, force, phase, energy as NumPy arrays (SI)."""
        if self.trace is None:
            raise ValueError("this result has no time series (read it with read_result(DIR) from a written run)")
        return {name: np.asarray(self.trace[name]) for name, _ in TIMESERIES_COLUMNS}

    def to_dict(self) -> dict[str, Any]:
        """The result.json record."""
        return dict(self.record)

    def write(self, out_dir: str | Path) -> Path:
        """Write result.json, timeseries.csv, height.png and impacts.png atomically into `out_dir`."""
        if self.trace is None:
            raise ValueError("this result has no time series to write")
        return write_impact(out_dir, dict(self.record), dict(self.trace))

    def write_record(self, folder: str | Path) -> Path:
        """Write result.json alone (no time series, no figures) into the existing `folder`, atomically."""
        return write_result_files(folder, dict(self.record))


def write_impact(out_dir: str | Path, result: dict, trace: dict) -> Path:
    """Write result.json, timeseries.csv, height.png and impacts.png atomically."""
    name = result["scene"]["values"].get("name", "scene")

    def draw_height(path):
        plots.save(plots.height_vs_time(trace), path, f"{name}: height of the body")

    def draw_force(path):
        plots.save(plots.force_vs_time(trace, result["bounces"]), path, f"{name}: force during each impact")

    figures = {"height.png": draw_height, "impacts.png": draw_force}
    band = (result.get("surface") or {}).get("cutoff_band")
    if band and "ensemble" not in result:
        def draw_band(path):
            plots.save(plots.cutoff_band_panel(band), path, f"{name}: first impact against the summit cutoff")
        figures["cutoff_band.png"] = draw_band
    if "ensemble" in result:
        def draw_ensemble(path):
            plots.save(plots.ensemble_spread(result["ensemble"], band=(result.get("surface") or {}).get("cutoff_band")),
                       path, f"{name}: spread over summit realisations")
        figures["ensemble.png"] = draw_ensemble
    return write_run(out_dir, result, trace, figures)
