"""Where the mean-field (GW averaged) rough law stops describing the ensemble of discrete realisations.

For the paper's roller on rough silica (the `paper` set: JKR summits, rigid substrate, one impact), the release
height is swept from 100 nm to 100 um so that the expected number of summits in contact at the first impact, N_c
(the Hertz estimate of `continuum.model.estimates`, the number `auto` reads), runs from a few to several hundred on the
same surface. (Raising the summit density barely moves N_c: the datum, the tallest summit, rises with it.) At
each height the first impact's energy loss fraction L = 1 - h1/h0 of the mean field is compared with its mean
over an ensemble of discrete realisations (`continuum.dynamics.ensemble_run`), relative to that mean, with the mean's
standard error. Beyond ten contacts the departure falls like A/sqrt(N_c) (the datum, the realisation's tallest
summit, scatters, and the loss counts summits within a fixed depth of it); A is fitted by weighted least squares
(weights 1/s.e.^2) and the threshold is where the fit meets the tolerance (continuum.model.decisions.
ENSEMBLE_TOLERANCE): N* = (A / tolerance)^2. Each point's departure is also tested directly (beyond the tolerance
by more than two standard errors: `fails`).

    python benchmarks/bench_ensemble_threshold.py [--members 128] [--json docs/figures/ensemble_threshold.json]
        [--figure docs/figures/ensemble_threshold.png]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from continuum.dynamics.ensemble_run import run_ensemble
from continuum.dynamics.impact import run_impact
from continuum.model.decisions import ENSEMBLE_BELOW_CONTACTS, ENSEMBLE_TOLERANCE
from continuum.scene import resolve_scene

HEIGHTS = (1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4)
BASE = {"physics.half_space": "off", "physics.adhesion_law": "jkr", "numerics.max_bounces": 1,
        "surfaces.roughness.mode": "mean_field"}


def point(height: float, members: int, executor: str) -> dict:
    resolved = resolve_scene("rough_silica", params="paper", overrides={**BASE, "release_height": height},
                             override_label="threshold sweep")
    h0 = resolved.scene.release_height
    t = time.perf_counter()
    rec = run_impact(resolved).to_dict()
    t_mf = time.perf_counter() - t
    b = rec["bounces"][0]
    mf = (b["rebound_height"] or 0.0) / h0
    n_c = rec["models"]["regimes"]["expected_contacts"]
    ens = run_ensemble(resolved, members=members, seed=1, executor=executor)
    loss = 1.0 - ens.first_rebounds() / h0
    mean, se = float(loss.mean()), float(loss.std(ddof=1) / math.sqrt(loss.size))
    rel, rel_se = (1.0 - mf) / mean - 1.0, se / mean
    return {"release_height": height, "expected_contacts": n_c, "mean_field_first_rebound_over_h0": mf,
            "mean_field_loss": 1.0 - mf, "ensemble_mean_loss": mean, "ensemble_standard_error": se,
            "ensemble_std": float(loss.std(ddof=1)), "relative_departure": rel, "relative_standard_error": rel_se,
            "fails": abs(rel) > ENSEMBLE_TOLERANCE + 2.0 * rel_se,
            "stick_probability_first_impact": ens.stick_probability_first_impact,
            "mean_field_max_contacts": rec["models"].get("diagnostics", {}).get("max_contacts"),
            "members": members, "seconds_mean_field": t_mf, "seconds_ensemble": ens.wall_s}


#: The fit of departure = A / sqrt(N_c) uses the points with at least this many expected contacts.
FIT_MIN_CONTACTS = 10.0


def fit_amplitude(points: list[dict]) -> tuple[float, float]:
    """(A, its standard error) of relative departure = A / sqrt(N_c), weighted least squares over N_c >= 10."""
    pts = [p for p in points if p["expected_contacts"] >= FIT_MIN_CONTACTS]
    x = np.array([p["expected_contacts"] ** -0.5 for p in pts])
    y = np.array([p["relative_departure"] for p in pts])
    w = np.array([p["relative_standard_error"] ** -2 for p in pts])
    a = float(np.sum(w * x * y) / np.sum(w * x * x))
    return a, float(np.sum(w * x * x) ** -0.5)


def threshold(points: list[dict], tolerance: float = ENSEMBLE_TOLERANCE) -> float:
    """N_c where the fitted departure A / sqrt(N_c) equals `tolerance`."""
    a, _ = fit_amplitude(points)
    return (abs(a) / tolerance) ** 2


def figure(points: list[dict], n_star: float, path: Path) -> None:
    fig = Figure(figsize=(7, 4))
    ax = fig.subplots()
    n = np.array([p["expected_contacts"] for p in points])
    ax.errorbar(n, [p["relative_departure"] for p in points], yerr=[2 * p["relative_standard_error"] for p in points],
                fmt="o", ms=4, capsize=3, label="(mean-field loss) / (ensemble mean loss) - 1, +- 2 s.e.")
    ax.plot(n, [p["ensemble_std"] / p["ensemble_mean_loss"] for p in points], "^", ms=4, color="C2",
            label="member spread: std / mean of the loss")
    ax.axhspan(-ENSEMBLE_TOLERANCE, ENSEMBLE_TOLERANCE, color="C3", alpha=0.2, label="tolerance")
    ax.axhline(0.0, color="k", lw=0.5)
    a, _ = fit_amplitude(points)
    grid = np.geomspace(FIT_MIN_CONTACTS, max(n.max(), n_star) * 1.2, 50)
    ax.plot(grid, a / np.sqrt(grid), "-", color="C3", lw=1, label=f"fit {a:.3g} / sqrt(N_c)")
    ax.axvline(n_star, color="k", ls="--", lw=1, label=f"threshold N_c = {n_star:.3g}")
    ax.set_xscale("log")
    ax.set_xlabel("expected summits in contact N_c (first impact, Hertz estimate)")
    ax.set_ylabel("first impact's energy loss: relative")
    ax.set_title("paper roller on rough silica, release height swept (100 nm - 100 um)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=128)
    ap.add_argument("--executor", default="processes")
    ap.add_argument("--json", default="docs/figures/ensemble_threshold.json")
    ap.add_argument("--figure", default="docs/figures/ensemble_threshold.png")
    ap.add_argument("--replot", action="store_true", help="refit and redraw from the --json file's points")
    args = ap.parse_args()
    points = json.loads(Path(args.json).read_text())["points"] if args.replot else []
    for d in (() if args.replot else HEIGHTS):
        p = point(d, args.members, args.executor)
        print(json.dumps({k: (f"{v:.5g}" if isinstance(v, float) else v) for k, v in p.items()}), flush=True)
        points.append(p)
    n_star = threshold(points)
    a, a_se = fit_amplitude(points)
    out = {"fit": {"form": "relative departure = A / sqrt(N_c), N_c >= 10, weights 1/s.e.^2", "A": a,
                   "A_standard_error": a_se, "threshold_at_1_percent": threshold(points, 0.01)},
           "what": __doc__.splitlines()[0], "scene": "rough_silica", "params": "paper", "overrides": BASE,
           "tolerance_over_h0": ENSEMBLE_TOLERANCE,
           "criterion": "fit A / sqrt(N*) = tolerance; a point 'fails' where |L_mf / <L>_ens - 1| > tolerance "
                        "+ 2 s.e., L = 1 - h1/h0",
           "threshold_expected_contacts": n_star, "constant_in_code": ENSEMBLE_BELOW_CONTACTS, "points": points}
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(out, indent=2) + "\n")
    figure(points, n_star, Path(args.figure))
    print(f"threshold: N_c = {n_star:.4g} (code: {ENSEMBLE_BELOW_CONTACTS:g}); wrote {args.json}, {args.figure}")


if __name__ == "__main__":
    main()
