"""The plastic GW mean field in the compiled contact phase against the Python stepper, measured in one run.

    .venv/bin/python benchmarks/bench_plastic_gw_compiled.py [--params silicon] [--case sigma_10nm] [--repeat 1]
                                                             [--json FILE]

The paper's impact task (`continuum.paper.run._impact_task`: one dry case on one parameter set, `nanoimpact
impact`'s run and its files) and the paper's escape-velocity search on its law
(`continuum.paper.samples.escape_search`: bracketed from the drop speed, bisected to ESCAPE_REL_TOL), each run three
ways, one after the other in this process (tables built and the kernel loaded first, untimed):

* `before`: the law's contacts on the Python DOP853 stepper (`PlasticGWPunch.compiled_contact = False`), the
  compiled sums summing the roller footprint's 24-node kernel at every node
  (`PlasticBranchGWSurface.footprint_tabulated = False`): the code before the compiled contact phase took this law;
* `python`: the same stepper, the footprint kernel interpolated in its table;
* `compiled`: the contacts in the compiled contact phase (kernel kind LAW_PLASTIC_GW), the kernel tabulated.

Reports wall and CPU seconds of each, the ratios before / compiled and python / compiled, and the load average (the
2 cores are shared: the CPU ratio is the steadier one).
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from continuum.dynamics.impact import first_impact_speed  # noqa: E402
from continuum.laws.plastic_rough import PlasticGWPunch  # noqa: E402
from continuum.model import select_law  # noqa: E402
from continuum.paper import run as paper  # noqa: E402
from continuum.paper.samples import ESCAPE_REL_TOL, escape_search  # noqa: E402
from continuum.rough.plastic_gw_branches import PlasticBranchGWSurface  # noqa: E402

log = logging.getLogger("bench_plastic_gw_compiled")


def _timed(fn) -> tuple[float, float, object]:
    start, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - start, time.process_time() - cpu, out


def measure(params: str, case_name: str, repeat: int) -> dict:
    case = {c.name: c for c in paper.dry_cases()}[case_name]
    out: dict = {"params": params, "case": case_name, "repeat": repeat}
    folder = tempfile.mkdtemp(prefix="bench_plastic_gw_")
    paper._impact_task(case, params, None, folder)          # tables and the kernel loaded, untimed
    for label, contact, tabulated in (("compiled", True, True), ("python", False, True), ("before", False, False)):
        PlasticGWPunch.compiled_contact = contact
        PlasticBranchGWSurface.footprint_tabulated = tabulated
        try:
            resolved = paper.resolve_case(case, params, None)
            scene = resolved.scene
            v0 = first_impact_speed(resolved)
            law, _ = select_law(scene, v0)
            out["law"] = law.name
            wall = cpu = 0.0
            for _ in range(repeat):
                w, c, res = _timed(lambda: paper._impact_task(case, params, None, folder))
                wall, cpu = wall + w, cpu + c
            r = res["result"]
            ew, ec, esc = _timed(lambda: escape_search(law, scene.body.mass, scene.environment.gravity, v0,
                                                       scene.numerics.rtol, ESCAPE_REL_TOL))
        finally:
            PlasticGWPunch.compiled_contact = True
            PlasticBranchGWSurface.footprint_tabulated = True
        kt = law.surface._tx_tw[2] if getattr(law.surface, "compiled", False) else None
        out[label] = {"impact_wall_s": wall / repeat, "impact_cpu_s": cpu / repeat, "n_bounces": r["n_bounces"],
                      "rebound_heights_m": [b.get("rebound_height") for b in r.get("bounces", [])][:3],
                      "energy_audit": r["energy_audit"]["max_error_over_turnover"],
                      "footprint_table_points": None if kt is None or kt.size == 0 else int(kt[1]),
                      "escape_wall_s": ew, "escape_cpu_s": ec,
                      "escape": {k: v for k, v in esc.items() if isinstance(v, (int, float, str, bool))}}
        log.info("%s: impact %.2f s (%.2f s CPU), escape search %.2f s (%.2f s CPU)", label, wall / repeat,
                 cpu / repeat, ew, ec)
    for ref in ("before", "python"):
        for key in ("impact_wall_s", "impact_cpu_s", "escape_wall_s", "escape_cpu_s"):
            out[f"ratio_{ref}_over_compiled_{key}"] = out[ref][key] / out["compiled"][key]
    out["load_average"] = os.getloadavg()
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", default="silicon")
    ap.add_argument("--case", default="sigma_10nm")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    res = measure(args.params, args.case, args.repeat)
    text = json.dumps(res, indent=1, default=str)
    if args.json:
        args.json.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
