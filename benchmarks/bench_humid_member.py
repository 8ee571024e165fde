"""CPU of one compiled humid member run (wet plastic and wet elastic summits), the first (compiling) run apart.

    python benchmarks/bench_humid_member.py [--repeat 4]

A `wet_silica` member (`continuum.dynamics.ensemble_run.member_law`, fixed condensation at 20 ns) dropped from
0.3 mm, three bounces, compiled, for the `calibrated` set (yielding summits: `continuum.numerics.wet_plastic_kernel`)
and the `paper` set (elastic summits). To compare two versions of the code in one session, run it once as is and once
with PYTHONPATH at an export of the other version (`git archive REV continuum nanoimpact | tar -x -C DIR`), each with
NUMBA_CACHE_DIR at an empty folder of its own.
"""
from __future__ import annotations

import argparse
import os
import time

import continuum
from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.ensemble_run import member_law, member_plan
from continuum.model.regime import first_impact_speed
from continuum.scene import resolve_scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=4, help="member runs per set (the first compiles)")
    args = parser.parse_args()
    print(f"code: {os.path.dirname(continuum.__file__)}; load average {os.getloadavg()[0]:.2f}")
    for params in ("calibrated", "paper"):
        scene = resolve_scene("wet_silica", params=params, overrides={
            "surfaces.roughness.mode": "ensemble", "menisci.condensation_model": "fixed",
            "menisci.condensation_time": 2e-8}).scene
        times = []
        for _ in range(args.repeat):
            _, law = member_law(scene, 1, member_plan(scene, first_impact_speed(scene)))
            t0 = time.process_time()
            simulate(law, scene.body.mass, 9.81, release_height=3e-4,
                     settings=DriverSettings(rtol=1e-8, max_bounces=3, compiled=True))
            times.append(time.process_time() - t0)
        print(f"{params}: CPU per member run (s), the first compiling: " + " ".join(f"{t:.3f}" for t in times))
    print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
