"""The compiled discrete contact with a bridge on each summit (continuum.numerics.wet_discrete_kernel) against its
Python form (continuum.laws.wet_summits, continuum.laws.discrete_bridges) and against closed forms."""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.discrete_bridges import wet_discrete
from continuum.laws.discrete_roller import DiscreteRoughRoller
from continuum.laws.wet_summits import wet_summit_roller
from continuum.numerics import contact_kernel as ck
from continuum.numerics import kernel_laws as kl
from continuum.numerics import wet_discrete_kernel as wk
from continuum.numerics.compiled_contact import STATS
from continuum.reference import jkr as ref
from continuum.rough.summits import SummitStatistics

GAMMA = 0.072                       # N/m, water
THETA = math.radians(20.0)
BETA = 0.2e-6                       # summit radius (m)
R_K = 0.52e-9                       # Kelvin radius (m)
D_K = 2.0 * R_K * math.cos(THETA)   # Kelvin gap of two faces at THETA
F0 = 4.0 * math.pi * BETA * GAMMA * math.cos(THETA)     # Israelachvili 2011 eq 17.23
T_A, H1 = 1e-6, 0.34e-9
W_DRY, W_WET, E_STAR = 0.192, 0.028, 2e10
PARAMS = {"bridge_pull_off": F0, "kelvin_gap": D_K, "condensation_time": T_A, "growth_length": H1}


def _rollers(w_dry, w_wet, summits=None, seed=0):
    """Dry and wet JKR discrete rollers on the same summits (one at the datum by default)."""
    stats = SummitStatistics(1e-9, 1e13, BETA)
    one = (np.array([0.0]), np.array([0.0]), np.array([0.0])) if summits is None else summits
    kw = dict(seed=seed, half_space=False, summits=one)
    return (DiscreteRoughRoller(stats, w_dry, E_STAR, 5e-6, 1e-3, 1e11, **kw),
            DiscreteRoughRoller(stats, w_wet, E_STAR, 5e-6, 1e-3, 1e11, **kw))


def _many_summits(n=40, seed=5):
    rng = np.random.default_rng(seed)
    return rng.uniform(-3e-7, 3e-7, n), rng.uniform(0.0, 1e-3, n), rng.normal(0.0, 1e-9, n)


def _handover(law, depth, t0=0.25):
    """Press `law` to `depth` before t_a, hold past t_a, accept there, and take its compiled form. The press runs
    in Python and, as the dry kernel would, in the dry form issued at touch (whose history the bridged form keeps)."""
    law.reset()
    first = law.compiled(t0)
    for g in np.linspace(0.5 * D_K, -depth, 200):
        law.set_time(0.0)
        law.accept(g)
        kl.law_accept(first.kind, g, first.S, first.P, first.T)
    law.set_time(1.5 * T_A)
    law.accept(-depth)
    form = law.compiled(t0)
    assert form is not None and form.kind in (wk.LAW_WET_DISCRETE, wk.LAW_BRIDGED)
    return form


def _compare_along(law, form, path, t0=0.25):
    """Python and compiled force, stored and booked energy along `path` ((gap, contact time) pairs), both
    accepting every state; returns the largest differences over the scales (force: F0, energies: F0 D_K)."""
    worst = [0.0, 0.0, 0.0]
    scales = (F0, F0 * D_K, F0 * D_K)
    for g, tc in path:
        law.set_time(tc)
        py = (law.force(g), law.stored_energy(g), law.dissipated(g))
        cc = tuple(f(form.kind, t0 + tc, g, form.S, form.P, form.T) for f in (ck._force, ck._stored, ck._dissipated))
        for j in range(3):
            worst[j] = max(worst[j], abs(py[j] - cc[j]) / scales[j])
        law.accept(g)
        ck._accept(form.kind, t0 + tc, g, form.S, form.P, form.T)
    return worst


def _retreat_path(depth, n=600):
    """Pull off from -depth past the Kelvin gap while the bridgeable gap grows (gap, contact time)."""
    return list(zip(np.linspace(-depth, 1.6 * D_K, n), np.linspace(1.5 * T_A, 8.0 * T_A, n)))


