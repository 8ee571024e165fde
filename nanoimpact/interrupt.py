"""Ctrl-C that cannot be lost.

Python raises KeyboardInterrupt wherever the interpreter happens to be when SIGINT arrives. If that is
inside a ctypes callback -- numba's object-cache hook fires during JIT compilation of the contact
kernels -- ctypes prints "Exception ignored on calling ctypes callback function" and carries on: the
run finishes and writes its output as if nothing had been pressed (seen in CI, 2026-11-25).

Worse, numba is left
half-way: its next call fails with "RuntimeError: no compiled object yet" and a traceback (found by
sending SIGINT at 40 delays into `nanoimpact impact rough_silica` with an empty numba cache).

The command line therefore installs `handler` for the duration of a command (`sigint_guard`). It
remembers the interrupt; it raises KeyboardInterrupt at once unless the interpreter is inside numba
or llvmlite (compiling), where it only remembers. The long loops and the one place a run's output
folder is committed call `raise_if_interrupted()`, so a deferred or swallowed interrupt is raised at
the next safe point and nothing is written after it. Outside the command line (the
Python API, tests) the guard is not installed and `raise_if_interrupted` never raises.
"""
from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

_pending = False

#: Packages that must not be interrupted mid-call: they swallow the exception and are left inconsistent.
UNSAFE_PACKAGES = ("numba", "llvmlite")


def _in_unsafe_code(frame) -> bool:
    while frame is not None:
        if frame.f_globals.get("__name__", "").split(".", 1)[0] in UNSAFE_PACKAGES:
            return True
        frame = frame.f_back
    return False


def handler(signum, frame) -> None:      # noqa: ARG001  (signal handler signature)
    """SIGINT handler: remember the interrupt; raise it as Python's default handler would, except inside
    numba/llvmlite, where `raise_if_interrupted` raises it at the next safe point."""
    global _pending
    _pending = True
    if not _in_unsafe_code(frame):
        raise KeyboardInterrupt


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt if a SIGINT arrived under `sigint_guard` (deferred, or swallowed by foreign code)."""
    if _pending:
        raise KeyboardInterrupt


@contextmanager
def sigint_guard() -> Iterator[None]:
    """Install `handler` for SIGINT while the block runs (main thread only) and restore the previous one after."""
    global _pending
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, handler)
    _pending = False
    try:
        yield
    finally:
        # None: the previous handler was not installed from Python; Python's default is the closest restorable one
        signal.signal(signal.SIGINT, signal.default_int_handler if previous is None else previous)
        _pending = False
