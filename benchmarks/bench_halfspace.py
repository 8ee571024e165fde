"""Cost of the line half-space vs grid size: FFT displacement, coupled solve, hard-contact solve.

Run:  python benchmarks/bench_halfspace.py [--quick]

Problem: Hertz-sized roller contact (R = 5 um, E* = 100 GPa, W' = 1 N/m, x_ref = 3.3 mm), grid
2 Hertz half-widths either side, so the physical problem is the same at every N. The coupled
solve uses a cold start (p = 0) with the test suite's stiff exponential wall
p = p0 exp(-h/lam), lam = 1e-13 m (mu = |dp/dh| x compliance ~ 1e3), at the rigid approach of
the hard-contact solution. Prints N, wall time, time / (N log2 N), and iteration counts.
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

from continuum.elastic.halfspace import choose_grid, solve_coupled, solve_hard_contact
from continuum.reference.hertz import line_peak_pressure

E_STAR, RADIUS, LOAD, X_REF = 100e9, 5e-6, 1.0, 3.3e-3


def wall(p_s: float, lam: float):
    """Exponential repulsion for h > 0, continued linearly (C1) into overlap."""
    def law(h):
        e = np.exp(-np.maximum(h, 0.0) / lam)
        p = np.where(h > 0, p_s * e, p_s * (1.0 - h / lam))
        dp = np.where(h > 0, -p_s * e / lam, -p_s / lam)
        return p, dp
    return law


def best_time(fn, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(quick: bool = False) -> None:
    sizes = [64, 128, 256, 512, 1024] if quick else [64, 128, 256, 512, 1024, 2048, 4096, 8192]
    p0 = float(line_peak_pressure(LOAD, RADIUS, 1.0, E_STAR))     # per unit length: a roller of 1 m
    law = wall(p0, 1e-13)
    rng = np.random.default_rng(0)
    print("displacement (one FFT convolution, best of many)")
    print(f"{'N':>6} {'time [s]':>11} {'t/(N log2 N) [s]':>17}")
    for n in sizes:
        hs = choose_grid(RADIUS, LOAD, E_STAR, n_points=n, span=2.0).half_space(E_STAR, x_ref=X_REF)
        p = rng.random(n)
        reps = max(20, 200000 // n)
        t = best_time(lambda: hs.displacement(p), 5) if n > 4096 else \
            min(best_time(lambda: [hs.displacement(p) for _ in range(reps)], 3) / reps, math.inf)
        print(f"{n:6d} {t:11.3e} {t / (n * math.log2(n)):17.3e}")

    print("\nsolve_hard_contact (Polonsky-Keer CG) and solve_coupled (cold start, stiff wall)")
    print(f"{'N':>6} {'hard [s]':>10} {'CG its':>7} {'coupled [s]':>12} {'t/(N log2 N)':>13} "
          f"{'method':>8} {'its':>4} {'matvecs':>8} {'|W/W_hard-1|':>13}")
    for n in sizes:
        hs = choose_grid(RADIUS, LOAD, E_STAR, n_points=n, span=2.0).half_space(E_STAR, x_ref=X_REF)
        gap0 = hs.x**2 / (2 * RADIUS)
        t0 = time.perf_counter()
        hard = solve_hard_contact(hs, gap0, LOAD)
        t_hard = time.perf_counter() - t0
        t0 = time.perf_counter()
        sol = solve_coupled(hs, gap0 + hard.h_ref, law)
        t_c = time.perf_counter() - t0
        print(f"{n:6d} {t_hard:10.3e} {hard.iterations:7d} {t_c:12.3e} {t_c / (n * math.log2(n)):13.3e} "
              f"{sol.method:>8} {sol.iterations:4d} {sol.matvecs:8d} {abs(sol.load_per_length / LOAD - 1):13.2e}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="only N <= 1024")
    main(ap.parse_args().quick)
