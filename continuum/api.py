"""The continuum layer's Python front door: `run_scene` -> a typed `ImpactResult`.

    >>> from continuum import run_scene
    >>> r = run_scene("hertz_roller", overrides={"numerics.max_bounces": 3})
    >>> r.n_bounces, r.bounces[0].restitution, r.models["adhesion"].used
    >>> r.write("out/hertz_roller")        # result.json, timeseries.csv, height.png, impacts.png

A scene is a shipped scene's name (`hertz_roller`), a path to a TOML file, a TOML table (dict),
or a `ResolvedScene` from `continuum.load_scene`. `params` replaces the scene's parameter set
(a name or a path) and `overrides` ({dotted key: value}, file units) win over everything, as on
the command line. The result carries the same record as `result.json` (`to_dict()`), typed views
of it (bounces, model decisions, energy audit) and the time series in SI units.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from .dynamics.driver import Bounce
from .dynamics.impact import run_impact, write_impact
from .output.results import TIMESERIES_COLUMNS, load_result
from .rough.ensemble import EnsembleResult
from .scene import ResolvedScene, resolve_scene

__all__ = ["run_scene", "load_scene", "read_result", "ImpactResult", "ModelDecision", "EnergyAudit", "EnsembleResult"]

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
    the bounces and trace are then the mean-field run's."""

    record: Mapping[str, Any]
    bounces: tuple[Bounce, ...]
    models: Mapping[str, ModelDecision]
    regimes: Mapping[str, Any]
    energy_audit: EnergyAudit
    warnings: tuple[str, ...]
    trace: Mapping[str, np.ndarray] | None = None
    ensemble: EnsembleResult | None = None

    @classmethod
    def from_record(cls, record: Mapping[str, Any], trace: Mapping[str, np.ndarray] | None = None) -> "ImpactResult":
        models = {name: ModelDecision.from_record(name, rec) for name, rec in record["models"].items()
                  if name != "regimes" and isinstance(rec, Mapping)}
        return cls(record=record, bounces=tuple(Bounce(**b) for b in record["bounces"]), models=models,
                   regimes=dict(record["models"].get("regimes", {})),
                   energy_audit=EnergyAudit.from_record(record["energy_audit"]),
                   warnings=tuple(record.get("warnings", ())), trace=trace,
                   ensemble=(EnsembleResult.from_record(record["ensemble"], record["ensemble"].get("release_height_m"))
                             if record.get("ensemble") else None))

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


def load_scene(scene: str | Path | Mapping[str, Any], params: str | Path | None = None,
               overrides: Mapping[str, Any] | None = None) -> ResolvedScene:
    """Read, merge and validate a scene (a shipped name, a path or a TOML table); `SceneError` names the
    first bad key, its value and what is allowed."""
    if isinstance(scene, Mapping):
        return resolve_scene(table=dict(scene), params=None if params is None else str(params),
                             overrides=dict(overrides or {}), override_label="run_scene overrides")
    return resolve_scene(scene, params=None if params is None else str(params), overrides=dict(overrides or {}),
                         override_label="run_scene overrides")


def run_scene(scene: str | Path | Mapping[str, Any] | ResolvedScene, params: str | Path | None = None,
              overrides: Mapping[str, Any] | None = None,
              progress: Callable[[Bounce], None] | None = None, executor: Any = None,
              workers: int | None = None) -> ImpactResult:
    """Run one impact scene and return its typed result (nothing is written; call `.write(dir)`). An ensemble
    (surfaces.roughness.mode 'ensemble', or 'auto' with few summits) runs its members on `executor`
    (`nanoimpact.executors` name with `workers`, or an open executor; None: in this process)."""
    if isinstance(scene, ResolvedScene):
        if params is not None or overrides:
            raise ValueError("params and overrides apply when the scene is read: pass them to load_scene")
        resolved = scene
    else:
        resolved = load_scene(scene, params, overrides)
    record, trace = run_impact(resolved, progress=progress, executor=executor, workers=workers)
    return ImpactResult.from_record(record, trace)


def read_result(folder: str | Path) -> ImpactResult:
    """A written run (result.json + timeseries.csv) as an `ImpactResult`; checks the schema version."""
    stored = load_result(folder)
    trace = stored.timeseries() if (Path(folder) / "timeseries.csv").is_file() else None
    return ImpactResult.from_record(dict(stored), trace)
