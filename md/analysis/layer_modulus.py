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
    film"). Molecular simulations of alkanethiol
    monolayers compressed the same way (isothermal uniaxial compression of the SAM lattice) reach ~1 GPa at a
    volume compression of ~0.1, a secant M of order 10 GPa, by chain tilting and gauche defects (Patterson & Dlott,
    J. Phys. Chem. B 109 (2005) 5045); AFM indentation of C18 alkanethiol monolayers gives E ~ 1 GPa (DelRio, Jaye,
    Fischer & Cook, Appl. Phys. Lett. 94 (2009) 131909).

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

__all__ = ["confined_layer_modulus", "sam_layer_thickness_A", "young_from_confined"]

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
