"""Hertz impacts against closed forms: the driver's flight, contact and event handling."""
import math
from pathlib import Path

import pytest

from continuum.dynamics.driver import DriverSettings, flight_time_to, simulate
from continuum.dynamics.impact import run_impact
from continuum.laws.hertz import HertzLine, HertzSphere, LinearSpring, roller_constant_stiffness
from continuum.reference import hertz as ref
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parents[2]
M, R, L = 0.6e-9, 5e-6, 3.28e-3            # the paper's roller
E_STAR = float(ref.effective_modulus(169e9, 0.22, 169e9, 0.22))
G, H0 = 9.80665, 100e-9
V = math.sqrt(2 * G * H0)


@pytest.fixture(scope="module")
def spring():
    k, _ = roller_constant_stiffness(M, V, R, L, E_STAR)
    return k


def test_constant_k_contact_time_and_max_approach_match_shifted_oscillator(spring):
    run = simulate(LinearSpring(spring), M, G, release_height=H0, settings=DriverSettings(max_bounces=3))
    exact = ref.linear_oscillator_impact(M, spring, V, G)
    for b in run.bounces:
        assert b.duration == pytest.approx(float(exact["contact_time"]), rel=1e-6, abs=0)
        assert b.max_penetration == pytest.approx(float(exact["max_approach"]), rel=1e-6, abs=0)
        assert b.peak_force == pytest.approx(spring * float(exact["max_approach"]), rel=1e-6, abs=0)


def test_constant_k_without_gravity_in_contact_is_pi_sqrt_m_over_k(spring):
    run = simulate(LinearSpring(spring), M, 0.0, impact_velocity=V, settings=DriverSettings())
    b = run.bounces[0]
    assert run.status == "escaped"
    assert b.duration == pytest.approx(math.pi * math.sqrt(M / spring), rel=1e-6, abs=0)
    assert b.max_penetration == pytest.approx(V * math.sqrt(M / spring), rel=1e-6, abs=0)
    assert b.restitution == pytest.approx(1.0, abs=1e-9)


def test_constant_k_twenty_bounces_return_to_release_height(spring):
    run = simulate(LinearSpring(spring), M, G, release_height=H0, settings=DriverSettings(max_bounces=20))
    assert len(run.bounces) == 20 and run.status == "max_bounces"
    for b in run.bounces:
        assert b.rebound_height == pytest.approx(H0, rel=1e-6, abs=0)
    assert run.audit["max_relative_error"] < 1e-6


def test_implicit_log_stiffness_max_approach_from_energy_balance():
    run = simulate(HertzLine(R, L, E_STAR), M, G, release_height=H0, settings=DriverSettings(max_bounces=2))
    expected = float(ref.line_impact_max_approach(M, V, R, L, E_STAR, G))
    assert run.bounces[0].max_penetration == pytest.approx(expected, rel=1e-8, abs=0)
    assert run.audit["max_relative_error"] < 1e-6


def test_paper_scale_check_for_the_smooth_roller():
    """Notes, Fig 6: delta_max about 6 pm and t about 14 ns for the smooth Hertz roller."""
    run = simulate(HertzLine(R, L, E_STAR), M, G, release_height=H0, settings=DriverSettings(max_bounces=1))
    b = run.bounces[0]
    assert 5e-12 < b.max_penetration < 7e-12
    assert 13e-9 < b.duration < 15e-9


def test_hertz_sphere_matches_classical_impact_closed_form():
    radius, mass, speed = 1e-6, 1e-14, 0.01
    run = simulate(HertzSphere(radius, E_STAR), mass, 0.0, impact_velocity=speed)
    exact = ref.sphere_impact(mass, speed, radius, E_STAR)
    b = run.bounces[0]
    assert b.max_penetration == pytest.approx(float(exact["max_approach"]), rel=1e-6, abs=0)
    assert b.duration == pytest.approx(float(exact["contact_time"]), rel=1e-6, abs=0)
    assert b.peak_force == pytest.approx(float(exact["peak_force"]), rel=1e-6, abs=0)


def test_free_flight_is_closed_form_and_bounce_period_is_flight_plus_contact(spring):
    run = simulate(LinearSpring(spring), M, G, release_height=H0, settings=DriverSettings(max_bounces=4))
    first, second = run.bounces[0], run.bounces[1]
    assert first.t_contact == pytest.approx(math.sqrt(2 * H0 / G), rel=1e-12, abs=0)
    assert second.t_contact - first.t_release == pytest.approx(2 * V / G, rel=1e-9, abs=0)
    assert flight_time_to(0.0, 1.0, 0.0, 0.0) == math.inf


def test_energy_audit_can_fail_when_the_law_misreports_its_stored_energy(spring):
    class Liar(LinearSpring):
        def stored_energy(self, gap):
            return 0.9 * super().stored_energy(gap)

    run = simulate(Liar(spring), M, G, release_height=H0, settings=DriverSettings(max_bounces=1))
    assert run.audit["max_relative_error"] > 1e-2


def test_hertz_roller_scene_runs_and_returns_to_release_height():
    resolved = resolve_scene(ROOT / "inputs" / "scenes" / "hertz_roller.toml")
    run = run_impact(resolved)
    result, trace = run.to_dict(), run.trace
    assert result["n_bounces"] == 20
    assert result["energy_audit"]["max_relative_error"] < 1e-6
    for b in result["bounces"]:
        assert b["rebound_height"] == pytest.approx(H0, rel=1e-6, abs=0)
    assert len(trace["t"]) == len(trace["force"]) > 100
