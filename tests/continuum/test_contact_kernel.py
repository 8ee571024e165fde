"""The compiled contact integrator (continuum.numerics.contact_kernel) against closed forms and the Python stepper.

Tolerances follow the problems, not one CPU's last digits:
- Hertz sphere (F = 4/3 E* sqrt(R) delta^1.5, no gravity): the integration runs at rtol 1e-10, the
  events are located on a 7th-order dense output, so contact time, maximum approach and peak force
  match Johnson's closed form to 1e-7, restitution is 1 to 1e-8 and kinetic + stored energy stays
  constant to 1e-8 of the impact energy at every sample.
- Splines: the kernel evaluates FITPACK's B-spline tables by the same de Boor recursion; agreement
  to 1e-12 of the table's largest value (round-off of a 16-term sum).
- Rough impacts (GW-JKR summits, tabulated rigid footprint law, rtol 1e-8 at `standard`): the kernel
  and the Python stepper run the same algorithm on the same tables; round-off in the error norm moves
  step sizes by an ulp, which can flip one step's acceptance, so two runs differ by O(rtol) (seen:
  1.2e-8 on OTS). Times, approaches, forces and booked losses must agree to 10 rtol relative, rebound
  speeds to 10 rtol of the impact speed (near the escape velocity a rebound is a small difference of
  large terms): below the tables' accuracy (~1e-6), and any change of method or event logic breaks it.
"""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, RectBivariateSpline

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.escape import escape_velocity, single_impact
from continuum.dynamics.impact import first_impact_speed
from continuum.model import select_law
from continuum.numerics import kernel_laws as kl
from continuum.numerics.compiled_contact import power_law, run_compiled
from continuum.reference import hertz as ref
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "inputs" / "scenes"
M, R, E_STAR, V = 1e-12, 5e-6, 80e9, 1e-2


def _hertz(mass=M, speed=V, gravity=0.0, rtol=1e-10):
    k = 4.0 / 3.0 * E_STAR * math.sqrt(R)
    law = power_law(k, 1.5)
    exact = ref.sphere_impact(mass, speed, R, E_STAR)
    length = float(exact["max_approach"])
    atol = np.array([rtol * length, rtol * speed]) * 0.1
    out = run_compiled(law, mass, gravity, 0.0, 0.0, -speed, rtol=rtol, atol=atol, first_step=1e-3 * length / speed,
                       max_step=math.inf, t_bound=1.0, release=0.0, bound_is_final=True, has_history=False,
                       samples_per_step=3)
    return out, exact, k


def test_hertz_sphere_contact_time_approach_and_peak_force_match_the_closed_form():
    out, exact, _ = _hertz()
    assert out.end is None                                   # released
    assert out.t == pytest.approx(float(exact["contact_time"]), rel=1e-7, abs=0)
    assert out.max_penetration == pytest.approx(float(exact["max_approach"]), rel=1e-7, abs=0)
    assert out.peak_force == pytest.approx(float(exact["peak_force"]), rel=1e-7, abs=0)
    assert out.max_approach[0] == pytest.approx(0.5 * float(exact["contact_time"]), rel=1e-7)


def test_elastic_hertz_impact_has_restitution_one_and_conserves_energy_at_every_sample():
    out, _, _ = _hertz()
    assert abs(out.v) / V == pytest.approx(1.0, abs=1e-8)
    rows = out.samples[out.samples[:, 6] == 0.0]
    energy = 0.5 * M * rows[:, 2] ** 2 + rows[:, 4]
    assert len(rows) > 50
    assert np.max(np.abs(energy - 0.5 * M * V * V)) < 1e-8 * 0.5 * M * V * V
    assert out.booked == 0.0


@pytest.mark.parametrize("speed", [1e-4, 1e-2, 1.0])
def test_hertz_contact_time_scales_as_v_to_the_minus_one_fifth(speed):
    out, exact, _ = _hertz(speed=speed)
    assert out.t == pytest.approx(float(exact["contact_time"]), rel=1e-7, abs=0)


