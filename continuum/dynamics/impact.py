"""Run one impact scene end to end: scene -> regime (derived once) -> law -> driver -> typed result (+ figures)."""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Callable

from ..model import dry_run_verdict, select_law
from ..model.decisions import menisci_decision, realisation_decision
from ..model.regime import Regime, regime_of
from ..model.regime import first_impact_speed as scene_first_impact_speed
from ..output.bounce import Bounce
from ..output.impact_result import ImpactResult
from ..output.notices import audit_warnings, model_warnings, result_warnings
from ..output.provenance import provenance
from ..output.results import SCHEMA_VERSION
from ..scene import ResolvedScene, SceneError
from .driver import DriverSettings, simulate


def first_impact_speed(resolved: ResolvedScene) -> float:
    """Speed (m/s) at the first touch of a resolved scene (`continuum.model.regime.first_impact_speed`)."""
    return scene_first_impact_speed(resolved.scene)


def run_impact(resolved: ResolvedScene, progress: Callable[[Bounce], None] | None = None,
               executor=None, workers: int | None = None, condensation_sweep: bool = True,
               series: bool = True) -> ImpactResult:
    """Simulate a resolved scene; returns its typed result (`continuum.output.impact_result.ImpactResult`: the
    result.json record, its typed views, the time series and the scene's `Regime`).

    The scene's regime (`continuum.model.regime.regime_of`: moduli, Tabor numbers, the first impact's estimate,
    condensation and meniscus parameters) is derived once here and passed to every step. Rough contact:
    surfaces.roughness.mode is settled first (`realisation_decision`; 'auto' by the expected summits in contact).
    An ensemble runs its members on `executor` (a `nanoimpact.executors` name or an open executor; None: in this
    process) and adds result.json -> ensemble; the trajectory (bounces, time series) is then the mean-field law's,
    with the members' summit law, for comparison. A humid scene (menisci not 'off') adds result.json ->
    menisci_condensation_time, its sticking against t_a over the range the estimate allows
    (`continuum.dynamics.wet_sweep`; `condensation_sweep` False leaves it out). `series=False`, for a caller that
    reads the bounces and the verdict only (as `continuum.dynamics.escape.single_impact`): no samples inside the
    integrator's steps, two per flight and no profiles, so the time series holds the step ends and events only; the
    steps, the events and so every bounce are the same, while the samples' law evaluations (~40 % of a compiled
    contact's) and a rough law's snapshots are not made."""
    start = time.perf_counter()
    regime = regime_of(resolved.scene, first_impact_speed(resolved))
    resolved, realisation = _settle_realisation(resolved, regime)
    scene = resolved.scene
    law, models = select_law(scene, regime.speed, regime=regime)
    if realisation is not None:
        models["realisation"] = realisation.record()
    run, release = _simulate(resolved, law, models, progress, series)
    if models["menisci"].get("decided_by") == "longest_contact_time" and "used" not in models["menisci"]:
        # auto menisci, pending: the dry run settles it (continuum.model.decisions.dry_run_verdict)
        verdict = dry_run_verdict(regime, [b.duration for b in run.bounces], run.status)
        if verdict.rerun:
            law, models = select_law(scene, regime.speed, menisci=True, regime=regime)
            if realisation is not None:
                models["realisation"] = realisation.record()
            run, release = _simulate(resolved, law, models, progress, series)
        models["menisci"].update(verdict.record())
    models["regimes"] = regime_numbers(scene, regime, models, run)
    wall = time.perf_counter() - start
    diagnostics = law.diagnostics()
    if diagnostics:
        models["diagnostics"] = diagnostics
    warnings = (list((resolved.surface or {}).get("warnings", ())) + result_warnings(scene, law, run.bounces)
                + model_warnings(models) + audit_warnings(scene, run.audit))
    result = {
        "schema_version": SCHEMA_VERSION,
        "scene": resolved.to_json(),
        "surface": resolved.surface,
        "models": models,
        "bounces": run.bounce_dicts(),
        "n_bounces": len(run.bounces),
        "status": run.status,
        "stuck": run.stuck,
        "energy_audit": run.audit,
        "warnings": warnings,
        "provenance": provenance(resolved.input_hash),
        "timing": {"wall_s": wall},
    }
    if realisation is not None and realisation.mode == "ensemble":
        result["ensemble"], extra = _ensemble_record(resolved, run, executor, workers, regime)
        if extra is not None:  # a height map: its cutoff band and the tail models (continuum.dynamics.map_ensembles)
            result["surface"] = {**result["surface"], "cutoff_band": extra["cutoff_band"]}
            result["warnings"] += extra["warnings"]
        result["timing"]["wall_s"] = time.perf_counter() - start
    elif realisation is not None and realisation.mode == "mean_field" and (resolved.surface or {}).get("cutoff"):
        from .map_ensembles import mean_field_band  # a map under the mean field: its first impact at each cutoff
        band = mean_field_band(resolved)
        result["surface"] = {**result["surface"], "cutoff_band": band["cutoff_band"]}
        result["warnings"] += band["warnings"]
    if condensation_sweep and menisci_decision(scene, regime).choice != "off":
        from .wet_sweep import condensation_sweep as sweep
        result["menisci_condensation_time"] = sweep(resolved, result, executor, workers, rerun=run_impact,
                                                          regime=regime)
        result["timing"]["wall_s"] = time.perf_counter() - start
    return ImpactResult.from_record(result, run.trace.arrays(), regime)


