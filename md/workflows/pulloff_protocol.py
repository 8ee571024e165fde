"""The pull-off workflow's plan pieces (:class:`md.workflows.pulloff.PullOff`): the legs of one tip position
(approach, hold, retractions), their per-(re)start commands and sampled columns, the thermostats of the flat and
the asperity, and the lateral tip offsets."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from md import units as U
from md.engine.plan import Leg, Stage
from md.system.topology import System
from md.workflows.common import (
    Settings,
    common_define,
    derived_seed,
    equilibrate_stage,
    fresh_from_data,
    minimize_lines,
    restart_header_lines,
    round_up,
    stage_list,
    steps_of,
    thermostat_lines,
)


def leg_name(base: str, position: int) -> str:
    """The name of a leg at tip position ``position``: position 0 keeps the plain name (``approach``,
    ``retract_0``), the others carry ``_p<k>`` (``approach_p1``, ``retract_p1_0``)."""
    if position == 0:
        return base
    head, _, tail = base.partition("_")
    return f"{head}_p{position}" + (f"_{tail}" if tail else "")


def measures_flat(s: Settings) -> bool:
    """Whether the flat's thermostat force is sampled (columns f_flat, p_flat): with the silica-only flat
    thermostat or several tip positions."""
    return s.flat_thermostat != "mobile" or int(s.tip_positions) > 1


def tip_offsets(n: int, cell: tuple[float, float]) -> list[tuple[float, float]]:
    """``n`` lateral offsets (A) of the tip over the flat: the first zero, the others the R2 quasi-random sequence
    (Roberts 2018: k (1/phi2, 1/phi2^2) mod 1, phi2 the plastic number) over the fundamental domain [0, 1) x
    [0, 1/2) of the flat's rectangular surface cell ``cell``. That cell is centred on the cristobalite faces
    (its (1/2, 1/2) point is a lattice translation), so the half cell is the primitive cell and no offset but the
    first is a lattice translation (or a copy of another)."""
    phi2 = 1.324717957244746
    a = np.array([1.0 / phi2, 1.0 / phi2 ** 2])
    k = np.arange(int(n))[:, None]
    frac = np.mod(k * a, 1.0) * np.array([1.0, 0.5])
    return [(round(float(u * cell[0]), 6), round(float(v * cell[1]), 6)) for u, v in frac]


def shift_tip(system: System, offset) -> System:
    """The system with the tip (asperity and holder, group 'adsorbate') moved laterally by ``offset`` (A); the
    data writer wraps it into the periodic box."""
    pos = system.positions.copy()
    pos[system.group("adsorbate"), :2] += np.asarray(offset, float)
    return replace(system, positions=pos)


def sample_columns(s: Settings) -> dict[str, str]:
    columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_holder": "v_zh", "tip_zmin": "v_tipmin",
               "flat_zmax": "v_flatmax", "f_holder": "f_hold_holder[3]", "p_tip": "v_ptip"}
    if measures_flat(s):
        columns.update(f_flat="f_hold_flat[3]", p_flat="v_pflat")
    return columns


def leg_define(s: Settings, salt: int):
    """The per-(re)start commands of every pull-off leg: holds, the group/group force, sampled variables and the
    thermostats (``salt`` varies the Langevin seeds between legs)."""
    def d(step: int) -> list[str]:
        return common_define(s, "mobile") + [
            "neigh_modify exclude group flat_fixed flat_fixed",
            "neigh_modify exclude group holder_rigid holder_rigid",
            "fix hold_flat flat_fixed setforce 0.0 0.0 0.0",
            "fix hold_holder holder_rigid setforce 0.0 0.0 0.0",
            "fix move_holder holder_rigid nve",
            "compute gg tip group/group flat kspace yes",
            "variable zh equal xcm(holder_rigid,z)", "variable tipmin equal bound(tip,zmin)",
            "variable flatmax equal bound(flat,zmax)",
            "variable ptip equal mass(tip_mobile)*vcm(tip_mobile,z)"] + \
            (["variable pflat equal mass(flat_mobile)*vcm(flat_mobile,z)"] if measures_flat(s) else []) + \
            pulloff_thermostat(s, step, salt)
    return d


def position_legs(s: Settings, ff, data: Path, groups: Mapping[str, Any], n: int, p: int,
                   run_dir: Path) -> list[Leg]:
    """The legs of tip position ``p``: its approach (equilibrate, approach, hold: its own contact) and, from the
    restart at the end of its hold, ``retract_repeats`` retractions per speed. Position 0 has the seeds and salts
    of a single-position run; the others shift them."""
    dt, si, seed, t = s.timestep_fs, s.sample_interval, int(s.seed), s.temperature_K
    v_app = U.m_per_s_to_angstrom_per_fs(s.approach_speed_m_s)
    n_app = round_up(s.approach_distance_A / (v_app * dt), si)
    columns = sample_columns(s)
    base = 1000 * p
    extra = ["group flat_silica subtract flat_mobile flat_sam"] if "flat_sam" in groups else []

    def fresh(leg_dir: Path) -> list[str]:
        return fresh_from_data(ff, data, s, groups) + [
            "group held union flat_fixed holder_rigid", "group mobile subtract all held",
            "group flat_mobile subtract flat flat_fixed", "group tip_mobile subtract tip holder_rigid"] + extra

    vz = lambda v: f"velocity holder_rigid set 0.0 0.0 {v:.10g} units box"
    approach = Leg(                       # reads only its position's data file: starts at once with --jobs
        name=leg_name("approach", p), fresh=fresh, define=leg_define(s, base), after=(),
        prepare=lambda d: minimize_lines(s, d / "minimized.data"), restart_head=restart_header_lines(s),
        stages=stage_list(equilibrate_stage(s, "mobile", 1 + base, (vz(0.0),)),
                          Stage("approach", n_app, (vz(-v_app),)),
                          Stage("hold", steps_of(s.hold_steps, s.sample_interval), (vz(0.0),))),
        columns=columns, sample_interval=si, chunk_steps=s.chunk_steps, n_atoms=n,
        info={"v_approach_A_fs": v_app, **({"position": p} if s.tip_positions > 1 else {})})
    legs = [approach]
    approach_dir = run_dir / "legs" / approach.name
    repeats = int(s.retract_repeats)
    for k, v in enumerate(s.retract_speeds_m_s):
        v_ret = U.m_per_s_to_angstrom_per_fs(v)
        n_ret = round_up(s.retract_distance_A / (v_ret * dt), si)
        for j in range(repeats):
            def fresh_retract(leg_dir: Path, _total=approach.total_steps) -> list[str]:
                return restart_header_lines(s)(approach_dir / f"restart.{_total}") + [f"timestep {dt:g}"]
            stages = [Stage("retract", n_ret, (vz(v_ret),))]
            if repeats > 1:     # independent pulls: fresh velocities, then hold_steps more in contact
                vseed = derived_seed(seed, 7, k, j) if p == 0 else derived_seed(seed, 7, k, j, p)
                stages = stage_list(Stage("rehold", steps_of(s.hold_steps, s.sample_interval), (
                    f"velocity mobile create {t:g} {vseed} mom yes rot no dist gaussian",
                    vz(0.0)), sampled=False)) + stages
            legs.append(Leg(name=leg_name(f"retract_{k}" + (f"_{j}" if j else ""), p), fresh=fresh_retract,
                            after=(approach.name,),       # from the end of its position's hold
                            define=leg_define(s, base + 100 + 10 * k + j), prepare=lambda d: ["reset_timestep 0"],
                            restart_head=restart_header_lines(s), stages=stages, columns=columns,
                            sample_interval=si, chunk_steps=s.chunk_steps, n_atoms=n,
                            info={"speed_m_s": v, "v_A_fs": v_ret, "repeat": j,
                                  **({"position": p} if s.tip_positions > 1 else {})}))
    return legs


def _thermostat_fix(name: str, group: str, settings: Settings, step: int, salt: int) -> list[str]:
    """A named thermostat fix on ``group`` (Langevin + nve, or Nose-Hoover nvt)."""
    t = settings.temperature_K
    damp = settings.thermostat_damping_fs
    if settings.thermostat == "nose-hoover":
        return [f"fix {name} {group} nvt temp {t:g} {t:g} {damp:g}"]
    return [f"fix {name} {group} langevin {t:g} {t:g} {damp:g} {derived_seed(settings.seed, 17, salt, step)} zero yes",
            f"fix {name}_nve {group} nve"]


def pulloff_thermostat(s: Settings, step: int, salt: int) -> list[str]:
    """The pull-off thermostats (recipe ``tip_thermostat``, ``flat_thermostat``): the flat's mobile atoms (or only
    its silica, the SAM then NVE); the asperity's mobile
    atoms in its own frame ('comoving': a temp/com bias, so drag and noise act on the thermal velocities only and
    sum to zero over the asperity), not at all ('none': NVE), or together with the
    flat in the lab frame ('lab')."""
    mode = s.tip_thermostat
    if mode == "lab":
        return thermostat_lines("mobile", s, step, salt)
    if s.flat_thermostat == "silica" and s.surface == "ots":
        cmds = _thermostat_fix("thermo_flat", "flat_silica", s, step, 2 * salt) + \
            ["fix integrate_flat_sam flat_sam nve"]
    else:
        cmds = _thermostat_fix("thermo_flat", "flat_mobile", s, step, 2 * salt)
    if mode == "comoving":
        cmds += ["compute tip_com tip_mobile temp/com"] + \
            _thermostat_fix("thermo_tip", "tip_mobile", s, step, 2 * salt + 1) + ["fix_modify thermo_tip temp tip_com"]
    else:
        cmds += ["fix integrate_tip tip_mobile nve"]
    return cmds
