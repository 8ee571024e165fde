"""The `nanoimpact` command line: one entry point, a subcommand per job, `--help` on each.

This is the one place where the continuum and molecular layers meet the user. Habits shared by
every subcommand: inputs are checked before any work (an invalid scene, recipe, calibration recipe,
parameter set or option is one line on stderr naming the key, the value and what is allowed, exit 2,
nothing written); diagnostics go through `logging` (`-v`/`-q`; this module installs the handler,
library code only logs), results go to stdout; `nanoimpact.errors.exit_code` is the one map from an
error to the exit code (`EXIT_CODES` below lists them for `--help`).
"""
from __future__ import annotations

import argparse
import importlib
import importlib.util
import logging
import sys
from pathlib import Path

from nanoimpact.cli import ArgumentParser, add_verbosity, check_out_dir, positive_int, setup_logging
from nanoimpact import __version__, data
from nanoimpact.executors import check_executor
from nanoimpact.errors import (EXIT_PARTIAL, InputError, NanoimpactError, UsageError,
                               run_command)

log = logging.getLogger("calibration.cli")      # not __name__: it is __main__ under python -m

EXIT_CODES = ("exit codes: 0 done; 1 a run failed; 2 invalid input or option (one line on stderr, nothing "
              "written); 3 a backend is missing (LAMMPS, MPI, dask); 4 `paper --strict` with a failing claim, "
              "or a sweep with failed points; 75 another process holds the run directory; 130 interrupted (Ctrl-C)")


def _fmt(x, scale=1.0, spec=".4g"):
    return "-" if x is None else format(x * scale, spec)


def bounce_table(bounces: list[dict]) -> str:
    """A short fixed-width table of the bounces (display units)."""
    head = f"{'#':>3} {'v_in mm/s':>10} {'t_c ns':>10} {'F_peak uN':>10} {'pen pm':>9} {'e':>9} {'rebound nm':>11}"
    rows = [head, "-" * len(head)]
    for b in bounces:
        rows.append(f"{b['index'] + 1:>3} {_fmt(b['v_impact'], 1e3):>10} {_fmt(b['duration'], 1e9):>10} "
                    f"{_fmt(b['peak_force'], 1e6):>10} {_fmt(b['max_penetration'], 1e12):>9} "
                    f"{_fmt(b['restitution'], 1, '.6f'):>9} {_fmt(b['rebound_height'], 1e9):>11}")
    return "\n".join(rows)


# ----------------------------------------------------------------------------- up-front checks
def check_params_set(spec: str) -> Path:
    """A parameter set (name or file) that exists, parses and whose every value passes the scene checks."""
    from continuum.scene import FIELD_BY_PATH, check_value, find_params, flatten, read_toml

    path = find_params(spec)
    flat = flatten(read_toml(path, "params"), str(path), skip=("meta",))
    for key, value in flat.items():
        check_value(FIELD_BY_PATH[key], value, str(path))
    return path


# ----------------------------------------------------------------------------- commands
def cmd_impact(args) -> int:
    from continuum.impact import run_impact, write_impact
    from continuum.scene import SceneError, resolve_scene

    check_out_dir(args.out)
    overrides = {"numerics.fidelity": args.fidelity} if args.fidelity else None
    resolved = resolve_scene(args.scene, params=args.params, overrides=overrides, override_label="command line")
    out = Path(args.out) if args.out else Path("out") / resolved.scene.name
    check_out_dir(out)
    sc = resolved.scene
    print(f"scene {sc.name}: {sc.body.shape}, contact {sc.contact}, adhesion {sc.physics.adhesion_law}, "
          f"params {resolved.params_file or 'none'}")

    def progress(b):
        if b.index < 5 or (b.index + 1) % 10 == 0:
            log.info("  impact %d: e = %.6f", b.index + 1, b.restitution)
        else:
            log.debug("  impact %d: e = %.6f", b.index + 1, b.restitution)

    try:
        result, trace = run_impact(resolved, progress=progress)
    except SceneError:
        raise
    except ValueError as exc:            # refusals that need the model (datum, depth range): nothing written
        raise UsageError(f"refused: {exc}") from exc
    write_impact(out, result, trace)
    print(bounce_table(result["bounces"]))
    audit = result["energy_audit"]["max_relative_error"]
    print(f"status: {result['status']} after {result['n_bounces']} impacts; energy audit max error {audit:.2e}; "
          f"wall {result['timing']['wall_s']:.3f} s")
    for w in result["warnings"]:
        print(f"warning: {w}")
    print(f"wrote {out}/result.json, timeseries.csv, height.png, impacts.png")
    return 0


