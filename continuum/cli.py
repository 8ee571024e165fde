"""The continuum's `nanoimpact` commands: `impact` (one scene) and `paper` (the founding paper's cases).

Contributed to the top-level command through `COMMANDS` (the registry is assembled in calibration.cli, where
the layers meet). Runners check their inputs before any work and print results to stdout; diagnostics go
through `logging`. Physics modules are imported inside the runners, so listing the commands costs nothing.
"""
from __future__ import annotations

import argparse
import logging
from pathlib import Path

from nanoimpact import data
from nanoimpact.cli import Command, check_out_dir, positive_int
from nanoimpact.errors import EXIT_PARTIAL, InputError, UsageError
from nanoimpact.executors import check_executor

log = logging.getLogger("continuum.cli")

__all__ = ["COMMANDS", "bounce_table", "check_params_set", "cmd_impact", "cmd_paper"]


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


def check_params_set(spec: str) -> Path:
    """A parameter set (name or file) that exists, parses, whose every value passes the scene checks and has an
    origin ([meta.origin], continuum.origins)."""
    from continuum.origins import check_origins
    from continuum.scene import FIELD_BY_PATH, check_value, find_params, flatten, read_toml

    path = find_params(spec)
    raw = read_toml(path, "params")
    flat = flatten(raw, str(path), skip=("meta",))
    for key, value in flat.items():
        check_value(FIELD_BY_PATH[key], value, str(path))
    check_origins(raw.get("meta"), flat, str(path))
    return path


# ----------------------------------------------------------------------------- impact
def configure_impact(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene", help="scene name (hertz_roller) or file (inputs/scenes/hertz_roller.toml)")
    p.add_argument("--out", help="output folder (default: out/<scene name>)")
    p.add_argument("--params", help="parameter set NAME (inputs/params/NAME.toml) or FILE; replaces the scene's")
    p.add_argument("--fidelity", choices=("fast", "standard", "reference"), help="numerical preset")
    p.add_argument("--executor", choices=("local", "processes", "dask"), default="processes",
                   help="where an ensemble's members run (surfaces.roughness.mode 'ensemble' or 'auto'; default: "
                        "processes, a local pool of --workers)")
    p.add_argument("--workers", type=positive_int, help="parallel processes for an ensemble (default: CPU count)")
    p.add_argument("--scheduler", help="dask scheduler address (tcp://host:port) of an existing cluster")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", type=scene_override,
                   help="override a scene key (TOML value, file units), e.g. --set surfaces.roughness.mode=auto; "
                        "repeatable; wins over the scene and its parameter set")


def scene_override(text: str) -> tuple[str, object]:
    """KEY=VALUE of --set: VALUE read as a TOML value (a bare word that is not one is a string)."""
    import tomllib

    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise argparse.ArgumentTypeError(f"--set {text!r}: expected KEY=VALUE, e.g. surfaces.roughness.mode=auto")
    try:
        return key.strip(), tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return key.strip(), value.strip()


def ensemble_summary(ens: dict, surface: dict | None = None) -> str:
    """Lines on an ensemble: stick probabilities (count of members, Wilson 95 % interval, censored), rebound counts
    and first rebounds (median, 5-95 %); the members' escape velocities where the scene asked for them; for a height
    map the tail models and the cutoff band (`continuum.rough.cutoff_band`)."""
    from continuum.rough.cutoff_band import band_summary, tails_summary

    p, r = ens["stick_probability"], ens["rebounds"]
    first = ens.get("first_rebound_over_h0") or ens["first_rebound_m"]
    unit = "h0" if "first_rebound_over_h0" in ens else "m"
    v = (ens.get("escape_velocity") or {}).get("m_per_s")
    escape = (f"\n  escape velocity median {v['p50']:.3g} m/s (5-95 %: {v['p5']:.3g}-{v['p95']:.3g})" if v else "")

    def stick(q):
        return (f"{q['count']}/{q['members']} ({q['interval'][0]:.3f}-{q['interval'][1]:.3f}, Wilson 95 %)"
                if "interval" in q else f"{q['value']:.3f}")
    censored = p["within_run"].get("censored")
    tails = ens.get("tail_models")
    band = (surface or {}).get("cutoff_band")
    return (f"ensemble of {ens['members']} realisations (master seed {ens['master_seed']}, {ens['wall_s']:.2f} s"
            f"{'; ' + ens['members_rule']['stopped'] if 'stopped' in ens.get('members_rule', {}) else ''}): stuck "
            f"at the first impact {stick(p['first_impact'])}, within the run {stick(p['within_run'])}"
            + (f" ({censored} censored by max_bounces/max_time)" if censored else "")
            + f"\n  rebounds median {r['p50']:g} (5-95 %: {r['p5']:g}-{r['p95']:g}); first rebound median "
            f"{first['p50']:.3g} {unit} (5-95 %: {first['p5']:.3g}-{first['p95']:.3g})" + escape
            + (f"\n{tails_summary(tails)}" if tails else "") + (f"\n{band_summary(band)}" if band else ""))


