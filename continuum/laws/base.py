"""What a contact law provides to the impact driver.

Following ASE's calculator idea, a law declares what it provides and the driver never cares
which law it has. Coordinates: `gap` h (m) is the height of the body's lowest point above the
contact datum; approach delta = -h. Forces are upward forces on the body (N, positive pushes the
body away from the surface). Energies are in J.

A law owns its own losses: dissipation is booked from the law's loss terms (e.g. the closed-form
area of a JKR hysteresis loop at each detachment), never taken as the leftover of an energy
balance, so the driver's energy audit can fail.
"""
from __future__ import annotations

from abc import ABC, abstractmethod


class ContactLaw(ABC):
    """A rate-independent contact law with optional history.

    Attributes
    ----------
    name : str
        Short identifier recorded in results.
    touch_gap : float
        Gap (m) at which contact begins on approach.
    bound_is_final : bool
        True if, once the body turns back towards the surface while still in contact, it can
        never leave (the law is elastic while attached, so the motion is a lossless oscillation).
    has_history : bool
        True if the force depends on the path (e.g. GW summits attached at the deepest approach).
        The driver then restarts the integrator at every extremum of the motion, so that no
        Runge-Kutta stage after an extremum uses the history from before it.
    time_dependent : bool
        True if the force also depends on the time since touch (capillary bridges condensing);
        the driver then calls `set_time` before every evaluation and cuts steps at `time_events`.
    has_rigid_approach : bool
        True if the law has a rigid approach branch and so a `quasi_static_depth(energy, weight)` (the rough
        rollers); the wet law sizes the bridges' extra pull with it.
    """

    name: str = "law"
    touch_gap: float = 0.0
    bound_is_final: bool = True
    has_history: bool = False
    time_dependent: bool = False
    has_rigid_approach: bool = False

    def set_time(self, t_contact: float) -> None:
        """Time-dependent laws (`time_dependent`): the contact time (s since this impact's touch) of the
        state that the next calls evaluate. The driver sets it before every evaluation."""

    def max_step(self, speed: float) -> float:
        """Largest integrator step (s) the law allows at the current contact time, for an impact at
        `speed` (m/s); the driver applies it whenever it (re)starts the integrator. Default: no limit."""
        return float("inf")

    def time_events(self) -> list[float]:
        """Contact times (s) at which the force jumps; the driver ends a step exactly there and restarts."""
        return []

    def prepare(self, mass: float, speed: float, gravity: float) -> None:
        """Called before each contact with the impact's mass (kg), speed (m/s) and gravity (m/s^2).

        Laws with a spatial grid size it here so that cost follows the impact; others ignore it.
        """

    def reset(self) -> None:
        """Start a new contact (history cleared)."""

    def forget_history(self) -> None:
        """Return the surfaces to their virgin state, for an independent run (a fresh body on a fresh spot).

        Laws whose state outlives a contact (a plastic flattening the next impact meets) clear it here;
        `reset` keeps it. Others have nothing to forget."""

    @abstractmethod
    def force(self, gap: float) -> float:
        """Upward contact force (N) at `gap` (m) on the current branch."""

    @abstractmethod
    def stiffness(self, gap: float) -> float:
        """Contact stiffness -dF/dgap = dP/d(delta) (N/m)."""

    @abstractmethod
    def stored_energy(self, gap: float) -> float:
        """Energy (J) stored in the contact relative to the state at touch."""

    @abstractmethod
    def release_gap(self) -> float:
        """Gap (m) at which the contact ends while the body moves away."""

    def dissipated(self, gap: float) -> float:
        """Energy (J) dissipated so far in this contact, as the law would book it at `gap`.

        Laws whose losses accrue during a contact (summits letting go one by one) report them
        here, including what a trial state at `gap` would release; laws that lose energy only at
        the release return 0 until then.
        """
        return 0.0

    def on_release(self) -> float:
        """The whole contact's loss, booked at release from the law's own loss terms (J)."""
        return 0.0

    def accept(self, gap: float) -> None:
        """Update history after an accepted integration step (stateless laws ignore it)."""

    def compiled(self, t0: float):
        """The law's compiled form for the contact that starts at `t0` (s), a
        `continuum.numerics.compiled_contact.CompiledLaw`, or None (the driver's Python stepper integrates it).
        Called after `prepare` and `reset`."""
        return None

    def compiled_commit(self, state, last_accept: float) -> None:
        """Take back the history `state` (the CompiledLaw's S) after a compiled contact whose last accepted
        state was `last_accept` s after touch."""

    def snapshot(self, gap: float) -> dict | None:
        """Spatial profiles at `gap` (pressure, deflection...) for laws that have them, else None."""
        return None

    @abstractmethod
    def length_scale(self, mass: float, speed: float) -> float:
        """A typical approach (m) for an impact of `mass` (kg) at `speed` (m/s): scales tolerances."""

    def diagnostics(self) -> dict:
        """What the law saw during the run that a reader should know (JSON-ready)."""
        return {}

    @abstractmethod
    def describe(self) -> dict:
        """JSON-ready description: name, equations' source, parameters (SI)."""
