"""Asperity pull-off: the maximum tensile force, traction-law fits and rate extrapolation.
"""
from __future__ import annotations

import math

import numpy as np

from md import units as _units
from md.analysis.common import KCALMOL_PER_A_TO_N, refined_min

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

    best = _least_squares_law(shape, ds, fs, ws, offset, peak_x, peak_val)
    amp, z0 = best.x[0] * abs(fmin), best.x[1] * scale
    off = d0 + best.x[2] * scale if offset else 0.0
    rms = float(np.sqrt(np.mean((best.fun / ws) ** 2))) * abs(fmin)
    npar = len(best.x)
    dof = int(ds.size) - npar
    cov = _covariance(best, dof, weighted=sd is not None, units=np.array([abs(fmin), scale, scale][:npar]))
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


def _least_squares_law(shape, ds, fs, ws, offset: bool, peak_x: float, peak_val: float):
    """The least-squares fit (scipy) of amp * shape((d - off) / z0) to the scaled points (ds, fs) with weights
    ``ws``, from several starting offsets (the best kept); RuntimeError if none converges."""
    from scipy.optimize import least_squares

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
    return best


def _covariance(best, dof: int, weighted: bool, units: np.ndarray) -> np.ndarray:
    """Covariance of the fitted (amp, z0[, offset]) in physical units (``units`` undo the scaling): inv(J^T J)
    scaled by the residual variance (unweighted) or by max(1, reduced chi^2) (weighted); nan if singular."""
    npar = len(best.x)
    try:
        cov = np.linalg.inv(best.jac.T @ best.jac)
        chi2 = float(np.sum(best.fun ** 2)) / dof if dof > 0 else float("nan")
        cov = cov * (max(1.0, chi2) if weighted else chi2)
        return cov * np.outer(units, units)
    except np.linalg.LinAlgError:
        return np.full((npar, npar), np.nan)


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
    d_max, f_min = refined_min(d, fs, i)
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


def paired_speed_extrapolation(speeds_m_s, forces_by_speed, model: str = "linear", target_m_s: float = 0.0) -> dict:
    """The pull-off force extrapolated in pulling speed, position by position: each tip position's forces at the
    speeds (``forces_by_speed``: one row per speed, one column per position, the same positions at every speed, each
    position's pulls from its own held contact) are fitted by a line and evaluated at ``target_m_s``; the mean over
    positions, its stderr = spread / sqrt(n) x Student t (n - 1 dof; md.analysis.stats.student_t_factor), so the
    pairing cancels the positions' geometric spread from the slope.

    ``model`` = 'linear': F = F0 + c v, a viscous (drag-like) excess force, whose v -> 0 limit (target 0) is the
    quasi-static pull-off; 'log': F = a + b ln v, the Bell-Evans thermally activated regime (Bell, Science 200
    (1978) 618; Evans & Ritchie, Biophys. J. 72 (1997) 1541), which has no v -> 0 limit (target must be > 0) and
    saturates near equilibrium (Friddle, Noy & De Yoreo, PNAS 109 (2012) 13573). With two speeds neither model is
    tested: the two bracket what the data allow. Returns ``value``, ``stderr``, ``per_position``, ``slope`` (mean
    dF/dv or dF/d ln v), ``positions``, ``t_factor``, ``model`` and ``target_m_s``."""
    from md.analysis.stats import student_t_factor

    v = np.asarray(speeds_m_s, float).ravel()
    f = np.asarray(forces_by_speed, float)
    if f.ndim != 2 or f.shape[0] != v.size or v.size < 2 or f.shape[1] < 2:
        raise ValueError("need >= 2 speeds and >= 2 positions: forces_by_speed has one row per speed")
    if model not in ("linear", "log"):
        raise ValueError(f"model = {model!r}: 'linear' or 'log'")
    if np.any(v <= 0) or (model == "log" and not target_m_s > 0) or target_m_s < 0:
        raise ValueError(f"speeds must be > 0 and the target >= 0 ('log': > 0); got target {target_m_s}")
    x = v if model == "linear" else np.log(v)
    xt = float(target_m_s) if model == "linear" else math.log(float(target_m_s))
    a = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(a, f, rcond=None)               # one line per position (columns)
    per = coef[0] + coef[1] * xt
    n = per.size
    t = student_t_factor(n)
    return {"value": float(per.mean()), "stderr": float(per.std(ddof=1) / math.sqrt(n) * t),
            "per_position": per.tolist(), "slope": float(coef[1].mean()), "positions": int(n), "t_factor": t,
            "model": model, "target_m_s": float(target_m_s)}


