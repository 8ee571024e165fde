"""Cost of plastic summits in an ensemble against the elastic dry ensemble, measured in one run.

    .venv/bin/python benchmarks/bench_plastic_summits.py [--members 16] [--bounces 100] [--params calibrated]
                                                         [--release-height M] [--json FILE]

The `rough_silica` scene on the given parameter set (its hardness makes psi say the summits yield): the same N
ensemble members (seeds 1..N, the scene's first-impact plan) run each with `physics.plasticity = 'off'` (the
elastic dry members: the compiled discrete roller of the set's summit law) and with `'auto'` (each member's
realisation with Thornton-Ning summits on that law, `continuum.laws.plastic_rough`), `--bounces` impacts each,
in this process, one after the other (the shared tables built and the compiled kernel loaded first, untimed).
Reports the wall and CPU time of each, their ratios plastic/elastic and the load average (the cores are shared:
the CPU ratio moves less with load), and how many summits the first impact of the first members yielded: at the
scene's 100 nm drop none does (the impact is too gentle to reach the yield approach), so `--release-height`
gives a drop that yields. The issue's budget: ratio <= 2.

An ensemble run (`nanoimpact impact`) also integrates the trajectory on the mean-field law for comparison; with
plastic summits that law is the state-by-state NumPy sum (`continuum.rough.plastic_gw_branches`), against the
elastic law's footprint tables. `mean_field` times that trajectory (the same drop, `--bounces` impacts) with each
choice, and `ensemble_ratio...` adds it to the members' time.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from continuum.dynamics.driver import DriverSettings, simulate  # noqa: E402
from continuum.dynamics.ensemble_run import _release, member_law, member_plan, run_member  # noqa: E402
from continuum.dynamics.impact import run_impact  # noqa: E402
from continuum.model.regime import first_impact_speed  # noqa: E402
from continuum.scene import SceneError, resolve_scene  # noqa: E402

log = logging.getLogger("bench_plastic_summits")


def _resolved(params: str, plasticity: str, bounces: int, release_height: float | None = None, **more):
    overrides = {"physics.plasticity": plasticity, "numerics.max_bounces": bounces, **more}
    if release_height is not None:
        overrides["release_height"] = release_height
    return resolve_scene(ROOT / "inputs" / "scenes" / "rough_silica.toml", params=params, overrides=overrides)


def _scene(params: str, plasticity: str, bounces: int, release_height: float | None = None):
    return _resolved(params, plasticity, bounces, release_height).scene


def _mean_field(params: str, plasticity: str, bounces: int, release_height: float | None) -> dict:
    """The trajectory on the mean-field law (mode 'mean_field'), timed from the law's selection (tables built)."""
    start, cpu = time.perf_counter(), time.process_time()
    try:
        resolved = _resolved(params, plasticity, bounces, release_height, **{"surfaces.roughness.mode": "mean_field"})
        result = run_impact(resolved, condensation_sweep=False).record
    except SceneError as err:       # e.g. the elastic footprint tables' cost bound: what a run would say
        return {"refused": str(err), "wall_s": None, "cpu_s": None}
    return {"wall_s": time.perf_counter() - start, "cpu_s": time.process_time() - cpu,
            "law": result["models"]["contact_law"]["name"], "bounces": result["n_bounces"],
            "energy_audit": result["energy_audit"]["max_error_over_turnover"]}


def _yielded(scene, plan, seed: int) -> int:
    """Summits yielded by member `seed`'s first impact (untimed)."""
    member, law = member_law(scene, seed, plan)
    simulate(law, member.body.mass, member.environment.gravity, release_height=_release(member, float(law.z_top)),
             impact_velocity=member.impact_velocity, settings=DriverSettings(max_bounces=1))
    return int(law.diagnostics().get("summits_yielded", 0))


def measure(params: str, members: int, bounces: int, release_height: float | None = None, save=None) -> dict:
    out: dict = {"params": params, "members": members, "bounces": bounces, "release_height": release_height}
    for label, choice in (("elastic", "off"), ("plastic", "auto")):
        scene = _scene(params, choice, bounces, release_height)
        plan = member_plan(scene, first_impact_speed(scene))
        _, law = member_law(scene, 1, plan)             # build shared tables outside the timing
        run_member(_scene(params, choice, 1, release_height), members + 1, plan)   # and load the compiled kernel
        start, cpu = time.perf_counter(), time.process_time()
        runs = [run_member(scene, seed, plan) for seed in range(1, members + 1)]
        wall, cpu = time.perf_counter() - start, time.process_time() - cpu
        yielded = [_yielded(scene, plan, s) for s in range(1, min(members, 4) + 1)] if choice == "auto" else []
        out[label] = {"wall_s": wall, "cpu_s": cpu, "law": law.name, "first_impact_summits_yielded": yielded,
                      "statuses": [r.status for r in runs],
                      "rebounds": [len(r.rebound_heights) for r in runs],
                      "max_energy_error": max(r.energy_error for r in runs)}
        log.info("%s: %s, %d members x %d bounces in %.2f s (%.2f s CPU)", label, law.name, members, bounces, wall,
                 cpu)
    out["ratio_plastic_over_elastic"] = out["plastic"]["wall_s"] / out["elastic"]["wall_s"]
    out["cpu_ratio_plastic_over_elastic"] = out["plastic"]["cpu_s"] / out["elastic"]["cpu_s"]
    out["load_average_members"] = os.getloadavg()
    if save is not None:
        save(out)                   # the members' ratio first: the mean-field trajectories can take long
    out["mean_field"] = {}
    for label, choice in (("elastic", "off"), ("plastic", "auto")):
        out["mean_field"][label] = mf = _mean_field(params, choice, bounces, release_height)
        log.info("mean field %s: %s", label, mf.get("refused") or f"{mf['law']} in {mf['wall_s']:.2f} s "
                 f"({mf['cpu_s']:.2f} s CPU)")
    if all(out["mean_field"][k]["cpu_s"] is not None for k in ("elastic", "plastic")):
        for kind, key in (("wall_s", "ensemble_ratio_with_trajectory"),
                          ("cpu_s", "ensemble_cpu_ratio_with_trajectory")):
            out[key] = ((out["plastic"][kind] + out["mean_field"]["plastic"][kind])
                        / (out["elastic"][kind] + out["mean_field"]["elastic"][kind]))
    out["load_average"] = os.getloadavg()
    out["machine"] = {"python": platform.python_version(), "platform": platform.platform()}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", default="calibrated")
    ap.add_argument("--members", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=100)
    ap.add_argument("--release-height", type=float, help="m; default: the scene's (100 nm)")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    def save(out):
        if args.json:
            args.json.write_text(json.dumps(out, indent=1))
    res = measure(args.params, args.members, args.bounces, args.release_height, save=save)
    text = json.dumps(res, indent=1)
    save(res)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