def test_hertz_with_gravity_turns_back_in_contact_when_too_slow_to_leave():
    """Under a gravity that overwhelms the impact the body oscillates about its static approach without ever
    reaching the release gap: it turns back (v = 0) still in contact, with the spring pushing less than its
    weight there (the driver's 'stuck': it can never leave)."""
    k = 4.0 / 3.0 * E_STAR * math.sqrt(R)
    law = power_law(k, 1.5)
    g = 1e9
    out = run_compiled(law, M, g, 0.0, 0.0, -1e-6, rtol=1e-10, atol=np.array([1e-20, 1e-17]), first_step=1e-12,
                       max_step=math.inf, t_bound=1.0, release=0.0, bound_is_final=True, has_history=False,
                       samples_per_step=3)
    static = (M * g / k) ** (2.0 / 3.0)
    assert out.end == "stuck" and out.v == 0.0
    assert -out.gap < static and k * (-out.gap) ** 1.5 < M * g
    # energy: the turning point is where kinetic energy is zero again
    assert 0.5 * M * 1e-12 + M * g * 0.0 == pytest.approx(M * g * out.gap + k * (-out.gap) ** 2.5 / 2.5, rel=1e-6)


def test_bicubic_and_ppoly_match_scipy():
    rng = np.random.default_rng(3)
    x, y = np.sort(rng.uniform(-2, 1, 40)), np.linspace(0, 1, 9)
    z = rng.normal(size=(x.size, y.size))
    spline = RectBivariateSpline(x, y, z, kx=3, ky=3)
    tx, ty, c = spline.tck
    xs, ys = rng.uniform(x[0], x[-1], 300), rng.uniform(0, 1, 300)
    xs[:len(x)] = x                                            # on the knots too
    got = np.array([kl.bicubic(tx, ty, c, a, b) for a, b in zip(xs, ys)])
    assert np.max(np.abs(got - spline.ev(xs, ys))) < 1e-12 * np.max(np.abs(z))
    cs = CubicSpline(x, z[:, 0])
    pts = np.concatenate([rng.uniform(x[0] - 0.1, x[-1] + 0.1, 200), x])
    got = np.array([kl.ppoly3(cs.x, cs.c, a) for a in pts])
    assert np.max(np.abs(got - cs(pts))) < 1e-12 * np.max(np.abs(z))


def _rough(scene_file, **overrides):
    resolved = resolve_scene(SCENES / scene_file, overrides={"physics.half_space": "off", **overrides})
    scene = resolved.scene
    return scene, first_impact_speed(resolved)


def _bounce_pairs(scene_file, bounces, **overrides):
    scene, v0 = _rough(scene_file, **overrides)
    runs = []
    for compiled in (True, False):
        law, _ = select_law(scene, v0)
        runs.append(simulate(law, scene.body.mass, scene.environment.gravity, release_height=scene.release_height,
                             settings=DriverSettings(rtol=scene.numerics.rtol, max_bounces=bounces,
                                                     compiled=compiled)))
    return runs


@pytest.mark.parametrize("scene_file,bounces", [("rough_silica.toml", 4), ("rough_ots.toml", 3)])
def test_compiled_rough_impacts_match_the_python_stepper(scene_file, bounces):
    fast, slow = _bounce_pairs(scene_file, bounces)
    tol = 10 * _rough(scene_file)[0].numerics.rtol
    assert fast.status == slow.status and len(fast.bounces) == len(slow.bounces)
    for a, b in zip(fast.bounces, slow.bounces):
        for key in ("duration", "max_penetration", "peak_force", "energy_booked", "t_contact"):
            va, vb = getattr(a, key), getattr(b, key)
            assert va == pytest.approx(vb, rel=tol, abs=0), (key, a.index)
        assert a.v_rebound == pytest.approx(b.v_rebound, rel=0, abs=tol * b.v_impact)
        assert set(a.profiles or {}) == set(b.profiles or {}) == {"max_approach", "pull_off"}
        # the maximum approach is an event located on the dense output; the two trajectories differ by O(rtol)
        # (a step's acceptance can flip on round-off), so the gap there agrees to the same 10 rtol
        pa, pb = a.profiles["max_approach"], b.profiles["max_approach"]
        assert pa["gap"] == pytest.approx(pb["gap"], rel=tol)
        assert np.allclose(pa["pressure"], pb["pressure"], rtol=0, atol=1e-6 * np.max(np.abs(pb["pressure"])))
        # the pull-off profile is taken at the sample of lowest force: the force is flat there, and round-off
        # in the step sizes moves the samples (by ~1e-11 s), so the sample picked moves along the flat minimum
        # With a tabulated summit law (the coated OTS summits) the minimum sits on a table kink, not on a flat
        # minimum: the sample picked then moves the force by the slope times the sample shift, ~3e-4 of it here.
        pa, pb = a.profiles["pull_off"], b.profiles["pull_off"]
        pull_tol = 1e-5 if _rough(scene_file)[0].surfaces.sam is None else 1e-3
        assert pa["force"] == pytest.approx(pb["force"], rel=pull_tol)
        assert pa["gap"] == pytest.approx(pb["gap"], rel=1e-3)
    # the audit is the largest sampled energy error: set by the tables (~1e-6 of the turnover), not by rtol, and
    # a maximum over samples, so a step flipped by round-off (numba's FMA use differs between CPUs) moves it by a
    # fraction of itself (1.23e-6 -> 1.59e-6 seen with 1-ulp table noise): both small, and of the same size
    fa, sa = fast.audit["max_relative_error"], slow.audit["max_relative_error"]
    assert max(fa, sa) < 1e-5 and abs(fa - sa) <= 0.5 * max(fa, sa)
    # samples are taken per accepted step: a flipped acceptance changes the count by a few, not more
    assert abs(len(fast.trace.t) - len(slow.trace.t)) <= 0.02 * len(slow.trace.t)