# ------------------------------------------------------------------ surface-element integration (SEI)

def tip_height_map(xy, z, box_xy, bin_A: float, reach_A: float = 0.0) -> dict:
    """The asperity's height map on a lateral grid of ``bin_A`` over the periodic box ``box_xy`` (Lx, Ly): the
    height above the apex (the lowest atom of all) of the surface that faces a flat below a downward tip.

    ``reach_A`` = 0: each bin's lowest atom. A bin finer than the outermost atoms' spacing then sees the
    subsurface atoms between them, and the map has holes that a flat face does not have. ``reach_A`` > 0: each
    bin centre takes the lowest atom within that lateral distance (periodic). With ``reach_A`` at least the
    covering radius of the outermost sites (the largest distance from any point to its nearest site: a / sqrt 3
    on a hexagonal lattice of spacing a) a flat face of the crystal maps to one height at any grid spacing, so the
    flat-slab law applies unchanged to it; the price is that every protrusion is widened by up to ``reach_A``.
    Bins that still see no atom take the height of the nearest bin that does (scipy's distance transform).

    Returns ``heights`` (nbx, nby), ``cell_area`` (area of one bin), ``bins`` (nbx, nby), ``filled`` (the number
    of empty bins filled) and ``apex_z``. Same length units in and out."""
    from scipy.ndimage import distance_transform_edt
    from scipy.spatial import cKDTree

    p = np.asarray(xy, float).reshape(-1, 2)
    zz = np.asarray(z, float).ravel()
    lx, ly = (float(v) for v in box_xy)
    if not (bin_A > 0 and lx > 0 and ly > 0 and reach_A >= 0) or p.shape[0] != zz.size or zz.size == 0:
        raise ValueError("tip_height_map needs atoms (xy, z of equal length), a positive box, bin_A > 0 and "
                         "reach_A >= 0")
    nbx, nby = max(1, int(round(lx / bin_A))), max(1, int(round(ly / bin_A)))
    low = np.full((nbx, nby), np.inf)
    wrapped = np.mod(p, [lx, ly])
    if reach_A > 0:
        cx, cy = np.meshgrid((np.arange(nbx) + 0.5) * lx / nbx, (np.arange(nby) + 0.5) * ly / nby, indexing="ij")
        tree = cKDTree(np.minimum(wrapped, np.nextafter([lx, ly], 0)), boxsize=[lx, ly])
        for k, idx in enumerate(tree.query_ball_point(np.column_stack([cx.ravel(), cy.ravel()]), reach_A)):
            if idx:
                low.flat[k] = zz[idx].min()
    else:
        ix = np.floor(wrapped[:, 0] / lx * nbx).astype(int) % nbx
        iy = np.floor(wrapped[:, 1] / ly * nby).astype(int) % nby
        np.minimum.at(low, (ix, iy), zz)
    empty = ~np.isfinite(low)
    if empty.all():
        raise ValueError("tip_height_map: no bin sees an atom")
    if empty.any():
        _, (jx, jy) = distance_transform_edt(empty, return_indices=True)
        low = low[jx, jy]
    apex = float(zz.min())
    return {"heights": low - apex, "cell_area": lx * ly / (nbx * nby), "bins": (nbx, nby),
            "filled": int(empty.sum()), "apex_z": apex}


def tabulated_traction(separation, traction):
    """The flat-slab traction law sigma(d) (positive = repulsive) as a function: linear between the tabulated
    points (sorted by separation), linear extrapolation of the first interval below the first point (the
    repulsive wall keeps rising), zero beyond the last point (the law is tabulated out to where the slabs no
    longer interact)."""
    d = np.asarray(separation, float).ravel()
    s = np.asarray(traction, float).ravel()
    if d.shape != s.shape or d.size < 2:
        raise ValueError("a traction law needs >= 2 (separation, traction) points of equal length")
    o = np.argsort(d)
    d, s = d[o], s[o]
    slope = (s[1] - s[0]) / (d[1] - d[0])

    def sigma(x):
        x = np.asarray(x, float)
        inside = np.interp(x, d, s)
        return np.where(x < d[0], s[0] + slope * (x - d[0]), np.where(x > d[-1], 0.0, inside))
    return sigma


