"""Works of adhesion from energies and force curves: energy differences, thermodynamic integration of the
mean force, the flat-slab traction law's sigma0 and z0, dispersion beyond the cutoff.
"""
from __future__ import annotations

import math

import numpy as np

from md import units as _units
from md.analysis.common import KCALMOL_PER_A2_TO_J_PER_M2, refined_min
from md.analysis.stats import block_average, student_t_factor, timeseries_stats

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


#: an interval whose force change exceeds this fraction of the peak attraction is flagged for refinement (a
#: choice: one interval then carries a jump of the order of the well depth, as a rupture between two windows does)
REFINE_FRACTION = 0.5


def grid_interval_bounds(separation_A, force, start_A: float, refine_fraction: float = REFINE_FRACTION) -> dict:
    """Grid error bound of the trapezoid rule, interval by interval, over the integrated range [start, d[-1]].

    For a force monotone between two neighbouring windows the true integral over the interval lies between the
    two rectangles f_k dd and f_{k+1} dd, so the trapezoid (their mean) is within b_k = 1/2 |f_{k+1} - f_k| dd of
    it, whatever the shape in between (a step -- a rupture -- anywhere inside the interval included). The first
    interval is cut at ``start_A`` (the force there is interpolated). Returns ``bounds_kcal_mol`` (b_k per
    interval of the sorted grid, 0 outside the range), ``detachment_max_kcal_mol`` (the largest b_k from the most
    attractive window outwards: where the force returns to zero), ``refine_A`` ([d_k, d_k+1] where
    |f_{k+1} - f_k| > ``refine_fraction`` x the peak attraction |min f|) and ``refine`` (bool per interval)."""
    d = np.asarray(separation_A, float).ravel()
    f = np.asarray(force, float).ravel()
    lo = np.maximum(d[:-1], float(start_A))
    width = np.clip(d[1:] - lo, 0.0, None)
    f_lo = np.where(d[:-1] < lo, np.interp(lo, d, f), f[:-1])
    jump = np.abs(f[1:] - f_lo)
    bounds = 0.5 * jump * width
    i_min = int(np.argmin(f))
    detach = bounds[i_min:] if i_min < bounds.size else bounds[:0]
    peak = max(-float(f.min()), 0.0)
    refine = (width > 0) & (jump > refine_fraction * peak) if peak > 0 else np.zeros(bounds.size, bool)
    return {"bounds_kcal_mol": bounds, "detachment_max_kcal_mol": float(detach.max()) if detach.size else 0.0,
            "refine_A": [[float(d[k]), float(d[k + 1])] for k in np.flatnonzero(refine)], "refine": refine}


