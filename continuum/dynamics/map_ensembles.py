"""What a height map adds to an ensemble: the run under the other tail model and the cutoff band.

A map's summit statistics at one cutoff, extrapolated with one tail model, are two choices the scan cannot fix
(`continuum.rough.tail`, `continuum.rough.cutoff_band`). Beside the scene's own ensemble this runs, to the first
rebound (the physical statistic no numerical cap censors):

- the ensemble under the other tail model of the map's summit heights (result.json -> ensemble.tail_models);
- ensembles at the cutoffs of `BAND_FACTORS` other than the run's own, with the statistics SurfaceTopography's map
  gives there (`continuum.rough.topography.summit_statistics`, the scene's route) and the scene's tail model
  (result.json -> surface.cutoff_band).

The scene's own ensemble supplies the entries at its own tail model and cutoff (a member's first impact does not
depend on how many bounces follow). Each extra ensemble follows the scene's members rule ('auto': until the first
impact's Wilson half-width is below the target).
"""
from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any

from ..rough.cutoff_band import BAND_FACTORS, band_entry, band_warning, tail_warning
from ..rough.ensemble import EnsembleResult, first_impact_summary
from ..rough.tail import TAIL_MODELS, TailFitError, fit_empirical_gpd
from ..scene import ResolvedScene, Scene
from .ensemble_run import open_executor, run_ensemble
from .map_tail import _map, _pooled, _summits, map_tail

log = logging.getLogger(__name__)


def _with_rough(scene: Scene, **values) -> Scene:
    rough = replace(scene.surfaces.roughness, **values)
    return replace(scene, surfaces=replace(scene.surfaces, roughness=rough))


def map_ensembles(resolved: ResolvedScene, main: EnsembleResult, executor: Any = None,
                  workers: int | None = None) -> dict | None:
    """{'tail_models': ..., 'cutoff_band': [...], 'warnings': [...]} for a scene with a height map whose ensemble
    `main` ran; None for a scene without a map."""
    found = _map(resolved)
    if found is None:
        return None
    hmap, cutoff, route = found
    sc = resolved.scene
    headline = sc.surfaces.roughness.tail_model
    model, tail_record = map_tail(resolved)
    tails: dict = {headline: {**first_impact_summary(main.outcomes), "from": "the scene's ensemble (first impacts)"}}
    band = [band_entry(1.0, cutoff, _stats_of(sc), {**first_impact_summary(main.outcomes)})]
    with open_executor(executor, workers) as ex:
        for other in TAIL_MODELS:
            if other == headline:
                continue
            if other == "empirical_gpd" and model is None:
                tails[other] = {"run": False, "why": tail_record["why"]}
                continue
            ens = run_ensemble(_with_rough(sc, tail_model=other), heights=model if other == "empirical_gpd" else None,
                               first_impact=True, executor=ex)
            tails[other] = {**first_impact_summary(ens.outcomes), "members_rule": dict(ens.members_rule),
                            "from": "an ensemble run to the first rebound", "wall_s": ens.wall_s}
        tails["empirical_gpd"] = {**tails.get("empirical_gpd", {}), "fit": tail_record}
        for factor in BAND_FACTORS:
            if factor != 1.0:
                band.append(_band_point(sc, hmap, factor * cutoff, factor, route, headline, ex))
    band.sort(key=lambda e: e["cutoff"])
    warnings = [w for w in (band_warning(sc.name, band), tail_warning(sc.name, tails)) if w]
    return {"tail_models": tails, "cutoff_band": band, "warnings": warnings}


def _stats_of(scene: Scene) -> dict:
    rough = scene.surfaces.roughness
    return {"summit_radius": rough.summit_radius, "summit_density": rough.summit_density,
            "summit_height_std": rough.sigma}


