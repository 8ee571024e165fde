"""The `nanoimpact` command line: one entry point, a subcommand per job, `--help` on each.

The command is a registry: each package contributes its subcommands as `cli.COMMANDS`
(`nanoimpact.cli.Command`): `continuum.cli` (impact, paper), `md.cli` (md, doctor) and this module
(calibrate, sweep, the jobs where the layers meet). `PROVIDERS` lists them; this module assembles the parser
and dispatches. Habits shared by every subcommand: inputs are checked before any work (an invalid scene,
recipe, calibration recipe, parameter set or option is one line on stderr naming the key, the value and what
is allowed, exit 2, nothing written); diagnostics go through `logging` (`-v`/`-q`; this module installs the
handler, library code only logs), results go to stdout; `nanoimpact.errors.exit_code` is the one map from an
error to the exit code (`EXIT_CODES` below lists them for `--help`).
"""
from __future__ import annotations

import argparse
import importlib
import importlib.util
import logging
import sys
from pathlib import Path

from nanoimpact import __version__, data
from nanoimpact.cli import ArgumentParser, Command, add_verbosity, check_out_dir, positive_int, setup_logging
from nanoimpact.errors import InputError, NanoimpactError, RunInterrupted, run_command
from nanoimpact.executors import check_executor

log = logging.getLogger("calibration.cli")      # not __name__: it is __main__ under python -m

EXIT_CODES = ("exit codes: 0 done; 1 a run failed; 2 invalid input or option (one line on stderr, nothing "
              "written); 3 a backend is missing (LAMMPS, MPI, dask); 4 `paper --strict` with a failing claim, "
              "or a sweep with failed points; 75 another process holds the run directory; 130 interrupted (Ctrl-C)")

#: The modules whose `COMMANDS` make up `nanoimpact`, in the order `--help` lists them.
PROVIDERS = ("continuum.cli", "calibration.cli", "md.cli")


def cmd_calibrate(args) -> int:
    check_out_dir(args.out)
    check_out_dir(args.md_cache, "--md-cache")
    if args.params_out is not None and Path(args.params_out).is_dir():
        raise InputError("--params-out", args.params_out, "is an existing folder; give the set's file path")
    check_executor(args.executor, args.workers, args.scheduler)
    from calibration.pipeline import calibrate  # after the option checks: they need none of the physics
    # calibrate checks the whole recipe (pipeline.load_calibration) before any MD or paper run starts
    calibrate(args.recipe, args.out, md_fidelity=args.md_fidelity, executor_name=args.executor,
              workers=args.workers, scheduler=args.scheduler, params_out=args.params_out, md_cache=args.md_cache,
              progress=log.info, same_versions=args.same_versions)
    return 0


def cmd_sweep(args) -> int:
    check_out_dir(args.out)
    check_executor(args.executor, args.workers, args.scheduler)
    from calibration.sweep import parse_vary, run_sweep
    vary = parse_vary(args.vary)             # run_sweep validates every point before anything runs or is written
    record = run_sweep(args.scene, vary, args.out, params=args.params, executor_name=args.executor,
                       workers=args.workers, scheduler=args.scheduler, progress=log.info)
    print(f"sweep: {record['computed']} points run, {record['reused']} reused; wrote {args.out}/sweep.csv and "
          f"sweep.png ({record['wall_s']:.1f} s)")
    if record.get("failed"):
        print(f"sweep: {len(record['failed'])} of {len(record['rows'])} points failed; their one-line reasons are in "
              f"the error column of sweep.csv and in {args.out}/failures.json", file=sys.stderr)
    return record.get("exit_code", 0)          # EXIT_PARTIAL when some points failed (calibration.sweep)


def configure_calibrate(c: argparse.ArgumentParser) -> None:
    c.add_argument("recipe", help="calibration recipe name (quick, smoke) or file (inputs/calibration/quick.toml)")
    c.add_argument("--md-fidelity", choices=("smoke", "quick", "production"), default="quick")
    c.add_argument("--executor", choices=("local", "processes", "dask"), default="local",
                   help="where independent jobs run (default: local, no server)")
    c.add_argument("--scheduler", help="dask scheduler address (tcp://host:port) of an existing cluster; "
                                       "--executor dask only")
    c.add_argument("--workers", type=positive_int, help="worker processes, >= 1 (processes, dask LocalCluster, "
                                                        "paper pool)")
    c.add_argument("--out", default="out/calibration", help="output folder (default: out/calibration)")
    c.add_argument("--params-out", help="write the set here instead of <data folder>/params/<name>.toml")
    c.add_argument("--md-cache", help="MD cache directory (default: $NANOIMPACT_CACHE or ~/.cache/nanoimpact/md)")
    c.add_argument("--require-same-versions", dest="same_versions", action="store_true",
                   help="run again every committed or cached MD result made under another nanoimpact or LAMMPS "
                        "version (by default it is used and the report names its versions)")


def configure_sweep(w: argparse.ArgumentParser) -> None:
    w.add_argument("scene", help="scene name or file")
    w.add_argument("--vary", action="append", required=True, metavar="KEY=V1,V2,...",
                   help="dotted scene key and comma-separated values (repeat for a grid)")
    w.add_argument("--params", help="parameter set NAME or FILE; replaces the scene's")
    w.add_argument("--executor", choices=("local", "processes", "dask"), default="local")
    w.add_argument("--scheduler", help="dask scheduler address of an existing cluster; --executor dask only")
    w.add_argument("--workers", type=positive_int, help="worker processes, >= 1")
    w.add_argument("--out", default="out/sweep", help="output folder (default: out/sweep)")