def force_integration_work(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA,
                           area_A2: float, from_zero_crossing: bool = True, correlation: float = 0.0,
                           refine_fraction: float = REFINE_FRACTION) -> dict:
    """Free energy of separation by thermodynamic integration of the mean force over separation (J/m^2).

    W_F = -(1/A) integral <F_z> dd from the bottom of the adhesive well to the last window, with ``mean_force``
    the force on the upper body along +z (repulsion positive, attraction negative) at each held separation
    ``separation_A`` (A, any order). The bottom of the well is where the mean force changes sign from repulsive
    to attractive (linear interpolation between the two windows around it: the PMF's minimum, the equilibrium
    contact at zero load). The grid must therefore reach into compression: ``repulsive_end`` is False when no
    window before the most attractive one is repulsive -- then the integral starts at the first window and
    misses part of the well (a lower bound); ``from_zero_crossing=False`` always integrates the whole grid.

    ``value`` uses the trapezoid rule and ``stderr`` propagates the windows' statistical errors through it
    (linearised: the start point moves with the forces, at zero force). Windows that form a chain (each started
    from its neighbour's last state) share slow modes, so their errors are positively correlated: ``correlation``
    rho gives them the lag-1 (AR(1)) covariance C_kl = rho^|k-l| e_k e_l in separation order, and the stderr is
    sqrt(g^T C g) with g the rule's weights (propagation of correlated inputs, JCGM 100:2008, the GUM, section
    5.2; rho = 0: independent windows; :func:`chain_correlation` estimates rho from replicate chains).

    ``value_pchip`` integrates the shape-preserving cubic (PCHIP, Fritsch & Carlson, SIAM J. Numer. Anal. 17
    (1980) 238) over the same range. Two quadratures of different order agree when the grid resolves the curve,
    and both interpolate monotonically across a step, so |trapezoid - PCHIP| cannot see where in a wide interval
    the force jumped (a rupture). Each interval's own bound does: if the force is monotone between two windows,
    the true area lies between the two rectangles, so the trapezoid is within 1/2 |df| dd of it
    (:func:`grid_interval_bounds`). ``discretisation_error`` = max(|trapezoid - PCHIP|, the largest interval
    bound over the detachment region, from the most attractive window outwards); ``refine_intervals`` lists the
    intervals whose force change exceeds ``refine_fraction`` of the peak attraction (windows to add there).
    ``pmf_J_per_m2``: the PMF at each window relative to the well's bottom; ``cumulative_J_per_m2``: -integral
    from the first window.
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
    if not 0.0 <= correlation < 1.0:
        raise ValueError(f"correlation = {correlation}: must lie in [0, 1)")
    lag = np.abs(np.subtract.outer(np.arange(f.size), np.arange(f.size)))
    ge = grad * e
    err = math.sqrt(max(float(ge @ (float(correlation) ** lag) @ ge), 0.0)) * conv
    trap = w_kcal * conv
    pchip = -float(PchipInterpolator(d, f).integrate(start, d[-1])) * conv if d.size >= 3 else trap
    grid = grid_interval_bounds(d, f, start, refine_fraction)
    grid_max = float(grid["detachment_max_kcal_mol"]) * conv
    cumulative = -np.concatenate([[0.0], np.cumsum(0.5 * np.diff(d) * (f[1:] + f[:-1]))]) * conv
    # PMF relative to the well's bottom: cumulative minus its (interpolated) value at the start
    # (the trapezoid value at the crossing, where f = 0; the first window without a crossing)
    c_start = float(cumulative[j]) - 0.5 * (start - d[j]) * f[j] * conv if j is not None else 0.0
    return {"value": trap, "stderr": err, "value_pchip": pchip,
            "discretisation_error": max(abs(trap - pchip), grid_max),
            "quadrature_difference": abs(trap - pchip), "grid_bound_max": grid_max,
            "interval_bounds_J_per_m2": grid["bounds_kcal_mol"] * conv, "refine_intervals_A": grid["refine_A"],
            "correlation": float(correlation), "units": "J/m^2", "separation_A": d, "cumulative_J_per_m2": cumulative,
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
    ``stderr = max(t std over registries / sqrt(n), sqrt(sum stderr^2) / n)`` -- the first is the random-effects
    error (it carries the registries' own statistical noise too), scaled by the Student-t factor of n - 1 degrees
    of freedom (:func:`md.analysis.stats.student_t_factor`: 1.84 for two registries, 1.32 for three) so that it is
    a one-sigma half-width although the spread of so few is itself uncertain; the second guards it when two or
    three registries agree by chance. One registry: its own stderr.
    Returns ``mean``, ``stderr``, ``stderr_statistical`` (the registries' own stderrs only), ``registry_spread``
    (std, ddof 1), ``t_factor`` and ``n``.
    """
    scalar = np.ndim(values) == 1
    v = np.asarray(values, float).reshape(len(values), -1)
    e = np.asarray(stderrs, float).reshape(v.shape)
    n = v.shape[0]
    mean = v.mean(axis=0)
    stat = np.sqrt(np.sum(e ** 2, axis=0)) / n
    spread = v.std(axis=0, ddof=1) if n >= 2 else np.zeros_like(mean)
    t = student_t_factor(n) if n >= 2 else 1.0
    err = np.maximum(t * spread / math.sqrt(n), stat)
    pick = (lambda a: float(a[0])) if scalar else (lambda a: a)
    return {"mean": pick(mean), "stderr": pick(err), "stderr_statistical": pick(stat),
            "registry_spread": pick(spread), "t_factor": t, "n": int(n)}


