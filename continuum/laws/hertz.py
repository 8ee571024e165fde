"""Non-adhesive Hertz contact laws: sphere, and a roller (line contact) with log stiffness.

Sources: Johnson, *Contact Mechanics* (1985) §4.2 (sphere, eqs 4.22-4.23; line-contact
half-width); the roller's approach W = pi l E* delta / (2 ln(2l/b) + 1) is the paper's eq 1 (its
ref. [19]) with b = sqrt(4WR/(pi E* l)) in Johnson's E* convention. Johnson §5.6 explains why the
approach of a finite cylinder needs such a length-dependent log term (see docs/model.md).
"""
from __future__ import annotations

import math

from ..reference import hertz as ref
from .base import ContactLaw


class HertzSphere(ContactLaw):
    """Hertz sphere on a flat: P = 4/3 E* sqrt(R) delta^{3/2}."""

    name = "hertz_sphere"

    def __init__(self, radius: float, e_star: float):
        self.radius, self.e_star = radius, e_star

    def force(self, gap):
        return float(ref.sphere_force(max(-gap, 0.0), self.radius, self.e_star))

    def stiffness(self, gap):
        return float(ref.sphere_stiffness(max(-gap, 0.0), self.radius, self.e_star))

    def stored_energy(self, gap):
        return float(ref.sphere_energy(max(-gap, 0.0), self.radius, self.e_star))

    def release_gap(self):
        return 0.0

    def length_scale(self, mass, speed):
        return (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4

    def describe(self):
        return {"name": self.name, "source": "Johnson (1985) eqs 4.22-4.23",
                "radius": self.radius, "e_star": self.e_star}


class HertzLine(ContactLaw):
    """Roller of radius R and length l, W(delta) from the paper's eq 1 solved exactly.

    With D = pi l E* delta and the log factor q = 2 ln(2l/b) + 1, eq 1 reads W q = D with
    q = C - ln W (C from `reference.hertz`), i.e. q - ln q = C - ln D. The reference module solves
    this through Lambert's W_{-1} for arrays; the driver calls the law one scalar at a time, so
    here the same root is found by Newton's method on g(q) = q - ln q - (C - ln D) (g convex,
    g' = 1 - 1/q > 0 on the physical branch q > 1) in pure-float arithmetic, warm-started from
    the previous call. `tests/continuum/test_laws.py` checks it against the reference to 1e-12.
    """

    name = "hertz_line_implicit"

    def __init__(self, radius: float, length: float, e_star: float):
        self.radius, self.length, self.e_star = radius, length, e_star
        self._ple = math.pi * length * e_star
        self._c = float(ref._line_c(radius, length, e_star))
        self._q_min = float(ref._log_factor_min())
        self._cache = (None, 0.0, math.inf)

    def _solve(self, delta: float) -> tuple[float, float]:
        """(W in N, log factor q) at approach delta (m)."""
        if delta <= 0.0:
            return 0.0, math.inf
        if self._cache[0] == delta:
            return self._cache[1], self._cache[2]
        rhs = self._c - math.log(self._ple * delta)
        q = self._cache[2] if math.isfinite(self._cache[2]) else max(rhs + math.log(max(rhs, 2.0)), 2.0)
        for _ in range(50):
            step = (q - math.log(q) - rhs) / (1.0 - 1.0 / q)
            q -= step
            if abs(step) <= 1e-15 * q:
                break
        if q < self._q_min:
            raise ValueError(f"roller approach {delta:.3e} m exceeds the line-contact limit (b > l)")
        load = self._ple * delta / q
        self._cache = (delta, load, q)
        return load, q

    def force(self, gap):
        return self._solve(-gap)[0]

    def stiffness(self, gap):
        load, q = self._solve(-gap)
        return self._ple / (q - 1.0) if load > 0.0 else 0.0

    def stored_energy(self, gap):
        load, q = self._solve(-gap)
        return load * load * (0.5 * q - 0.25) / self._ple if load > 0.0 else 0.0

    def release_gap(self):
        return 0.0

    def length_scale(self, mass, speed):
        return float(ref.line_impact_max_approach(mass, speed, self.radius, self.length, self.e_star))

    def describe(self):
        return {"name": self.name, "source": "paper eq 1 (E* convention fixed, Johnson 1985 §4.2), b(W) solved exactly",
                "radius": self.radius, "length": self.length, "e_star": self.e_star}


class LinearSpring(ContactLaw):
    """Constant-K linearisation of the roller contact (paper eqs 1-2): W = K delta."""

    name = "hertz_line_constant"

    def __init__(self, stiffness: float, provenance: dict | None = None):
        self.k = stiffness
        self.provenance = provenance or {}

    def force(self, gap):
        return self.k * max(-gap, 0.0)

    def stiffness(self, gap):
        return self.k if gap < 0.0 else 0.0

    def stored_energy(self, gap):
        return 0.5 * self.k * max(-gap, 0.0) ** 2

    def release_gap(self):
        return 0.0

    def length_scale(self, mass, speed):
        return speed * math.sqrt(mass / self.k)

    def describe(self):
        return {"name": self.name, "source": "paper eqs 1-2 (linearised)", "stiffness": self.k, **self.provenance}


def roller_constant_stiffness(mass: float, speed: float, radius: float, length: float, e_star: float,
                              tol: float = 1e-14) -> tuple[float, float]:
    """K of paper eq 1 with b taken at the impact's own peak load W = v sqrt(M K) (paper eq 2).

    A fixed point: K depends on b(W) only logarithmically, so plain iteration converges in a
    handful of steps. Returns (K in N/m, peak load W in N).
    """
    k = math.pi * length * e_star / 20.0
    for _ in range(200):
        load = speed * math.sqrt(mass * k)
        k_new = float(ref.line_stiffness(load, radius, length, e_star))
        if abs(k_new - k) <= tol * k:
            return k_new, speed * math.sqrt(mass * k_new)
        k = k_new
    raise RuntimeError("roller stiffness fixed point did not converge")
