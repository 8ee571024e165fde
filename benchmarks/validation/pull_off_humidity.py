"""Pull-off force of a smooth sphere (an AFM tip) against relative humidity (a script).

    python benchmarks/validation/pull_off_humidity.py [SCENE] [--rh 0.05 0.2 ...] [--set KEY=VALUE ...]
                                                      [--json FILE]

For each humidity the scene (default: inputs/scenes/afm_tip_humidity.toml) is read with
environment.relative_humidity set and physics.menisci = 'auto', its meniscus decision taken
(`continuum.model.menisci_decision`: no bridge where the Kelvin radius is below menisci.min_kelvin_radius)
and its contact law built as an impact would build it; the pull-off is the quasi-static one of
`continuum.laws.sphere_meniscus.pull_off` (slow retreat, bridge in equilibrium with the vapour), with the
bridge where the decision keeps it and of the dry law otherwise. Prints a table (forces in nN) and, with
--json, writes the rows (SI).
"""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from continuum import load_scene
from continuum.laws.sphere_meniscus import pull_off
from continuum.model import menisci_decision
from continuum.model.regime import first_impact_speed, regime_of
from continuum.model.select import select_law

DEFAULT_SCENE = "afm_tip_humidity"
DEFAULT_RH = tuple(float(x) for x in np.round(np.arange(0.05, 0.951, 0.05), 2))


def pull_off_at(scene, rh: float, overrides: dict | None = None) -> dict:
    """The pull-off (N) of `scene` at relative humidity `rh`, with the decision and the bridge's numbers."""
    resolved = load_scene(scene, overrides={**(overrides or {}), "environment.relative_humidity": rh,
                                            "physics.menisci": "auto"})
    s = resolved.scene
    regime = regime_of(s, first_impact_speed(s))
    decision = menisci_decision(s, regime)
    r_k, cutoff = regime.kelvin_radius, regime.min_kelvin_radius
    row = {"relative_humidity": rh, "kelvin_radius": r_k, "min_kelvin_radius": cutoff,
           "bridge": decision.choice != "off", "decided_by": decision.decided_by, "why": decision.why}
    law, models = select_law(s, regime.speed, menisci=decision.choice != "off", regime=regime)
    if row["bridge"]:
        q = models["contact_law"]["quasi_static"]
        row.update(pull_off_force=q["pull_off_force"], dry_pull_off_force=q["dry_pull_off_force"],
                   bridge_part=q["bridge_part"], solid_part=q["solid_part"],
                   bridge_pull_off=models["menisci"]["bridge_pull_off"], kelvin_gap=models["menisci"]["kelvin_gap"],
                   solid_work_of_adhesion=models["menisci"]["solid_work_of_adhesion"])
    else:
        dry = pull_off(law, None)["pull_off_force"]
        row.update(pull_off_force=dry, dry_pull_off_force=dry, bridge_part=0.0, solid_part=dry)
    row["law"] = law.name
    return row


def pull_off_curve(scene=DEFAULT_SCENE, rhs=DEFAULT_RH, overrides: dict | None = None) -> list[dict]:
    """`pull_off_at` over the humidities `rhs`."""
    return [pull_off_at(scene, rh, overrides) for rh in rhs]


def table(rows: list[dict]) -> str:
    head = f"{'RH':>5} {'r_K nm':>8} {'bridge':>6} {'F_po nN':>9} {'dry nN':>8} {'bridge nN':>10} {'solid nN':>9}  law"
    out = [head, "-" * len(head)]
    for r in rows:
        out.append(f"{r['relative_humidity']:>5.2f} {r['kelvin_radius'] * 1e9:>8.3f} "
                   f"{'yes' if r['bridge'] else 'no':>6} "
                   f"{r['pull_off_force'] * 1e9:>9.4g} {r['dry_pull_off_force'] * 1e9:>8.4g} "
                   f"{r['bridge_part'] * 1e9:>10.4g} {r['solid_part'] * 1e9:>9.4g}  {r['law']}")
    return "\n".join(out)


def _override(text: str) -> tuple[str, object]:
    import tomllib
    key, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"--set {text!r}: expected KEY=VALUE")
    try:
        return key.strip(), tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return key.strip(), value.strip()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help="scene name or file (default afm_tip_humidity)")
    ap.add_argument("--rh", type=float, nargs="+", default=list(DEFAULT_RH), help="relative humidities in (0, 1)")
    ap.add_argument("--set", action="append", default=[], type=_override, metavar="KEY=VALUE",
                    help="override a scene key (TOML value, file units), repeatable")
    ap.add_argument("--json", help="write the rows (SI) to this file")
    args = ap.parse_args(argv)
    bad = [rh for rh in args.rh if not 0.0 < rh < 1.0 or not math.isfinite(rh)]
    if bad:
        print(f"--rh = {bad[0]!r}: relative humidity must be in (0, 1)", file=sys.stderr)
        return 2
    rows = pull_off_curve(args.scene, args.rh, dict(args.set))
    print(table(rows))
    if args.json:
        from nanoimpact.fileio import atomic_write_json
        atomic_write_json(args.json, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
