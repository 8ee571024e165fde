"""Command-line plumbing shared by every `nanoimpact` command (the top-level one in calibration.cli,
`nanoimpact md`, `nanoimpact doctor`): an ArgumentParser whose usage errors are one line (exit 2),
-v/-q verbosity, the only place a logging handler is installed (library code only logs), and option
checks that run before any work. Leaf module: imports none of continuum, md, calibration.
"""
from __future__ import annotations

import argparse
import importlib
import logging
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .errors import InputError, UsageError

__all__ = ["ArgumentParser", "Command", "positive_int", "check_out_dir", "add_verbosity", "setup_logging",
           "logging_ready"]


@dataclass(frozen=True)
class Command:
    """One `nanoimpact` subcommand, contributed by the package that owns the job (its `cli.COMMANDS`).

    `module`/`function` name the runner, looked up when the command runs (so importing a package's command
    list costs no physics imports, and a test may replace the function). With `configure` the top-level parser
    gets a subparser that `configure(parser)` fills and the runner receives the parsed `argparse.Namespace`;
    without it the command parses its own arguments and the runner receives the list of strings after the
    command's name (`nanoimpact md`, `nanoimpact doctor`).
    """

    name: str
    help: str
    module: str
    function: str
    configure: Callable[[argparse.ArgumentParser], None] | None = None
    description: str = ""

    def runner(self) -> Callable:
        return getattr(importlib.import_module(self.module), self.function)


class ArgumentParser(argparse.ArgumentParser):
    """argparse with usage errors as one line (raised as UsageError: exit 2, printed by run_command)."""

    def error(self, message: str):
        exc = UsageError(f"error: {' '.join(message.split())} (see {self.prog} --help)")
        exc.prog = self.prog
        raise exc


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1 (--workers, --np)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: an integer >= 1 is required") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value}: an integer >= 1 is required")
    return value


def check_out_dir(value: str | Path | None, option: str = "--out") -> None:
    """Refuse an output folder that is an existing file (before any work is done)."""
    if value is not None and Path(value).exists() and not Path(value).is_dir():
        raise InputError(option, str(value), "is an existing file; give a folder (new or existing)")


def add_verbosity(parser: argparse.ArgumentParser, *, suppress: bool = False, quiet_help: str = "",
                  dest_prefix: str = "") -> None:
    """-v/--verbose and -q/--quiet (repeatable), stored as `<dest_prefix>verbose` and `<dest_prefix>quiet`.
    `suppress`: no attribute when not given (tells "not given" from 0)."""
    kw = {"default": argparse.SUPPRESS} if suppress else {"default": 0}
    parser.add_argument("-v", "--verbose", action="count", dest=f"{dest_prefix}verbose",
                        help="more diagnostics on stderr (-vv: debug)", **kw)
    parser.add_argument("-q", "--quiet", action="count", dest=f"{dest_prefix}quiet",
                        help=quiet_help or "fewer diagnostics on stderr: warnings and errors only (-qq: errors)", **kw)


class _StderrHandler(logging.StreamHandler):
    """Writes to whatever sys.stderr is when a record is emitted (pytest's capture, a redirected stream)."""

    def __init__(self):
        super().__init__(sys.stderr)

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):
        pass


_handler: logging.Handler | None = None
_PACKAGES = ("nanoimpact", "continuum", "md", "calibration")
#: Libraries whose import-time warnings say nothing about a run (MDAnalysis: "netCDF4 is not available.
#: Writing AMBER ncdf files will be slow.", at every import): shown from -v on.
_CHATTY = ("MDAnalysis",)


def setup_logging(verbosity: int = 0) -> None:
    """Install the command line's stderr handler (replacing an earlier one) and set the levels.

    verbosity 0: INFO from nanoimpact's packages, WARNING from everything else (ERROR from the chatty
    libraries in _CHATTY); each -v one step more (-vv: DEBUG everywhere), each -q one step less (-q: WARNING,
    -qq: ERROR).
    """
    global _handler
    root = logging.getLogger()
    if _handler is not None:
        root.removeHandler(_handler)
    _handler = _StderrHandler()
    _handler.setFormatter(logging.Formatter("%(message)s" if verbosity < 1 else "%(levelname)s %(name)s: %(message)s"))
    root.addHandler(_handler)
    ours = min(max(logging.INFO - 10 * verbosity, logging.DEBUG), logging.CRITICAL)
    for name in _PACKAGES:
        logging.getLogger(name).setLevel(ours)
    for name in _CHATTY:
        logging.getLogger(name).setLevel(logging.ERROR if verbosity < 1 else logging.NOTSET)
    root.setLevel(logging.DEBUG if verbosity >= 2 else max(ours, logging.WARNING))


def logging_ready() -> bool:
    """True when setup_logging has installed its handler (the top-level command did)."""
    return _handler is not None and _handler in logging.getLogger().handlers
