"""Error of the `fast` and `standard` presets against `reference` on the paper's rough cases, beside their cost.

    python benchmarks/bench_fidelity.py [--params paper] [--cases rough_silica,rough_ots]

For each case and preset: first rebound height, first impact duration, rebounds before sticking,
wall time; errors are relative to the `reference` run of the same case. One run of this script
gives all the numbers, so the cost ratios are comparable.
"""
from __future__ import annotations

import argparse
import time

from continuum.dynamics.impact import run_impact
from continuum.paper.cases import Case, sigma_case
from continuum.paper.checks import rebounds
from continuum.paper.run import resolve_case

CASES = {"rough_silica": Case("rough_silica", "rough_silica.toml", {"physics.half_space": "off"}),
         "rough_ots": Case("rough_ots", "rough_ots.toml", {"numerics.max_bounces": 30}),
         "sigma_10nm": sigma_case(10.0)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", default="paper")
    parser.add_argument("--cases", default="rough_silica,rough_ots,sigma_10nm")
    args = parser.parse_args(argv)
    print(f"{'case':14s} {'preset':10s} {'wall s':>8s} {'impacts':>7s} {'rebounds':>8s} "
          f"{'1st rebound err':>16s} {'1st duration err':>17s} {'audit':>8s}")
    for name in args.cases.split(","):
        runs = {}
        for preset in ("reference", "standard", "fast"):
            resolved = resolve_case(CASES[name], args.params, preset)
            start = time.perf_counter()
            result = run_impact(resolved).to_dict()
            runs[preset] = (result, time.perf_counter() - start)
        ref = runs["reference"][0]
        h_ref, t_ref = rebounds(ref)[0] if rebounds(ref) else None, ref["bounces"][0]["duration"]
        for preset, (res, wall) in runs.items():
            reb = rebounds(res)
            e_h = (reb[0] / h_ref - 1) if (reb and h_ref) else float("nan")
            e_t = (res["bounces"][0]["duration"] / t_ref - 1) if t_ref else float("nan")
            print(f"{name:14s} {preset:10s} {wall:8.2f} {res['n_bounces']:7d} {len(reb):8d} {e_h:16.2e} {e_t:17.2e} "
                  f"{res['energy_audit']['max_relative_error']:8.1e}")


if __name__ == "__main__":
    main()
