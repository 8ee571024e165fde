"""Per-contact cost of discrete plastic summits: this checkout against a baseline commit, measured in one run.

    .venv/bin/python benchmarks/bench_plastic_members.py [--baseline REF] [--members 16] [--bounces 100]
                                                         [--json FILE]

Two workloads, each run in a child process on each source tree (the baseline's sources extracted with
`git archive REF`, then this checkout's), one tree after the other, each timed on its second run (the first, untimed,
loads or compiles every kernel it calls: the baseline's tree compiles afresh):

* `wet_silica`: the paper's humid silica impact task on the `silicon` set (`continuum.paper.run._impact_task`: the
  scene's 64-member ensemble of plastic Maugis-Dugdale summits, 100 bounces each, wrapped in bridges after t_a,
  plus its mean-field trajectory);
* `dry_plastic`: `--members` members (seeds 1..N) of the `rough_silica` scene on the `calibrated` set with
  `physics.plasticity = 'auto'` (plastic summits, `--bounces` impacts each), as `bench_plastic_summits.py` runs them.

For each: CPU seconds, the number of compiled contacts and, per contact, the CPU inside the compiled contact
kernel (`contact_kernel.integrate_contact`) and outside it (the law's Python: compiled tables, release gap, commit,
the driver; for `wet_silica` also the task's mean-field trajectory and model selection). Ratios baseline/this are
the speed-ups. The cores are shared: CPU time moves less with load than wall time, and both trees run under the same
load within a few minutes.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
log = logging.getLogger("bench_plastic_members")


def _timed_kernel():
    """Wrap the compiled contact kernel so its CPU time is counted; returns the counter [seconds, calls]."""
    from continuum.numerics import compiled_contact as cc
    inner = cc.ck.integrate_contact
    acc = [0.0, 0]

    def counted(*args):
        t = time.process_time()
        try:
            return inner(*args)
        finally:
            acc[0] += time.process_time() - t
            acc[1] += 1

    cc.ck.integrate_contact = counted
    return acc


def _measure(label, work, acc) -> dict:
    acc[0], acc[1] = 0.0, 0
    start, cpu = time.perf_counter(), time.process_time()
    work()
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    contacts = max(acc[1], 1)
    out = {"wall_s": wall, "cpu_s": cpu, "contacts": acc[1], "kernel_cpu_s": acc[0],
           "kernel_ms_per_contact": 1e3 * acc[0] / contacts,
           "python_ms_per_contact": 1e3 * (cpu - acc[0]) / contacts}
    log.info("%s: %.2f s CPU, %d contacts, kernel %.3f ms + rest %.3f ms per contact", label, cpu, acc[1],
             out["kernel_ms_per_contact"], out["python_ms_per_contact"])
    return out


def child(tree: Path, members: int, bounces: int) -> dict:
    """Both workloads on the sources under `tree` (this process imports them)."""
    sys.path.insert(0, str(tree))
    from continuum.dynamics.ensemble_run import member_plan, run_member
    from continuum.model.regime import first_impact_speed
    from continuum.paper import run as paper
    from continuum.scene import resolve_scene

    acc = _timed_kernel()
    case = {c.name: c for c in paper.wet_cases()}["wet_silica"]
    out_dir = tempfile.mkdtemp(prefix="bench_plastic_members_")
    paper._impact_task(case, "silicon", None, out_dir)        # every kernel it calls loaded (or compiled), untimed
    wet = _measure("wet_silica silicon task", lambda: paper._impact_task(case, "silicon", None, out_dir), acc)

    dry_scene = resolve_scene(tree / "inputs" / "scenes" / "rough_silica.toml", params="calibrated",
                              overrides={"physics.plasticity": "auto", "numerics.max_bounces": bounces}).scene
    plan = member_plan(dry_scene, first_impact_speed(dry_scene))
    run_member(dry_scene, members + 1, plan)
    dry = _measure(f"rough_silica calibrated plastic, {members} members",
                   lambda: [run_member(dry_scene, seed, plan) for seed in range(1, members + 1)], acc)
    return {"wet_silica": wet, "dry_plastic": dry}


def _run_tree(tree: Path, args) -> dict:
    with tempfile.NamedTemporaryFile(suffix=".json") as f:
        subprocess.run([sys.executable, str(Path(__file__).resolve()), "--child", str(tree), "--child-json", f.name,
                        "--members", str(args.members), "--bounces", str(args.bounces)], cwd=tree, check=True)
        return json.loads(Path(f.name).read_text())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", default="main", help="git ref of the sources to compare against (default main)")
    ap.add_argument("--members", type=int, default=16)
    ap.add_argument("--bounces", type=int, default=100)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--child-json", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if args.child is not None:
        args.child_json.write_text(json.dumps(child(args.child, args.members, args.bounces)))
        return 0
    commit = subprocess.run(["git", "rev-parse", args.baseline], cwd=ROOT, capture_output=True, text=True,
                            check=True).stdout.strip()
    res: dict = {"baseline": {"ref": args.baseline, "commit": commit}, "members": args.members,
                 "bounces": args.bounces}
    with tempfile.TemporaryDirectory(prefix="bench_plastic_baseline_") as base:
        archive = subprocess.run(["git", "archive", commit], cwd=ROOT, capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", base], input=archive, check=True)
        log.info("baseline %s (%s)", args.baseline, commit[:10])
        res["baseline"].update(_run_tree(Path(base), args))
    log.info("this checkout")
    res["this"] = _run_tree(ROOT, args)
    res["ratios_baseline_over_this"] = {
        work: {key: res["baseline"][work][key] / res["this"][work][key]
               for key in ("cpu_s", "kernel_ms_per_contact", "python_ms_per_contact")}
        for work in ("wet_silica", "dry_plastic")}
    res["load_average"] = os.getloadavg()
    res["machine"] = {"python": platform.python_version(), "platform": platform.platform()}
    text = json.dumps(res, indent=1)
    if args.json:
        args.json.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
