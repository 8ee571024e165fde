"""The plastic GW mean field in the compiled contact phase against the code before it, measured in one run.

    .venv/bin/python benchmarks/bench_plastic_gw_compiled.py [--params silicon] [--case sigma_10nm] [--rounds 3]
                                                             [--baseline REV] [--json FILE]

What is timed: the paper's impact task (`continuum.paper.run._impact_task`: one dry case on one parameter set,
`nanoimpact impact`'s run and its files; `silicon` sigma_10nm runs the roller on the Maugis-Dugdale summits' plastic
mean field, 100 impacts) and the paper's escape-velocity search on the same law (`continuum.paper.samples.
escape_search`: bracketed from the drop speed, bisected to ESCAPE_REL_TOL), each in a fresh interpreter that loads
(or compiles) its numba kernels and runs the task once untimed first. Three trees and settings, run in turn
`--rounds` times (baseline, this tree compiled, this tree on the Python stepper, baseline, ...):

* `baseline`: git revision REV (default BASELINE, the commit before the plastic mean field ran in the compiled
  contact phase), exported with `git archive` into a temporary folder: its contacts on the Python DOP853 stepper,
  its sums summing the footprint kernel's 24 nodes at every quadrature node;
* `compiled`: this tree, the contacts in the compiled contact phase (kernel kind LAW_PLASTIC_GW);
* `python`: this tree with `PlasticGWPunch.compiled_contact = False` (the same sums, the Python stepper).

Reports each run's wall and CPU seconds, the median of each, the ratios baseline / compiled and python / compiled of
the medians, and the load average (the 2 cores are shared: CPU is the steadier measure).
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the commit before this work (main at 4745e9e: the plastic mean field's contacts on the Python stepper)
BASELINE = "4745e9e"

log = logging.getLogger("bench_plastic_gw_compiled")

#: run in a fresh interpreter whose working folder is the tree to time (sys.path[0] = '' imports it first)
CHILD = r"""
import json, sys, tempfile, time
import continuum
from continuum.dynamics.impact import first_impact_speed
from continuum.model import select_law
from continuum.paper import run as paper
from continuum.paper.samples import ESCAPE_REL_TOL, escape_search
params, case_name, python_stepper = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
if python_stepper:
    from continuum.laws.plastic_rough import PlasticGWPunch
    PlasticGWPunch.compiled_contact = False
case = {c.name: c for c in paper.dry_cases()}[case_name]
folder = tempfile.mkdtemp(prefix="bench_plastic_gw_")
resolved = paper.resolve_case(case, params, None)
scene = resolved.scene
v0 = first_impact_speed(resolved)
law, _ = select_law(scene, v0)
def escape():
    return escape_search(law, scene.body.mass, scene.environment.gravity, v0, scene.numerics.rtol, ESCAPE_REL_TOL)
paper._impact_task(case, params, None, folder)          # kernels loaded (or compiled), tables built: untimed
escape()
out = {"tree": continuum.__file__, "law": law.name}
for name, fn in (("impact", lambda: paper._impact_task(case, params, None, folder)["result"]), ("escape", escape)):
    wall, cpu = time.perf_counter(), time.process_time()
    res = fn()
    out[name] = {"wall_s": time.perf_counter() - wall, "cpu_s": time.process_time() - cpu}
    if name == "impact":
        out[name].update(n_bounces=res["n_bounces"], audit=res["energy_audit"]["max_error_over_turnover"])
    else:
        out[name]["escape_velocity"] = res.get("escape_velocity")
print("BENCH " + json.dumps(out))
"""


def _child(tree: Path, params: str, case: str, python_stepper: bool) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-c", CHILD, params, case, "1" if python_stepper else "0"], cwd=tree,
                          env=env, capture_output=True, text=True, check=False)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("BENCH ")]
    if proc.returncode != 0 or not lines:
        raise RuntimeError(f"benchmark child in {tree} failed ({proc.returncode}): {proc.stderr[-2000:]}")
    return json.loads(lines[-1][len("BENCH "):])


def _export(rev: str, dest: Path) -> Path:
    """The tree of git revision `rev` at `dest` (`git archive`: tracked files only)."""
    archive = dest.with_suffix(".tar")
    subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", "-o", str(archive), rev], check=True)
    dest.mkdir(parents=True)
    with tarfile.open(archive) as tar:
        tar.extractall(dest, filter="data")
    return dest


def measure(params: str, case: str, rounds: int, baseline: str) -> dict:
    out: dict = {"params": params, "case": case, "rounds": rounds, "baseline": baseline, "runs": []}
    with tempfile.TemporaryDirectory(prefix="bench_plastic_gw_base_") as tmp:
        base = _export(baseline, Path(tmp) / "tree")
        configs = (("baseline", base, False), ("compiled", ROOT, False), ("python", ROOT, True))
        for r in range(rounds):
            for label, tree, python_stepper in configs:
                res = _child(tree, params, case, python_stepper)
                res.update(config=label, round=r, load_average=os.getloadavg())
                out["runs"].append(res)
                log.info("round %d %s: impact %.2f s CPU, escape search %.2f s CPU (%s)", r, label,
                         res["impact"]["cpu_s"], res["escape"]["cpu_s"], res["tree"])
    for label, _, _ in configs:
        runs = [x for x in out["runs"] if x["config"] == label]
        out[label] = {f"{task}_{k}_median": statistics.median(x[task][k] for x in runs)
                      for task in ("impact", "escape") for k in ("wall_s", "cpu_s")}
        out[label].update(law=runs[0]["law"], impact_audit=runs[0]["impact"]["audit"],
                          escape_velocity=runs[0]["escape"]["escape_velocity"])
    for ref in ("baseline", "python"):
        for key in ("impact_cpu_s", "impact_wall_s", "escape_cpu_s", "escape_wall_s"):
            out[f"ratio_{ref}_over_compiled_{key}"] = (out[ref][f"{key}_median"]
                                                       / out["compiled"][f"{key}_median"])
    out["load_average"] = os.getloadavg()
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", default="silicon")
    ap.add_argument("--case", default="sigma_10nm")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--baseline", default=BASELINE, help="git revision to compare with (default %(default)s)")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    res = measure(args.params, args.case, args.rounds, args.baseline)
    text = json.dumps(res, indent=1, default=str)
    if args.json:
        args.json.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
