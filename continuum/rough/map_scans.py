"""Several scans of one surface, how deep their data reach, and where the summit model applies.

Scans (`topography = ["small.di", "large.di"]`). Scans of one surface at different sizes resolve different
wavelengths: a scan resolves from `MIN_CUTOFF_PIXELS` pixels (below that the 8-neighbour summit and its
curvature are pixel noise, Greenwood 1984) up to its own side. At the cutoff lambda_c the run uses every scan
that resolves lambda_c and spans at least `MIN_SPANS` cutoffs; the others are recorded with the reason they
sit out. The used scans' summits are pooled, as samples of one surface: direct route, density = all summits /
all areas, sigma_s their heights' standard deviation (each about its own mean plane), beta = 1 / their mean
curvature; spectral route, the area-weighted mean of the scans' profile moments (the largest scan dominates
m0). One scan is the special case of this rule.

Data depth. The impact does not meet a typical summit: a rough roller first touches the tallest of the N_f
summits in its strip, z_max = Phi^-1(1 - 1/N_f) sigma_s above their mean (`continuum.rough.datum`, Gumbel
1958). The map can only vouch for heights it holds: its tallest summit in sigma_s, against the Gaussian's
expected tallest of the map's own N summits (lighter or heavier tail) and the excess kurtosis of the summit
heights. Where z_max lies beyond the map's tallest summit, the outcome rests on an assumed tail, and the record
and a warning say so.

Range of validity (each check with its numbers in `surface.validity`; a warning or a one-line refusal):
- summit radius against the body's: Greenwood-Williamson summits are small spheres under a large body,
  beta << R. beta >= R refuses (the "summits" are flatter than the body; the footprint then spans less than a
  summit), beta > R/10 warns.
- footprint against the cutoff: the strip 2 x_f the body touches should hold summits, i.e. be wider than
  lambda_c; narrower warns.
- summits on the maps: fewer than `MIN_SUMMITS` refuses (`continuum.rough.topography`), fewer than
  `FEW_SUMMITS` warns with the sampling errors (density ~ 1/sqrt(N), sigma_s ~ 1/sqrt(2N)).
- map size against the cutoff: the largest used scan should span several cutoffs; under `WARN_SPANS` warns
  (no scan spanning `MIN_SPANS` refuses).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats as sps

from .datum import tallest_summit
from .summit_stats import areal_moments, direct_summary, profile_moments, spectral_from_moments
from .summits import expected_max_height
from .topography import (
    KEY_CUTOFF,
    KEY_FILE,
    MIN_CUTOFF_PIXELS,
    MIN_SUMMITS,
    ROUTES,
    HeightMap,
    Summits,
    SurfaceStatistics,
    TopographyError,
    map_summits,
)

__all__ = ["MIN_SPANS", "WARN_SPANS", "FEW_SUMMITS", "MAX_RADIUS_RATIO", "WARN_RADIUS_RATIO", "PooledScans",
           "pooled_statistics", "scan_record", "data_depth", "validity"]

#: A scan takes part at a cutoff when it spans at least this many cutoff wavelengths along its shorter side.
MIN_SPANS = 2.0
#: Below this many cutoffs along the largest used scan's shorter side, a warning.
WARN_SPANS = 5.0
#: Below this many summits on the maps, a warning with the sampling errors.
FEW_SUMMITS = 100
#: beta / R at and above which the run is refused, and above which it warns.
MAX_RADIUS_RATIO = 1.0
WARN_RADIUS_RATIO = 0.1


class PooledScans:
    """The scans at one cutoff: statistics, pooled summits, the maps used and one record per scan."""

    def __init__(self, statistics: SurfaceStatistics, summits: Summits, used: list[HeightMap], scans: list[dict]):
        self.statistics, self.summits, self.used, self.scans = statistics, summits, used, scans


def scan_record(hmap: HeightMap, cutoff: float) -> tuple[bool, dict]:
    """(takes part at `cutoff`, the scan's record): what it resolves, and why it sits out if it does."""
    pixel, side = max(hmap.pixel_size), min(hmap.physical_size)
    resolves = [MIN_CUTOFF_PIXELS * pixel, side]
    record = {"file": hmap.source.get("file"), "channel_name": hmap.source.get("channel_name"),
              "detrend": (hmap.source.get("detrend") or {}).get("mode"), "physical_size_m": list(hmap.physical_size),
              "pixel_size_m": list(hmap.pixel_size), "resolves_wavelengths_m": resolves}
    if cutoff < resolves[0]:
        record["used"], record["why_not"] = False, (f"its pixel ({pixel:.3g} m) does not resolve the cutoff "
                                                    f"{cutoff:.3g} m (needs >= {MIN_CUTOFF_PIXELS:g} pixels)")
    elif side < MIN_SPANS * cutoff:
        record["used"], record["why_not"] = False, (f"its side ({side:.3g} m) spans fewer than {MIN_SPANS:g} "
                                                    f"cutoffs ({cutoff:.3g} m)")
    else:
        record["used"] = True
    return record["used"], record


def pooled_statistics(hmaps, cutoff: float, route: str = "direct", key_value=None) -> PooledScans:
    """Summit statistics of the scans `hmaps` of one surface at `cutoff` (m), pooled over those that resolve it
    (module docstring). Raises TopographyError when no scan takes part or the pooled summits are fewer than
    MIN_SUMMITS."""
    if route not in ROUTES:
        raise TopographyError("surfaces.roughness.summit_route", route, f"must be one of {ROUTES}")
    key, value = key_value or (KEY_FILE, [h.source.get("file") for h in hmaps])
    used, scans, found = [], [], []
    for hmap in hmaps:
        ok, record = scan_record(hmap, cutoff)
        if ok:
            s = map_summits(hmap, cutoff)
            record["summits"] = s.count
            used.append(hmap)
            found.append(s)
        scans.append(record)
    if not used:
        if len(hmaps) == 1 and scans[0]["why_not"].startswith("its pixel"):
            raise TopographyError(KEY_CUTOFF, cutoff, f"must be >= {MIN_CUTOFF_PIXELS:g} pixels "
                                                      f"({scans[0]['resolves_wavelengths_m'][0]:.3g} m on this map)")
        raise TopographyError(KEY_CUTOFF, cutoff, "no scan takes part at this cutoff: " +
                              "; ".join(f"{r['file']}: {r['why_not']}" for r in scans))
    pooled = Summits(x=np.concatenate([s.x for s in found]), y=np.concatenate([s.y for s in found]),
                     height=np.concatenate([s.height for s in found]),
                     curvature=np.concatenate([s.curvature for s in found]),
                     radius=np.concatenate([s.radius for s in found]), area=float(sum(s.area for s in found)),
                     cutoff=float(cutoff))
    if pooled.count < MIN_SUMMITS:
        sizes = " + ".join(f"{h.physical_size[0]:.3g} x {h.physical_size[1]:.3g} m" for h in used)
        raise TopographyError(key, value, f"the {sizes} map holds {pooled.count} summits at summit_cutoff "
                                          f"{cutoff:.3g} m; summit statistics need >= {MIN_SUMMITS}: a larger map or "
                                          "a shorter cutoff")
    areas = np.array([h.physical_size[0] * h.physical_size[1] for h in used])
    moments = np.array([profile_moments(*areal_moments(h.topography(), cutoff)) for h in used])
    spectral = spectral_from_moments(*(areas @ moments / areas.sum()))
    direct = direct_summary(pooled)
    chosen = spectral if route == "spectral" else direct
    rms = float(np.sqrt(np.sum(areas * np.array([h.rms_height**2 for h in used])) / areas.sum()))
    statistics = SurfaceStatistics(rms_height=rms, summit_height_std=chosen.summit_height_std,
                                   summit_density=chosen.summit_density, summit_radius=chosen.summit_radius,
                                   route=route, cutoff=float(cutoff), spectral=spectral, direct=direct)
    mean, std = float(np.mean(pooled.height)), float(np.std(pooled.height))
    for record, s in zip([r for r in scans if r["used"]], found):
        record["tallest_summit_sigma"] = float((np.max(s.height) - mean) / std) if s.count and std > 0 else None
    return PooledScans(statistics, pooled, used, scans)


def data_depth(pooled: PooledScans, sigma: float, density: float, body_radius: float, length: float | None) -> dict:
    """How deep the maps' data reach against how deep the impact reaches (module docstring; heights in units of
    the summit heights' standard deviation)."""
    h = pooled.summits.height
    n = int(h.size)
    tallest = float((np.max(h) - np.mean(h)) / np.std(h))
    out = {"summits_on_maps": n, "tallest_summit_sigma": tallest,
           "gaussian_expected_tallest_of_map_sigma": float(expected_max_height(n)),
           "summit_height_excess_kurtosis": float(sps.kurtosis(h)),
           "summit_height_skewness": float(sps.skew(h)),
           "impact_tallest_summit_sigma": None, "summits_in_footprint": None, "footprint_half_width_m": None}
    if length is None:
        out["impact_note"] = "a sphere: the strip datum (continuum.rough.datum) is defined for a roller"
        return out
    try:
        datum = tallest_summit(sigma, density, body_radius, length)
    except ValueError as exc:
        out["impact_note"] = str(exc)
        return out
    out.update({"impact_tallest_summit_sigma": datum["z_max"], "summits_in_footprint": datum["summits_in_footprint"],
                "footprint_half_width_m": datum["footprint_half_width"],
                "tail_extrapolated": bool(datum["z_max"] > tallest),
                "what": "the maps' tallest summit (about the summits' mean, in sigma_s) against the expected tallest "
                        "of the summits in the roller's strip, which touches first (continuum.rough.datum)"})
    return out


def validity(pooled: PooledScans, depth: dict, body_radius: float, cutoff: float) -> tuple[list[dict], list[str]]:
    """(checks, warnings) of the range of validity (module docstring); raises TopographyError (KEY_CUTOFF) where
    the summit radius is not below the body's."""
    st = pooled.statistics
    checks, warnings = [], []

    def check(name, value, limit, verdict, text=None):
        checks.append({"check": name, "value": value, "limit": limit, "verdict": verdict})
        if text:
            warnings.append(text)

    ratio = st.summit_radius / body_radius
    if ratio >= MAX_RADIUS_RATIO:
        raise TopographyError(KEY_CUTOFF, cutoff, f"gives summit radius beta = {st.summit_radius:.3g} m >= "
                                                  f"body.radius {body_radius:.3g} m: the surface's 'summits' are "
                                                  "flatter than the body and Greenwood-Williamson summits do not "
                                                  "apply; a shorter cutoff, or a smooth-contact scene")
    check("summit_radius_over_body_radius", ratio, WARN_RADIUS_RATIO, "warning" if ratio > WARN_RADIUS_RATIO else "ok",
          f"summit radius beta = {st.summit_radius:.3g} m is {ratio:.2g} of body.radius ({body_radius:.3g} m), not "
          f"small (> {WARN_RADIUS_RATIO:g}): the summits are not small spheres under the body, and the GW "
          "model's contact stiffness and adhesion per summit are rough estimates here"
          if ratio > WARN_RADIUS_RATIO else None)
    half = depth.get("footprint_half_width_m")
    if half is not None:
        narrow = 2.0 * half < cutoff
        check("footprint_width_over_cutoff", 2.0 * half / cutoff, 1.0, "warning" if narrow else "ok",
              f"the body's strip (2 x_f = {2.0 * half:.3g} m) is narrower than the cutoff wavelength "
              f"{cutoff:.3g} m: the contact is smaller than one summit's width, which the GW average does not "
              "describe" if narrow else None)
    n = pooled.summits.count
    few = n < FEW_SUMMITS
    check("summits_on_maps", n, FEW_SUMMITS, "warning" if few else "ok",
          f"the maps hold {n} summits at the cutoff (< {FEW_SUMMITS}): their density carries a sampling error of "
          f"about {1.0 / math.sqrt(n):.0%} and sigma_s about {1.0 / math.sqrt(2.0 * n):.0%}" if few else None)
    spans = max(min(h.physical_size) for h in pooled.used) / cutoff
    small = spans < WARN_SPANS
    check("map_side_over_cutoff", spans, WARN_SPANS, "warning" if small else "ok",
          f"the largest map used spans only {spans:.3g} cutoff wavelengths (< {WARN_SPANS:g}): its wavelengths "
          "near the cutoff are few, and the summit statistics follow a handful of them" if small else None)
    if depth.get("tail_extrapolated"):
        check("impact_depth_over_data_depth", depth["impact_tallest_summit_sigma"], depth["tallest_summit_sigma"],
              "warning", f"the impact reaches summits {depth['impact_tallest_summit_sigma']:.3g} sigma_s above the "
              f"mean (the tallest of {depth['summits_in_footprint']:.3g} in the strip); the maps' tallest summit is "
              f"{depth['tallest_summit_sigma']:.3g} sigma_s (of {depth['summits_on_maps']}): the outcome rests on "
              "a summit-height tail the data do not reach (surface.data_depth)")
    return checks, warnings

