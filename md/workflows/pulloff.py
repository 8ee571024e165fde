"""Asperity pull-off (:class:`PullOff`).

pulloff
    A hemispherical asperity on a holder, flipped onto a flat. The flat's bottom layer is fixed; the
    holder's back is moved rigidly (``velocity set`` + ``setforce 0 0 0``: constant speed) -- approach, hold,
    retract (``retract_repeats`` times per speed, each with fresh velocities). The flat and the asperity have
    separate thermostats, the asperity's in its own frame (no drag on its motion); the residual drag is measured
    from the holder's reaction. The force on the asperity is ``compute group/group`` (asperity body vs flat,
    ``kspace yes``); the separation is the rigid-holder gap (apex to the top of the flat at the minimised start,
    plus the holder's travel). :func:`md.analysis.pull_off_analysis` gives the maximum tensile force, a 9-3 z0
    (validation only: it absorbs the asperity's compliance) and Delta gamma_eff = F/(1.5 pi R) (JKR) and
    F/(2 pi R) (DMT, the limit at MD scale). At production a rate scan branches several retractions from the same
    held contact and extrapolates (:func:`md.analysis.rate_extrapolation`) from three or more speeds.
    ``tip_positions`` > 1 repeats approach, hold and retractions at several lateral offsets of the tip over the
    flat (each its own held contact: the spread then includes the geometric variance); ``flat_thermostat``
    'silica' leaves the flat's SAM out of the lab-frame thermostat and measures the flat-side thermostat force.
    The prediction to compare with is :func:`md.analysis.pulloff.surface_element_pull_off` (the flat-slab traction
    law integrated over the asperity's height map).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from md import analysis as A
from md import units as U
from md.analysis.pulloff import SILICA_E_STAR_PA, tabor_parameter
from md.build import flip_upside_down, graft_dome, place_on, silica_asperity
from md.engine.plan import Analysis, Leg, Plan
from md.system.atoms import as_system
from md.system.lammps_data import read_atoms, write_data
from md.system.topology import System
from md.workflows.common import (
    Settings,
    Workflow,
    derived_seed,
    figure_writer,
    forcefield_of,
    intersect_ids,
    quantity_record,
    silica_face_of,
    surface_slab,
    system_summary,
)
from md.workflows.plan_records import PullOffPlanRecord
from md.workflows.pulloff_protocol import leg_name, measures_flat, position_legs, shift_tip, tip_offsets

# ================================================================================================ pull-off

class PullOff(Workflow):
    """Asperity approach-hold-retract against a flat at constant holder speed.

    The moving asperity is not dragged by the thermostat (``tip_thermostat``: 'comoving' thermostats only its
    thermal motion, a temp/com bias; the flat has its own thermostat): a lab-frame Langevin thermostat drags an
    asperity moving at v with gamma M v, which at tens of m/s dwarfs a pull-off force of a fraction of a nN. The
    residual drag on the asperity is measured from the holder's reaction and reported; ``retract_repeats``
    independent retractions per speed give the pull-off force a spread (from one held contact: "same contact");
    ``tip_positions`` gives each position its own contact; the OTS asperity carries >= 4 chains per nm^2 of
    projected cap. ``version`` enters the run hash; the options at their neutral values
    (:data:`md.recipe.NEUTRAL_KEYS`) run the same plan as without them."""
    name = "pulloff"
    version = 2
    yields = {"pull_off_force": "N", "separation_at_max_tension": "m", "interaction_range_z0": "m",
              "work_of_adhesion_eff_jkr": "J/m^2", "work_of_adhesion_eff_dmt": "J/m^2"}

    def _forcefield_files(self, s: Settings) -> list[str]:
        return ["silica_interface"] + (["ots_trappe_ua"] if s.surface == "ots" else [])

    def build(self, s) -> tuple[System, dict[str, Any]]:
        seed = int(s.seed)
        R = float(s.asperity_radius_A)
        face = silica_face_of((s.surface,), s.silica_face)
        dens = s.silanol_density if face == "001" else 4.5
        asp = as_system(silica_asperity(radius=R, holder_thickness=s.holder_thickness_A,
                                        margin=s.asperity_margin_A, silanol_density=dens, face=face, seed=seed,
                                        lattice_a=s.silica_lattice_A))
        nx, ny = asp.info["surface_cells"]
        fnx, fny = (s.flat_nx or nx), (s.flat_ny or ny)
        if (fnx, fny) != (nx, ny):
            raise ValueError(f"flat_nx/flat_ny ({fnx}, {fny}) must match the asperity's holder cells ({nx}, {ny}) "
                             f"(both are periodic in x and y); set them to 0")
        flat = surface_slab(s.surface, nx, ny, s.flat_thickness_A, s, seed + 20, face)
        info: dict[str, Any] = {"radius_A": R, "face": face}
        if s.surface == "ots":
            asp, ginfo = graft_dome(asp, radius_A=R, max_polar_deg=s.graft_max_polar_deg,
                                    coverage_nm2=s.sam_coverage, chain_length=s.chain_length, seed=seed + 30)
            info["asperity_sam"] = ginfo
        system = as_system(place_on(flat, flip_upside_down(asp), gap=s.initial_gap_A,
                                    vacuum=s.retract_distance_A + 15.0))
        info.update(asperity=system_summary(asp), flat=system_summary(flat), box_A=system.cell.tolist())
        if s.tip_positions > 1:
            info["tip_offsets_A"] = tip_offsets(s.tip_positions, (system.cell[0] / nx, system.cell[1] / ny))
        return system, info

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        ff = forcefield_of(self.forcefield_files(s))
        system, info = self.build(s)
        groups = {"flat": system.group("substrate"), "tip": system.group("adsorbate"),
                  "flat_fixed": intersect_ids(system, "frozen", "substrate"),
                  "holder_rigid": intersect_ids(system, "frozen", "adsorbate")}
        if s.flat_thermostat == "silica" and s.surface == "ots":
            groups["flat_sam"] = intersect_ids(system, "sam", "substrate")
        tip_mobile = np.setdiff1d(groups["tip"], groups["holder_rigid"])
        n = system.n_atoms
        seed = int(s.seed)
        legs: list[Leg] = []
        for p, offset in enumerate(info.get("tip_offsets_A", [(0.0, 0.0)])):
            data = run_dir / ("system.data" if p == 0 else f"system_p{p}.data")
            write_data(system if p == 0 else shift_tip(system, offset), ff, data)
            legs += position_legs(s, ff, data, groups, n, p, run_dir)
        info.update(n_flat=int(len(groups["flat"])), n_tip=int(len(groups["tip"])),
                    tip_mobile_mass_g_mol=float(system.masses[tip_mobile].sum()), tip_thermostat=s.tip_thermostat)
        if measures_flat(s):
            info.update(flat_thermostat=s.flat_thermostat, n_flat_sam=int(len(groups.get("flat_sam", ()))))
        return Plan(legs=legs, timestep_fs=s.timestep_fs, n_atoms=n,
                    seeds={"structure_asperity": seed, "structure_flat": seed + 20,
                           "velocities": derived_seed(seed, 3, 1),
                           "thermostat_base": seed, **({"sam_asperity": seed + 30} if s.surface == "ots" else {})},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        return _PullOffAnalysis(ctx, ctx.settings).run()


@dataclass(slots=True)
class _PullOffResults:
    """What :class:`_PullOffAnalysis` computes, in one place, filled in as :meth:`~_PullOffAnalysis.run` goes: the
    tip radius, each position's origin (the flat's surface, the holder's start), the pulls per speed and their
    summaries, the approach curve, the smoothing, the force, the lab-frame drag, curves and figures. Slotted: a name
    not declared here cannot be set."""
    R_m: float | None = None                          # the asperity's radius (m)
    origin: dict[int, tuple[float, float]] = field(default_factory=dict)   # position -> (flat surface, holder) A
    s0: float | None = None
    zh0: float | None = None
    dt: float | None = None                           # fs
    curves: dict[str, Any] = field(default_factory=dict)
    figures: dict[str, Any] = field(default_factory=dict)
    pulls: list[tuple] = field(default_factory=list)  # (speed m/s, repeat, leg, pull-off record)
    smooth: int | None = None
    d_app: dict[str, np.ndarray] | None = None        # the approach leg's samples
    speeds: list[float] = field(default_factory=list)
    per_speed: list[dict[str, Any]] = field(default_factory=list)
    F: float | None = None                            # the slowest speed's pull-off force (kcal/mol/A)
    gamma_lab: float | None = None


class _PullOffAnalysis:
    """Pull-off force, z0 and the residual drag from the retraction legs, in the MDAnalysis manner:
    :meth:`_prepare` (the separation's origin), :meth:`_single_retraction` for every retraction leg,
    :meth:`_conclude` (per-speed means, quantities, notes, a rate extrapolation over several speeds, curves and the
    figure)."""

    def __init__(self, ctx, s):
        self.ctx, self.s = ctx, s
        self.plan = PullOffPlanRecord.from_system(ctx.plan.system_info)
        self.results = _PullOffResults()

    def run(self) -> Analysis:
        self._prepare()
        for leg in self.ctx.plan.legs:
            if leg.name.startswith("retract_"):
                self._single_retraction(leg)
        return self._conclude()

    def _prepare(self) -> None:
        res = self.results
        ctx = self.ctx
        res.R_m = U.angstrom_to_m(self.s.asperity_radius_A)
        res.origin: dict[int, tuple[float, float]] = {}
        n_flat = self.plan.n_flat
        for p in range(self.plan.positions):
            name = leg_name("approach", p)
            ids, _, pos = read_atoms(ctx.leg_dir(name) / "minimized.data")
            # ids 1..n_flat are the flat (place_on puts the substrate first)
            s0 = pos[n_flat:, 2].min() - pos[:n_flat, 2].max()
            # the holder's height at the minimised start: it does not move before the approach stage, so the first
            # sample of the equilibration has it exactly
            res.origin[p] = (float(s0), float(ctx.samples(name, False)["z_holder"][0]))
        res.s0, res.zh0 = res.origin[0]
        res.dt = ctx.plan.timestep_fs
        res.curves, res.figures, res.pulls = {}, {}, []
        res.smooth = None

    def sep(self, d, position: int = 0) -> np.ndarray:
        """The rigid-holder separation (A) of the samples ``d`` of tip position ``position``."""
        s0, zh0 = self.results.origin[position]
        return s0 + (d["z_holder"] - zh0)

    def _single_retraction(self, leg) -> None:
        res = self.results
        d = self.ctx.samples(leg)
        n = len(d["step"])
        res.smooth = smooth = max(5, (n // 25) | 1) if n >= 15 else None
        p = int(leg.info.get("position", 0))
        r = A.pull_off_analysis(self.sep(d, p), d["fz"], smooth=smooth, radius_m=res.R_m)
        r["local_noise"] = _local_noise(r, smooth)
        r["drag"] = _residual_drag(d, res.dt)
        if "f_flat" in d:
            r["flat_drag"] = _residual_drag(d, res.dt, side="flat")
        r["position"] = p
        res.pulls.append((leg.info["speed_m_s"], leg.info.get("repeat", 0), leg.name, r))
        res.curves[f"pulloff_curve_{leg.name}"] = (
            ["separation_m", "force_N", "force_smoothed_N"],
            np.column_stack([r["curve"]["separation"], r["curve"]["force"], r["curve"]["force_smoothed"]]))

    def _conclude(self) -> Analysis:
        res = self.results
        res.d_app = d_app = self.ctx.samples("approach", False)
        res.curves["approach_curve"] = (["step", "stage", "separation_m", "force_N"],
                                        np.column_stack([d_app["step"], d_app["stage"],
                                                          U.angstrom_to_m(self.sep(d_app)),
                                                          U.kcal_per_mol_A_to_N(d_app["fz"])]))
        res.speeds = speeds = sorted({v for v, *_ in res.pulls})
        res.per_speed = [_speed_summary(float(v), [r for vv, _, _, r in res.pulls if vv == v]) for v in speeds]
        q = self._quantities()
        notes = self._notes(q)
        details = self._details()
        if len(speeds) == 2 and len(res.origin) >= 2:
            details["speed_difference"] = _paired_speed_difference(res.per_speed)
            notes.append(_speed_difference_note(details["speed_difference"]))
        if len(speeds) >= 3:
            ext = A.rate_extrapolation(np.array(speeds), np.array([p["force"] for p in res.per_speed]),
                                       target_rate=float(min(speeds)) / 10.0, temperature_K=self.s.temperature_K)
            q["pull_off_force_extrapolated"] = quantity_record(ext["F0"], ext["stderr"], "N",
                                                  kind=f"F = a + b ln(v) fitted to {len(speeds)} speeds, "
                                                       f"evaluated at {ext['target_rate']:g} m/s")
            details["rate_extrapolation"] = ext
            notes.append("rate scan: F = a + b ln(v) (Bell-Evans) extrapolated one decade below the slowest "
                         "simulated speed; valid only while the Bell-Evans regime holds.")
        res.figures["pulloff_curve"] = figure_writer(self._draw)
        return Analysis(quantities=q, curves=res.curves, figures=res.figures, notes=notes, details=details)

    def _quantities(self) -> dict:
        """The slowest speed's pull-off force (mean of its pulls), z0, the effective works of adhesion and the
        residual drag on the asperity."""
        res = self.results
        slow = res.per_speed[0]
        best = slow["results"][0]
        F, f_err = slow["force"], slow["stderr"]
        res.F = F
        R_m = res.R_m
        z0q = _z0_quantity(best) if len(slow["results"]) == 1 else _z0_mean([r for r in slow["results"]])
        drag = np.array([r["drag"]["value"] for r in slow["results"]])
        drag_err = np.array([r["drag"]["stderr"] for r in slow["results"]])
        v_slow = U.m_per_s_to_angstrom_per_fs(slow["speed_m_s"])
        res.gamma_lab = gamma_lab = U.g_per_mol_A_per_fs2_to_kcal_per_mol_A(
            self.plan.tip_mobile_mass_g_mol * v_slow / self.s.thermostat_damping_fs)
        err = lambda x: x / (2 * math.pi * R_m) if x else None
        extra = {"positions": slow["positions"]} if slow["positions"] > 1 else {}
        q = {"pull_off_force": quantity_record(F, f_err, "N", speed_m_s=slow["speed_m_s"],
                                                  repeats=len(slow["results"]), **extra,
                                                  kind=f"maximum tensile force on retraction ({slow['what']}; "
                                                       f"stderr: {slow['how']})"),
                "separation_at_max_tension": quantity_record(best["separation_at_max"], None, "m"),
                "interaction_range_z0": z0q,
                "work_of_adhesion_eff_jkr": quantity_record(F / (1.5 * math.pi * R_m),
                                                            f_err / (1.5 * math.pi * R_m) if f_err else None,
                                                            "J/m^2", kind="F / (1.5 pi R)"),
                "work_of_adhesion_eff_dmt": quantity_record(F / (2 * math.pi * R_m), err(f_err), "J/m^2",
                                               kind="F / (2 pi R): compare with the flat-slab W_F (DMT limit; "
                                                    "Tabor's parameter in the notes)"),
                "residual_drag_force": quantity_record(float(U.kcal_per_mol_A_to_N(drag.mean())),
                                          float(U.kcal_per_mol_A_to_N(math.sqrt(np.sum(drag_err ** 2)) / len(drag))),
                                          "N", kind="mean thermostat force on the moving asperity along the pulling "
                                                    "axis on retraction (holder reaction - interaction + momentum "
                                                    "change)",
                                          lab_frame_drag_N=float(U.kcal_per_mol_A_to_N(-gamma_lab)))}
        flat = [r["flat_drag"] for r in slow["results"] if "flat_drag" in r]
        if flat:
            q["flat_thermostat_force"] = quantity_record(
                float(U.kcal_per_mol_A_to_N(np.mean([f["value"] for f in flat]))),
                float(U.kcal_per_mol_A_to_N(math.sqrt(sum(f["stderr"] ** 2 for f in flat)) / len(flat))), "N",
                kind=f"mean force of the flat's thermostat ('{self.s.flat_thermostat}') on the flat's mobile atoms "
                     "along the pulling axis on retraction (holder-of-the-flat reaction + interaction + momentum "
                     "change); it reaches the asperity through the interface")
        return q

    def _notes(self, q: dict) -> list[str]:
        res = self.results
        s, slow, F, R_m = self.s, res.per_speed[0], res.F, res.R_m
        notes = [f"separation = gap between the lowest asperity atom and the highest flat atom at the minimised "
                 f"start ({res.s0:.2f} A) plus the rigid holder's travel (no correction for the asperity's or the "
                 f"flat's deformation); force = compute group/group (asperity body vs flat, kspace yes), "
                 f"positive = repulsive.",
                 f"pull-off force at {slow['speed_m_s']:g} m/s: {slow['what']}; stderr: {slow['how']}.",
                 f"thermostat on the asperity: '{s.tip_thermostat}'"
                 + {"comoving": " (its thermal motion only: compute temp/com bias, so no drag on its motion; the flat "
                                "has its own thermostat)",
                    "none": " (the asperity runs NVE; only the flat is thermostatted)",
                    "lab": " (lab frame, every mobile atom together with the flat: it drags the moving asperity)"}[
                     s.tip_thermostat]
                 + f"; residual drag measured {q['residual_drag_force']['value'] * 1e9:+.3f} nN against "
                   f"{-res.gamma_lab * U.kcal_per_mol_A_to_N(1.0) * 1e9:.2f} nN that a lab-frame thermostat "
                   f"(gamma M v) would apply.",
                 _flat_thermostat_note(s, q.get("flat_thermostat_force")),
                 f"validation, not calibration: F / (2 pi R) = {F / (2 * math.pi * R_m):.4f} J/m^2 is the number "
                 f"to compare with the flat-slab work of adhesion W_F (the calibration report does); "
                 + _tabor_note(R_m, F / (2 * math.pi * R_m), q["interaction_range_z0"]["value"], s.surface),
                 f"R = {s.asperity_radius_A:g} A (the requested radius of the carved, faceted dome)."]
        if s.surface == "ots":
            g = self.plan.asperity_sam
            notes.append(f"OTS chains on the asperity: {g.get('chains')} on dome silanols within "
                         f"graft_max_polar_deg of the apex ({g.get('chains_per_projected_nm2', float('nan')):.2f} per "
                         f"nm^2 of projected cap, lateral spacing >= {g.get('min_spacing_A', float('nan')):.2f} A); "
                         "they point along the pulling axis, not along the local normal (the builder grafts along "
                         "one axis); the chain-end surface is the dome translated by the chain vector, so its "
                         "curvature radius is still R.")
        return notes

    def _details(self) -> dict:
        res = self.results
        return {"per_speed": [{"speed_m_s": p["speed_m_s"], "max_tensile_force_N": p["force"],
                               "stderr_N": p["stderr"], "forces_N": p["forces"], "stderr_how": p["how"],
                               "positions": p["positions"], **({"t_factor": p["t_factor"],
                                                               "stderr_plain_N": p["stderr_plain"]}
                                                              if p["positions"] > 1 else {})}
                              for p in res.per_speed],
                "per_position": [dict(pp, speed_m_s=p["speed_m_s"]) for p in res.per_speed
                                 for pp in p["per_position"]],
                "tip_offsets_A": self.plan.tip_offsets_A or [[0.0, 0.0]],
                "pulls": [{"leg": name, "speed_m_s": float(v), "repeat": j, "position": r["position"],
                           "contact": leg_name("approach", r["position"]),
                           "same_contact_as": [n2 for _, _, n2, r2 in res.pulls
                                               if r2["position"] == r["position"] and n2 != name],
                           "max_tensile_force_N": r["max_tensile_force"],
                           "separation_at_max_m": r["separation_at_max"], "z0_m": r["z0"],
                           "z0_stderr_m": r["z0_stderr"], "z0_zero_to_min_m": r["z0_zero_to_min"],
                           "zero_force_separation_m": r["zero_force_separation"],
                           "local_noise_N": r["local_noise"],
                           "residual_drag_N": float(U.kcal_per_mol_A_to_N(r["drag"]["value"])),
                           "residual_drag_stderr_N": float(U.kcal_per_mol_A_to_N(r["drag"]["stderr"])),
                           **({"flat_thermostat_force_N": float(U.kcal_per_mol_A_to_N(r["flat_drag"]["value"])),
                               "flat_thermostat_force_stderr_N": float(U.kcal_per_mol_A_to_N(
                                   r["flat_drag"]["stderr"]))} if "flat_drag" in r else {}),
                           "traction_fit": {k: v for k, v in r["traction_fit"].items()
                                            if isinstance(v, (int, float, str, dict))}}
                          for v, j, name, r in res.pulls],
                "s0_A": float(res.s0), "holder_z0_A": res.zh0, "smoothing_window": res.smooth,
                "lab_frame_drag_estimate_N": float(U.kcal_per_mol_A_to_N(-res.gamma_lab)),
                "tip_mobile_mass_g_mol": self.plan.tip_mobile_mass_g_mol}

    def _draw(self, ax) -> None:
        res = self.results
        for (v, j, name, r) in res.pulls:
            c = r["curve"]
            ax.plot(c["separation"] * 1e9, c["force"] * 1e9, lw=0.5, alpha=0.5)
            ax.plot(c["separation"] * 1e9, c["force_smoothed"] * 1e9, lw=1.5, label=f"{name} {v:g} m/s")
        ax.plot(U.angstrom_to_m(self.sep(res.d_app)) * 1e9, U.kcal_per_mol_A_to_N(res.d_app["fz"]) * 1e9, lw=0.5,
                color="grey", label="approach/hold")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("separation (nm)")
        ax.set_ylabel("force on asperity (nN)")
        ax.set_title(f"pull-off {res.F * 1e9:.3f} nN, R = {self.s.asperity_radius_A:g} Å")
        ax.legend(fontsize=7)


def _student_t(n: int) -> float:
    """Student-t factor of the one-sigma (68.27 %) interval of a mean of ``n`` samples whose stderr comes from
    their own spread (n - 1 degrees of freedom; JCGM 100:2008, annex G): 1.84 for 2, 1.32 for 3, -> 1."""
    from scipy.stats import t as student_t
    return float(student_t.ppf(0.5 * (1.0 + math.erf(1.0 / math.sqrt(2.0))), int(n) - 1))


def _speed_summary(v: float, rs: list[dict]) -> dict[str, Any]:
    """The pull-off force at one speed from its pulls ``rs``: the mean over tip positions of each position's
    mean. Over >= 2 positions (independent contacts) its stderr is the positions' spread / sqrt(n) times the
    Student-t factor (one-sigma-equivalent); with one position and several pulls, the pulls' spread, marked
    "same contact" (they branch from one held contact: no geometric variance in it); one pull, the force noise."""
    pos = sorted({r["position"] for r in rs})
    per = [{"position": p, "max_tensile_force_N": float(np.mean([r["max_tensile_force"] for r in rs
                                                                 if r["position"] == p])),
            "pulls": sum(r["position"] == p for r in rs)} for p in pos]
    fs = np.array([r["max_tensile_force"] for r in rs])
    fp = np.array([x["max_tensile_force_N"] for x in per])
    out = {"speed_m_s": v, "force": float(fp.mean()), "forces": fs.tolist(), "results": rs, "positions": len(pos),
           "per_position": per}
    if len(pos) >= 2:
        plain = float(fp.std(ddof=1) / math.sqrt(len(pos)))
        t = _student_t(len(pos))
        out.update(stderr=t * plain, stderr_plain=plain, t_factor=t,
                   what=f"mean over {len(pos)} tip positions, each its own held contact",
                   how=f"spread of the {len(pos)} positions / sqrt(n) x Student t = {t:.2f} ({len(pos) - 1} dof)")
    elif len(rs) >= 2:
        out.update(stderr=float(fs.std(ddof=1) / math.sqrt(len(rs))), what=f"mean of {len(rs)}",
                   how=f"spread of {len(rs)} pulls, same contact (all branch from one held contact at one lateral "
                       f"position: the geometric variance is not in it)")
    else:
        out.update(stderr=rs[0]["local_noise"], what="one pull", how="force noise of one curve near its maximum")
    return out


def _paired_speed_difference(per_speed: list[dict]) -> dict[str, Any]:
    """F(fast) - F(slow) per tip position (both speeds pull from the same held contact: a paired difference),
    its mean and the Student-t stderr over positions."""
    slow, fast = ({x["position"]: x["max_tensile_force_N"] for x in p["per_position"]} for p in per_speed)
    common = sorted(set(slow) & set(fast))
    dF = np.array([fast[p] - slow[p] for p in common])
    out = {"speeds_m_s": [per_speed[0]["speed_m_s"], per_speed[1]["speed_m_s"]], "positions": common,
           "difference_N": dF.tolist(), "mean_N": float(dF.mean())}
    if dF.size >= 2:
        out["stderr_N"] = _student_t(dF.size) * float(dF.std(ddof=1) / math.sqrt(dF.size))
    return out


def _speed_difference_note(d: Mapping[str, Any]) -> str:
    e = d.get("stderr_N")
    return (f"speed dependence: F({d['speeds_m_s'][1]:g} m/s) - F({d['speeds_m_s'][0]:g} m/s) = "
            f"{d['mean_N'] * 1e9:+.3f}" + (f" +- {e * 1e9:.3f}" if e is not None else "") +
            f" nN (paired per position over {len(d['positions'])} positions; the two speeds of one position pull "
            "from the same held contact).")


def _flat_thermostat_note(s: Settings, q: Mapping[str, Any] | None) -> str:
    what = {"mobile": "every mobile atom of the flat, in the lab frame (on an OTS flat its SAM too, whose chain "
                      "ends the tip drags along)",
            "silica": "the flat's silica only (the SAM of an OTS flat runs NVE: nothing the tip drags is "
                      "thermostatted in the lab frame)"}[s.flat_thermostat]
    out = f"thermostat on the flat ('{s.flat_thermostat}'): {what}"
    if q is not None:
        e = q["stderr"]
        out += (f"; its force on the flat measured {q['value'] * 1e9:+.3f}"
                + (f" +- {e * 1e9:.3f}" if e is not None else "") + " nN")
    return out + "."


def _tabor_note(R_m: float, w_eff: float, z0_m: float, surface: str) -> str:
    """Tabor's parameter of this run from its own numbers: R, W = F/(2 pi R), the retraction curve's z0 (it
    absorbs the asperity's compliance, so it overstates z0 and understates mu) and E* of silica on silica
    (:data:`md.analysis.pulloff.SILICA_E_STAR_PA`)."""
    if not (w_eff > 0 and z0_m and np.isfinite(z0_m) and z0_m > 0):
        return "Tabor's parameter not computed (no positive W or z0)."
    t = tabor_parameter(R_m, w_eff, SILICA_E_STAR_PA, z0_m)
    out = (f"Tabor mu = {t['mu']:.3f} (Maugis lambda = {t['lambda']:.3f}) from R, F / (2 pi R), the fitted z0 and "
           f"E* = {SILICA_E_STAR_PA / 1e9:.1f} GPa of silica on silica: mu < 0.1 is the DMT limit (pull-off 2 pi R "
           "W), near 1 the Maugis-Dugdale transition (about 1.9 pi R W at lambda 0.2)")
    if surface == "ots":
        out += "; the OTS layers are far more compliant than silica, so the coated contact's mu is larger"
    return out + "."


def _local_noise(r: Mapping[str, Any], smooth: int | None) -> float | None:
    """Force noise of one retraction curve near its maximum: std of raw minus smoothed force within two smoothing
    windows of the maximum (under compression the force, and its noise, is many times larger)."""
    if not smooth:
        return None
    c = r["curve"]
    resid = c["force"] - c["force_smoothed"]
    i_max = int(np.argmin(np.abs(c["separation"] - r["separation_at_max"])))
    lo, hi = max(0, i_max - 2 * smooth), min(len(resid), i_max + 2 * smooth + 1)
    return float(np.std(resid[lo:hi]))


def _residual_drag(d: Mapping[str, np.ndarray], dt_fs: float, block: int = 10,
                   side: str = "tip") -> dict[str, float]:
    """Mean thermostat force on the moving asperity's mobile atoms (``side`` 'tip') or on the flat's mobile atoms
    ('flat') along z over a retraction (kcal/mol/A).

    Newton for the asperity: dP/dt = F_thermostat + F_flat->asperity + F_holder->asperity, and the holder's
    setforce reports f_holder = F_asperity->holder + F_flat->holder; with F_gg = compute group/group of the whole
    upper body (asperity + holder) against the flat, F_thermostat = dP/dt + f_holder - F_gg. Per block of
    ``block`` samples: the time average of f_holder - F_gg (trapezoid) plus the block's momentum change over its
    duration -- the momentum term cancels the asperity's vibrations, which would otherwise swamp the mean. The value
    is the mean over blocks (= the whole leg's), the stderr from the blocks' statistical inefficiency.
    The flat by the same bookkeeping: the fixed bottom's setforce reports f_flat = F_mobile->fixed +
    F_asperity->fixed, the whole flat feels -F_gg, so F_thermostat,flat = dP_flat/dt + F_gg + f_flat."""
    if side == "flat":
        x = np.asarray(d["f_flat"], float) + np.asarray(d["fz"], float)
        p = np.asarray(d["p_flat"], float)
    else:
        x = np.asarray(d["f_holder"], float) - np.asarray(d["fz"], float)
        p = np.asarray(d["p_tip"], float)
    t = np.asarray(d["step"], float) * dt_fs
    if x.size < 3:
        return {"value": float("nan"), "stderr": float("nan")}
    edges = np.arange(0, x.size, block)
    if edges[-1] != x.size - 1:
        edges = np.append(edges, x.size - 1)
    vals, w = [], []
    for i0, i1 in zip(edges[:-1], edges[1:]):
        span = t[i1] - t[i0]
        if span <= 0:
            continue
        integral = float(np.sum(0.5 * np.diff(t[i0:i1 + 1]) * (x[i0 + 1:i1 + 1] + x[i0:i1])))
        vals.append((integral + float(U.g_per_mol_A_per_fs2_to_kcal_per_mol_A(p[i1] - p[i0]))) / span)
        w.append(span)
    vals, w = np.array(vals), np.array(w)
    st = A.timeseries_stats(vals, equilibrate=False)
    return {"value": float(np.sum(vals * w) / np.sum(w)), "stderr": st["stderr"], "blocks": int(vals.size)}


def _z0_quantity(r: Mapping[str, Any]) -> dict[str, Any]:
    """z0 of the fitted LJ 9-3 traction law, stderr from the fit's covariance; if the fit fails, from the
    zero-to-minimum distance of the curve (for the 9-3 law that distance is (3^(1/6) - 1) z0), without a stderr.
    A pull-off z0 is a validation number: it is fitted against the rigid holder's travel, so it absorbs the
    asperity's compliance; the calibration takes z0 from the flat-slab force curve of the adhesion workflow."""
    if r["z0"] is not None and np.isfinite(r["z0"]):
        e = r.get("z0_stderr")
        return quantity_record(r["z0"], e if e is not None and np.isfinite(e) else None, "m",
                  kind="z0 of the LJ 9-3 traction law fitted to the retraction curve (stderr from the fit's "
                       "covariance; includes the asperity's compliance)")
    zm = r["z0_zero_to_min"]
    return quantity_record(zm / (3 ** (1 / 6) - 1) if np.isfinite(zm) else float("nan"), None, "m",
              kind="z0 = (zero-to-minimum distance) / (3^(1/6) - 1) (the 9-3 law fit failed: "
                   f"{r['traction_fit'].get('error', '?')})")


def _z0_mean(rs: list[Mapping[str, Any]]) -> dict[str, Any]:
    """z0 over repeated pulls: the mean of the fitted z0, stderr max(spread / sqrt(n), fit stderrs / n)."""
    z = np.array([r["z0"] for r in rs if r["z0"] is not None and np.isfinite(r["z0"])])
    if not z.size:
        return _z0_quantity(rs[0])
    e = np.array([r.get("z0_stderr") or 0.0 for r in rs if r["z0"] is not None and np.isfinite(r["z0"])])
    e = np.where(np.isfinite(e), e, 0.0)
    avg = A.registry_average(z, e) if z.size >= 2 else {"mean": float(z[0]), "stderr": float(e[0]) or None}
    return quantity_record(avg["mean"], avg["stderr"], "m",
                           kind=f"mean z0 of the LJ 9-3 law fitted to {z.size} retraction "
                                f"curves (includes the asperity's compliance)")
