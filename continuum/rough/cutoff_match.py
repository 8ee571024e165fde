"""The summit scale measured by the boundary-element reference: the summit cutoff at which the discrete summits
of a map lose, per quasi-static approach-retraction cycle, the energy the reference loses on the same map.

Summit radius and density depend on the short-wavelength cutoff at which a map's summits are taken (Greenwood &
Wu, Meccanica 36 (2001) 617: the summit picture has no intrinsic scale), and the energy lost per impact with them
(audit 3, finding 2). The reference (`continuum.rough.bem_reference`: Tamaas boundary elements, Dugdale's law
matched to the Maugis-Dugdale summit law) has no summits: it solves the whole map. The discrete level
(`continuum.rough.quasistatic.discrete_cycle`) takes the map's summits at a cutoff lambda_c, each at its own height,
all of their mean tip radius, with the Maugis-Dugdale summit law. Its loss per cycle L_d(lambda_c) is evaluated on a
ladder of cutoffs, and the measured cutoff is where log L_d crosses log L_ref (linear in log lambda_c between the
two bracketing rungs); the match error is the distance of the nearest rung's loss from L_ref.

The reference's loss must be converged in the pixel for this to mean anything (`continuum.rough.bem_convergence`);
where it is not, L_ref is the first-order extrapolation of the two finest grids (or their finest loss where that
is not positive), the finest loss bounds it from above, and the record says so (`reference_converged`,
`cutoff_at_upper_bound_m`).

The match runs once per map and law: `measured_cutoff` caches it by the hash of the heights, the patch size, the
law's parameters and the ladder (`nanoimpact.fileio.atomic_write_json`, under $NANOIMPACT_CACHE/bem or
~/.cache/nanoimpact/bem).
"""
from __future__ import annotations

import hashlib
import json
import logging
import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from SurfaceTopography import Topography

from nanoimpact.errors import InputError
from nanoimpact.fileio import atomic_write_json

from .bem_convergence import GridRun, cohesive_zone_length, convergence
from .bem_reference import bem_cycle, dugdale_range, require_solver
from .branch_laws import make_summit_law
from .quasistatic import discrete_cycle, separation_path
from .topography import identify_summits

__all__ = ["CutoffMatch", "discrete_loss", "match_cutoff", "cache_key", "cache_dir", "measured_cutoff",
           "scene_cutoff", "CUTOFF_PIXELS", "MATCH_VERSION", "MAX_GRID", "MIN_ZONE_PIXELS", "KEY_CUTOFF_FROM"]

log = logging.getLogger(__name__)

#: The ladder of cutoffs, in pixels of the map as given (>= 4: `topography.MIN_CUTOFF_PIXELS`).
CUTOFF_PIXELS = (4, 6, 8, 12, 16, 24, 32)
#: Bumped when the match's method changes, so that cached matches of the old method are not reused.
MATCH_VERSION = 2
#: The scene key that asks for the measured cutoff.
KEY_CUTOFF_FROM = "surfaces.roughness.summit_cutoff_from"
#: Largest map (points per side) a scene may send to the reference: its cycle costs ~n^3.4 CPU (bem_convergence's
#: measured growth; ~1 CPU min at 128^2 on the benchmark's patch).
MAX_GRID = 256
#: Pixels the cohesive zone E* dgamma / sigma0^2 must span on the map's own grid (the reference's finest).
MIN_ZONE_PIXELS = 4.0


@dataclass(frozen=True)
class CutoffMatch:
    """The measured summit cutoff of one map and law."""

    cutoff: float | None
    """Cutoff wavelength (m) at which the discrete level's loss per cycle equals the reference's; None when no
    cutoff of the ladder brackets it."""
    match_error: float
    """(L_d - L_ref)/L_ref at the ladder's rung nearest the match (or at the closest rung when none brackets)."""
    reference_loss: float
    """L_ref (J) matched."""
    reference_converged: bool
    """Whether the reference's loss per cycle converged in the pixel (`bem_convergence.convergence`)."""
    cutoff_at_upper_bound: float | None
    """The cutoff matching the reference's finest-grid loss, its upper bound (m); None when none brackets it."""
    ladder: list = field(default_factory=list)
    """Per rung: cutoff_m, cutoff_pixels, summits, summit_radius_m, loss_J."""
    reason: str = ""
    """Why there is no cutoff, or what it rests on."""

    def origin(self) -> dict:
        """The `summit_cutoff` origin a scene records: kind "bem" with the match error and what it rests on."""
        return {"kind": "bem", "cutoff_m": self.cutoff, "match_error": self.match_error,
                "reference_loss_J": self.reference_loss, "reference_converged": self.reference_converged,
                "cutoff_at_upper_bound_m": self.cutoff_at_upper_bound, "note": self.reason}

    def to_json(self) -> dict:
        return asdict(self)


