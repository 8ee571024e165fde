"""Event-driven impact driver: closed-form free flight, adaptive contact phases, bounce records.

The body's state is its gap h (m, lowest point above the contact datum) and velocity v (m/s,
positive upward). Free flight under gravity g is integrated in closed form (no time steps):
h(t) = h0 + v0 t - g t^2/2. A contact starts when h falls to the law's `touch_gap` and is
integrated with an explicit 8th-order Runge-Kutta (Dormand-Prince DOP853, Hairer, Norsett &
Wanner, *Solving ODEs I*, §II.10) stepped by hand, so that history-dependent laws see every
accepted step, with events located on the dense output by Brent's method:

* maximum approach (v crosses 0 upward)   -> max penetration, law history update;
* release (h crosses the law's `release_gap` upward) -> contact ends, the law books its loss;
* turning back while still in contact (v crosses 0 downward) -> for laws that are elastic while
  attached (`bound_is_final`), the body can never leave: it is stuck (or at rest, for Hertz).

Laws with a compiled form (`ContactLaw.compiled`: the rigid rough roller's tables, and the wet law up
to t_a) run the same loop compiled (`continuum.numerics.contact_kernel`, ~1 ms a contact instead of ~0.1 s);
`DriverSettings(compiled=False)` keeps every contact on the Python stepper below.

Energy audit: E(t) = kinetic + gravitational + stored (law) + dissipated (law's own loss terms,
e.g. the JKR loop area at each release), normalised by the first impact's kinetic energy. The
dissipation is booked independently of the motion, so the audit measures the integrator's and
the laws' consistency and can fail.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from nanoimpact.interrupt import raise_if_interrupted

from ..laws.base import ContactLaw
from ..output.bounce import Bounce

_EPS = float(np.finfo(float).eps)


@dataclass
class Trace:
    """Time series: time (s), gap (m), velocity (m/s), contact force (N), phase (-1 flight, else bounce index)."""

    t: list = field(default_factory=list)
    gap: list = field(default_factory=list)
    velocity: list = field(default_factory=list)
    force: list = field(default_factory=list)
    phase: list = field(default_factory=list)
    energy: list = field(default_factory=list)

    def add(self, t, gap, velocity, force, phase, energy):
        self.t.append(t)
        self.gap.append(gap)
        self.velocity.append(velocity)
        self.force.append(force)
        self.phase.append(phase)
        self.energy.append(energy)

    def arrays(self) -> dict:
        return {k: np.asarray(getattr(self, k)) for k in ("t", "gap", "velocity", "force", "phase", "energy")}


@dataclass
class ImpactRun:
    """Outcome of a simulation. `status` is one of rest, stuck, escaped, max_bounces, max_time."""

    bounces: list[Bounce]
    status: str
    trace: Trace
    audit: dict

    @property
    def stuck(self) -> bool:
        return self.status == "stuck"

    def bounce_dicts(self) -> list[dict]:
        return [asdict(b) for b in self.bounces]


@dataclass(frozen=True)
class DriverSettings:
    """Numerical settings of the driver (see numerics.* in the scene schema)."""

    rtol: float = 1e-10
    max_bounces: int = 100
    max_time: float = 10.0
    rest_fraction: float = 1e-3
    samples_per_flight: int = 64
    samples_per_step: int = 3
    #: integrate contacts of laws with a compiled form (`ContactLaw.compiled`) with the compiled kernel
    #: (`continuum.numerics.contact_kernel`, the same DOP853 algorithm); False: always the Python stepper
    compiled: bool = True
    #: take the law's profiles (`ContactLaw.snapshot`) at maximum approach and at pull-off into
    #: `Bounce.profiles`; False: none (a run read for its outcome only: the motion is the same, and a rough law's
    #: snapshot is a footprint quadrature that costs about as much as the contact itself)
    profiles: bool = True


def flight_time_to(gap0: float, v0: float, gravity: float, target: float) -> float:
    """Time (s) for closed-form free flight from (gap0, v0) to reach `target` moving down; inf if never."""
    if gravity == 0.0:
        return (target - gap0) / v0 if v0 < 0.0 else math.inf
    disc = v0 * v0 + 2.0 * gravity * (gap0 - target)
    if disc < 0.0:
        return math.inf
    return (v0 + math.sqrt(disc)) / gravity


def simulate(law: ContactLaw, mass: float, gravity: float, *, release_height: float | None = None,
             impact_velocity: float | None = None, settings: DriverSettings = DriverSettings(),
             progress: Callable[[Bounce], None] | None = None) -> ImpactRun:
    """Drop or throw a body of `mass` (kg) onto the surface described by `law`.

    Give `release_height` (m above the touch level `law.touch_gap`, from rest) or `impact_velocity` (m/s at
    touch).
    """
    if (release_height is None) == (impact_velocity is None):
        raise ValueError("give exactly one of release_height and impact_velocity")
    touch = law.touch_gap
    if release_height is not None:
        t, gap, v = 0.0, touch + release_height, 0.0
        height_scale = release_height
    else:
        t, gap, v = 0.0, touch, -abs(impact_velocity)
        height_scale = impact_velocity**2 / (2.0 * gravity) if gravity > 0 else math.inf
    ledger = _Ledger(mass, gravity)
    ledger.e0 = ledger.energy(gap, v, 0.0)
    bounces: list[Bounce] = []
    status = "max_bounces"
    for index in range(settings.max_bounces):
        arrival = _fly(ledger, t, gap, v, gravity, touch, settings)
        if isinstance(arrival, str):
            status = arrival
            break
        t, gap, v = arrival
        if ledger.ek_ref is None:
            ledger.ek_ref = 0.5 * mass * v * v
        outcome = _ContactRun(law, mass, gravity, t, gap, v, settings, index, ledger).run()
        raise_if_interrupted()
        ledger.booked += outcome["booked"]
        b = outcome["bounce"]
        if b is not None:
            bounces.append(b)
            if progress:
                progress(b)
        t, gap, v = outcome["t"], outcome["gap"], outcome["v"]
        if outcome["end"] is not None:
            status = outcome["end"]
            break
        if gravity == 0.0:
            status = "escaped"
            ledger(t, gap, v, 0.0, -1, 0.0)
            break
        if b.rebound_height is not None and b.rebound_height < settings.rest_fraction * height_scale:
            status = "rest"
            ledger(t, gap, v, 0.0, -1, 0.0)
            break
    return ImpactRun(bounces, status, ledger.trace, ledger.audit())


class _Ledger:
    """The run's samples and its energy audit. E(t) = kinetic + gravitational + stored + booked (+ the current
    contact's dissipation not yet booked) against E(0) = `e0`; relative to the first impact's kinetic energy
    `ek_ref` and to the turnover, the largest kinetic + |stored| + dissipated energy of the run. Called as
    `ledger(t, gap, v, force, phase, stored, extra_booked)` for one sample, `ledger.block(rows, phase)` for many."""

    def __init__(self, mass: float, gravity: float):
        self.mass, self.gravity = mass, gravity
        self.trace = Trace()
        self.booked = 0.0                 # dissipated energy booked by the law (J)
        self.e0 = None                    # total energy at start (J)
        self.ek_ref = None                # first impact kinetic energy (J)
        self.worst = 0.0
        self.worst_abs = 0.0              # largest |E(t) - E(0)| (J)
        self.turnover = 0.0               # largest energy in play: kinetic + |stored| + dissipated (J)

    def energy(self, gap_, v_, stored, extra_booked=0.0):
        mass = self.mass
        return 0.5 * mass * v_ * v_ + mass * self.gravity * gap_ + stored + self.booked + extra_booked

    def __call__(self, t_, gap_, v_, force_, phase_, stored, extra_booked=0.0):
        """Add a sample; `extra_booked` is dissipation of the current contact not yet in `booked`."""
        e = self.energy(gap_, v_, stored, extra_booked)
        self.trace.add(t_, gap_, v_, force_, phase_, e)
        self.turnover = max(self.turnover, 0.5 * self.mass * v_ * v_ + abs(stored) + self.booked + extra_booked)
        if self.e0 is not None:
            self.worst_abs = max(self.worst_abs, abs(e - self.e0))
            if self.ek_ref:
                self.worst = max(self.worst, abs(e - self.e0) / self.ek_ref)

    def block(self, rows: np.ndarray, phase_: int) -> None:
        """Many samples at once: rows of the compiled kernel (t, gap, v, force, stored, dissipated, kind), kind 1
        the instant after release (phase -1, no force, nothing stored, the loss booked)."""
        if len(rows) == 0:
            return
        mass, trace = self.mass, self.trace
        t_, gap_, v_, f_, stored, extra, kind = rows.T
        after = kind != 0.0
        f_ = np.where(after, 0.0, f_)
        stored = np.where(after, 0.0, stored)
        phases = np.where(after, -1, phase_)
        kinetic = 0.5 * mass * v_ * v_
        e = kinetic + mass * self.gravity * gap_ + stored + self.booked + extra
        trace.t.extend(t_.tolist())
        trace.gap.extend(gap_.tolist())
        trace.velocity.extend(v_.tolist())
        trace.force.extend(f_.tolist())
        trace.phase.extend(phases.tolist())
        trace.energy.extend(e.tolist())
        self.turnover = max(self.turnover, float(np.max(kinetic + np.abs(stored) + self.booked + extra)))
        dev = float(np.max(np.abs(e - self.e0)))
        self.worst_abs = max(self.worst_abs, dev)
        if self.ek_ref:
            self.worst = max(self.worst, dev / self.ek_ref)

    def audit(self) -> dict:
        turnover = self.turnover
        return {"max_relative_error": self.worst, "reference": "first impact kinetic energy",
                "reference_energy": self.ek_ref, "dissipated_booked": self.booked,
                "max_error_over_turnover": self.worst_abs / turnover if turnover > 0 else 0.0,
                "turnover": turnover,
                "turnover_note": "largest kinetic + |stored| + dissipated energy of the run: where adhesion releases "
                                 "far more energy than the impact brings, table errors scale with it, not with the "
                                 "impact energy"}


def _fly(record, t, gap, v, gravity, touch, settings: DriverSettings):
    """Free flight in closed form from (t, gap, v), sampled into `record`: (t, gap, v) at the next touch, the
    arrival speed from energy conservation (exact), or how the run ends ('escaped', 'max_time')."""
    dt = flight_time_to(gap, v, gravity, touch) if gap > touch or v > 0.0 else 0.0
    if not math.isfinite(dt):
        record(t, gap, v, 0.0, -1, 0.0)
        return "escaped"
    if t + dt > settings.max_time:
        dt_end = settings.max_time - t
        for s in np.linspace(0.0, dt_end, settings.samples_per_flight):
            record(t + s, gap + v * s - 0.5 * gravity * s * s, v - gravity * s, 0.0, -1, 0.0)
        return "max_time"
    for s in np.linspace(0.0, dt, settings.samples_per_flight)[:-1]:
        record(t + s, gap + v * s - 0.5 * gravity * s * s, v - gravity * s, 0.0, -1, 0.0)
    v = -math.sqrt(v * v + 2.0 * gravity * (gap - touch))
    return t + dt, touch, v


class _ContactRun:
    """One contact from touch: integrated compiled where the law has a compiled form, else (and after a time event
    the kernel stops at) stepped here with events; the law's history sees every accepted step and every extremum.
    `run()` returns the bounce record, the end state and the loss the law booked."""

    def __init__(self, law: ContactLaw, mass, gravity, t0, gap0, v0, settings: DriverSettings, index, record):
        self.law, self.mass, self.gravity = law, mass, gravity
        self.t0, self.gap0, self.v0 = t0, gap0, v0
        self.settings, self.index, self.record = settings, index, record
        self.speed = speed = abs(v0)
        law.prepare(mass, speed, gravity)
        law.reset()
        self.length = law.length_scale(mass, speed)
        self.atol = np.array([settings.rtol * self.length, settings.rtol * speed]) * 0.1
        self.timed = law.time_dependent
        self.event_times = list(law.time_events()) if self.timed else []
        self.pending_times = sorted(t0 + te for te in self.event_times)
        self.e_mech_in = 0.5 * mass * v0 * v0 + mass * gravity * gap0
        self.pull_force, self.after_max = math.inf, False
        self.profiles: dict = {}
        self.peak_force = self.max_pen = None

    def at(self, s):
        """Tell a time-dependent law the contact time of the state it evaluates next. At a time event (absolute
        t0 + t_e) the law gets t_e itself: s - t0 rounds to either side of it, and the law changes exactly there
        (bridges condense on the summits in contact at t_a, and its step limit starts)."""
        if self.timed:
            tc = s - self.t0
            for e in self.event_times:
                if abs(tc - e) <= 4.0 * _EPS * abs(s):
                    tc = e
            self.law.set_time(tc)

    def rhs(self, _t, y):
        self.at(_t)
        return np.array([y[1], self.law.force(y[0]) / self.mass - self.gravity])

    def start(self, t_start, y_start):
        self.at(t_start)
        first = 1e-3 * self.length / self.speed
        cap = self.law.max_step(self.speed)
        return DOP853(self.rhs, t_start, np.asarray(y_start, float), t_bound=self.settings.max_time,
                      rtol=self.settings.rtol, atol=self.atol, first_step=min(first, cap), max_step=cap)

    def sample(self, s, gap_, v_):
        law = self.law
        self.at(s)
        f = law.force(gap_)
        self.record(s, gap_, v_, f, self.index, law.stored_energy(gap_), law.dissipated(gap_))
        if self.after_max and f < self.pull_force and self.settings.profiles:
            snap = law.snapshot(gap_)
            if snap is not None:
                self.pull_force = f
                self.profiles["pull_off"] = {"t": s, "gap": gap_, "force": f, **snap}

    def finish(self, t_end, gap_end, v_end, end, booked):
        self.at(t_end)
        mass, gravity, speed, t0 = self.mass, self.gravity, self.speed, self.t0
        e_mech_out = 0.5 * mass * v_end * v_end + mass * gravity * gap_end
        free = end is None
        rebound = None
        if free and gravity > 0.0:
            rebound = gap_end + v_end * v_end / (2.0 * gravity) - self.law.touch_gap
        b = Bounce(index=self.index, t_contact=t0, t_release=t_end if free else None,
                   duration=(t_end - t0) if free else None, v_impact=speed,
                   v_rebound=abs(v_end) if free else 0.0,
                   restitution=abs(v_end) / speed if free else 0.0,
                   peak_force=self.peak_force, max_penetration=self.max_pen, rebound_height=rebound,
                   energy_lost=self.e_mech_in - e_mech_out if free else math.nan, energy_booked=booked,
                   profiles=self.profiles or None)
        return {"bounce": b, "t": t_end, "gap": gap_end, "v": v_end, "end": end, "booked": booked}

    def run(self) -> dict:
        law, settings = self.law, self.settings
        compiled = law.compiled(self.t0) if settings.compiled else None
        kernel = None
        if compiled is not None:
            from ..numerics.compiled_contact import run_compiled
            kernel = run_compiled(compiled, self.mass, self.gravity, self.t0, self.gap0, self.v0, rtol=settings.rtol,
                                  atol=self.atol, first_step=1e-3 * self.length / self.speed,
                                  max_step=law.max_step(self.speed), t_bound=settings.max_time,
                                  release=law.release_gap(), bound_is_final=law.bound_is_final,
                                  has_history=law.has_history, samples_per_step=settings.samples_per_step)
        if kernel is not None:
            continued = False
            while kernel is not None:
                done, solver = self._take_kernel(compiled, kernel, continued)
                if done is not None:
                    return done
                # a time event: the law may go on compiled from there (bridges on discrete summits after t_a)
                compiled = law.compiled(self.t0)
                if compiled is None:
                    break
                continued = True
                kernel = run_compiled(compiled, self.mass, self.gravity, solver.t, solver.y[0], solver.y[1],
                                      rtol=settings.rtol, atol=self.atol, first_step=1e-3 * self.length / self.speed,
                                      max_step=law.max_step(self.speed), t_bound=settings.max_time,
                                      release=law.release_gap(), bound_is_final=law.bound_is_final,
                                      has_history=law.has_history, samples_per_step=settings.samples_per_step,
                                      after_max=self.after_max)
        else:
            solver = self.start(self.t0, [self.gap0, self.v0])
            self.at(self.t0)
            self.peak_force = law.force(self.gap0)
            self.max_pen = -self.gap0
            self.sample(self.t0, self.gap0, self.v0)
        return self._step(solver)

    def _take_kernel(self, compiled, kernel, continued=False):
        """Take over what the compiled kernel did: its samples, the profiles the Python stepper takes (at the first
        maximum approach, and at the lowest force after it), and its end; a time event hands the contact back to
        the Python stepper. `continued`: the kernel went on from a time event the Python law already sampled
        (its first sample is that one). Returns (the contact's outcome or None, the stepper to go on with)."""
        law, profiles = self.law, self.profiles
        law.compiled_commit(compiled.S, kernel.last_accept - self.t0)
        if continued:
            self.record.block(kernel.samples[1:], self.index)
            self.peak_force = max(self.peak_force, kernel.peak_force)
            self.max_pen = max(self.max_pen, kernel.max_penetration)
        else:
            self.record.block(kernel.samples, self.index)
            self.peak_force, self.max_pen = kernel.peak_force, kernel.max_penetration
        if kernel.max_approach is not None and "max_approach" not in profiles:
            te, ge = kernel.max_approach
            self.at(te)
            snap = law.snapshot(ge) if self.settings.profiles else None
            if snap is not None:
                profiles["max_approach"] = {"t": te, "gap": ge, "force": law.force(ge), **snap}
            self.after_max = True
        if kernel.pull_off is not None and self.settings.profiles and kernel.pull_off[2] < self.pull_force:
            te, ge, fe = kernel.pull_off
            self.at(te)
            snap = law.snapshot(ge)
            if snap is not None:
                self.pull_force = fe
                profiles["pull_off"] = {"t": te, "gap": ge, "force": fe, **snap}
        if kernel.end != "stop_time":
            return self.finish(kernel.t, kernel.gap, kernel.v, kernel.end, kernel.booked), None
        # the law's force jumps here (a time event): the Python law samples and accepts it and goes on
        te, ye = kernel.t, [kernel.gap, kernel.v]
        self.at(te)
        self.sample(te, ye[0], ye[1])
        law.accept(ye[0])
        return None, self.start(te, ye)

    def _step(self, solver) -> dict:
        """DOP853 steps until the contact ends: dense samples between steps, then the step's events in time
        order; the law accepts every step's end."""
        law, settings = self.law, self.settings
        while True:
            release = law.release_gap()       # may grow during a contact (bridges hold beyond the dry release)
            t_prev, y_prev = solver.t, solver.y.copy()
            msg = solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"contact integration failed at t = {solver.t:.6g} s: {msg}")
            t1, y1 = solver.t, solver.y.copy()
            dense = solver.dense_output()
            events = self._events(t_prev, y_prev, t1, y1, dense, release)
            for s in np.linspace(t_prev, t1, settings.samples_per_step + 2)[1:-1]:
                if events and s >= events[0][0]:
                    break
                y = dense(s)
                self.sample(s, y[0], y[1])
            done, restart = self._on_events(events, dense, release)
            if done is not None:
                return done
            if restart is not None:
                solver = self.start(*restart)
                continue
            self.at(t1)
            self.max_pen = max(self.max_pen, -y1[0])
            self.peak_force = max(self.peak_force, law.force(y1[0]))
            self.sample(t1, y1[0], y1[1])
            self.at(t1)
            law.accept(y1[0])
            if solver.status == "finished":
                return self.finish(t1, y1[0], y1[1], "max_time", 0.0)

    def _events(self, t_prev, y_prev, t1, y1, dense, release) -> list:
        """The events inside the step (time, kind), in time order: maximum approach, turning back, release, and
        a time event of the law."""
        events = []
        if y_prev[1] < 0.0 <= y1[1]:
            events.append((_root(lambda s: dense(s)[1], t_prev, t1), "max_approach"))
        t_turn = None
        if y_prev[1] > 0.0 >= y1[1]:
            t_turn = _root(lambda s: dense(s)[1], t_prev, t1)
            events.append((t_turn, "turn"))
        if y_prev[0] < release <= y1[0]:
            events.append((_root(lambda s: dense(s)[0] - release, t_prev, t1), "release"))
        elif y_prev[0] < release and t_turn is not None and dense(t_turn)[0] >= release:
            # the gap crossed the release point and came back within one step (slow release):
            # the endpoints miss it, the turning point does not
            events.append((_root(lambda s: dense(s)[0] - release, t_prev, t_turn), "release"))
        pending = self.pending_times
        while pending and pending[0] <= t_prev:
            pending.pop(0)
        if pending and pending[0] <= t1:
            # the law's force jumps here (e.g. bridges condense at t_a): end the step exactly there
            events.append((pending.pop(0), "time"))
        events.sort()
        return events

    def _on_events(self, events, dense, release):
        """Handle a step's events in order (`release`: the step's release gap). Returns (the contact's outcome or
        None, (t, y) to restart from or None): extrema of the gap update the history, after which a history law
        restarts the step there."""
        law, profiles = self.law, self.profiles
        restart = None
        for te, kind in events:
            ye = dense(te)
            self.at(te)
            if kind == "time":
                self.sample(te, ye[0], ye[1])
                law.accept(ye[0])
                return None, (te, [ye[0], ye[1]])
            if kind in ("max_approach", "turn"):
                # extrema of the gap: history must see them (paper notes on eq 11)
                self.max_pen = max(self.max_pen, -ye[0])
                self.peak_force = max(self.peak_force, law.force(ye[0]))
                self.sample(te, ye[0], 0.0)
                if kind == "max_approach" and "max_approach" not in profiles and self.settings.profiles:
                    snap = law.snapshot(ye[0])
                    if snap is not None:
                        profiles["max_approach"] = {"t": te, "gap": ye[0], "force": law.force(ye[0]), **snap}
                    self.after_max = True
                law.accept(ye[0])
                if law.has_history:
                    # stages after the extremum used the old history: cut the step here, restart
                    restart = (te, [ye[0], 0.0])
            if kind == "turn" and law.bound_is_final:
                end = "stuck" if law.force(ye[0]) < self.mass * self.gravity or self.gravity == 0.0 else "rest"
                return self.finish(te, ye[0], 0.0, end, law.dissipated(ye[0])), None
            if kind == "release":
                gap_r, v_r = release, ye[1]
                self.sample(te, gap_r, v_r)
                loss = law.on_release()
                # the instant after: nothing stored, the law's loss terms are booked as dissipated
                self.record(te, gap_r, v_r, 0.0, -1, 0.0, extra_booked=loss)
                return self.finish(te, gap_r, v_r, None, loss), None
            if restart is not None:
                break
        return None, restart


def _root(fun, a, b):
    fa, fb = fun(a), fun(b)
    if fa == 0.0:
        return a
    if fb == 0.0 or fa * fb > 0.0:
        return b
    return brentq(fun, a, b, xtol=1e-30, rtol=4 * np.finfo(float).eps, maxiter=200)
