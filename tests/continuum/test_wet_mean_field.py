"""The rigid mean field with two classes of summits (continuum.laws.wet_mean_field): inside a bridge the JKR summits
adhere at W_wet, force and loop; outside at dgamma. Checked against the dry law (W_wet = dgamma), against a
brute-force quadrature of the split footprint integral written here from the GW density, and by the energy books of a
humid impact."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from continuum.laws.rough_rigid import RigidRoughRoller
from continuum.laws.wet import MeniscusBridges
from continuum.laws.wet_mean_field import TwoClassRigidRoller, WetMeanFieldRoller
from continuum.reference import jkr as ref
from continuum.rough.datum import tallest_summit
from continuum.rough.gw import GWJKRSurface
from continuum.rough.summits import SummitStatistics
from continuum.scene import resolve_scene

SIGMA, DENSITY, BETA = 6e-9, 1.0e13, 0.5e-6      # paper-like summits (m, 1/m^2, m)
E_STAR, W_DRY = 3.0e10, 0.042                   # Pa, J/m^2
RADIUS, LENGTH = 2.0e-6, 1.0e-5                 # roller (m)
D_K, F0, T_A, H1 = 1.08e-9, 1.6e-7, 1e-6, 0.34e-9


def _stats():
    return SummitStatistics(SIGMA, DENSITY, BETA)


def _roller(w: float) -> RigidRoughRoller:
    z = tallest_summit(SIGMA, DENSITY, RADIUS, LENGTH)["z_max"]
    law = RigidRoughRoller(GWJKRSurface(_stats(), w, E_STAR, z_max=z), RADIUS, LENGTH)
    law.size_for(2.0 * SIGMA, 1e-3)
    return law


def _two_class(w_wet: float) -> TwoClassRigidRoller:
    law = TwoClassRigidRoller.from_dry(_roller(W_DRY), _roller(w_wet), D_K)
    law.size_for(2.0 * SIGMA, 1e-3)
    return law


def _path(depth: float):
    """(gap, contact time): approach to -depth, t_a passed on the way down, retreat to beyond the Kelvin gap."""
    down = np.linspace(0.0, -depth, 120)
    up = np.linspace(-depth, 1.3 * D_K, 300)
    gaps = np.concatenate([down, up[1:]])
    times = np.linspace(0.0, 6.0 * T_A, gaps.size)
    return list(zip(gaps, times))


def test_wet_equal_to_dry_work_is_the_dry_mean_field_to_round_off():
    """W_wet = dgamma: whatever the class boundary does (bridges from t_a, growing, breaking on the way out), force,
    stored energy and booked energy are the dry law's, to round-off of the force and energy scales."""
    law, dry = _two_class(W_DRY), _roller(W_DRY)
    bridges = MeniscusBridges(_stats(), law.z_top, RADIUS, LENGTH, F0, D_K, T_A, H1)
    law.reset()
    dry.reset()
    f_scale = abs(dry.force(-2.0 * SIGMA))
    e_scale = abs(dry.stored_energy(-2.0 * SIGMA))
    crossed = 0
    for g, t in _path(2.0 * SIGMA):
        law.set_boundary(bridges.offset(g, t))
        crossed += math.isfinite(law.s_trial)
        assert law.force(g) == pytest.approx(dry.force(g), abs=1e-9 * f_scale)
        assert law.stored_energy(g) == pytest.approx(dry.stored_energy(g), abs=1e-9 * e_scale)
        assert law.dissipated(g) == pytest.approx(dry.dissipated(g), abs=1e-9 * e_scale)
        law.accept(g)
        dry.accept(g)
        bridges.accept(g, t)
    assert crossed > 100 and law.loops[1] > 0.0           # the two classes were both in play
    # run bare after a humid contact (the paper's humidity comparison runs the wet law's own dry part), it is dry
    wet_only = _two_class(0.3 * W_DRY)
    wet_only.reset()
    wet_only.set_boundary(-SIGMA)
    wet_only.reset()
    dry.reset()
    for g, _ in _path(2.0 * SIGMA):
        assert wet_only.force(g) == pytest.approx(dry.force(g), abs=1e-9 * f_scale)
        assert wet_only.dissipated(g) == pytest.approx(dry.dissipated(g), abs=1e-9 * e_scale)
        wet_only.accept(g)
        dry.accept(g)


