"""A hysteretic contact law tabulated on one quasi-static approach-retraction cycle, for the impact driver.

The table is a `continuum.rough.quasistatic.ForceCycle`: the force on the body (N, + pushes it away) at rigid
separations s (m) stepped down to the deepest state and back, each state an equilibrium (from the boundary-element
reference, `continuum.rough.bem_reference`, or from a summit level). Between tabulated states the force is linear
in s, so every energy below is the exact integral of the force the driver sees, and the driver's energy audit
measures its integration alone.

Coordinates: the driver's gap is the separation s itself; contact starts at the table's first separation
(`touch_gap`, where the force range has not begun) and ends on the way out where the retraction's force is zero
for good (`release_gap`).

History: the body is on the approach branch while it goes deeper than it has been (gap below the deepest accepted
gap); above that gap it is on the retraction branch started from its turn s_t (the deepest accepted gap, which the
driver makes an accepted state at every extremum: `has_history`). The table holds one retraction, from its own
deepest state s_m; the body's is taken as that one shifted rigidly by s_t - s_m. That is exact only for a turn at
s_m, so the table must be made to turn where the body turns (its energy chosen for the table, or the table rerun to
the turn a first run found); `diagnostics()` records the shift, which the caller checks against the table's step.

Once the body turns back downwards while attached it can never leave: every later excursion runs a loop of this
rate-independent law, which only takes energy, and the body left the approach branch with less than the
retraction needs (Thornton & Ning, Powder Technol. 99 (1998) 154: capture) - `bound_is_final`, so the driver ends
the contact as stuck there.

Losses: stored(s) = work done on the contact along the path so far; at release that is the loop's area (for a turn at
s_m, W = -closed_integral F ds of the table, `ForceCycle.hysteresis_energy`), booked by `on_release`.
"""
from __future__ import annotations

from bisect import bisect_right

import numpy as np
from scipy.optimize import brentq

from ..laws.base import ContactLaw
from ..rough.quasistatic import ForceCycle

__all__ = ["PiecewiseLinear", "TabulatedCycleLaw"]


class PiecewiseLinear:
    """y(x) linear between nodes x (strictly increasing), extended below the first node along the first segment and
    held at the last node's value above it; with its exact integral from the first node."""

    def __init__(self, x, y):
        x, y = np.asarray(x, float), np.asarray(y, float)
        if x.ndim != 1 or x.size < 2 or not np.all(np.diff(x) > 0):
            raise ValueError("PiecewiseLinear needs >= 2 strictly increasing nodes")
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])
        # plain lists: the driver calls these one scalar at a time, where bisect beats numpy's per-call overhead
        self.x, self.y, self.cum = x.tolist(), y.tolist(), cum.tolist()
        self.slopes = (np.diff(y) / np.diff(x)).tolist()
        self._last = len(self.x) - 2

    def _segment(self, x: float) -> int:
        return min(max(bisect_right(self.x, x) - 1, 0), self._last)

    def __call__(self, x: float) -> float:
        if x >= self.x[-1]:
            return self.y[-1]
        k = self._segment(x)
        return self.y[k] + self.slopes[k] * (x - self.x[k])

    def slope(self, x: float) -> float:
        return 0.0 if x >= self.x[-1] else self.slopes[self._segment(x)]

    def integral(self, x: float) -> float:
        """int_{x[0]}^{x} y dx' (negative below x[0])."""
        if x >= self.x[-1]:
            return self.cum[-1] + self.y[-1] * (x - self.x[-1])
        k = self._segment(x)
        return self.cum[k] + 0.5 * (self.y[k] + self(x)) * (x - self.x[k])