def discrete_loss(heights: np.ndarray, size: float, cutoff: float, e_star: float, work_of_adhesion: float,
                  z0: float, path: np.ndarray) -> dict:
    """Loss per cycle (J) of the map's summits at `cutoff` (m), each at its own height, all of the mean tip radius,
    Maugis-Dugdale, along `path` (m above the heights' mean plane); with the summit count and mean radius.

    Exact: a summit whose approach reaches its jump-in delta_in is on the retreat branch from there to its jump-out
    whatever the turn, so it loses the law's loop_energy once per cycle and the level loses (number jumped in) x
    loop_energy. The trapezoid loop along the sampled path (`loss_sampled_J`) misses or overcounts each summit's
    sliver of loop (narrower than a step of rho/8 at lambda < 1) and is kept for comparison only."""
    h = np.asarray(heights, float)
    summits = identify_summits(h - h.mean(), size / h.shape[0], cutoff, periodic=True)
    keep = np.isfinite(summits.radius)
    z, beta = summits.height[keep], summits.radius[keep]
    row = {"cutoff_m": float(cutoff), "cutoff_pixels": float(cutoff * h.shape[0] / size), "summits": int(keep.sum())}
    if not keep.any():
        return {**row, "summit_radius_m": math.nan, "loss_J": 0.0}
    radius = float(np.mean(beta))
    delta_max = 1.5 * float(z.max() - np.min(path)) + 10 * z0
    law = make_summit_law("maugis_dugdale", radius, work_of_adhesion, e_star, z0=z0, delta_max=delta_max)
    touched = int(np.sum(z - np.min(path) >= law.delta_in))
    return {**row, "summit_radius_m": radius, "summits_jumped_in": touched, "loss_J": touched * law.loop_energy,
            "loss_sampled_J": discrete_cycle(law, z, path).hysteresis_energy}


def _crossing(ladder: list[dict], target: float) -> float | None:
    """Cutoff (m) where log L_d crosses log target, interpolated in log cutoff between bracketing rungs (the first
    crossing from the smallest cutoff); None when no pair of rungs brackets it."""
    c = np.array([r["cutoff_m"] for r in ladder])
    loss = np.array([r["loss_J"] for r in ladder])
    if not target > 0:
        return None
    for k in range(len(c) - 1):
        lo, hi = loss[k], loss[k + 1]
        if lo > 0 and hi > 0 and (lo - target) * (hi - target) <= 0 and lo != hi:
            t = (math.log(target) - math.log(lo)) / (math.log(hi) - math.log(lo))
            return float(math.exp(math.log(c[k]) + t * (math.log(c[k + 1]) - math.log(c[k]))))
    return None


def match_cutoff(ladder: list[dict], reference_loss: float, upper_bound: float, converged: bool) -> CutoffMatch:
    """The match on a computed ladder (`discrete_loss` rows, increasing cutoff) against the reference's loss
    `reference_loss` (J) and its finest-grid value `upper_bound` (J)."""
    if len(ladder) < 2:
        raise InputError("cutoff_match.ladder", len(ladder), "at least two cutoffs")
    if not (np.isfinite(reference_loss) and reference_loss > 0):
        raise InputError("cutoff_match.reference_loss", reference_loss, "a positive finite loss per cycle (J)")
    cutoff = _crossing(ladder, reference_loss)
    nearest = min(ladder, key=lambda r: abs(math.log(r["cutoff_m"] / cutoff)) if cutoff else
                  abs(math.log(max(r["loss_J"], 1e-300) / reference_loss)))
    error = (nearest["loss_J"] - reference_loss) / reference_loss
    basis = "the converged reference" if converged else (
        "the first-order pixel extrapolation of an unconverged reference (its finest loss is an upper bound: "
        "cutoff_at_upper_bound_m)")
    if cutoff is None:
        losses = [r["loss_J"] for r in ladder]
        reason = (f"no cutoff from {ladder[0]['cutoff_m']:.3g} to {ladder[-1]['cutoff_m']:.3g} m brings the "
                  f"discrete loss ({min(losses):.3g} to {max(losses):.3g} J) to the reference's "
                  f"{reference_loss:.3g} J ({basis})")
    else:
        reason = f"matched to {basis}; match error at the nearest rung ({nearest['cutoff_m']:.3g} m)"
    return CutoffMatch(cutoff, float(error), float(reference_loss), bool(converged), _crossing(ladder, upper_bound),
                       list(ladder), reason)


