"""The `nanoimpact` command line: one entry point, a subcommand per job, `--help` on each.

This is the one place where the continuum and molecular layers meet the user.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


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


def cmd_impact(args) -> int:
    from continuum.impact import run_impact, write_impact
    from continuum.scene import SceneError, resolve_scene

    overrides = {"numerics.fidelity": args.fidelity} if args.fidelity else None
    try:
        resolved = resolve_scene(args.scene, params=args.params, overrides=overrides, override_label="command line")
    except SceneError as exc:
        print(f"nanoimpact impact: invalid scene: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out) if args.out else Path("out") / resolved.scene.name
    sc = resolved.scene
    print(f"scene {sc.name}: {sc.body.shape}, contact {sc.contact}, adhesion {sc.physics.adhesion_law}, "
          f"params {resolved.params_file or 'none'}")

    def progress(b):
        if not args.quiet and (b.index < 5 or (b.index + 1) % 10 == 0):
            print(f"  impact {b.index + 1}: e = {b.restitution:.6f}", file=sys.stderr)

    try:
        result, trace = run_impact(resolved, progress=progress)
    except (SceneError, ValueError) as exc:            # refusals that need the model (datum, depth range)
        print(f"nanoimpact impact: refused: {exc}", file=sys.stderr)
        return 2
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
    from continuum.scene import SceneError, find_params

    if args.params is None:
        from nanoimpact import data
        args.params = "paper,silicon" + (",calibrated" if "calibrated" in data.names("params") else "")
    sets = [s.strip() for s in args.params.split(",") if s.strip()]
    try:
        for s in sets:
            find_params(s)
    except SceneError as exc:
        print(f"nanoimpact paper: {exc}", file=sys.stderr)
        return 2
    record = make_paper(sets, args.out, fidelity=args.fidelity, workers=args.workers)
    failed = [c for c in record["checks"] if not c["pass"]]
    print(f"checks: {len(record['checks']) - len(failed)} pass, {len(failed)} fail "
          f"(see {args.out}/summary.md and checks.json); wall {record['wall_s']:.1f} s")
    for c in failed:
        print(f"  FAIL [{c['set']}] {c['name']}: {c['threshold']}")
    return 0


def cmd_calibrate(args) -> int:
    from calibration.pipeline import CalibrationError, calibrate
    from continuum.scene import SceneError

    try:
        calibrate(args.recipe, args.out, md_fidelity=args.md_fidelity, executor_name=args.executor,
                  workers=args.workers, scheduler=args.scheduler, params_out=args.params_out, md_cache=args.md_cache,
                  progress=lambda m: print(m, file=sys.stderr))
    except (CalibrationError, SceneError) as exc:
        print(f"nanoimpact calibrate: {exc}", file=sys.stderr)
        return 2
    return 0


def cmd_sweep(args) -> int:
    from calibration.sweep import parse_vary, run_sweep
    from continuum.scene import SceneError

    try:
        vary = parse_vary(args.vary)
        record = run_sweep(args.scene, vary, args.out, params=args.params, executor_name=args.executor,
                           workers=args.workers, scheduler=args.scheduler, progress=lambda m: print(m, file=sys.stderr))
    except SceneError as exc:
        print(f"nanoimpact sweep: invalid point: {exc}", file=sys.stderr)
        return 2
    print(f"sweep: {record['computed']} points run, {record['reused']} reused; wrote {args.out}/sweep.csv and "
          f"sweep.png ({record['wall_s']:.1f} s)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="nanoimpact", description=(
        "Nanoscale adhesive impact of rough surfaces: continuum impact runs, LAMMPS calibration."))
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("impact", help="run one impact scene", description=(
        "Simulate a body released onto a surface described by a scene file (TOML, SI units); "
        "writes result.json, timeseries.csv and figures to --out."))
    p.add_argument("scene", help="scene file, e.g. inputs/scenes/hertz_roller.toml")
    p.add_argument("--out", help="output folder (default: out/<scene name>)")
    p.add_argument("--params", help="parameter set NAME (inputs/params/NAME.toml) or FILE; replaces the scene's")
    p.add_argument("--fidelity", choices=("fast", "standard", "reference"), help="numerical preset")
    p.add_argument("--quiet", action="store_true", help="no per-impact progress lines")
    p.set_defaults(func=cmd_impact)

    q = sub.add_parser("paper", help="reproduce the founding paper's cases for each parameter set",
                       description="Run every case of the paper (Hertz roller, rough silica, OTS, roughness and "
                                   "velocity sweeps) for each parameter set; write figures, data, summary.md and "
                                   "checks.json to --out.")
    q.add_argument("--params", default=None, help="parameter sets, comma-separated (default: paper,silicon and, "
                                                    "when inputs/params/calibrated.toml exists, calibrated)")
    q.add_argument("--out", default="out/paper", help="output folder (default: out/paper)")
    q.add_argument("--fidelity", choices=("fast", "standard", "reference"), help="numerical preset for every case")
    q.add_argument("--workers", type=int, help="parallel processes (default: CPU count)")
    q.set_defaults(func=cmd_paper)

    c = sub.add_parser("calibrate", help="MD results -> calibrated parameter set -> the paper's cases, with bands",
                       description="Run the MD recipes a calibration needs (reusing committed or cached results whose "
                                   "hash is current), write the parameter set, run the paper's dry, wet and SAM cases "
                                   "with it beside the base and silicon sets, propagate the MD errors and user ranges "
                                   "(Latin hypercube), and write report.md. See docs/calibration.md.")
    c.add_argument("recipe", help="calibration recipe, e.g. inputs/calibration/quick.toml")
    c.add_argument("--md-fidelity", choices=("smoke", "quick", "production"), default="quick")
    c.add_argument("--executor", choices=("local", "processes", "dask"), default="local",
                   help="where independent jobs run (default: local, no server)")
    c.add_argument("--scheduler", help="dask scheduler address (tcp://host:port) of an existing cluster")
    c.add_argument("--workers", type=int, help="worker processes (processes, dask LocalCluster, paper pool)")
    c.add_argument("--out", default="out/calibration", help="output folder (default: out/calibration)")
    c.add_argument("--params-out", help="write the set here instead of inputs/params/<name>.toml")
    c.add_argument("--md-cache", help="MD cache directory (default: $NANOIMPACT_CACHE or ~/.cache/nanoimpact/md)")
    c.set_defaults(func=cmd_calibrate)

    w = sub.add_parser("sweep", help="run a scene over a grid of overrides (resumable), with a table and a plot",
                       description="Cartesian product of --vary KEY=V1,V2 overrides (file units); each point's "
                                   "result.json is kept under OUT/points/<input hash>, so a rerun skips finished "
                                   "points. Writes OUT/sweep.csv and OUT/sweep.png.")
    w.add_argument("scene", help="scene file")
    w.add_argument("--vary", action="append", required=True, metavar="KEY=V1,V2,...",
                   help="dotted scene key and comma-separated values (repeat for a grid)")
    w.add_argument("--params", help="parameter set NAME or FILE; replaces the scene's")
    w.add_argument("--executor", choices=("local", "processes", "dask"), default="local")
    w.add_argument("--scheduler", help="dask scheduler address of an existing cluster")
    w.add_argument("--workers", type=int, help="worker processes")
    w.add_argument("--out", default="out/sweep", help="output folder (default: out/sweep)")
    w.set_defaults(func=cmd_sweep)

    # doctor owns its own options (md.doctor.main parses them); listed here for the top-level help
    sub.add_parser("doctor", help="check the LAMMPS installation (in-process and mpirun -np 2)", add_help=False)
    sub.add_parser("md", help="run an MD recipe (work of adhesion, pull-off, contact angle, surface tension)",
                   add_help=False)
    return parser


#: Subcommands that parse their own arguments (module, function).
_DELEGATED = {"doctor": ("md.doctor", "main"), "md": ("md.cli", "main")}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] and argv[0] in _DELEGATED:
        import importlib
        module, func = _DELEGATED[argv[0]]
        return getattr(importlib.import_module(module), func)(argv[1:])
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
