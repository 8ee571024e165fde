"""Cost of an ensemble whose summits carry menisci against the elastic dry ensemble of the same members.

wet_silica on the `calibrated` set, an ensemble of `--members` realisations (same master seed, so the same summits),
run in this process one after another (executor 'local'), each case `--repeat` times, the best wall and CPU (process)
time kept (on a shared machine the CPU time is the steadier of the two):

- dry: environment.relative_humidity = 0 (the members carry no bridges);
- humid, nucleation t_a: the set's own t_a (ms), which no contact reaches: the wet law is its dry law up to t_a
  (compiled, stopped at t_a), so the cost is the dry cost plus the bridges' bookkeeping;
- humid, short t_a (`--short-ta`, s, fixed): bridges form in most contacts, and after t_a a contact runs in the
  Python stepper with each summit's bridge and its wet summit law (continuum.laws.wet_summits): the worst case.

The ratios (humid / dry) are the numbers docs/benchmarks.md quotes; every number comes from one run of this script.

    python benchmarks/bench_wet_ensemble.py [--members 16] [--bounces 20] [--short-ta 1e-6] [--repeat 2] [--json P]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from continuum.dynamics.ensemble_run import run_ensemble
from continuum.numerics.compiled_contact import warm_up
from continuum.scene import resolve_scene


def case(label: str, overrides: dict, members: int, repeat: int) -> dict:
    resolved = resolve_scene("wet_silica", params="calibrated", overrides=overrides, override_label=label)
    best, cpu, rec = float("inf"), float("inf"), None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        rec = run_ensemble(resolved, members=members, seed=1, executor="local").to_record()
        best, cpu = min(best, time.perf_counter() - t), min(cpu, time.process_time() - c)
    men = rec["menisci"]
    return {"case": label, "seconds": best, "cpu_seconds": cpu, "members": members,
            "members_with_bridges": men.get("members_with_bridges", 0), "menisci_carried": men["carried"],
            "stick_probability_within_run": rec["stick_probability"]["within_run"]["value"],
            "energy_audit_max_relative_error": rec["energy_audit_max_relative_error"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=20)
    ap.add_argument("--short-ta", type=float, default=1e-6)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    warm_up()
    base = {"surfaces.roughness.mode": "ensemble", "numerics.max_bounces": a.bounces}
    rows = [case("dry", {**base, "environment.relative_humidity": 0.0}, a.members, a.repeat),
            case("humid_nucleation_t_a", base, a.members, a.repeat),
            case("humid_short_t_a", {**base, "menisci.condensation_model": "fixed",
                                     "menisci.condensation_time": a.short_ta}, a.members, a.repeat)]
    dry, dry_cpu = rows[0]["seconds"], rows[0]["cpu_seconds"]
    for r in rows:
        r["ratio_to_dry"], r["cpu_ratio_to_dry"] = r["seconds"] / dry, r["cpu_seconds"] / dry_cpu
        print(f"{r['case']:22s} {r['seconds']:8.2f} s  x{r['ratio_to_dry']:.2f}  CPU {r['cpu_seconds']:7.2f} s  "
              f"x{r['cpu_ratio_to_dry']:.2f}  members with bridges "
              f"{r['members_with_bridges']}/{r['members']}  stick {r['stick_probability_within_run']:.3f}  "
              f"audit {r['energy_audit_max_relative_error']:.1e}")
    out = {"scene": "wet_silica", "params": "calibrated", "members": a.members, "max_bounces": a.bounces,
           "short_t_a_s": a.short_ta, "repeat": a.repeat, "rows": rows}
    if a.json:
        a.json.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
