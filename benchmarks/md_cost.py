"""Cost of every MD recipe at every fidelity: atoms, MD steps, atom-steps and wall time, measured where a run exists.

    .venv/bin/python benchmarks/md_cost.py [--measure] [--steps 1500] [--json PATH]

* Atoms and MD steps come from the workflows' own plans (`md.workflows.get_workflow(...).plan`): the structures
  are built in a temporary directory, nothing runs. Atom-steps = atoms of the largest leg x all MD steps (an upper
  bound for recipes whose legs differ in size; minimisation not counted).
* Quick: the committed runs in `inputs/md/results/<recipe>-quick/result.json` give the **measured** dynamics wall
  time and per-core speed (one rank, PPPM 1e-4). A committed run whose `run_hash` differs from what the recipe
  gives now is marked stale and not used.
* Production: an **estimate** = atom-steps / (that recipe's measured quick speed / k), where k is the slow-down of
  the production settings (PPPM 1e-5, the production cutoff) against the quick ones on the same system.
  With ``--measure`` k is measured here: the one-leg recipes (SPC/E film, droplet on silica) run ``--steps`` MD
  steps in process at their quick settings and again with the production `kspace_accuracy` and `cutoff_A`, one
  rank, one after the other, and the film once more with ``--np 2`` (`mpirun`) for the two-rank speed-up; and
  every recipe runs once at smoke (the whole call, set-up and analysis included). The
  largest k measured is applied to every recipe (conservative; the solid-only recipes carry fewer charges per
  atom). Without ``--measure`` the numbers of the last measurement (``--json`` output) may be given with
  ``--factors PATH``; otherwise production rows say "not estimated".
Run it on an idle machine: the measurement compares wall times.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_md_engine import LOOP, bench_recipe  # noqa: E402  (same folder; sys.path[0] when run as a script)

from md import workflows as R  # noqa: E402  (run_recipe, run_hash)
from md.recipe import RECIPE_DIR, load_recipe  # noqa: E402
from md.workflows import get_workflow  # noqa: E402

FIDELITIES = ("smoke", "quick", "production")
RESULTS = ROOT / "inputs" / "md" / "results"


def plan_size(recipe, fidelity: str) -> tuple[int, int, float]:
    """(atoms of the largest leg, MD steps over all legs, timestep fs) from the workflow's plan."""
    settings = recipe.settings(fidelity)
    with tempfile.TemporaryDirectory(prefix="md_cost_") as tmp:
        plan = get_workflow(recipe.workflow).plan(settings, Path(tmp))
        return plan.n_atoms, sum(leg.total_steps for leg in plan.legs), plan.timestep_fs


def committed_quick(recipe) -> dict | None:
    """The committed quick result of ``recipe`` if its run hash is what the recipe gives now."""
    path = RESULTS / f"{recipe.name}-quick" / "result.json"
    if not path.exists():
        return None
    res = json.loads(path.read_text())
    settings = recipe.settings("quick")
    ff = get_workflow(recipe.workflow).forcefield_files(settings)
    res["_stale"] = R.run_hash(recipe, "quick", ff)[0] != res["run_hash"]
    return res


def md_loop_seconds(log: Path) -> tuple[float, int]:
    """Summed 'Loop time' and steps of the MD runs in a LAMMPS log (minimisations, whose 'Loop time' line is
    followed by 'Minimization stats', are left out)."""
    lines = log.read_text(errors="replace").splitlines()
    t, steps = 0.0, 0
    for i, line in enumerate(lines):
        m = LOOP.match(line)
        if m and not any(l.startswith("Minimization stats") for l in lines[i + 1:i + 6]):
            t += float(m.group(1))
            steps += int(m.group(3))
    return t, steps


def timed_recipe(name: str, fidelity: str, steps: int, overrides: dict, np_: int, cache: Path) -> float:
    """Seconds per MD step (LAMMPS 'Loop time', minimisation excluded) of a one-leg recipe cut to ``steps``."""
    fid = tomllib.loads((RECIPE_DIR / f"{name}.toml").read_text())["fidelity"][fidelity]
    chunk = steps // 3 // fid["sample_interval"] * fid["sample_interval"]
    recipe = bench_recipe(name, fidelity, steps, chunk, minimize_steps=min(fid.get("minimize_steps", 1000), 50),
                          **overrides)
    out = R.run_recipe(recipe, fidelity, cache=cache, np_=np_, progress=False, force=True, echo=None)
    legs = sorted((out.run_dir / "legs").iterdir())
    t, n = md_loop_seconds(legs[0] / "log.lammps")
    if n != steps:
        raise SystemExit(f"{name}: {n} MD steps in the log, expected {steps}")
    return t / n


