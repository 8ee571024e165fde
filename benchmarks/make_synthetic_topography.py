"""Write the shipped synthetic height map, inputs/topographies/synthetic_selfaffine.txt.

A periodic self-affine Gaussian surface from SurfaceTopography's Fourier synthesis (Jacobs, Junge & Pastewka,
Surf. Topogr.: Metrol. Prop. 5 (2017) 013001): 128 x 128 points on 5 um x 5 um, Hurst exponent 0.8, rms height
6 nm, spectrum flat above 1.25 um and empty below 0.3125 um (8 pixels), seed 2017. Written as the plain-text
matrix SurfaceTopography reads (a `# Width`, `# Height`, `# Value units` header and heights in nm to 1 pm), so
the file carries its own size and unit and stays small (about 120 kB). The file is not periodic once read
(SurfaceTopography takes a text matrix as non-periodic), which is how a measured map is treated.

    python benchmarks/make_synthetic_topography.py [--out FILE]
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from SurfaceTopography.Generation import fourier_synthesis

from nanoimpact.fileio import atomic_write_text

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "inputs" / "topographies" / "synthetic_selfaffine.txt"
N, SIZE, HURST, RMS, SHORT, LONG, SEED = 128, 5e-6, 0.8, 6e-9, 0.3125e-6, 1.25e-6, 2017


def render() -> str:
    topo = fourier_synthesis((N, N), (SIZE, SIZE), HURST, rms_height=RMS, short_cutoff=SHORT, long_cutoff=LONG,
                             rng=np.random.default_rng(SEED), unit="m")
    heights_nm = np.asarray(topo.heights()) * 1e9
    header = [f"# Channel: Height (synthetic: fourier_synthesis H={HURST}, rms {RMS:g} m, short_cutoff {SHORT:g} m, "
              f"long_cutoff {LONG:g} m, seed {SEED}; benchmarks/make_synthetic_topography.py)",
              f"# Width: {SIZE * 1e6:g} µm", f"# Height: {SIZE * 1e6:g} µm", "# Value units: nm"]
    # SurfaceTopography reads a text matrix as rows = y, columns = x (heights[x, y] is the transpose)
    rows = [" ".join(f"{v:.3f}" for v in row) for row in heights_nm.T]
    return "\n".join(header + rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=OUT)
    args = p.parse_args(argv)
    atomic_write_text(args.out, render())
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