def _settle_realisation(resolved: ResolvedScene, regime: Regime):
    """(resolved scene with surfaces.roughness.mode settled, the decision); (resolved, None) for smooth contact.
    A realisation changes no number of the scene's `regime` (its estimate included)."""
    from .ensemble_run import with_realisation

    scene = resolved.scene
    if scene.contact != "rough":
        return resolved, None
    decision = realisation_decision(scene, regime)
    if decision.mode != scene.surfaces.roughness.mode:
        resolved = replace(resolved, scene=with_realisation(scene, decision.mode))
    return resolved, decision


def _ensemble_record(resolved: ResolvedScene, run, executor, workers,
                     regime: Regime) -> tuple[dict, dict | None]:
    """(result.json -> ensemble: the members' distributions, with the mean-field run's numbers beside them; for a
    scene with a height map, what `continuum.dynamics.map_ensembles` adds: the tail models, the cutoff band,
    warnings)."""
    from .ensemble_run import open_executor, run_ensemble
    from .map_ensembles import map_ensembles

    with open_executor(executor, workers) as ex:
        ens = run_ensemble(resolved, executor=ex, regime=regime)
        extra = map_ensembles(resolved, ens, executor=ex)
    heights = [b.rebound_height for b in run.bounces if b.rebound_height is not None]
    mean_field = {"rebounds": len(heights), "first_rebound_m": heights[0] if heights else 0.0,
                  "status": run.status, "stuck": run.stuck,
                  "what": "the mean-field law of the trajectory (bounces, timeseries), same summit law"}
    record = ens.to_record(mean_field=mean_field)
    if extra is not None:
        record["tail_models"] = extra["tail_models"]
    return record, extra


def regime_numbers(scene, regime: Regime, models: dict, run) -> dict:
    """The numbers that place a scene (recorded whatever was decided), read from its one `Regime`
    (`continuum.model.regime`): Tabor parameter of the summits (or sphere), Fuller-Tabor theta, half-space
    deflection span / sigma, expected contacts, and the longest contact of the run against the condensation
    time t_a (SI)."""
    rough = regime.rough
    est = models.get("estimate", {})
    longest = max((b.duration for b in run.bounces if b.duration is not None), default=0.0)
    t_a = regime.condensation_time
    return {
        "tabor_parameter": regime.tabor_parameter if regime.tabor_parameter is not None else 0.0,
        "interaction_range_z0": regime.interaction_range,
        # no adhesion: None (JSON null, as the infinite theta it stood for)
        "fuller_tabor_theta": regime.fuller_tabor_theta,
        "deflection_over_sigma": (est["deflection_span"] / scene.surfaces.roughness.sigma) if rough and est else None,
        "expected_contacts": est.get("contacts") if rough else None,
        "longest_contact_s": longest, "condensation_time_s": t_a,
        "longest_contact_over_t_a": longest / t_a,
        "note": "Tabor > 5 JKR, < 0.1 DMT; deflection/sigma < 1e-3 leaves the half-space out; contacts < 10 make "
                "the GW average unreliable; contacts shorter than t_a cannot grow bridges",
    }


def _simulate(resolved: ResolvedScene, law, models: dict, progress, series: bool = True):
    """Drive `law` through the scene's release; returns the run and the release height used (m). `series`: the
    scene's samples and the law's profiles (`run_impact`)."""
    scene = resolved.scene
    n = scene.numerics
    sampled = {} if series else {"samples_per_step": 0, "profiles": False}
    settings = DriverSettings(rtol=n.rtol, max_bounces=n.max_bounces, max_time=n.max_time,
                              rest_fraction=n.rest_fraction,
                              samples_per_flight=n.samples_per_flight if series else 2, **sampled)
    release = scene.release_height
    rough = scene.surfaces.roughness if scene.contact == "rough" else None
    if rough is not None and release is not None:
        z_top = float(law.z_top)                      # tallest summit above the summits' mean plane (m)
        if rough.datum == "mean_plane":
            release = scene.release_height - z_top
            if release <= 0.0:
                raise SceneError("release_height", scene.release_height,
                                 f"with surfaces.roughness.datum = 'mean_plane' the body would start in contact: the "
                                 f"tallest summit expected in the footprint is {z_top:.3g} m above the mean plane",
                                 resolved.scene_file or "")
        models["contact_law"]["datum"]["heights_measured_from"] = "tallest summit (gap coordinate of bounces and trace)"
        models["contact_law"]["datum"]["release_above_tallest_summit"] = release
    run = simulate(law, scene.body.mass, scene.environment.gravity, release_height=release,
                   impact_velocity=scene.impact_velocity, settings=settings, progress=progress)
    return run, release
