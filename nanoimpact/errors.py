"""Error classes shared by every layer, and the one map from error class to exit code.

Every input error is one line naming the key, the value and what is allowed
(`InputError`); the command line prints that line and exits with `exit_code(exc)`.
"""
from __future__ import annotations

from typing import Any

#: Exit codes of the `nanoimpact` command (sysexits-like where one fits).
EXIT_OK = 0
EXIT_FAILED = 1          # a run failed (LAMMPS error, a solver that could not finish)
EXIT_INPUT = 2           # an invalid input: scene, recipe, calibration recipe, option
EXIT_BACKEND = 3         # a backend is missing (LAMMPS, MPI, dask)
EXIT_PARTIAL = 4         # some points of a sweep or some paper claims failed; the rest were written
EXIT_BUSY = 75           # EX_TEMPFAIL: another process holds the run directory; try again later
EXIT_INTERRUPTED = 130   # Ctrl-C (128 + SIGINT)


def _rebuild(cls: type, args: tuple, state: dict) -> BaseException:
    """An exception of class `cls` with `args` and attributes `state`, made without calling its `__init__`
    (`NanoimpactError.__reduce__`)."""
    exc = cls.__new__(cls, *args)
    exc.args = args
    exc.__dict__.update(state)
    return exc


class NanoimpactError(Exception):
    """Base class of the errors the command line turns into one line and an exit code.

    Every subclass survives pickling whatever its `__init__` takes (a worker process or a Dask worker sends the
    error back pickled): the default reduction calls `cls(*args)` with the formatted message alone, which an
    `__init__` asking for (key, value, allowed) refuses on the way back, breaking the pool. This one restores the
    message and the attributes without calling `__init__`."""

    exit_code = EXIT_FAILED
    #: the command that raised it (`nanoimpact impact`), named at the start of the line; None: the program's name
    prog: str | None = None

    def __reduce__(self):
        return _rebuild, (type(self), self.args, dict(self.__dict__))


class InputError(NanoimpactError, ValueError):
    """An invalid input: names the key, the value and what is allowed (one line)."""

    exit_code = EXIT_INPUT

    def __init__(self, key: str, value: Any, allowed: str, origin: str = ""):
        self.key, self.value, self.allowed, self.origin = key, value, allowed, origin
        where = f"{origin}: " if origin else ""
        super().__init__(f"{where}{key} = {value!r}: {allowed}")


class DataNotFound(InputError):
    """A shipped or user data file (scene, parameter set, recipe, force field) that is not there."""


class UsageError(NanoimpactError, ValueError):
    """A command-line usage error (argparse's own errors, options that do not go together): one line."""

    exit_code = EXIT_INPUT


class BackendUnavailable(NanoimpactError, RuntimeError):
    """A backend the job needs (LAMMPS, MPI, dask.distributed) cannot be loaded."""

    exit_code = EXIT_BACKEND


class RunFailed(NanoimpactError, RuntimeError):
    """A run started and failed (a LAMMPS error, a solver that did not converge)."""

    exit_code = EXIT_FAILED


class RunBusy(NanoimpactError, RuntimeError):
    """Another live process is writing the same run directory."""

    exit_code = EXIT_BUSY


class RunInterrupted(NanoimpactError):
    """A run stopped by Ctrl-C (or a test's stop hook); the message says how to continue."""

    exit_code = EXIT_INTERRUPTED


def exit_code(exc: BaseException) -> int:
    """The exit code for an exception reaching the command line."""
    if isinstance(exc, KeyboardInterrupt):
        return EXIT_INTERRUPTED
    if isinstance(exc, NanoimpactError):
        return exc.exit_code
    return EXIT_FAILED


def one_line(exc: BaseException) -> str:
    """The message of `exc` for the command line, on one line (a multi-line message is joined with '; ')."""
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted"
    text = str(exc).strip() or type(exc).__name__
    return "; ".join(part.strip() for part in text.splitlines() if part.strip())


def run_command(fn, *args, prog: str = "nanoimpact", stream=None) -> int:
    """Call `fn(*args)` (a command returning its exit code) and turn the errors above into one line on
    `stream` (default: sys.stderr at call time) and their exit code; Ctrl-C gives 130 and no traceback.

    The one try/except of the command line: every entry point (`nanoimpact`, `python -m md.cli`,
    `nanoimpact doctor`) runs through it. Anything else (a bug) keeps its traceback.
    """
    import sys

    from nanoimpact.interrupt import raise_if_interrupted, sigint_guard

    try:
        with sigint_guard():
            code = fn(*args)
            raise_if_interrupted()            # an interrupt that foreign code swallowed still ends in 130
    except SystemExit as exc:                 # argparse's --help / --version, or an explicit sys.exit
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else EXIT_FAILED)
    except (NanoimpactError, KeyboardInterrupt) as exc:
        label = exc.prog if isinstance(exc, NanoimpactError) and exc.prog else prog
        print(f"{label}: {one_line(exc)}", file=stream or sys.stderr)
        return exit_code(exc)
    return EXIT_OK if code is None else int(code)
