"""The confined (compressive) modulus of a self-assembled monolayer from the compression branch of a flat-slab
mean-force curve.

What is measured
    Two flat slabs held at a separation d (backs rigid, the lateral box fixed) and pressed into each other below
    their zero-force separation d0: the layers between the backs are compressed along the normal while they cannot
    expand laterally (periodic box, both faces held). That is uniaxial strain, whose stress-strain slope is the
    confined (oedometric, P-wave) modulus M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) of an isotropic layer, not Young's
    modulus E (Johnson, *Contact Mechanics*, Cambridge 1985, chapter 5, the elastic-foundation model: a thin layer of
    thickness t on a rigid base under a punch much wider than t has the stiffness per area M / t; the same
    proportionality to area / t, independent of the indenter, is the thin-film limit of a compressible layer bonded
    to a rigid substrate, F. Yang, "Asymptotic solution to axisymmetric indentation of a compressible elastic thin
    film"). Measured SAM moduli depend strongly on the method: AFM indentation
    of C18 alkanethiol monolayers gives E ~ 1 GPa (DelRio, Jaye, Fischer & Cook, Appl. Phys. Lett. 94 (2009)
    131909), conducting-AFM with a DMT contact ~50 GPa (Engelkes & Frisbie, J. Phys. Chem. B 110 (2006) 10011);
    MD of alkanethiol SAMs on Au(111) under uniaxial compression computes Young's moduli from stress-strain
    curves (Ramin & Jabbarzadeh, "Effect of pressure on dry and hydrated self assembled monolayers: a molecular
    dynamics simulation study", Appl. Mech. Mater. 553 (2014) 35; its values are not quoted here, unchecked).
    (Patterson & Dlott, J. Phys. Chem. B 109 (2005) 5045, cited here before, is an ultrafast shock-compression
    experiment, not an isothermal simulation: it is not a source
    for this modulus.) A surface-force study of FOTS SAMs finds a viscous response while only the chain ends are
    pressed and a steep elastic rise only above ~0.2 GPa (Devaprakasam & Biswas, "Molecular damping: mechanical
    response of self-assembled monomolecular layer to compression"): the branch stiffens, so the modulus a
    contact at small load sees is the tangent at the zero-force point (:func:`tangent_confined_modulus`), not a
    chord through the whole branch.

How
    sigma_k = F_k / A at the repulsive windows (mean force > 0 on the upper body) below the zero crossing, strain
    eps_k = (d0 - d_k) / t with t the total thickness of the compliant layers between the rigid backs, and
    M = d sigma / d eps = -t d sigma / d d from a weighted straight line through (d_k, sigma_k) (weights 1/e_k^2).
    The slope's stderr comes from the fit's covariance, scaled by the reduced chi^2 where that exceeds one (the
    scatter about the line then says the window stderrs are too small; Bevington & Robinson, *Data Reduction and
    Error Analysis*, 3rd ed., section 6.5). The compliance of everything else between the backs -- the slabs'
    silica, the contact's own interface -- is in series with the layers and counted as theirs, so M is the
    layer stack's effective value (the silica under a 2.4 nm SAM: ~1.3 nm at M ~ 75 GPa adds a few per cent of
    compliance at M ~ 5 GPa).
"""
from __future__ import annotations

import math

import numpy as np

from md import units as _units

__all__ = ["confined_layer_modulus", "sam_layer_thickness_A", "young_from_confined", "tangent_confined_modulus",
           "thickness_at_tilt_A", "stress_ratio_poisson", "plane_strain_from_confined", "poisson_spread",
           "tilt_of_anneal", "small_strain_layer_record"]

#: fewest repulsive windows for a line with a degree of freedom to spare (two fix it exactly)
MIN_WINDOWS_CHECKED = 3


