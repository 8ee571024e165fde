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

    try:
        resolved = resolve_scene(args.scene, params=args.params)
    except SceneError as exc:
        print(f"nanoimpact impact: invalid scene: {exc}", file=sys.stderr)
        return 2
    if args.fidelity:
        from dataclasses import replace

        from continuum.schema import FIDELITY
        sc = resolved.scene
        numerics = replace(sc.numerics, fidelity=args.fidelity,
                           rtol=FIDELITY[args.fidelity]["rtol"] if resolved.sources.get("numerics.rtol") == "default"
                           else sc.numerics.rtol)
        values = {**resolved.values, "numerics.fidelity": args.fidelity}
        sources = {**resolved.sources, "numerics.fidelity": "command line"}
        resolved = replace(resolved, scene=replace(sc, numerics=numerics), values=values, sources=sources)
    out = Path(args.out) if args.out else Path("out") / resolved.scene.name
    sc = resolved.scene
    print(f"scene {sc.name}: {sc.body.shape}, contact {sc.contact}, adhesion {sc.physics.adhesion_law}, "
          f"params {resolved.params_file or 'none'}")

    def progress(b):
        if not args.quiet and (b.index < 5 or (b.index + 1) % 10 == 0):
            print(f"  impact {b.index + 1}: e = {b.restitution:.6f}", file=sys.stderr)

    result, trace = run_impact(resolved, progress=progress)
    write_impact(out, result, trace)
    print(bounce_table(result["bounces"]))
    audit = result["energy_audit"]["max_relative_error"]
    print(f"status: {result['status']} after {result['n_bounces']} impacts; energy audit max error {audit:.2e}; "
          f"wall {result['timing']['wall_s']:.3f} s")
    print(f"wrote {out}/result.json, timeseries.csv, height.png, impacts.png")
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

    # doctor owns its own options (md.doctor.main parses them); listed here for the top-level help
    sub.add_parser("doctor", help="check the LAMMPS installation (in-process and mpirun -np 2)", add_help=False)
    return parser


#: Subcommands that parse their own arguments (module, function).
_DELEGATED = {"doctor": ("md.doctor", "main")}


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
