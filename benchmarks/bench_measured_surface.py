"""Seconds and memory of the whole measured-surface answer (target: <= 60 s on 2 cores and <= 1 GB): the calibrated
roller of `rough_topography` on a height map, `members = "auto"`, both tail models and the cutoff band, end to end
(`continuum.dynamics.impact.run_impact`: the map's statistics, the mean-field run, the scene's ensemble, the other tail
model's and the band's ensembles).

    python benchmarks/bench_measured_surface.py PATH [--cutoff M] [--workers 2] [--executor processes]
                                                [--set KEY=VALUE ...] [--json FILE]

PATH: any height map SurfaceTopography reads (default cutoff: the shipped synthetic map's 0.3125 um; give the
cutoff of a measured scan). Reported: wall seconds, CPU seconds (user + system of this process and its ended worker
processes), the peak resident memory of this process and of the largest worker (`ru_maxrss`), the machine's load
average before and after, the members each ensemble ran and why the 'auto' rule stopped, and the stick
probabilities: on a shared machine the CPU seconds are the steadier measure of cost.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import resource
import time
import tomllib

from continuum.dynamics.impact import run_impact
from continuum.numerics.compiled_contact import warm_up
from continuum.scene import resolve_scene

log = logging.getLogger("bench_measured_surface")


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its children that have ended (the pool's workers)."""
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                  resource.getrusage(resource.RUSAGE_CHILDREN)))


def _override(text: str) -> tuple[str, object]:
    key, _, value = text.partition("=")
    try:
        return key.strip(), tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return key.strip(), value.strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("path", help="height map file")
    ap.add_argument("--cutoff", type=float, default=0.3125e-6, help="summit cutoff wavelength (m)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--executor", default="processes", choices=("processes", "local"))
    ap.add_argument("--set", action="append", default=[], type=_override, metavar="KEY=VALUE")
    ap.add_argument("--json", help="write the numbers here")
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    overrides = {"surfaces.roughness.topography": os.path.abspath(args.path),
                 "surfaces.roughness.summit_cutoff": args.cutoff, **dict(args.set)}
    warm_up()                                   # the compiled kernel loads once, before the clock
    load_before = os.getloadavg()[0]
    cpu, start = cpu_seconds(), time.perf_counter()
    resolved = resolve_scene("rough_topography", overrides=overrides, override_label="bench")
    result = run_impact(resolved, executor=args.executor, workers=args.workers).to_dict()
    wall = time.perf_counter() - start
    ens = result.get("ensemble") or {}
    band = result["surface"].get("cutoff_band") or []
    row = {"map": overrides["surfaces.roughness.topography"], "cutoff_m": args.cutoff, "executor": args.executor,
           "workers": args.workers, "wall_s": wall, "cpu_s": cpu_seconds() - cpu,
           "peak_rss_mb_main": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
           "peak_rss_mb_largest_worker": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0,
           "load_average_before": load_before, "load_average_after": os.getloadavg()[0],
           "law": result["models"]["adhesion"].get("law"), "mode": result["models"]["realisation"]["mode"],
           "members": ens.get("members"), "members_rule": ens.get("members_rule"),
           "stick_probability": ens.get("stick_probability"),
           "tail_models": {k: {"members": v.get("members"), "stick": v.get("stick_probability_first_impact")}
                           for k, v in (ens.get("tail_models") or {}).items()},
           "cutoff_band": [{k: e.get(k) for k in ("factor", "cutoff", "summit_radius", "members", "stick_probability")}
                           for e in band],
           "warnings": result["warnings"]}
    log.info("%s", json.dumps(row, indent=1))
    log.info("wall %.1f s, CPU %.1f s, peak RSS %.0f MB (main) / %.0f MB (largest worker); members %s + %s",
             wall, row["cpu_s"], row["peak_rss_mb_main"], row["peak_rss_mb_largest_worker"], row["members"],
             [e.get("members") for e in band if e.get("factor") != 1.0] + [v["members"] for v in
                                                                         row["tail_models"].values()][1:])
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(row, fh, indent=1)


if __name__ == "__main__":
    main()
