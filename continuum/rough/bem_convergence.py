"""Pixel convergence of the boundary-element reference (`continuum.rough.bem_reference`): the cohesive-zone
criterion, and whether the pull-off and the energy lost per approach-retraction cycle have converged on a ladder
of grids, with the numbers that say why not.

The cohesive-zone scale. With Dugdale's law (tension sigma0 = 1.03 dgamma/z0 below the gap rho = dgamma/sigma0)
the length over which the interface goes from contact to free is set by the elastic energy of the tension it
carries: l = E* dgamma / sigma0^2 (Maugis, J. Colloid Interface Sci. 150 (1992) 243; for a plane Dugdale-Barenblatt
crack the zone is d = (pi/8) E* G / sigma0^2 with G = dgamma: Rice, in *Fracture* vol. 2, ed. Liebowitz (1968)
191). A boundary-element grid resolves the force law only where d spans several pixels.

What the ladder measures. On a grid, Dugdale's traction is a step at the gap rho: each node that crosses it snaps
(its traction jumps by sigma0 over one pixel's area a^2, an elastic energy of order sigma0^2 a^3 / E*), on approach
and again on retraction, so the loop carries a lattice-trapping term of order A sigma0^2 a / E* (A: the area the
zone sweeps), first order in the pixel a and independent of how many pixels span the zone. Where the continuum
loop is small (Maugis lambda < 1: the summit's loop is a sliver between its jump-in and jump-out) this term can
exceed it at every grid a machine can hold; `convergence` then says so with the numbers: the measured order, the
first-order fit, the pixel the loop would need and what that costs at the measured growth of the solve time.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from nanoimpact.errors import InputError

from .bem_reference import bem_cycle, dugdale_range
from .branch_laws import make_summit_law
from .quasistatic import discrete_cycle, separation_path

__all__ = ["GridRun", "cohesive_zone_length", "dugdale_crack_zone", "convergence", "single_summit_ladder",
           "TOLERANCE"]

#: Convergence criterion on the loss per cycle: the two finest grids within this relative difference.
TOLERANCE = 0.10


def cohesive_zone_length(e_star: float, work_of_adhesion: float, z0: float) -> float:
    """l = E* dgamma / sigma0^2 (m) with sigma0 = 1.03 dgamma/z0 (the issue's and Maugis' scale of the zone)."""
    for key, v in (("e_star", e_star), ("work_of_adhesion", work_of_adhesion), ("z0", z0)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(key, v, "a positive finite number (SI)")
    sigma0, _ = dugdale_range(work_of_adhesion, z0)
    return float(e_star * work_of_adhesion / sigma0**2)


def dugdale_crack_zone(e_star: float, work_of_adhesion: float, z0: float) -> float:
    """Length (m) of the cohesive zone of a plane Dugdale crack, (pi/8) E* dgamma / sigma0^2 (Rice 1968)."""
    return math.pi / 8 * cohesive_zone_length(e_star, work_of_adhesion, z0)


@dataclass(frozen=True)
class GridRun:
    """One reference cycle on one grid."""

    grid: int
    """Points per side."""
    pixel: float
    """Grid spacing (m)."""
    pull_off: float
    """Pull-off force (N)."""
    loss: float
    """Energy lost per approach-retraction cycle (J)."""
    seconds: float
    """Wall time of the cycle (s)."""
    unconverged: int = 0
    """States the solver left above its tolerance."""
    cpu_seconds: float = math.nan
    """CPU time of the cycle (s): the cost that does not move with the machine's load."""


def _order(coarse: float, mid: float, fine: float, ratio: float) -> float:
    """Observed order of convergence from three values at pixels in constant ratio (nan where undefined)."""
    d1, d2 = coarse - mid, mid - fine
    if d1 == 0 or d2 == 0 or (d1 > 0) != (d2 > 0):
        return math.nan
    return math.log(d1 / d2) / math.log(ratio)


