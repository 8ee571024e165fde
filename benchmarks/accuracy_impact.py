"""The impact comparison of benchmarks/bench_accuracy.py: a short roller dropped on the patch through the impact
driver, its contact force the boundary-element reference's, tabulated on approach and retraction, against each
summit level's at the same cutoff.

The body (`continuum.rough.bem_impact.Roller`): a silicon cylinder of radius ROLLER_RADIUS lying across the patch,
as long as the patch is wide. Each level's force on it is one quasi-static cycle along the same separations
(`roller_path`): the reference's from Tamaas on the composite surface (the map minus the roller's drop), the GW mean
field's summed over strips across the patch, the discrete summits' each lowered by the roller's drop over it. Each
table becomes a contact law (`continuum.dynamics.tabulated_cycle.TabulatedCycleLaw`: linear between states, the
retraction from the body's turn) and the body is dropped through `continuum.dynamics.driver.simulate`, first impact
only. Its speed is the one that turns it at the reference table's deepest state. A summit level's table is made in
steps: to 3x the reference's depth, where the body turns on it (solved on that table's exact approach work), then
rerun to that turn, keeping its approach states, RERUNS times, so that its retraction starts where the body turns;
`turn_shift_over_step` records how far the body's turn still lies from the table's (the law shifts the retraction by
that much).

Outputs per level: first-rebound height h1 (the apex of the flight after the impact, above the touch), restitution,
stuck or not, the driver's energy audit, the restitution the quasi-static energy balance through the same table
gives (`bem_impact.impact_outcome`: a check of the integration, equal up to gravity's work over the contact), and
the seconds the level's tables and drops took.
"""
from __future__ import annotations

import math
import time

import numpy as np

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.tabulated_cycle import TabulatedCycleLaw
from continuum.rough.bem_impact import STANDARD_G, Roller, approach_work, impact_outcome
from continuum.rough.bem_reference import bem_cycle
from continuum.rough.quasistatic import separation_path

#: Roller radius (m), a choice: at ROLLER_DEPTH below the composite surface's top the band within the cohesive range
#: of the roller spans the middle ~60 % of the 0.25 um patch (`reach_band` records it), where ~10 of its ~20 summits
#: touch, and stays clear of the cell's edges so that the periodic images of the contact do not meet.
ROLLER_RADIUS = 1e-6
#: Depth (m) of the reference table's deepest state below the composite surface's top: the body's turn, a choice
#: that sets the impact energy (about 3 summit-height standard deviations into the patch).
ROLLER_DEPTH = 3e-9
#: Density of the body (kg/m^3): silicon (the calibrated set's body is polysilicon); it sets the impact speed and
#: the drop height, not the restitution.
BODY_DENSITY = 2330.0
#: The driver's settings: first impact only.
SETTINGS = DriverSettings(max_bounces=1)


def roller_path(h: np.ndarray, roller: Roller, mat: dict, quick: bool) -> np.ndarray:
    """Separations (m) from 2 rho above the composite surface's top down ROLLER_DEPTH below it and back, in steps
    of rho/8 (quick) or rho/16, as the flat cycle."""
    top = float(roller.heights(h).max())
    rho = mat["dugdale_range"]
    return separation_path(top + 2 * rho, top - ROLLER_DEPTH, rho / (8 if quick else 16))


def table_speed(cycle, mass: float) -> float:
    """Impact speed (m/s) at the table's touch that turns the body at the table's deepest state: 1/2 m v^2 =
    W_app(deepest) - m g (s_touch - s_deepest)."""
    drop = float(cycle.separation[0] - cycle.separation[cycle.turn])
    return math.sqrt(2 * (float(approach_work(cycle)[-1]) - mass * STANDARD_G * drop) / mass)