def _density(law, u: float) -> float:
    """GW summits per unit u under the roller: 2 l n/sigma int_0^{x_m} phi((u + z_top + x^2/2R)/sigma) dx, truncated
    at the tallest summit (x_m^2 = -2 R u); Greenwood & Williamson (1966) with the roller's parabola."""
    if u >= 0.0:
        return 0.0
    xm = math.sqrt(-2.0 * RADIUS * u)
    inner = integrate.quad(lambda x: math.exp(-0.5 * ((u + law.z_top + x * x / (2.0 * RADIUS)) / SIGMA) ** 2),
                           0.0, xm, epsabs=0.0, epsrel=1e-11)[0]
    return 2.0 * LENGTH * DENSITY / SIGMA * inner / math.sqrt(2.0 * math.pi)


def _brute(law, what: str, h: float, w_wet: float, a_w: float, a_d: float, b_d: float) -> float:
    """int q rho over the wet summits u >= a_w (JKR at W_wet) and the dry ones a_d <= u < b_d (JKR at dgamma)."""
    def q(delta, w):
        if w == 0.0:                                   # Hertz (Johnson 1985 eq 4.23) and its work
            d = max(delta, 0.0)
            return (4.0 / 3.0 * E_STAR * math.sqrt(BETA) * d ** 1.5 if what == "force"
                    else 8.0 / 15.0 * E_STAR * math.sqrt(BETA) * d ** 2.5)
        return float(ref.force_from_approach(delta, BETA, w, E_STAR) if what == "force"
                     else ref.energy_from_approach(delta, BETA, w, E_STAR))

    def part(lo, hi, w):
        if not hi > lo:
            return 0.0
        pts = [p for p in (0.0,) if lo < p < hi]
        return integrate.quad(lambda d: q(d, w) * _density(law, h + d), lo, hi, points=pts or None, limit=200,
                              epsabs=0.0, epsrel=1e-9)[0]

    return part(a_w - h, -h, w_wet) + part(a_d - h, min(b_d - h, -h), W_DRY)


@pytest.mark.parametrize("ratio", [0.3, 0.0])
@pytest.mark.parametrize("state", [
    # (gap, deepest gap, offset s, lowest offset s_min) in units of the dry release stretch
    (-3.0, -6.0, -3.4, -3.6),        # on the way out: wet down to its release, dry ones below the lowest offset
    (-1.0, -6.0, -1.6, -1.8),        # the wet release cuts the wet class, the dry class cut by s_min
    (-4.5, -5.0, -4.8, -4.9),        # just after the turn: a thin stretched band bridged
    (-4.0, -5.0, -3.9, -4.2),        # boundary above the gap (class books after t_a): the band 0 < delta < s - h
])
def test_the_split_law_is_the_split_footprint_integral(state, ratio):
    """At states of the two classes the tables' split (T_wet(h, h - a_w) + T_dry(h, h - a_d) - T_dry(h, h - b_d)) is
    the footprint integral split at the bridges' boundary, done here by adaptive quadrature over the approach with the
    GW density and the JKR closed forms, on the classes written here from the physics: wet and attached u >= max(s,
    h - Delta_wet, h_min); dry and attached max(h - Delta_dry, h_min) <= u < s_min (D_K > Delta_wet: a summit that lost
    its bridge at D_K had let go inside it). Tolerance: 1e-8 (the quadrature's) plus 5x the tables' own error at the
    windows used, each table T(h, r) against the brute-force integral over delta >= -r (the GW tables' and the
    footprint quadrature's error off the nodes, docs/rough-gw.md); a wrong split misses whole bands of summits.
    W_wet = 0 (a liquid that wets between the solids): Hertz summits inside the bridges, released at delta = 0."""
    w_wet = ratio * W_DRY
    law = _two_class(w_wet)
    d = law.delta_dry
    h, h_min, s, s_min = (x * d for x in state)
    assert D_K > law.delta_wet
    law.reset()
    law.h_min, law.s, law.s_min, law.h_acc = h_min, s, s_min, h
    law.set_boundary(s)
    a_w = max(s, h - law.delta_wet, h_min)
    a_d, b_d = max(h - d, h_min), s_min
    assert a_d < b_d and a_w < 0.0                      # both classes hold attached summits here
    for what, fun in (("force", law.force), ("energy", law.stored_energy)):
        tables = sum(abs(law._above(x, what, h, a - h) - _brute(law, what, h, w_wet, *(
            (a, 0.0, 0.0) if x is law.wet else (math.inf, a, math.inf))))
            for x, a in ((law.wet, a_w), (law, a_d), (law, b_d)))
        brute = _brute(law, what, h, w_wet, a_w, a_d, b_d)
        assert tables < 1e-4 * abs(brute)
        assert fun(h) == pytest.approx(brute, abs=1e-8 * abs(brute) + 5.0 * tables)