def convergence(runs: list[GridRun], zone_length: float, patch_size: float, *, tolerance: float = TOLERANCE) -> dict:
    """The `bem_convergence` record of a ladder of reference cycles (at least two grids, any order).

    converged: the two finest grids' losses per cycle within `tolerance` of the finer. Otherwise `not_converged`
    gives the reason with the numbers: the change between the two finest grids, the order measured on the three
    finest (where three were run), the first-order fit loss = L0 + c a by least squares, the successive first-order
    (Richardson) extrapolations 2 L(a) - L(2a), and the pixel at which c a would fall to `tolerance` of the
    converged loss (taken as the smallest positive extrapolation, the finest loss where none is positive: the
    bound is then optimistic), with the grid and the solve time that pixel needs (CPU time where the runs give it,
    growing as n^q, q measured on the two finest grids)."""
    if len(runs) < 2:
        raise InputError("bem_convergence.grids", len(runs), "at least two grids")
    runs = sorted(runs, key=lambda r: -r.pixel)                 # coarse -> fine
    a = np.array([r.pixel for r in runs])
    loss = np.array([r.loss for r in runs])
    pull = np.array([r.pull_off for r in runs])
    rows = [{"grid": r.grid, "pixel_m": r.pixel, "zone_pixels": zone_length / r.pixel, "pull_off_force_N": r.pull_off,
             "hysteresis_energy_J": r.loss, "seconds": r.seconds, "cpu_seconds": r.cpu_seconds,
             "unconverged_states": r.unconverged} for r in runs]
    rel = lambda f, c: abs(f - c) / abs(f) if f else math.inf   # noqa: E731
    loss_change, pull_change = rel(loss[-1], loss[-2]), rel(pull[-1], pull[-2])
    order = _order(*loss[-3:], a[-2] / a[-1]) if len(runs) >= 3 else math.nan
    slope, intercept = np.polyfit(a, loss, 1)
    rich = [float(2 * loss[k + 1] - loss[k]) if math.isclose(a[k] / a[k + 1], 2.0, rel_tol=1e-9) else math.nan
            for k in range(len(runs) - 1)]
    record = {"tolerance": tolerance, "zone_length_m": zone_length, "zone_pixels_finest": zone_length / a[-1],
              "zone_definition": "E* dgamma / sigma0^2, sigma0 = 1.03 dgamma/z0", "grids": rows,
              "loss_rel_change_last_two": loss_change, "pull_off_rel_change_last_two": pull_change,
              "pull_off_converged": bool(pull_change <= tolerance),
              "loss_observed_order": order, "loss_first_order_fit": {"loss_at_zero_pixel_J": float(intercept),
                                                                     "slope_J_per_m": float(slope)},
              "loss_richardson_J": rich, "converged": bool(loss_change <= tolerance), "not_converged": None}
    if record["converged"]:
        return record
    positive = [r for r in rich if np.isfinite(r) and r > 0]
    target = min(positive) if positive else float(loss[-1])
    need_pixel = tolerance * target / slope if slope > 0 else math.nan
    need_grid = int(math.ceil(patch_size / need_pixel)) if need_pixel > 0 else None
    cost = [r.cpu_seconds if np.isfinite(r.cpu_seconds) else r.seconds for r in runs[-2:]]
    q = math.log(cost[1] / cost[0]) / math.log(runs[-1].grid / runs[-2].grid) if min(cost) > 0 else math.nan
    need_seconds = cost[1] * (need_grid / runs[-1].grid) ** q if need_grid and np.isfinite(q) else math.nan
    record.update(required_pixel_m=need_pixel, required_grid=need_grid, solve_time_exponent=q,
                  required_seconds_estimate=need_seconds)
    spread = (max(positive) / min(positive)) if len(positive) >= 2 else math.nan
    record["not_converged"] = (
        f"the loss per cycle changes by {100 * loss_change:.0f} % between pixels {a[-2] * 1e9:.3g} and "
        f"{a[-1] * 1e9:.3g} nm (tolerance {100 * tolerance:.0f} %) although the cohesive zone E* dgamma/sigma0^2 = "
        f"{zone_length * 1e9:.3g} nm spans {zone_length / a[-1]:.1f} pixels; the loss falls with the pixel at order "
        f"{order:.2f} (first-order fit: {slope:.3g} J per m of pixel, {intercept:.3g} J at zero pixel), the lattice "
        f"trapping of Dugdale's step; the successive first-order extrapolations are "
        f"{', '.join(f'{r:.3g}' for r in rich)} J (spread {spread:.2g}x), so the finest loss {loss[-1]:.3g} J is an "
        f"upper bound. Bringing the trapping term under {100 * tolerance:.0f} % of {target:.3g} J needs a pixel of "
        f"{need_pixel * 1e9:.3g} nm, a {need_grid}^2 grid on this {patch_size * 1e9:.3g} nm patch, ~{need_seconds:.2g} "
        f"CPU s per cycle at the measured n^{q:.2f} growth (the finest took {cost[1]:.3g} CPU s)")
    return record


def single_summit_ladder(radius: float, e_star: float, work_of_adhesion: float, z0: float, grids=(16, 32, 64), *,
                         depth_in_rho: float = 5.0) -> dict:
    """The reference on one paraboloid of tip radius `radius` (m) against the same Dugdale law, on a ladder of
    grids, beside the Maugis-Dugdale summit law's own cycle (the continuum answer for one summit, `branch_laws`):
    the flat goes from 2 rho above the apex to `depth_in_rho` rho below it and back in steps of rho/16, in a
    periodic cell four contact radii wide at that depth. Per grid: pixel, pull-off, loss and the loss over the
    summit law's."""
    _, rho = dugdale_range(work_of_adhesion, z0)
    depth = depth_in_rho * rho
    cell = 4 * math.sqrt(2 * radius * depth)
    law = make_summit_law("maugis_dugdale", radius, work_of_adhesion, e_star, z0=z0, delta_max=10 * depth)
    path = separation_path(2 * rho, -depth, rho / 16)
    exact = discrete_cycle(law, [0.0], path)
    rows = []
    for n in grids:
        x = (np.arange(n) - n // 2) * cell / n
        xx, yy = np.meshgrid(x, x, indexing="ij")
        h = -(xx**2 + yy**2) / (2 * radius)
        cyc, stats = bem_cycle(h, cell, e_star, work_of_adhesion, z0, path + float((h - h.mean()).max()))
        rows.append({"grid": n, "pixel_m": cell / n, "pull_off_force_N": cyc.pull_off_force,
                     "hysteresis_energy_J": cyc.hysteresis_energy,
                     "loss_over_summit_law": cyc.hysteresis_energy / law.loop_energy,
                     "seconds": stats.seconds, "cpu_seconds": stats.notes["cpu_seconds"]})
    return {"radius_m": radius, "cell_m": cell, "depth_m": depth, "summit_law_loss_J": law.loop_energy,
            "summit_law_loss_sampled_J": exact.hysteresis_energy, "summit_law_pull_off_N": exact.pull_off_force,
            "grids": rows}
