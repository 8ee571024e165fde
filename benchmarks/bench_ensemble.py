"""Seconds for an ensemble of discrete realisations of `rough_silica` (target: 64 members in <= 20 s on the
2-core machine), on the executors of `nanoimpact.executors`, with the machine's load average beside each number.

    python benchmarks/bench_ensemble.py [--params calibrated,paper] [--members 64] [--half-space N] [--escape]
                                        [--json FILE]

Members on a rigid substrate (each contact in the compiled kernel, continuum.numerics.contact_kernel): the scene's
physics.half_space = 'auto' leaves it out (the deflection is femtometres). `--half-space N` also times N members
with physics.half_space = 'on' (the coupled fixed point in Python, ~1 s per impact). The ensemble's
own wall time is reported (`EnsembleResult.wall_s`: the members, not the scene's resolution or the mean-field run),
with the CPU seconds (user + system) of this process and its worker processes over the same call: on a machine
other jobs load, the CPU time is the steadier measure (two idle cores give about half of it as wall time).
`--escape` also bisects each member's escape velocity (surfaces.roughness.escape_velocities).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import time
from pathlib import Path

from continuum.dynamics.ensemble_run import run_ensemble
from continuum.numerics.compiled_contact import warm_up
from continuum.scene import resolve_scene

RIGID = {"physics.half_space": "auto"}


def cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its children that have ended (the pool's workers)."""
    return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                  resource.getrusage(resource.RUSAGE_CHILDREN)))


def one(params: str, overrides: dict, members: int, executor: str, workers: int | None) -> dict:
    resolved = resolve_scene("rough_silica", params=params, overrides=overrides, override_label="bench")
    load_before = os.getloadavg()[0]
    cpu = cpu_seconds()
    start = time.perf_counter()
    ens = run_ensemble(resolved, members=members, seed=1, executor=executor, workers=workers)
    total = time.perf_counter() - start
    return {"executor": executor, "workers": workers, "members": members, "seconds": total,
            "cpu_seconds": cpu_seconds() - cpu,
            "ensemble_wall_s": ens.wall_s, "member_seconds_sum": sum(o.wall_s for o in ens.outcomes),
            "stick_probability": ens.stick_probability,
            "stick_probability_first_impact": ens.stick_probability_first_impact,
            "load_average_before": load_before, "load_average_after": os.getloadavg()[0]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", default="calibrated,paper")
    ap.add_argument("--members", type=int, default=64)
    ap.add_argument("--half-space", type=int, default=0, metavar="N", help="also time N members, half-space on")
    ap.add_argument("--executors", default="processes,local", help="which of processes, local to time")
    ap.add_argument("--escape", action="store_true", help="also bisect each member's escape velocity")
    ap.add_argument("--json", help="write the numbers here")
    args = ap.parse_args()
    warm_up()
    out = {"scene": "rough_silica", "cpus": os.cpu_count(), "cases": {}}
    executors = {"processes": ("processes", os.cpu_count()), "local": ("local", None)}
    rigid = {**RIGID, "surfaces.roughness.escape_velocities": True} if args.escape else RIGID
    runs = [(p, "rigid" + (" +escape" if args.escape else ""), rigid, args.members, executors[ex])
            for p in args.params.split(",")
            for ex in args.executors.split(",")]
    if args.half_space:
        runs += [(p, "half-space on", {"physics.half_space": "on"}, args.half_space, ("processes", os.cpu_count()))
                 for p in args.params.split(",")]
    for params, name, overrides, members, (executor, workers) in runs:
        row = one(params, overrides, members, executor, workers)
        out["cases"].setdefault(f"{params} {name}", []).append(row)
        print(f"{params:11s} {name:14s} {executor:9s} {members} members: {row['seconds']:6.2f} s wall, "
              f"{row['cpu_seconds']:6.2f} s CPU (members' own wall {row['member_seconds_sum']:.2f} s; "
              f"stick p {row['stick_probability']:.3f}, first impact "
              f"{row['stick_probability_first_impact']:.3f}; load {row['load_average_before']:.2f} -> "
              f"{row['load_average_after']:.2f})", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
