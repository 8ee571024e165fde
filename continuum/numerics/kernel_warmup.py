"""Compile the contact kernel into numba's cache in two processes at once, before parallel workers need it.

numba compiles in one thread per process. With a cold cache (a fresh clone, or any edit of the sources: the cache
folder is keyed by them, `nanoimpact.compiled_cache`) every process that runs a contact compiles the whole contact
kernel (`contact_kernel.integrate_contact` and every law it dispatches to, ~250 functions), and two pytest-xdist
workers compile the same functions side by side. `warm()` compiles them once, split over two processes that work on
different branches of the kernel's call tree: one follows `compiled_contact.warm_up` (the integrator down to the
force), the other compiles the energy, loss, accept and release dispatchers bottom-up; a function either of them
needs while the other compiles it is waited for and then loaded from the cache (one lock file per function in the
cache folder), so nothing is compiled twice. Then every later process loads the kernel from the cache.

`python -m continuum.numerics.kernel_warmup` runs it (the test suite's conftest does, before its workers start);
it returns at once where the cache already holds the kernel. Compiling changes no arithmetic: the same functions
with the same argument types are compiled as a contact would compile them.
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import logging
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from numba import typeof, types
from numba.core import dispatcher as _dispatcher
from numba.core import sigutils

from . import compiled_contact as cc
from . import kernel_laws as kl

try:
    import fcntl
except ImportError:                 # Windows: no warm-up, every process compiles what it needs
    fcntl = None

log = logging.getLogger(__name__)

#: Longest wait (s) for a function the other process compiles before compiling it here too (a guard: two processes
#: that each wait for the other cannot deadlock).
LOCK_WAIT_S = 120.0


def cache_folder() -> Path:
    """The folder numba caches this package's kernels in (set by `continuum/__init__`)."""
    return Path(os.environ["NUMBA_CACHE_DIR"])


def is_warm() -> bool:
    """The cache holds the contact kernel (its index file exists)."""
    return any(cache_folder().glob("*/contact_kernel.integrate_contact-*.nbi"))


class _FunctionLocks:
    """One lock file per compiled function in `folder`, taken around each compile of this process (re-entrant for a
    recursive compile), so two processes never compile (nor write the cache index of) the same function at once."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.held: dict[str, object] = {}
        folder.mkdir(parents=True, exist_ok=True)

    @contextlib.contextmanager
    def hold(self, name: str):
        if name in self.held:
            yield
            return
        path = self.folder / (hashlib.sha1(name.encode()).hexdigest()[:20] + ".lock")
        with open(path, "a") as fh:
            deadline = time.monotonic() + LOCK_WAIT_S
            locked = False
            while not locked:
                try:
                    fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    locked = True
                except BlockingIOError:
                    if time.monotonic() > deadline:
                        log.warning("waited %.0f s for %s: compiling it here too", LOCK_WAIT_S, name)
                        break
                    time.sleep(0.05)
            self.held[name] = fh
            try:
                yield
            finally:
                del self.held[name]
                if locked:
                    fcntl.flock(fh, fcntl.LOCK_UN)


def _install_locks(locks: _FunctionLocks) -> None:
    """Wrap numba's `Dispatcher.compile` in this process: a function not yet compiled here is compiled (or, where
    the other process wrote it meanwhile, loaded from the cache) while this process holds its lock."""
    original = _dispatcher.Dispatcher.compile

    def compile(self, sig):
        args, _ = sigutils.normalize_signature(sig)
        if tuple(args) in self.overloads:
            return original(self, sig)
        with locks.hold(f"{self.py_func.__module__}.{self.py_func.__qualname__}"):
            return original(self, sig)

    _dispatcher.Dispatcher.compile = compile


def law_part() -> list[tuple[object, tuple]]:
    """(dispatcher, argument types) of the laws' energy, loss, accept and release dispatchers, in the order the
    laws' part compiles them (bottom-up: the integrator's own branch, `compiled_contact.warm_up`, reaches the force
    first), with the types the contact kernel calls them with. The kernel's own thin wrappers (`_stored`,
    `_dissipated`, `_accept`) are inlined into their callers, so the dispatchers below them are what is compiled."""
    arr, f8, i8 = typeof(np.zeros(1)), types.float64, types.int64
    tables = typeof(cc.EMPTY_TABLES)
    state = (i8, f8, arr, arr, tables)             # kind, gap, S, P, T
    return [(kl.law_release_loss, state), (kl.law_release_gap, (i8, arr, arr, tables, f8)),
            (kl.law_accept, state), (kl.law_dissipated, state), (kl.law_stored, state)]


def _part_laws() -> None:
    """Compile `law_part` (every law below each dispatcher with it)."""
    for dispatcher, sig in law_part():
        dispatcher.compile(sig)


PARTS = {"contact": cc.warm_up, "laws": _part_laws}


def run_part(name: str) -> None:
    """Compile one part in this process, under the per-function locks."""
    _install_locks(_FunctionLocks(cache_folder() / "warm-locks"))
    PARTS[name]()


def warm(timeout: float = 600.0) -> float:
    """Compile the contact kernel into the cache with the two parts in two processes at once (nothing where the cache
    already holds it); returns the seconds it took. Raises CalledProcessError where a part failed, TimeoutExpired
    after `timeout` s (the parts killed)."""
    if fcntl is None or is_warm():
        return 0.0
    start = time.monotonic()
    cmd = [sys.executable, "-m", "continuum.numerics.kernel_warmup", "--part"]
    procs = [subprocess.Popen([*cmd, name]) for name in PARTS]
    try:
        for name, proc in zip(PARTS, procs):
            rc = proc.wait(timeout=max(timeout - (time.monotonic() - start), 1.0))
            if rc != 0:
                raise subprocess.CalledProcessError(rc, [*cmd, name])
    finally:                            # a failed or timed-out warm-up leaves no part running
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    return time.monotonic() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m continuum.numerics.kernel_warmup",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--part", choices=sorted(PARTS), help="compile one part here (else both, in two processes)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if args.part:
        run_part(args.part)
        return 0
    took = warm()
    log.info("contact kernel %s (%s)", f"compiled in {took:.0f} s" if took else "already in the cache", cache_folder())
    return 0


if __name__ == "__main__":
    sys.exit(main())