def drop(cycle, mass: float, speed: float, label: str) -> dict:
    """The driver's first impact at `speed` on the table `cycle`: its record (SI)."""
    law = TabulatedCycleLaw(cycle, label)
    run = simulate(law, mass, STANDARD_G, impact_velocity=speed, settings=SETTINGS)
    b = run.bounces[0]
    k0 = 0.5 * mass * speed * speed
    stuck = run.status == "stuck"
    balance = impact_outcome(cycle, float(approach_work(cycle)[-1]))
    return {"status": run.status, "stuck": stuck, "restitution": b.restitution,
            "rebound_height_m": 0.0 if stuck else b.rebound_height, "impact_energy_J": k0,
            "loss_J": b.energy_booked, "turn_m": -b.max_penetration, "peak_force_N": b.peak_force,
            "energy_audit_max_relative_error": run.audit["max_relative_error"],
            "energy_balance_restitution": balance.restitution, **{k: v for k, v in law.diagnostics().items()
                                                                  if k in ("turn_shift_m", "turn_shift_over_step")}}


def reference(grids: dict, desc: dict, mat: dict, roller: Roller, path: np.ndarray) -> tuple[dict, dict]:
    """The reference's roller tables on the reference grid and its half: (record, cycles by grid)."""
    n_ref = desc["reference_grid"]
    cycles, solvers = {}, {}
    for n in (n_ref // 2, n_ref):
        cyc, stats = bem_cycle(roller.heights(grids[n]), desc["size_m"], mat["e_star"], mat["work_of_adhesion"],
                               mat["z0"], path)
        cycles[n], solvers[str(n)] = cyc, stats.to_json()
    return {"grids": {str(n): {"hysteresis_energy_J": c.hysteresis_energy, "pull_off_force_N": c.pull_off_force}
                      for n, c in cycles.items()}, "solvers": solvers}, cycles


def path_to(path: np.ndarray, turn: float) -> np.ndarray:
    """The approach states of `path` above `turn` (m), then `turn`, and back: a table that keeps the states (so the
    approach work) of the table it came from and turns exactly at `turn`."""
    down = path[:int(np.argmin(path)) + 1]
    down = np.append(down[down > turn], turn)
    return np.concatenate([down, down[-2::-1]])


#: Reruns of a summit level's table to the body's turn: each keeps the previous table's approach states, so the
#: turn moves only by the last segment's change (second order in the step); two bring it to ~1e-6 of a step.
RERUNS = 3


def level_impact(build, mass: float, speed: float, path: np.ndarray, label: str) -> tuple[dict, object]:
    """A summit level's impact: its table to 3x the reference's depth, where the body turns on it (solved on the
    table's exact approach work, `TabulatedCycleLaw.turn_for`), the table rerun to that turn (`path_to`, RERUNS
    times), the drop through the driver. `build(path)` -> the level's roller cycle along `path`. (record, the final
    table); the record says `not_run` where the deep table does not stop the body."""
    start, deepest = float(path[0]), float(path.min())
    step = float(np.max(np.abs(np.diff(path))))
    table = separation_path(start, start - 3 * (start - deepest), step)
    cycle = build(table)
    for k in range(RERUNS):
        turn = TabulatedCycleLaw(cycle, label).turn_for(speed, mass, STANDARD_G, below=0.0 if k == 0 else step)
        if not np.isfinite(turn):
            return {"not_run": f"the table down to {table.min():.3g} m does not stop the body"}, None
        table = path_to(table, turn)
        cycle = build(table)
    out = drop(cycle, mass, speed, label)
    out["turn_located_m"] = turn
    return out, cycle


def compare(grids: dict, desc: dict, mat: dict, sets: dict, levels: dict, quick: bool) -> dict:
    """The roller impact for the reference and every level (`levels`: name -> builder(sets, mat, path, roller)).
    Returns {"body": ..., "reference": ..., "levels": {name: record}, "curves": ...}."""
    n_ref = desc["reference_grid"]
    roller = Roller(ROLLER_RADIUS, desc["size_m"])
    path = roller_path(grids[n_ref], roller, mat, quick)
    t0 = time.perf_counter()
    record, bem = reference(grids, desc, mat, roller, path)
    ref_seconds = time.perf_counter() - t0
    mass = roller.mass(BODY_DENSITY)
    speed = table_speed(bem[n_ref], mass)
    ref = drop(bem[n_ref], mass, speed, f"bem {n_ref}^2")
    # the half grid at the same speed turns elsewhere on its own table: rerun once to that turn (keeping its states)
    t0 = time.perf_counter()
    n_half, step = n_ref // 2, float(np.max(np.abs(np.diff(path))))
    turn = TabulatedCycleLaw(bem[n_half], "half").turn_for(speed, mass, STANDARD_G, below=step)
    if np.isfinite(turn):
        bem[n_half], _ = bem_cycle(roller.heights(grids[n_half]), desc["size_m"], mat["e_star"],
                                   mat["work_of_adhesion"], mat["z0"], path_to(path, turn))
    half = drop(bem[n_half], mass, speed, f"bem {n_half}^2")
    half["seconds"] = record["solvers"][str(n_half)]["seconds"] + time.perf_counter() - t0
    touching = int(np.sum(sets["own_heights"] - roller.drop(sets["own_x"], sets["grid"]) > path.min()))
    body = {"shape": "short roller across the patch (axis along y through x = L/2), as long as the patch is wide",
            "radius_m": roller.radius, "length_m": roller.size, "density_kg_m3": BODY_DENSITY, "mass_kg": mass,
            "impact_velocity_m_s": speed, "impact_energy_J": 0.5 * mass * speed * speed,
            "drop_height_m": speed * speed / (2 * STANDARD_G), "table_depth_m": ROLLER_DEPTH,
            "reach_band_x_over_L": roller.reach_band(grids[n_ref], float(path.min()), mat["dugdale_range"]),
            "summits_reached_at_turn": touching, "summits_on_patch": int(sets["own_heights"].size),
            "method": "each level's quasi-static cycle under the roller, tabulated "
                      "(continuum/dynamics/tabulated_cycle.py) and integrated by continuum/dynamics/driver.py (first "
                      "impact); the speed turns the body at "
                      "the reference table's deepest state; summit levels rerun to their own turn"}
    rich = 2 * bem[n_ref].hysteresis_energy - record["grids"][str(n_ref // 2)]["hysteresis_energy_J"]
    k0 = body["impact_energy_J"]
    record.update(seconds=ref_seconds, impact=ref, half_grid_impact=half,
                  loss_richardson_J=rich,
                  restitution_at_extrapolated_loss=math.sqrt(max(0.0, 1 - rich / k0)) if rich > 0 else None,
                  note="the reference's loss per cycle is not converged in the pixel (bem_convergence): its half "
                       "grid's impact and the first-order extrapolation of the loss show how far that moves e")
    rows, curves = {}, {"separation_m": path.tolist(), "bem": bem[n_ref].force.tolist()}
    for name, build in levels.items():
        t0 = time.perf_counter()
        out, cycle = level_impact(lambda p, b=build: b(sets, mat, p, roller), mass, speed, path, name)
        out["seconds"] = time.perf_counter() - t0
        rows[name] = out
        if cycle is not None:
            curves[name] = {"separation_m": cycle.separation.tolist(), "force_N": cycle.force.tolist()}
    return {"body": body, "reference": record, "levels": rows, "curves": curves}


def rebound_error(row: dict, ref: dict) -> float:
    """(h1 - h1_ref) / h1_ref of first-rebound heights; nan where the reference sticks (h1_ref = 0) or the level
    did not run."""
    if "rebound_height_m" not in row or not ref["rebound_height_m"]:
        return math.nan
    return (row["rebound_height_m"] - ref["rebound_height_m"]) / ref["rebound_height_m"]