def _humid_mean_field(w_wet_over_dry: float):
    """wet_silica (paper set) as a rigid mean field with bridges from t_a = 1 us and the 'wet' solid adhesion, its
    faces' W_SL set so that W_wet = w_wet_over_dry x dgamma (Dupre in the liquid: W_wet = dgamma + 2 gamma - 2 W_SL)."""
    from continuum.model.regime import first_impact_speed
    from continuum.model.select import select_law

    base = resolve_scene("wet_silica", params="paper").scene
    w, gamma = base.surfaces.interface_work_of_adhesion, base.menisci.surface_tension
    w_sl = 0.5 * (w + 2.0 * gamma - w_wet_over_dry * w)
    scene = resolve_scene("wet_silica", params="paper", overrides={
        "surfaces.roughness.mode": "mean_field", "menisci.condensation_time": 1e-6, "menisci.solid_adhesion": "wet",
        "surfaces.body.work_of_adhesion_sl": w_sl, "surfaces.substrate.work_of_adhesion_sl": w_sl}).scene
    v = first_impact_speed(scene)
    law, _ = select_law(scene, v, menisci=True)
    return scene, law


def test_a_humid_mean_field_impact_keeps_its_books_and_needs_the_class_change_work(monkeypatch):
    """One impact of the humid mean field whose bridged summits adhere at 0.3 dgamma: E_kin + E_pot + stored + booked
    constant to the driver's tolerance (1e-4 of the turnover at rtol 1e-8, as the discrete law's test); without the
    work booked when summits change class (the jump of their stored energy) the audit fails."""
    from continuum.dynamics.driver import DriverSettings, simulate

    scene, law = _humid_mean_field(0.3)
    assert isinstance(law, WetMeanFieldRoller)
    assert law.dry.wet.surface.work_of_adhesion == pytest.approx(0.3 * scene.surfaces.interface_work_of_adhesion)
    settings = DriverSettings(rtol=1e-8, max_bounces=1)
    run = simulate(law, scene.body.mass, 9.81, release_height=scene.release_height, settings=settings)
    assert law.diagnostics()["menisci"]["contacts_with_bridges"] >= 1
    assert law.dry.loops[1] > 0.0 and law.dry.switched != 0.0
    assert run.audit["max_relative_error"] < 1e-4

    pending = TwoClassRigidRoller._pending
    monkeypatch.setattr(TwoClassRigidRoller, "_pending", lambda self, gap: (*pending(self, gap)[:2], 0.0))
    scene, law = _humid_mean_field(0.3)
    run = simulate(law, scene.body.mass, 9.81, release_height=scene.release_height, settings=settings)
    assert run.audit["max_relative_error"] > 1e-3


