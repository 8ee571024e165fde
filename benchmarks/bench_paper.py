"""What `nanoimpact paper` costs against the previous cycle's code, per set and per impact, against a floor.

    python benchmarks/bench_paper.py --side-by-side 5 [--baseline REV] [--keep-checks DIR]  # the budget check
    python benchmarks/bench_paper.py [--sets paper,silicon,calibrated] [--workers 2]
                                     [--baseline REV] [--skip-paper] [--whole] [--breakdown] [--repeat 5]

With `--side-by-side N` it prints only the budget check: the whole command as a user runs it
(`nanoimpact paper` with its defaults: every set, the default discrete-summit seeds and the sampled claims, 2
workers), for this tree and for git revision `--baseline` (default PREVIOUS_CYCLE, checked out into a temporary
git worktree that is removed afterwards), run alternately N times each (baseline, this tree, baseline, ...), each
tree's numba kernels loaded or compiled first by one untimed run of the command, and each run with an empty sample
cache (NANOIMPACT_CACHE: the seeds' and the sampled claims' bundles are run, as on a first run, never read back from
an earlier one). Each pair's ratio (baseline / this tree, wall and CPU of the command and its pool) and their range
are printed: on a shared machine the load moves both runs of a pair alike, so the pair ratios scatter far less than
the times.

Otherwise it prints, from one run of this script (so the ratios are comparable on a shared machine):

1. the paper's wall and CPU time per parameter set (`continuum.paper.run.run_paper`, one set at a time,
   each in a fresh interpreter with a process pool of `--workers`), and with `--baseline REV` the same
   for the code of git revision REV (exported with `git archive` into a temporary folder and run there);
   the CPU time (the process and its pool) is the steadier measure on a shared machine;
2. the cost of one rough impact (rough_silica, `paper` set, rigid substrate, 100 nm drop) through the
   driver with the compiled contact kernel, through the driver with the Python DOP853 stepper, and the
   floor: the same contact in the compiled kernel alone (tables built, no trace recorded by Python);
   with `--whole`, also the whole command as a user runs it (`nanoimpact paper`, every set in one process:
   runs, figures, checks and summary), for this tree and the baseline;
3. how the cost grows with the number of bounces (the whole rough_silica run, 1-100 bounces) and with
   the table size (footprint tables at the `fast`, `standard` and `reference` resolutions, all at rtol 1e-8).

With `--breakdown`, where the whole command's CPU goes (this tree only): the command process and its pool
apart, the pool's CPU by kind of run, and two costs that cut across the runs, the rigid rough roller's
footprint-table builds (`RigidRoughRoller._build`, per process: a table one worker built is built again
in the other) and the figures' rendering (`atomic_save_figure`, in the runs and in the command process), and the
costliest runs one by one.

The load average is printed at the start and the end: absolute times move by +-30 % on the shared
2-core machine, ratios much less.
"""
from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: The previous cycle's code: the last commit before the merge of the cycle that added the discrete-summit seeds
#: and the sampled claims to `nanoimpact paper` (`git log`: 4b7d0e0, 2026-11-26 16:13, then ten hours without a
#: commit until that cycle's merge began).
PREVIOUS_CYCLE = "4b7d0e0"

#: numba's one-time compile of the contact kernel (cached beside the module) is not a run's cost; an exported
#: baseline tree starts with an empty cache, so every tree is warmed first, untimed.
# compile (or load) a tree's numba kernels untimed (whole_command skips it for a revision from before the kernels)
#: each tree's kernels compiled or loaded, untimed (a tree from before continuum's modules moved into folders keeps
#: the compiled contact phase at the package root)
WARM_SNIPPET = """
try:
    from continuum.numerics.compiled_contact import warm_up
except ImportError:
    from continuum.compiled_contact import warm_up
warm_up()
"""

PAPER_SNIPPET = """
import sys
from continuum.paper.run import run_paper
run_paper([sys.argv[2]], sys.argv[1], workers=int(sys.argv[3]), progress=lambda m: None)
"""


def paper_walls(code_root: Path, sets: list[str], workers: int) -> dict[str, tuple[float, float]]:
    """(wall s, CPU s of the process and its pool) of run_paper for each set, each in a fresh interpreter run
    from `code_root`."""
    import resource

    out = {}
    env = {**os.environ, "PYTHONPATH": str(code_root)}
    subprocess.run([sys.executable, "-c", WARM_SNIPPET], cwd=code_root, env=env, check=True, capture_output=True)
    for name in sets:
        with tempfile.TemporaryDirectory() as folder:
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", PAPER_SNIPPET, folder, name, str(workers)], cwd=code_root, env=env,
                           check=True, capture_output=True)
            wall = time.perf_counter() - start
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
        out[name] = (wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime))
    return out