def cache_key(heights: np.ndarray, size: float, e_star: float, work_of_adhesion: float, z0: float,
              settings: dict) -> str:
    """sha256 of the heights (float64, C order), the patch size, the law's parameters and the ladder settings."""
    digest = hashlib.sha256(np.ascontiguousarray(np.asarray(heights, np.float64)).tobytes())
    digest.update(json.dumps({"size": float(size), "e_star": float(e_star), "work_of_adhesion": float(work_of_adhesion),
                              "z0": float(z0), "version": MATCH_VERSION, **settings}, sort_keys=True).encode())
    return digest.hexdigest()


def cache_dir(root: str | Path | None = None) -> Path:
    """Where matches are cached: `root`, else $NANOIMPACT_CACHE/bem, else ~/.cache/nanoimpact/bem."""
    if root:
        return Path(root).expanduser()
    env = os.environ.get("NANOIMPACT_CACHE", "").strip()
    return (Path(env).expanduser() if env else Path("~/.cache/nanoimpact").expanduser()) / "bem"


def fourier_resample(heights: np.ndarray, n: int) -> np.ndarray:
    """A periodic map on n x n points by zero-padding or truncating its spectrum (exact when band-limited below
    both grids' Nyquist wavelengths)."""
    m = heights.shape[0]
    if n == m:
        return heights
    if n > m:
        return np.asarray(Topography(heights, (1.0, 1.0), periodic=True).interpolate_fourier((n, n)).heights())
    spec = np.fft.fft2(heights)
    k = np.fft.fftfreq(m, 1.0 / m)
    keep = np.abs(k) < n / 2
    kk = k[keep].astype(int) % n
    out = np.zeros((n, n), complex)
    out[np.ix_(kk, kk)] = spec[np.ix_(keep, keep)]
    return np.real(np.fft.ifft2(out)) * (n * n) / (m * m)


