"""Before a rough impact runs: how deep it presses, how many summits it touches, how far the
half-space under it deflects. `continuum.model` uses these numbers to decide which models a
scene needs (`auto`), and records them.

The estimate is the quasi-static first approach of the roller onto non-adhesive (Hertz) summits
on a rigid substrate, pressed until it has absorbed the impact's kinetic energy against its
weight (the same estimate that sizes the tables and grids, `continuum.laws.depth`). From the
pressure profile at that depth, the plane-strain half-space (FFT influence coefficients,
`continuum.elastic.halfspace.LineHalfSpace`, referenced at x_ref = l) gives the deflection across the
footprint; its span (largest minus smallest over the loaded cells) is what changes the summits'
gaps relative to the rigid geometry. Cost: ~10-50 ms.

Bounded cost (`check_table_cost`): before any table is built, the memory the averaged model's
GW tables would take is estimated from the scene (the window table grows like (delta_c/sigma)^2,
`continuum.rough.gw_layout.table_size`) and so is the time of the rigid-substrate footprint tables (nodes
over the range of gaps, `continuum.laws.costs.table_shape`, times a measured cost per surface state).
A scene beyond `MEMORY_BOUND_BYTES` or `continuum.laws.costs.MAX_BUILD_SECONDS` is refused
with a one-line `SceneError` naming the key, the value, the estimate and the way out (discrete
summits, a larger sigma, tabulated JKR summits, the half-space grid law). docs/model.md, "Bounded
cost".
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass

import numpy as np

from ..elastic.halfspace import LineHalfSpace

#: Most memory (bytes) the averaged rough model's tables may take while they are built.
MEMORY_BOUND_BYTES = 2 * 2**30
#: Build time of the GW window table per node (s), measured on a busy 2-core machine (load ~10):
#: 20-23 us at 9e4-6e5 nodes, the band table's build included (docs/rough-gw.md).
GW_SECONDS_PER_NODE = 2.5e-5


@dataclass(frozen=True)
class RoughImpactEstimate:
    """Quasi-static estimate of one rough impact (SI)."""

    impact_energy: float
    """Kinetic energy at touch, 1/2 M v^2 (J)."""
    depth: float
    """Approach below the tallest summit at which the Hertz approach branch absorbs it (m)."""
    contacts: float
    """Summits in contact at that depth."""
    peak_force: float
    """Force at that depth (N)."""
    footprint_half_width: float
    """Half-width of the loaded strip (m)."""
    deflection_span: float
    """Largest minus smallest half-space deflection over the loaded strip (m)."""
    seconds: float
    """Wall time of the estimate (s), its surface's tables included."""

    def to_json(self) -> dict:
        return asdict(self)


def rough_impact_estimate(surface, law, e_star: float, radius: float, length: float, mass: float, speed: float,
                          gravity: float, samples: int = 513) -> RoughImpactEstimate:
    """Estimate a rough roller impact (see the module docstring).

    surface: the non-adhesive summits' averaged surface (`continuum.model.factory.averaged_surface`, Hertz summits,
    'fast' tables) and law: the rigid-substrate roller on it (`factory.rigid_roller`), both built by the caller
    (`continuum.model.regime.impact_estimate`); e_star (Pa): the bodies' contact modulus (the half-space's);
    radius, length (m) of the roller; mass (kg), speed (m/s) at touch, gravity (m/s^2).
    """
    start = time.perf_counter()
    energy = 0.5 * mass * speed * speed
    depth = law.quasi_static_depth(energy, mass * gravity)
    half = math.sqrt(2.0 * radius * depth)
    x = np.linspace(-half, half, samples)
    d = surface.z_max - depth + x * x / (2.0 * radius)
    zeta = np.full_like(d, np.inf)
    p = surface.pressure(d, zeta)
    force = float(length * np.trapezoid(p, x))
    contacts = float(length * np.trapezoid(surface.contacts(d, zeta), x))
    dx = x[1] - x[0]
    hs = LineHalfSpace(dx, samples, e_star, x_ref=length)
    u = hs.displacement(p)
    loaded = p > 0.0
    span = float(np.max(u[loaded]) - np.min(u[loaded])) if np.count_nonzero(loaded) > 1 else 0.0
    return RoughImpactEstimate(energy, depth, contacts, force, half, span, time.perf_counter() - start)


