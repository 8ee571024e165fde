"""Cost and outcome of the humid mean field's first impact: bridged summits at W_wet, force and loop
(`continuum.laws.wet_mean_field`), against the previous law (dry summits with the DMT solid pull inside the bridges,
`continuum.laws.wet.WetRoughRoller` with `solid_pull`), in one run on one machine.

The scene: wet_silica with the `paper` set as a rigid mean field, bridges from t_a = 1 us (so that they form within
the first contact), menisci.solid_adhesion = 'wet', and the faces' W_SL at each W_wet/dgamma of `RATIOS` (Dupre in the
liquid: W_wet = dgamma + 2 gamma - 2 W_SL; the `paper` set's own angles give W_wet < 0, Hertz summits inside the
bridges). Each law is built once (`select_law`, tables included: `build_s`) and dropped once (first impact only,
`contact_s`); reported: restitution, stuck, the energy audit, and the cost ratio new/old.

    .venv/bin/python benchmarks/bench_wet_mean_field.py
"""
from __future__ import annotations

import json
import time

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.wet import MeniscusBridges, WetRoughRoller
from continuum.model import factory
from continuum.model.regime import first_impact_speed
from continuum.model.select import select_law
from continuum.scene import resolve_scene

#: W_wet / dgamma of the runs (None: the scene's own contact angles).
RATIOS = (None, 0.3)


def _previous(dry, scene, stats, parameters):
    """The humid mean field before the wet loop: dry summits, the bridges taking the DMT solid pull."""
    body, p = scene.body, parameters
    bridges = MeniscusBridges(stats, dry.z_top, body.radius, body.length, p["bridge_pull_off"], p["kelvin_gap"],
                              p["condensation_time"], p["growth_length"])
    return WetRoughRoller(dry, bridges, p)


def _scene(ratio):
    over = {"surfaces.roughness.mode": "mean_field", "menisci.condensation_time": 1e-6,
            "menisci.solid_adhesion": "wet"}
    if ratio is not None:
        base = resolve_scene("wet_silica", params="paper").scene
        w, gamma = base.surfaces.interface_work_of_adhesion, base.menisci.surface_tension
        w_sl = 0.5 * (w + 2.0 * gamma - ratio * w)
        over.update({"surfaces.body.work_of_adhesion_sl": w_sl, "surfaces.substrate.work_of_adhesion_sl": w_sl})
    return resolve_scene("wet_silica", params="paper", overrides=over).scene


def _run(scene, previous: bool) -> dict:
    build = factory.with_menisci
    if previous:
        factory.with_menisci = _previous
    try:
        t0 = time.perf_counter()
        law, _ = select_law(scene, first_impact_speed(scene), menisci=True)
        t1 = time.perf_counter()
        run = simulate(law, scene.body.mass, 9.81, release_height=scene.release_height,
                       settings=DriverSettings(max_bounces=1))
        t2 = time.perf_counter()
    finally:
        factory.with_menisci = build
    b = run.bounces[0]
    return {"law": law.name, "build_s": t1 - t0, "contact_s": t2 - t1, "restitution": float(b.restitution),
            "stuck": bool(float(b.restitution) == 0.0), "audit": float(run.audit["max_relative_error"])}


def main() -> None:
    out = []
    for ratio in RATIOS:
        scene = _scene(ratio)
        old, new = _run(scene, True), _run(scene, False)
        out.append({"w_wet_over_dgamma": ratio, "previous": old, "wet_loop": new,
                    "contact_cost_ratio": new["contact_s"] / old["contact_s"]})
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
