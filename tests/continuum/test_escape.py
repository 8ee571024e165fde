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
