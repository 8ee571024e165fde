"""Run one contact through the compiled kernel (`continuum.numerics.contact_kernel`) for laws that have a compiled form.

A law offers one through `ContactLaw.compiled()` (a `CompiledLaw`: kind, parameters, tables, history)
and takes the history back through `ContactLaw.compiled_commit`. `run_compiled` calls the kernel and
returns what the driver needs: the samples to record, how the contact ended and where. It returns
None where the kernel could not finish the contact (a state deeper than the law's tables, where the
Python law evaluates its integral directly; or a step-size underflow, which the Python stepper then
reports with its own message): the driver then integrates that contact with the Python DOP853
stepper, the same algorithm, from the start (the law's history is committed only on success).
`KernelStats` counts both paths per process (the benchmarks report them).
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from . import contact_kernel as ck
from . import kernel_laws as kl

log = logging.getLogger(__name__)

#: Samples a contact may record before the buffer is enlarged (4x) and the contact run again.
FIRST_BUFFER_SAMPLES = 4096
#: Largest buffer (samples) tried before the contact goes to the Python stepper.
MAX_BUFFER_SAMPLES = 4096 * 64

END_NAMES = {ck.END_RELEASE: None, ck.END_STUCK: "stuck", ck.END_REST: "rest", ck.END_MAX_TIME: "max_time",
             ck.END_STOP_TIME: "stop_time"}


@dataclass
class CompiledLaw:
    """A law's compiled form: `kind` (kernel_laws.LAW_*), parameters P, tables T (a tuple of 8 arrays) and
    history S (float arrays, SI); the kernel updates a copy of S, committed back to the law on success."""

    kind: int
    P: np.ndarray
    T: tuple
    S: np.ndarray
    #: absolute time (s) at which the contact must stop and hand over to the Python law (inf: none)
    t_stop: float = math.inf


@dataclass
class KernelStats:
    """Contacts run compiled, handed over at a stop time, or sent to the Python stepper (this process)."""

    compiled: int = 0
    handed_over: int = 0
    python: int = 0
    steps: int = 0
    evaluations: int = 0


STATS = KernelStats()

#: Tables of a law with no tables (the power law): the right types, so one compiled specialisation serves all.
_EMPTY = np.zeros(8)
EMPTY_TABLES = (_EMPTY, _EMPTY, _EMPTY, _EMPTY, _EMPTY, _EMPTY, _EMPTY, np.zeros((4, 1)))


@dataclass(frozen=True)
class KernelOutcome:
    """A finished (or handed-over) compiled contact. `end`: None (released), 'stuck', 'rest', 'max_time' or
    'stop_time' (the state at `t` is for the caller's law to sample and accept). Samples: rows of
    (t, gap, v, force, stored, dissipated, kind), kind 1 the instant after release."""

    end: str | None
    t: float
    gap: float
    v: float
    peak_force: float
    max_penetration: float
    booked: float
    samples: np.ndarray
    max_approach: tuple[float, float] | None
    pull_off: tuple[float, float, float] | None
    last_accept: float


def run_compiled(law_c: CompiledLaw, mass: float, gravity: float, t0: float, gap0: float, v0: float, *,
                 rtol: float, atol: np.ndarray, first_step: float, max_step: float, t_bound: float, release: float,
                 bound_is_final: bool, has_history: bool, samples_per_step: int,
                 after_max: bool = False) -> KernelOutcome | None:
    """Integrate one contact compiled; None if the kernel could not (see the module docstring). `after_max`: the
    contact passed its maximum approach before t0 (a continuation after a stop time)."""
    size = FIRST_BUFFER_SAMPLES
    info = np.zeros(ck.INFO_SIZE)
    while True:
        S = law_c.S.copy()
        buf = np.empty((size, ck.SAMPLE_COLUMNS))
        end = int(ck.integrate_contact(law_c.kind, S, law_c.P, law_c.T, float(mass), float(gravity), float(t0),
                                       float(gap0), float(v0), float(rtol), np.asarray(atol, float),
                                       float(first_step), float(max_step), float(t_bound), float(release),
                                       bool(bound_is_final), bool(has_history), int(samples_per_step),
                                       float(law_c.t_stop), buf, info, bool(after_max)))
        if end == ck.ABORT_BUFFER and size < MAX_BUFFER_SAMPLES:
            size *= 4
            continue
        break
    STATS.steps += int(info[ck.I_STEPS])
    STATS.evaluations += int(info[ck.I_EVALS])
    if end not in END_NAMES:
        STATS.python += 1
        log.debug("compiled contact ended with code %d at t = %.6g s: the Python stepper integrates it", end,
                  info[ck.I_T])
        return None
    law_c.S[:] = S
    if end == ck.END_STOP_TIME:
        STATS.handed_over += 1
    else:
        STATS.compiled += 1
    n = int(info[ck.I_NSAMPLES])
    return KernelOutcome(
        end=END_NAMES[end], t=float(info[ck.I_T]), gap=float(info[ck.I_GAP]), v=float(info[ck.I_V]),
        peak_force=float(info[ck.I_PEAK]), max_penetration=float(info[ck.I_MAXPEN]), booked=float(info[ck.I_BOOKED]),
        samples=buf[:n].copy(),
        max_approach=(float(info[ck.I_MAX_T]), float(info[ck.I_MAX_GAP])) if info[ck.I_HAS_MAX] else None,
        pull_off=(float(info[ck.I_PULL_T]), float(info[ck.I_PULL_GAP]), float(info[ck.I_PULL_F]))
        if info[ck.I_HAS_PULL] else None,
        last_accept=float(info[ck.I_LAST_ACCEPT_T]))


def power_law(k: float, n: float) -> CompiledLaw:
    """F = k (-h)^n for h < 0 (N; k in N/m^n), no history: Hertz sphere (n = 3/2, k = 4/3 E* sqrt(R)) for tests."""
    return CompiledLaw(kl.LAW_POWER, np.array([k, n]), EMPTY_TABLES, np.array([math.inf, 0.0, 0.0, 0.0, 0.0]))


def warm_up() -> None:
    """Load (or compile, the first time on a machine: ~15 s) the kernel in this process: a process pool forked
    after it inherits the compiled code instead of loading it again in every worker (~1.5 s each)."""
    law = power_law(1.0, 1.5)
    saved = KernelStats(**vars(STATS))
    run_compiled(law, 1.0, 0.0, 0.0, 0.0, -1.0, rtol=1e-6, atol=np.array([1e-9, 1e-9]), first_step=1e-3,
                 max_step=math.inf, t_bound=10.0, release=0.0, bound_is_final=True, has_history=False,
                 samples_per_step=1)
    STATS.__dict__.update(vars(saved))
    from ..rough.gw_layout import _hermite2d_eval  # and the GW window tables' evaluation
    _hermite2d_eval(np.zeros((1, 16)), 0.0, 1.0, 1, 0.0, 1.0, 1, np.zeros(1), np.zeros(1), True)
    from ..rough import gw_kernel as gk  # the GW surface's values (footprint-table builds)
    P = np.zeros(gk.P_SIZE)
    P[gk.P_N1] = 1.0
    one, line, t1 = np.zeros(1), np.zeros((4, 1)), np.zeros((4, 1, 1))
    gk.integral(0, one, one, gk.log_hertz(one, P, t1), P, t1, np.zeros((1, 16)), line, line, one, one, one, one,
                np.zeros(1, np.int8))
    from ..laws import bridge_kernel as bk  # the wet law's compiled bridge sum, loaded the same way
    bk.bridge_integral(bk.KIND_FORCE, -1.0, -2.0, math.inf, False, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0,
                       np.ones(3), np.ones(3), bk._GL_X, bk._GL_W)