def check_table_cost(*, stats, work_of_adhesion: float, summit_e_star: float, z_max_sigma: float,
                     detachment: str, resolution: str, gw_tables: bool, rigid: bool, rigid_resolution: str,
                     release_stretch: float, end_gap: float, depth_estimate: float | None, sigma_key_value: float,
                     origin: str = "") -> dict:
    """Refuse a rough scene whose tables would outgrow the bounds, before anything is built.

    gw_tables: the JKR summits' GW tables will be built (`GWJKRSurface` with adhesion); rigid: the
    rigid-substrate footprint tables will be (`RigidRoughRoller`), for a first design depth of at
    least 1.5 x `depth_estimate` (the Hertz summits' quasi-static depth; adhesion only pulls deeper,
    which coarsens those tables' spacing). Returns the estimates (recorded in the result).
    Raises `continuum.scene.SceneError` (key surfaces.roughness.sigma) with a one-line reason.
    """
    from ..laws.costs import MAX_BUILD_SECONDS, SECONDS_PER_STATE, table_cost_refusal, table_shape
    from ..rough.gw_layout import table_size
    from ..scene import SceneError

    sigma = stats.sigma
    rec: dict = {"memory_bound_bytes": MEMORY_BOUND_BYTES}
    if gw_tables and work_of_adhesion > 0.0:
        size = table_size(stats, work_of_adhesion, summit_e_star, z_max=z_max_sigma, detachment=detachment,
                          resolution=resolution)
        seconds = size["nodes"] * GW_SECONDS_PER_NODE
        rec["gw_table"] = {"nodes": size["nodes"], "shape": list(size["shape"]), "peak_bytes": size["peak_bytes"],
                           "estimated_seconds": seconds, "resolution": resolution,
                           "sigma_over_delta_c": 1.0 / size["lambda"]}
        over = max(size["peak_bytes"] / MEMORY_BOUND_BYTES, seconds / MAX_BUILD_SECONDS)
        if over > 1.0:
            lam = size["lambda"]
            # the table grows like lambda^2: the sigma that would fit, by that scaling (an estimate)
            fit = sigma * math.sqrt(over)
            raise SceneError(
                "surfaces.roughness.sigma", sigma_key_value,
                f"sigma/delta_c = {1.0 / lam:.3g} (delta_c = {lam * sigma:.3g} m from the summits' radius, work of "
                f"adhesion and modulus): the averaged model's GW tables would take ~{size['peak_bytes'] / 2**30:.3g} "
                f"GiB and ~{seconds:.3g} s to build ({size['nodes']:.3g} nodes at '{resolution}'), above the "
                f"{MEMORY_BOUND_BYTES / 2**30:g} GiB / {MAX_BUILD_SECONDS:g} s bounds; use surfaces.roughness.mode = "
                f"'discrete' (individual summits, no tables) or sigma >= ~{fit:.2g} m (or stiffer summits, less "
                "adhesion)", origin)
    if rigid and depth_estimate is not None and depth_estimate > 0.0:
        # the first design depth is at least 1.5 x the Hertz estimate (adhesion only pulls deeper); the
        # tables are checked again against the same bound with the real design depth before each build
        depth = 1.5 * depth_estimate
        shape = table_shape(sigma, release_stretch, end_gap, depth, rigid_resolution)
        kind = "tabulated" if gw_tables else "generic"
        rec["rigid_table"] = {"nodes": shape["nodes"], "states": shape["states"], "design_depth_at_least": depth,
                              "resolution": rigid_resolution, "surface": kind,
                              "estimated_seconds": shape["states"] * SECONDS_PER_STATE[kind],
                              "max_build_seconds": MAX_BUILD_SECONDS}
        refusal = table_cost_refusal(sigma_key_value, shape, kind, release_stretch, depth)
        if refusal is not None:
            raise refusal
    return rec
