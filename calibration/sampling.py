"""Uncertainty samples of a calibration: a Latin hypercube over the calibrated values (each drawn from the normal of
its MD mean and stderr, truncated to the scene key's allowed range) and the user's ranges (uniform), and the job
that reruns the recipe's scene for one sample (`calibration.pipeline` runs them on its executor)."""
from __future__ import annotations

import math

import numpy as np

from continuum.api import FIELD_BY_PATH as SCENE_FIELDS


def latin_hypercube(n: int, dims: int, rng: np.random.Generator) -> np.ndarray:
    """n points in [0, 1)^dims, each dimension's n strata hit exactly once (McKay et al. 1979)."""
    u = (rng.random((n, dims)) + np.arange(n)[:, None]) / n
    for j in range(dims):
        u[:, j] = u[rng.permutation(n), j]
    return u


def sampling_bounds(key: str) -> tuple[float, float]:
    """The interval a calibrated value of scene `key` is sampled on: the key's own allowed range
    (continuum.schema), or the real line for a key without one."""
    f = SCENE_FIELDS.get(key)
    lo = -math.inf if f is None or f.low is None else float(f.low)
    hi = math.inf if f is None or f.high is None else float(f.high)
    return lo, hi


def truncation(calibration: dict) -> dict[str, dict]:
    """{key: {low, high, outside}} for every calibrated value whose normal (MD mean, MD stderr) puts more than
    1e-4 of its probability outside the key's allowed range, i.e. where :func:`sample_inputs` truncates."""
    from scipy.stats import norm

    out = {}
    for key, v in calibration.items():
        if not v.get("stderr"):
            continue
        lo, hi = sampling_bounds(key)
        mu, sd = float(v["value"]), float(v["stderr"])
        outside = float(norm.cdf((lo - mu) / sd) + norm.sf((hi - mu) / sd))
        if outside > 1e-4:
            out[key] = {"low": lo if math.isfinite(lo) else None, "high": hi if math.isfinite(hi) else None,
                        "outside": outside}
    return out


def sample_inputs(calibration: dict, ranges: dict, n: int, seed: int) -> tuple[list[str], list[dict]]:
    """Latin-hypercube samples of the calibrated values and user ranges (uniform).

    A calibrated value is drawn from the normal with its MD mean and stderr, truncated to the scene key's allowed
    range (:func:`sampling_bounds`; ``scipy.stats.truncnorm``): a work of adhesion or an interaction range z0 whose
    stderr is a large fraction of its mean (z0 of bare silica over a few registries: `[meta.calibration]`) would
    otherwise be sampled negative, and the scene would refuse that sample, so the band would silently lose its
    low tail. Far from the bounds this is the plain normal; :func:`truncation` reports where it is not."""
    from scipy.stats import truncnorm

    normal = {k: (float(v["value"]), float(v["stderr"])) for k, v in calibration.items() if v.get("stderr")}
    keys = list(normal) + list(ranges)
    u = latin_hypercube(n, len(keys), np.random.default_rng(seed)) if keys else np.zeros((n, 0))
    dists = {}
    for key, (mu, sd) in normal.items():
        lo, hi = sampling_bounds(key)
        dists[key] = truncnorm((lo - mu) / sd, (hi - mu) / sd, loc=mu, scale=sd)
    samples = []
    for row in u:
        s = {}
        for j, key in enumerate(keys):
            if key in normal:
                s[key] = float(dists[key].ppf(min(max(row[j], 1e-9), 1 - 1e-9)))
            else:
                lo, hi = ranges[key]
                s[key] = float(lo + (hi - lo) * row[j])
        samples.append(s)
    return keys, samples


def uncertainty_sample(task: tuple) -> dict:
    """One sample: the scene with the set and the sampled overrides; rebounds and escape velocity. Picklable."""
    scene, params, overrides, max_bounces = task
    from continuum.api import (
        SceneError,
        contact_law,
        escape_velocity,
        first_impact_speed,
        load_scene,
        row_for_scene,
        run_scene,
        single_impact,
    )

    try:
        # a SAM's values describe nothing on a scene without one (row_for_scene): left out and said so
        used, left_out = row_for_scene(scene, params, {}, overrides)
        # the sample reads the mean-field trajectory: an ensemble that 'auto' would add goes unread
        resolved = load_scene(scene, params=params, overrides={"surfaces.roughness.mode": "mean_field", **used,
                                                               "numerics.max_bounces": max_bounces},
                              override_label="uncertainty sample")
        result = run_scene(resolved)
    except (SceneError, ValueError, RuntimeError) as exc:      # refused or failed: counted and reported
        return {"overrides": overrides, "error": str(exc)}
    h0 = result.release_height
    reb = result.rebound_heights()
    sc = resolved.scene
    v0 = first_impact_speed(resolved)
    law = contact_law(resolved, result.regime)      # the run's regime: nothing derived again
    esc, esc_error = None, None
    try:
        grid = [v0 * f for f in np.geomspace(0.05, 2.0, 8)]
        stuck = [v for v in grid if single_impact(law, sc.body.mass, sc.environment.gravity, v, sc.numerics.rtol).stuck]
        free = [v for v in grid if v not in stuck]
        if stuck and free and max(stuck) < min(free):
            esc = escape_velocity(law, sc.body.mass, sc.environment.gravity, max(stuck), min(free), rel_tol=1e-2,
                                  rtol=sc.numerics.rtol)["escape_velocity"]
    except (ValueError, RuntimeError) as exc:
        esc_error = str(exc)
    return {"overrides": overrides, "rebounds_over_h0": [r / h0 for r in reb[:3]],
            "rebound_count": sum(r > 1e-3 * h0 for r in reb), "escape_velocity": esc,
            **({"escape_error": esc_error} if esc_error else {}), **({"left_out": left_out} if left_out else {})}
