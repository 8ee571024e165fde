"""Time saved by `auto` model selection (a script, not a timed test).

    python benchmarks/bench_model_selection.py [--repeat 3]

For each pair the scene runs once with the model `auto` leaves out and once with it forced back on;
the table gives best-of-N wall times, their ratio, and the largest rebound difference in units of
the release height (the omission is "safe" below 5e-3; tests/continuum/test_model_selection.py enforces it).
All numbers come from one run of this script, so the ratios are comparable.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from continuum.dynamics.impact import run_impact
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "inputs" / "scenes"
PAIRS = [
    ("half-space, rough silica, 6 bounces", "rough_silica.toml", {"numerics.max_bounces": 6},
     {"physics.half_space": "auto"}, {"physics.half_space": "on"}),
    ("menisci, wet silica to stiction", "wet_silica.toml", {"physics.half_space": "off"},
     {"physics.menisci": "auto"}, {"physics.menisci": "on"}),
    ("adhesion, stiff weakly adhesive summits, 20 bounces", "rough_silica.toml",
     {"params": None, "numerics.max_bounces": 20, "physics.half_space": "off",
      "surfaces.roughness.summit_modulus": 150e9, "surfaces.work_of_adhesion": 0.002},
     {"physics.adhesion_law": "auto"}, {"physics.adhesion_law": "maugis_dugdale"}),
]


def _time(path, overrides, repeat):
    resolved = resolve_scene(path, overrides=overrides)
    best, result = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = run_impact(resolved).to_dict()
        best = min(best, time.perf_counter() - start)
    return best, result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    print(f"{'omitted model':52s} {'auto s':>8s} {'forced s':>9s} {'ratio':>6s} {'max |dh|/h0':>12s}  decided by")
    for label, file, base, auto, forced in PAIRS:
        base = {k: v for k, v in base.items() if k != "params"}
        t_auto, r_auto = _time(SCENES / file, {**base, **auto}, args.repeat)
        t_forced, r_forced = _time(SCENES / file, {**base, **forced}, args.repeat)
        h0 = r_auto["scene"]["values"]["release_height"]
        a = [b["rebound_height"] or 0.0 for b in r_auto["bounces"]]
        f = [b["rebound_height"] or 0.0 for b in r_forced["bounces"]]
        n = max(len(a), len(f))
        a, f = a + [0.0] * (n - len(a)), f + [0.0] * (n - len(f))
        diff = max(abs(x - y) for x, y in zip(a, f)) / h0
        key = next(iter(auto)).split(".")[1]
        rec = r_auto["models"]["adhesion" if key == "adhesion_law" else key]
        print(f"{label:52s} {t_auto:8.3f} {t_forced:9.3f} {t_forced / t_auto:6.1f} {diff:12.2e}  "
              f"{rec.get('decided_by')}: {rec.get('why', '')[:70]}")


if __name__ == "__main__":
    main()
