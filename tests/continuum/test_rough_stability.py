"""Rough impacts across the parameter ranges users sweep: each point runs to the code's own accuracy or is
refused for its stated reason.

A coarse grid over sigma 0.1-100 nm, release height 1 nm-10 um, work of adhesion 0-1 J/m^2 and summit E* 1 MPa -
1 TPa, JKR summits on a rigid substrate in the mean-field model, 3 impacts at the `standard` preset. Every point is
declared:

* refused, for one of two reasons (docs/model.md, "Bounded cost"): ``RANGE``, the impact would press the roller
  more than 10 sigma below the summits' mean plane, where every summit touches and the averaged rough model does
  not apply; ``COST``, the rigid-substrate footprint tables would exceed their time bound. The refusal is one
  line naming surfaces.roughness.sigma, its value and the way out.
* or run: finite numbers and an energy audit (largest |E(t) - E(0)| over the run's energy turnover) within
  ``audit_tolerance``. Hertz summits (no adhesion) and the paper's range (``must_run``) hold 1e-6 and 2e-6 of
  the turnover. Where adhesion releases much more energy than the impact brings (1 J/m^2, or 0.1 J/m^2 on
  0.1 nm roughness) the tables' relative error applies to that energy, and the tolerance is wider.

`test_the_audit_tolerance_catches_a_law_that_misreports_its_energy` shows the tolerance bites: a law whose
stored energy is off by 1e-5 of itself fails it. Automatic model choices at the extremes and the memory bound:
tests/continuum/test_extremes.py.
"""
import itertools
import math
from pathlib import Path

import numpy as np
import pytest

import continuum.dynamics.impact as impact
from continuum.dynamics.impact import run_impact
from continuum.scene import SceneError, resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "inputs" / "scenes" / "rough_silica.toml"
SIGMAS = (0.1e-9, 5e-9, 100e-9)
RELEASES = (1e-9, 100e-9, 10e-6)
WORKS = (0.0, 0.1, 1.0)
MODULI = (1e6, 20e9, 1e12)

RANGE = "more than 10 sigma below the summits' mean plane"
COST = "the rigid-substrate footprint tables would evaluate"
#: (sigma, release, work, modulus) -> why the point is refused; every other point must run.
REFUSED = {
    **{(0.1e-9, r, w, 1e6): RANGE for r in RELEASES for w in WORKS if (r, w) != (1e-9, 0.0)},
    **{(0.1e-9, r, 1.0, 20e9): RANGE for r in RELEASES},
    **{(5e-9, r, w, 1e6): RANGE for r in RELEASES for w in (0.1, 1.0)},
    **{(100e-9, r, 1.0, 1e6): RANGE for r in RELEASES},
    (100e-9, 100e-9, 0.1, 1e12): COST,
    (100e-9, 10e-6, 0.1, 1e12): COST,
}


def must_run(sigma, release, work, modulus):
    """The paper's range: moderate roughness, drops of 10 nm and more, silicon-like summits, moderate adhesion."""
    return sigma >= 1e-9 and release >= 10e-9 and 5e9 <= modulus <= 200e9 and work <= 0.5


def audit_tolerance(sigma, release, work, modulus):
    """Largest energy-audit error over the turnover the point may show (see the module docstring)."""
    if must_run(sigma, release, work, modulus):
        return 2e-6
    if work == 0.0:
        return 1e-6
    if work >= 1.0:
        return 5e-4
    return 1e-4 if sigma < 1e-9 else 1e-5


def overrides(sigma, release, work, modulus, max_bounces=3, plasticity="off"):
    return {"surfaces.roughness.sigma": sigma, "release_height": release,
            "surfaces.work_of_adhesion": work, "surfaces.roughness.summit_modulus": modulus,
            "physics.adhesion_law": "jkr" if work > 0 else "none", "physics.half_space": "off",
            # the grid sweeps the elastic JKR mean field; where the set's hardness yields the summits (stiff points)
            # the plastic mean field runs in `test_a_point_with_yielding_summits_...` below
            "physics.plasticity": plasticity,
            "surfaces.roughness.mode": "mean_field",
            "numerics.fidelity": "standard", "numerics.max_bounces": max_bounces, "numerics.max_time": 1.0}