def sam_layer_thickness_A(system_info: dict) -> tuple[float, int]:
    """(total thickness in A, number of layers) of the SAMs between the two slabs of an adhesion run, from the
    run's ``system`` record: every part built by ``ots_sam`` counts with its ``thickness_A`` (the builder's mean
    CH3 height above the anchor-O plane: the chain length and tilt it was built with). No SAM: ValueError."""
    parts = [system_info.get(side) or {} for side in ("lower", "upper")]
    t = [float(p["thickness_A"]) for p in parts if p.get("builder") == "ots_sam" and p.get("thickness_A")]
    if not t:
        raise ValueError("no SAM layer (builder 'ots_sam' with thickness_A) between the slabs")
    return float(sum(t)), len(t)


def young_from_confined(modulus_Pa: float, poisson_ratio: float) -> float:
    """Young's modulus of an isotropic layer whose confined modulus is M: E = M (1 + nu)(1 - 2 nu) / (1 - nu)."""
    nu = float(poisson_ratio)
    if not -1.0 < nu < 0.5:
        raise ValueError(f"poisson_ratio = {poisson_ratio}: must lie in (-1, 0.5)")
    return float(modulus_Pa) * (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu)


def _repulsive_branch(d: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Indices of the compression branch: the windows from the innermost outwards while the force stays
    repulsive (> 0), i.e. below the first zero crossing."""
    first_attractive = np.flatnonzero(f <= 0.0)
    end = int(first_attractive[0]) if first_attractive.size else d.size
    return np.arange(end)


def _sorted_branch(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA, area_A2, thickness_A):
    """(d, f, e sorted by separation, area, thickness, indices of the repulsive branch): the inputs both modulus
    fits check the same way."""
    d = np.asarray(separation_A, float).ravel()
    f = np.asarray(mean_force_kcal_per_molA, float).ravel()
    e = np.asarray(force_stderr_kcal_per_molA, float).ravel()
    if not (d.shape == f.shape == e.shape):
        raise ValueError("separation, mean force and stderr must be 1-D arrays of equal length")
    area, t = float(area_A2), float(thickness_A)
    if not (area > 0 and t > 0):
        raise ValueError(f"area_A2 ({area_A2}) and thickness_A ({thickness_A}) must be positive")
    order = np.argsort(d)
    d, f, e = d[order], f[order], e[order]
    sel = _repulsive_branch(d, f)
    return d, f, e, area, t, sel


def confined_layer_modulus(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA, area_A2: float,
                           thickness_A: float) -> dict:
    """Confined modulus M (Pa) of the layers between two held flat slabs from the compression branch of their
    mean-force curve (module docstring: what it is and its sources).

    ``separation_A`` (any order), ``mean_force_kcal_per_molA`` (on the upper body along +z, repulsion positive),
    ``force_stderr_kcal_per_molA`` per window; ``area_A2`` the interface area; ``thickness_A`` the total
    thickness of the compliant layers (both SAMs of a SAM/SAM contact; :func:`sam_layer_thickness_A`).
    Returns ``modulus_Pa``, ``stderr_Pa``, ``windows`` (used), ``separation_A`` of those, ``strain_max`` (the
    largest compression / t, from the zero-force point d0 of the line), ``zero_force_separation_A`` (d0, where the
    line crosses zero), ``chi2_per_dof`` (nan for two windows) and ``note`` (set when fewer than
    MIN_WINDOWS_CHECKED windows are repulsive: a line through two points has no check of its linearity). Fewer
    than two repulsive windows, or a slope that is not a stiffening (force not rising with compression):
    ValueError."""
    d, f, e, area, t, sel = _sorted_branch(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA,
                                           area_A2, thickness_A)
    if sel.size < 2:
        raise ValueError(f"{sel.size} repulsive window(s) below the zero crossing: a modulus needs at least two "
                         "(add windows pressed into the contact)")
    x, y = d[sel], f[sel]
    w = 1.0 / np.where(e[sel] > 0, e[sel], np.max(e[sel][e[sel] > 0], initial=1.0)) ** 2
    a = np.column_stack([np.ones_like(x), x])
    cov = np.linalg.inv(a.T @ (a * w[:, None]))
    c0, c1 = cov @ (a.T @ (w * y))
    if not c1 < 0:
        raise ValueError(f"the repulsive windows do not stiffen under compression (slope {c1:+.3g} kcal/mol/A^2)")
    dof = sel.size - 2
    chi2 = float(np.sum(w * (y - c0 - c1 * x) ** 2)) / dof if dof else float("nan")
    scale = max(1.0, chi2) if dof else 1.0
    to_pa = lambda k: float(_units.kcal_per_mol_A3_to_Pa(k / area))       # (kcal/mol/A) / A^2 per A
    m = -c1 * t
    d0 = -c0 / c1
    out = {"modulus_Pa": to_pa(m), "stderr_Pa": to_pa(t * math.sqrt(cov[1, 1] * scale)), "windows": int(sel.size),
           "separation_A": x.tolist(), "zero_force_separation_A": float(d0),
           "strain_max": float((d0 - x.min()) / t), "thickness_A": t, "chi2_per_dof": chi2,
           "stress_max_Pa": to_pa(float(y.max())), "note": ""}
    if sel.size < MIN_WINDOWS_CHECKED:
        out["note"] = (f"only {sel.size} repulsive windows: the line through them is exact, its linearity unchecked "
                       "and its stderr from the two windows' stderrs alone")
    return out


def _weighted_polyfit(x, y, w, deg: int):
    """Coefficients (ascending powers) and covariance of a weighted least-squares polynomial, the covariance scaled
    by the reduced chi^2 where that exceeds one (Bevington & Robinson, section 6.5); also chi^2 and its dof."""
    a = np.vander(x, deg + 1, increasing=True)
    cov = np.linalg.inv(a.T @ (a * w[:, None]))
    c = cov @ (a.T @ (w * y))
    dof = x.size - deg - 1
    chi2 = float(np.sum(w * (y - a @ c) ** 2))
    if dof > 0 and chi2 / dof > 1.0:
        cov = cov * (chi2 / dof)
    return c, cov, chi2, dof


def tangent_confined_modulus(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA, area_A2: float,
                             thickness_A: float) -> dict:
    """Small-strain (tangent) confined modulus M0 = -t/A df/dd at the zero-force point d0 of the compression
    branch, from a weighted quadratic through the repulsive windows (the branch stiffens: its chord
    (:func:`confined_layer_modulus`) overstates what a contact at small load sees).

    d0 is the quadratic's root nearest the line's zero-force point (the root on the branch's open end); the stderr
    comes from the quadratic's covariance by the delta method (d0 moves with the coefficients), scaled by the
    reduced chi^2 where that exceeds one. Also returned: the chord (the line's M) for comparison, the tangent at
    the innermost window, ``curvature_delta_chi2`` (chi^2 of the line minus that of the quadratic: > 3.84 is a
    curvature significant at 95 %, one degree of freedom) and ``strain_max`` from d0. Needs four repulsive windows
    (a quadratic with a degree of freedom to spare); fewer, or a branch whose slope at d0 is not a stiffening:
    ValueError."""
    d, f, e, area, t, sel = _sorted_branch(separation_A, mean_force_kcal_per_molA, force_stderr_kcal_per_molA,
                                           area_A2, thickness_A)
    if sel.size < 4:
        raise ValueError(f"{sel.size} repulsive window(s): a tangent from a quadratic needs at least four")
    x, y = d[sel], f[sel]
    w = 1.0 / np.where(e[sel] > 0, e[sel], np.max(e[sel][e[sel] > 0], initial=1.0)) ** 2
    lin, _, chi2_lin, _ = _weighted_polyfit(x, y, w, 1)
    c, cov, chi2_q, dof = _weighted_polyfit(x, y, w, 2)
    d0_line = -lin[0] / lin[1]

    def root_and_slope(cc):
        c0, c1, c2 = cc
        if abs(c2) < 1e-14 * max(abs(c1), 1e-300):
            r = -c0 / c1
        else:
            disc = c1 * c1 - 4.0 * c2 * c0
            if disc < 0:
                raise ValueError("the quadratic through the repulsive windows has no zero-force point")
            roots = (-c1 + np.array([1.0, -1.0]) * math.sqrt(disc)) / (2.0 * c2)
            r = float(roots[np.argmin(np.abs(roots - d0_line))])
        return r, c1 + 2.0 * c2 * r

    d0, slope0 = root_and_slope(c)
    if not slope0 < 0:
        raise ValueError(f"the branch does not stiffen at its zero-force point (slope {slope0:+.3g} kcal/mol/A^2)")
    grad = np.empty(3)
    for k in range(3):                                       # delta method: d slope0 / d c_k (central differences)
        h = 1e-6 * max(abs(c[k]), 1e-6)
        cp, cm = c.copy(), c.copy()
        cp[k] += h
        cm[k] -= h
        grad[k] = (root_and_slope(cp)[1] - root_and_slope(cm)[1]) / (2.0 * h)
    to_pa = lambda k: float(_units.kcal_per_mol_A3_to_Pa(k / area))
    return {"modulus_Pa": to_pa(-slope0 * t), "stderr_Pa": to_pa(t * math.sqrt(float(grad @ cov @ grad))),
            "zero_force_separation_A": float(d0), "chord_modulus_Pa": to_pa(-lin[1] * t),
            "innermost_tangent_Pa": to_pa(-(c[1] + 2.0 * c[2] * x.min()) * t),
            "curvature_delta_chi2": float(chi2_lin - chi2_q), "chi2_per_dof": chi2_q / dof if dof else float("nan"),
            "windows": int(sel.size), "strain_max": float((d0 - x.min()) / t), "thickness_A": t}


def thickness_at_tilt_A(height_of_tilt, tilt_deg: float, tilt_spread_deg: float,
                        layers: int = 1) -> tuple[float, float]:
    """(thickness, its stderr) in A of ``layers`` identical SAMs whose chains tilt ``tilt_deg`` from the normal:
    ``layers`` x ``height_of_tilt(tilt_deg)`` (the builder's CH3 height above the anchor-O plane of an all-trans
    chain at that tilt, md.build.sam.chain_geometry), the stderr from ``tilt_spread_deg`` through the height's
    derivative. Gauche defects, which the tilt alone does not see, would thin the layer further: the value is the
    all-trans upper bound at the measured tilt."""
    th, sp = float(tilt_deg), abs(float(tilt_spread_deg))
    if not 0.0 <= th < 90.0:
        raise ValueError(f"tilt_deg = {tilt_deg}: must lie in [0, 90)")
    h = 0.25
    slope = (height_of_tilt(min(th + h, 89.9)) - height_of_tilt(max(th - h, 0.0))) / (min(th + h, 89.9)
                                                                                   - max(th - h, 0.0))
    return layers * float(height_of_tilt(th)), float(layers * abs(slope) * sp)


def stress_ratio_poisson(separation_A, sigma_lateral_Pa, sigma_normal_Pa, sigma_lateral_stderr_Pa,
                         sigma_normal_stderr_Pa) -> dict:
    """The layer's C13/C33 and Poisson ratio from its own stress tensor in the compression windows.

    Under uniaxial strain along the normal z (the lateral box held), a transversely isotropic layer (axis z)
    answers with sigma_xx = sigma_yy = C13 eps_zz and sigma_zz = C33 eps_zz (Voigt notation; Nye, *Physical
    Properties of Crystals*, Oxford 1957, ch. VIII; Landau & Lifshitz, *Theory of Elasticity*, 3rd ed., section 10),
    so the ratio of the slopes of the lateral and the normal stress against the separation is r = C13/C33,
    independent of the thickness. For an isotropic layer C13 = lambda, C33 = lambda + 2 mu and r = nu / (1 - nu),
    so nu = r / (1 + r) (Landau & Lifshitz, section 5). A transversely isotropic layer has more constants than
    uniaxial strain can fix: then ``poisson_ratio`` is the isotropic layer with the same r, the one the continuum's
    isotropic thin-layer model needs for the measured M.

    ``sigma_lateral_Pa`` is the mean of the layer's xx and yy stresses per window, ``sigma_normal_Pa`` its zz
    stress (both from the per-atom virial summed over the layer's atoms over the layer's volume, the sign the same
    for both; Thompson, Plimpton & Mattson, J. Chem. Phys. 131 (2009) 154107, for the per-atom stress); stderrs
    per window. Weighted lines against the separation; r and nu with their stderrs by the delta method (the two
    slopes' errors taken independent: they come from the same frames, so the stderr is an upper estimate when the
    two stresses move together). Needs three windows; a normal stress that does not rise with compression:
    ValueError."""
    d = np.asarray(separation_A, float).ravel()
    arrays = [np.asarray(a, float).ravel() for a in (sigma_lateral_Pa, sigma_normal_Pa, sigma_lateral_stderr_Pa,
                                                      sigma_normal_stderr_Pa)]
    if any(a.shape != d.shape for a in arrays):
        raise ValueError("separation, stresses and stderrs must be 1-D arrays of equal length")
    if d.size < 3:
        raise ValueError(f"{d.size} window(s): the stress ratio needs at least three")
    sl, sn, el, en = arrays
    slopes = []
    for y, e in ((sl, el), (sn, en)):
        w = 1.0 / np.where(e > 0, e, np.max(e[e > 0], initial=1.0)) ** 2
        c, cov, _, _ = _weighted_polyfit(d, y, w, 1)
        slopes.append((float(c[1]), math.sqrt(float(cov[1, 1]))))
    (b_l, e_l), (b_n, e_n) = slopes
    if abs(b_n) <= 2.0 * e_n:
        raise ValueError(f"the normal stress does not change with compression beyond its error "
                         f"(slope {b_n:.3g} +- {e_n:.2g} Pa/A)")
    r = b_l / b_n
    r_err = abs(r) * math.hypot(e_l / b_l if b_l else float("inf"), e_n / b_n) if b_l else abs(e_l / b_n)
    nu = r / (1.0 + r)
    return {"c13_over_c33": r, "c13_over_c33_stderr": r_err, "poisson_ratio": nu,
            "poisson_ratio_stderr": r_err / (1.0 + r) ** 2, "windows": int(d.size),
            "slope_lateral_Pa_per_A": b_l, "slope_normal_Pa_per_A": b_n}


def plane_strain_from_confined(modulus_Pa: float, poisson_ratio: float) -> float:
    """The plane-strain modulus E' = E / (1 - nu^2) of an isotropic layer whose confined modulus is M:
    E' = M (1 - 2 nu) / (1 - nu)^2 (from M = E (1 - nu) / ((1 + nu)(1 - 2 nu))). At fixed M, nu enters E' this
    way, through both M -> E and E -> E'."""
    nu = float(poisson_ratio)
    if not -1.0 < nu < 0.5:
        raise ValueError(f"poisson_ratio = {poisson_ratio}: must lie in (-1, 0.5)")
    return float(modulus_Pa) * (1.0 - 2.0 * nu) / (1.0 - nu) ** 2


def poisson_spread(nu_low: float, nu_high: float, nu_used: float, n: int = 2001) -> dict:
    """What an unmeasured Poisson ratio, taken uniform on [nu_low, nu_high], does to a layer of measured confined
    modulus M: the relative root-mean-square deviation of E'(nu) = M (1 - 2 nu)/(1 - nu)^2 from E'(nu_used) (bias
    and spread together, so it is the error of using nu_used), and the ratio's range. The Young's modulus
    E(nu_used) entering the set then carries ``relative_stderr`` x E as the part of its stderr that nu holds."""
    lo, hi, nu0 = float(nu_low), float(nu_high), float(nu_used)
    if not (-1.0 < lo <= nu0 <= hi < 0.5):
        raise ValueError(f"need -1 < nu_low <= nu_used <= nu_high < 0.5 (got {nu_low}, {nu_used}, {nu_high})")
    nus = np.linspace(lo, hi, n)
    ratio = (1.0 - 2.0 * nus) / (1.0 - nus) ** 2 / ((1.0 - 2.0 * nu0) / (1.0 - nu0) ** 2)
    return {"relative_stderr": float(np.sqrt(np.mean((ratio - 1.0) ** 2))), "ratio_min": float(ratio.min()),
            "ratio_max": float(ratio.max()), "nu_mean": 0.5 * (lo + hi), "nu_stderr": (hi - lo) / math.sqrt(12.0)}


def tilt_of_anneal(mean_tilt_deg) -> tuple[float, float] | None:
    """(mean, standard deviation) in deg of a SAM anneal's mean-tilt series over its second half (the first half is
    the relaxation, md.workflows.adhesion_protocol.anneal_record); None for fewer than four frames. The standard
    deviation, not the stderr of the mean, is the spread: the tilt the compression windows start from is one draw
    of it."""
    t = np.asarray(mean_tilt_deg, float).ravel()
    t = t[np.isfinite(t)]
    if t.size < 4:
        return None
    half = t[t.size // 2:]
    return float(np.mean(half)), float(np.std(half, ddof=1))


def small_strain_layer_record(separation_A, force_kcal_per_molA, stderr_kcal_per_molA, area_A2: float,
                              system_info: dict, tilt_deg: tuple[float, float] | None, height_of_tilt) -> dict:
    """The SAM stack's small-strain confined modulus as a contact model needs it: the tangent at the zero-force
    point (:func:`tangent_confined_modulus`) normalised by the annealed thickness (:func:`thickness_at_tilt_A` at
    the anneal's mean tilt, ``tilt_deg`` = (mean, spread) or None for the builder's thickness), with the thickness
    spread carried into the stderr. ``height_of_tilt`` is the builder's CH3 height at a tilt (one SAM). Returns
    ``modulus_Pa``, ``stderr_Pa`` (fit and thickness in quadrature), ``thickness_A`` (all layers) and its stderr,
    ``thickness_per_layer_m``, ``layers``, ``thickness_source``, and the tangent record under ``tangent``.
    ValueError where :func:`sam_layer_thickness_A` or the tangent fails."""
    t_built, layers = sam_layer_thickness_A(system_info)
    if tilt_deg is not None:
        t, t_err = thickness_at_tilt_A(height_of_tilt, tilt_deg[0], tilt_deg[1], layers)
        source = (f"annealed: {layers} x the builder's all-trans CH3 height at the anneal's mean tilt "
                  f"{tilt_deg[0]:.1f} +- {tilt_deg[1]:.1f} deg (second half)")
    else:
        t, t_err, source = t_built, 0.0, "the builder's (as-built tilt; no anneal)"
    tg = tangent_confined_modulus(separation_A, force_kcal_per_molA, stderr_kcal_per_molA, area_A2, t)
    m = tg["modulus_Pa"]
    return {"modulus_Pa": m, "stderr_Pa": math.hypot(tg["stderr_Pa"], m * t_err / t), "stderr_fit_Pa": tg["stderr_Pa"],
            "thickness_A": t, "thickness_stderr_A": t_err, "thickness_per_layer_m": t / layers * 1e-10,
            "builder_thickness_A": t_built, "layers": layers, "thickness_source": source, "tangent": tg}