def cmd_paper(args) -> int:
    from continuum.paper.report import make_paper

    check_out_dir(args.out)
    if args.params is None:
        args.params = "paper,silicon" + (",calibrated" if "calibrated" in data.names("params") else "")
    sets = [s.strip() for s in args.params.split(",") if s.strip()]
    if not sets:
        raise InputError("--params", args.params, "one or more parameter set names or files, comma-separated")
    for s in sets:
        check_params_set(s)
    check_executor(args.executor, args.workers, args.scheduler)
    record = make_paper(sets, args.out, fidelity=args.fidelity, workers=args.workers, executor_name=args.executor,
                        scheduler=args.scheduler, progress=log.info)
    failed = [c for c in record["checks"] if not c["pass"]]
    print(f"checks: {len(record['checks']) - len(failed)} pass, {len(failed)} fail "
          f"(see {args.out}/summary.md and checks.json); wall {record['wall_s']:.1f} s")
    for c in failed:
        print(f"  FAIL [{c['set']}] {c['name']}: {c['threshold']}")
    return EXIT_PARTIAL if failed and args.strict else 0


def cmd_calibrate(args) -> int:
    check_out_dir(args.out)
    check_out_dir(args.md_cache, "--md-cache")
    if args.params_out is not None and Path(args.params_out).is_dir():
        raise InputError("--params-out", args.params_out, "is an existing folder; give the set's file path")
    check_executor(args.executor, args.workers, args.scheduler)
    from calibration.pipeline import calibrate      # after the option checks: they need none of the physics
    # calibrate checks the whole recipe (pipeline.load_calibration) before any MD or paper run starts
    calibrate(args.recipe, args.out, md_fidelity=args.md_fidelity, executor_name=args.executor,
              workers=args.workers, scheduler=args.scheduler, params_out=args.params_out, md_cache=args.md_cache,
              progress=log.info)
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


def _global_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--version", action="version", version=f"nanoimpact {__version__}")
    add_verbosity(parser)
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

    p = _sub(sub, "impact", help="run one impact scene", description=(
        "Simulate a body released onto a surface described by a scene (a shipped name such as hertz_roller, "
        "or a TOML file, SI units); writes result.json, timeseries.csv and figures to --out."))
    p.add_argument("scene", help="scene name (hertz_roller) or file (inputs/scenes/hertz_roller.toml)")
    p.add_argument("--out", help="output folder (default: out/<scene name>)")
    p.add_argument("--params", help="parameter set NAME (inputs/params/NAME.toml) or FILE; replaces the scene's")
    p.add_argument("--fidelity", choices=("fast", "standard", "reference"), help="numerical preset")

    q = _sub(sub, "paper", help="reproduce the founding paper's cases for each parameter set",
             description="Run every case of the paper (Hertz roller, rough silica, OTS, roughness and "
                         "velocity sweeps) for each parameter set; write figures, data, summary.md and "
                         "checks.json to --out. Exit 0 whatever the claims give, unless --strict.")
    q.add_argument("--params", default=None, help="parameter sets, comma-separated (default: paper,silicon and, "
                                                    "when a `calibrated` set exists, calibrated)")
    q.add_argument("--out", default="out/paper", help="output folder (default: out/paper)")
    q.add_argument("--fidelity", choices=("fast", "standard", "reference"), help="numerical preset for every case")
    q.add_argument("--workers", type=positive_int, help="parallel processes, >= 1 (default: CPU count)")
    q.add_argument("--executor", choices=("local", "processes", "dask"), default="processes",
                   help="where the cases run (default: processes, a local pool of --workers)")
    q.add_argument("--scheduler", help="dask scheduler address (tcp://host:port) of an existing cluster")
    q.add_argument("--strict", action="store_true",
                   help=f"exit {EXIT_PARTIAL} when any of the paper's claims fails (everything is still written)")

    c = _sub(sub, "calibrate", help="MD results -> calibrated parameter set -> the paper's cases, with bands",
             description="Run the MD recipes a calibration needs (reusing committed or cached results whose "
                         "hash is current), write the parameter set, run the paper's dry, wet and SAM cases "
                         "with it beside the base and silicon sets, propagate the MD errors and user ranges "
                         "(Latin hypercube), and write report.md. The recipe is checked whole before anything "
                         "runs. See docs/calibration.md.")
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

    w = _sub(sub, "sweep", help="run a scene over a grid of overrides (resumable), with a table and a plot",
             description="Cartesian product of --vary KEY=V1,V2 overrides (file units); each point's "
                         "result.json is kept under OUT/points/<input hash>, so a rerun skips finished "
                         "points. Every point is validated before any runs. Writes OUT/sweep.csv and OUT/sweep.png.")
    w.add_argument("scene", help="scene name or file")
    w.add_argument("--vary", action="append", required=True, metavar="KEY=V1,V2,...",
                   help="dotted scene key and comma-separated values (repeat for a grid)")
    w.add_argument("--params", help="parameter set NAME or FILE; replaces the scene's")
    w.add_argument("--executor", choices=("local", "processes", "dask"), default="local")
    w.add_argument("--scheduler", help="dask scheduler address of an existing cluster; --executor dask only")
    w.add_argument("--workers", type=positive_int, help="worker processes, >= 1")
    w.add_argument("--out", default="out/sweep", help="output folder (default: out/sweep)")

    # doctor and md own their options (md.doctor / md.cli parse them); listed here for the top-level help
    sub.add_parser("doctor", help="check the LAMMPS installation (in-process and mpirun -np 2)", add_help=False)
    sub.add_parser("md", help="run an MD recipe (work of adhesion, pull-off, contact angle, surface tension)",
                   add_help=False)
    return parser


