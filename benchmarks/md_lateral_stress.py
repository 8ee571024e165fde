"""Lateral stress of the free silica slab at the builder's lattice constant (the second MD review's F10.4).

    .venv/bin/python benchmarks/md_lateral_stress.py [--thickness 10 25] [--nx 6] [--ny 3] [--steps 12000]
                                                     [--lattice-a A] [--json PATH]

The slabs of every silica recipe keep the ideal beta-cristobalite lattice of the builder (``md.build.silica``),
and the box is never relaxed under the IFF force field (Emami et al., Chem. Mater. 26 (2014) 2647). The review
asks whether that strains them: check the in-plane stress of a relaxed slab once, and rescale if it exceeds about
0.5 GPa. What this script does, per slab thickness:

1. builds the (111) slab of the recipes' surface (isolated Q3 silanols, both faces hydroxylated), nothing held;
2. minimises it (FIRE) and runs NVT at 300 K (Nose-Hoover, 100 fs) with the recipes' settings (lj/cut/coul/long
   12 A, PPPM 1e-4 with the slab correction, 1 fs), the first sixth as equilibration;
3. samples Pxx and Pyy every 10 steps. The slab's in-plane force per length is S = -(Pxx + Pyy)/2 V / A (V the
   box volume, A its area: the vacuum carries no stress), in N/m; positive S is tension.

For a slab of thickness t, S = sigma_bulk t + 2 f (f the surface stress of one face), so two thicknesses give the
bulk stress sigma_bulk = dS/dt (t: the span of the Si planes, the same for both definitions up to a constant) --
the part a lattice rescale would remove -- and the surface stress f, which no lattice constant removes. Errors:
block averages (10 blocks) of the sampled S. ``--lattice-a`` builds the slabs at another cubic lattice constant
(default: the builder's, ``md.build.silica.CRISTOBALITE_A``), to find the one at which the bulk stress vanishes. A
script, not a test; it runs LAMMPS in this process on one core (about a minute per 1000 atoms and 10 000 steps on
the development machine).
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from md import units as U  # noqa: E402
from md.build.common import silica_forcefield  # noqa: E402
from md.build.silica import CRISTOBALITE_A, silica_slab  # noqa: E402
from md.lammps_loader import new_lammps  # noqa: E402
from md.system.lammps_data import lammps_setup_commands, write_data  # noqa: E402

N_BLOCKS = 10


def slab_stress(thickness: float, nx: int, ny: int, steps: int, work: Path, seed: int = 1,
                lattice_a: float | None = None) -> dict:
    """Build, minimise and sample one free slab; its in-plane force per length S (N/m) with a block stderr."""
    ff = silica_forcefield()
    atoms = silica_slab(nx, ny, thickness=thickness, face="111", seed=seed, vacuum=15.0, lattice_a=lattice_a)
    data = write_data(atoms, ff, work / f"slab_{thickness:g}.data")
    sym = np.array(atoms.get_chemical_symbols())
    zsi = atoms.positions[sym == "Si", 2]
    lmp = new_lammps(["-nocite", "-screen", "none", "-log", (work / f"log_{thickness:g}.lammps").as_posix()])
    try:
        for c in lammps_setup_commands(ff, data, boundary="p p f", pair="long", cutoff=12.0, kspace_accuracy=1e-4):
            lmp.command(c)
        for c in ["neighbor 2.0 bin", "neigh_modify delay 0 every 1 check yes", "timestep 1.0",
                  "fix zwalls all wall/reflect zlo EDGE zhi EDGE",
                  "min_style fire", "minimize 0.0 1.0e-3 1000 10000", "reset_timestep 0",
                  f"velocity all create 300 {seed + 4242} mom yes rot no dist gaussian",
                  "fix nvt all nvt temp 300 300 100",
                  "variable pxx equal pxx", "variable pyy equal pyy", "variable vol equal vol",
                  f"run {steps // 6}",
                  "fix samp all ave/time 10 1 10 v_pxx v_pyy v_vol file "
                  f"{(work / f'samples_{thickness:g}.dat').as_posix()}",
                  f"run {steps - steps // 6}", "unfix samp"]:
            lmp.command(c)
    finally:
        lmp.close()
    rows = np.loadtxt(work / f"samples_{thickness:g}.dat", comments="#")
    pxx, pyy, vol = rows[:, 1], rows[:, 2], rows[:, 3]
    area = float(atoms.cell[0, 0] * atoms.cell[1, 1])
    s_atm_a = -0.5 * (pxx + pyy) * vol / area                 # atm A
    s = U.atm_A_to_N_per_m(s_atm_a)
    blocks = np.array([b.mean() for b in np.array_split(s, N_BLOCKS)])
    return {"thickness_request_A": thickness, "si_span_A": float(zsi.max() - zsi.min()), "atoms": len(atoms),
            "area_A2": area, "samples": int(s.size), "S_N_per_m": float(s.mean()),
            "S_stderr_N_per_m": float(blocks.std(ddof=1) / np.sqrt(N_BLOCKS)),
            "Sxx_N_per_m": float(U.atm_A_to_N_per_m(-(pxx * vol / area).mean())),
            "Syy_N_per_m": float(U.atm_A_to_N_per_m(-(pyy * vol / area).mean()))}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--thickness", type=float, nargs=2, default=[10.0, 25.0], metavar=("T1", "T2"),
                    help="two slab thicknesses (A, Si-plane span requested from the builder)")
    ap.add_argument("--nx", type=int, default=6)
    ap.add_argument("--ny", type=int, default=3)
    ap.add_argument("--steps", type=int, default=12000)
    ap.add_argument("--lattice-a", type=float, default=None, help="cubic lattice constant (A) of the build")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="md_lateral_stress_") as tmp:
        rows = [slab_stress(t, args.nx, args.ny, args.steps, Path(tmp), lattice_a=args.lattice_a)
                for t in args.thickness]
    a, b = rows
    dt_m = U.angstrom_to_m(b["si_span_A"] - a["si_span_A"])
    sigma = (b["S_N_per_m"] - a["S_N_per_m"]) / dt_m
    sigma_err = float(np.hypot(a["S_stderr_N_per_m"], b["S_stderr_N_per_m"]) / dt_m)
    f_surface = 0.5 * (a["S_N_per_m"] - sigma * U.angstrom_to_m(a["si_span_A"]))
    for r in rows:
        print(f"t = {r['si_span_A']:5.2f} A ({r['atoms']} atoms): S = {r['S_N_per_m']:+.3f} +- "
              f"{r['S_stderr_N_per_m']:.3f} N/m (xx {r['Sxx_N_per_m']:+.3f}, yy {r['Syy_N_per_m']:+.3f}); "
              f"mean stress S/t = {r['S_N_per_m'] / U.angstrom_to_m(r['si_span_A']) / 1e9:+.2f} GPa")
    print(f"bulk in-plane stress dS/dt = {sigma / 1e9:+.2f} +- {sigma_err / 1e9:.2f} GPa (positive: tension); "
          f"surface stress per face f = {f_surface:+.3f} N/m; review threshold 0.5 GPa")
    if args.json:
        Path(args.json).write_text(json.dumps({"lattice_a_A": args.lattice_a or CRISTOBALITE_A, "rows": rows,
                                               "sigma_bulk_Pa": sigma, "sigma_bulk_stderr_Pa": sigma_err,
                                               "surface_stress_N_per_m": f_surface}, indent=1))


if __name__ == "__main__":
    main()
