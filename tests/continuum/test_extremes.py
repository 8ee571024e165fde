"""Bounded cost at the extremes of the rough model (docs/model.md, "Bounded cost").

On rough_silica with adhesion_law and half_space on `auto`, sigma 0.1 nm - 100 nm, summit E* 1 MPa - 1 TPa,
work of adhesion 0 - 1 J/m^2 and release 1 nm - 10 um, every point is declared: it runs (finite numbers, an
energy audit within its tolerance at the `fast` preset) or it is refused with a one-line SceneError naming the
key, the value and the way out, before any table that would break the bounds is built. Every refusal here is
for the model's range (the impact would press the roller more than 10 sigma below the summits' mean plane).

Memory: checked with the code's own estimates, recorded for every table actually built (`table_size` for the
GW window table, `RigidRoughRoller.table_shape` for the footprint tables), which must stay within
MEMORY_BOUND_BYTES; `test_table_size_bounds_the_measured_build` checks the estimate against tracemalloc's peak.

The grid is the corners (sigma, E*, work, release at both ends of their ranges), points that once needed
tables of terabytes or minutes to build, and the paper's regime; the larger hand-run grid is summarised in
docs/model.md ("Bounded cost").
"""
import math
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from continuum.dynamics.impact import run_impact
from continuum.laws import rough_rigid
from continuum.model import estimates
from continuum.reference import jkr
from continuum.rough.gw import GWJKRSurface
from continuum.rough.gw_layout import table_size
from continuum.rough.summits import SummitStatistics, expected_max_height
from continuum.scene import SceneError, resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "inputs" / "scenes" / "rough_silica.toml"
RANGE = "more than 10 sigma below the summits' mean plane"

CORNERS = [(s, e, w, r) for s in (0.1e-9, 100e-9) for e in (1e6, 1e12) for w in (0.0, 1.0) for r in (1e-9, 10e-6)]
HARD = [
    (0.1e-9, 10e9, 0.01, 1e-9),     # Maugis-Dugdale footprint tables on 0.1 nm roughness
    (0.3e-9, 1e8, 1.0, 1e-6),       # soft, strongly adhesive summits: a GW window table of minutes
    (0.3e-9, 10e9, 0.01, 1e-9),     # Maugis-Dugdale footprint tables
    (10e-9, 10e9, 0.1, 100e-9),     # the paper's regime under auto (Maugis-Dugdale)
]
POINTS = CORNERS + HARD
#: (sigma, E*, work, release) of the points refused for the model's range; every other point must run.
REFUSED = {(0.1e-9, 1e6, 0.0, 10e-6), (0.1e-9, 1e6, 1.0, 1e-9), (0.1e-9, 1e6, 1.0, 10e-6),
           (100e-9, 1e6, 1.0, 1e-9), (100e-9, 1e6, 1.0, 10e-6), (0.3e-9, 1e8, 1.0, 1e-6)}


def audit_tolerance(work):
    """Largest energy-audit error over the turnover at the `fast` preset: Hertz summits hold 2e-5; adhesive
    summits (Maugis-Dugdale tables under auto) 5e-4, their tables' relative error applied to the adhesive energy."""
    return 2e-5 if work == 0.0 else 5e-4


@pytest.fixture
def built(monkeypatch):
    """Record the estimate of every table the run actually builds."""
    seen = []
    window = GWJKRSurface._build_window
    rigid = rough_rigid.RigidRoughRoller._build

    def build_window(self, dh):
        size = table_size(self.stats, self.work_of_adhesion, self.e_star,
                          z_max=self._tmax if self.truncated else None, detachment=self.detachment,
                          resolution=self.resolution)
        seen.append(("gw", size["peak_bytes"], size["nodes"]))
        return window(self, dh)

    def build_rigid(self, depth):
        shape = self.table_shape(self.sigma, self.release_stretch, self.end_gap, depth, self.resolution)
        seen.append(("rigid", shape["peak_bytes"], shape["states"]))
        return rigid(self, depth)

    monkeypatch.setattr(GWJKRSurface, "_build_window", build_window)
    monkeypatch.setattr(rough_rigid.RigidRoughRoller, "_build", build_rigid)
    return seen


def run_point(sigma, modulus, work, release):
    overrides = {"surfaces.roughness.sigma": sigma, "surfaces.roughness.summit_modulus": modulus,
                 "surfaces.work_of_adhesion": work, "release_height": release,
                 "physics.adhesion_law": "auto", "physics.half_space": "auto",
                 "surfaces.roughness.mode": "mean_field", "numerics.fidelity": "fast", "numerics.max_bounces": 2}
    return run_impact(resolve_scene(SCENE, overrides=overrides, override_label="extremes"))


