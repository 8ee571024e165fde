"""Thermodynamic integration of the solid-liquid work of adhesion W_SL (no contact line, no droplet).

Why
    A droplet cannot resolve small angles: on IFF (111) silica the contact line of a short-run droplet can stay
    where it was started (docs/md.md shows two starts keeping their angles), so its angle measures the start, not
    the surface. W_SL = gamma_sv + gamma_lv - gamma_sl needs no contact line: it is the reversible work that takes a
    liquid film off the solid per unit area (Leroy & Mueller-Plathe, Langmuir 31 (2015) 8335, the dry-surface
    method; Leroy, dos Santos & Mueller-Plathe, Macromol. Rapid Commun. 30 (2009) 864, the phantom wall).

The path (a decoupling; :class:`md.workflows.wsl_ti.WslTI`)
    State 1: a water film on the solid, its top a free liquid-vapour surface. State 0: the same film not
    interacting with the solid at all -- a free-standing film (two liquid-vapour surfaces) and a bare solid. Per
    unit area F0 - F1 = gamma_sv + 2 gamma_lv - (gamma_sl + gamma_lv) = W_SL, exactly; nothing about the end
    state needs estimating (the dry-surface method's W of its "dry" end state is zero here). Two stages:

    * charges: the solid's partial charges scaled by lambda_q from 1 to 0 (PPPM stays exact; the water keeps
      its charges). This also switches off the solid's charges among themselves, so the same stage is run on
      the solid alone (the *reference*, vacuum above) and subtracted: what is left is the solid-water part;
    * dispersion: the solid-water Lennard-Jones pairs switched off by a soft core (Beutler, Mark, van Schaik,
      Gerber & van Gunsteren, Chem. Phys. Lett. 222 (1994) 529: LAMMPS ``lj/cut/coul/long/soft``, n = 1,
      alpha = 0.5), so nothing diverges as the film and the solid start to overlap.

    W_SL A = I_q(reference) - I_q(film) - I_lj(film), with I = int_0^1 <dU/dlambda>_lambda dlambda.

    Each integral is a Gauss-Legendre sum over its nodes (no window at lambda = 0 or 1); <dU/dlambda> at a node
    is the central difference of LAMMPS ``compute fep`` energies at lambda +- delta, its stderr from the
    statistical inefficiency (:func:`md.analysis.timeseries_stats`). The discretisation error is the
    difference between the Gauss-Legendre sum and the monotone-cubic (PCHIP) integral through the same nodes,
    linearly extrapolated to 0 and 1 -- for the charge stage, of the film-minus-reference integrand.

The film's centre of mass is held by a spring along z (decoupled, it would drift); the spring's energy at full
coupling is added back (:func:`tether_correction`), an O(kT) translational term is not.

Then the angle: Young-Dupre, cos theta = W_SL / gamma_lv - 1; W_SL >= 2 gamma_lv (spreading coefficient S =
W_SL - 2 gamma_lv >= 0) means the water wets: theta = 0, reported as "wets" with S.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from scipy.interpolate import PchipInterpolator

from md.analysis.common import KCALMOL_PER_A2_TO_J_PER_M2

__all__ = ["gauss_legendre_unit", "ti_integral", "ti_work_of_adhesion_sl", "angle_from_work_of_adhesion_sl",
           "tether_correction", "film_lower_dividing_plane"]


def gauss_legendre_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1], nodes descending (1 -> 0: the order a decoupling runs them).
    Exact for polynomials of degree <= 2n - 1; the weights sum to 1."""
    if int(n) < 1:
        raise ValueError(f"n = {n}: need at least one Gauss-Legendre node")
    x, w = np.polynomial.legendre.leggauss(int(n))
    order = np.argsort(-x)
    return 0.5 * (x[order] + 1.0), 0.5 * w[order]


