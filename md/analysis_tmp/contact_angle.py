"""Analysis of the molecular runs: errors, works of adhesion, contact angles, surface tension, pull-off.

Inputs are what LAMMPS ``units real`` writes (kcal/mol, angstrom, atm, g/mol); every function returns SI
(J/m^2, N/m, N, m, kg/m^3) unless its name or key says otherwise (``angle_deg``, ``*_A``, g/cm^3 density
maps).  Every conversion factor comes from :mod:`md.units`.

Sources (details and measured accuracies: ``docs/_fragments/md_analysis.md``):

* block averaging -- Flyvbjerg & Petersen, J. Chem. Phys. 91 (1989) 461;
* cylindrical droplets -- de Ruijter, Blake & De Coninck, Langmuir 15 (1999) 2209 (a droplet periodic
  along one axis has a straight contact line, so its angle carries no line-tension correction);
  Weijs, Marchand, Andreotti, Lohse & Snoeijer, Phys. Fluids 23 (2011) 022001 (circular fit away from
  the wall-layered region);
* circle fits -- Kasa, IEEE Trans. Instrum. Meas. 25 (1976) 8 (algebraic), then geometric least squares;
* surface tension -- Kirkwood & Buff, J. Chem. Phys. 17 (1949) 338; LJ tail: Blokhuis, Bedeaux, Holcomb
  & Zollweg, Mol. Phys. 85 (1995) 665; SPC/E reference: Vega & de Miguel, J. Chem. Phys. 126 (2007)
  154707 (63.6 mN/m at 300 K);
* traction law -- Maugis, J. Colloid Interface Sci. 150 (1992) 243 (LJ 9-3 law, sigma0 = 1.026 w/z0,
  Dugdale range h0 = w/sigma0); Derjaguin, Kolloid Z. 69 (1934) 155 (sphere-flat force = 2 pi R x
  energy per area);
* rate dependence -- Bell, Science 200 (1978) 618; Evans & Ritchie, Biophys. J. 72 (1997) 1541.

:class:`ContactAngle` needs MDAnalysis (the ``md`` extra); everything else needs numpy and scipy only.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from md import units as _units

__all__ = [
    "KCALMOL_PER_A2_TO_J_PER_M2", "KCALMOL_PER_A_TO_N", "ATM_A_TO_N_PER_M", "WATER_MOLAR_MASS",
    "block_average", "block_analysis", "statistical_inefficiency", "detect_equilibration", "timeseries_stats",
    "force_integration_work", "registry_average", "traction_peak", "flat_slab_range", "lj_tail_between",
    "MAUGIS_LJ93",
    "energy_separation_work", "work_from_energy_curve",
    "ContactAngle", "fit_contact_angle", "fit_circle", "dividing_plane", "wetting_bound", "block_drift",
    "work_of_adhesion_sl", "cap_angle_for_base", "cap_angle_for_height",
    "surface_tension", "lj_tail_correction", "density_profile", "slab_density",
    "pull_off_analysis", "fit_traction_law", "rate_extrapolation",
]

# ----------------------------------------------------------------------------------------------- units
# Every LAMMPS real -> SI factor comes from md.units (the one place for them).
#: 1 kcal/mol/A^2 in J/m^2 (kcal 4184 J, N_A 6.02214076e23: 0.694769...)
KCALMOL_PER_A2_TO_J_PER_M2 = float(_units.kcal_per_mol_A2_to_J_per_m2(1.0))
#: 1 kcal/mol/A in N (6.94769...e-11)
KCALMOL_PER_A_TO_N = float(_units.kcal_per_mol_A_to_N(1.0))
#: 1 atm A in N/m (1.01325e-5)
ATM_A_TO_N_PER_M = float(_units.atm_A_to_N_per_m(1.0))
#: Molar mass of water in g/mol (one oxygen per molecule in density maps).
WATER_MOLAR_MASS = _units.WATER_MOLAR_MASS


# ---------------------------------------------------------------------------------------- block errors

def block_average(x, n_blocks: int = 5) -> tuple[float, float]:
    """Mean and standard error of a correlated time series by block averaging (Flyvbjerg-Petersen 1989).

    The series is cut into ``n_blocks`` contiguous blocks of equal length (the first ``len(x) % n_blocks``
    samples -- the oldest -- are dropped); ``stderr = std(block means, ddof=1) / sqrt(n_blocks)``.  The
    blocks must be longer than the correlation time for the error to be right; check with
    :func:`block_analysis`.
    """
    x = np.asarray(x, dtype=float).ravel()
    n_blocks = int(n_blocks)
    if n_blocks < 2:
        raise ValueError(f"n_blocks must be >= 2, got {n_blocks}")
    m = x.size // n_blocks
    if m < 1:
        raise ValueError(f"{x.size} samples cannot fill {n_blocks} blocks")
    means = x[x.size - m * n_blocks:].reshape(n_blocks, m).mean(axis=1)
    return float(means.mean()), float(means.std(ddof=1) / math.sqrt(n_blocks))


def block_analysis(x, min_blocks: int = 4) -> dict:
    """Standard error of the mean against block size: the Flyvbjerg-Petersen blocking transformation.

    The series is halved repeatedly (pairs of neighbours averaged); at each level with ``n`` blocks the
    error estimate is ``sqrt(var(ddof=0) / (n - 1))`` with its own uncertainty ``estimate / sqrt(2 (n -
    1))``.  The estimate grows with the block size and levels off once blocks are longer than the
    correlation time; ``stderr_plateau`` is a heuristic reading of that plateau (the first level whose
    estimate agrees within errors with every larger block size), ``nan`` when none does.

    Returns ``block_size``, ``n_blocks``, ``stderr``, ``stderr_error`` (arrays) and ``stderr_plateau``.
    """
    y = np.asarray(x, dtype=float).ravel()
    sizes, counts, errs, derrs = [], [], [], []
    size = 1
    while y.size >= max(2, min_blocks):
        n = y.size
        se = math.sqrt(y.var() / (n - 1))
        sizes.append(size), counts.append(n), errs.append(se), derrs.append(se / math.sqrt(2.0 * (n - 1)))
        if n % 2:
            y = y[1:]
        y = 0.5 * (y[0::2] + y[1::2])
        size *= 2
    errs_a, derrs_a = np.array(errs), np.array(derrs)
    plateau = float("nan")
    for i in range(len(errs_a) - 1):
        later = slice(i + 1, None)
        if np.all(np.abs(errs_a[later] - errs_a[i]) <= derrs_a[later] + derrs_a[i]):
            plateau = float(errs_a[i])
            break
    return {"block_size": np.array(sizes), "n_blocks": np.array(counts), "stderr": errs_a,
            "stderr_error": derrs_a, "stderr_plateau": plateau}


# ----------------------------------------------------------------------------- statistical inefficiency
#
# Chodera, "A simple method for automated equilibration detection in molecular simulations", J. Chem. Theory
# Comput. 12 (2016) 1799, the estimators of pymbar.timeseries (statisticalInefficiency, detectEquilibration),
# written here with an FFT autocovariance so that pymbar is not a dependency. Every MD quantity's stderr goes
# through timeseries_stats (or, for a derived quantity, through the stderrs it returns), not fixed block counts.

def _autocorrelation(x: np.ndarray) -> np.ndarray:
    """Normalised autocorrelation C(t) = <dx_i dx_{i+t}>_{i < N-t} / var, t = 0 .. N-1 (FFT, zero padded)."""
    n = x.size
    dx = x - x.mean()
    var = float(dx @ dx) / n
    size = 1 << int(2 * n - 1).bit_length()
    f = np.fft.rfft(dx, size)
    acov = np.fft.irfft(f * np.conj(f), size)[:n] / np.arange(n, 0, -1)
    return acov / var


def statistical_inefficiency(x, mintime: int = 3) -> float:
    """Statistical inefficiency g of a stationary series (Chodera 2016, eq. 7; pymbar.timeseries):

        g = 1 + 2 sum_{t=1}^{N-1} (1 - t/N) C(t),

    the sum truncated at the first t > ``mintime`` with C(t) <= 0 (beyond it C(t) is noise), g >= 1. The number
    of effectively uncorrelated samples is N/g and the integrated autocorrelation time (tau = (g - 1)/2) in
    sample intervals. A constant series (zero variance) has g = 1.
    """
    x = np.asarray(x, float).ravel()
    n = x.size
    if n < 2:
        return 1.0
    if not float(np.ptp(x)) > 0.0:
        return 1.0
    c = _autocorrelation(x)
    t = np.arange(1, n - 1)
    stop = np.flatnonzero((c[1:n - 1] <= 0.0) & (t > mintime))
    end = int(stop[0]) if stop.size else t.size
    g = 1.0 + 2.0 * float(np.sum((1.0 - t[:end] / n) * c[1:end + 1]))
    return max(1.0, g)


def detect_equilibration(x, nskip: int | None = None, min_samples: int = 10) -> dict:
    """Automated equilibration detection (Chodera 2016, pymbar.timeseries.detectEquilibration): the start t0
    that maximises the effective number of uncorrelated samples N_eff(t0) = (N - t0) / g(t0) of the production
    part x[t0:]. ``nskip``: candidate starts every nskip samples (default: about 100 candidates); at least
    ``min_samples`` are kept. Returns ``t0``, ``g`` (of x[t0:]) and ``n_eff``."""
    x = np.asarray(x, float).ravel()
    n = x.size
    if n < 2:
        return {"t0": 0, "g": 1.0, "n_eff": float(n)}
    step = max(1, n // 100) if nskip is None else max(1, int(nskip))
    best = (0, 1.0, -1.0)
    for t0 in range(0, max(1, n - max(2, min_samples) + 1), step):
        g = statistical_inefficiency(x[t0:])
        ne = (n - t0) / g
        if ne > best[2]:
            best = (t0, g, ne)
    return {"t0": int(best[0]), "g": float(best[1]), "n_eff": float(best[2])}


def timeseries_stats(x, *, equilibrate: bool = True, mintime: int = 3) -> dict:
    """Mean of a correlated series and its standard error from the statistical inefficiency (Chodera 2016).

    With ``equilibrate`` the start is chosen by :func:`detect_equilibration` (the samples before t0 are discarded
    as not yet equilibrated); then ``stderr = sqrt(var(x[t0:], ddof=1) g / (N - t0))``. Returns ``mean``,
    ``stderr``, ``g`` (statistical inefficiency), ``tau`` ((g - 1)/2, sample intervals), ``t0`` (first sample
    used), ``n`` (samples used), ``n_eff`` and ``std``. A series of one sample has an undefined (nan) stderr.
    """
    x = np.asarray(x, float).ravel()
    if x.size == 0:
        raise ValueError("empty series")
    t0 = detect_equilibration(x)["t0"] if equilibrate and x.size >= 4 else 0
    y = x[t0:]
    n = y.size
    g = statistical_inefficiency(y, mintime)
    if n < 2:
        return {"mean": float(y.mean()), "stderr": float("nan"), "g": 1.0, "tau": 0.0, "t0": t0, "n": n,
                "n_eff": float(n), "std": float("nan")}
    sd = float(y.std(ddof=1))
    return {"mean": float(y.mean()), "stderr": sd * math.sqrt(g / n), "g": g, "tau": 0.5 * (g - 1.0), "t0": t0,
            "n": n, "n_eff": n / g, "std": sd}


# ------------------------------------------------------------------------------------ works of adhesion

_ENERGY_NOTE = ("interaction energy per area, not a free energy (entropic contribution neglected)")


def energy_separation_work(e_contact_kcal, e_separated_kcal, area_A2: float, n_blocks: int | None = None) -> dict:
    """Work of separation from two equilibrium runs: W = (<E_sep> - <E_contact>) / A (J/m^2).

    ``e_contact_kcal`` and ``e_separated_kcal`` are time series of the potential energy (kcal/mol) of the
    same system in contact and pulled apart; ``area_A2`` is the contact area in A^2 (both interfaces'
    area if the cell has two). Each mean and its stderr come from :func:`timeseries_stats` (automated
    equilibration detection and the statistical inefficiency, Chodera 2016); the two are combined in quadrature.
    ``n_blocks`` (optional) adds the old fixed-block estimate as ``stderr_blocks`` for comparison only.
    This is an energy, not a free energy: the entropic part of the work of adhesion is neglected.
    """
    area = float(area_A2)
    if not area > 0:
        raise ValueError(f"area_A2 must be positive, got {area_A2}")
    c, s_ = timeseries_stats(e_contact_kcal), timeseries_stats(e_separated_kcal)
    mc, sc, ms, ss = c["mean"], c["stderr"], s_["mean"], s_["stderr"]
    f = KCALMOL_PER_A2_TO_J_PER_M2 / area
    out = {"value": (ms - mc) * f, "stderr": math.hypot(sc, ss) * f, "units": "J/m^2",
           "note": _ENERGY_NOTE, "e_contact_kcal": mc, "e_separated_kcal": ms,
           "e_contact_stderr_kcal": sc, "e_separated_stderr_kcal": ss, "area_A2": area,
           "contact_stats": {k: c[k] for k in ("g", "t0", "n", "n_eff")},
           "separated_stats": {k: s_[k] for k in ("g", "t0", "n", "n_eff")}}
    if n_blocks:
        out["stderr_blocks"] = math.hypot(block_average(e_contact_kcal, n_blocks)[1],
                                          block_average(e_separated_kcal, n_blocks)[1]) * f
    return out


def _zero_crossing(d: np.ndarray, f: np.ndarray) -> int | None:
    """Index j of the repulsive-to-attractive crossing that bounds the adhesive well: f[j] >= 0 > f[j+1], the
    last such crossing before the most attractive window; None if no window before the well is repulsive."""
    i_min = int(np.argmin(f))
    js = np.flatnonzero((f[:-1] >= 0.0) & (f[1:] < 0.0))
    js = js[js < i_min] if i_min > 0 else js[:0]
    return int(js[-1]) if js.size else None


def _trapezoid_from(d: np.ndarray, f: np.ndarray, j: int | None) -> tuple[float, float]:
    """(-integral of f from the zero crossing of segment j -- or from d[0] if j is None -- to d[-1], start)."""
    if j is None:
        return -float(np.sum(0.5 * np.diff(d) * (f[1:] + f[:-1]))), float(d[0])
    den = f[j] - f[j + 1]
    start = float(d[j] + (d[j + 1] - d[j]) * (f[j] / den if den != 0 else 0.0))
    area = 0.5 * (d[j + 1] - start) * f[j + 1]
    k = slice(j + 1, None)
    area += float(np.sum(0.5 * np.diff(d[k]) * (f[k][1:] + f[k][:-1])))
    return -area, start


def force_integration_work(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA,
                           area_A2: float, from_zero_crossing: bool = True) -> dict:
    """Free energy of separation by thermodynamic integration of the mean force over separation (J/m^2).

    W_F = -(1/A) integral <F_z> dd from the bottom of the adhesive well to the last window, with ``mean_force``
    the force on the upper body along +z (repulsion positive, attraction negative) at each held separation
    ``separation_A`` (A, any order). The bottom of the well is where the mean force changes sign from repulsive
    to attractive (linear interpolation between the two windows around it: the PMF's minimum, the equilibrium
    contact at zero load). The grid must therefore reach into compression: ``repulsive_end`` is False when no
    window before the most attractive one is repulsive -- then the integral starts at the first window and
    misses part of the well (a lower bound); ``from_zero_crossing=False`` always integrates the whole grid.

    ``value`` uses the trapezoid rule and ``stderr`` propagates the windows' statistical errors through it
    (linearised: the start point moves with the forces, at zero force). ``value_pchip`` integrates the
    shape-preserving cubic (PCHIP, Fritsch & Carlson, SIAM J. Numer. Anal. 17 (1980) 238) over the same range;
    ``discretisation_error`` = |trapezoid - PCHIP| estimates what the window grid misses (two quadratures of
    different order agree when the grid resolves the force curve). ``pmf_J_per_m2``: the PMF at each window
    relative to the well's bottom; ``cumulative_J_per_m2``: -integral from the first window.
    """
    from scipy.interpolate import PchipInterpolator

    d = np.asarray(separation_A, float).ravel()
    f = np.asarray(mean_force_kcal_per_molA, float).ravel()
    e = np.asarray(force_stderr_kcal_per_molA, float).ravel()
    if not (d.shape == f.shape == e.shape) or d.size < 2:
        raise ValueError("separation, mean force and stderr must be 1-D arrays of equal length >= 2")
    area = float(area_A2)
    if not area > 0:
        raise ValueError(f"area_A2 must be positive, got {area_A2}")
    order = np.argsort(d)
    d, f, e = d[order], f[order], e[order]
    if np.any(np.diff(d) <= 0):
        raise ValueError("two windows at the same separation")
    j = _zero_crossing(d, f) if from_zero_crossing else None
    conv = KCALMOL_PER_A2_TO_J_PER_M2 / area
    w_kcal, start = _trapezoid_from(d, f, j)
    # linear error propagation: dW/df_k by central differences (exact for the piecewise-linear rule)
    grad = np.zeros_like(f)
    for k in range(f.size):
        h = 1e-6 * max(abs(f[k]), float(np.max(np.abs(f))), 1e-12)
        fp, fm = f.copy(), f.copy()
        fp[k] += h
        fm[k] -= h
        grad[k] = (_trapezoid_from(d, fp, j)[0] - _trapezoid_from(d, fm, j)[0]) / (2 * h)
    err = float(np.sqrt(np.sum((grad * e) ** 2))) * conv
    trap = w_kcal * conv
    pchip = -float(PchipInterpolator(d, f).integrate(start, d[-1])) * conv if d.size >= 3 else trap
    cumulative = -np.concatenate([[0.0], np.cumsum(0.5 * np.diff(d) * (f[1:] + f[:-1]))]) * conv
    # PMF relative to the well's bottom: cumulative minus its (interpolated) value at the start
    # (the trapezoid value at the crossing, where f = 0; the first window without a crossing)
    c_start = float(cumulative[j]) - 0.5 * (start - d[j]) * f[j] * conv if j is not None else 0.0
    return {"value": trap, "stderr": err, "value_pchip": pchip, "discretisation_error": abs(trap - pchip),
            "units": "J/m^2", "separation_A": d, "cumulative_J_per_m2": cumulative,
            "pmf_J_per_m2": cumulative - c_start, "repulsive_end": j is not None,
            "zero_force_separation_A": start if j is not None else float("nan"), "start_A": start}


# ------------------------------------------------------------------------ flat-slab force curves: z0, sigma0

#: Maugis (1992) for the LJ 9-3 traction law: sigma0 = (16 / (9 sqrt 3)) w / z0 = 1.0264 w / z0
MAUGIS_LJ93 = 16.0 / (9.0 * math.sqrt(3.0))


def registry_average(values, stderrs) -> dict:
    """Average over lateral registries of quantities measured at the same points.

    ``values``, ``stderrs``: shape (n_registries,) for one quantity or (n_registries, n_points) for a curve.
    The registries sample the lateral offset of two crystalline faces; an incommensurate contact averages over
    all of them, so the mean over registries is the estimate and their spread is part of its error:
    ``stderr = max(std over registries / sqrt(n), sqrt(sum stderr^2) / n)`` -- the first is the random-effects
    error (it carries the registries' own statistical noise too), the second guards it when two or three
    registries agree by chance. One registry: its own stderr.
    Returns ``mean``, ``stderr``, ``stderr_statistical``, ``registry_spread`` (std, ddof 1) and ``n``.
    """
    scalar = np.ndim(values) == 1
    v = np.asarray(values, float).reshape(len(values), -1)
    e = np.asarray(stderrs, float).reshape(v.shape)
    n = v.shape[0]
    mean = v.mean(axis=0)
    stat = np.sqrt(np.sum(e ** 2, axis=0)) / n
    spread = v.std(axis=0, ddof=1) if n >= 2 else np.zeros_like(mean)
    err = np.maximum(spread / math.sqrt(n), stat)
    pick = (lambda a: float(a[0])) if scalar else (lambda a: a)
    return {"mean": pick(mean), "stderr": pick(err), "stderr_statistical": pick(stat),
            "registry_spread": pick(spread), "n": int(n)}


def traction_peak(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA, area_A2: float) -> dict:
    """Peak tensile traction sigma0 (Pa) of a flat-slab mean-force curve, with its standard error.

    A quadratic through the three windows around the most attractive one gives the peak (its vertex); its stderr
    follows from the windows' stderrs by the delta method (the fit is exact, so the covariance is the noise's
    alone). ``discretisation_error`` = |3-point - 5-point (weighted least squares) vertex| estimates what the grid
    misses, as the trapezoid-PCHIP difference does for W. If the parabola opens downwards or its vertex lies outside
    the windows used, the most attractive window itself is taken (``method = 'window'``: on a coarse grid that
    underestimates the peak). Returns ``sigma0`` (Pa, > 0 for tension), ``stderr``, ``discretisation_error``,
    ``separation_A`` (of the peak) and ``method``.
    """
    d = np.asarray(separation_A, float).ravel()
    f = np.asarray(mean_force_kcal_per_molA, float).ravel()
    e = np.asarray(force_stderr_kcal_per_molA, float).ravel()
    order = np.argsort(d)
    d, f, e = d[order], f[order], e[order]
    area = float(area_A2)
    i = int(np.argmin(f))
    if not f[i] < 0:
        raise ValueError("no attractive window: the curve has no tensile peak")
    to_pa = lambda x: float(_units.kcal_per_mol_A3_to_Pa(x / area))

    def vertex(m):
        if d.size < m:
            return None
        lo = min(max(0, i - m // 2), d.size - m)
        sel = slice(lo, lo + m)
        x, y = d[sel] - d[i], f[sel]
        s = np.where(e[sel] > 0, e[sel], 1.0)
        a = np.column_stack([np.ones_like(x), x, x * x]) / s[:, None]
        coef, *_ = np.linalg.lstsq(a, y / s, rcond=None)
        c0, c1, c2 = coef
        if not c2 > 0 or not (x.min() <= -c1 / (2 * c2) <= x.max()):
            return None
        cov = np.linalg.inv(a.T @ a)
        g = np.array([1.0, -c1 / (2 * c2), c1 * c1 / (4 * c2 * c2)])
        return c0 - c1 * c1 / (4 * c2), math.sqrt(max(float(g @ cov @ g), 0.0)), float(d[i] - c1 / (2 * c2))

    v3, v5 = vertex(3), vertex(5)
    if v3 is None:
        return {"sigma0": to_pa(-f[i]), "stderr": to_pa(e[i]), "discretisation_error": float("nan"),
                "separation_A": float(d[i]), "method": "window"}
    disc = to_pa(abs(v3[0] - v5[0])) if v5 is not None else float("nan")
    return {"sigma0": to_pa(-v3[0]), "stderr": to_pa(v3[1]), "discretisation_error": disc,
            "separation_A": v3[2], "method": "quadratic"}


def flat_slab_range(work_J_per_m2: float, work_stderr: float, sigma0_Pa: float, sigma0_stderr: float) -> dict:
    """Interaction range z0 (m) that makes the LJ 9-3 law carry the measured work W and peak traction sigma0
    (Maugis, J. Colloid Interface Sci. 150 (1992) 243): z0 = (16 / (9 sqrt 3)) W / sigma0 = 1.0264 W / sigma0, and
    the Dugdale range h0 = W / sigma0. The stderr combines the two relative errors in quadrature (their
    correlation -- both come from the same windows -- is neglected, which overstates the error)."""
    w, s = float(work_J_per_m2), float(sigma0_Pa)
    if not (w > 0 and s > 0):
        raise ValueError(f"need W > 0 and sigma0 > 0, got W = {w:g} J/m^2, sigma0 = {s:g} Pa")
    z0 = MAUGIS_LJ93 * w / s
    rel = math.hypot((work_stderr or 0.0) / w, (sigma0_stderr or 0.0) / s)
    return {"z0": z0, "stderr": z0 * rel, "h0": w / s, "h0_stderr": w / s * rel}


# ------------------------------------------------------------------------ dispersion beyond the cutoff

def lj_tail_between(pos_a, types_a, pos_b, types_b, epsilon, sigma, include, cell_xy, r_cut_A: float,
                    r_max_A: float = 30.0, smeared_beyond: bool = True) -> dict:
    """Lennard-Jones interaction beyond the cutoff between two groups of atoms, A below and B above (kcal/mol).

    The dynamics truncate LJ at ``r_cut_A`` (``lj/cut``: not shifted); what a full sum adds is
    U_tail = sum over pairs with r > r_cut of 4 eps [(s/r)^12 - (s/r)^6]. Pairs with r_cut < r <= ``r_max_A`` are
    summed explicitly, over every periodic image in x and y (``cell_xy``; z is not periodic); beyond r_max the
    images are smeared into a uniform layer per pair (density 1 / cell area), which gives the closed form
    -pi C6 / (2 A max(r_max, |dz|)^4) per pair with C6 = 4 eps s^6 (and its z-derivative for the force).
    ``types_*`` are integer indices into the (T, T) arrays ``epsilon``, ``sigma`` (kcal/mol, A) and the boolean
    ``include`` (the pairs to count). Positions in A, any wrapping in x, y.

    Returns ``energy`` (kcal/mol), ``force_z`` (on B along +z, kcal/mol/A; negative = attraction), the explicit
    and smeared parts of both, and ``pairs`` (explicit pair count).
    """
    from scipy.spatial import cKDTree

    pa, pb = np.asarray(pos_a, float).reshape(-1, 3), np.asarray(pos_b, float).reshape(-1, 3)
    ta, tb = np.asarray(types_a, int).ravel(), np.asarray(types_b, int).ravel()
    eps, sig, inc = np.asarray(epsilon, float), np.asarray(sigma, float), np.asarray(include, bool)
    lx, ly = float(cell_xy[0]), float(cell_xy[1])
    rc, rm = float(r_cut_A), float(r_max_A)
    if not rm > rc:
        raise ValueError(f"r_max_A ({rm}) must exceed r_cut_A ({rc})")
    # only atoms that have an included partner type on the other side
    ka = np.isin(ta, np.flatnonzero(inc[:, np.unique(tb)].any(axis=1))) if tb.size else np.zeros(ta.size, bool)
    kb = np.isin(tb, np.flatnonzero(inc[np.unique(ta), :].any(axis=0))) if ta.size else np.zeros(tb.size, bool)
    pa, ta, pb, tb = pa[ka], ta[ka], pb[kb], tb[kb]
    out = {"energy": 0.0, "force_z": 0.0, "energy_explicit": 0.0, "force_z_explicit": 0.0,
           "energy_smeared": 0.0, "force_z_smeared": 0.0, "pairs": 0}
    if not (pa.size and pb.size):
        return out
    pa = pa.copy()
    pb = pb.copy()
    pa[:, 0] %= lx
    pa[:, 1] %= ly
    pb[:, 0] %= lx
    pb[:, 1] %= ly
    nx, ny = int(math.ceil(rm / lx)) + 1, int(math.ceil(rm / ly)) + 1
    shifts = np.array([(i * lx, j * ly, 0.0) for i in range(-nx, nx + 1) for j in range(-ny, ny + 1)])
    # every image of B within r_max of the primary cell (laterally), in one tree
    img = (pb[None, :, :] + shifts[:, None, :]).reshape(-1, 3)
    src = np.tile(np.arange(pb.shape[0]), len(shifts))
    near = (img[:, 0] > -rm) & (img[:, 0] < lx + rm) & (img[:, 1] > -rm) & (img[:, 1] < ly + rm)
    img, src = img[near], src[near]
    res = cKDTree(pa).sparse_distance_matrix(cKDTree(img), rm, output_type="ndarray")
    i, j, r = res["i"], src[res["j"]], res["v"]
    keep = (r > rc) & inc[ta[i], tb[j]]
    i, jj, j, r = i[keep], res["j"][keep], j[keep], r[keep]
    e_ij, s_ij = eps[ta[i], tb[j]], sig[ta[i], tb[j]]
    sr6 = (s_ij / r) ** 6
    e_exp = float(np.sum(4.0 * e_ij * (sr6 * sr6 - sr6)))
    # force on b along z: -dU/dr * (z_b - z_a) / r
    dudr = 4.0 * e_ij * (-12.0 * sr6 * sr6 + 6.0 * sr6) / r
    f_exp = float(np.sum(-dudr * (img[jj, 2] - pa[i, 2]) / r))
    n_pairs = int(r.size)
    e_sm = f_sm = 0.0
    if smeared_beyond:
        area = lx * ly
        c6 = 4.0 * eps * sig ** 6 * inc
        for k in range(0, pa.shape[0], 2048):
            dz = pb[None, :, 2] - pa[k:k + 2048, None, 2]
            c = c6[ta[k:k + 2048, None], tb[None, :]]
            h = np.maximum(np.abs(dz), rm)
            e_sm += float(np.sum(-math.pi * c / (2.0 * area * h ** 4)))
            # d/d(dz) of -pi C6 / (2 A dz^4) for |dz| > r_max; force on b = -dU/d(dz)
            far = np.abs(dz) > rm
            f_sm += float(np.sum(np.where(far, -2.0 * math.pi * c * np.sign(dz) / (area * h ** 5), 0.0)))
    out.update(energy=e_exp + e_sm, force_z=f_exp + f_sm, energy_explicit=e_exp, force_z_explicit=f_exp,
               energy_smeared=e_sm, force_z_smeared=f_sm, pairs=n_pairs)
    return out


def _refined_min(x, y, i):
    """Minimum near sample i, refined on a cubic spline through the 7 nearest samples (O(h^4)).

    Falls back to the sample itself at the ends of the data or when the spline has no minimum between
    the neighbours of i.
    """
    if i <= 0 or i >= len(x) - 1:
        return float(x[i]), float(y[i])
    from scipy.interpolate import CubicSpline
    from scipy.optimize import minimize_scalar

    lo, hi = max(0, i - 3), min(len(x), i + 4)
    xs, ys = np.asarray(x[lo:hi], float), np.asarray(y[lo:hi], float)
    if np.any(np.diff(xs) <= 0):
        return float(x[i]), float(y[i])
    spl = CubicSpline(xs, ys)
    sol = minimize_scalar(lambda t: float(spl(t)), bounds=(float(x[i - 1]), float(x[i + 1])),
                          method="bounded", options={"xatol": 1e-10 * float(x[i + 1] - x[i - 1])})
    if not sol.success or sol.fun > y[i]:
        return float(x[i]), float(y[i])
    return float(sol.x), float(sol.fun)


def work_from_energy_curve(separation_A, energy_kcal, area_A2: float, *, tail_power: float | None = None,
                           tail_fraction: float = 0.2, energy_stderr_kcal=None) -> dict:
    """Work of separation from an energy-separation curve E(D): W = (E_plateau - E_min) / A (J/m^2).

    ``E_min`` is the curve's minimum, refined on a local cubic spline.  The plateau is the
    energy at large separation: with ``tail_power=None`` the mean of the last ``tail_fraction`` of the
    points (by separation); with ``tail_power=p`` the tail points are fitted to ``E_inf + C D^-p`` and
    ``E_inf`` is used (p = 3 for a sphere/atom against a half-space, 2 for two half-spaces).
    ``energy_stderr_kcal`` (per point) gives a propagated ``stderr``; without it ``stderr`` is nan.
    """
    d = np.asarray(separation_A, dtype=float).ravel()
    e = np.asarray(energy_kcal, dtype=float).ravel()
    if d.shape != e.shape or d.size < 3:
        raise ValueError("separation_A and energy_kcal must be 1-D arrays of the same length >= 3")
    order = np.argsort(d)
    d, e = d[order], e[order]
    se = None if energy_stderr_kcal is None else np.asarray(energy_stderr_kcal, float).ravel()[order]
    area = float(area_A2)
    n_tail = max(1, int(round(tail_fraction * d.size)))
    tail = slice(d.size - n_tail, None)
    if tail_power is None:
        plateau = float(e[tail].mean())
        var_plateau = float(np.sum(se[tail] ** 2)) / n_tail**2 if se is not None else float("nan")
        method = f"plateau = mean of the last {n_tail} points"
    else:
        if n_tail < 3:
            n_tail = min(3, d.size)
            tail = slice(d.size - n_tail, None)
        a = np.column_stack([np.ones(n_tail), d[tail] ** (-float(tail_power))])
        w = np.ones(n_tail) if se is None else 1.0 / se[tail]
        coef, *_ = np.linalg.lstsq(a * w[:, None], e[tail] * w, rcond=None)
        plateau = float(coef[0])
        if se is not None:
            cov = np.linalg.inv((a * w[:, None]).T @ (a * w[:, None]))
            var_plateau = float(cov[0, 0])
        else:
            var_plateau = float("nan")
        method = f"plateau = E_inf of E_inf + C D^-{tail_power} fitted to the last {n_tail} points"
    i = int(np.argmin(e))
    d_min, e_min = _refined_min(d, e, i)
    var_min = float(se[i] ** 2) if se is not None else float("nan")
    f = KCALMOL_PER_A2_TO_J_PER_M2 / area
    return {"value": (plateau - e_min) * f, "stderr": math.sqrt(var_min + var_plateau) * f,
            "units": "J/m^2", "note": _ENERGY_NOTE, "method": method,
            "separation_at_min": float(_units.angstrom_to_m(d_min)), "energy_min_kcal": e_min,
            "plateau_kcal": plateau}


# -------------------------------------------------------------------------------------- contact angle

def fit_circle(x, z) -> tuple[float, float, float]:
    """Circle (xc, zc, r) through points: Kasa's algebraic fit refined by geometric least squares.

    The algebraic fit minimises sum (x^2 + z^2 + D x + E z + F)^2 (linear, biased towards small circles
    for short arcs); it starts :func:`scipy.optimize.least_squares` on the geometric residuals
    ``hypot(x - xc, z - zc) - r``.
    """
    from scipy.optimize import least_squares

    x = np.asarray(x, float).ravel()
    z = np.asarray(z, float).ravel()
    if x.size < 3:
        raise ValueError("a circle needs at least 3 points")
    a = np.column_stack([x, z, np.ones_like(x)])
    (dd, ee, ff), *_ = np.linalg.lstsq(a, -(x * x + z * z), rcond=None)
    xc, zc = -dd / 2.0, -ee / 2.0
    r = math.sqrt(max(xc * xc + zc * zc - ff, 1e-300))

    def res(p):
        return np.hypot(x - p[0], z - p[1]) - p[2]

    def jac(p):
        dist = np.maximum(np.hypot(x - p[0], z - p[1]), 1e-300)
        return np.column_stack([-(x - p[0]) / dist, -(z - p[1]) / dist, -np.ones_like(x)])

    sol = least_squares(res, [xc, zc, r], jac=jac, method="lm", xtol=1e-12, ftol=1e-12)
    xc, zc, r = (float(v) for v in sol.x)
    return xc, zc, abs(r)


def _bulk_density(rho, z_centres, z_cut, bin_A, core_margin_A=2.0):
    """Bulk density of the droplet core: mean over the region above half the bulk, eroded by a margin."""
    from scipy import ndimage

    sub = rho[:, z_centres > z_cut]
    if sub.size == 0 or not np.any(sub > 0):
        raise ValueError("no density above surface_z + exclude_layer: is surface_z right?")
    est = float(ndimage.gaussian_filter(sub, 1.0, mode="nearest").max())
    n_erode = max(1, int(round(core_margin_A / bin_A)))
    for _ in range(4):
        mask = sub > 0.5 * est
        core = ndimage.binary_erosion(mask, iterations=n_erode)
        if core.sum() < 4:
            core = mask
        est = float(sub[core].mean())
    return est


REFERENCES = ("dividing_surface", "surface_z")


def dividing_plane(density_map, u_edges, z_edges, bulk_density: float, u_centre: float = 0.0,
                   half_width: float | None = None) -> dict:
    """The water's own reference plane: the height at which its density, averaged over the columns under the
    droplet (|u - ``u_centre``| <= ``half_width``; all columns when None), first rises to half the bulk value
    (scanning up from the bottom of the map; linear interpolation between bin centres).

    Next to a solid the liquid starts after a depleted gap (about 2 A above the CH3 groups of a SAM), so this
    plane -- the solid-liquid analogue of the half-density liquid-vapour surface the circle is fitted to -- lies
    above the solid's atoms. If the lowest bin is already above half the bulk, the plane is the map's lower
    edge (``at_map_edge``: start the map lower). Returns ``z`` (A), ``profile_z``, ``profile`` (the averaged
    density) and ``n_columns``.
    """
    rho = np.asarray(density_map, float)
    ue, ze = np.asarray(u_edges, float), np.asarray(z_edges, float)
    uc, zc = 0.5 * (ue[1:] + ue[:-1]), 0.5 * (ze[1:] + ze[:-1])
    du = float(np.diff(ue).mean())
    if half_width is None or not np.isfinite(half_width):
        sel = np.ones(len(uc), bool)
    else:
        lu = ue[-1] - ue[0]
        d = (uc - u_centre + lu / 2) % lu - lu / 2
        sel = np.abs(d) <= max(float(half_width), du)
    prof = rho[sel].mean(axis=0)
    half = 0.5 * float(bulk_density)
    above = np.flatnonzero(prof >= half)
    if not len(above):
        raise ValueError("the water density under the droplet never reaches half the bulk value")
    k = int(above[0])
    if k == 0:
        z = float(ze[0])
    else:
        z = float(zc[k - 1] + (half - prof[k - 1]) * (zc[k] - zc[k - 1]) / (prof[k] - prof[k - 1]))
    return {"z": z, "profile_z": zc, "profile": prof, "n_columns": int(sel.sum()), "at_map_edge": k == 0}


def fit_contact_angle(density_map, u_edges, z_edges, surface_z: float, exclude_layer: float = 5.0,
                      bulk_density: float | None = None, reference: str = "dividing_surface",
                      max_iter: int = 8) -> dict:
    """Contact angle of a cylindrical droplet from its density map rho(u, z) (any density unit).

    The liquid-vapour interface is the contour rho = bulk/2 (``bulk_density`` from the droplet core when not
    given), computed by :mod:`contourpy` (linear interpolation between bin centres).  Contour pieces shorter
    than a fifth of the longest (noise islands) are dropped; points below the reference plane +
    ``exclude_layer`` are excluded from the fit (the wall-layered region).  A circle is fitted
    (:func:`fit_circle`) and cut with the reference plane z_ref: ``theta = 90 deg + asin((zc - z_ref) / r)``
    (through the liquid), < 90 deg when the centre lies below the plane and > 90 deg when above.

    ``reference``: ``"dividing_surface"`` (default) -- z_ref is the water's own plane, where its density under
    the droplet reaches half the bulk (:func:`dividing_plane`, searched from ``surface_z`` up; the fit, the
    plane and the bulk density are iterated to consistency); ``"surface_z"`` -- z_ref = ``surface_z`` (a plane
    of solid atoms: biased, the liquid starts a depleted gap above the atoms; kept for comparison).
    ``surface_z`` is always the lower limit of the search and of the excluded layer's first guess.

    Returns ``angle_deg`` (nan when the circle misses the plane), ``circle`` (xc, zc, r), ``reference_z``,
    ``reference``, ``surface_z``, ``interface_points`` (used in the fit), ``all_interface_points``,
    ``bulk_density``, ``fit_rms_A``, ``base_half_width_A``, ``cap_height_A`` (top of the circle above the
    plane), ``area_A2`` (liquid cross-section above the plane, from the map) and ``dividing`` (the profile).
    """
    import contourpy

    if reference not in REFERENCES:
        raise ValueError(f"reference must be one of {REFERENCES}, got {reference!r}")
    rho = np.asarray(density_map, float)
    ue, ze = np.asarray(u_edges, float), np.asarray(z_edges, float)
    uc, zc_ = 0.5 * (ue[1:] + ue[:-1]), 0.5 * (ze[1:] + ze[:-1])
    bin_A = float(min(np.diff(ue).mean(), np.diff(ze).mean()))
    gen = contourpy.contour_generator(x=uc, y=zc_, z=rho.T, line_type="Separate")
    z_ref = float(surface_z)
    div = None
    for _ in range(max(1, int(max_iter))):
        z_cut = z_ref + float(exclude_layer)
        bulk = _bulk_density(rho, zc_, z_cut, bin_A) if bulk_density is None else float(bulk_density)
        lines = [ln for ln in gen.lines(0.5 * bulk) if len(ln) >= 2]
        if not lines:
            raise ValueError("no half-bulk density contour found")
        lengths = np.array([np.hypot(*np.diff(ln, axis=0).T).sum() for ln in lines])
        keep = [ln for ln, ll in zip(lines, lengths) if ll >= 0.2 * lengths.max()]
        pts_all = np.concatenate(keep, axis=0)
        pts = pts_all[pts_all[:, 1] > z_cut]
        if len(pts) < 5 or np.ptp(pts[:, 1]) < 2 * bin_A:
            raise ValueError(f"only {len(pts)} interface points spanning {np.ptp(pts[:, 1]) if len(pts) else 0:.2f} A "
                             f"in height above the reference plane + exclude_layer (z > {z_cut:.2f} A): the cap is "
                             f"too flat to fit (a film?)")
        xc, zc, r = fit_circle(pts[:, 0], pts[:, 1])
        if reference == "surface_z":
            break
        dz = zc - z_ref
        half_w = math.sqrt(r * r - dz * dz) if abs(dz) < r else 0.5 * float(np.ptp(pts_all[:, 0]))
        div = dividing_plane(rho, ue, ze, bulk, xc, 0.5 * half_w)
        new = max(div["z"], float(surface_z))
        if abs(new - z_ref) < 1e-3:
            break
        z_ref = new
    s = (zc - z_ref) / r
    if abs(s) > 1.0:
        warnings.warn("fitted circle does not reach the reference plane; contact angle undefined", RuntimeWarning,
                      stacklevel=2)
        angle = float("nan")
    else:
        angle = 90.0 + math.degrees(math.asin(s))
    rms = float(np.sqrt(np.mean((np.hypot(pts[:, 0] - xc, pts[:, 1] - zc) - r) ** 2)))
    du, dzb = float(np.diff(ue).mean()), float(np.diff(ze).mean())
    area = float(rho[:, zc_ >= z_ref].sum() * du * dzb / bulk)
    return {"angle_deg": angle, "circle": (xc, zc, r), "interface_points": pts, "reference_z": z_ref,
            "reference": reference, "surface_z": float(surface_z),
            "all_interface_points": pts_all, "bulk_density": bulk, "fit_rms_A": rms,
            "base_half_width_A": math.sqrt(max(r * r - (zc - z_ref) ** 2, 0.0)),
            "cap_height_A": zc + r - z_ref, "area_A2": area, "dividing": div}


def _segment_area(theta: float) -> float:
    """Area of a circular cap of unit radius with contact angle ``theta`` (rad) on its chord."""
    return theta - math.sin(theta) * math.cos(theta)


def cap_angle_for_base(area_A2: float, base_width_A: float) -> float:
    """Contact angle (deg) of the cylindrical cap of cross-section ``area_A2`` whose base is ``base_width_A``
    wide: (theta - sin theta cos theta) / sin^2 theta = 4 A / w^2 (the left side grows monotonically from 0 at
    theta = 0 to pi/2 at 90 deg). A cap of that area in a periodic box of width w touches its image there, so
    a film spanning the box has an equilibrium angle below it. nan when 4 A / w^2 >= pi/2."""
    from scipy.optimize import brentq

    target = 4.0 * float(area_A2) / float(base_width_A) ** 2
    if target >= math.pi / 2:
        return float("nan")
    f = lambda t: _segment_area(t) / math.sin(t) ** 2 - target
    return math.degrees(brentq(f, 1e-6, math.pi / 2))


def cap_angle_for_height(area_A2: float, height_A: float) -> float:
    """Contact angle (deg) of the cylindrical cap of cross-section ``area_A2`` and height ``height_A``:
    R = sqrt(A / (theta - sin theta cos theta)), h = R (1 - cos theta), increasing in theta."""
    from scipy.optimize import brentq

    def h(t):
        return math.sqrt(area_A2 / _segment_area(t)) * (1.0 - math.cos(t))

    if height_A >= h(math.pi):
        return 180.0
    return math.degrees(brentq(lambda t: h(t) - height_A, 1e-4, math.pi))


def wetting_bound(density_map, u_edges, z_edges, bulk_density: float, reference_z: float,
                  exclude_layer: float = 5.0, min_arc_bins: int = 2, band_A: float = 3.0) -> dict:
    """Is the droplet too flat to give an angle? Then the measurable statement is an upper bound ("wets").

    * ``spans_box``: every column of the map holds liquid (mean density over ``band_A`` above the reference
      plane > half the bulk): the water is a film across the periodic box, and its equilibrium angle is below
      ``theta_max_deg`` = :func:`cap_angle_for_base` (area, box width) -- a cap of this volume touches its
      periodic image at that angle.
    * ``theta_resolvable_deg``: the angle of a cap of this volume whose top is only ``exclude_layer`` +
      ``min_arc_bins`` bins above the plane; below it no circle can be fitted above the excluded layer, so a
      failed fit on an unspanned map means theta < theta_resolvable.

    ``area_A2`` is the liquid cross-section above the plane (map integral / bulk).
    """
    rho = np.asarray(density_map, float)
    ue, ze = np.asarray(u_edges, float), np.asarray(z_edges, float)
    zc = 0.5 * (ze[1:] + ze[:-1])
    du, dz = float(np.diff(ue).mean()), float(np.diff(ze).mean())
    width = float(ue[-1] - ue[0])
    area = float(rho[:, zc >= reference_z].sum() * du * dz / bulk_density)
    band = (zc >= reference_z) & (zc < reference_z + max(band_A, dz))
    if not band.any():
        band = zc >= reference_z
    col = rho[:, band].mean(axis=1)
    spans = bool(col.min() > 0.5 * bulk_density)
    h_min = float(exclude_layer) + min_arc_bins * dz
    return {"spans_box": spans, "area_A2": area, "box_width_A": width,
            "film_thickness_A": area / width, "theta_max_deg": cap_angle_for_base(area, width),
            "theta_resolvable_deg": cap_angle_for_height(area, h_min) if area > 0 else float("nan"),
            "min_column_density": float(col.min()), "min_cap_height_A": h_min}


def block_drift(values, times=None) -> dict:
    """Linear trend of a block series (drift check): ordinary least squares of ``values`` against ``times``
    (default 0, 1, 2, ...) with the slope's standard error from the residual scatter (n - 2 degrees of
    freedom). ``drifting`` when |slope| > 2 stderr: the series has not levelled off, so its mean depends on
    where the run stopped. ``change`` is slope x the time span covered. Non-finite values are left out;
    fewer than 3 points give nan."""
    from scipy import stats

    y = np.asarray(values, float)
    t = np.arange(len(y), dtype=float) if times is None else np.asarray(times, float)
    ok = np.isfinite(y) & np.isfinite(t)
    y, t = y[ok], t[ok]
    nan = float("nan")
    if len(y) < 3 or np.ptp(t) == 0:
        return {"slope": nan, "stderr": nan, "t": nan, "p": nan, "change": nan, "drifting": False, "n": int(len(y))}
    tm = t - t.mean()
    sxx = float((tm * tm).sum())
    slope = float((tm * (y - y.mean())).sum() / sxx)
    resid = y - y.mean() - slope * tm
    dof = len(y) - 2
    se = math.sqrt(float((resid * resid).sum()) / dof / sxx)
    tval = slope / se if se > 0 else (math.inf if slope else 0.0)
    p = float(2 * stats.t.sf(abs(tval), dof)) if np.isfinite(tval) else 0.0
    return {"slope": slope, "stderr": se, "t": float(tval), "p": p, "change": slope * float(np.ptp(t)),
            "drifting": bool(abs(slope) > 2 * se), "n": int(len(y))}


def work_of_adhesion_sl(gamma_lv, theta_deg, gamma_stderr=None, theta_stderr_deg=None) -> dict:
    """Young-Dupre work of adhesion of the liquid on the solid, W_SL = gamma_lv (1 + cos theta), and
    gamma_lv cos theta (what the meniscus force of the continuum model uses), with stderrs propagated to
    first order from those of gamma_lv (same units as gamma) and theta (deg). Missing errors count as zero."""
    th = math.radians(float(theta_deg))
    g = float(gamma_lv)
    sg = 0.0 if gamma_stderr is None or not np.isfinite(gamma_stderr) else float(gamma_stderr)
    st = 0.0 if theta_stderr_deg is None or not np.isfinite(theta_stderr_deg) else math.radians(float(theta_stderr_deg))
    w = g * (1.0 + math.cos(th))
    w_err = math.hypot((1.0 + math.cos(th)) * sg, g * math.sin(th) * st)
    gc = g * math.cos(th)
    gc_err = math.hypot(math.cos(th) * sg, g * math.sin(th) * st)
    return {"value": w, "stderr": w_err, "gamma_cos_theta": gc, "gamma_cos_theta_stderr": gc_err}


try:  # ContactAngle needs MDAnalysis; the functions above do not
    from MDAnalysis.analysis.base import AnalysisBase as _AnalysisBase
except ImportError:  # pragma: no cover - exercised only without the md extra
    _AnalysisBase = None


if _AnalysisBase is not None:
    class ContactAngle(_AnalysisBase):
        """Contact angle of a quasi-2-D (cylindrical) water droplet periodic along ``axis``.

        Parameters
        ----------
        atomgroup : AtomGroup
            Water oxygens (one per molecule; the map counts them as water molecules, 18.015 g/mol).
        surface_z : float
            Height (A) of the solid surface (a plane of its outermost atoms): the lower limit of the search for
            the reference plane, and the reference plane itself with ``reference="surface_z"``.
        axis : "x" or "y"
            The periodic axis of the cylinder; the map is in the other in-plane axis (u) and z.
        bin_size : float
            Bin edge (A) in u and z.
        exclude_layer : float
            Interface points below the reference plane + ``exclude_layer`` (A) are left out of the circle fit.
        n_blocks : int
            Contiguous blocks of frames whose maps are fitted separately for the error and the drift check.
        z_max : float, optional
            Top of the map (A); default the box height of the first frame.
        z_min : float, optional
            Bottom of the map (A); default ``surface_z``. Start it below the solid's outer atoms when water can
            sit between them (silanols), so the dividing plane is found from below.
        reference : "dividing_surface" or "surface_z"
            Where the angle is read (:func:`fit_contact_angle`); default the water's own half-density plane.

        Each frame the droplet is centred in u on the circular mean of its atoms (then corrected by the
        arithmetic mean of the unwrapped coordinates), so a droplet straddling the periodic boundary or
        drifting is handled.  ``results``: ``angle_deg`` (from the full map; nan when no circle can be fitted
        -- see ``wetting``), ``stderr_deg`` (std of the block angles / sqrt(n_blocks)), ``block_angles_deg``,
        ``block_frames`` (mean frame index of each block), ``drift`` (:func:`block_drift` of the block angles
        against ``block_frames``), ``circle`` (xc, zc, r in A, xc in the centred frame), ``reference_z``,
        ``density_map`` (g/cm^3, shape (n_u, n_z)), ``edges`` (u_edges, z_edges in A), ``interface_points``
        (those used in the fit), ``bulk_density`` (g/cm^3), ``fit_rms_A``, ``cap_height_A``, ``wetting``
        (:func:`wetting_bound`), ``fit_error`` (why the full-map fit failed, or None).
        """

        def __init__(self, atomgroup, surface_z: float, axis: str = "y", bin_size: float = 0.5,
                     exclude_layer: float = 5.0, n_blocks: int = 5, z_max: float | None = None,
                     z_min: float | None = None, reference: str = "dividing_surface", **kwargs):
            super().__init__(atomgroup.universe.trajectory, **kwargs)
            if axis not in ("x", "y"):
                raise ValueError(f"axis must be 'x' or 'y' (the droplet's periodic axis), got {axis!r}")
            if reference not in REFERENCES:
                raise ValueError(f"reference must be one of {REFERENCES}, got {reference!r}")
            self._ag = atomgroup
            self.surface_z = float(surface_z)
            self.axis = axis
            self._iaxis = "xyz".index(axis)
            self._iu = 1 - self._iaxis if self._iaxis in (0, 1) else 0
            self.bin_size = float(bin_size)
            self.exclude_layer = float(exclude_layer)
            self.n_blocks = int(n_blocks)
            self.z_max = z_max
            self.z_min = self.surface_z if z_min is None else min(float(z_min), self.surface_z)
            self.reference = reference

        def _prepare(self):
            self._edges = None
            self._sum = None
            self._block_sum = None
            self._block_count = None

        def _setup_grid(self, dims):
            lu = float(dims[self._iu])
            nu = max(1, int(round(lu / self.bin_size)))
            zmax = float(dims[2]) if self.z_max is None else float(self.z_max)
            nz = max(1, int(math.ceil((zmax - self.z_min) / self.bin_size)))
            self._u_edges = np.linspace(-lu / 2, lu / 2, nu + 1)
            self._z_edges = self.z_min + self.bin_size * np.arange(nz + 1)
            self._edges = (self._u_edges, self._z_edges)
            nb = max(1, min(self.n_blocks, self.n_frames))
            self._nb = nb
            self._sum = np.zeros((nu, nz))
            self._block_sum = np.zeros((nb, nu, nz))
            self._block_count = np.zeros(nb, dtype=int)
            self._block_frame_sum = np.zeros(nb)

        def _single_frame(self):
            dims = self._ts.dimensions
            if dims is None or not np.all(np.asarray(dims[:3]) > 0):
                raise ValueError("ContactAngle needs a periodic box (trajectory has no dimensions)")
            if self._edges is None:
                self._setup_grid(dims)
            pos = self._ag.positions
            lu, la = float(dims[self._iu]), float(dims[self._iaxis])
            u = pos[:, self._iu].astype(float)
            phase = 2.0 * np.pi * u / lu
            centre = lu * math.atan2(np.sin(phase).mean(), np.cos(phase).mean()) / (2.0 * np.pi)
            uw = (u - centre + lu / 2) % lu - lu / 2
            centre += uw.mean()
            uw = (u - centre + lu / 2) % lu - lu / 2
            counts, _, _ = np.histogram2d(uw, pos[:, 2], bins=self._edges)
            du, dz = np.diff(self._u_edges).mean(), self.bin_size
            number_density = counts / (du * dz * la)                  # 1/A^3
            rho = _units.kg_per_m3_to_g_per_cm3(                     # g/cm^3
                _units.amu_per_A3_to_kg_per_m3(number_density * WATER_MOLAR_MASS))
            self._sum += rho
            b = min(self._frame_index * self._nb // self.n_frames, self._nb - 1)
            self._block_sum[b] += rho
            self._block_count[b] += 1
            self._block_frame_sum[b] += self._frame_index

        def _fit(self, rho):
            return fit_contact_angle(rho, self._u_edges, self._z_edges, self.surface_z, self.exclude_layer,
                                     reference=self.reference)

        def _conclude(self):
            if self._edges is None:
                raise ValueError("no frames analysed")
            nf = int(self._block_count.sum())
            rho = self._sum / nf
            fit, fit_error = None, None
            try:
                fit = self._fit(rho)
            except ValueError as exc:               # too flat to fit: see wetting
                fit_error = str(exc)
            block_angles = []
            for b in range(self._nb):
                if self._block_count[b] == 0:
                    continue
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", RuntimeWarning)
                        fb = self._fit(self._block_sum[b] / self._block_count[b])
                    block_angles.append(fb["angle_deg"])
                except ValueError:
                    block_angles.append(float("nan"))
            ba = np.array(block_angles, float)
            bf = (self._block_frame_sum / np.maximum(self._block_count, 1))[self._block_count > 0]
            good = ba[np.isfinite(ba)]
            stderr = float(good.std(ddof=1) / math.sqrt(good.size)) if good.size >= 2 else float("nan")
            if good.size < ba.size and fit is not None:
                warnings.warn(f"{ba.size - good.size} of {ba.size} block fits failed", RuntimeWarning,
                              stacklevel=2)
            if fit is not None:
                bulk, z_ref = fit["bulk_density"], fit["reference_z"]
            else:                                   # a film: its own bulk and plane, if it has any
                zc = 0.5 * (self._z_edges[1:] + self._z_edges[:-1])
                try:
                    bulk = _bulk_density(rho, zc, self.surface_z + self.exclude_layer, self.bin_size)
                except ValueError:
                    bulk = float(rho.max())
                try:
                    z_ref = max(dividing_plane(rho, self._u_edges, self._z_edges, bulk)["z"], self.surface_z) \
                        if self.reference == "dividing_surface" else self.surface_z
                except ValueError:
                    z_ref = self.surface_z
            nan = float("nan")
            r = self.results
            r.angle_deg = fit["angle_deg"] if fit else nan
            r.stderr_deg = stderr
            r.block_angles_deg = ba
            r.block_frames = bf
            r.drift = block_drift(ba, bf)
            r.circle = fit["circle"] if fit else (nan, nan, nan)
            r.reference = self.reference
            r.reference_z = z_ref
            r.surface_z = self.surface_z
            r.density_map = rho
            r.edges = self._edges
            r.interface_points = fit["interface_points"] if fit else np.zeros((0, 2))
            r.all_interface_points = fit["all_interface_points"] if fit else np.zeros((0, 2))
            r.bulk_density = bulk
            r.fit_rms_A = fit["fit_rms_A"] if fit else nan
            r.base_half_width_A = fit["base_half_width_A"] if fit else nan
            r.cap_height_A = fit["cap_height_A"] if fit else nan
            r.dividing = fit["dividing"] if fit else None
            r.wetting = wetting_bound(rho, self._u_edges, self._z_edges, bulk, z_ref, self.exclude_layer)
            r.fit_error = fit_error
            r.n_frames = nf
else:  # pragma: no cover
    class ContactAngle:  # type: ignore[no-redef]
        """Placeholder: the contact-angle analysis needs MDAnalysis (``pip install "nanoimpact[md]"``)."""

        def __init__(self, *args, **kwargs):
            raise ImportError('ContactAngle needs MDAnalysis: pip install "nanoimpact[md]"')


# ------------------------------------------------------------------------------------ surface tension

def surface_tension(pxx_atm, pyy_atm, pzz_atm, lz_A, tail_correction_N_per_m: float = 0.0,
                    n_blocks: int | None = None) -> dict:
    """Liquid-vapour surface tension of a slab with two interfaces normal to z (Kirkwood-Buff 1949).

    gamma = (Lz / 2) (<Pzz> - (<Pxx> + <Pyy>) / 2), pressures in atm (LAMMPS real), ``lz_A`` in A (a
    number or a series like the pressures).  The mean of the instantaneous gamma(t) and its stderr come from
    :func:`timeseries_stats` (automated equilibration detection and the statistical inefficiency, Chodera
    2016), so correlations between the components enter the error; ``n_blocks`` (optional) adds the old
    fixed-block estimate as ``stderr_blocks`` for comparison only.  ``tail_correction_N_per_m`` (e.g. from
    :func:`lj_tail_correction`) is added to ``value``; ``value_uncorrected`` omits it.
    """
    pxx, pyy, pzz = (np.asarray(p, float).ravel() for p in (pxx_atm, pyy_atm, pzz_atm))
    if not pxx.shape == pyy.shape == pzz.shape:
        raise ValueError("pressure series must have the same length")
    lz = np.broadcast_to(np.asarray(lz_A, float), pxx.shape)
    g = 0.5 * lz * (pzz - 0.5 * (pxx + pyy)) * ATM_A_TO_N_PER_M
    st = timeseries_stats(g)
    mean, err = st["mean"], st["stderr"]
    tail = float(tail_correction_N_per_m)
    out = {"value": mean + tail, "stderr": err, "tail_correction": tail, "value_uncorrected": mean,
           "units": "N/m", "statistical_inefficiency": st["g"], "t0": st["t0"], "n_eff": st["n_eff"]}
    if n_blocks:
        out["stderr_blocks"] = block_average(g, n_blocks)[1]
    return out


def lj_tail_correction(epsilon_kcal: float, sigma_A: float, rho_liquid_per_A3: float, r_cut_A: float,
                       rho_vapour_per_A3: float = 0.0, width_A: float = 0.0) -> float:
    """LJ long-range correction to the surface tension (N/m) for pair interactions cut at ``r_cut_A``.

    Blokhuis, Bedeaux, Holcomb & Zollweg, Mol. Phys. 85 (1995) 665, for a tanh profile
    rho(z) = (rho_l + rho_v)/2 - (rho_l - rho_v)/2 tanh(z / d) and the r^-6 part of
    u = 4 eps [(s/r)^12 - (s/r)^6] beyond r_c (g(r) = 1):

        gamma_tail = 12 pi eps s^6 (rho_l - rho_v)^2 int_0^1 ds int_rc^inf dr coth(r s / d) (3 s^3 - s) / r^3

    which for a sharp interface (``width_A = 0``) is (3 pi / 2) eps s^6 (rho_l - rho_v)^2 / r_c^2.
    Number densities of the LJ sites in 1/A^3 (SPC/E: oxygens, ~0.0334).  Use it when the LJ part is
    truncated (no LJ PPPM) and Coulomb is done by PPPM/Ewald; it is added to gamma by formula.
    """
    eps, sig, rc = float(epsilon_kcal), float(sigma_A), float(r_cut_A)
    drho = float(rho_liquid_per_A3) - float(rho_vapour_per_A3)
    pref = 12.0 * math.pi * eps * sig**6 * drho**2
    d = float(width_A)
    if d <= 0.0:
        integral = 0.25 * 0.5 / rc**2
    else:
        from scipy import integrate

        def inner(s):  # int_rc^inf coth(r s/d) / r^3 dr  (s > 0)
            return integrate.quad(lambda r: 1.0 / (math.tanh(r * s / d) * r**3), rc, np.inf, limit=200)[0]

        integral = integrate.quad(lambda s: (3 * s**3 - s) * inner(s) if s > 0 else -d / (3 * rc**3),
                                  0.0, 1.0, limit=200)[0]
    return pref * integral * KCALMOL_PER_A2_TO_J_PER_M2


def density_profile(z_positions, masses, area, bins) -> dict:
    """Mass density profile along z (kg/m^3), averaged over frames.

    ``z_positions``: (n_frames, n_atoms) or (n_atoms,) in A; ``masses``: (n_atoms,) in g/mol;
    ``area``: cross-section in A^2 (a number or one per frame); ``bins``: number of bins or edges (A).
    Returns ``z_A`` (bin centres), ``edges_A``, ``z`` (m), ``density`` (kg/m^3).
    """
    z = np.atleast_2d(np.asarray(z_positions, float))
    m = np.broadcast_to(np.asarray(masses, float), z.shape[-1:])
    area = np.broadcast_to(np.asarray(area, float), (z.shape[0],))
    edges = np.histogram_bin_edges(z, bins=bins) if np.ndim(bins) == 0 else np.asarray(bins, float)
    dz = np.diff(edges)
    rho = np.zeros(dz.size)
    for zi, ai in zip(z, area):
        h, _ = np.histogram(zi, bins=edges, weights=m)
        rho += h / (ai * dz)                                           # g/mol / A^3
    rho = _units.amu_per_A3_to_kg_per_m3(rho / z.shape[0])           # kg/m^3
    centres = 0.5 * (edges[1:] + edges[:-1])
    return {"z_A": centres, "edges_A": edges, "z": _units.angstrom_to_m(centres), "density": rho,
            "units": "kg/m^3"}


def _tanh_slab(z, rho_l, rho_v, h, d):
    return 0.5 * (rho_l + rho_v) - 0.5 * (rho_l - rho_v) * np.tanh((np.abs(z) - h) / d)


def _fit_slab(zc, rho):
    from scipy.optimize import curve_fit

    peak = float(np.max(rho))
    liquid = rho > 0.5 * peak
    rl0 = float(np.mean(rho[liquid]))
    h0 = 0.5 * float(np.sum(liquid)) * float(np.diff(zc).mean())
    p, _ = curve_fit(_tanh_slab, zc, rho, p0=[rl0, 0.0, h0, 2.0], maxfev=20000)
    return p


def slab_density(z_positions, masses, area_A2, lz_A: float | None = None, bin_A: float = 0.5,
                 n_blocks: int = 5) -> dict:
    """Bulk density (kg/m^3) of a liquid slab normal to z, by a tanh fit to its symmetrised profile.

    Each frame is centred on the slab's mass-weighted circular mean in z (periodic ``lz_A``; plain mean
    when ``lz_A`` is None), then profiles are fitted to rho(z) = (rho_l + rho_v)/2 - (rho_l - rho_v)/2
    tanh((|z| - h)/d).  ``value`` = rho_l from the full average; ``stderr`` from block fits.  Also
    ``rho_vapour``, ``half_thickness_A`` (h, the Gibbs dividing surfaces at +-h), ``width_A`` (d),
    ``core_mean`` (plain mean over |z| < h - 3d) and the ``profile``.
    """
    z = np.atleast_2d(np.asarray(z_positions, float))
    m = np.broadcast_to(np.asarray(masses, float), z.shape[-1:])
    nf = z.shape[0]
    zc = np.empty_like(z)
    for i, zi in enumerate(z):
        if lz_A is None:
            c = np.average(zi, weights=m)
            zc[i] = zi - c
        else:
            lz = float(lz_A)
            ph = 2 * np.pi * zi / lz
            c = lz * math.atan2(np.average(np.sin(ph), weights=m), np.average(np.cos(ph), weights=m)) / (2 * np.pi)
            w = (zi - c + lz / 2) % lz - lz / 2
            c += np.average(w, weights=m)
            zc[i] = (zi - c + lz / 2) % lz - lz / 2
    half = float(lz_A) / 2 if lz_A is not None else float(np.abs(zc).max()) + bin_A
    nb = max(1, int(round(2 * half / bin_A)))
    edges = np.linspace(-half, half, nb + 1)
    prof = density_profile(zc, m, area_A2, edges)
    rl, rv, h, d = _fit_slab(prof["z_A"], prof["density"])
    nblk = min(int(n_blocks), nf)
    vals = []
    if nblk >= 2:
        for idx in np.array_split(np.arange(nf), nblk):
            pb = density_profile(zc[idx], m, area_A2, edges)
            try:
                vals.append(_fit_slab(pb["z_A"], pb["density"])[0])
            except RuntimeError:
                vals.append(np.nan)
    vals = np.array(vals, float)
    good = vals[np.isfinite(vals)]
    err = float(good.std(ddof=1) / math.sqrt(good.size)) if good.size >= 2 else float("nan")
    core = np.abs(prof["z_A"]) < abs(h) - 3 * abs(d)
    core_mean = float(prof["density"][core].mean()) if core.any() else float("nan")
    return {"value": float(rl), "stderr": err, "units": "kg/m^3", "rho_vapour": float(rv),
            "half_thickness_A": float(abs(h)), "width_A": float(abs(d)), "core_mean": core_mean,
            "block_values": vals, "profile": prof}


# ------------------------------------------------------------------------------------------ pull-off

_LJ93_PEAK = 3.0 ** (1.0 / 6.0)   # peak traction of the LJ 9-3 law at h = 3^(1/6) z0


def _law(kind):
    """Shape f(h/z0) of a law F = amplitude * f; amplitude = 8w/(3 z0) (lj93) or Fc (sphere_lj93)."""
    if kind == "lj93":
        return lambda x: x ** -9 - x ** -3
    if kind == "sphere_lj93":
        return lambda x: x ** -8 / 3.0 - 4.0 * x ** -2 / 3.0
    raise ValueError(f"unknown traction law {kind!r}: use 'lj93' or 'sphere_lj93'")


def fit_traction_law(sep, force, kind: str = "lj93", offset: bool = False, force_stderr=None) -> dict:
    """Fit an LJ-type force-separation law (positive = repulsive) to (sep, force) in consistent units.

    ``kind="lj93"``: the LJ 9-3 traction law (Maugis 1992)
        F(D) = (8 w / (3 z0)) [(z0/h)^9 - (z0/h)^3],  h = D - D_off,
    with equilibrium separation z0 and work w = -int_z0^inf F dh (force x length units of the input;
    J/m^2 if the input is a traction in Pa vs m).  Peak tension 16 w / (9 sqrt 3 z0) = 1.026 w/z0 at
    h = 3^(1/6) z0; Maugis' Dugdale range h0 = w / sigma0 = 0.974 z0.
    ``kind="sphere_lj93"``: a rigid sphere against a flat with the same surface law in the Derjaguin
    approximation, F(D) = Fc [(z0/h)^8 / 3 - 4 (z0/h)^2 / 3]; Fc = 2 pi R w is the pull-off force,
    reached at h = z0.
    With ``offset=True`` the origin D_off of the separation is fitted too (MD separations are measured
    between atom centres, not from the law's origin).  Points with F > 3 |F_min| (the stiff repulsive
    wall) are left out so they do not dominate the least squares.

    ``force_stderr`` (per point) weights the least squares by 1/stderr.

    Returns ``kind``, ``params`` (w or Fc, z0, offset), ``z0``, ``w`` (None for sphere_lj93), ``peak``
    (magnitude of the most tensile force of the law), ``sep_at_peak``, ``h0_maugis`` (lj93), ``rms`` and
    ``stderr`` (of ``params``, ``z0`` and ``peak``) from the fit's covariance inv(J^T J), scaled by the residual
    variance (unweighted) or by max(1, reduced chi^2) (weighted); nan when the fit has no degrees of freedom.
    """
    from scipy.optimize import least_squares

    d = np.asarray(sep, float).ravel()
    f = np.asarray(force, float).ravel()
    order = np.argsort(d)
    d, f = d[order], f[order]
    sd = None if force_stderr is None else np.asarray(force_stderr, float).ravel()[order]
    shape = _law(kind)
    i = int(np.argmin(f))
    fmin, dmin = float(f[i]), float(d[i])
    if not fmin < 0:
        raise ValueError("the force curve has no tensile (negative) part to fit")
    use = f <= 3.0 * abs(fmin)
    # scaled: the minimum at (1, -1). Without an offset the law's origin is d = 0, so d is scaled by dmin
    # (> 0 required). With an offset, d is measured from the first point used, d0, in units of dmin - d0, so
    # MD separations that start at or below zero (a compressed contact) scale the same way.
    if offset:
        d0 = float(d[use].min())
        scale = dmin - d0
        if not scale > 0:
            raise ValueError("the most tensile point is the first one used: no attractive branch to fit")
    else:
        if not dmin > 0:
            raise ValueError("separations must be positive when the law's origin is not fitted (offset=False)")
        d0, scale = 0.0, dmin
    ds, fs = (d[use] - d0) / scale, f[use] / abs(fmin)
    ws = np.ones_like(fs) if sd is None else abs(fmin) / np.maximum(sd[use], 1e-300)
    peak_x = _LJ93_PEAK if kind == "lj93" else 1.0
    peak_val = -float(shape(np.array(peak_x)))       # |shape| at its minimum

    def model(p, dd):
        amp, z0, off = p[0], p[1], (p[2] if offset else 0.0)
        h = np.maximum(dd - off, 1e-6)
        return amp * shape(h / z0)

    def res(p):
        return (model(p, ds) - fs) * ws

    best = None
    offs = (-0.2, -0.5, -1.0, -2.0) if offset else (0.0,)
    for off0 in offs:
        z00 = (1.0 - off0) / peak_x
        p0 = [1.0 / peak_val, z00] + ([off0] if offset else [])
        lo = [0.0, 1e-6] + ([-np.inf] if offset else [])
        hi = [np.inf, np.inf] + ([float(ds.min()) - 1e-9] if offset else [])
        try:
            sol = least_squares(res, p0, bounds=(lo, hi), xtol=1e-14, ftol=1e-14, gtol=1e-14,
                                max_nfev=20000)
        except ValueError:
            continue
        if best is None or sol.cost < best.cost:
            best = sol
    if best is None:
        raise RuntimeError("traction-law fit failed")
    amp, z0 = best.x[0] * abs(fmin), best.x[1] * scale
    off = d0 + best.x[2] * scale if offset else 0.0
    rms = float(np.sqrt(np.mean((best.fun / ws) ** 2))) * abs(fmin)
    # covariance of (amp, z0[, offset]) in physical units
    npar, m = len(best.x), int(ds.size)
    dof = m - npar
    try:
        cov = np.linalg.inv(best.jac.T @ best.jac)
        chi2 = float(np.sum(best.fun ** 2)) / dof if dof > 0 else float("nan")
        cov = cov * (chi2 if sd is None else max(1.0, chi2))
        cov = cov * np.outer(*(2 * [np.array([abs(fmin), scale, scale][:npar])]))
    except np.linalg.LinAlgError:
        cov = np.full((npar, npar), np.nan)
    se = lambda g: float(math.sqrt(g @ cov @ g)) if np.all(np.isfinite(cov)) and g @ cov @ g >= 0 else float("nan")
    g_amp, g_z0 = np.eye(npar)[0], np.eye(npar)[1]
    out = {"kind": kind, "z0": float(z0), "offset": float(off), "rms": rms,
           "peak": float(amp * peak_val), "sep_at_peak": float(off + peak_x * z0), "dof": dof}
    stderr = {"z0": se(g_z0), "offset": se(np.eye(npar)[2]) if offset else 0.0, "peak": se(g_amp) * peak_val}
    if kind == "lj93":
        w = amp * 3.0 * z0 / 8.0
        stderr["w"] = se(3.0 / 8.0 * (z0 * g_amp + amp * g_z0))
        out.update(w=float(w), params={"w": float(w), "z0": float(z0), "offset": float(off)},
                   h0_maugis=float(w / (amp * peak_val)))
    else:
        stderr["Fc"] = se(g_amp)
        out.update(w=None, params={"Fc": float(amp), "z0": float(z0), "offset": float(off)})
    out["stderr"] = stderr
    return out


def pull_off_analysis(separation_A, force_kcal_per_molA, smooth: int | None = None,
                      radius_m: float | None = None, law: str = "lj93", fit_offset: bool = True) -> dict:
    """Pull-off force and interaction range from an asperity force-separation curve (SI out).

    Convention: ``force_kcal_per_molA`` is the force on the asperity along the pulling direction,
    positive = repulsive (pushing the surfaces apart); ``separation_A`` grows as the asperity is pulled
    off.  ``smooth`` (odd window, in points) applies a cubic Savitzky-Golay filter before the minimum is
    searched.

    Returns (SI):
    ``max_tensile_force`` (N, the magnitude of the most tensile force, spline-refined),
    ``separation_at_max`` (m), ``zero_force_separation`` (m, the last repulsive-to-tensile crossing
    before the maximum tension), ``z0_zero_to_min`` (m, the distance from that crossing to the maximum
    tension -- a model-free range), ``traction_fit`` (:func:`fit_traction_law` with ``law``, in SI) and
    ``z0`` (m): the equilibrium separation z0 of the fitted law, the length in Tabor's parameter and
    Maugis' lambda (for ``lj93`` the zero-to-min distance is (3^(1/6) - 1) z0 = 0.201 z0).  With
    ``radius_m``: ``eff_work_jkr`` = F / (1.5 pi R) and ``eff_work_dmt`` = F / (2 pi R) (J/m^2).
    ``curve``: ``separation`` (m), ``force`` (N) and ``force_smoothed`` (N) sorted by separation.
    """
    d = np.asarray(separation_A, float).ravel()
    f = np.asarray(force_kcal_per_molA, float).ravel()
    if d.shape != f.shape or d.size < 3:
        raise ValueError("separation_A and force_kcal_per_molA must be 1-D arrays of equal length >= 3")
    order = np.argsort(d, kind="stable")
    d = _units.angstrom_to_m(d[order])
    f = f[order] * KCALMOL_PER_A_TO_N
    fs = f
    if smooth:
        from scipy.signal import savgol_filter

        win = int(smooth) | 1
        fs = savgol_filter(f, win, min(3, win - 1))
    i = int(np.argmin(fs))
    d_max, f_min = _refined_min(d, fs, i)
    out = {"max_tensile_force": float(max(-f_min, 0.0)), "separation_at_max": d_max, "units": "SI",
           "curve": {"separation": d, "force": f, "force_smoothed": fs}}
    cross = np.nonzero((fs[:i] >= 0) & (fs[1:i + 1] < 0))[0]
    if cross.size:
        j = int(cross[-1])
        d_zero = float(d[j] + (d[j + 1] - d[j]) * fs[j] / (fs[j] - fs[j + 1]))
    else:
        d_zero = float("nan")
    out["zero_force_separation"] = d_zero
    out["z0_zero_to_min"] = d_max - d_zero
    try:
        fit = fit_traction_law(d, fs, kind=law, offset=fit_offset)
    except (ValueError, RuntimeError) as exc:
        fit = {"error": str(exc), "z0": float("nan")}
    out["traction_fit"] = fit
    out["z0"] = fit["z0"]
    out["z0_stderr"] = fit.get("stderr", {}).get("z0", float("nan"))
    if radius_m is not None:
        fmag = out["max_tensile_force"]
        out["eff_work_jkr"] = fmag / (1.5 * math.pi * float(radius_m))
        out["eff_work_dmt"] = fmag / (2.0 * math.pi * float(radius_m))
        if law == "sphere_lj93" and "params" in fit:
            fit["w"] = fit["params"]["Fc"] / (2.0 * math.pi * float(radius_m))
    else:
        out["eff_work_jkr"] = out["eff_work_dmt"] = None
    return out


def rate_extrapolation(rates, forces, target_rate: float = 1.0, forces_stderr=None,
                       temperature_K: float | None = None) -> dict:
    """Pull-off force vs loading rate: linear fit F = a + b ln(rate) (Bell 1978; Evans-Ritchie 1997).

    In the Bell-Evans regime the most probable rupture force grows with the logarithm of the loading
    rate, F = (kT / x_b) ln(rate x_b / (k_off kT)); ``F0`` is the fit evaluated at ``target_rate`` (same
    unit as ``rates``: default 1, e.g. 1 m/s for pulling speeds in m/s).  ``slope`` is dF/d ln(rate);
    ``stderr`` of F0 from the fit covariance (weighted by ``forces_stderr`` if given, otherwise scaled
    by the residuals; nan with two points).  With ``temperature_K`` and forces in N, ``x_beta`` =
    kT / slope (m).  Extrapolating far below the simulated rates is a lower bound on the slow-pulling
    force only while the Bell-Evans regime holds: near equilibrium the force levels off at a finite
    value (Friddle, Noy & De Yoreo, PNAS 109 (2012) 13573), so F0 below that is not physical.
    """
    r = np.asarray(rates, float).ravel()
    fo = np.asarray(forces, float).ravel()
    if r.shape != fo.shape or r.size < 2 or np.any(r <= 0):
        raise ValueError("need >= 2 positive rates with one force each")
    x = np.log(r)
    a = np.column_stack([np.ones_like(x), x])
    if forces_stderr is not None:
        w = 1.0 / np.asarray(forces_stderr, float).ravel()
    else:
        w = np.ones_like(x)
    aw, fw = a * w[:, None], fo * w
    coef, *_ = np.linalg.lstsq(aw, fw, rcond=None)
    cov = np.linalg.inv(aw.T @ aw)
    dof = x.size - 2
    if forces_stderr is None:
        cov = cov * (np.sum((fw - aw @ coef) ** 2) / dof if dof > 0 else np.nan)
    xt = math.log(float(target_rate))
    g = np.array([1.0, xt])
    f0 = float(coef[0] + coef[1] * xt)
    out = {"F0": f0, "slope": float(coef[1]), "intercept": float(coef[0]),
           "stderr": float(math.sqrt(g @ cov @ g)) if np.all(np.isfinite(cov)) else float("nan"),
           "slope_stderr": float(math.sqrt(cov[1, 1])) if np.isfinite(cov[1, 1]) else float("nan"),
           "target_rate": float(target_rate)}
    if temperature_K is not None and coef[1] > 0:
        out["x_beta"] = _units.BOLTZMANN * float(temperature_K) / float(coef[1])
    return out