def surface_element_force(heights, cell_area: float, traction, apex_separation) -> np.ndarray:
    """Surface-element integration (Bhattacharjee & Elimelech, J. Colloid Interface Sci. 193 (1997) 273): the
    force of a rigid asperity on a flat, F(D) = sum over the cells of sigma(D + h_cell) * cell_area, with h_cell
    the cell's height above the apex (:func:`tip_height_map`), D the apex separation and sigma the flat-slab
    traction law (a callable, positive = repulsive). For a paraboloid and a surface law with work w it reduces to
    Derjaguin's 2 pi R Phi(D) and a pull-off of 2 pi R w (DMT); for a flat punch of area A to A sigma(D).
    Vectorised over ``apex_separation`` (any shape; F has that shape)."""
    h = np.asarray(heights, float).ravel()
    D = np.asarray(apex_separation, float)
    hs, counts = np.unique(h, return_counts=True)        # many cells share a height (a flat holder)
    out = np.array([float(np.dot(counts, traction(d + hs))) for d in D.ravel()]) * float(cell_area)
    return out.reshape(D.shape)


def surface_element_pull_off(heights, cell_area: float, traction, d_range, n_grid: int = 400) -> dict:
    """The most tensile force of :func:`surface_element_force` over apex separations in ``d_range`` (lo, hi):
    a grid of ``n_grid`` points, refined by a bounded scalar minimisation around the grid's minimum. Returns
    ``pull_off_force`` (the magnitude of the most tensile force; 0 when F never turns tensile),
    ``apex_separation_at_max`` and ``curve`` (the grid's D and F)."""
    from scipy.optimize import minimize_scalar

    lo, hi = (float(v) for v in d_range)
    if not hi > lo:
        raise ValueError(f"d_range = {d_range}: needs lo < hi")
    D = np.linspace(lo, hi, int(n_grid))
    F = surface_element_force(heights, cell_area, traction, D)
    i = int(np.argmin(F))
    a, b = D[max(i - 1, 0)], D[min(i + 1, D.size - 1)]
    f = lambda d: float(surface_element_force(heights, cell_area, traction, np.array([d]))[0])
    best_d, best_f = float(D[i]), float(F[i])
    if b > a:
        r = minimize_scalar(f, bounds=(a, b), method="bounded", options={"xatol": (hi - lo) * 1e-7})
        if r.fun < best_f:
            best_d, best_f = float(r.x), float(r.fun)
    return {"pull_off_force": max(-best_f, 0.0), "apex_separation_at_max": best_d, "curve": {"D": D, "F": F}}


def tabor_parameter(radius_m: float, work_J_m2: float, e_star_Pa: float, z0_m: float) -> dict:
    """Tabor's parameter mu = (R W^2 / (E*^2 z0^3))^(1/3) (Tabor, J. Colloid Interface Sci. 58 (1977) 2) and
    Maugis' lambda = 2 sigma0 (R / (pi W K^2))^(1/3), K = 4 E*/3, with the LJ 9-3 peak traction
    sigma0 = 1.026 W / z0 (Maugis, J. Colloid Interface Sci. 150 (1992) 243; lambda = 1.157 mu). Small (< 0.1)
    is the DMT limit, pull-off 2 pi R W; large (> 5) JKR, 1.5 pi R W."""
    R, W, E, z0 = (float(v) for v in (radius_m, work_J_m2, e_star_Pa, z0_m))
    if min(R, W, E, z0) <= 0:
        raise ValueError("tabor_parameter needs positive R, W, E* and z0")
    mu = (R * W ** 2 / (E ** 2 * z0 ** 3)) ** (1.0 / 3.0)
    sigma0 = 16.0 / (9.0 * math.sqrt(3.0)) * W / z0
    lam = 2.0 * sigma0 * (R / (math.pi * W * (4.0 * E / 3.0) ** 2)) ** (1.0 / 3.0)
    return {"mu": float(mu), "lambda": float(lam), "sigma0_Pa": float(sigma0)}


#: E* = E / (2 (1 - nu^2)) of silica on silica (Pa): fused silica E = 72 GPa, nu = 0.17 (Bansal & Doremus,
#: Handbook of Glass Properties, Academic Press 1986). A declared choice for Tabor's parameter of the MD pull-off:
#: the MD asperity is IFF beta-cristobalite, whose moduli are not measured here; mu scales as E*^(-2/3), so
#: +-30 % in E* moves mu by about +-20 %, not across the DMT/JKR boundary.
SILICA_E_STAR_PA = 72.0e9 / (2.0 * (1.0 - 0.17 ** 2))
