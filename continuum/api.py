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

The other packages (`calibration`) reach continuum through this module and `continuum` alone
(`tests/test_architecture.py`): besides the names above it offers the scene's keys and checks (`FIELD_BY_PATH`,
`check_value`, `SceneError`, `find_params`, `find_scene`, `read_toml`, `flatten`, `json_schema`, `check_origins`),
single impacts and escape velocities on a scene's law (`contact_law`, `single_impact`, `escape_velocity`,
`first_impact_speed`) and the paper's runs (`make_paper`, `row_for_scene`, `DEFAULT_SEEDS`, `fig4_choice_probe`).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Mapping

from .dynamics import impact
from .dynamics.escape import escape_velocity as escape_velocity
from .dynamics.escape import single_impact as single_impact
from .dynamics.impact import first_impact_speed as first_impact_speed
from .laws.base import ContactLaw
from .model.regime import Regime
from .model.select import select_law
from .origins import check_origins as check_origins
from .output.bounce import Bounce
from .output.impact_result import EnergyAudit, ImpactResult, ModelDecision
from .output.results import load_result
from .paper import loop_probe
from .paper import report as paper_report
from .paper.samples import DEFAULT_SEEDS as DEFAULT_SEEDS
from .paper.samples import row_for_scene as row_for_scene
from .paper.verdict import single_text as single_text
from .rough.ensemble import EnsembleResult
from .scene import ResolvedScene, resolve_scene
from .scene import SceneError as SceneError
from .scene import check_value as check_value
from .scene import find_params as find_params
from .scene import find_scene as find_scene
from .scene import flatten as flatten
from .scene import read_toml as read_toml
from .schema import FIELD_BY_PATH as FIELD_BY_PATH
from .schema import json_schema as json_schema

__all__ = ["run_scene", "load_scene", "read_result", "ImpactResult", "ModelDecision", "EnergyAudit", "EnsembleResult"]


def load_scene(scene: str | Path | Mapping[str, Any], params: str | Path | None = None,
               overrides: Mapping[str, Any] | None = None,
               override_label: str = "run_scene overrides") -> ResolvedScene:
    """Read, merge and validate a scene (a shipped name, a path or a TOML table); `SceneError` names the
    first bad key, its value and what is allowed. `override_label` names where the overrides come from (in error
    messages and result.json -> scene.sources)."""
    if isinstance(scene, Mapping):
        return resolve_scene(table=dict(scene), params=None if params is None else str(params),
                             overrides=dict(overrides or {}), override_label=override_label)
    return resolve_scene(scene, params=None if params is None else str(params), overrides=dict(overrides or {}),
                         override_label=override_label)


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
    return impact.run_impact(resolved, progress=progress, executor=executor, workers=workers)


def read_result(folder: str | Path) -> ImpactResult:
    """A written run (result.json + timeseries.csv) as an `ImpactResult`; checks the schema version."""
    stored = load_result(folder)
    trace = stored.timeseries() if (Path(folder) / "timeseries.csv").is_file() else None
    return ImpactResult.from_record(dict(stored), trace)


def contact_law(resolved: ResolvedScene, regime: Regime | None = None) -> ContactLaw:
    """The contact law a resolved scene runs at its first impact (`continuum.model.select_law`), on the scene's
    `regime` where a run derived it already (`ImpactResult.regime`), else derived here. For single impacts at other
    speeds (`single_impact`, `escape_velocity`)."""
    return select_law(resolved.scene, first_impact_speed(resolved), regime=regime)[0]


def make_paper(sets: list[str], out: str | Path, **options) -> dict:
    """Run every case of the founding paper for every parameter set in `sets` into `out` and check its claims
    (`continuum.paper.report.make_paper`, whose keyword `options` it takes: fidelity, executor, seeds, ...);
    returns {"checks": [...], "wall_s": ...}."""
    return paper_report.make_paper(sets, out, **options)


def fig4_choice_probe(params: str, fidelity: str | None = None) -> dict:
    """Fig 4's loop ratio under the set `params` and under its declared choices (SAM layer modulus, summit radius;
    `continuum.paper.loop_probe.fig4_choice_probe`)."""
    return loop_probe.fig4_choice_probe(params, fidelity)