def run_point(point, max_bounces=3, plasticity="off"):
    return run_impact(resolve_scene(SCENE, overrides=overrides(*point, max_bounces=max_bounces, plasticity=plasticity),
                                    override_label="stability sweep"))


def test_the_declared_refusals_lie_outside_the_required_range():
    assert not [p for p in REFUSED if must_run(*p)]
    assert sum(must_run(*p) for p in itertools.product(SIGMAS, RELEASES, WORKS, MODULI)) == 8


@pytest.mark.parametrize("point", [p for p in itertools.product(SIGMAS, RELEASES, WORKS, MODULI) if p in REFUSED])
def test_a_point_outside_the_model_is_refused_in_one_line_for_its_reason(point):
    with pytest.raises(SceneError) as info:
        run_point(point)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"surfaces.roughness.sigma = {point[0]:g}: ")
    assert REFUSED[point] in message and "use " in message


@pytest.mark.parametrize("point", [p for p in itertools.product(SIGMAS, RELEASES, WORKS, MODULI)
                                   if p not in REFUSED])
def test_a_point_inside_the_model_runs_to_the_codes_accuracy(point):
    run = run_point(point)
    result, trace = run.to_dict(), run.trace
    for key in ("t", "gap", "velocity", "force", "energy"):
        assert np.all(np.isfinite(trace[key])), key
    assert result["n_bounces"] >= 1
    audit = result["energy_audit"]["max_error_over_turnover"]
    assert math.isfinite(audit) and audit < audit_tolerance(*point)


#: stiff summits (1 TPa) whose set's hardness makes them yield: the plastic JKR mean field (Thornton-Ning summits,
#: `continuum.rough.plastic_summits`) at the thinnest and the roughest sigma; the last drop sent DOP853's trial
#: stages kilometres below the surface, where the quadrature once grew without bound (tens of GB)
PLASTIC = ((0.1e-9, 1e-9, 0.1, 1e12), (5e-9, 1e-9, 1.0, 1e12), (100e-9, 100e-9, 1.0, 1e12))


@pytest.mark.parametrize("point", PLASTIC)
def test_a_point_with_yielding_summits_runs_the_plastic_mean_field_with_a_bounded_quadrature(point, monkeypatch):
    from continuum.rough import plastic_summits as ps
    nodes, counts = ps.PlasticGWSurface._nodes, []

    def counted(self, lo, hi, floor=-math.inf):
        x, w = nodes(self, lo, hi, floor)
        counts.append(x.size <= (self.node_bound(hi - lo) if hi > lo else 0))
        return x, w
    monkeypatch.setattr(ps.PlasticGWSurface, "_nodes", counted)
    run = run_point(point, plasticity="auto")
    result, trace = run.to_dict(), run.trace
    assert result["models"]["contact_law"]["name"] == "rough_roller_gw_plastic_rigid"
    assert counts and all(counts)
    for key in ("t", "gap", "velocity", "force", "energy"):
        assert np.all(np.isfinite(trace[key])), key
    audit = result["energy_audit"]["max_error_over_turnover"]
    assert math.isfinite(audit) and audit < audit_tolerance(*point)


def test_the_audit_tolerance_catches_a_law_that_misreports_its_energy(monkeypatch):
    """The same must-run point on the Python stepper: exact, it holds the tolerance; with the law's stored energy
    scaled by 1 + 1e-5 (the energy in play at maximum approach is of the order of the impact's), it fails it."""
    point = (5e-9, 100e-9, 0.1, 20e9)
    select = impact.select_law

    def stepper(scale):
        def select_law(scene, speed, **kw):
            law, models = select(scene, speed, **kw)
            stored = law.stored_energy
            law.stored_energy = lambda gap: scale * stored(gap)
            law.compiled = lambda t0: None
            return law, models
        monkeypatch.setattr(impact, "select_law", select_law)
        return run_point(point, max_bounces=1).to_dict()["energy_audit"]["max_error_over_turnover"]

    assert stepper(1.0) < audit_tolerance(*point) < stepper(1.0 + 1e-5)