def registry_consistency(values, stderrs, p_min: float = 0.01) -> dict:
    """Do the lateral registries agree within their own stderrs, point by point?

    ``values``, ``stderrs``: shape (n_registries, n_points), e.g. each window's mean force per registry. At each
    point chi^2 = sum_r (v_r - m)^2 / e_r^2 with m the inverse-variance weighted mean, chi^2-distributed with
    n - 1 degrees of freedom when the registries measure one value (Bevington & Robinson, *Data Reduction and
    Error Analysis*, 3rd ed., section 11.1, with the registries as repeated measurements of one quantity). A
    point is ``inconsistent`` where the chi^2 tail probability is below ``p_min``. There, either the quantity
    depends on the registry (a crystalline contact), or each registry's stderr is too small for what its window
    really resolves (a mean not converged in the window). Either way the registries' spread, which
    `registry_average` puts into the error, is what carries the error there. Fewer than two registries: nothing to
    compare (all points consistent, chi^2 nan). Returns ``chi2_per_dof`` and ``p`` (arrays), ``inconsistent``
    (bool array), ``dof``."""
    from scipy.stats import chi2 as chi2_dist

    v = np.asarray(values, float)
    e = np.asarray(stderrs, float)
    if v.ndim != 2 or v.shape != e.shape:
        raise ValueError(f"values and stderrs must both have shape (registries, points); got {v.shape}, {e.shape}")
    n = v.shape[0]
    if n < 2:
        nan = np.full(v.shape[1], np.nan)
        return {"chi2_per_dof": nan, "p": np.ones(v.shape[1]), "inconsistent": np.zeros(v.shape[1], bool), "dof": 0}
    with np.errstate(divide="ignore", invalid="ignore"):
        w = 1.0 / e ** 2
        m = np.sum(w * v, axis=0) / np.sum(w, axis=0)
        chi2 = np.sum(w * (v - m) ** 2, axis=0)
    p = chi2_dist.sf(chi2, n - 1)
    return {"chi2_per_dof": chi2 / (n - 1), "p": p, "inconsistent": p < p_min, "dof": n - 1}


def chain_correlation(values, stderrs) -> float:
    """Lag-1 correlation rho of the window errors along a chain, from replicate chains (registries) of one curve.

    ``values``, ``stderrs``: shape (n_registries, n_windows) in separation order. Each chain's deviation from the
    mean over chains, in units of its own stderr, z_rk = (v_rk - m_k) / e_rk, is its error at window k (up to the
    mean's share); in a chain whose windows share slow modes neighbouring z's have the same sign. rho = sum z_rk
    z_r,k+1 / sum z_rk^2, pooled over chains and pairs of neighbours (the lag-1 autocorrelation estimate, Box,
    Jenkins & Reinsel, *Time Series Analysis*, 4th ed., eq. 2.1.12), clipped to [0, 0.95]: a negative estimate
    from few chains is taken as independence, and 0.95 keeps the AR(1) covariance of
    :func:`force_integration_work` well conditioned. A registry-dependent force that one chain keeps along the
    curve counts as correlation too (conservative). Fewer than two chains or three windows: 0."""
    v = np.asarray(values, float)
    e = np.asarray(stderrs, float)
    if v.ndim != 2 or v.shape != e.shape:
        raise ValueError(f"values and stderrs must both have shape (registries, windows); got {v.shape}, {e.shape}")
    if v.shape[0] < 2 or v.shape[1] < 3:
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(e > 0, (v - v.mean(axis=0)) / e, 0.0)
    den = float(np.sum(z * z))
    if not den > 0:
        return 0.0
    return float(np.clip(np.sum(z[:, 1:] * z[:, :-1]) / den, 0.0, 0.95))