def measure_factors(steps: int) -> dict:
    """k = production/quick seconds per step on the same system, one rank; two-rank speed-up of the film."""
    out = {"steps": steps, "systems": {}}
    with tempfile.TemporaryDirectory(prefix="md_cost_run_") as tmp:
        cache = Path(tmp)
        for name in ("surface_tension_spce", "contact_angle_silica"):
            rec = load_recipe(name)
            prod = rec.settings("production")
            over = {"kspace_accuracy": prod["kspace_accuracy"], "cutoff_A": prod["cutoff_A"]}
            t0 = time.perf_counter()
            quick = timed_recipe(name, "quick", steps, {}, 1, cache)
            slow = timed_recipe(name, "quick", steps, over, 1, cache)
            row = {"quick_s_per_step": quick, "production_settings_s_per_step": slow, "k": slow / quick,
                   "production_overrides": over}
            if name == "surface_tension_spce":
                two = timed_recipe(name, "quick", steps, over, 2, cache)
                row["np2_s_per_step"] = two
                row["speedup_np2"] = slow / two
            row["wall_s"] = time.perf_counter() - t0
            out["systems"][name] = row
            print(f"{name}: {quick * 1e3:.2f} ms/step at quick settings, {slow * 1e3:.2f} ms/step with "
                  f"{over} (k = {slow / quick:.2f})"
                  + (f"; 2 ranks {row['np2_s_per_step'] * 1e3:.2f} ms/step (speed-up {row['speedup_np2']:.2f})"
                     if "np2_s_per_step" in row else ""), flush=True)
        out["smoke_wall_s"] = {}
        for path in sorted(RECIPE_DIR.glob("*.toml")):
            rec = load_recipe(path)
            t0 = time.perf_counter()
            R.run_recipe(rec, "smoke", cache=cache, np_=1, progress=False, force=True, echo=None)
            out["smoke_wall_s"][rec.name] = time.perf_counter() - t0
            print(f"{rec.name} smoke: {out['smoke_wall_s'][rec.name]:.1f} s (whole run, in process)", flush=True)
    out["k"] = max(r["k"] for r in out["systems"].values())
    out["speedup_np2"] = out["systems"]["surface_tension_spce"]["speedup_np2"]
    return out


def fmt_h(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.0f} min" if seconds < 5400 else f"{seconds / 3600:.0f} h"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--measure", action="store_true", help="measure the production/quick slow-down and np=2 speed-up")
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--factors", default=None, help="JSON written by an earlier --measure --json run")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    factors = measure_factors(args.steps) if args.measure else (
        json.loads(Path(args.factors).read_text())["factors"] if args.factors else None)
    rows = []
    print("| recipe | fidelity | atoms | MD steps | simulated (ns) | atom-steps | per-core speed (M atom-steps/s) "
          "| ns/day (1 core) | wall, 1 core | source |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for path in sorted(RECIPE_DIR.glob("*.toml")):
        rec = load_recipe(path)
        quick = committed_quick(rec)
        speed_q = quick["atom_steps_per_s"] if quick and not quick["_stale"] else None
        for fid in FIDELITIES:
            atoms, steps, dt = plan_size(rec, fid)
            aps = atoms * steps
            row = {"recipe": rec.name, "fidelity": fid, "atoms": atoms, "steps": steps, "timestep_fs": dt,
                   "simulated_ns": steps * dt * 1e-6, "atom_steps": aps}
            if fid == "quick" and speed_q:
                row.update(speed=speed_q, wall_s=quick["wall_s"]["dynamics"], source="measured (committed run)")
            elif fid == "smoke" and factors and rec.name in factors.get("smoke_wall_s", {}):
                w = factors["smoke_wall_s"][rec.name]
                row.update(speed=aps / w, wall_s=w, source="measured (whole run incl. set-up, 1 rank)")
            elif fid == "production" and speed_q and factors:
                sp = speed_q / factors["k"]
                row.update(speed=sp, wall_s=aps / sp, source=f"estimate: quick speed / k = {factors['k']:.2f}")
            else:
                row.update(speed=None, wall_s=None, source="not measured" if fid != "smoke" else
                           "seconds (CI runs every smoke recipe)")
            if row["speed"]:
                row["ns_per_day"] = row["simulated_ns"] / (aps / row["speed"]) * 86400
            rows.append(row)
            sp = f"{row['speed'] / 1e6:.2f}" if row["speed"] else "—"
            nd = f"{row['ns_per_day']:.1f}" if row.get("ns_per_day") else "—"
            wall = fmt_h(row["wall_s"]) if row["wall_s"] else "—"
            print(f"| `{rec.name}` | {fid} | {atoms} | {steps:,} | {row['simulated_ns']:.4g} | {aps:.3g} | {sp} | "
                  f"{nd} | {wall} | {row['source']} |")
    if factors:
        print(f"\nk (production settings / quick settings, same system, 1 rank) = {factors['k']:.2f}; "
              f"two-rank speed-up of the film = {factors['speedup_np2']:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"factors": factors, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
