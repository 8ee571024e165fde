"""A scene's height map: which map (a file or a synthesis), which cutoff, and the summit statistics it gives.

`map_statistics(values, sources, scene_dir)` reads the `surfaces.roughness` keys of a merged scene (file units,
which are SI for these keys) and returns the statistics the run uses together with the `surface` block of
result.json, or None when the scene names no map. Precedence, one rule: a map's sigma, summit_density and
summit_radius replace those of the parameter set (the block lists what they replaced); the same key given in the
scene file itself or as an override next to a map is an error, since two sources for one number would leave the
reader guessing which one ran. `surfaces.roughness.sigma` holds the summits' height standard deviation (the GW
sigma), so a map fills it with sigma_s, not with the surface's rms height.

The map supplies statistics (to the mean-field law and to the draws of an ensemble's members,
`continuum.dynamics.ensemble_run`): the roller's footprint may be far larger than the map, and nothing tiles the map
under it. `topography` may list several scans of one surface (`continuum.rough.map_scans`: each takes part at the cutoff
where it resolves it, and their summits are pooled); the block records each scan, how deep the data reach against the
impact (`data_depth`), and the range-of-validity checks (`validity`, `warnings`).

The cutoff is the scene's summit_cutoff (or its tip_radius, or a synthesis' short cutoff), or, with
`summit_cutoff_from = "bem"`, the one the boundary-element reference measures on the map
(`continuum.rough.cutoff_match`); `cutoff_from` in the block says which.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

from nanoimpact import data
from nanoimpact.errors import InputError

from ..reference.hertz import effective_modulus
from .cutoff_match import KEY_CUTOFF_FROM, scene_cutoff
from .map_scans import PooledScans, data_depth, pooled_statistics, validity
from .topography import (
    KEY_CHANNEL,
    KEY_CUTOFF,
    KEY_DETREND,
    KEY_FILE,
    KEY_SIZE,
    KEY_SYNTH,
    KEY_TIP,
    KEY_UNIT,
    HeightMap,
    Synthesis,
    TopographyError,
    cutoff_from_tip_radius,
    load_height_map,
)

__all__ = ["MapStatistics", "map_statistics", "statistics_block", "find_topography", "height_map", "height_maps",
           "scene_scans", "MAP_KEYS"]

KEY_ROUTE = "surfaces.roughness.summit_route"
#: The scene keys a map fills, and the statistic each takes.
MAP_KEYS = {"surfaces.roughness.sigma": "summit_height_std", "surfaces.roughness.summit_density": "summit_density",
            "surfaces.roughness.summit_radius": "summit_radius"}
_SYNTH_KEYS = ("hurst", "rms_height", "short_cutoff", "long_cutoff", "size", "grid_points", "seed")
_SYNTH_REQUIRED = ("hurst", "rms_height", "short_cutoff", "size")


@dataclass(frozen=True)
class MapStatistics:
    """What a scene's map gives: the values of MAP_KEYS (SI) and result.json's `surface` block."""

    values: dict
    block: dict


def find_topography(spec: str, scene_dir: Path | None) -> Path:
    """A height-map path: absolute as given; a relative one against the scene file's folder (the working folder
    for a scene given as a table), then each data root (`nanoimpact.data.roots`) and its `topographies/`."""
    path = Path(spec).expanduser()
    if path.is_absolute():
        candidates = [path]
    else:
        candidates = [(scene_dir or Path.cwd()) / path]
        for root in data.roots():
            candidates += [root / path, root / "topographies" / path]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise TopographyError(KEY_FILE, spec, "file not found (looked in: " + ", ".join(str(c.parent) for c in candidates)
                          + ")")


def _synthesis(values: dict) -> Synthesis | None:
    given = {k: values.get(f"{KEY_SYNTH}.{k}") for k in _SYNTH_KEYS}
    if all(given[k] is None for k in ("hurst", "rms_height", "short_cutoff", "long_cutoff", "size")):
        return None
    for k in _SYNTH_REQUIRED:
        if given[k] is None:
            raise TopographyError(f"{KEY_SYNTH}.{k}", None, "is required for a synthetic surface (hurst, rms_height, "
                                                            "short_cutoff, size)")
    return Synthesis(**{k: v for k, v in given.items() if v is not None})


@functools.lru_cache(maxsize=8)
def _statistics(specs, channel, size, unit, cutoff, tip_radius, route, stamp,
                detrend="plane") -> tuple[tuple[HeightMap, ...], PooledScans, str]:
    """(maps, pooled statistics, what set the cutoff); cached on the inputs and the files' sizes and mtimes
    (`stamp`), as sweeps resolve one scene many times."""
    if isinstance(specs, Synthesis):
        hmaps = (load_height_map(synthesis=specs),)
    else:
        hmaps = tuple(load_height_map(spec, channel=channel, size=None if size is None else list(size), unit=unit,
                                      detrend=detrend) for spec in specs)
    if cutoff is not None:
        wavelength, origin = cutoff, "summit_cutoff"
    elif tip_radius is not None:
        wavelength = max(cutoff_from_tip_radius(hmap, tip_radius) for hmap in hmaps)
        origin = (f"tip_radius {tip_radius:g} m (SurfaceTopography scanning_probe_reliability_cutoff" +
                  (", the longest of the scans')" if len(hmaps) > 1 else ")"))
    else:
        wavelength, origin = specs.short_cutoff, "synthetic.short_cutoff (the spectrum holds no shorter wavelength)"
    key_value = ((f"{KEY_SYNTH}.size", specs.size) if isinstance(specs, Synthesis)
                 else (KEY_FILE, str(specs[0]) if len(specs) == 1 else [str(s) for s in specs]))
    return hmaps, pooled_statistics(hmaps, wavelength, route, key_value), origin


def map_statistics(values: dict, sources: dict, scene_dir: Path | None) -> MapStatistics | None:
    """The statistics of the scene's height map, or None when it names none (see the module docstring for the
    precedence). Raises TopographyError naming the key."""
    file_spec, synthesis = values.get(KEY_FILE), _synthesis(values)
    if file_spec is not None and not file_spec:
        raise TopographyError(KEY_FILE, file_spec, "must name a file or a list of one or more files")
    if file_spec is None and synthesis is None:
        for key in (KEY_CHANNEL, KEY_SIZE, KEY_UNIT, KEY_CUTOFF, KEY_TIP, KEY_DETREND):
            if values.get(key) is not None and sources.get(key) != "default":
                raise TopographyError(key, values[key], f"is for a height map: set {KEY_FILE} or [{KEY_SYNTH}]")
        return None
    if synthesis is not None and values.get(KEY_DETREND) is not None and sources.get(KEY_DETREND) != "default":
        raise TopographyError(KEY_DETREND, values[KEY_DETREND], "is for a measured map (a synthetic map is periodic "
                                                                "and only loses its mean)")
    if file_spec is not None and synthesis is not None:
        raise TopographyError(KEY_FILE, file_spec, f"give a measured map or a synthetic one ([{KEY_SYNTH}]), not both")
    if values.get("contact") != "rough":
        raise TopographyError(KEY_FILE if file_spec else f"{KEY_SYNTH}.hurst", file_spec or synthesis.hurst,
                              "a height map is for contact = 'rough'")
    cutoff, tip = values.get(KEY_CUTOFF), values.get(KEY_TIP)
    if cutoff is not None and tip is not None:
        raise TopographyError(KEY_TIP, tip, "give summit_cutoff or tip_radius, not both")
    if values.get(KEY_CUTOFF_FROM) == "bem" and (cutoff is not None or tip is not None):
        raise TopographyError(KEY_CUTOFF_FROM, "bem", "measures the cutoff: remove summit_cutoff and tip_radius")
    if synthesis is None and cutoff is None and tip is None and values.get(KEY_CUTOFF_FROM) != "bem":
        raise TopographyError(KEY_CUTOFF, None, "is required with a measured map (or give tip_radius): summit "
                                                "radius and density depend on the shortest wavelength kept")
    replaced = {}
    for key in MAP_KEYS:
        source = sources.get(key)
        if values.get(key) is not None and source != "default":
            if not str(source).startswith("params:"):
                raise TopographyError(key, values[key], f"is derived from the height map; remove it from the "
                                                        f"{source}, or remove the map")
            replaced[key] = {"value": values[key], "source": source}
    hmaps, pooled, origin = _load(values, scene_dir)
    stats = pooled.statistics
    radius, length = values.get("body.radius"), values.get("body.length")
    block = {**stats.to_json(), "cutoff_from": origin, "source": dict(pooled.used[0].source), "scans": pooled.scans,
             "replaced": replaced, "fills": {key: attr for key, attr in MAP_KEYS.items()},
             "note": "the map supplies summit statistics to the mean-field (GW) law and the distributions an "
                     "ensemble's members draw their strip from (never copies of the map; result.json -> ensemble); "
                     "data_depth says how far its summits reach against the impact"}
    warnings = [w for hmap in hmaps for w in hmap.warnings]
    if radius is not None:
        depth = data_depth(pooled, stats.summit_height_std, stats.summit_density, float(radius),
                           None if length is None else float(length))
        checks, more = validity(pooled, depth, float(radius), stats.cutoff)
        block.update(data_depth=depth, validity=checks)
        warnings += more
    block["warnings"] = warnings
    return MapStatistics(values={key: getattr(stats, attr) for key, attr in MAP_KEYS.items()}, block=block)


def _load(values: dict, scene_dir: Path | None) -> tuple[tuple[HeightMap, ...], PooledScans, str]:
    """The scene's maps, their pooled statistics and what set the cutoff (one cached load)."""
    spec, stamp = _map_spec(values.get(KEY_FILE), _synthesis(values), scene_dir)
    size = values.get(KEY_SIZE)
    channel = values.get(KEY_CHANNEL)
    cutoff, bem_origin = _cutoff(values, spec, stamp)
    hmaps, pooled, origin = _statistics(spec, channel, None if size is None else tuple(size), values.get(KEY_UNIT),
                                        cutoff, values.get(KEY_TIP), values.get(KEY_ROUTE, "direct"), stamp,
                                        values.get(KEY_DETREND) or "plane")
    return hmaps, pooled, bem_origin or origin


