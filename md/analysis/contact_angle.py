"""The contact angle of a cylindrical droplet: :class:`ContactAngle` (an MDAnalysis ``AnalysisBase``) and
the fits it uses on any density map.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from md import units as _units
from md.analysis.drift import block_drift
from md.analysis.stats import timeseries_stats

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


#: excluded layers (A above the reference plane) of the shape check's circle fits
SHAPE_CHECK_EXCLUDE_A = (3.0, 5.0, 10.0)


def shape_check(density_map, u_edges, z_edges, surface_z: float, angle_stderr_deg: float | None = None,
                exclude_layers=SHAPE_CHECK_EXCLUDE_A, reference: str = "dividing_surface") -> dict:
    """Is the mean droplet a circular cap? The same map read three more ways; a spread beyond the statistics
    means the angle depends on how it is read, not only on the sampling.

    A cylindrical droplet at rest has one curvature (Laplace, no gravity at nm scale), so its liquid-vapour
    contour is a circle and every band of it gives the same angle. Pinned or still-moving contact lines, a
    sheared or elongated mean shape, and the wall-layered foot break that. Checks:

    * ``angles_by_exclude_deg``: circle fits (:func:`fit_contact_angle`) above the reference plane + each of
      ``exclude_layers`` (default 3, 5, 10 A); a circle gives the same angle from each.
    * ``angle_from_height_deg``: the cap of the map's liquid cross-section whose height is the fitted cap
      height (:func:`cap_angle_for_height`) -- area and height only, no contour shape.
    * ``spread_deg``: max - min of those angles; ``circular`` is False when the spread exceeds
      ``max(3 stderr, 2 deg)`` (``angle_stderr_deg`` the blocks' stderr of the angle; 2 deg when not given),
      the resolution a 1 A map gives a 3 nm cap; None when fewer than two readings exist.

    Fits that fail (too few points above a thick excluded layer) are left out and listed in ``failed``.
    """
    angles: dict[str, float] = {}
    failed: dict[str, str] = {}
    height = None
    area = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for ex in exclude_layers:
            try:
                f = fit_contact_angle(density_map, u_edges, z_edges, surface_z, float(ex), reference=reference)
            except ValueError as exc:
                failed[f"{float(ex):g}"] = str(exc)
                continue
            angles[f"{float(ex):g}"] = float(f["angle_deg"])
            if height is None or float(ex) == 5.0:
                height, area = float(f["cap_height_A"]), float(f["area_A2"])
    from_height = cap_angle_for_height(area, height) if area and height and area > 0 and height > 0 else float("nan")
    values = [a for a in angles.values() if np.isfinite(a)] + ([from_height] if np.isfinite(from_height) else [])
    spread = float(np.ptp(values)) if len(values) >= 2 else float("nan")
    tol = max(3.0 * float(angle_stderr_deg), 2.0) if angle_stderr_deg is not None and np.isfinite(angle_stderr_deg) \
        else 2.0
    return {"angles_by_exclude_deg": angles, "angle_from_height_deg": from_height, "spread_deg": spread,
            "tolerance_deg": tol, "circular": bool(spread <= tol) if np.isfinite(spread) else None, "failed": failed,
            "what": "circle fits above the water's plane + each excluded layer, and the cap of the map's area at "
                    "the fitted height; a circular cap gives one angle from all"}


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


def tail_antiderivative(d, r_cut):
    """F(d) = int_d^inf max(r_cut, |u|)^-4 du (A^-3): the laterally integrated r^-6 attraction beyond the cutoff
    of one site at depth d below a uniform half-space (d = z_plane - z_site, A; d < 0: the site is inside it).

    A site at distance u from a slice du of a uniform liquid (n per A^3) interacting by -C6 r^-6 beyond r_c feels,
    integrated over the slice, -(pi/2) C6 n max(r_c, |u|)^-4 du (pairs closer than r_c in 3-D are the dynamics'
    own; within |u| < r_c only the in-slice pairs beyond r_c count, which gives the constant r_c^-4)."""
    d = np.asarray(d, float)
    rc = float(r_cut)
    far = np.abs(d) >= rc
    out = np.where(d >= rc, 1.0 / (3.0 * np.maximum(d, rc) ** 3), 0.0)
    near = ~far
    out = np.where(near, (rc - d) / rc**4 + 1.0 / (3.0 * rc**3), out)
    deep = d <= -rc                                   # the site deep inside the liquid: both sides
    out = np.where(deep, 2.0 / (3.0 * rc**3) + 2.0 / rc**3 - 1.0 / (3.0 * np.maximum(-d, rc) ** 3), out)
    return out


def dispersion_tail_work(site_z_A, c6, z_plane_A, number_density_A3, r_cut_A, area_A2):
    """Work of adhesion per area (kcal/mol/A^2, > 0 = more adhesion) that the r^-6 dispersion beyond the cutoff
    adds between a liquid and the solid sites under it: the liquid a uniform half-space above its dividing
    plane ``z_plane_A`` at the bulk ``number_density_A3`` of the sites it interacts through, the solid its
    explicit sites (heights ``site_z_A``, each with its cross coefficient ``c6`` = 4 eps sigma^6 with a liquid
    site, kcal/mol A^6) in a cell of ``area_A2``:

        dW = (n / A) sum_j (pi/2) C6_j F(z_plane - z_j),  F = :func:`tail_antiderivative`.

    Without a cutoff (F = d^-3/3) a solid half-space of density rho_s at gap D gives pi C6 rho_s n / (12 D^2) =
    A_H / (12 pi D^2) with Hamaker's A_H = pi^2 C6 rho_s n (Israelachvili, Intermolecular and Surface Forces,
    3rd ed., ch. 13). The r^-12 part beyond the cutoff ((sigma/r_c)^6 ~ 1e-3 of it) is left out. A static
    (first-order) correction: the structures are those of the truncated run, the liquid uniform above its
    dividing plane (the same half-space construction as Blokhuis et al.'s tail of gamma_lv)."""
    z = np.asarray(site_z_A, float)
    c = np.broadcast_to(np.asarray(c6, float), z.shape)
    return float(number_density_A3) / float(area_A2) * float(np.sum(0.5 * np.pi * c * tail_antiderivative(
        float(z_plane_A) - z, r_cut_A)))


def cutoff_crossing_work(site_z_A, c6, z_plane_A, number_density_A3, r_cut_A, area_A2):
    """Work of adhesion per area (kcal/mol/A^2, > 0 = more adhesion) that a truncated r^-6 attraction misses
    inside its cutoff. Plain `lj/cut` puts no impulse at r_c, so a run's forces are those of the shifted potential
    u(r) - u(r_c): each liquid-site pair closer than r_c misses the constant u(r_c) ~ -C6 / r_c^6 (its r^-12 part,
    (sigma/r_c)^6 ~ 1e-3 of it, left out). With the liquid a uniform half-space above ``z_plane_A`` (as in
    :func:`dispersion_tail_work`), a site at depth d = z_plane - z has within r_c the liquid volume of a spherical
    cap, V(d) = pi (r_c - d)^2 (2 r_c + d) / 3 for |d| < r_c (0 for d >= r_c, 4/3 pi r_c^3 for d <= -r_c), so

        dW = (n / A) sum_j C6_j V(d_j) / r_c^6.

    Beside the beyond-cutoff tail it turns the shifted-potential W_SL into the full potential's; for two
    half-spaces in contact it is half that tail (pi C n^2 / (4 r_c^2) against pi C n^2 / (2 r_c^2)); the same
    bookkeeping as the adhesion workflow's force route."""
    z = np.asarray(site_z_A, float)
    c = np.broadcast_to(np.asarray(c6, float), z.shape)
    rc = float(r_cut_A)
    d = np.clip(float(z_plane_A) - z, -rc, rc)
    volume = np.pi * (rc - d) ** 2 * (2.0 * rc + d) / 3.0
    return float(number_density_A3) / float(area_A2) * float(np.sum(c * volume)) / rc**6


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
            The most contiguous blocks of frames whose maps are fitted separately for the error and the drift
            check. Fewer are used when the droplet's shape decorrelates fewer times: the blocks are sized from
            the statistical inefficiency g of a per-frame shape observable (the water's mean height above
            ``z_min``), so that each spans about 2 g frames (``n_blocks_used`` = clamp(N_eff / 2, 3, n_blocks),
            N_eff = frames / g). Blocks shorter than the correlation would be correlated, and their scatter
            would understate the error.
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
        -- see ``wetting``), ``stderr_deg`` (std of the block angles / sqrt(n_blocks_used)), ``n_blocks_used``,
        ``shape_series_A`` (the per-frame mean height), ``shape_statistical_inefficiency`` (its g, in frames),
        ``blocks_independent`` (each block spans at least 2 g frames), ``block_angles_deg``,
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
            self._frames_rho: list[np.ndarray] = []
            self._shape: list[float] = []

        def _setup_grid(self, dims):
            lu = float(dims[self._iu])
            nu = max(1, int(round(lu / self.bin_size)))
            zmax = float(dims[2]) if self.z_max is None else float(self.z_max)
            nz = max(1, int(math.ceil((zmax - self.z_min) / self.bin_size)))
            self._u_edges = np.linspace(-lu / 2, lu / 2, nu + 1)
            self._z_edges = self.z_min + self.bin_size * np.arange(nz + 1)
            self._edges = (self._u_edges, self._z_edges)
            self._sum = np.zeros((nu, nz))

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
                _units.amu_per_A3_to_kg_per_m3(number_density * _units.WATER_MOLAR_MASS))
            self._sum += rho
            self._frames_rho.append(rho.astype(np.float32))
            z = pos[:, 2].astype(float)
            z = z[(z >= self.z_min) & (z < self._z_edges[-1])]
            self._shape.append(float(z.mean()) - self.z_min if z.size else float("nan"))

        def _fit(self, rho):
            return fit_contact_angle(rho, self._u_edges, self._z_edges, self.surface_z, self.exclude_layer,
                                     reference=self.reference)

        def _conclude(self):
            if self._edges is None:
                raise ValueError("no frames analysed")
            nf = len(self._frames_rho)
            rho = self._sum / nf
            shape = np.asarray(self._shape, float)
            g_shape = timeseries_stats(shape[np.isfinite(shape)], equilibrate=False)["g"] \
                if np.isfinite(shape).sum() >= 2 else 1.0
            nb = int(min(self.n_blocks, max(3, (nf / g_shape) // 2), nf))
            nb = max(1, nb)
            bounds = np.linspace(0, nf, nb + 1).round().astype(int)
            block_rho = [np.mean(self._frames_rho[a:b], axis=0) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
            block_frames = [0.5 * (a + b - 1) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
            fit, fit_error = None, None
            try:
                fit = self._fit(rho)
            except ValueError as exc:               # too flat to fit: see wetting
                fit_error = str(exc)
            block_angles = []
            for brho in block_rho:
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", RuntimeWarning)
                        fb = self._fit(brho)
                    block_angles.append(fb["angle_deg"])
                except ValueError:
                    block_angles.append(float("nan"))
            ba = np.array(block_angles, float)
            bf = np.array(block_frames, float)
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
            r.n_blocks_used = len(block_rho)
            r.shape_series_A = shape
            r.shape_statistical_inefficiency = float(g_shape)
            r.blocks_independent = bool(nf / max(len(block_rho), 1) >= 2.0 * g_shape)
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