def test_compiled_rough_impact_books_the_energy_it_loses():
    """GW-JKR summits: what the body loses over a contact is what the summits' hysteresis loops book."""
    fast, _ = _bounce_pairs("rough_silica.toml", 3)
    for b in fast.bounces:
        assert b.energy_booked > 0.0
        assert b.energy_lost == pytest.approx(b.energy_booked, rel=1e-5)
    assert fast.audit["max_relative_error"] < 1e-5


def test_sticking_and_escaping_single_impacts_agree_with_the_python_stepper():
    scene, v0 = _rough("rough_silica.toml")
    law, _ = select_law(scene, v0)
    g, m = scene.environment.gravity, scene.body.mass
    for factor in (0.05, 0.3, 3.0):
        v = v0 * factor
        a = single_impact(law, m, g, v, scene.numerics.rtol)
        slow = simulate(law, m, g, impact_velocity=v,
                        settings=DriverSettings(rtol=scene.numerics.rtol, max_bounces=1, max_time=1.0,
                                                samples_per_flight=2, compiled=False))
        assert a.status == slow.status
        if not a.stuck:
            assert a.bounces[0].v_rebound == pytest.approx(slow.bounces[0].v_rebound, rel=0,
                                                           abs=10 * scene.numerics.rtol * v)


def test_wet_impact_hands_over_to_the_python_law_at_t_a():
    """Wet silica near its escape velocity: the contact outlasts t_a; the compiled dry phase stops there and
    the Python wet law finishes the contact, as the Python stepper alone does."""
    scene, v0 = _rough("wet_silica.toml")
    wet, _ = select_law(scene, v0, menisci=True)
    g, m = scene.environment.gravity, scene.body.mass
    t_a = wet.bridges.t_a
    dry, _ = select_law(scene, v0, menisci=False)
    upper = escape_velocity(dry, m, g, 0.3 * v0, 0.6 * v0, rel_tol=1e-3, rtol=scene.numerics.rtol)["upper"]
    pairs = []
    for speed in (0.3 * v0, upper * 1.001, upper * 1.01, 0.6 * v0, 2.0 * v0):
        # both paths at one speed in a row: the law sizes its tables for the speed, so both see the same tables
        pairs.append([simulate(wet, m, g, impact_velocity=speed,
                               settings=DriverSettings(rtol=scene.numerics.rtol, max_bounces=1, max_time=1.0,
                                                       samples_per_flight=2, compiled=compiled))
                      for compiled in (True, False)])
    long_seen = False
    for a, b in pairs:
        assert a.status == b.status
        ba, bb = a.bounces[0], b.bounces[0]
        long_seen |= a.trace.t[-1] > t_a                          # the contact went on past t_a (stuck there)
        # a turn while attached is a slow zero of v: ill-conditioned in time (the Python stepper's own stuck time
        # moves by 1.7e-7 when rtol moves by 1e-9), so the end times agree to 1e-6, the rest to 10 rtol
        assert a.trace.t[-1] == pytest.approx(b.trace.t[-1], rel=1e-6)
        if ba.duration is not None:
            assert ba.duration == pytest.approx(bb.duration, rel=10 * scene.numerics.rtol)
            assert ba.v_rebound == pytest.approx(bb.v_rebound, rel=0, abs=10 * scene.numerics.rtol * bb.v_impact)
        assert ba.energy_booked == pytest.approx(bb.energy_booked, rel=10 * scene.numerics.rtol, abs=1e-30)
    assert long_seen, "no impact outlasted t_a: the hand-over was not exercised"