WHOLE_SNIPPET = """
import sys
from calibration.cli import main
sys.exit(main(["paper", "--out", sys.argv[1], "--params", sys.argv[2], "--workers", sys.argv[3], "-q"]))
"""


def whole_command(code_root: Path, sets: list[str], workers: int, warm: bool = True,
                  keep: Path | None = None) -> tuple[float, float]:
    """(wall s, CPU s) of `nanoimpact paper` for all `sets` in one process, run from `code_root` (its numba
    kernels loaded or compiled first, untimed, unless `warm` is False); with `keep`, the run's checks.json is
    copied there (the claims' verdicts and margins, to compare two trees' numbers)."""
    import resource

    env = {**os.environ, "PYTHONPATH": str(code_root)}
    if warm and (code_root / "continuum" / "compiled_contact.py").exists():
        subprocess.run([sys.executable, "-c", WARM_SNIPPET], cwd=code_root, env=env, check=True, capture_output=True)
    with tempfile.TemporaryDirectory() as folder, tempfile.TemporaryDirectory() as cache:
        # a fresh sample cache each run: the seeds' and sampled claims' bundles are run, never read back
        env["NANOIMPACT_CACHE"] = cache
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", WHOLE_SNIPPET, folder, ",".join(sets), str(workers)],
                              cwd=code_root, env=env, capture_output=True, text=True)
        if proc.returncode not in (0, 4):
            raise RuntimeError(f"nanoimpact paper in {code_root} failed: {proc.stderr[-2000:]}")
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if keep is not None and (Path(folder) / "checks.json").is_file():
            keep.parent.mkdir(parents=True, exist_ok=True)
            keep.write_bytes((Path(folder) / "checks.json").read_bytes())
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


BREAKDOWN_SNIPPET = """
import json, os, resource, sys, time
from continuum.numerics.compiled_contact import warm_up
warm_up()
import continuum.paper.run as run
import continuum.paper.figures as figures
import continuum.output.plots as plots
from continuum.laws import rough_rigid
log = open(sys.argv[4], "a", buffering=1)

def timed(what, fn):
    def wrapper(*a, **k):
        cpu = time.process_time()
        try:
            return fn(*a, **k)
        finally:
            log.write(json.dumps({"pid": os.getpid(), "what": what, "cpu": time.process_time() - cpu}) + "\\n")
    return wrapper

def build(self, depth, _orig=rough_rigid.RigidRoughRoller._build):
    fresh = depth not in self._kept_tables and (self._shared_key, depth) not in rough_rigid._SHARED_TABLES
    return timed("table build" if fresh else "table reuse", _orig)(self, depth)

rough_rigid.RigidRoughRoller._build = build
plots.atomic_save_figure = timed("figure", plots.atomic_save_figure)
figures.atomic_save_figure = timed("figure", figures.atomic_save_figure)
_orig_run = run._run
def _run(task):
    out = _orig_run(task)
    log.write(json.dumps({"pid": os.getpid(), "what": "run: " + out["kind"], "cpu": out["cpu_s"],
                          "task": f"{out['kind']} {out['case']} ({out['set']})"}) + "\\n")
    return out
run._run = _run
from calibration.cli import main
rc = main(["paper", "--out", sys.argv[1], "--params", sys.argv[2], "--workers", sys.argv[3], "-q"])
me = resource.getrusage(resource.RUSAGE_SELF)
log.write(json.dumps({"pid": os.getpid(), "what": "command process", "cpu": me.ru_utime + me.ru_stime}) + "\\n")
sys.exit(rc)
"""


def breakdown(sets: list[str], workers: int) -> dict:
    """(wall s, CPU s of the command and its pool, {what: (CPU s in the command process, CPU s in the pool,
    calls)}, [(task, CPU s), ...] costliest first) of `nanoimpact paper` for all `sets` in one process with
    BREAKDOWN_SNIPPET's counters."""
    import json
    import resource

    with tempfile.TemporaryDirectory() as folder:
        # a fresh sample cache: the seeds' and the sampled claims' bundles are run, as on a first run
        env = {**os.environ, "PYTHONPATH": str(ROOT), "NANOIMPACT_CACHE": str(Path(folder) / "cache")}
        log = Path(folder) / "cpu.jsonl"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-c", BREAKDOWN_SNIPPET, str(Path(folder) / "out"), ",".join(sets),
                               str(workers), str(log)], cwd=ROOT, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode not in (0, 4):
            raise RuntimeError(f"nanoimpact paper failed: {proc.stderr[-2000:]}")
        rows = [json.loads(line) for line in log.read_text().splitlines()]
    main_pid = next(r["pid"] for r in rows if r["what"] == "command process")
    out: dict = {}
    for r in rows:
        here, pool, calls = out.get(r["what"], (0.0, 0.0, 0))
        out[r["what"]] = (here + r["cpu"] * (r["pid"] == main_pid), pool + r["cpu"] * (r["pid"] != main_pid), calls + 1)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    tasks = sorted(((r["task"], r["cpu"]) for r in rows if "task" in r), key=lambda t: -t[1])
    return {"wall": wall, "cpu": cpu, "parts": out, "tasks": tasks}