def test_dense_discrete_realisations_of_the_wet_law_average_to_the_mean_field():
    """The same humid contact on discrete GW realisations (each summit its own bridge and class,
    continuum.laws.wet_summits) and on the mean field, along one quasi-static path of the roller's height above the
    summits' mean plane (approach past t_a, then retreat; each holds ~10^3 summits in contact). What humidity does
    to the force, F_humid - F_dry on the same summits (the realisation's scatter cancels in it), averages over the
    realisations to the mean field's within 4 standard errors of their mean, and that change is resolved (> 10 of
    them); the mean field that kept the dry law and the DMT pull inside its bridges misses it by more than 4."""
    from continuum.laws.discrete_roller import DiscreteRoughRoller
    from continuum.laws.wet_mean_field import wet_mean_field_roller
    from continuum.laws.wet_summits import wet_summit_roller

    w_wet, length = 0.3 * W_DRY, 1e-3
    params = {"bridge_pull_off": F0, "kelvin_gap": D_K, "condensation_time": T_A, "growth_length": H1}
    datum = tallest_summit(SIGMA, DENSITY, RADIUS, length)
    z = datum["z_max"]

    def mean_field(w):
        law = RigidRoughRoller(GWJKRSurface(_stats(), w, E_STAR, z_max=z), RADIUS, length)
        law.size_for(4.5 * SIGMA, 1e-3)
        return law

    dry_mf = mean_field(W_DRY)
    bridges = MeniscusBridges(_stats(), dry_mf.z_top, RADIUS, length, F0, D_K, T_A, H1)
    mf = wet_mean_field_roller(mean_field(W_DRY), mean_field(w_wet), bridges, params)
    mf.dry.size_for(4.5 * SIGMA, 1e-3)
    depth = 3.0 * SIGMA
    down = np.linspace(0.0, -depth, 40)
    up = np.linspace(-depth, -depth + 6.0 * mf.dry.delta_dry, 80)
    gaps = np.concatenate([down, up[1:]])
    times = np.linspace(0.0, 4.0 * T_A, gaps.size)
    check = np.arange(gaps.size)[30::8]

    def forces(law, offset):
        law.reset()
        out = []
        for k, (g, t) in enumerate(zip(gaps + offset, times)):
            law.set_time(t)
            if k in check:
                out.append(law.force(g))
            law.accept(g)
        return np.array(out)

    change_mf = forces(mf, 0.0) - forces(dry_mf, 0.0)
    runs = []
    for seed in range(6):
        kw = dict(seed=seed, half_space=False, footprint_half_width=datum["footprint_half_width"])
        dry = DiscreteRoughRoller(_stats(), W_DRY, E_STAR, RADIUS, length, 1e11, **kw)
        summits = dict(kw, summits=(dry.sx, dry.sy, dry.sz))
        wet = DiscreteRoughRoller(_stats(), w_wet, E_STAR, RADIUS, length, 1e11, **summits)
        alone = DiscreteRoughRoller(_stats(), W_DRY, E_STAR, RADIUS, length, 1e11, **summits)
        humid = wet_summit_roller(dry, wet, params)
        # the same height above the mean plane: each law's gap is measured from its own tallest summit
        offset = dry_mf.z_top - dry.z_top
        runs.append(forces(humid, offset) - forces(alone, offset))
    runs = np.array(runs)
    mean, sem = runs.mean(axis=0), runs.std(axis=0, ddof=1) / math.sqrt(len(runs))
    assert np.all(np.abs(mean - change_mf) <= 4.0 * sem)
    assert np.all(np.abs(change_mf) > 10.0 * sem)
    # the mean field as it was: dry summits inside the bridges, the DMT solid pull taken from the compressed ones
    from continuum.laws.wet import WetRoughRoller

    pull = 2.0 * math.pi * BETA * (W_DRY - w_wet)            # continuum.wet.menisci.solid_pull_inside_bridge
    old = WetRoughRoller(mean_field(W_DRY), MeniscusBridges(_stats(), dry_mf.z_top, RADIUS, length, F0, D_K, T_A, H1,
                                                           solid_pull=pull), params)
    old.dry.size_for(4.5 * SIGMA, 1e-3)
    change_old = forces(old, 0.0) - forces(dry_mf, 0.0)
    assert np.max(np.abs(mean - change_old) / sem) > 4.0
