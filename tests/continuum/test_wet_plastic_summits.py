"""Plastic summits at the wet work of adhesion inside their bridges (continuum.laws.wet_plastic_summits) against
closed forms (Thornton-Ning on JKR), the laws it must reduce to (the elastic wet class at p_y = inf, the dry plastic
law at W_wet = dgamma), the energy audit of a humid plastic member, and its compiled form
(continuum.numerics.wet_plastic_kernel) point by point and over a member's motion."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.discrete_roller import DiscreteRoughRoller
from continuum.laws.plastic_rough import PlasticDiscreteRoller
from continuum.laws.wet_plastic_summits import WetPlasticSummits, wet_plastic_summit_roller
from continuum.laws.wet_summits import wet_summit_roller
from continuum.numerics import contact_kernel as ck
from continuum.numerics import kernel_laws as kl
from continuum.numerics import wet_discrete_kernel as wk
from continuum.numerics.compiled_contact import STATS
from continuum.reference import jkr as ref
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.hertz_plastic import HertzPlasticSummitLaw
from continuum.rough.plastic_branches import PlasticBranchSummitLaw
from continuum.rough.plastic_summits import PlasticSummitLaw
from continuum.rough.summits import SummitStatistics

GAMMA = 0.072                       # N/m, water
THETA = math.radians(20.0)
BETA = 0.2e-6                       # summit radius (m)
R_K = 0.52e-9                       # Kelvin radius (m)
D_K = 2.0 * R_K * math.cos(THETA)   # Kelvin gap of two faces at THETA
F0 = 4.0 * math.pi * BETA * GAMMA * math.cos(THETA)     # Israelachvili 2011 eq 17.23
T_A, H1 = 1e-6, 0.34e-9
PARAMS = {"bridge_pull_off": F0, "kelvin_gap": D_K, "condensation_time": T_A, "growth_length": H1}
# the calibrated silica's summits: silicon E*, MD works of adhesion (dry, wet) and range, hardness 11 GPa
W_DRY, W_WET, E, P_Y, Z0, SIGMA = 0.192, 0.028, 89e9, 11e9, 0.207e-9, 6e-9
DMAX = 30 * SIGMA
T0 = 0.25


def _md(w, p_y=P_Y):
    return PlasticBranchSummitLaw("maugis_dugdale", BETA, w, E, p_y, z0=Z0, delta_max=DMAX)


def _elastic(w=W_DRY, n=40, seed=5, summit_law=None):
    rng = np.random.default_rng(seed)
    summits = rng.uniform(-3e-7, 3e-7, n), rng.uniform(0.0, 1e-3, n), rng.normal(0.0, SIGMA, n)
    return DiscreteRoughRoller(SummitStatistics(SIGMA, 1e13, BETA), w, E, 5e-6, 1e-3, 1e11, seed=0,
                               half_space=False, summits=summits, summit_law=summit_law)


def _wet_plastic(dry_law, wet_law, elastic=None):
    el = _elastic() if elastic is None else elastic
    return wet_plastic_summit_roller(PlasticDiscreteRoller(dry_law, el.eff, SIGMA, el.depth_keep), wet_law, el,
                                     PARAMS)


def _press_and_hold(law, depth, forms=True):
    """Press `law` to `depth` before t_a (as the dry kernel would, in the dry form issued at touch), hold past t_a and
    accept there; returns the compiled form issued then (None: `forms` False)."""
    law.reset()
    first = law.compiled(T0) if forms else None
    for g in np.linspace(0.5 * D_K, -depth, 120):
        law.set_time(0.0)
        law.accept(g)
        if first is not None:
            kl.law_accept(first.kind, g, first.S, first.P, first.T)
    law.set_time(1.5 * T_A)
    law.accept(-depth)
    return law.compiled(T0) if forms else None


def _path(depth, deeper, n=500):
    """After t_a: deeper (summits yield while bridged), then pulled off past the Kelvin gap: (gap, contact time)."""
    gaps = np.concatenate([np.linspace(-depth, -deeper, n // 4), np.linspace(-deeper, 1.6 * D_K, n)])
    return list(zip(gaps, np.linspace(1.5 * T_A, 8.0 * T_A, gaps.size)))


def _along(law, path, other=None):
    """Force, stored and booked energy of `law` along `path`, accepting every state; with `other` (a compiled form or
    a second Python law) the same for it."""
    rows = []
    for g, tc in path:
        law.set_time(tc)
        row = [law.force(g), law.stored_energy(g), law.dissipated(g)]
        if isinstance(other, ContactLike):
            other.set_time(tc)
            row += [other.force(g), other.stored_energy(g), other.dissipated(g)]
            other.accept(g)
        elif other is not None:
            row += [f(other.kind, T0 + tc, g, other.S, other.P, other.T) for f in (ck._force, ck._stored,
                                                                                   ck._dissipated)]
            ck._accept(other.kind, T0 + tc, g, other.S, other.P, other.T)
        law.accept(g)
        rows.append(row)
    return np.array(rows)


class ContactLike:
    """Marker base: a Python law compared along a path (`_along`)."""


def _worst(rows):
    """Largest difference of each quantity between the two laws over the largest magnitude it takes on the path."""
    a, b = rows[:, :3], rows[:, 3:]
    return np.max(np.abs(a - b), axis=0) / np.max(np.abs(a), axis=0)


def test_compiled_wet_plastic_summits_follow_the_python_law():
    """40 Maugis-Dugdale Thornton-Ning summits, pressed past yield before t_a and deeper after it (bridged summits
    yield on their wet plastic line), then pulled off through both classes' release points while bridges form and
    break: force, stored and booked energy of the kernel and the Python law agree to round-off (1e-11 of their
    largest value on the path)."""
    law = _wet_plastic(_md(W_DRY), _md(W_WET))
    form = _press_and_hold(law, 9e-9)
    assert form.kind == wk.LAW_WET_DISCRETE and form.P[wk.DRY + wk.C_MODE] == wk.MODE_PLASTIC
    rows = _along(law, _path(9e-9, 14e-9), form)
    assert np.all(_worst(rows) < 1e-11)
    s = law.dry
    assert np.sum(s.delta_max > s.wet.yield_approach) >= 5            # summits yielded: the plastic terms tested
    assert s.switched != 0.0 and s._loops != 0.0                     # summits changed class and let go


class _ElasticWet(ContactLike):
    def __init__(self, law):
        self.law = law

    def __getattr__(self, name):
        return getattr(self.law, name)


@pytest.mark.parametrize("w_wet", [W_WET, 0.0])
def test_infinite_hardness_is_the_elastic_wet_class(w_wet):
    """p_y = inf: no summit yields, and the plastic law with its wet class is the elastic discrete law of the same
    Maugis-Dugdale summits with theirs (continuum.laws.wet_summits; Hertz at W_wet = 0, against the no-adhesion
    plastic class) to 1e-7 along a press, a hold past t_a and a pull-off through both release points."""
    tables = {w: make_summit_law("maugis_dugdale", BETA, w, E, z0=Z0, delta_max=DMAX) for w in (W_DRY, W_WET)}
    dry_el = _elastic(W_DRY, summit_law=tables[W_DRY])
    wet_el = _elastic(w_wet, summit_law=tables[w_wet]) if w_wet > 0 else _elastic(0.0)
    elastic = wet_summit_roller(dry_el, wet_el, PARAMS)
    wet = _md(w_wet, math.inf) if w_wet > 0 else HertzPlasticSummitLaw(BETA, E, math.inf)
    plastic = _wet_plastic(_md(W_DRY, math.inf), wet, _elastic())
    for law in (plastic, elastic):
        _press_and_hold(law, 3e-9, forms=False)
    rows = _along(plastic, _path(3e-9, 5e-9), _ElasticWet(elastic))
    assert np.all(_worst(rows) < 1e-7)
    assert elastic.dry.detached + elastic.dry.detached_wet > 0      # summits let go in both classes' rules


def test_w_wet_equal_to_dgamma_is_the_dry_plastic_law():
    """W_wet = dgamma: the wet class is the dry law, so whatever summits are bridged the law is the dry plastic
    discrete law (force, stored and booked energy equal to round-off)."""
    el = _elastic()
    law = _md(W_DRY)
    dry = PlasticDiscreteRoller(law, el.eff, SIGMA, el.depth_keep)
    wet = WetPlasticSummits.from_dry(PlasticDiscreteRoller(law, el.eff, SIGMA, el.depth_keep), law)
    rng = np.random.default_rng(3)
    gaps = np.concatenate([np.linspace(D_K, -14e-9, 200), np.linspace(-14e-9, 2 * D_K, 300)])
    for g in gaps:
        wet.set_wet_prefix(int(rng.integers(0, 41)))
        a = (wet.force(g), wet.stored_energy(g), wet.dissipated(g))
        b = (dry.force(g), dry.stored_energy(g), dry.dissipated(g))
        assert a == pytest.approx(b, rel=1e-12, abs=1e-12 * max(abs(b[0]), 1e-9))
        wet.accept(g)
        dry.accept(g)
    assert dry._w_total > 0.0 and wet.switched == pytest.approx(0.0, abs=1e-25)


def test_one_bridged_plastic_summit_lets_go_at_the_wet_release_point_and_books_the_wet_loop():
    """One JKR Thornton-Ning summit inside its bridge, pressed past yield and pulled off: it lets go at the wet law's
    fold delta_p - delta_c(R_p) and books Thornton-Ning's plastic work and the Fuller-Tabor loop of the R_p branch at
    W_wet, all written here from the closed forms (Thornton & Ning 1998: yield at centre pressure p_y, plastic line
    pi p_y beta, R_p = 4E*a*^3 / 3(F* + sqrt(8 pi w E* a*^3))); the dry law would let go elsewhere."""
    w, p_y = W_WET, 3e9
    summits = PlasticDiscreteRoller(PlasticSummitLaw(BETA, W_DRY, E, p_y), np.array([0.0]), SIGMA, 1e-6)
    law = WetPlasticSummits.from_dry(summits, PlasticSummitLaw(BETA, w, E, p_y))
    law.set_wet_prefix(1)
    # the closed forms
    a_y = brentq(lambda a: 2 * E * a / (math.pi * BETA) - math.sqrt(2 * w * E / (math.pi * a)) - p_y, 1e-12, 1e-6)
    f_y, d_y = float(ref.force_from_radius(a_y, BETA, w, E)), float(ref.approach_from_radius(a_y, BETA, w, E))
    dm = d_y + 4e-9
    big_d = dm - d_y
    a_s = math.sqrt(a_y**2 + BETA * big_d)
    f_s = f_y + math.pi * p_y * BETA * big_d
    r_p = 4 * E * a_s**3 / (3 * (f_s + math.sqrt(8 * math.pi * w * E * a_s**3)))
    d_p = dm - float(ref.approach_from_radius(a_s, r_p, w, E))
    fold = d_p - float(ref.critical_approach(r_p, w, E))
    work = (float(ref.energy_from_radius(a_y, BETA, w, E)) + f_y * big_d + 0.5 * math.pi * p_y * BETA * big_d**2
            - float(ref.energy_from_radius(a_s, r_p, w, E)))
    loop = float(ref.energy_from_approach(-float(ref.critical_approach(r_p, w, E)), r_p, w, E))
    for g in np.linspace(1e-10, -dm, 400):
        law.accept(g)
    assert law.force(-dm) == pytest.approx(f_s, rel=1e-9)                         # on the wet plastic line
    step = 1e-13
    gaps = np.arange(-dm, 1e-9, step)
    for g in gaps:
        law.accept(g)
        if not law._attached[0]:
            break
    assert -g == pytest.approx(fold, abs=2 * step)
    assert law.dissipated(g) == pytest.approx(work + loop, rel=1e-9)
    assert abs(fold - (PlasticSummitLaw(BETA, W_DRY, E, p_y).flattening(dm)[1]
                       - PlasticSummitLaw(BETA, W_DRY, E, p_y).release_stretch(
                           PlasticSummitLaw(BETA, W_DRY, E, p_y).flattening(dm)[0]))) > 100 * step


def test_one_bridged_plastic_summit_without_wet_adhesion_unloads_on_hertz_about_its_flattening():
    """W_wet <= 0: inside its bridge a summit follows Thornton's construction without adhesion. Pressed past yield
    and pulled off, it lets go at its residual approach delta_p with no loop, and books the plastic work, all from
    the closed forms written here (yield at centre pressure 2E*a/(pi beta) = p_y, line pi p_y beta, R_p = 4E*a*^3
    / 3F*); on the way out its force is Hertz about (R_p, delta_p)."""
    p_y = 3e9
    summits = PlasticDiscreteRoller(PlasticSummitLaw(BETA, W_DRY, E, p_y), np.array([0.0]), SIGMA, 1e-6)
    law = WetPlasticSummits.from_dry(summits, HertzPlasticSummitLaw(BETA, E, p_y))
    law.set_wet_prefix(1)
    a_y = math.pi * BETA * p_y / (2 * E)
    d_y, f_y = a_y**2 / BETA, 4 * E * a_y**3 / (3 * BETA)
    dm = d_y + 4e-9
    big_d = dm - d_y
    a2 = a_y**2 + BETA * big_d
    f_s = f_y + math.pi * p_y * BETA * big_d
    r_p = 4 * E * a2**1.5 / (3 * f_s)
    d_p = dm - a2 / r_p
    work = (8 / 15 * E * math.sqrt(BETA) * d_y**2.5 + f_y * big_d + 0.5 * math.pi * p_y * BETA * big_d**2
            - 8 / 15 * E * math.sqrt(r_p) * (dm - d_p)**2.5)
    for g in np.linspace(1e-10, -dm, 400):
        law.accept(g)
    assert law.force(-dm) == pytest.approx(f_s, rel=1e-12)
    half = -(d_p + 0.5 * (dm - d_p))
    assert law.force(half) == pytest.approx(4 / 3 * E * math.sqrt(r_p) * (0.5 * (dm - d_p))**1.5, rel=1e-12)
    step = 1e-13
    for g in np.arange(-dm, 1e-9, step):
        law.accept(g)
        if not law._attached[0]:
            break
    assert -g == pytest.approx(d_p, abs=2 * step)
    assert law.dissipated(g) == pytest.approx(work, rel=1e-9)
    assert law.dissipated(g) == pytest.approx(law.wet.plastic_work(dm), rel=1e-12)


@pytest.fixture(scope="module")
def humid_member_runs():
    """A wet_silica member (calibrated: yielding Maugis-Dugdale summits; t_a = 20 ns, shorter than its contact)
    dropped from 0.3 mm so that summits yield, one bounce, compiled and in Python."""
    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model.regime import first_impact_speed
    from continuum.scene import resolve_scene

    scene = resolve_scene("wet_silica", params="calibrated", overrides={
        "surfaces.roughness.mode": "ensemble", "menisci.condensation_model": "fixed",
        "menisci.condensation_time": 2e-8}).scene
    out = []
    for compiled in (True, False):
        _, law = member_law(scene, 1, member_plan(scene, first_impact_speed(scene)))
        before = (STATS.compiled, STATS.handed_over)
        run = simulate(law, scene.body.mass, 9.81, release_height=3e-4,
                       settings=DriverSettings(rtol=1e-8, max_bounces=1, compiled=compiled))
        out.append((run, (STATS.compiled - before[0], STATS.handed_over - before[1]), law, scene))
    return out


def test_a_humid_plastic_member_closes_its_energy_books(humid_member_runs):
    """The driver's audit (-int F dg against the change of stored + booked energy) over a humid member whose
    bridged summits yield and change class: within 3e-5 of the impact energy (the switch work it books is a few
    1e-4 of it, so leaving it out would fail)."""
    for run, _, law, scene in humid_member_runs:
        s = law.dry
        assert isinstance(s, WetPlasticSummits)
        assert law.diagnostics()["menisci"]["contacts_with_bridges"] == 1
        assert np.sum(s.delta_max > s.wet.yield_approach) >= 1 and s._w_total > 0.0
        impact = 0.5 * scene.body.mass * run.bounces[0].v_impact**2
        assert abs(s.switched) > 1e-4 * impact
        assert run.audit["max_relative_error"] < 3e-5


def test_a_humid_plastic_member_gives_the_same_motion_compiled_and_in_python(humid_member_runs):
    """Compiled (the dry plastic kernel to t_a, then the wet plastic kernel) and the Python stepper: the same
    rebound to the integrator's tolerance (rtol 1e-8; booked loss within 1e-6 of the impact energy)."""
    (fast, (n_fast, handed), law, scene), (slow, _, _, _) = humid_member_runs
    assert n_fast == 1 and handed == 1
    a, b = fast.bounces[0], slow.bounces[0]
    impact = 0.5 * scene.body.mass * a.v_impact**2
    assert a.restitution == pytest.approx(b.restitution, rel=1e-6)
    assert a.energy_booked == pytest.approx(b.energy_booked, abs=1e-6 * impact)
    assert a.max_penetration == pytest.approx(b.max_penetration, rel=1e-6)