def ti_integral(nodes: Sequence[float], means: Sequence[float], stderrs: Sequence[float]) -> dict:
    """int_0^1 <dU/dlambda> dlambda from Gauss-Legendre nodes (in units of ``means``).

    ``nodes`` must be the n-point Gauss-Legendre nodes on [0, 1] (any order; :func:`gauss_legendre_unit`).
    Returns value, stderr (independent nodes: sqrt(sum w^2 se^2)), value_pchip (PCHIP through the nodes with
    linear ends) and discretisation_error = |value - value_pchip|."""
    lam = np.asarray(nodes, float)
    f = np.asarray(means, float)
    se = np.asarray(stderrs, float)
    if not (lam.shape == f.shape == se.shape) or lam.ndim != 1:
        raise ValueError("nodes, means and stderrs must be 1-D and of one length")
    x, w = gauss_legendre_unit(len(lam))
    order = np.argsort(-lam)
    lam, f, se = lam[order], f[order], se[order]
    if not np.allclose(lam, x, atol=1e-9):
        raise ValueError(f"nodes {lam.tolist()} are not the {len(lam)}-point Gauss-Legendre nodes on [0, 1]")
    value = float(np.dot(w, f))
    stderr = float(math.sqrt(np.dot(w**2, np.nan_to_num(se, nan=0.0)**2)))
    if len(lam) >= 2:
        asc = np.argsort(lam)
        xs, ys = lam[asc], f[asc]
        grid = np.concatenate([[0.0], xs, [1.0]])
        lo = ys[0] + (ys[1] - ys[0]) / (xs[1] - xs[0]) * (0.0 - xs[0])
        hi = ys[-1] + (ys[-1] - ys[-2]) / (xs[-1] - xs[-2]) * (1.0 - xs[-1])
        vals = np.concatenate([[lo], ys, [hi]])
        pchip = float(PchipInterpolator(grid, vals).integrate(0.0, 1.0))
    else:
        pchip = float("nan")
    return {"value": value, "stderr": stderr, "value_pchip": pchip,
            "discretisation_error": abs(value - pchip) if np.isfinite(pchip) else float("nan"),
            "nodes": lam.tolist(), "weights": w.tolist(), "means": f.tolist(), "stderrs": se.tolist()}


def ti_work_of_adhesion_sl(charge_film: dict, lj_film: dict, charge_reference: dict, area_A2: float) -> dict:
    """W_SL (J/m^2) from the three :func:`ti_integral` results (kcal/mol) over an interface of ``area_A2``.

    W_SL A = I_q(reference) - I_q(film) - I_lj(film) (module docstring). Stderrs add in quadrature; the
    discretisation errors add linearly (they are systematic). The charge stage's is estimated on the integrand
    that is integrated, film minus reference at the shared nodes: each alone is dominated by the held atoms'
    solid-solid term, exactly quadratic in lambda (so Gauss-Legendre integrates it exactly) but not for the PCHIP
    the estimate compares with, which would report a spurious error, far larger than the difference's, that
    cancels in the difference. Also returned: each stage's share in J/m^2."""
    conv = KCALMOL_PER_A2_TO_J_PER_M2 / float(area_A2)
    electro = charge_reference["value"] - charge_film["value"]
    disp = -lj_film["value"]
    err = math.sqrt(charge_reference["stderr"]**2 + charge_film["stderr"]**2 + lj_film["stderr"]**2)
    if "means" in charge_film and "means" in charge_reference and \
            np.allclose(charge_film["nodes"], charge_reference["nodes"]):
        diff = ti_integral(charge_film["nodes"], np.subtract(charge_film["means"], charge_reference["means"]),
                           np.hypot(charge_film["stderrs"], charge_reference["stderrs"]))
        charge_disc = diff["discretisation_error"]
    else:
        charge_disc = sum(abs(d["discretisation_error"]) for d in (charge_reference, charge_film))
    disc = sum(abs(x) for x in (charge_disc, lj_film["discretisation_error"]) if np.isfinite(x))
    return {"value": (electro + disp) * conv, "stderr": err * conv, "discretisation_error": disc * conv,
            "electrostatic": electro * conv, "dispersion": disp * conv,
            "electrostatic_stderr": math.hypot(charge_reference["stderr"], charge_film["stderr"]) * conv,
            "dispersion_stderr": lj_film["stderr"] * conv, "units": "J/m^2"}


