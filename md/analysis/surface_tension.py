"""Liquid-vapour surface tension of a film (Kirkwood & Buff) with its LJ tail correction, and density
profiles.
"""
from __future__ import annotations

import math

import numpy as np

from md import units as _units
from md.analysis.common import ATM_A_TO_N_PER_M, KCALMOL_PER_A2_TO_J_PER_M2
from md.analysis.stats import block_average, timeseries_stats

# ------------------------------------------------------------------------------------ surface tension

def surface_tension(pxx_atm, pyy_atm, pzz_atm, lz_A, tail_correction_N_per_m: float = 0.0,
                    n_blocks: int | None = None) -> dict:
    """Liquid-vapour surface tension of a slab with two interfaces normal to z (Kirkwood-Buff 1949).

    gamma = (Lz / 2) (<Pzz> - (<Pxx> + <Pyy>) / 2), pressures in atm (LAMMPS real), ``lz_A`` in A (a
    number or a series like the pressures).  The mean of the instantaneous gamma(t) and its stderr come from
    :func:`timeseries_stats` (automated equilibration detection and the statistical inefficiency, Chodera
    2016, checked by blocking: the pressure tensor's autocorrelation oscillates, and there the blocking estimate
    is the larger one), so correlations between the components enter the error; ``n_blocks`` (optional) adds the old
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
           "units": "N/m", "statistical_inefficiency": st["g"], "t0": st["t0"], "n_eff": st["n_eff"],
           "error_method": st["error_method"]}
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