def cmd_impact(args) -> int:
    from continuum.dynamics.impact import run_impact
    from continuum.scene import SceneError, resolve_scene

    check_out_dir(args.out)
    overrides = {**({"numerics.fidelity": args.fidelity} if args.fidelity else {}), **dict(args.set)}
    resolved = resolve_scene(args.scene, params=args.params, overrides=overrides or None, override_label="command line")
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
        check_executor(args.executor, args.workers, args.scheduler)
        ex = None
        if args.scheduler:
            from nanoimpact.executors import executor as make_executor
            ex = make_executor(args.executor, args.workers, args.scheduler)
        try:
            run = run_impact(resolved, progress=progress, executor=ex or args.executor, workers=args.workers)
        finally:
            if ex is not None:
                ex.close()
    except SceneError:
        raise
    except ValueError as exc:            # refusals that need the model (datum, depth range): nothing written
        raise UsageError(f"refused: {exc}") from exc
    run.write(out)
    result = run.to_dict()
    print(bounce_table(result["bounces"]))
    audit = result["energy_audit"]["max_relative_error"]
    print(f"status: {result['status']} after {result['n_bounces']} impacts; energy audit max error {audit:.2e}; "
          f"wall {result['timing']['wall_s']:.3f} s")
    band = (result.get("surface") or {}).get("cutoff_band")
    if "ensemble" in result:
        print(ensemble_summary(result["ensemble"], result.get("surface")))
    elif band:
        from continuum.rough.cutoff_band import band_summary
        print("cutoff band (mean field, first impact):\n" + band_summary(band))
    if "menisci_condensation_time" in result:
        print(result["menisci_condensation_time"]["summary"])
    for w in result["warnings"]:
        print(f"warning: {w}")
    print(f"wrote {out}/result.json, timeseries.csv, height.png, impacts.png"
          + (", ensemble.png" if "ensemble" in result else ", cutoff_band.png" if band else ""))
    return 0


# ----------------------------------------------------------------------------- paper
def configure_paper(q: argparse.ArgumentParser) -> None:
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
    q.add_argument("--case-figures", action="store_true",
                   help="also draw each case's own height.png and impacts.png in cases/<case>/<set>/ (about a tenth "
                        "of the command's CPU)")
    q.add_argument("--seeds", type=int, default=None,
                   help="discrete-summit seeds per set on which the sampled claims are judged (default 8)")
    q.add_argument("--uncertainty", action="append", default=[], metavar="SET=CSV",
                   help="judge the sampled claims of SET also on the rows of CSV (a calibration's uncertainty.csv, "
                        "its Latin hypercube); repeatable")


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
    seeds, uncertainty = paper_samples(args)
    record = make_paper(sets, args.out, fidelity=args.fidelity, workers=args.workers, executor_name=args.executor,
                        scheduler=args.scheduler, progress=log.info, seeds=seeds, uncertainty=uncertainty,
                        case_figures=args.case_figures)
    states = [c.get("state", "pass" if c["pass"] else "fail") for c in record["checks"]]
    print(f"checks: {states.count('pass')} pass, {states.count('fail')} fail, {states.count('not_evaluable')} not "
          f"evaluable (see {args.out}/summary.md and checks.json); wall {record['wall_s']:.1f} s")
    for c, state in zip(record["checks"], states):
        if state != "pass":
            print(f"  {state.upper()} [{c['set']}] {c['name']} ({c.get('kind', 'claim')}): "
                  f"{c.get('reason') or c['threshold']}")
    return EXIT_PARTIAL if "fail" in states and args.strict else 0


def paper_samples(args) -> tuple[int, dict[str, list[dict]]]:
    """--seeds (>= 0) and --uncertainty SET=CSV (each file read; its rows are scene overrides)."""
    from continuum.paper.samples import DEFAULT_SEEDS, read_uncertainty_csv

    seeds = DEFAULT_SEEDS if args.seeds is None else args.seeds
    if seeds < 0:
        raise InputError("--seeds", seeds, "an integer >= 0")
    rows = {}
    for spec in args.uncertainty:
        name, sep, path = spec.partition("=")
        if not sep or not Path(path).is_file():
            raise InputError("--uncertainty", spec, "SET=CSV, CSV an existing file (a calibration's uncertainty.csv)")
        rows[Path(name.strip()).stem] = read_uncertainty_csv(path)
    return seeds, rows


COMMANDS = (
    Command("impact", "run one impact scene", "continuum.cli", "cmd_impact", configure_impact, description=(
        "Simulate a body released onto a surface described by a scene (a shipped name such as hertz_roller, "
        "or a TOML file, SI units); writes result.json, timeseries.csv and figures to --out.")),
    Command("paper", "reproduce the founding paper's cases for each parameter set", "continuum.cli", "cmd_paper",
            configure_paper, description=(
                "Run every case of the paper (Hertz roller, rough silica, OTS, roughness and velocity sweeps) for "
                "each parameter set; write figures, data, summary.md and checks.json to --out. Exit 0 whatever "
                "the claims give, unless --strict.")),
)