def window_length_check(separation_A, first_half_force, second_half_force, statistical_stderr, area_A2: float,
                        correlation: float = 0.0, n_sigma: float = 2.0) -> dict:
    """Have the windows run long enough for their mean force to settle? W from the first half of every window's
    samples against W from the second half, over the same grid (each from its zero-force point).

    ``first_half_force``, ``second_half_force``: the mean force of each half per window (kcal/mol/A, averaged over
    the registries in the same way as the whole); ``statistical_stderr``: the whole window's stderr from its
    samples alone (within-registry statistics, :func:`registry_average`'s ``stderr_statistical``). A half has
    sqrt 2 of it, so W of a half has sqrt 2 of the whole's error sigma_W, and the difference of two independent
    halves 2 sigma_W. The registries' spread must stay out of this tolerance: a registry's offset is in both of
    its halves and cancels in their difference, so a tolerance that held it would pass drifts it has nothing to
    do with. ``converged`` when |difference| <= ``n_sigma`` x its stderr. Returns both halves' W, the
    difference, its stderr and ``converged``."""
    e = np.asarray(statistical_stderr, float) * math.sqrt(2.0)
    w1 = force_integration_work(separation_A, first_half_force, e, area_A2, correlation=correlation)
    w2 = force_integration_work(separation_A, second_half_force, e, area_A2, correlation=correlation)
    diff = w2["value"] - w1["value"]
    err = math.hypot(w1["stderr"], w2["stderr"])
    return {"first_half_J_m2": w1["value"], "second_half_J_m2": w2["value"], "difference_J_m2": diff,
            "difference_stderr_J_m2": err, "n_sigma": float(n_sigma), "converged": bool(abs(diff) <= n_sigma * err)}


def entropic_term(energy_work: dict, free_energy_work: dict) -> dict:
    """T dS / A = (dE - dF) / A of each registry that has both works (J/m^2).

    ``energy_work``, ``free_energy_work``: {registry: (value, stderr)} -- dE/A from a zero-load contact leg and
    W_F by force integration of that registry's own chain. dE and dF must describe the same contact: the
    difference of one registry's energy and another registry's (or the registries' average) free energy holds
    their registry dependence, not the entropy (Israelachvili, *Intermolecular and Surface Forces*, 3rd ed.,
    section 17.2, for dF = dE - T dS at the interface). Returns ``per_registry`` {registry: (value, stderr)},
    ``registries`` (sorted) and, with several, their ``mean`` and ``stderr`` (:func:`registry_average`);
    with one, its value and stderr. No common registry: ValueError."""
    common = sorted(set(energy_work) & set(free_energy_work))
    if not common:
        raise ValueError(f"no registry has both dE (registries {sorted(energy_work)}) and dF "
                         f"(registries {sorted(free_energy_work)})")
    per = {r: (float(energy_work[r][0]) - float(free_energy_work[r][0]),
               math.hypot(float(energy_work[r][1] or 0.0), float(free_energy_work[r][1] or 0.0))) for r in common}
    avg = registry_average([per[r][0] for r in common], [per[r][1] for r in common])
    return {"per_registry": per, "registries": common, "mean": avg["mean"], "stderr": avg["stderr"]}


def hysteresis(w_out: float, stderr_out: float, w_back: float, stderr_back: float) -> dict:
    """Out-and-back works of one path (J/m^2): the hysteresis W_out - W_back with its stderr, and the estimate of
    the reversible work as their mean, stderr 1/2 sqrt(e_out^2 + e_back^2) (the two chains' statistical errors
    taken as independent), with half the hysteresis as a systematic error. A forward non-equilibrium work exceeds
    the free energy and a reverse one falls short of it (second law), so the mean brackets it to first order in
    the dissipation (Crooks, Phys. Rev. E 61 (2000) 2361: for a dissipation symmetric in the two directions)."""
    h = float(w_out - w_back)
    e = float(np.hypot(stderr_out, stderr_back))
    return {"value": 0.5 * float(w_out + w_back), "stderr": 0.5 * e, "hysteresis": h, "hysteresis_stderr": e,
            "systematic": 0.5 * abs(h)}


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
    d_min, e_min = refined_min(d, e, i)
    var_min = float(se[i] ** 2) if se is not None else float("nan")
    f = KCALMOL_PER_A2_TO_J_PER_M2 / area
    return {"value": (plateau - e_min) * f, "stderr": math.sqrt(var_min + var_plateau) * f,
            "units": "J/m^2", "note": _ENERGY_NOTE, "method": method,
            "separation_at_min": float(_units.angstrom_to_m(d_min)), "energy_min_kcal": e_min,
            "plateau_kcal": plateau}
