"""The escape-velocity bisection recovers the closed-form JKR escape velocity sqrt(2 loop / M)."""
import math

import pytest

from continuum.dynamics.escape import escape_velocity
from continuum.laws.jkr import JKRSphere

RADIUS, W, E_STAR = 5e-6, 0.1, 37.6e9
MASS = 4 / 3 * math.pi * RADIUS**3 * 2200.0


@pytest.mark.parametrize("detachment", ["displacement", "load"])
def test_bisection_finds_jkr_escape_velocity(detachment):
    law = JKRSphere(RADIUS, W, E_STAR, detachment)
    exact = law.escape_velocity(MASS)
    found = escape_velocity(law, MASS, 0.0, exact / 10, exact * 10, rel_tol=1e-4)
    assert found["lower"] <= exact * (1 + 1e-6) and found["upper"] >= exact * (1 - 1e-6)
    assert found["escape_velocity"] == pytest.approx(exact, rel=1e-4, abs=0)


def test_bracket_that_misses_the_transition_is_refused():
    law = JKRSphere(RADIUS, W, E_STAR)
    exact = law.escape_velocity(MASS)
    with pytest.raises(ValueError, match="below the bracket"):
        escape_velocity(law, MASS, 0.0, 2 * exact, 4 * exact)
    with pytest.raises(ValueError, match="above the bracket"):
        escape_velocity(law, MASS, 0.0, exact / 4, exact / 2)


@pytest.mark.parametrize("compiled", [True, False])
def test_an_outcome_only_impact_has_the_same_outcome_without_samples_or_profiles(compiled):
    """series=False (the escape searches' and sweeps' runs) drops the samples inside steps and the profiles; the
    steps and events are the same, so the outcome is too (a rough law whose snapshots are footprint quadratures,
    on the compiled kernel and on the Python stepper). Negative control: the full run does hold more samples and
    its profiles."""
    from continuum.dynamics.driver import DriverSettings, simulate
    from continuum.dynamics.impact import first_impact_speed
    from continuum.model import select_law
    from continuum.scene import resolve_scene
    from nanoimpact.data import shipped_root

    resolved = resolve_scene(shipped_root() / "scenes" / "rough_silica.toml", params="paper",
                             overrides={"physics.half_space": "off", "numerics.fidelity": "fast"})
    sc = resolved.scene
    v = first_impact_speed(resolved)
    law = select_law(sc, v)[0]
    runs = []
    for series in (True, False):
        law.forget_history()
        runs.append(simulate(law, sc.body.mass, sc.environment.gravity, impact_velocity=v, settings=DriverSettings(
            rtol=sc.numerics.rtol, max_bounces=1, max_time=1.0, samples_per_flight=2,
            samples_per_step=3 if series else 0, profiles=series, compiled=compiled)))
    full, bare = runs
    assert full.status == bare.status and len(full.bounces) == len(bare.bounces) == 1
    a, b = full.bounces[0], bare.bounces[0]
    for key in ("duration", "v_rebound", "restitution", "peak_force", "max_penetration", "energy_lost"):
        x, y = getattr(a, key), getattr(b, key)
        assert (x is None and y is None) or x == pytest.approx(y, rel=1e-12, abs=0), key
    assert a.profiles and "max_approach" in a.profiles and b.profiles is None
    assert len(bare.trace.t) < len(full.trace.t)
