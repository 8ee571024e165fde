"""Run one impact scene end to end: scene -> law -> driver -> result record (+ figures)."""
from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Callable

from . import plots
from .driver import Bounce, DriverSettings, simulate
from .model import dry_run_verdict, select_law
from .provenance import provenance
from .results import SCHEMA_VERSION, write_run
from .scene import ResolvedScene, SceneError
from .warnings import model_warnings, result_warnings


def first_impact_speed(resolved: ResolvedScene) -> float:
    """Speed (m/s) at the first touch: sqrt(2 g h0) for a release height, else the given velocity."""
    s = resolved.scene
    if s.release_height is not None:
        return math.sqrt(2.0 * s.environment.gravity * s.release_height)
    return s.impact_velocity


def run_impact(resolved: ResolvedScene, progress: Callable[[Bounce], None] | None = None) -> tuple[dict, dict]:
    """Simulate a resolved scene; returns (result record for result.json, time-series arrays)."""
    scene = resolved.scene
    start = time.perf_counter()
    law, models = select_law(scene, first_impact_speed(resolved))
    run, release = _simulate(resolved, law, models, progress)
    if models["menisci"].get("decided_by") == "longest_contact_time" and "used" not in models["menisci"]:
        # auto menisci, pending: the dry run settles it (continuum.model.decisions.dry_run_verdict)
        verdict = dry_run_verdict(scene, [b.duration for b in run.bounces], run.status)
        if verdict.rerun:
            law, models = select_law(scene, first_impact_speed(resolved), menisci=True)
            run, release = _simulate(resolved, law, models, progress)
        models["menisci"].update(verdict.record())
    models["regimes"] = regime_numbers(scene, models, run)
    wall = time.perf_counter() - start
    diagnostics = law.diagnostics()
    if diagnostics:
        models["diagnostics"] = diagnostics
    warnings = result_warnings(scene, law, run.bounces) + model_warnings(models)
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
    return result, run.trace.arrays()


def regime_numbers(scene, models: dict, run) -> dict:
    """The numbers that place a scene (recorded whatever was decided), read from its one `Regime`
    (`continuum.model.regime`): Tabor parameter of the summits (or sphere), Fuller-Tabor theta, half-space
    deflection span / sigma, expected contacts, and the longest contact of the run against the condensation
    time t_a (SI)."""
    from .model.regime import condensation_time, regime_of

    regime = regime_of(scene)
    rough = regime.rough
    est = models.get("estimate", {})
    longest = max((b.duration for b in run.bounces if b.duration is not None), default=0.0)
    t_a = condensation_time(scene)[0]
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


def _simulate(resolved: ResolvedScene, law, models: dict, progress):
    """Drive `law` through the scene's release; returns the run and the release height used (m)."""
    scene = resolved.scene
    n = scene.numerics
    settings = DriverSettings(rtol=n.rtol, max_bounces=n.max_bounces, max_time=n.max_time,
                              rest_fraction=n.rest_fraction, samples_per_flight=n.samples_per_flight)
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


def write_impact(out_dir: str | Path, result: dict, trace: dict) -> Path:
    """Write result.json, timeseries.csv, height.png and impacts.png atomically."""
    name = result["scene"]["values"].get("name", "scene")

    def draw_height(path):
        plots.save(plots.height_vs_time(trace), path, f"{name}: height of the body")

    def draw_force(path):
        plots.save(plots.force_vs_time(trace, result["bounces"]), path, f"{name}: force during each impact")

    return write_run(out_dir, result, trace, {"height.png": draw_height, "impacts.png": draw_force})
