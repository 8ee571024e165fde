"""Two-rank speed-up of a slab leg (``nanoimpact md --np 2``) on LAMMPS's default processor grid and on the
engine's :data:`md.engine.lammps.DECOMPOSITION` (x and y only).

    .venv/bin/python benchmarks/bench_md_ranks.py [--recipe adhesion_silica] [--fidelity quick]
                                                  [--steps 2000] [--chunk 1000] [--json PATH]

The recipe is cut to ``--steps`` MD steps per leg in chunks of ``--chunk`` (``bench_md_engine.bench_recipe``) and
its first leg runs through the real runner three times, one after the other: one rank in process; two ranks
(``mpirun``) on the default grid; two ranks on the engine's grid. Reported per case: the processor grid LAMMPS
chose, the summed ``Loop time`` of the dynamics chunks (minimisation left out), the per-section times of the
last chunk (min/max over ranks: the imbalance), and the speed-up against one rank. Run it on an idle machine;
the cases compare wall times. A script, not a test; nothing it writes is kept.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_md_engine import LOOP, bench_recipe  # noqa: E402  (same folder)

import md.engine.lammps as E  # noqa: E402
from md import workflows as W  # noqa: E402
from md.engine.runner import Interrupted  # noqa: E402

GRID = re.compile(r"^\s*(\d+) by (\d+) by (\d+) MPI processor grid")
SECTION = re.compile(r"^(Pair|Kspace|Neigh|Comm|Modify)\s*\|\s*([0-9.eE+-]+)\s*\|\s*([0-9.eE+-]+)\s*\|\s*([0-9.eE+-]+)")


def first_leg_run(recipe, fidelity: str, np_: int, cache: Path, chunks: int) -> dict:
    """Run the first ``chunks`` chunks of the recipe's first leg; its log's grid, dynamics loop time, sections."""
    try:
        W.run_recipe(recipe, fidelity, cache=cache, np_=np_, progress=False, force=True, echo=None,
                     stop_after_chunks=chunks)
    except Interrupted:
        pass
    log = next(cache.rglob("legs/*/log.lammps"))
    lines = log.read_text(errors="replace").splitlines()
    grids = [m.groups() for m in map(GRID.match, lines) if m]
    loops = [(float(m.group(1)), int(m.group(3))) for m in map(LOOP.match, lines) if m]
    dyn = loops[1:]                                   # the first Loop line is the minimisation
    sections = {}
    for l in lines:
        m = SECTION.match(l)
        if m:
            sections[m.group(1)] = {"min_s": float(m.group(2)), "max_s": float(m.group(4))}
    return {"np": np_, "grid": "x".join(grids[-1]) if grids else "1x1x1",
            "dynamics_loop_s": sum(t for t, _ in dyn), "steps": sum(n for _, n in dyn),
            "last_chunk_sections": sections}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--recipe", default="adhesion_silica")
    ap.add_argument("--fidelity", default="quick")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--chunk", type=int, default=1000)
    ap.add_argument("--json", default=None, help="also write the numbers here")
    args = ap.parse_args(argv)
    recipe = bench_recipe(args.recipe, args.fidelity, args.steps, args.chunk)
    chunks = max(1, args.steps // args.chunk)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_md_ranks_") as tmp:
        tmp = Path(tmp)
        engine_grid = E.DECOMPOSITION
        for label, np_, grid in (("one rank", 1, engine_grid), ("two ranks, default grid", 2, ""),
                                 ("two ranks, engine grid", 2, engine_grid)):
            E.DECOMPOSITION = grid
            try:
                row = first_leg_run(recipe, args.fidelity, np_, tmp / f"cache_{len(rows)}", chunks)
            finally:
                E.DECOMPOSITION = engine_grid
            row["case"] = label
            rows.append(row)
    base = rows[0]["dynamics_loop_s"] / max(rows[0]["steps"], 1)
    for r in rows:
        per = r["dynamics_loop_s"] / max(r["steps"], 1)
        r["speedup_vs_one_rank"] = base / per if per else float("nan")
        pair = r["last_chunk_sections"].get("Pair", {})
        print(f"{r['case']:26s} grid {r['grid']:7s} {r['steps']:6d} steps {r['dynamics_loop_s']:8.2f} s  "
              f"speed-up {r['speedup_vs_one_rank']:.2f}  pair min/max {pair.get('min_s', float('nan')):.2f}/"
              f"{pair.get('max_s', float('nan')):.2f} s")
    if args.json:
        Path(args.json).write_text(json.dumps({"recipe": args.recipe, "fidelity": args.fidelity, "rows": rows},
                                              indent=1))


if __name__ == "__main__":
    main()