#: Subcommands that parse their own arguments (module, function that raises rather than printing).
_DELEGATED = {"doctor": ("md.doctor", "run"), "md": ("md.cli", "run")}
#: Global options that take a value (for finding the subcommand in argv).
_VALUED = ("--data",)


def _split_globals(argv: list[str]) -> tuple[list[str], list[str]]:
    """(global options, [subcommand, its arguments...])."""
    i = 0
    while i < len(argv) and argv[i].startswith("-") and argv[i] != "--":
        i += 2 if argv[i] in _VALUED else 1
    return argv[:i], argv[i:]


def _apply_globals(args: argparse.Namespace) -> None:
    setup_logging(getattr(args, "verbose", 0) + getattr(args, "sub_verbose", 0)
                  - getattr(args, "quiet", 0) - getattr(args, "sub_quiet", 0))
    if args.data is not None:
        if not Path(args.data).expanduser().is_dir():
            raise InputError("--data", args.data, "must be an existing folder (the user data folder)")
        data.set_user_root(args.data)


def _labelled(prog: str, fn, *a) -> int:
    try:
        return fn(*a)
    except (NanoimpactError, KeyboardInterrupt) as exc:   # name the subcommand in the line run_command prints
        if not getattr(exc, "prog", None):
            exc.prog = prog
        raise


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
    if rest and rest[0] in _DELEGATED and not {"-h", "--help", "--version"} & set(head):
        _apply_globals(_parser("globals").parse_args(head))
        module, func = _DELEGATED[rest[0]]
        return _labelled(f"nanoimpact {rest[0]}", getattr(importlib.import_module(module), func), rest[1:])
    args = _parser().parse_args(argv)
    _apply_globals(args)
    # looked up at call time (not bound in the cached parser), so a command can be replaced (tests)
    return _labelled(f"nanoimpact {args.command}", globals()[f"cmd_{args.command}"], args)


def main(argv: list[str] | None = None) -> int:
    """The `nanoimpact` command; returns the exit code. The one place errors become a line and a code
    (nanoimpact.errors.run_command): input errors 2, missing backend 3, Ctrl-C 130, no traceback."""
    return run_command(_run, sys.argv[1:] if argv is None else list(argv), prog="nanoimpact")


if __name__ == "__main__":
    sys.exit(main())