def _cutoff(values: dict, spec, stamp) -> tuple[float | None, dict | None]:
    """(cutoff, its origin when the boundary-element reference measured it): the scene's summit_cutoff, or with
    summit_cutoff_from = "bem" the cutoff `continuum.rough.cutoff_match.scene_cutoff` measures on the map with the
    scene's dry law (work_of_adhesion, interaction_range, E* of body and substrate)."""
    if values.get(KEY_CUTOFF_FROM) != "bem":
        return values.get(KEY_CUTOFF), None
    size = values.get(KEY_SIZE)
    if isinstance(spec, Synthesis):
        hmap = _statistics(spec, None, None, None, None, None, "direct", stamp)[0][0]
    elif len(spec) != 1:
        raise TopographyError(KEY_CUTOFF_FROM, "bem", f"measures the cutoff on one scan: give one {KEY_FILE} "
                                                      f"(this scene gives {len(spec)})")
    else:
        hmap = load_height_map(spec[0], channel=values.get(KEY_CHANNEL), size=None if size is None else list(size),
                               unit=values.get(KEY_UNIT), detrend=values.get(KEY_DETREND) or "plane")
    e_star = float(effective_modulus(values["surfaces.body.youngs_modulus"], values["surfaces.body.poisson_ratio"],
                                     values["surfaces.substrate.youngs_modulus"],
                                     values["surfaces.substrate.poisson_ratio"]))
    return _measured(hmap, e_star, values["surfaces.work_of_adhesion"], values["surfaces.interaction_range"])


