"""A height map's summit-height tail for an ensemble: the map's own summits at a cutoff, pooled over the scans that
take part there (`continuum.rough.map_scans`), and the `empirical_gpd` model fitted to them (`continuum.rough.tail`).

Used by the ensemble runner (a scene whose tail model is `empirical_gpd`) and by `continuum.dynamics.map_ensembles` (the
other tail model and the cutoff band), so that neither imports the other.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..rough.tail import TailFitError, fit_empirical_gpd, map_summit_record
from ..scene import ResolvedScene


def _map(resolved: ResolvedScene):
    """(the scene's height maps (every scan that takes part), cutoff (m), summit route), or None without a map."""
    from ..rough.surface_map import height_maps

    scene_dir = Path(resolved.scene_file).parent if resolved.scene_file else None
    found = height_maps(resolved.values, scene_dir)
    if found is None:
        return None
    return found[0], found[1], resolved.values.get("surfaces.roughness.summit_route", "direct")


def _pooled(hmaps, cutoff: float, route: str = "direct"):
    """The scans' pooled summits and statistics at `cutoff` (`continuum.rough.map_scans`: each scan that resolves
    it contributes; a non-periodic scan is mirror-stitched, never wrapped)."""
    from ..rough.map_scans import pooled_statistics
    return pooled_statistics(hmaps, cutoff, route)


def _summits(hmaps, cutoff: float):
    return _pooled(hmaps, cutoff).summits


def map_tail(resolved: ResolvedScene, cutoff: float | None = None) -> tuple[Any, dict]:
    """(the `empirical_gpd` model of the map's summit heights at `cutoff` (default: the run's) or None where the map
    cannot carry the fit, its record with the map's summit distributions)."""
    from ..rough.datum import tallest_summit

    hmap, own, _ = _map(resolved)
    rough, body = resolved.scene.surfaces.roughness, resolved.scene.body
    summits = _summits(hmap, own if cutoff is None else cutoff)
    sigma_s = float(summits.height.std())
    rec = {"map_summits": map_summit_record(summits, sigma_s)}
    try:
        model = fit_empirical_gpd(summits.height)
    except TailFitError as exc:
        return None, {**rec, "fitted": False, "why": str(exc)}
    strip = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)["summits_in_footprint"]
    return model, {**rec, "fitted": True, **model.record(sigma_s, strip)}