def measured_cutoff(heights, size: float, e_star: float, work_of_adhesion: float, z0: float, *,
                    grids: tuple[int, ...] | None = None, depth_in_summit_std: float = 0.5,
                    cutoffs_pixels: tuple[float, ...] = CUTOFF_PIXELS, cache: str | Path | None = None) -> dict:
    """The measured cutoff of a square periodic map (heights m, side `size` m) with its BEM ladder, cached.

    The reference runs on `grids` (Fourier-resampled; default: the map's own grid, its half and its quarter),
    along the path from 2 rho above the tallest point down to
    the mean summit height (at the smallest cutoff) + `depth_in_summit_std` summit standard deviations, in steps
    of rho/8. Returns {"match": CutoffMatch.to_json(), "origin": ..., "bem_convergence": ..., "cached": bool}."""
    h = np.asarray(heights, float)
    if h.ndim != 2 or h.shape[0] != h.shape[1]:
        raise InputError("summit_cutoff", f"map of shape {h.shape}", '"bem" needs a square periodic map')
    h = h - h.mean()
    grids = grids or (h.shape[0] // 4, h.shape[0] // 2, h.shape[0])
    settings = {"grids": list(grids), "depth": depth_in_summit_std, "cutoffs_pixels": list(cutoffs_pixels)}
    key = cache_key(h, size, e_star, work_of_adhesion, z0, settings)
    path_file = cache_dir(cache) / f"cutoff-{key[:24]}.json"
    if path_file.is_file():
        stored = json.loads(path_file.read_text())
        if stored.get("key") == key:
            log.info("summit cutoff from the BEM: cached %s", path_file)
            return {**stored, "cached": True}
    require_solver(KEY_CUTOFF_FROM, "bem")              # a cache hit needs no solver; a run does
    pixel = size / h.shape[0]
    _, rho = dugdale_range(work_of_adhesion, z0)
    base = identify_summits(h, pixel, cutoffs_pixels[0] * pixel, periodic=True)
    deepest = float(np.mean(base.height) + depth_in_summit_std * np.std(base.height))
    path = separation_path(float(h.max()) + 2 * rho, deepest, rho / 8)
    runs = []
    for n in grids:
        cyc, stats = bem_cycle(fourier_resample(h, n), size, e_star, work_of_adhesion, z0, path)
        runs.append(GridRun(n, size / n, cyc.pull_off_force, cyc.hysteresis_energy, stats.seconds, stats.unconverged))
        log.info("summit cutoff from the BEM: grid %d^2, loss %.4g J, %.1f s", n, cyc.hysteresis_energy, stats.seconds)
    record = convergence(runs, cohesive_zone_length(e_star, work_of_adhesion, z0), size)
    upper = min(runs, key=lambda r: r.pixel).loss
    ref = reference_estimate(record)
    ladder = [discrete_loss(h, size, c * pixel, e_star, work_of_adhesion, z0, path) for c in cutoffs_pixels]
    match = match_cutoff(ladder, ref, upper, record["converged"])
    out = {"key": key, "match": match.to_json(), "origin": match.origin(), "bem_convergence": record}
    atomic_write_json(path_file, out)
    return {**out, "cached": False}


def reference_estimate(record: dict) -> float:
    """The reference's loss per cycle to match (J): the finest grid's when converged, else the first-order
    extrapolation of the two finest grids where positive, else the finest grid's (an upper bound)."""
    finest = record["grids"][-1]["hysteresis_energy_J"]
    if record["converged"]:
        return float(finest)
    rich = record["loss_richardson_J"][-1] if record["loss_richardson_J"] else math.nan
    return float(rich) if np.isfinite(rich) and rich > 0 else float(finest)


def scene_cutoff(heights, size: float, periodic: bool, e_star: float, work_of_adhesion: float, z0: float, *,
                 cache: str | Path | None = None) -> tuple[float, dict]:
    """(cutoff (m), origin) for a scene that asks `summit_cutoff_from = "bem"`: the measured cutoff of its map, run
    once and cached (`measured_cutoff` on the map's own grid, half and quarter). Refused, naming the key, where the
    reference cannot stand: a map that is not square, larger than MAX_GRID^2, or whose grid does not resolve the
    cohesive zone (MIN_ZONE_PIXELS), or a ladder that brackets no cutoff. A measured map is treated as periodic
    (its wrap-around step is part of the reference); the origin says so."""
    h = np.asarray(heights, float)
    if h.ndim != 2 or h.shape[0] != h.shape[1] or h.shape[0] > MAX_GRID:
        raise InputError(KEY_CUTOFF_FROM, "bem", f"needs a square map of at most {MAX_GRID}^2 points (this one: "
                                                 f"{h.shape}): the reference's cycle grows as ~n^3.4")
    zone = cohesive_zone_length(e_star, work_of_adhesion, z0)
    pixel = size / h.shape[0]
    if zone < MIN_ZONE_PIXELS * pixel:
        raise InputError(KEY_CUTOFF_FROM, "bem", f"needs the cohesive zone E* dgamma/sigma0^2 = {zone:.3g} m to span "
                                                 f">= {MIN_ZONE_PIXELS:g} pixels of the map ({pixel:.3g} m): use a "
                                                 "smaller patch or a finer map")
    found = measured_cutoff(h, size, e_star, work_of_adhesion, z0, cache=cache)
    origin = dict(found["origin"], cached=found["cached"], periodic_map=bool(periodic),
                  bem_loss_converged=found["bem_convergence"]["converged"],
                  bem_not_converged=found["bem_convergence"]["not_converged"])
    if origin["cutoff_m"] is None:
        raise InputError(KEY_CUTOFF_FROM, "bem", f"found no cutoff: {origin['note']}")
    return float(origin["cutoff_m"]), origin
