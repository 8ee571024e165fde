"""Cost of building the tabulated summit laws (Maugis-Dugdale, and Thornton-Ning's plastic construction on it), this
tree against a baseline revision, measured in one run.

    .venv/bin/python benchmarks/bench_summit_laws.py [--baseline REV] [--set calibrated] [--row 0] [--repeat 3]
                                                     [--pairs 1] [--json FILE]

Each tree (this one, and `--baseline` exported with `git archive` into a temporary folder) runs in a fresh
interpreter: one Latin-hypercube bundle of `--set` (`continuum.paper.samples._bundle`, row `--row`, the dry cases,
as `nanoimpact paper` runs it) once untimed (numba kernels compiled or loaded, the summit laws' parameters
recorded), then, with the summit-law caches emptied,

* `md_law`: one Maugis-Dugdale summit law (`make_summit_law`'s uncached builder) at the bundle's first plastic
  summit's numbers, best of `--repeat`;
* `plastic_law`: that plastic summit law (`PlasticBranchSummitLaw`, its node laws built too), best of `--repeat`;
* `bundle`: the bundle again, wall and CPU, and the time spent in it building plastic summit laws (`plastic_in_bundle`,
  the factory's `_plastic_summit_law` calls).

The trees alternate (`--pairs` pairs, the baseline first in odd pairs); the ratios baseline / this tree are of the
same pair. The cores are shared: the load average is printed, and the CPU times move less with it.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

log = logging.getLogger("bench_summit_laws")

#: the tree before the compiled Maugis root and flattening table
BASELINE = "4745e9e"

SNIPPET = r"""
import json, sys, time
import continuum.model.factory as factory
from continuum.paper.samples import set_uncertainty_rows, bundle_cases, _bundle
from continuum.paper.run import dry_cases
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.plastic_branches import PlasticBranchSummitLaw

name, row, repeat = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = set_uncertainty_rows([name])[name]
cases = bundle_cases(dry_cases())
cached, calls, spent = factory._plastic_summit_law, [], [0.0]


def timed(*args):
    calls.append(args)
    start = time.perf_counter()
    try:
        return cached(*args)
    finally:
        spent[0] += time.perf_counter() - start


factory._plastic_summit_law = timed


def clear():
    cached.cache_clear()
    make_summit_law.cache_clear()


def best(fn):
    out = []
    for _ in range(repeat):
        clear()
        start = time.perf_counter()
        fn()
        out.append(time.perf_counter() - start)
    return min(out)


_bundle(name, "u1", rows[row], None, cases, True)
law_args = next(a for a in calls if a[0] != "jkr")
lname, radius, w, e_star, p_y, z0, delta_max = law_args
md = best(lambda: make_summit_law.__wrapped__("maugis_dugdale", radius, w, e_star, z0=z0, delta_max=delta_max))
plastic = best(lambda: PlasticBranchSummitLaw(lname, radius, w, e_star, p_y, z0=z0, delta_max=delta_max))
clear()
spent[0] = 0.0
start, cpu = time.perf_counter(), time.process_time()
_bundle(name, "u1", rows[row], None, cases, True)
wall, cpu = time.perf_counter() - start, time.process_time() - cpu
print(json.dumps({"md_law": md, "plastic_law": plastic, "bundle_wall": wall, "bundle_cpu": cpu,
                  "plastic_in_bundle": spent[0], "law": [float(x) if not isinstance(x, str) else x for x in law_args]}))
"""


def export_revision(rev: str, dest: Path) -> Path:
    """The tree of git revision `rev` exported into `dest` (nothing in .git changes), its shipped inputs linked
    where an installed package looks for them."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    link = dest / "nanoimpact" / "inputs"
    if not link.exists():
        link.symlink_to(Path("..") / "inputs")
    return dest


def measure(tree: Path, name: str, row: int, repeat: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    proc = subprocess.run([sys.executable, "-c", SNIPPET, name, str(row), str(repeat)], cwd=tree, env=env,
                          capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{tree}: {proc.stderr[-2000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=BASELINE)
    parser.add_argument("--set", default="calibrated")
    parser.add_argument("--row", type=int, default=0)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--pairs", type=int, default=1)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    pairs = []
    with tempfile.TemporaryDirectory() as tmp:
        base = export_revision(args.baseline, Path(tmp))
        for i in range(args.pairs):
            order = (("baseline", base), ("this tree", ROOT)) if i % 2 == 0 else (("this tree", ROOT),
                                                                                  ("baseline", base))
            pair = {"load_start": os.getloadavg()[0]}
            for label, tree in order:
                log.info("pair %d: %s ...", i + 1, label)
                pair[label] = measure(tree, args.set, args.row, args.repeat)
            pair["load_end"] = os.getloadavg()[0]
            pairs.append(pair)
    for i, pair in enumerate(pairs, 1):
        b, n = pair["baseline"], pair["this tree"]
        print(f"pair {i} (load {pair['load_start']:.1f} -> {pair['load_end']:.1f}), baseline {args.baseline} / this "
              f"tree:")
        for key, what in (("md_law", "one Maugis-Dugdale summit law"), ("plastic_law", "one plastic MD summit law"),
                          ("plastic_in_bundle", "plastic summit laws in the bundle"),
                          ("bundle_wall", "bundle wall"), ("bundle_cpu", "bundle CPU")):
            print(f"  {what:36s} {b[key]:9.4f} s  {n[key]:9.4f} s  ratio {b[key] / n[key]:7.1f}")
        print(f"  law: {n['law']}")
    if args.json:
        args.json.write_text(json.dumps({"baseline": args.baseline, "set": args.set, "row": args.row,
                                         "pairs": pairs}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