@pytest.mark.parametrize("sigma,modulus,work,release", [p for p in POINTS if p in REFUSED])
def test_an_extreme_point_outside_the_model_is_refused_in_one_line(built, sigma, modulus, work, release):
    with pytest.raises(SceneError) as info:
        run_point(sigma, modulus, work, release)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"surfaces.roughness.sigma = {sigma:g}: ")
    assert RANGE in message and "use " in message
    for kind, peak, _ in built:
        assert peak <= estimates.MEMORY_BOUND_BYTES, kind


@pytest.mark.parametrize("sigma,modulus,work,release", [p for p in POINTS if p not in REFUSED])
def test_an_extreme_point_inside_the_model_runs_within_bounds(built, sigma, modulus, work, release):
    run = run_point(sigma, modulus, work, release)
    result, trace = run.to_dict(), run.trace
    for key in ("t", "gap", "velocity", "force", "energy"):
        assert np.all(np.isfinite(trace[key])), key
    assert result["n_bounces"] >= 1
    audit = result["energy_audit"]["max_error_over_turnover"]
    assert math.isfinite(audit) and audit < audit_tolerance(work)
    for kind, peak, _ in built:
        assert peak <= estimates.MEMORY_BOUND_BYTES, kind


def test_a_terabyte_table_case_is_refused_before_any_table(built):
    """Soft, strongly adhesive summits on 0.1 nm roughness (a GW window table of terabytes): the adhesive approach
    would pull the roller beyond the averaged model's range, so that is what the refusal says (the size refusal's
    ways out would all be refused too), and no table is built."""
    with pytest.raises(SceneError) as info:
        run_point(0.1e-9, 1e6, 1.0, 1e-9)
    message = str(info.value)
    assert "\n" not in message and "more than 10 sigma below the summits' mean plane" in message
    assert not built


def test_an_oversized_gw_table_is_refused_in_one_line_with_the_way_out():
    stats = SummitStatistics(0.1e-9, 1e13, 2e-7)
    with pytest.raises(SceneError) as info:
        estimates.check_table_cost(stats=stats, work_of_adhesion=1.0, summit_e_star=1e6, z_max_sigma=4.1,
                                   detachment="displacement", resolution="standard", gw_tables=True, rigid=False,
                                   rigid_resolution="standard", release_stretch=0.0, end_gap=0.0,
                                   depth_estimate=None, sigma_key_value=0.1e-9)
    message = str(info.value)
    assert "\n" not in message and message.startswith("surfaces.roughness.sigma = 1e-10: ")
    assert "GiB" in message and "surfaces.roughness.mode = 'discrete'" in message
    # within the bounds: no refusal, and the estimate is recorded
    ok = estimates.check_table_cost(stats=SummitStatistics(6e-9, 1e13, 2e-7), work_of_adhesion=0.12,
                                    summit_e_star=10e9, z_max_sigma=4.1, detachment="displacement",
                                    resolution="standard", gw_tables=True, rigid=False, rigid_resolution="standard",
                                    release_stretch=0.0, end_gap=0.0, depth_estimate=None, sigma_key_value=6e-9)
    assert ok["gw_table"]["peak_bytes"] < estimates.MEMORY_BOUND_BYTES


def test_table_size_bounds_the_measured_build():
    beta, work, e_star = 1e-7, 0.1, 38e9
    delta_c = float(jkr.critical_approach(beta, work, e_star))
    z_max = float(expected_max_height(1e5))
    for ratio in (13.7, 0.3):
        stats = SummitStatistics(ratio * delta_c, 1e14, beta)
        est = table_size(stats, work, e_star, z_max=z_max, resolution="standard")
        tracemalloc.start()
        try:
            surface = GWJKRSurface(stats, work, e_star, z_max=z_max, resolution="standard")
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        table = surface._t2[0]
        assert (table.na + 1) * (table.nb + 1) == est["nodes"]
        assert peak <= est["peak_bytes"]
    # the rigid footprint tables on such a surface: built in blocks, their peak within the estimate
    from continuum.laws.rough_rigid import RigidRoughRoller

    law = RigidRoughRoller(surface, 5e-6, 3.28e-3, resolution="standard")
    depth = 3.0 * surface.sigma
    shape = law.table_shape(law.sigma, law.release_stretch, law.end_gap, depth, "standard")
    tracemalloc.start()
    try:
        law._build(depth)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert law.table_points == shape["nodes"] and peak <= shape["peak_bytes"]
    # the estimate grows like (delta_c/sigma)^2 and crosses the bounds
    stats = SummitStatistics(0.1e-9, 1e13, 2e-7)
    huge = table_size(stats, 1.0, 1e6, z_max=4.1, resolution="fast")
    assert huge["peak_bytes"] > 1e3 * estimates.MEMORY_BOUND_BYTES