def _band_point(sc: Scene, hmap, cutoff: float, factor: float, route: str, tail_model: str, ex) -> dict:
    """One cutoff of the band: the map's statistics there and an ensemble of them, or why it was not evaluated."""
    from ..rough.topography import TopographyError

    try:
        stats = _pooled(hmap, cutoff, route).statistics
    except TopographyError as exc:
        return band_entry(factor, cutoff, {"summit_radius": None, "summit_density": None, "summit_height_std": None},
                          None, str(exc))
    scene = _with_rough(sc, sigma=stats.summit_height_std, summit_density=stats.summit_density,
                        summit_radius=stats.summit_radius)
    values = _stats_of(scene)
    heights = None
    if tail_model == "empirical_gpd":
        try:
            heights = fit_empirical_gpd(_summits(hmap, cutoff).height)
        except TailFitError as exc:
            return band_entry(factor, cutoff, values, None, str(exc))
    try:
        ens = run_ensemble(scene, heights=heights, first_impact=True, executor=ex)
    except ValueError as exc:           # e.g. too few summits in the footprint at this cutoff's density
        return band_entry(factor, cutoff, values, None, str(exc))
    log.info("cutoff band: %.3g m (x%g) in %.2f s", cutoff, factor, ens.wall_s)
    return {**band_entry(factor, cutoff, values, first_impact_summary(ens.outcomes)),
            "members_rule": dict(ens.members_rule)}


def _mean_field_first_impact(scene: Scene) -> dict:
    """The mean-field law's first impact of `scene` (to its first rebound): a summary shaped as an ensemble's of
    one deterministic member (no interval: nothing random is sampled), with the law that ran."""
    from ..model import dry_run_verdict, select_law
    from ..model.regime import first_impact_speed, regime_of
    from .driver import DriverSettings, simulate

    speed = first_impact_speed(scene)
    regime = regime_of(scene, speed)
    law, models = select_law(scene, speed, regime=regime)
    n = scene.numerics
    settings = DriverSettings(rtol=n.rtol, max_bounces=1, max_time=n.max_time, rest_fraction=n.rest_fraction,
                              samples_per_flight=2, samples_per_step=0)

    def run(law):
        release = scene.release_height
        if release is not None and scene.surfaces.roughness.datum == "mean_plane":
            release -= float(law.z_top)
        return simulate(law, scene.body.mass, scene.environment.gravity, release_height=release,
                        impact_velocity=scene.impact_velocity, settings=settings)
    out = run(law)
    if models["menisci"].get("decided_by") == "longest_contact_time" and "used" not in models["menisci"]:
        if dry_run_verdict(regime, [b.duration for b in out.bounces], out.status).rerun:
            law, models = select_law(scene, speed, menisci=True, regime=regime)
            out = run(law)
    first = next((b.rebound_height for b in out.bounces if b.rebound_height is not None), None)
    stuck = out.status == "stuck" and first is None
    h0 = scene.release_height
    value = (first or 0.0) / h0 if h0 else (first or 0.0)
    return {"members": 1, "stick_probability_first_impact": {
                "count": int(stuck), "members": 1, "value": float(stuck), "interval": None, "censored": 0,
                "what": "the mean-field law (deterministic): stuck or not, no interval"},
            "first_rebound_m": {"p50": first or 0.0}, **({"first_rebound_over_h0": {"p50": value}} if h0 else {}),
            "law": models["adhesion"].get("law") if "adhesion" in models else None}


def mean_field_band(resolved: ResolvedScene) -> dict | None:
    """{'cutoff_band': [...], 'warnings': [...]} of a mean-field run on a height map: the mean-field law's first
    impact at each cutoff of BAND_FACTORS with the map's statistics there; None for a scene without a map."""
    from ..rough.topography import TopographyError

    found = _map(resolved)
    if found is None:
        return None
    hmap, cutoff, route = found
    sc = resolved.scene
    band = []
    for factor in BAND_FACTORS:
        c = factor * cutoff
        try:
            stats = _pooled(hmap, c, route).statistics if factor != 1.0 else None
        except TopographyError as exc:
            band.append(band_entry(factor, c, {"summit_radius": None, "summit_density": None,
                                               "summit_height_std": None}, None, str(exc)))
            continue
        scene = sc if stats is None else _with_rough(sc, sigma=stats.summit_height_std,
                                                     summit_density=stats.summit_density,
                                                     summit_radius=stats.summit_radius)
        try:
            summary = _mean_field_first_impact(scene)
        except ValueError as exc:       # e.g. too few summits in the footprint at this cutoff's density
            band.append(band_entry(factor, c, _stats_of(scene), None, str(exc)))
            continue
        band.append({**band_entry(factor, c, _stats_of(scene), summary), "model": "mean_field",
                     "law": summary["law"]})
    warning = band_warning(sc.name, band)
    return {"cutoff_band": band, "warnings": [warning] if warning else []}