class TabulatedCycleLaw(ContactLaw):
    """The contact law of one tabulated quasi-static cycle (module docstring). `label` names the table's source."""

    has_history = True
    bound_is_final = True

    def __init__(self, cycle: ForceCycle, label: str = "table"):
        s, f, t = np.asarray(cycle.separation, float), np.asarray(cycle.force, float), int(cycle.turn)
        if not (0 < t < s.size - 1):
            raise ValueError("the table needs an approach and a retraction")
        self.name, self.label = "tabulated_cycle", label
        self.approach = PiecewiseLinear(s[:t + 1][::-1], f[:t + 1][::-1])
        self.retraction = PiecewiseLinear(s[t:], f[t:])
        self.s_deepest, self.touch_gap = float(s[t]), float(s[0])
        nonzero = np.nonzero(f[t:] != 0.0)[0]
        self._release = float(s[t:][min(nonzero[-1] + 1, s.size - t - 1)]) if nonzero.size else float(s[t])
        self._work_top = self.approach.integral(self.touch_gap)     # int_{s_m}^{s_0} F_app ds
        self.step = float(np.max(np.abs(np.diff(s))))
        self.loop = float(cycle.hysteresis_energy)
        self.reset()

    def reset(self) -> None:
        self.deepest = np.inf          # deepest accepted gap of this contact
        self.turned = False
        self.turns: list[float] = []

    # -- branches --------------------------------------------------------------------------------------------------
    def _shift(self) -> float:
        return self.deepest - self.s_deepest

    def _approach_work(self, gap: float) -> float:
        """W_app(gap) = int_gap^{s_0} F_app ds, the work the body has done on the contact coming down to `gap`."""
        return self._work_top - self.approach.integral(gap)

    def _on_retraction(self, gap: float) -> bool:
        return np.isfinite(self.deepest) and gap > self.deepest

    def force(self, gap: float) -> float:
        if self._on_retraction(gap):
            return 0.0 if gap >= self.release_gap() else self.retraction(gap - self._shift())
        return 0.0 if gap >= self.touch_gap else self.approach(gap)

    def stiffness(self, gap: float) -> float:
        if self._on_retraction(gap):
            return 0.0 if gap >= self.release_gap() else -self.retraction.slope(gap - self._shift())
        return 0.0 if gap >= self.touch_gap else -self.approach.slope(gap)

    def stored_energy(self, gap: float) -> float:
        if self._on_retraction(gap):
            g = min(gap, self.release_gap()) - self._shift()
            return self._approach_work(self.deepest) - self.retraction.integral(g)
        return self._approach_work(min(gap, self.touch_gap))

    def release_gap(self) -> float:
        return self._release + (self._shift() if np.isfinite(self.deepest) else 0.0)

    def accept(self, gap: float) -> None:
        if gap < self.deepest:
            if self.turned:
                raise RuntimeError("the body went deeper after turning: bound_is_final should have ended the contact")
            self.deepest = gap
        elif np.isfinite(self.deepest) and gap > self.deepest and not self.turned:
            self.turned = True
            self.turns.append(self.deepest)

    def turn_for(self, speed: float, mass: float, gravity: float, below: float = 0.0) -> float:
        """Gap (m) at which a body of `mass` (kg) arriving at the touch at `speed` (m/s) turns on the approach branch:
        W_app(s) = 1/2 m v^2 + m g (s_touch - s), solved on the table's exact (piecewise quadratic) work, searched
        down to `below` (m) under the table's deepest state (along its last segment); -inf where that does not stop
        the body."""
        k0 = 0.5 * mass * speed * speed
        excess = lambda s: self._approach_work(s) - k0 - mass * gravity * (self.touch_gap - s)   # noqa: E731
        lowest = self.s_deepest - below
        if excess(lowest) < 0.0:
            return -np.inf
        scale = self.touch_gap - lowest
        return float(brentq(excess, lowest, self.touch_gap, xtol=1e-15 * scale, rtol=4 * np.finfo(float).eps))

    def on_release(self) -> float:
        return self.stored_energy(self.release_gap())

    def length_scale(self, mass: float, speed: float) -> float:
        return self.touch_gap - self.s_deepest

    def diagnostics(self) -> dict:
        turn = self.turns[-1] if self.turns else None
        return {"table": self.label, "table_deepest_m": self.s_deepest, "table_step_m": self.step,
                "turn_m": turn, "turn_shift_m": None if turn is None else turn - self.s_deepest,
                "turn_shift_over_step": None if turn is None else (turn - self.s_deepest) / self.step,
                "table_loop_J": self.loop}

    def describe(self) -> dict:
        return {"name": self.name, "table": self.label, "touch_gap_m": self.touch_gap,
                "deepest_m": self.s_deepest, "release_gap_m": self._release, "loop_J": self.loop,
                "source": "a quasi-static approach-retraction cycle (continuum.rough.quasistatic.ForceCycle), linear "
                          "between states; retraction from the body's turn = the table's shifted rigidly"}