@pytest.mark.parametrize("w_wet", [W_WET, 0.0])
def test_compiled_wet_summits_follow_the_python_law(w_wet):
    """40 JKR summits, bridged ones at W_wet (or Hertz where W_wet = 0), pulled off through their wet and dry
    release points: force, stored and booked energy of the two forms agree to round-off. The JKR root is the same
    closed form in both (np.cbrt in numba, math.cbrt in Python), a few ulps apart, so 1e-9 of the bridge's scale."""
    dry, wet = _rollers(W_DRY, w_wet, _many_summits())
    law = wet_summit_roller(dry, wet, PARAMS)
    form = _handover(law, 2.0 * D_K)
    worst = _compare_along(law, form, _retreat_path(2.0 * D_K))
    assert max(worst) < 1e-9
    assert law.dry.detached + law.dry.detached_wet > 0           # summits let go on the way: the books were tested


def test_compiled_bridges_round_a_dry_discrete_law_follow_the_python_law():
    """`wet_discrete` (bridges with a DMT solid pull round summits that keep their dry law), LAW_BRIDGED round
    LAW_DISCRETE: the two forms agree to round-off."""
    dry, _ = _rollers(W_DRY, W_WET, _many_summits())
    law = wet_discrete(dry, dry, {**PARAMS, "solid_pull": 0.3 * F0})
    form = _handover(law, 2.0 * D_K)
    assert form.kind == wk.LAW_BRIDGED
    assert max(_compare_along(law, form, _retreat_path(2.0 * D_K))) < 1e-9


def test_one_bridged_summit_is_jkr_at_w_wet_minus_the_kelvin_laplace_bridge():
    """One summit pressed before t_a and held past it: compiled, its force is the JKR stable branch at W_wet
    (continuum.reference.jkr) minus the Kelvin-Laplace bridge on a sphere, F = (gamma / r_K) 2 pi beta (D_K - g/2)
    compressed, (gamma / r_K) 2 pi beta (D_K - g) stretched (closed forms written here, not read from the code)."""
    dry, wet = _rollers(W_DRY, W_WET)
    law = wet_summit_roller(dry, wet, PARAMS)
    depth = 3.0 * dry.delta_c
    form = _handover(law, depth)
    delta_c_wet = float(ref.critical_approach(BETA, W_WET, E_STAR))
    for g in np.linspace(-depth, 0.95 * delta_c_wet, 25):
        tc = 2.0 * T_A
        ck._accept(form.kind, 0.25 + tc, g, form.S, form.P, form.T)
        got = ck._force(form.kind, 0.25 + tc, g, form.S, form.P, form.T)
        wetted = 2.0 * math.pi * BETA * (D_K - g / 2.0 if g < 0 else D_K - g)
        want = float(ref.force_from_approach(-g, BETA, W_WET, E_STAR)) - GAMMA / R_K * wetted
        assert got == pytest.approx(want, rel=1e-9, abs=1e-9 * F0)


@pytest.mark.parametrize("plasticity", ["off", "auto"])
def test_a_humid_member_gives_the_same_motion_compiled_and_in_python(plasticity):
    """A wet_silica member (calibrated; t_a = 1 us, shorter than its contacts): elastic Maugis-Dugdale summits at
    W_wet inside bridges (LAW_WET_DISCRETE) or yielding summits at W_wet inside bridges (its plastic mode). Compiled
    (the dry kernel to t_a, then the bridged kernel) and the Python stepper give the same restitution and booked
    loss to the integrator's tolerance (rtol 1e-8 on a force with jumps: 1e-5)."""
    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model.regime import first_impact_speed
    from continuum.scene import resolve_scene

    scene = resolve_scene("wet_silica", params="calibrated", overrides={
        "surfaces.roughness.mode": "ensemble", "menisci.condensation_model": "fixed",
        "menisci.condensation_time": 1e-6, "physics.plasticity": plasticity}).scene
    results = []
    for compiled in (True, False):
        _, law = member_law(scene, 1, member_plan(scene, first_impact_speed(scene)))
        before = STATS.compiled
        run = simulate(law, scene.body.mass, 9.81, release_height=100e-9,
                       settings=DriverSettings(rtol=1e-8, max_bounces=3, compiled=compiled))
        results.append((run, STATS.compiled - before, law.diagnostics()["menisci"]))
    (fast, n_fast, men_fast), (slow, _, men_slow) = results
    assert men_fast["contacts_with_bridges"] >= 1 and men_fast["max_bridges"] == men_slow["max_bridges"]
    assert n_fast >= 1
    assert len(fast.bounces) == len(slow.bounces)
    for a, b in zip(fast.bounces, slow.bounces):
        assert a.restitution == pytest.approx(b.restitution, rel=1e-5, abs=1e-6)
        assert a.energy_booked == pytest.approx(b.energy_booked, rel=1e-5)
    assert fast.audit["max_relative_error"] < 1e-4