COMMANDS = (
    Command("calibrate", "MD results -> calibrated parameter set -> the paper's cases, with bands",
            "calibration.cli", "cmd_calibrate", configure_calibrate, description=(
                "Run the MD recipes a calibration needs (reusing committed or cached results whose hash is "
                "current), write the parameter set, run the paper's dry, wet and SAM cases with it beside the "
                "base and silicon sets, propagate the MD errors and user ranges (Latin hypercube), and write "
                "report.md. The recipe is checked whole before anything runs. See docs/calibration.md.")),
    Command("sweep", "run a scene over a grid of overrides (resumable), with a table and a plot",
            "calibration.cli", "cmd_sweep", configure_sweep, description=(
                "Cartesian product of --vary KEY=V1,V2 overrides (file units); each point's result.json is kept "
                "under OUT/points/<input hash>, so a rerun skips finished points. Every point is validated before "
                "any runs. Writes OUT/sweep.csv and OUT/sweep.png.")),
)


def registry() -> dict[str, Command]:
    """Every subcommand of `nanoimpact`, by name, from the PROVIDERS' `COMMANDS` (a name given twice is a bug)."""
    commands: dict[str, Command] = {}
    for module in PROVIDERS:
        for cmd in importlib.import_module(module).COMMANDS:
            if cmd.name in commands:
                raise RuntimeError(f"nanoimpact command {cmd.name!r} is contributed by both "
                                   f"{commands[cmd.name].module} and {cmd.module}")
            commands[cmd.name] = cmd
    return commands


def _global_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--version", action="version", version=f"nanoimpact {__version__}")
    add_verbosity(parser)
    # a subcommand's own -v/-q (zero where it has none, or where it parses its own options)
    parser.set_defaults(sub_verbose=0, sub_quiet=0)
    parser.add_argument("--data", metavar="DIR", help=f"user data folder (scenes/, params/, md/, calibration/ as "
                        f"in inputs/), searched before the shipped data and where calibrated sets are written; "
                        f"default ${data.ENV_VAR}")


def _sub(sub, name: str, **kw) -> argparse.ArgumentParser:
    p = sub.add_parser(name, **kw)
    add_verbosity(p, dest_prefix="sub_")
    return p


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(prog="nanoimpact", description=(
        "Nanoscale adhesive impact of rough surfaces: continuum impact runs, LAMMPS calibration."),
        epilog=(f"Scenes, parameter sets, MD recipes and calibration recipes are given by shipped name "
                f"(hertz_roller, quick) or by path; names are looked up in the user data folder first (--data "
                f"DIR or the environment variable {data.ENV_VAR}), then in the shipped data. " + EXIT_CODES + "."))
    _global_options(parser)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=ArgumentParser)
    for cmd in registry().values():
        if cmd.configure is None:       # parses its own options (listed here for the top-level help)
            sub.add_parser(cmd.name, help=cmd.help, add_help=False)
        else:
            cmd.configure(_sub(sub, cmd.name, help=cmd.help, description=cmd.description or None))
    return parser


#: Global options that take a value (for finding the subcommand in argv).
_VALUED = ("--data",)


def _split_globals(argv: list[str]) -> tuple[list[str], list[str]]:
    """(global options, [subcommand, its arguments...])."""
    i = 0
    while i < len(argv) and argv[i].startswith("-") and argv[i] != "--":
        i += 2 if argv[i] in _VALUED else 1
    return argv[:i], argv[i:]


def _apply_globals(args: argparse.Namespace) -> None:
    setup_logging(args.verbose + args.sub_verbose - args.quiet - args.sub_quiet)
    if args.data is not None:
        if not Path(args.data).expanduser().is_dir():
            raise InputError("--data", args.data, "must be an existing folder (the user data folder)")
        data.set_user_root(args.data)


def _labelled(prog: str, fn, *a) -> int:
    try:
        return fn(*a)
    except NanoimpactError as exc:            # name the subcommand in the line run_command prints
        if not exc.prog:
            exc.prog = prog
        raise
    except KeyboardInterrupt:
        interrupted = RunInterrupted("interrupted")
        interrupted.prog = prog
        raise interrupted from None


_parsers: dict[str, argparse.ArgumentParser] = {}


def _parser(which: str = "full") -> argparse.ArgumentParser:
    """The parsers, built once per process (argparse's construction costs more than a refused input)."""
    if which not in _parsers:
        if which == "full":
            _parsers[which] = build_parser()
        else:
            _parsers[which] = g = ArgumentParser(prog="nanoimpact", add_help=False)
            _global_options(g)
    return _parsers[which]


def _run(argv: list[str]) -> int:
    head, rest = _split_globals(argv)
    commands = registry()
    if rest and rest[0] in commands and commands[rest[0]].configure is None \
            and not {"-h", "--help", "--version"} & set(head):
        _apply_globals(_parser("globals").parse_args(head))
        return _labelled(f"nanoimpact {rest[0]}", commands[rest[0]].runner(), rest[1:])
    args = _parser().parse_args(argv)
    _apply_globals(args)
    # looked up at call time (not bound in the cached parser), so a command can be replaced (tests)
    return _labelled(f"nanoimpact {args.command}", commands[args.command].runner(), args)


def main(argv: list[str] | None = None) -> int:
    """The `nanoimpact` command; returns the exit code. The one place errors become a line and a code
    (nanoimpact.errors.run_command): input errors 2, missing backend 3, Ctrl-C 130, no traceback."""
    return run_command(_run, sys.argv[1:] if argv is None else list(argv), prog="nanoimpact")


if __name__ == "__main__":
    sys.exit(main())