def worktree(rev: str, dest: Path) -> Path:
    """A temporary git worktree of revision `rev` at `dest` (detached; `drop_worktree` removes it). Its shipped data
    is linked where an installed package keeps it (`nanoimpact/inputs`): the virtual environment's editable install
    would otherwise resolve `nanoimpact.inputs` to this tree's inputs/, whose parameter sets the older code may
    refuse."""
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(dest), rev], check=True,
                   capture_output=True)
    link = dest / "nanoimpact" / "inputs"
    if not link.exists():
        link.symlink_to(Path("..") / "inputs")
    return dest


def drop_worktree(dest: Path) -> None:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(dest)], check=False,
                   capture_output=True)


def machine() -> str:
    """The CPU model, its count and the Python version: the machine a timing belongs to."""
    model = "unknown CPU"
    try:
        model = next(ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{model}, {os.cpu_count()} CPUs, Python {sys.version.split()[0]}"


def side_by_side(rev: str, repeat: int, workers: int, sets: list[str], keep: Path | None = None) -> list[dict]:
    """`nanoimpact paper --params SETS` of revision `rev` and of this tree, alternately `repeat` times each (module
    docstring); [{'baseline': (wall, CPU), 'this tree': (wall, CPU), 'load': ...}, ...] per pair. With `keep`, each
    run's checks.json is kept as keep/<baseline|this-tree>-<pair>.json."""
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base = worktree(rev, Path(tmp) / "baseline")
        try:
            for root in (base, ROOT):                # compile or load each tree's kernels once, untimed
                subprocess.run([sys.executable, "-c", WARM_SNIPPET], cwd=root,
                               env={**os.environ, "PYTHONPATH": str(root)}, check=True, capture_output=True)
                # numba compiles a kernel the first time a process calls it: the kernels outside warm_up's set
                # (footprint quadratures, summit laws) would compile inside the first timed run of a tree whose
                # source-keyed cache is cold (a fresh baseline worktree, this tree after an edit)
                whole_command(root, sets, workers, warm=False)
            for i in range(repeat):
                pair = {"load": load()}
                order = ((("baseline", base), ("this tree", ROOT)) if i % 2 == 0 else
                         (("this tree", ROOT), ("baseline", base)))
                for name, root in order:
                    kept = keep / f"{name.replace(' ', '-')}-{i + 1}.json" if keep is not None else None
                    pair[name] = whole_command(root, sets, workers, warm=False, keep=kept)
                rows.append(pair)
                b, n = pair["baseline"], pair["this tree"]
                print(f"pair {i + 1} (load {pair['load']}): baseline {b[0]:6.1f} s wall {b[1]:6.1f} s CPU; "
                      f"this tree {n[0]:6.1f} s wall {n[1]:6.1f} s CPU; ratio baseline/this wall {b[0] / n[0]:.2f} "
                      f"CPU {b[1] / n[1]:.2f}", flush=True)
        finally:
            drop_worktree(base)
    return rows


def export_revision(rev: str, dest: Path) -> Path:
    """The tree of git revision `rev` exported into `dest` (no worktree, nothing in .git changes)."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    return dest


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def per_impact(repeat: int, resolution: str = "standard") -> dict:
    """Seconds per rough impact: driver + kernel, driver + Python stepper, kernel alone (the floor)."""
    from continuum.dynamics.driver import DriverSettings, simulate
    from continuum.dynamics.impact import first_impact_speed
    from continuum.model import select_law
    from continuum.numerics.compiled_contact import run_compiled
    from continuum.scene import resolve_scene

    resolved = resolve_scene(ROOT / "inputs" / "scenes" / "rough_silica.toml", params="paper",
                             overrides={"physics.half_space": "off", "numerics.fidelity": resolution,
                                        "numerics.rtol": 1e-8})
    scene = resolved.scene
    v = first_impact_speed(resolved)
    law, _ = select_law(scene, v)
    m, g, rtol = scene.body.mass, scene.environment.gravity, scene.numerics.rtol

    def driver(compiled):
        return simulate(law, m, g, impact_velocity=v, settings=DriverSettings(
            rtol=rtol, max_bounces=1, max_time=1.0, samples_per_flight=2, compiled=compiled))

    run = driver(True)                                   # compiles (or loads) the kernel, sizes the tables
    law.prepare(m, v, g)
    law.reset()
    length = law.length_scale(m, v)
    atol = np.array([rtol * length, rtol * v]) * 0.1

    def kernel():
        c = law.compiled(0.0)
        return run_compiled(c, m, g, 0.0, 0.0, -v, rtol=rtol, atol=atol, first_step=1e-3 * length / v,
                            max_step=math.inf, t_bound=1.0, release=law.release_gap(), bound_is_final=True,
                            has_history=True, samples_per_step=3)

    out = kernel()
    return {"compiled": _best(lambda: driver(True), repeat),
            "python": _best(lambda: driver(False), max(1, repeat // 2)),
            "floor": _best(kernel, repeat), "table_nodes": law.table_points, "samples": len(out.samples),
            "restitution": run.bounces[0].restitution, "stuck": run.stuck}


def per_bounce(repeat: int) -> list[tuple[int, float, int]]:
    """Wall (s) of the whole rough_silica impact run (select_law, tables, driver; `silicon` set, which rebounds
    100 times) for 1 to 100 bounces."""
    from continuum.dynamics.impact import run_impact
    from continuum.scene import resolve_scene

    rows = []
    for n in (1, 10, 30, 100):
        resolved = resolve_scene(ROOT / "inputs" / "scenes" / "rough_silica.toml", params="silicon",
                                 overrides={"physics.half_space": "off", "numerics.max_bounces": n})
        holder = {}

        def once():
            holder["r"] = run_impact(resolved).to_dict()

        rows.append((n, _best(once, repeat), holder["r"]["n_bounces"]))
    return rows


def print_breakdown(sets: list[str], workers: int) -> None:
    print(f"\n## Where `nanoimpact paper --params {','.join(sets)}` spends its CPU ({workers} workers; load at start "
          f"{load()})")
    b = breakdown(sets, workers)
    parts = b["parts"]
    print(f"wall {b['wall']:.1f} s, CPU {b['cpu']:.1f} s (command process {parts['command process'][0]:.1f} s)")
    print(f"{'what':28s} {'command CPU s':>14s} {'pool CPU s':>11s} {'calls':>6s}")
    for what, (here, pool, calls) in sorted(parts.items(), key=lambda kv: -(kv[1][0] + kv[1][1])):
        if what != "command process":
            print(f"{what:28s} {here:14.1f} {pool:11.1f} {calls:6d}")
    print(f"\nthe costliest runs (CPU s; {len(b['tasks'])} runs):")
    for task, cpu in b["tasks"][:12]:
        print(f"  {cpu:7.1f}  {task}")


def _dirty() -> bool:
    return bool(subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip())


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sets", default="paper,silicon,calibrated")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--baseline", default=None, help="git revision to time the paper with as well")
    parser.add_argument("--skip-paper", action="store_true")
    parser.add_argument("--whole", action="store_true", help="also time the whole `nanoimpact paper` command")
    parser.add_argument("--breakdown", action="store_true", help="where the whole command's CPU goes (this tree)")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--side-by-side", type=int, default=0, metavar="N",
                        help="only the budget check: this tree and --baseline (default PREVIOUS_CYCLE) alternately, "
                        "N times each")
    parser.add_argument("--keep-checks", type=Path, default=None, metavar="DIR",
                        help="with --side-by-side: keep each run's checks.json in DIR")
    args = parser.parse_args(argv)
    sets = args.sets.split(",")
    print(f"load average at start: {load()}  ({machine()})")
    if args.side_by_side:
        rev = args.baseline or PREVIOUS_CYCLE
        head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True).stdout.strip() + (" + uncommitted changes" if _dirty() else "")
        print(f"\n## nanoimpact paper --params {args.sets} --workers {args.workers}: {rev} against this tree "
              f"({head}), alternately")
        rows = side_by_side(rev, args.side_by_side, args.workers, sets, args.keep_checks)
        for what, k in (("wall", 0), ("CPU", 1)):
            r = sorted(p["baseline"][k] / p["this tree"][k] for p in rows)
            t = sorted(p["this tree"][k] for p in rows)
            b = sorted(p["baseline"][k] for p in rows)
            print(f"{what}: ratio baseline / this tree {r[0]:.2f}-{r[-1]:.2f} (median {r[len(r) // 2]:.2f}); "
                  f"this tree {t[0]:.1f}-{t[-1]:.1f} s, baseline {b[0]:.1f}-{b[-1]:.1f} s")
        print(f"\nload average at end: {load()}")
        return
    from continuum.numerics.compiled_contact import warm_up
    warm_up()                                   # the kernel's load (or first compile) is not an impact's cost

    print("\n## Cost of one rough impact (rough_silica, paper set, rigid substrate, 100 nm drop; best of "
          f"{args.repeat})")
    print(f"{'tables':10s} {'nodes':>7s} {'driver+kernel ms':>17s} {'driver+Python ms':>17s} {'floor ms':>9s} "
          f"{'kernel/floor':>13s} {'Python/floor':>13s} {'samples':>8s}")
    for res in ("fast", "standard", "reference"):
        c = per_impact(args.repeat, res)
        print(f"{res:10s} {c['table_nodes']:7d} {1e3 * c['compiled']:17.2f} {1e3 * c['python']:17.1f} "
              f"{1e3 * c['floor']:9.3f} {c['compiled'] / c['floor']:13.1f} {c['python'] / c['floor']:13.0f} "
              f"{c['samples']:8d}")

    print("\n## Whole run against the number of bounces (rough_silica, silicon set; "
          f"best of {max(1, args.repeat // 2)})")
    print(f"{'bounces':>8s} {'wall s':>8s} {'per bounce ms':>14s} {'each bounce after the first ms':>31s}")
    rows = per_bounce(max(1, args.repeat // 2))
    first = rows[0][1]
    for n, wall, got in rows:
        extra = f"{1e3 * (wall - first) / (got - 1):31.2f}" if got > 1 else f"{'':>31s}"
        print(f"{got:8d} {wall:8.3f} {1e3 * wall / max(got, 1):14.1f} {extra}")

    if not args.skip_paper:
        print(f"\n## nanoimpact paper, one set at a time ({args.workers} workers)")
        walls = {"this tree": paper_walls(ROOT, sets, args.workers)}
        if args.baseline:
            with tempfile.TemporaryDirectory() as tmp:
                walls[f"baseline {args.baseline}"] = paper_walls(export_revision(args.baseline, Path(tmp)), sets,
                                                                 args.workers)
        print(f"{'code':24s} " + " ".join(f"{s + ' wall/CPU s':>22s}" for s in sets) + f" {'total wall/CPU s':>18s}")
        for name, w in walls.items():
            tw, tc = sum(v[0] for v in w.values()), sum(v[1] for v in w.values())
            print(f"{name:24s} " + " ".join(f"{w[s][0]:11.1f} {w[s][1]:10.1f}" for s in sets) + f" {tw:9.1f} {tc:8.1f}")
        if args.baseline:
            base, now = walls[f"baseline {args.baseline}"], walls["this tree"]
            ratio = [(base[s][0] / now[s][0], base[s][1] / now[s][1]) for s in sets]
            tot = (sum(v[0] for v in base.values()) / sum(v[0] for v in now.values()),
                   sum(v[1] for v in base.values()) / sum(v[1] for v in now.values()))
            print(f"{'speed-up':24s} " + " ".join(f"{a:11.1f} {b:10.1f}" for a, b in ratio)
                  + f" {tot[0]:9.1f} {tot[1]:8.1f}")
    if args.whole:
        print(f"\n## nanoimpact paper --params {','.join(sets)} (one process, {args.workers} workers; runs, figures, "
              f"checks, summary)")
        rows = {"this tree": whole_command(ROOT, sets, args.workers)}
        if args.baseline:
            with tempfile.TemporaryDirectory() as tmp:
                rows[f"baseline {args.baseline}"] = whole_command(export_revision(args.baseline, Path(tmp)), sets,
                                                                  args.workers)
        for name, (wall, cpu) in rows.items():
            print(f"{name:24s} wall {wall:7.1f} s  CPU {cpu:7.1f} s")
        if args.baseline:
            (bw, bc), (nw, nc) = rows[f"baseline {args.baseline}"], rows["this tree"]
            print(f"{'speed-up':24s} wall {bw / nw:7.2f}    CPU {bc / nc:7.2f}")
    if args.breakdown:
        print_breakdown(sets, args.workers)
    print(f"\nload average at end: {load()}")


if __name__ == "__main__":
    main()
