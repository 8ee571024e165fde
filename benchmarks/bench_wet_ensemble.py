"""Cost of an ensemble whose summits carry menisci against the elastic dry ensemble of the same members.

wet_silica on the `calibrated` set, an ensemble of `--members` realisations (same master seed, so the same summits),
run in this process one after another (executor 'local'), each case `--repeat` times, the best wall and CPU (process)
time kept (on a shared machine the CPU time is the steadier of the two):

- dry_elastic: environment.relative_humidity = 0 and physics.plasticity = 'off': the elastic dry ensemble, the
  reference of the budget (issue 42: an ensemble with menisci costs at most 2x it);
- dry: relative humidity 0 with the set's own summits (calibrated silicon yields: plastic Maugis-Dugdale summits);
- humid, nucleation t_a: the set's own t_a (ms), which no contact reaches: the wet law is its dry law up to t_a
  (compiled, stopped at t_a), so the cost is the dry cost plus the bridges' bookkeeping;
- humid, short t_a (`--short-ta`, s, fixed): bridges form in most contacts; after t_a a contact goes on compiled
  (`continuum.numerics.wet_discrete_kernel`): the set's plastic summits at W_wet inside their bridges (its plastic
  mode, `continuum.numerics.wet_plastic_kernel`), the same with menisci.solid_adhesion = 'additive' (the dry plastic
  loop with additive bridges, LAW_BRIDGED), and with plasticity off elastic summits at W_wet inside their bridges
  (LAW_WET_DISCRETE).

Each row gives its ratio to the elastic dry ensemble and to the dry ensemble of the same summits, and how its
contacts ran (compiled, handed over at t_a, on the Python stepper: `continuum.numerics.compiled_contact.STATS`).
The ratios are the numbers docs/benchmarks.md quotes; every number comes from one run of this script.

    python benchmarks/bench_wet_ensemble.py [--members 8] [--bounces 20] [--short-ta 1e-6] [--repeat 2] [--json P]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from continuum.dynamics.ensemble_run import run_ensemble
from continuum.numerics.compiled_contact import STATS, warm_up
from continuum.scene import resolve_scene


def case(label: str, overrides: dict, members: int, repeat: int) -> dict:
    resolved = resolve_scene("wet_silica", params="calibrated", overrides=overrides, override_label=label)
    best, cpu, rec = float("inf"), float("inf"), None
    for _ in range(repeat):
        before = dict(vars(STATS))
        t, c = time.perf_counter(), time.process_time()
        rec = run_ensemble(resolved, members=members, seed=1, executor="local").to_record()
        best, cpu = min(best, time.perf_counter() - t), min(cpu, time.process_time() - c)
        contacts = {k: v - before[k] for k, v in vars(STATS).items()}
    men = rec["menisci"]
    return {"case": label, "seconds": best, "cpu_seconds": cpu, "members": members, "contacts": contacts,
            "members_with_bridges": men.get("members_with_bridges", 0), "menisci_carried": men["carried"],
            "stick_probability_within_run": rec["stick_probability"]["within_run"]["value"],
            "energy_audit_max_relative_error": rec["energy_audit_max_relative_error"]}


_LABELS = {"dry_elastic": "dry, elastic summits (plasticity off): the reference",
           "dry": "dry, the set's summits (silicon yields: plastic)",
           "humid_nucleation_t_a": "humid, the set's nucleation t_a",
           "humid_short_t_a": "humid, short t_a: plastic summits at W_wet in bridges (LAW_WET_DISCRETE, plastic)",
           "humid_short_t_a_additive": "humid, short t_a: plastic summits, dry loop, additive bridges (LAW_BRIDGED)",
           "humid_short_t_a_elastic": "humid, short t_a: elastic summits at W_wet in bridges (LAW_WET_DISCRETE)"}


def markdown(result: dict) -> str:
    """The table docs/benchmarks.md quotes (tests/continuum/test_wet_ensemble_docs.py checks it is this)."""
    rows = ["| case | CPU s | CPU / elastic dry | per contact / elastic dry | contacts (at t_a: handed over; Python) "
            "| members with bridges | sticks | energy audit |", "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        n = r["contacts"]
        rows.append(f"| {_LABELS.get(r['case'], r['case'])} | {r['cpu_seconds']:.2f} | "
                    f"{r['cpu_ratio_to_elastic_dry']:.2f} | {r['cpu_per_contact_ratio_to_elastic_dry']:.2f} | "
                    f"{r['contacts_run']} ({n['handed_over']}; {n['python']}) | "
                    f"{r['members_with_bridges']}/{r['members']} | {r['stick_probability_within_run']:.2f} | "
                    f"{r['energy_audit_max_relative_error']:.1e} |")
    rows.append("")
    rows.append(f"Largest CPU ratio of an ensemble with menisci to the elastic dry ensemble: "
                f"**{result['max_cpu_ratio_with_menisci_to_elastic_dry']:.2f}×** ({result['members']} members, "
                f"{result['max_bounces']} bounces, short t_a = {result['short_t_a_s']:.3g} s, best of "
                f"{result['repeat']}).")
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=8)
    ap.add_argument("--bounces", type=int, default=20)
    ap.add_argument("--short-ta", type=float, default=1e-6)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    warm_up()
    base = {"surfaces.roughness.mode": "ensemble", "numerics.max_bounces": a.bounces}
    dry = {"environment.relative_humidity": 0.0}
    short = {"menisci.condensation_model": "fixed", "menisci.condensation_time": a.short_ta}
    elastic = {"physics.plasticity": "off"}
    rows = [case("dry_elastic", {**base, **dry, **elastic}, a.members, a.repeat),
            case("dry", {**base, **dry}, a.members, a.repeat),
            case("humid_nucleation_t_a", base, a.members, a.repeat),
            case("humid_short_t_a", {**base, **short}, a.members, a.repeat),
            case("humid_short_t_a_additive", {**base, **short, "menisci.solid_adhesion": "additive"}, a.members,
                 a.repeat),
            case("humid_short_t_a_elastic", {**base, **short, **elastic}, a.members, a.repeat)]
    ref = {r["case"]: r for r in rows}
    for r in rows:
        same, el = (ref["dry_elastic"] if r["case"].endswith("elastic") else ref["dry"]), ref["dry_elastic"]
        n = r["contacts"]
        r["contacts_run"] = n["compiled"] + n["python"]          # a contact handed over at t_a ends in one of them
        r["cpu_ms_per_contact"] = 1e3 * r["cpu_seconds"] / max(r["contacts_run"], 1)
        r["ratio_to_elastic_dry"] = r["seconds"] / el["seconds"]
        r["cpu_ratio_to_elastic_dry"] = r["cpu_seconds"] / el["cpu_seconds"]
        r["ratio_to_dry"] = r["seconds"] / same["seconds"]
        r["cpu_ratio_to_dry"] = r["cpu_seconds"] / same["cpu_seconds"]
        r["cpu_per_contact_ratio_to_elastic_dry"] = r["cpu_ms_per_contact"] / el["cpu_ms_per_contact"]
    for r in rows:
        n = r["contacts"]
        print(f"{r['case']:24s} {r['seconds']:6.2f} s CPU {r['cpu_seconds']:6.2f} s"
              f"  x{r['cpu_ratio_to_elastic_dry']:.2f} of elastic dry"
              f" (x{r['cpu_per_contact_ratio_to_elastic_dry']:.2f} per contact), x{r['cpu_ratio_to_dry']:.2f} of dry"
              f"  bridges {r['members_with_bridges']}/{r['members']}  contacts {r['contacts_run']} (handed over"
              f" {n['handed_over']}, Python {n['python']})  stick {r['stick_probability_within_run']:.3f}"
              f"  audit {r['energy_audit_max_relative_error']:.1e}")
    out = {"scene": "wet_silica", "params": "calibrated", "members": a.members, "max_bounces": a.bounces,
           "short_t_a_s": a.short_ta, "repeat": a.repeat, "rows": rows,
           "max_cpu_ratio_with_menisci_to_elastic_dry": max(r["cpu_ratio_to_elastic_dry"] for r in rows
                                                            if r["case"].startswith("humid"))}
    print(markdown(out))
    if a.json:
        a.json.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
