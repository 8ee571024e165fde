"""Wall time of the foundation's impact runs (a script, not a timed test).

    python benchmarks/bench_foundation.py [--repeat 5]

Reports the best and median of N repeats for: the paper's Hertz roller, 20 bounces, with the
implicit log stiffness and with constant K; and the JKR sphere scene, 10 bounces. All numbers
come from one run of this script, so their ratios are comparable.
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from continuum.dynamics.impact import run_impact
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parent.parent
CASES = [
    ("hertz roller, implicit K, 20 bounces", "hertz_roller.toml"),
    ("hertz roller, constant K, 20 bounces", "hertz_roller_constant_k.toml"),
    ("JKR sphere, to stiction (11 rebounds)", "jkr_sphere.toml"),
]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    print(f"{'case':40s} {'impacts':>7s} {'best s':>9s} {'median s':>9s} {'per impact ms':>14s} {'audit':>9s}")
    for label, file in CASES:
        resolved = resolve_scene(ROOT / "inputs" / "scenes" / file)
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            result = run_impact(resolved).to_dict()
            times.append(time.perf_counter() - start)
        n = result["n_bounces"]
        print(f"{label:40s} {n:7d} {min(times):9.4f} {statistics.median(times):9.4f} "
              f"{1e3 * min(times) / n:14.3f} {result['energy_audit']['max_relative_error']:9.1e}")


if __name__ == "__main__":
    main()
