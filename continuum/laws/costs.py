"""What the rough rollers' tables and grids cost, and the bounds that refuse a scene before it runs.

Pure numbers and functions, no law: the estimates (`continuum.model.estimates`) check a scene's tables against
these bounds before anything is built, and the laws (`rough_roller`, `rough_rigid`) check them again at run
time. The costs per surface state are used for the footprint tables' build (`RigidRoughRoller`) and the
grid law's run budget (`RoughRoller`) alike.
"""
from __future__ import annotations

import math

#: Cost of one surface-state evaluation (s), measured on a busy 2-core machine (load 6-9): tabulated JKR or
#: Hertz summits (GWJKRSurface) 2.0 us, generic summit laws (GWBranchSurface: DMT, Maugis-Dugdale, layered)
#: 19 us with its states sorted by depth (shared with the rigid law's table bound).
SECONDS_PER_STATE = {"tabulated": 2.5e-6, "generic": 2.5e-5}
#: Most estimated seconds of surface evaluations one run of the grid law may spend; beyond it
#: the run stops with a one-line SceneError naming the way out. rough_silica as shipped (`standard`, up to
#: 57 bounces over sigma = 3-30 nm) uses 2-93 s of it; Maugis-Dugdale summits on the grid (quadrature,
#: ~10x the cost per state) reach it after ~60 contacts at `standard`.
MAX_RUN_SECONDS = 600.0


def beyond_range(depth_search, sigma: float) -> float:
    """Run `depth_search()` (an `absorbing_depth` call); its range refusal becomes a `SceneError`.

    An adhesive approach pulls the roller deeper than the Hertz estimate that `continuum.model`
    checks before the tables are built, so the averaged model's range (10 sigma below the summits'
    mean plane, `continuum.laws.depth`) can first be crossed at a contact's start: the run then
    stops with the same one-line refusal, naming surfaces.roughness.sigma."""
    from ..scene import SceneError

    try:
        return depth_search()
    except SceneError:
        raise
    except ValueError as exc:
        raise SceneError("surfaces.roughness.sigma", float(sigma), str(exc)) from None


#: Table resolution per fidelity: (points per release stretch in h, points per sigma in h, w-nodes, Gauss nodes).
RESOLUTION = {"fast": (8, 40, 9, 16), "standard": (16, 80, 17, 24), "reference": (32, 160, 33, 40)}
#: Most surface states evaluated at once while the tables are built (bounds the build's temporaries).
_BLOCK_STATES = 200_000
#: Most estimated seconds one build of the tables may take; beyond it the scene is refused.
MAX_BUILD_SECONDS = 30.0


def table_cost_refusal(sigma: float, shape: dict, surface_kind: str, release_stretch: float, depth: float):
    """A SceneError if tables of `shape` (`table_shape`) would take longer than
    MAX_BUILD_SECONDS to build on `surface_kind` summits, else None."""
    from ..scene import SceneError

    seconds = shape["states"] * SECONDS_PER_STATE[surface_kind]
    if seconds <= MAX_BUILD_SECONDS:
        return None
    way = ("physics.adhesion_law = 'jkr' (tabulated summits, ~10x cheaper per state), " if surface_kind == "generic"
           else "")
    return SceneError(
        "surfaces.roughness.sigma", sigma,
        f"the rigid-substrate footprint tables would evaluate {shape['states']:.3g} {surface_kind} surface states "
        f"(~{seconds:.3g} s: {shape['nodes']:.3g} nodes spaced {shape['step']:.3g} m over an impact depth of "
        f"~{depth:.3g} m and a release stretch of {release_stretch:.3g} m), above the {MAX_BUILD_SECONDS:g} s bound; "
        f"use {way}physics.half_space = 'on' (grid law, no footprint table) or surfaces.roughness.mode = 'discrete'")


def table_shape(sigma: float, release_stretch: float, end_gap: float, depth: float,
                resolution: str = "standard") -> dict:
    """Nodes of the (gap, window) tables `RigidRoughRoller._build` makes for a design `depth` (m), and the surface
    states their quadrature evaluates (2 x Gauss nodes per node, for the force and the energy)."""
    per_delta, per_sigma, n_w, n_gauss = RESOLUTION[resolution]
    step = min(sigma / per_sigma, depth / (4 * per_sigma))
    if release_stretch > 0.0:
        step = min(step, release_stretch / per_delta)
    n_h = int(math.floor((end_gap + 2 * step + depth) / step)) + 1
    nodes = n_h * n_w
    return {"gap_nodes": n_h, "window_nodes": n_w, "nodes": nodes,
            "states": 2 * nodes * 2 * n_gauss + n_h * 2 * n_gauss, "step": step,
            # the build holds one block of states (nodes, weights, separations, thresholds and the surface's
            # own temporaries: 75 floats each measured with tracemalloc, 100 taken) and the tables (grids,
            # values, spline coefficients: ~16 floats per node)
            "peak_bytes": 8 * (100 * min(_BLOCK_STATES, nodes * 2 * n_gauss) + 16 * nodes)}