def _measured(hmap: HeightMap, e_star: float, w: float, z0: float) -> tuple[float, dict]:
    """The measured cutoff (run once per map and law: the match is cached on disk by the heights' hash)."""
    try:
        return scene_cutoff(hmap.heights, hmap.physical_size[0], hmap.periodic, e_star, w, z0)
    except TopographyError:
        raise
    except InputError as exc:
        raise TopographyError(exc.key, exc.value, exc.allowed) from None



def _map_spec(file_spec, synthesis, scene_dir: Path | None):
    """(what to load, cache stamp): the synthesis parameters (no stamp), or the map files' resolved paths (a
    tuple) with their sizes and modification times, so that the cached load is redone when a file changes."""
    if synthesis is not None:
        return synthesis, None
    paths = tuple(find_topography(spec, scene_dir) for spec in ([file_spec] if isinstance(file_spec, str)
                                                                 else file_spec))
    stats = [path.stat() for path in paths]
    return tuple(p.resolve() for p in paths), tuple((st.st_size, st.st_mtime_ns) for st in stats)

def statistics_block(values: dict, sources: dict) -> dict:
    """result.json's `surface` block of a rough scene given by its statistics (no map)."""
    return {"rms_height": None, "summit_height_std": values.get("surfaces.roughness.sigma"),
            "summit_density": values.get("surfaces.roughness.summit_density"),
            "summit_radius": values.get("surfaces.roughness.summit_radius"), "route": None, "cutoff": None,
            "source": {"kind": "statistics", "keys": {key: sources.get(key) for key in MAP_KEYS}}}


def scene_scans(values: dict, scene_dir: Path | None) -> PooledScans | None:
    """The scene's scans at its cutoff: pooled statistics, the pooled summits (`summits`), the maps that take part
    (`used`) and one record per scan (`scans`), or None when the scene names no map. For a scene
    `map_statistics` has already accepted (the same cached load)."""
    if values.get(KEY_FILE) is None and _synthesis(values) is None:
        return None
    return _load(values, scene_dir)[1]


def height_maps(values: dict, scene_dir: Path | None) -> tuple[tuple[HeightMap, ...], float] | None:
    """The scene's height maps that take part at the cutoff (largest first) and the cutoff wavelength (m) their
    statistics were taken at (the same cached load as `map_statistics`), or None when the scene names none. For a
    scene `map_statistics` has already accepted."""
    if values.get(KEY_FILE) is None and _synthesis(values) is None:
        return None
    _, pooled, _ = _load(values, scene_dir)
    used = sorted(pooled.used, key=lambda h: -h.physical_size[0] * h.physical_size[1])
    return tuple(used), float(pooled.statistics.cutoff)


def height_map(values: dict, scene_dir: Path | None) -> tuple[HeightMap, float] | None:
    """The scene's (largest used) height map and the cutoff wavelength (m) its statistics were taken at, or None
    when the scene names none (`height_maps` gives every scan that takes part)."""
    found = height_maps(values, scene_dir)
    return None if found is None else (found[0][0], found[1])