def tether_correction(z_coupled_A, z0_A: float, k_kcal_mol_A2: float, area_A2: float) -> dict:
    """What a centre-of-mass spring on the film adds to W_SL A (kcal/mol) and W_SL (J/m^2).

    The spring S = k/2 (z - z0)^2 is on at every lambda, so the integral measures F(decoupled) - F(coupled) of the
    system *with* it. Bound, the film's centre of mass sits in the interface's well, far stiffer than k, so the
    spring adds its energy there, S(z_b) = <S>_coupled to first order; decoupled, it only confines a free film,
    kT ln(sqrt(2 pi kT / k) / L): an O(kT) translational term that has no per-area limit and is left out. Hence
    W_SL A = I + <S>_coupled, with ``z_coupled_A`` the film's centre-of-mass heights at full coupling."""
    z = np.asarray(z_coupled_A, float)
    s = 0.5 * float(k_kcal_mol_A2) * (z - float(z0_A)) ** 2
    e = float(np.mean(s)) if s.size else 0.0
    return {"energy_kcal_mol": e, "value": e * KCALMOL_PER_A2_TO_J_PER_M2 / float(area_A2),
            "offset_A": float(np.mean(z) - float(z0_A)) if z.size else float("nan"), "units": "J/m^2"}


def angle_from_work_of_adhesion_sl(w: float, w_stderr: float, gamma_lv: float) -> dict:
    """Young-Dupre inverted: theta = arccos(W_SL / gamma_lv - 1) (deg) with its first-order stderr.

    W_SL >= 2 gamma_lv: status 'wets' (theta = 0; spreading coefficient S = W_SL - 2 gamma_lv >= 0 reported);
    W_SL <= 0: 'dewets' (theta = 180). The stderr is None where the derivative is singular (theta = 0 or 180);
    ``theta_upper_deg`` bounds theta from above at one stderr below W (useful when W is within an error of 2
    gamma)."""
    w, g = float(w), float(gamma_lv)
    se = 0.0 if w_stderr is None or not np.isfinite(w_stderr) else float(w_stderr)
    spreading = w - 2.0 * g
    c = w / g - 1.0
    upper_c = (w - se) / g - 1.0
    upper = math.degrees(math.acos(min(1.0, max(-1.0, upper_c))))
    if c >= 1.0:
        return {"status": "wets", "theta_deg": 0.0, "stderr_deg": None, "spreading_coefficient": spreading,
                "theta_upper_deg": upper, "cos_theta": 1.0}
    if c <= -1.0:
        return {"status": "dewets", "theta_deg": 180.0, "stderr_deg": None, "spreading_coefficient": spreading,
                "theta_upper_deg": 180.0, "cos_theta": -1.0}
    th = math.acos(c)
    return {"status": "measured", "theta_deg": math.degrees(th), "stderr_deg": math.degrees(se / (g * math.sin(th))),
            "spreading_coefficient": spreading, "theta_upper_deg": upper, "cos_theta": c}


def film_lower_dividing_plane(z_A, area_A2: float, n_frames: int, bin_A: float = 0.5) -> dict:
    """The lower dividing plane of a liquid film from its molecules' heights (one site per molecule, all frames
    together): the height where the number density first rises through half its bulk value, linearly
    interpolated between bins. The bulk is the mean over the bins within the middle half of the film's extent
    (first and last bins above half the maximum), clear of both interfaces' layering.

    Returns ``z_A`` (the plane), ``number_density_A3`` (bulk, molecules per A^3), ``film_thickness_A`` (between
    the two half-bulk crossings). Used for the static water-TraPPE dispersion tail of W_SL on OTS
    (:func:`md.analysis.dispersion_tail_work`, which takes the liquid uniform above this plane)."""
    z = np.asarray(z_A, float).ravel()
    if z.size == 0 or n_frames < 1:
        raise ValueError("film_lower_dividing_plane: no heights")
    edges = np.arange(z.min() - bin_A, z.max() + 2 * bin_A, bin_A)
    counts, edges = np.histogram(z, edges)
    rho = counts / (float(area_A2) * bin_A * int(n_frames))
    zc = 0.5 * (edges[1:] + edges[:-1])
    above = np.flatnonzero(rho >= 0.5 * rho.max())
    lo, hi = zc[above[0]], zc[above[-1]]
    core = (zc >= lo + 0.25 * (hi - lo)) & (zc <= hi - 0.25 * (hi - lo))
    bulk = float(rho[core].mean())
    half = 0.5 * bulk
    up = np.flatnonzero(rho >= half)
    k = int(up[0])
    z_low = float(zc[k] if k == 0 else np.interp(half, [rho[k - 1], rho[k]], [zc[k - 1], zc[k]]))
    j = int(up[-1])
    z_high = float(zc[j] if j == len(rho) - 1 else np.interp(half, [rho[j + 1], rho[j]], [zc[j + 1], zc[j]]))
    return {"z_A": z_low, "number_density_A3": bulk, "film_thickness_A": z_high - z_low}
