"""How the error of the SPC/E surface tension shrinks with run length and system size.

    .venv/bin/python benchmarks/bench_md_convergence.py [DIR ...] [--fractions 0.25,0.5,1] [--json PATH]

Each DIR holds an exported surface-tension run: `result.json` and `pressure_tensor.csv` (sampled steps only,
SI units), as written by `nanoimpact md surface_tension_spce --out DIR` and committed under
`inputs/md/results/`. Default: every `inputs/md/results/surface_tension_spce*` folder.

For the first 25 %, 50 % and 100 % of each run's samples: the Kirkwood-Buff surface tension
gamma = (Lz/2)(<Pzz> - (<Pxx> + <Pyy>)/2) with the run's own LJ tail correction added, its block-averaged
standard error with the run's `n_blocks` (as in result.json), and the Flyvbjerg-Petersen plateau estimate
(`md.analysis.block_analysis`) as a check that the blocks are long enough. Also the simulated time, the
atom count and the wall time that fraction cost (the run's measured dynamics wall time, prorated by steps
and including the unsampled equilibration). Reads files only; runs no MD.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from md.analysis import block_analysis, block_average  # noqa: E402


def load(folder: Path):
    res = json.loads((folder / "result.json").read_text())
    with open(folder / "pressure_tensor.csv") as fh:
        rows = list(csv.DictReader(fh))
    cols = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    # gamma(t) in N/m: pressures in Pa, Lz in m
    g = 0.5 * cols["lz_m"] * (cols["pzz_Pa"] - 0.5 * (cols["pxx_Pa"] + cols["pyy_Pa"]))
    return res, cols["step"], g


def analyse(folder: Path, fractions: list[float]) -> list[dict]:
    res, steps, g = load(folder)
    s = res["settings"]
    tail = float(res["details"]["tail_correction_N_per_m"])
    nb = int(s["n_blocks"])
    dt = float(res["timestep_fs"])
    eq = int(s["equilibrate_steps"])
    wall = float(res["wall_s"]["dynamics"])
    total = int(res["steps"])
    out = []
    for f in fractions:
        n = max(nb, int(round(f * g.size)))
        x = g[:n]
        mean, err = block_average(x, nb)
        fp = block_analysis(x)
        sampled_steps = n * int(s["sample_interval"])
        out.append({
            "run": folder.name, "atoms": res["n_atoms"], "fraction": f, "samples": n,
            "sampled_ps": sampled_steps * dt / 1000.0,
            "wall_s": wall * (eq + sampled_steps) / total,
            "gamma_mN_m": (mean + tail) * 1e3, "stderr_mN_m": err * 1e3,
            "stderr_fp_plateau_mN_m": fp["stderr_plateau"] * 1e3 if math.isfinite(fp["stderr_plateau"]) else None,
            "density_kg_m3": res["quantities"]["density"]["value"] if f == 1.0 else None,
        })
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="*")
    ap.add_argument("--fractions", default="0.25,0.5,1")
    ap.add_argument("--json", default=None)
    ap.add_argument("--png", default=None, help="also draw gamma against sampled time, one line per system size")
    args = ap.parse_args(argv)
    dirs = [Path(d) for d in args.dirs] or sorted((ROOT / "inputs/md/results").glob("surface_tension_spce*"))
    missing = [d for d in dirs if not (d / "result.json").exists()]
    for d in missing:
        print(f"{d.name}: no result.json (recipe prepared, not run yet): skipped")
    dirs = [d for d in dirs if d not in missing]
    fr = [float(x) for x in args.fractions.split(",")]
    rows = [r for d in dirs for r in analyse(d, fr)]
    print(f"{'run':34s} {'atoms':>5s} {'frac':>5s} {'ps':>6s} {'wall s':>7s} {'gamma mN/m':>11s} {'stderr':>7s} "
          f"{'FP plateau':>10s}")
    for r in rows:
        fp = f"{r['stderr_fp_plateau_mN_m']:.2f}" if r["stderr_fp_plateau_mN_m"] is not None else "n/a"
        print(f"{r['run']:34s} {r['atoms']:5d} {r['fraction']:5.2f} {r['sampled_ps']:6.1f} {r['wall_s']:7.0f} "
              f"{r['gamma_mN_m']:11.2f} {r['stderr_mN_m']:7.2f} {fp:>10s}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if args.png:
        draw(rows, Path(args.png))
    return 0


def draw(rows: list[dict], path: Path) -> None:
    """gamma +- stderr against sampled time for each run (smoke left out: 0.8 ps), Vega & de Miguel's 63.6 mN/m."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.6))
    runs = sorted({r["run"] for r in rows if r["sampled_ps"] > 10}, key=lambda n: next(r["atoms"] for r in rows
                                                                                         if r["run"] == n))
    for k, name in enumerate(runs):
        rr = [r for r in rows if r["run"] == name]
        t = [r["sampled_ps"] * (1 + 0.02 * (k - 1)) for r in rr]
        ax.errorbar(t, [r["gamma_mN_m"] for r in rr], yerr=[r["stderr_mN_m"] for r in rr], marker="o", ms=4,
                    capsize=3, label=f"{rr[0]['atoms']} atoms")
        full = rr[-1]
        bx.errorbar(full["atoms"], full["gamma_mN_m"], yerr=full["stderr_mN_m"], marker="o", ms=5, capsize=3,
                    color=f"C{k}")
    for a in (ax, bx):
        a.axhline(63.6, color="k", lw=0.8, ls="--")
        a.set_ylabel("γ_lv (mN/m)")
    ax.set_xscale("log")
    ax.set_xlabel("sampled time (ps)")
    ax.set_title("run length (first 25/50/100 %)", fontsize=9)
    ax.legend(fontsize=8)
    bx.set_xlabel("atoms (film 30 Å thick; box 20, 25, 35 Å)")
    bx.set_title("system size, 220 ps each; dashed: Vega & de Miguel 2007", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
