"""The four MD workflows: work of adhesion, asperity pull-off, contact angle, liquid-vapour surface tension.

Each workflow (1) builds its system with :mod:`md.builders` and writes it with :func:`md.lammps_data.write_data`,
(2) plans LAMMPS legs for :mod:`md.runner` -- FIRE minimisation first (the builds start strained), NVT
equilibration, sampling -- and (3) turns the stored samples into SI quantities with :mod:`md.analysis`, every
conversion through :mod:`md.units`.

Common LAMMPS set-up: ``units real``, ``atom_style full``, ``boundary p p f``, ``lj/cut/coul/long`` with PPPM
and ``kspace_modify slab 3.0`` (the Yeh-Berkowitz correction: the empty space above the system is tripled
for the Ewald sum, so periodic images along z do not interact), reflecting walls at the z faces of the box
(an evaporated molecule is turned back instead of being lost), pair coefficients and ``special_bonds`` from
the force-field files. Atoms held fixed (slab backs, whole substrates) are left out of the integrator, feel
``setforce 0 0 0`` during minimisation, and their internal pairs are excluded from the neighbour list.

adhesion
    Two slabs in contact (upper slab's back rigid, free along z at zero load) and separated by
    ``separation_A`` (> cutoff; both backs fixed). W = (<E_sep> - <E_contact>) / A from the NVT potential
    energies, block-averaged errors (:func:`md.analysis.energy_separation_work`). That is an *energy*: with
    ``free_energy = "pmf"`` the mean force between the slabs (``compute group/group`` with ``kspace yes``) is
    also sampled at fixed separations from contact to ``separation_A`` and integrated (thermodynamic
    integration along the separation), giving the free energy of separation and T dS = dE - dF.
pulloff
    A hemispherical asperity on a holder, flipped onto a flat. The flat's bottom layer is fixed; the
    holder's back is moved rigidly (``velocity set`` + ``setforce 0 0 0``: constant speed) -- approach, hold,
    retract. The force on the asperity is ``compute group/group`` (asperity body vs flat, ``kspace yes``), not
    the holder's reaction; the separation is the rigid-holder gap (apex to the top of the flat at the
    minimised start, plus the holder's travel). :func:`md.analysis.pull_off_analysis` gives the maximum
    tensile force, z0 and Delta gamma_eff = F/(1.5 pi R) (JKR) and F/(2 pi R) (DMT). At production a rate
    scan branches several retractions from the same held contact and extrapolates
    (:func:`md.analysis.rate_extrapolation`).
contact_angle
    A cylindrical droplet (periodic along y) on (111) silica with isolated Q3 silanols or on an OTS monolayer.
    The substrate is minimised with nothing held (FIRE at 1 fs), then only its deep Si and bridging O are held
    (silanol O-H by SHAKE) and it is equilibrated alone; the water is added as a cylindrical cap near its expected
    angle; water rigid (SHAKE). Water-oxygen configurations -> :class:`md.analysis.ContactAngle` (an in-memory
    MDAnalysis universe): the angle at the water's own dividing plane, W_SL = gamma_lv (1 + cos theta), a drift
    test of the block angles, and "wets" with an upper bound on the angle when the water spreads into a film.
surface_tension
    A free-standing SPC/E film; gamma = Lz/2 (<Pzz> - (<Pxx> + <Pyy>)/2) from the LAMMPS pressure tensor
    (:func:`md.analysis.surface_tension`) with the analytic LJ tail correction for the truncated LJ term
    (:func:`md.analysis.lj_tail_correction`; Coulomb is long-ranged through PPPM); bulk density from a tanh
    fit of the profile (:func:`md.analysis.slab_density`).
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from md import analysis as A
from md import units as U
from md.builders import (SILICA_FACE, flip_upside_down, ots_sam, place_on, silica_asperity, silica_slab,
                         water_cap, water_slab)
from md.forcefield import ForceField, combine, lammps_type_ids, load_forcefield
from md.lammps_data import lammps_setup_commands, write_data
from md.runner import Analysis, Frames, Leg, Plan, RunContext, Stage, id_ranges
from md.topology import System, remove_atoms, with_groups

__all__ = ["get_workflow", "WORKFLOWS", "ENERGY_NOT_FREE_ENERGY"]

ENERGY_NOT_FREE_ENERGY = (
    "work_of_adhesion is dE/A, the difference of mean potential energies (separated - contact) per area at "
    "the thermostat temperature: an energy, not the free energy of adhesion (the Dupre work). It neglects "
    "-T dS/A, the change of vibrational/conformational entropy on contact.")
WATER_MASS = 15.9994 + 2 * 1.008          # g/mol, SPC/E (force-field masses)


# ================================================================================================ LAMMPS helpers

def _seed(base: int, *salt: int) -> int:
    """A LAMMPS-valid seed (1 .. 900 000 000) derived from ``base`` and ``salt``."""
    x = int(base)
    for s in salt:
        x = (x * 1_000_003 + int(s) * 7919 + 12345) % 899_999_989
    return x + 1


def _restart_head(settings: Mapping[str, Any]) -> Callable[[Path], list[str]]:
    def head(path: Path) -> list[str]:
        return [f"read_restart {Path(path).as_posix()}",
                f"kspace_style pppm {settings['kspace_accuracy']:g}", "kspace_modify slab 3.0"] + _neighbor()
    return head


def _neighbor() -> list[str]:
    return ["neighbor 2.0 bin", "neigh_modify delay 0 every 1 check yes"]


def _fresh_from_data(ff: ForceField, data: Path, settings: Mapping[str, Any], groups: Mapping[str, Any]) -> list[str]:
    cmds = lammps_setup_commands(ff, data, boundary="p p f", pair="long", cutoff=settings["cutoff_A"],
                                 kspace_accuracy=settings["kspace_accuracy"])
    cmds += _neighbor()
    cmds += [f"timestep {settings['timestep_fs']:g}"]
    for name, idx in groups.items():
        if len(idx):
            cmds.append(f"group {name} id {id_ranges(idx)}")
        else:
            cmds.append(f"group {name} empty")
    return cmds


def _thermostat(group: str, settings: Mapping[str, Any], step: int, salt: int = 0) -> list[str]:
    t = settings["temperature_K"]
    damp = settings["thermostat_damping_fs"]
    if settings["thermostat"] == "nose-hoover":
        return [f"fix thermostat {group} nvt temp {t:g} {t:g} {damp:g}"]
    return [f"fix thermostat {group} langevin {t:g} {t:g} {damp:g} {_seed(settings['seed'], 17, salt, step)} "
            f"zero yes", f"fix integrate {group} nve"]


def _common_define(settings: Mapping[str, Any], mobile: str) -> list[str]:
    return ["fix zwalls all wall/reflect zlo EDGE zhi EDGE",
            f"compute tmob {mobile} temp",
            "variable pe equal pe", "variable temp equal c_tmob",
            "thermo_style custom step temp c_tmob pe ke press",
            f"thermo {max(settings['sample_interval'], settings['chunk_steps'] // 4)}",
            "thermo_modify norm no flush yes lost error"]


#: timestep (fs) FIRE runs at, whatever the MD timestep: FIRE grows its step to tmax (LAMMPS default 10) times the
#: timestep, and nothing is constrained while it runs (SHAKE comes afterwards; FIRE breaks SHAKE's restraints, see
#: :func:`_minimize_water`), so the silanol O-H bond (IFF 495 kcal/mol/A^2, H: period 9.5 fs) vibrates freely.
#: At 1 fs (steps up to 10 fs, the timestep of every flexible-O-H recipe) the minimisations are stable; at the 2 fs
#: of a SHAKE recipe (steps up to 20 fs, two O-H periods) the O-H integration diverges wherever FIRE's global power
#: test does not see it -- the quick contact_angle_silica substrate (4320 atoms) lost a silanol H at FIRE step 46.
FIRE_TIMESTEP_FS = 1.0


def _minimize(settings: Mapping[str, Any], write: Path | None = None, style: str = "fire") -> list[str]:
    """FIRE (or ``style``) minimisation of ``minimize_steps`` iterations; FIRE at :data:`FIRE_TIMESTEP_FS` when the
    MD timestep is longer, the MD timestep restored afterwards."""
    n = int(settings["minimize_steps"])
    cmds = []
    if n > 0:
        dt = float(settings["timestep_fs"])
        slow = style == "fire" and dt > FIRE_TIMESTEP_FS
        cmds += ([f"timestep {FIRE_TIMESTEP_FS:g}"] if slow else []) + \
            [f"min_style {style}", f"minimize 0.0 1.0e-3 {n} {10 * n}"] + ([f"timestep {dt:g}"] if slow else [])
    if write is not None:
        cmds.append(f"write_data {write.as_posix()}")
    return cmds + ["reset_timestep 0"]


def _minimize_water(settings: Mapping[str, Any], write: Path | None = None) -> list[str]:
    """Minimisation of a system with rigid water: conjugate gradients (FIRE moves SHAKE clusters apart: LAMMPS
    turns SHAKE into restraints while minimising, and FIRE's steps break them; cg does not)."""
    return _minimize(settings, write, style="cg")


#: silanol O-H bond (IFF OC24-HOY, 0.945 A): constrained where silanols are mobile at a 2 fs timestep
SILANOL_OH = (("OC24", "HOY"),)


def _shake(ff: ForceField, also: tuple[tuple[str, str], ...] = ()) -> list[str]:
    """``fix shake`` on every bond/angle type the force field marks rigid (SPC/E), and on the bond types
    between the atom-type pairs in ``also`` (e.g. :data:`SILANOL_OH`); [] if none."""
    pairs = {tuple(sorted(p)) for p in also}
    b = [k for k, t in enumerate(ff.bond_types, start=1)
         if t.constraint == "shake" or tuple(sorted(t.types)) in pairs]
    a = [k for k, t in enumerate(ff.angle_types, start=1) if t.constraint == "shake"]
    if not b and not a:
        return []
    args = (" b " + " ".join(map(str, b)) if b else "") + (" a " + " ".join(map(str, a)) if a else "")
    return [f"fix rigidwater all shake 1.0e-5 50 0{args} kbond 2.0e5"]


def _round_up(n: float, k: int) -> int:
    return int(max(k, k * math.ceil(float(n) / k - 1e-9)))


def _steps(settings: Mapping[str, Any], key: str) -> int:
    n = int(settings[key])
    return 0 if n == 0 else _round_up(n, settings["sample_interval"])


def _equil(settings: Mapping[str, Any], group: str, salt: int = 0, extra: tuple[str, ...] = ()) -> Stage:
    t = settings["temperature_K"]
    return Stage("equilibrate", _steps(settings, "equilibrate_steps"),
                 (f"velocity {group} create {t:g} {_seed(settings['seed'], 3, salt)} mom yes rot no dist gaussian",)
                 + extra, sampled=False)


def _stages(*stages: Stage) -> list[Stage]:
    return [s for s in stages if s.steps > 0]


def _read_data_positions(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(ids, positions (N, 3) in A) from the Atoms section of a LAMMPS data file (``atom_style full``)."""
    lines = Path(path).read_text().splitlines()
    start = next(i for i, l in enumerate(lines) if l.strip().startswith("Atoms"))
    rows = []
    for l in lines[start + 2:]:
        s = l.split("#")[0].split()
        if not s:
            if rows:
                break
            continue
        rows.append((int(s[0]), float(s[4]), float(s[5]), float(s[6])))
    arr = np.array(rows)
    order = np.argsort(arr[:, 0])
    return arr[order, 0].astype(int), arr[order, 1:]


def _ff(names: list[str]) -> ForceField:
    return load_forcefield(names[0]) if len(names) == 1 else combine(*names)


def _intersect(system: System, a: str, b: str) -> np.ndarray:
    return np.intersect1d(system.group(a), system.group(b))


def _q(value: float, stderr: float | None, units: str, **extra) -> dict[str, Any]:
    d = {"value": float(value), "stderr": None if stderr is None or not np.isfinite(stderr) else float(stderr),
         "units": units}
    d.update(extra)
    return d


def _figure(draw: Callable) -> Callable[[Path], None]:
    def save(path: Path) -> None:
        from matplotlib.figure import Figure    # object API: no pyplot state, no backend switch
        fig = Figure(figsize=(6.0, 4.2), dpi=110)
        ax = fig.subplots()
        draw(ax)
        fig.tight_layout()
        fig.savefig(path)
    return save


def _silica_face(settings: Mapping[str, Any]) -> str:
    """The cristobalite face of a recipe's silica: the recipe's ``silica_face`` (default
    :data:`md.builders.SILICA_FACE` = '111', isolated Q3 silanols) for bare silica; always (111) when an OTS SAM
    is involved (it is grafted on (111), and the two slabs of a pair must share the lateral cell)."""
    kinds = settings.get("surfaces") or [settings.get("surface")]
    if "ots" in kinds:
        return "111"
    return settings.get("silica_face", SILICA_FACE)


def _held_deep(system: System, group: str = "frozen") -> np.ndarray:
    """Atoms of ``group`` (the builder's deep layer) that are Si or bridging O: only these are held; silanol O
    and H stay mobile everywhere."""
    idx = np.asarray(system.group(group), int)
    return idx[np.isin(system.types[idx], ["SC4", "OC23"])]


def _surface_slab(kind: str, nx: int, ny: int, thickness: float, settings: Mapping[str, Any], seed: int,
                  face: str) -> System:
    if kind == "silica":
        dens = settings["silanol_density"] if face == "001" else 4.5
        return silica_slab(nx, ny, thickness=thickness, silanol_density=dens, face=face, seed=seed)
    slab = silica_slab(nx, ny, thickness=thickness, face="111", silanol_density=4.5, seed=seed)
    return ots_sam(slab, coverage=settings["sam_coverage"], chain_length=settings["chain_length"], seed=seed + 1)


# ================================================================================================ base class

class Workflow:
    """``version`` counts changes of a workflow's simulation protocol; above 1 it enters the run hash."""
    name = ""
    version = 1

    def forcefield_files(self, settings: Mapping[str, Any]) -> list[str]:
        raise NotImplementedError

    def plan(self, settings: Mapping[str, Any], run_dir: Path) -> Plan:
        raise NotImplementedError

    def analyse(self, ctx: RunContext) -> Analysis:
        raise NotImplementedError


# ================================================================================================ adhesion

#: the upper slab's back as one rigid body, free along z only (fix aveforce would give equal forces, not equal
#: accelerations, to atoms of different mass and tear the group apart)
_BACK_RIGID = "fix back_rigid upper_back rigid single force * off off on torque * off off off"

class Adhesion(Workflow):
    """Work of adhesion of two slabs: energy route, and optionally the free energy by force integration.

    Version 2: the force-integration windows start from the contact leg's last (equilibrated, 300 K) state, and
    the separation is measured from the contact leg's mean back height. Version 1 started them from the minimised
    build, whose back had been held at the initial 3 A gap: 2.8 A wider than the 300 K contact, so the windows
    missed the adhesive well (W_F 0.006 against dE/A 0.123 J/m^2 for silica)."""
    name = "adhesion"
    version = 2

    def forcefield_files(self, s):
        return ["silica_interface"] + (["ots_trappe_ua"] if "ots" in s["surfaces"] else [])

    def windows(self, s) -> np.ndarray:
        n = int(s["pmf_windows"])
        return s["separation_A"] * (np.arange(n) / (n - 1)) ** 2

    def plan(self, s, run_dir):
        ff = _ff(self.forcefield_files(s))
        lower_kind, upper_kind = s["surfaces"]
        face = _silica_face(s)
        seed = int(s["seed"])
        lower = _surface_slab(lower_kind, s["nx"], s["ny"], s["slab_thickness_A"], s, seed, face)
        upper = _surface_slab(upper_kind, s["nx"], s["ny"], s["slab_thickness_A"], s, seed + 10, face)
        system = place_on(lower, flip_upside_down(upper), gap=s["contact_gap_A"], vacuum=s["separation_A"] + 15.0)
        data = run_dir / "system.data"
        write_data(system, ff, data)
        groups = {"lower": system.group("substrate"), "upper": system.group("adsorbate"),
                  "lower_fixed": _intersect(system, "frozen", "substrate"),
                  "upper_back": _intersect(system, "frozen", "adsorbate")}
        n = system.n_atoms
        area = float(system.cell[0] * system.cell[1])
        contact_dir = run_dir / "legs" / "contact"
        minimized = contact_dir / "minimized.data"
        setup_groups = lambda: ["group held union lower_fixed upper_back", "group mobile subtract all held"]
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_back": "v_zback"}

        def define(upper_free: bool, salt: int):
            def d(step: int) -> list[str]:
                cmds = _common_define(s, "mobile") + [
                    "neigh_modify exclude group lower_fixed lower_fixed",
                    "neigh_modify exclude group upper_back upper_back",
                    "fix hold_lower lower_fixed setforce 0.0 0.0 0.0",
                    "compute gg upper group/group lower kspace yes",
                    "variable zback equal xcm(upper_back,z)"]
                if upper_free:      # one rigid body moving along z only, zero load: the contact finds its gap
                    cmds += [_BACK_RIGID]
                else:
                    cmds += ["fix hold_upper upper_back setforce 0.0 0.0 0.0"]
                return cmds + _thermostat("mobile", s, step, salt)
            return d

        def fresh_contact(leg_dir: Path) -> list[str]:
            return _fresh_from_data(ff, data, s, groups) + setup_groups()

        def fresh_from_minimized(shift: float):
            def f(leg_dir: Path) -> list[str]:
                return _fresh_from_data(ff, minimized, s, groups) + setup_groups() + \
                    ([f"displace_atoms upper move 0.0 0.0 {shift:.6f} units box"] if shift else [])
            return f

        base = dict(define=None, restart_head=_restart_head(s), columns=columns,
                    sample_interval=s["sample_interval"], chunk_steps=s["chunk_steps"], n_atoms=n)
        sample = Stage("sample", _steps(s, "sample_steps"))
        contact = Leg(name="contact", fresh=fresh_contact,
                      prepare=lambda d: ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"]
                      + _minimize(s, d / "minimized.data") + ["unfix back_min", _BACK_RIGID],
                      stages=_stages(_equil(s, "mobile", 1), sample), **{**base, "define": define(True, 1)})

        def fresh_from_contact_end(shift: float, _total=contact.total_steps):
            # the contact leg's last restart: the interface as it is at temperature and zero load
            def f(leg_dir: Path) -> list[str]:
                return _restart_head(s)(contact_dir / f"restart.{_total}") + [f"timestep {s['timestep_fs']:g}"] + \
                    ([f"displace_atoms upper move 0.0 0.0 {shift:.6f} units box"] if shift else [])
            return f

        legs = [
            contact,
            Leg(name="separated", fresh=fresh_from_minimized(s["separation_A"]), prepare=lambda d: ["reset_timestep 0"],
                stages=_stages(_equil(s, "mobile", 2), sample), **{**base, "define": define(False, 2)}),
        ]
        if s["free_energy"] == "pmf":
            pmf_equil = Stage("equilibrate", _steps(s, "pmf_equilibrate_steps"), (
                f"velocity mobile create {s['temperature_K']:g} {_seed(seed, 5)} mom yes rot no dist gaussian",),
                sampled=False)
            pmf_sample = Stage("sample", _steps(s, "pmf_sample_steps"))
            for k, d in enumerate(self.windows(s)):
                legs.append(Leg(name=f"pmf_{k:02d}", fresh=fresh_from_contact_end(float(d)),
                                prepare=lambda _d: ["reset_timestep 0"], stages=_stages(pmf_equil, pmf_sample),
                                info={"shift_A": float(d)}, **{**base, "define": define(False, 10 + k)}))
        info = {"area_A2": area, "box_A": system.cell.tolist(), "surfaces": list(s["surfaces"]), "face": face,
                "n_lower": int(len(groups["lower"])), "n_upper": int(len(groups["upper"])),
                "lower": _summary(lower), "upper": _summary(upper)}
        return Plan(legs=legs, timestep_fs=s["timestep_fs"], n_atoms=n,
                    seeds={"structure_lower": seed, "structure_upper": seed + 10, "velocities": _seed(seed, 3, 1),
                           "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        s = ctx.settings
        area = ctx.plan.system_info["area_A2"]
        nb = s["n_blocks"]
        con, sep = ctx.samples("contact"), ctx.samples("separated")
        w = A.energy_separation_work(con["pe"], sep["pe"], area, n_blocks=nb)
        q = {"work_of_adhesion": _q(w["value"], w["stderr"], "J/m^2",
                                    kind="energy per area (not a free energy)"),
             "interface_area": _q(U.angstrom_to_m(U.angstrom_to_m(area)), 0.0, "m^2")}
        notes = [ENERGY_NOT_FREE_ENERGY]
        details: dict[str, Any] = {"energy": {k: v for k, v in w.items() if k not in ("value", "stderr", "units")}}
        zc, zc_err = A.block_average(con["z_back"], nb)
        details["contact_back_z_A"] = {"mean": zc, "stderr": zc_err}
        curves: dict[str, tuple[list[str], np.ndarray]] = {}
        figures = {}
        dt = ctx.plan.timestep_fs
        all_con, all_sep = ctx.samples("contact", False), ctx.samples("separated", False)
        for name, d in (("energy_contact", all_con), ("energy_separated", all_sep)):
            curves[name] = (["step", "time_s", "stage", "potential_energy_J", "temperature_K"],
                            np.column_stack([d["step"], U.fs_to_s(d["step"] * dt), d["stage"],
                                             U.kcal_per_mol_to_J(d["pe"]), d["temp"]]))

        def draw_energy(ax):
            for d, lab in ((all_con, "contact"), (all_sep, "separated")):
                ax.plot(d["step"] * dt * 1e-3, d["pe"], lw=0.8, label=lab)
            ax.set_xlabel("time (ps)")
            ax.set_ylabel("potential energy (kcal/mol)")
            ax.set_title(f"W = {w['value']:.3f} ± {w['stderr']:.3f} J/m² (energy)")
            ax.legend()
        figures["energy_timeseries"] = _figure(draw_energy)
        if s["free_energy"] == "pmf":
            legs = [l for l in ctx.plan.legs if l.name.startswith("pmf_")]
            # separation from contact, measured: the window's (held) back height minus the contact leg's mean
            # back height at zero load; the windows start from the contact leg's last state, whose back height
            # is one sample of that fluctuating value, so the first window sits near (not at) zero
            d_A, f_mean, f_err = [], [], []
            for l in legs:
                win = ctx.samples(l)                   # one read of the window's samples
                m, e = A.block_average(win["fz"], min(nb, max(2, len(win["fz"]) // 2)))
                d_A.append(float(np.mean(win["z_back"])) - zc)
                f_mean.append(m)
                f_err.append(e)
            d_A, f_mean, f_err = np.array(d_A), np.array(f_mean), np.array(f_err)
            order = np.argsort(d_A)
            d_A, f_mean, f_err = d_A[order], f_mean[order], f_err[order]
            details["pmf_windows"] = {"separation_A": d_A.tolist(), "mean_force_kcal_mol_A": f_mean.tolist(),
                                      "stderr_kcal_mol_A": f_err.tolist(),
                                      "shift_from_contact_end_A": [legs[i].info["shift_A"] for i in order]}
            ti = A.force_integration_work(d_A, f_mean, f_err, area)
            wf, wf_err, wf_disc = ti["value"], ti["stderr"], ti["discretisation_error"]
            tds = w["value"] - wf
            q["work_of_adhesion_free_energy"] = _q(wf, wf_err, "J/m^2", kind="free energy per area (force "
                                                   "integration over separation, trapezoid rule)",
                                                   discretisation_error=wf_disc, value_pchip=ti["value_pchip"])
            q["entropic_term_TdS"] = _q(tds, math.hypot(w["stderr"], wf_err), "J/m^2",
                                        kind="T dS / A = (dE - dF) / A", discretisation_error=wf_disc)
            curves["pmf"] = (["separation_m", "mean_force_N", "mean_force_stderr_N", "work_J_per_m2"],
                             np.column_stack([U.angstrom_to_m(d_A), U.kcal_per_mol_A_to_N(f_mean),
                                              U.kcal_per_mol_A_to_N(f_err), ti["cumulative_J_per_m2"]]))
            notes.append(f"free energy of separation from {len(legs)} fixed-separation windows (0 to "
                         f"{s['separation_A']:g} A, quadratic spacing): dF/A = {wf:.4f} ± {wf_err:.4f} J/m^2 (trapezoid; "
                         f"PCHIP gives {ti['value_pchip']:.4f}, so the grid's discretisation error is about "
                         f"{wf_disc:.4f} J/m^2); "
                         f"T dS/A = dE/A - dF/A = {tds:.4f} J/m^2. The windows start from the contact leg's last state "
                         f"(back held, upper slab shifted rigidly); separations are measured from the contact leg's "
                         f"mean back height ({zc:.2f} A); the first window is at {d_A[0]:+.2f} A. The stderr is "
                         f"statistical only; the discretisation error is given beside it.")

            def draw_pmf(ax):
                ax.errorbar(d_A, f_mean, yerr=f_err, marker="o", ms=3, lw=1)
                ax.axhline(0, color="k", lw=0.5)
                ax.set_xlabel("separation from contact (Å)")
                ax.set_ylabel("mean force on upper slab (kcal/mol/Å)")
                ax.set_title(f"dF/A = {wf:.3f} ± {wf_err:.3f} (stat.) ± {wf_disc:.3f} (grid) J/m²")
            figures["pmf"] = _figure(draw_pmf)
        else:
            notes.append("free energy not estimated at this fidelity (free_energy = 'none'); the quick and "
                         "production recipes integrate the mean force over separation to measure T dS.")
        return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)


def _summary(system: System) -> dict[str, Any]:
    keep = ("builder", "polymorph", "face", "n_atoms", "silanol_density_top", "silanol_density_bottom", "chains",
            "coverage_nm2", "thickness_A", "radius_requested_A", "silanol_density_dome", "total_charge")
    return {k: system.info[k] for k in keep if k in system.info}


# ================================================================================================ pull-off

class PullOff(Workflow):
    """Asperity approach-hold-retract against a flat at constant holder speed."""
    name = "pulloff"

    def forcefield_files(self, s):
        return ["silica_interface"] + (["ots_trappe_ua"] if s["surface"] == "ots" else [])

    def build(self, s) -> tuple[System, dict[str, Any]]:
        seed = int(s["seed"])
        R = float(s["asperity_radius_A"])
        face = _silica_face(s)
        dens = s["silanol_density"] if face == "001" else 4.5
        asp = silica_asperity(radius=R, holder_thickness=s["holder_thickness_A"], margin=s["asperity_margin_A"],
                              silanol_density=dens, face=face, seed=seed)
        nx, ny = asp.info["surface_cells"]
        fnx, fny = (s["flat_nx"] or nx), (s["flat_ny"] or ny)
        if (fnx, fny) != (nx, ny):
            raise ValueError(f"flat_nx/flat_ny ({fnx}, {fny}) must match the asperity's holder cells ({nx}, {ny}) "
                             f"(both are periodic in x and y); set them to 0")
        flat = _surface_slab(s["surface"], nx, ny, s["flat_thickness_A"], s, seed + 20, face)
        info: dict[str, Any] = {"radius_A": R, "face": face}
        if s["surface"] == "ots":
            asp, ginfo = _graft_dome(asp, s, seed + 30)
            info["asperity_sam"] = ginfo
        system = place_on(flat, flip_upside_down(asp), gap=s["initial_gap_A"],
                          vacuum=s["retract_distance_A"] + 15.0)
        info.update(asperity=_summary(asp), flat=_summary(flat), box_A=system.cell.tolist())
        return system, info

    def plan(self, s, run_dir):
        ff = _ff(self.forcefield_files(s))
        system, info = self.build(s)
        data = run_dir / "system.data"
        write_data(system, ff, data)
        groups = {"flat": system.group("substrate"), "tip": system.group("adsorbate"),
                  "flat_fixed": _intersect(system, "frozen", "substrate"),
                  "holder_rigid": _intersect(system, "frozen", "adsorbate")}
        n = system.n_atoms
        dt = s["timestep_fs"]
        si = s["sample_interval"]
        v_app = U.m_per_s_to_angstrom_per_fs(s["approach_speed_m_s"])
        n_app = _round_up(s["approach_distance_A"] / (v_app * dt), si)
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_holder": "v_zh", "tip_zmin": "v_tipmin",
                   "flat_zmax": "v_flatmax"}

        def define(step: int) -> list[str]:
            return _common_define(s, "mobile") + [
                "neigh_modify exclude group flat_fixed flat_fixed",
                "neigh_modify exclude group holder_rigid holder_rigid",
                "fix hold_flat flat_fixed setforce 0.0 0.0 0.0",
                "fix hold_holder holder_rigid setforce 0.0 0.0 0.0",
                "fix move_holder holder_rigid nve",
                "compute gg tip group/group flat kspace yes",
                "variable zh equal xcm(holder_rigid,z)", "variable tipmin equal bound(tip,zmin)",
                "variable flatmax equal bound(flat,zmax)"] + _thermostat("mobile", s, step)

        def fresh(leg_dir: Path) -> list[str]:
            return _fresh_from_data(ff, data, s, groups) + [
                "group held union flat_fixed holder_rigid", "group mobile subtract all held"]

        vz = lambda v: f"velocity holder_rigid set 0.0 0.0 {v:.10g} units box"
        approach = Leg(
            name="approach", fresh=fresh, define=define, prepare=lambda d: _minimize(s, d / "minimized.data"),
            restart_head=_restart_head(s),
            stages=_stages(_equil(s, "mobile", 1, (vz(0.0),)), Stage("approach", n_app, (vz(-v_app),)),
                           Stage("hold", _steps(s, "hold_steps"), (vz(0.0),))),
            columns=columns, sample_interval=si, chunk_steps=s["chunk_steps"], n_atoms=n,
            info={"v_approach_A_fs": v_app})
        legs = [approach]
        approach_dir = run_dir / "legs" / "approach"
        for k, v in enumerate(s["retract_speeds_m_s"]):
            v_ret = U.m_per_s_to_angstrom_per_fs(v)
            n_ret = _round_up(s["retract_distance_A"] / (v_ret * dt), si)

            def fresh_retract(leg_dir: Path, _total=approach.total_steps) -> list[str]:
                return _restart_head(s)(approach_dir / f"restart.{_total}") + [f"timestep {dt:g}"]
            legs.append(Leg(name=f"retract_{k}", fresh=fresh_retract, define=define,
                            prepare=lambda d: ["reset_timestep 0"], restart_head=_restart_head(s),
                            stages=[Stage("retract", n_ret, (vz(v_ret),))], columns=columns, sample_interval=si,
                            chunk_steps=s["chunk_steps"], n_atoms=n, info={"speed_m_s": v, "v_A_fs": v_ret}))
        info.update(n_flat=int(len(groups["flat"])), n_tip=int(len(groups["tip"])))
        seed = int(s["seed"])
        return Plan(legs=legs, timestep_fs=dt, n_atoms=n,
                    seeds={"structure_asperity": seed, "structure_flat": seed + 20, "velocities": _seed(seed, 3, 1),
                           "thermostat_base": seed, **({"sam_asperity": seed + 30} if s["surface"] == "ots" else {})},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        s = ctx.settings
        R_m = U.angstrom_to_m(s["asperity_radius_A"])
        ids, pos = _read_data_positions(ctx.leg_dir("approach") / "minimized.data")
        n_flat = ctx.plan.system_info["n_flat"]
        # ids 1..n_flat are the flat (place_on puts the substrate first)
        flat_top = pos[:n_flat, 2].max()
        tip_bottom = pos[n_flat:, 2].min()
        s0 = tip_bottom - flat_top
        app = ctx.samples("approach", False)
        # the holder's height at the minimised start: it does not move before the approach stage, so the first
        # sample of the equilibration has it exactly
        zh0 = float(app["z_holder"][0])
        sep = lambda d: s0 + (d["z_holder"] - zh0)
        curves, figures, per_speed = {}, {}, []
        retracts = [l for l in ctx.plan.legs if l.name.startswith("retract_")]
        smooth = None
        for l in retracts:
            d = ctx.samples(l)
            n = len(d["step"])
            smooth = max(5, (n // 25) | 1) if n >= 15 else None
            r = A.pull_off_analysis(sep(d), d["fz"], smooth=smooth, radius_m=R_m)
            per_speed.append((l.info["speed_m_s"], r))
            curves[f"pulloff_curve_{l.name}"] = (
                ["separation_m", "force_N", "force_smoothed_N"],
                np.column_stack([r["curve"]["separation"], r["curve"]["force"], r["curve"]["force_smoothed"]]))
        d_app = ctx.samples("approach", False)
        curves["approach_curve"] = (["step", "stage", "separation_m", "force_N"],
                                    np.column_stack([d_app["step"], d_app["stage"], U.angstrom_to_m(sep(d_app)),
                                                     U.kcal_per_mol_A_to_N(d_app["fz"])]))
        speeds = np.array([v for v, _ in per_speed])
        forces = np.array([r["max_tensile_force"] for _, r in per_speed])
        slow = int(np.argmin(speeds))
        best = per_speed[slow][1]
        # the force noise sets the error of a single curve's maximum: std of the smoothed-minus-raw residual
        # near the maximum only: under compression the force (and its noise) is many times larger
        resid = best["curve"]["force"] - best["curve"]["force_smoothed"]
        f_err = None
        if smooth:
            i_max = int(np.argmin(np.abs(best["curve"]["separation"] - best["separation_at_max"])))
            lo, hi = max(0, i_max - 2 * smooth), min(len(resid), i_max + 2 * smooth + 1)
            f_err = float(np.std(resid[lo:hi]))
        q = {"pull_off_force": _q(best["max_tensile_force"], f_err, "N",
                                  speed_m_s=float(speeds[slow]), kind="maximum tensile force on retraction"),
             "separation_at_max_tension": _q(best["separation_at_max"], None, "m"),
             "interaction_range_z0": _z0_quantity(best),
             "work_of_adhesion_eff_jkr": _q(best["eff_work_jkr"], f_err / (1.5 * math.pi * R_m) if f_err else None,
                                            "J/m^2", kind="F / (1.5 pi R)"),
             "work_of_adhesion_eff_dmt": _q(best["eff_work_dmt"], f_err / (2 * math.pi * R_m) if f_err else None,
                                            "J/m^2", kind="F / (2 pi R)")}
        notes = [f"separation = gap between the lowest asperity atom and the highest flat atom at the minimised "
                 f"start ({s0:.2f} A) plus the rigid holder's travel (no correction for the asperity's or the "
                 f"flat's deformation); force = compute group/group (asperity body vs flat, kspace yes), "
                 f"positive = repulsive.",
                 "stderr of the pull-off force is the noise of one curve (std of the raw minus smoothed force within "
                 "two smoothing windows of the maximum), "
                 "not a spread over repeated pulls.",
                 f"R = {s['asperity_radius_A']:g} A (the requested radius of the carved, faceted dome)."]
        if s["surface"] == "ots":
            notes.append("OTS chains on the asperity are grafted on dome silanols within graft_max_polar_deg of "
                         "the apex and point along the pulling axis, not along the local normal (the builder "
                         "grafts along one axis); the chain-end surface is the dome translated by the chain "
                         "vector, so its curvature radius is still R.")
        details = {"per_speed": [{"speed_m_s": float(v), "max_tensile_force_N": r["max_tensile_force"],
                                  "separation_at_max_m": r["separation_at_max"], "z0_m": r["z0"],
                                  "z0_zero_to_min_m": r["z0_zero_to_min"],
                                  "zero_force_separation_m": r["zero_force_separation"],
                                  "traction_fit": {k: v for k, v in r["traction_fit"].items()
                                                   if isinstance(v, (int, float, str, dict))}}
                                 for v, r in per_speed],
                   "s0_A": float(s0), "holder_z0_A": zh0, "smoothing_window": smooth}
        if len(speeds) >= 2:
            ext = A.rate_extrapolation(speeds, forces, target_rate=float(speeds.min()) / 10.0,
                                       temperature_K=s["temperature_K"])
            q["pull_off_force_extrapolated"] = _q(ext["F0"], ext["stderr"], "N",
                                                  kind=f"F = a + b ln(v) fitted to {len(speeds)} speeds, "
                                                       f"evaluated at {ext['target_rate']:g} m/s")
            details["rate_extrapolation"] = ext
            notes.append("rate scan: F = a + b ln(v) (Bell-Evans) extrapolated one decade below the slowest "
                         "simulated speed; valid only while the Bell-Evans regime holds.")

        def draw(ax):
            for (v, r) in per_speed:
                c = r["curve"]
                ax.plot(c["separation"] * 1e9, c["force"] * 1e9, lw=0.5, alpha=0.5)
                ax.plot(c["separation"] * 1e9, c["force_smoothed"] * 1e9, lw=1.5, label=f"retract {v:g} m/s")
            ax.plot(U.angstrom_to_m(sep(d_app)) * 1e9, U.kcal_per_mol_A_to_N(d_app["fz"]) * 1e9, lw=0.5,
                    color="grey", label="approach/hold")
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlabel("separation (nm)")
            ax.set_ylabel("force on asperity (nN)")
            ax.set_title(f"pull-off {best['max_tensile_force'] * 1e9:.3f} nN, R = {s['asperity_radius_A']:g} Å")
            ax.legend(fontsize=7)
        figures["pulloff_curve"] = _figure(draw)
        return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)


def _z0_quantity(r: Mapping[str, Any]) -> dict[str, Any]:
    """z0 of the fitted LJ 9-3 traction law; if the fit fails, from the zero-to-minimum distance of the curve
    (for the 9-3 law that distance is (3^(1/6) - 1) z0)."""
    if r["z0"] is not None and np.isfinite(r["z0"]):
        return _q(r["z0"], None, "m", kind="z0 of the LJ 9-3 traction law fitted to the retraction curve")
    zm = r["z0_zero_to_min"]
    return _q(zm / (3 ** (1 / 6) - 1) if np.isfinite(zm) else float("nan"), None, "m",
              kind="z0 = (zero-to-minimum distance) / (3^(1/6) - 1) (the 9-3 law fit failed: "
                   f"{r['traction_fit'].get('error', '?')})")


def _graft_dome(asp: System, s: Mapping[str, Any], seed: int) -> tuple[System, dict[str, Any]]:
    """OTS chains on the dome silanols within ``graft_max_polar_deg`` of the apex (asperity tip up)."""
    R = float(s["asperity_radius_A"])
    centre = np.array(asp.info["centre_A"])
    dome = np.asarray(asp.group("silanol_O_dome"), int)
    p = asp.positions[dome] - centre
    cosang = p[:, 2] / np.maximum(np.linalg.norm(p, axis=1), 1e-9)
    sites = dome[cosang >= math.cos(math.radians(s["graft_max_polar_deg"]))]
    if not len(sites):
        raise ValueError("no dome silanols within graft_max_polar_deg of the apex: nothing to graft on")
    asp = with_groups(asp, graft_sites=sites)
    cap = math.pi * (R * math.sin(math.radians(s["graft_max_polar_deg"]))) ** 2      # projected area, A^2
    cell_area = float(asp.cell[0] * asp.cell[1])
    n_target = max(1, int(round(s["sam_coverage"] * cap / 100.0)))
    last = None
    for n in range(min(n_target, len(sites)), 0, -1):
        try:
            sam = ots_sam(asp, coverage=(n + 0.49) / (cell_area / 100.0), chain_length=s["chain_length"],
                          seed=seed, site_group="graft_sites")
            break
        except ValueError as exc:
            last = exc
    else:
        raise ValueError(f"no OTS chain fits on the dome: {last}")
    chains = int(sam.info["chains"])
    return sam, {"chains": chains, "requested_chains": n_target, "cap_projected_area_nm2": cap / 100.0,
                 "chains_per_projected_nm2": chains / (cap / 100.0), "sites": int(len(sites))}


# ================================================================================================ water

#: Water models a recipe may name: their force-field files and the model's own liquid-vapour surface tension at
#: 300 K (published), which turns every contact angle into W_SL = gamma_lv (1 + cos theta) and gamma_lv cos theta.
#: One model throughout a calibration: the angles and gamma_lv of the menisci must describe the same water.
WATER_MODELS: dict[str, dict[str, Any]] = {
    "spce": {"name": "SPC/E", "forcefields": ["water_spce"], "gamma_lv_N_m": 0.0636, "gamma_T_K": 300.0,
             "gamma_source": "SPC/E, 300 K, Ewald with LJ tail: Vega & de Miguel, J. Chem. Phys. 126 (2007) 154707 "
                             "(this project's quick films: 60.7 +/- 3.0 mN/m at 25 A, 64.0 +/- 1.9 mN/m at 35 A)"},
}


def _water_ff_names(model: str) -> list[str]:
    return list(WATER_MODELS[model]["forcefields"])


#: gap between the substrate's highest atom and the droplet's lowest one when the droplet is placed (A)
DROPLET_GAP_A = 3.0
#: water molecules closer than this to a substrate atom when the droplet is added are deleted (A)
DROPLET_OVERLAP_A = 2.0
#: the density map starts this far below the solid's reference atoms, so the water's dividing plane is found
#: from below even where water sits between the outer atoms (A)
MAP_FLOOR_A = 3.0


class ContactAngleWorkflow(Workflow):
    """Cylindrical droplet on silica or OTS; density map -> circle fit -> contact angle, W_SL and a drift check.

    Two legs. *substrate*: the substrate alone (the water's box) is minimised with nothing held (FIRE at
    :data:`FIRE_TIMESTEP_FS`, whatever the MD timestep), then only its deep Si and bridging O are held (silanol O
    and H mobile, O-H constrained by SHAKE) and it is equilibrated (the SAM relaxes before any water touches it).
    *droplet*: the water cap is added to the substrate's last state (``read_data ... add append``; molecules
    overlapping the substrate deleted), minimised, equilibrated and sampled. The angle is read at the water's own
    dividing plane (half the bulk density under the droplet).

    Version 3 (this protocol): the substrate's FIRE minimisation runs at 1 fs; version 2 ran it at the MD
    timestep, 2 fs on silica, where FIRE's steps (up to 20 fs) made the unconstrained silanol O-H diverge (the
    quick silica run lost an H at FIRE step 46: "Bond atoms missing"). Version 1 froze the whole silica (silanol H
    included) before minimising it, used the (001) face's silanol pairs, started a full cylinder on an
    unequilibrated SAM and read the angle at the plane of the solid's atoms (OTS: 140 deg there against 129 deg at
    the water's plane, same map)."""
    name = "contact_angle"
    version = 3

    def forcefield_files(self, s):
        return ["silica_interface"] + (["ots_trappe_ua"] if s["surface"] == "ots" else []) + \
            _water_ff_names(s["water_model"])

    def build(self, s) -> tuple[System, System, System]:
        """(substrate, droplet, both placed in one box) -- the substrate's coordinates are those of the combined
        system, so atom ids 1..n_substrate are the same in both legs."""
        seed = int(s["seed"])
        sub = _surface_slab(s["surface"], s["nx"], s["ny"], s["slab_thickness_A"], s, seed, _silica_face(s))
        R0 = float(s["droplet_radius_A"])
        wff = _ff(_water_ff_names(s["water_model"]))
        drop = water_cap(R0, float(sub.cell[1]), contact_angle_deg=s["droplet_initial_angle_deg"], seed=seed + 1,
                         forcefield=wff)
        system = place_on(sub, drop, gap=DROPLET_GAP_A, vacuum=max(20.0, R0))
        return sub, drop, system

    def plan(self, s, run_dir):
        ff = _ff(self.forcefield_files(s))
        seed = int(s["seed"])
        sub, drop, system = self.build(s)
        substrate = system.group("substrate")
        water = system.group("adsorbate")
        held = np.intersect1d(_held_deep(system), substrate)
        sub_data, water_data = run_dir / "substrate.data", run_dir / "water.data"
        write_data(system, ff, run_dir / "system.data", title="contact_angle system (reference; the legs read the "
                   "two parts)")
        write_data(remove_atoms(system, water), ff, sub_data, title="contact_angle substrate")
        write_data(remove_atoms(system, substrate), ff, water_data, title="contact_angle droplet")
        if s["surface"] == "silica":
            ref = _intersect(system, "silanol_O_top", "substrate")
        else:
            ref = system.group("sam_ch3")
        water_o = np.intersect1d(system.group("water_O"), water)
        n_sub, n = len(substrate), system.n_atoms
        dt = s["timestep_fs"]
        shake = _shake(ff, also=SILANOL_OH)
        sub_groups = {"substrate": substrate, "frozen": held}

        def fresh_substrate(leg_dir: Path) -> list[str]:
            # minimised with nothing held (no setforce, no exclusions): the deep layer is held only afterwards,
            # at its relaxed positions
            return _fresh_from_data(ff, sub_data, s, sub_groups) + ["group mobile subtract all frozen"] + \
                _minimize(s, leg_dir / "minimized.data")

        def define(salt: int, with_water: bool):
            def d(step: int) -> list[str]:
                return _common_define(s, "mobile") + ["neigh_modify exclude group frozen frozen"] + shake + \
                    ["fix hold frozen setforce 0.0 0.0 0.0"] + \
                    (["variable nw equal count(water)/3"] if with_water else []) + \
                    _thermostat("mobile", s, step, salt)
            return d

        t = s["temperature_K"]
        sub_leg = Leg(name="substrate", fresh=fresh_substrate, define=define(0, False), prepare=lambda d: [],
                      restart_head=_restart_head(s),
                      stages=[Stage("equilibrate", _steps(s, "substrate_equilibrate_steps"),
                                    (f"velocity mobile create {t:g} {_seed(seed, 3, 0)} mom yes rot no "
                                     f"dist gaussian",), sampled=False)],
                      columns={"pe": "v_pe", "temp": "v_temp"}, sample_interval=s["sample_interval"],
                      chunk_steps=s["chunk_steps"], n_atoms=n_sub)
        sub_dir = run_dir / "legs" / "substrate"

        def fresh_droplet(leg_dir: Path, _total=sub_leg.total_steps) -> list[str]:
            # the equilibrated substrate, then the water: ids n_sub+1.. as in the combined build
            return _restart_head(s)(sub_dir / f"restart.{_total}") + [
                f"timestep {dt:g}",
                f"read_data {water_data.as_posix()} add append group water",
                f"group framed id {id_ranges(np.union1d(water_o, ref))}",
                "group mobile subtract all frozen",
                f"delete_atoms overlap {DROPLET_OVERLAP_A:g} water substrate mol yes bond yes compress no"]

        drop_leg = Leg(name="droplet", fresh=fresh_droplet, define=define(1, True),
                       prepare=lambda d: _minimize_water(s), restart_head=_restart_head(s),
                       stages=_stages(_equil(s, "mobile", 1), Stage("sample", _steps(s, "sample_steps"))),
                       columns={"pe": "v_pe", "temp": "v_temp", "n_water": "v_nw"},
                       sample_interval=s["sample_interval"], chunk_steps=s["chunk_steps"], n_atoms=n,
                       frames=Frames("framed", s["frame_interval"] or s["sample_interval"]))
        ids = lammps_type_ids(ff)
        info = {"substrate": _summary(sub), "droplet": dict(drop.info), "box_A": system.cell.tolist(),
                "n_substrate": int(n_sub), "n_water_molecules_built": int(len(water_o)),
                "held_atoms": int(len(held)), "held": "deep Si and bridging O of the builder's bottom layer",
                "silica_face": _silica_face(s),
                "water_O_ids": (water_o + 1).tolist(), "surface_ref_ids": (ref + 1).tolist(),
                "surface_ref": "top silanol O" if s["surface"] == "silica" else "OTS CH3 groups",
                "water_model": s["water_model"], "type_ids": ids}
        return Plan(legs=[sub_leg, drop_leg], timestep_fs=dt, n_atoms=n,
                    seeds={"structure_substrate": seed, "structure_water": seed + 1,
                           "velocities_substrate": _seed(seed, 3, 0), "velocities": _seed(seed, 3, 1),
                           "thermostat_base": seed}, forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        import MDAnalysis as mda
        from MDAnalysis.coordinates.memory import MemoryReader

        s = ctx.settings
        info = ctx.plan.system_info
        steps, ids, pos, box = ctx.frames("droplet")
        if not len(steps):
            raise RuntimeError("no stored configurations: sample_steps shorter than frame_interval?")
        is_o = np.isin(ids, info["water_O_ids"])
        is_ref = np.isin(ids, info["surface_ref_ids"])
        solid_z = float(pos[:, is_ref, 2].mean())
        floor = solid_z - MAP_FLOOR_A
        opos = pos[:, is_o, :].astype(np.float32)
        u = mda.Universe.empty(int(is_o.sum()), trajectory=False)
        u.add_TopologyAttr("type", ["OW"] * int(is_o.sum()))
        dims = np.column_stack([box, np.full((len(box), 3), 90.0)]).astype(np.float32)
        u.load_new(opos, format=MemoryReader, dimensions=dims)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ca = A.ContactAngle(u.select_atoms("type OW"), surface_z=floor, axis="y", bin_size=s["bin_A"],
                                n_blocks=min(s["n_blocks"], len(steps)), reference="dividing_surface")
            ca.run()
        r = ca.results
        xc, zc, rad = r.circle
        z_ref = float(r.reference_z)
        wet = r.wetting
        model = WATER_MODELS[s["water_model"]]
        gamma = model["gamma_lv_N_m"]
        notes: list[str] = []
        if abs(s["temperature_K"] - model["gamma_T_K"]) > 1.0:
            notes.append(f"gamma_lv = {gamma * 1e3:.1f} mN/m is the model's value at {model['gamma_T_K']:g} K, not at "
                         f"the run's {s['temperature_K']:g} K: W_SL and gamma_lv cos theta carry that mismatch.")
        # what the map shows: a measured angle, no contact yet, or a film / a cap too flat to fit ("wets")
        if np.isfinite(r.angle_deg) and not wet["spans_box"]:
            status, angle, angle_err = "measured", float(r.angle_deg), r.stderr_deg
        elif np.isfinite(rad) and rad > 0 and (zc - z_ref) / rad > 1 and not wet["spans_box"]:
            status, angle, angle_err = "no_contact", 180.0, None
            notes.append(f"the fitted circle (centre {zc - z_ref:+.1f} A from the water's plane, r = {rad:.1f} A) "
                         f"lies above the plane: the droplet is not (yet) in contact; reported as 180 deg.")
        else:
            status, angle, angle_err = "wets", 0.0, None
        q = {"contact_angle": _q(angle, angle_err, "deg",
                                 kind={"measured": "circle fit, read at the water's dividing plane",
                                       "no_contact": "180 = no contact (mark, not a measurement)",
                                       "wets": "0 = wets (mark, not a measurement): see contact_angle_upper_bound"}
                                 [status], status=status),
             "droplet_bulk_density": _q(U.g_per_cm3_to_kg_per_m3(r.bulk_density), None, "kg/m^3"),
             "base_half_width": _q(U.angstrom_to_m(r.base_half_width_A), None, "m")}
        q["surface_tension_lv"] = _q(gamma, None, "N/m", kind=f"the water model's published gamma_lv "
                                     f"({model['gamma_source']})")
        if status == "wets":
            bound, why = (wet["theta_max_deg"], "the water spans the periodic box (a film); a cap of this volume "
                          f"touches its image at {wet['theta_max_deg']:.1f} deg") if wet["spans_box"] else \
                (wet["theta_resolvable_deg"], f"no circle can be fitted above the excluded layer "
                 f"({r.fit_error}); a cap of this volume is that flat below {wet['theta_resolvable_deg']:.1f} deg")
            q["contact_angle_upper_bound"] = _q(bound, None, "deg", kind="wets: theta below this bound")
            wl = A.work_of_adhesion_sl(gamma, bound)
            q["work_of_adhesion_sl"] = _q(wl["value"], None, "J/m^2", kind="lower bound (wets): "
                                          "gamma_lv (1 + cos theta_upper_bound)")
            q["gamma_lv_cos_theta"] = _q(wl["gamma_cos_theta"], None, "N/m", kind="lower bound (wets)")
            notes.append(f"wets: theta < {bound:.1f} deg ({why}); W_SL >= {wl['value'] * 1e3:.1f} mJ/m^2. "
                         f"A droplet cannot resolve complete wetting; the dry-surface thermodynamic integration "
                         f"(Leroy & Mueller-Plathe, Langmuir 31 (2015) 8335) would measure W_SL directly.")
        elif status == "measured":
            wl = A.work_of_adhesion_sl(gamma, angle, None, angle_err)
            q["work_of_adhesion_sl"] = _q(wl["value"], wl["stderr"], "J/m^2",
                                          kind="Young-Dupre W_SL = gamma_lv (1 + cos theta), this water model's gamma")
            q["gamma_lv_cos_theta"] = _q(wl["gamma_cos_theta"], wl["gamma_cos_theta_stderr"], "N/m",
                                         kind="gamma_lv cos theta (meniscus force), this water model's gamma")
        # drift of the block angles against time
        dt_ns = ctx.plan.timestep_fs * 1e-6
        t_blocks = np.interp(r.block_frames, np.arange(len(steps)), steps.astype(float)) * dt_ns
        drift = A.block_drift(r.block_angles_deg, t_blocks)
        if status == "measured":
            q["contact_angle_drift"] = _q(drift["slope"], drift["stderr"], "deg/ns",
                                          kind="slope of the block angles against time (OLS)",
                                          drifting=bool(drift["drifting"]))
            if drift["drifting"]:
                notes.append(f"DRIFTING: the block angles still change by {drift['slope']:+.0f} +/- "
                             f"{drift['stderr']:.0f} deg/ns ({drift['change']:+.1f} deg over the sampled "
                             f"{np.ptp(t_blocks) * 1e3:.0f} ps, |slope| > 2 stderr): not equilibrated; the mean "
                             f"depends on where the run stopped.")
            h = float(r.cap_height_A)
            if h < 3 * 5.0:
                notes.append(f"the cap is {h:.1f} A high, less than 3x the 5 A excluded layer: few interface "
                             f"points carry the fit.")
        notes += [f"angle read at the water's dividing plane z = {z_ref:.2f} A (half the bulk density under the "
                  f"droplet), {z_ref - solid_z:+.2f} A from the mean height of the {info['surface_ref']} "
                  f"({solid_z:.2f} A); circle fitted to the half-bulk contour above that plane + 5 A "
                  f"(md.analysis.ContactAngle, {r.n_frames} frames).",
                  "substrate minimised with nothing held, then its deep Si and bridging O held; silanol O and H "
                  "mobile (O-H by SHAKE)" + ("; the OTS SAM equilibrated alone before the droplet was placed"
                                              if s["surface"] == "ots" else "") +
                  f"; water rigid {model['name']} (SHAKE); the droplet started as a "
                  f"{s['droplet_initial_angle_deg']:g} deg cylindrical cap.",
                  "a cylindrical droplet has a straight contact line: no line-tension correction.",
                  f"W_SL and gamma_lv cos theta use gamma_lv = {gamma * 1e3:.1f} mN/m of the same water model "
                  f"({s['water_model']}); combine the angle only with a gamma_lv of that model."]
        ue, ze = r.edges
        rho = r.density_map
        curves = {"density_map": (["u_m", "z_m", "density_kg_m3"],
                                  np.column_stack([np.repeat(U.angstrom_to_m(0.5 * (ue[1:] + ue[:-1])), len(ze) - 1),
                                                   np.tile(U.angstrom_to_m(0.5 * (ze[1:] + ze[:-1])), len(ue) - 1),
                                                   U.g_per_cm3_to_kg_per_m3(rho.ravel())])),
                  "interface_points": (["u_m", "z_m"], U.angstrom_to_m(np.asarray(r.interface_points).reshape(-1, 2)))}
        d_app = ctx.samples("droplet", False)
        n_water = int(round(d_app["n_water"][-1])) if len(d_app.get("n_water", [])) else None

        def draw(ax):
            ax.pcolormesh(ue, ze, rho.T, cmap="Blues", shading="flat")
            if np.isfinite(rad):
                tt = np.linspace(0, 2 * np.pi, 400)
                cx, cz = xc + rad * np.cos(tt), zc + rad * np.sin(tt)
                keep = cz >= z_ref
                ax.plot(cx[keep], cz[keep], "r-", lw=1.2, label="fitted circle")
            pts = np.asarray(r.interface_points).reshape(-1, 2)
            ax.plot(pts[:, 0], pts[:, 1], "k.", ms=2, label="interface points")
            ax.axhline(z_ref, color="k", lw=0.8, label="water's dividing plane")
            ax.axhline(solid_z, color="grey", lw=0.8, ls="--", label=info["surface_ref"])
            ax.set_aspect("equal")
            ax.set_xlabel("x (Å, droplet-centred)")
            ax.set_ylabel("z (Å)")
            title = {"measured": f"θ = {angle:.1f} ± {(angle_err or float('nan')):.1f}°",
                     "no_contact": "no contact", "wets": "wets"}[status]
            ax.set_title(f"{title} ({s['surface']})")
            ax.legend(fontsize=7)
        block_w = [A.work_of_adhesion_sl(gamma, a)["value"] if np.isfinite(a) else None for a in r.block_angles_deg]
        details = {"status": status, "reference_z_A": z_ref, "surface_z_A": solid_z,
                   "reference_above_solid_A": z_ref - solid_z, "circle_A": [float(xc), float(zc), float(rad)],
                   "block_angles_deg": np.asarray(r.block_angles_deg).tolist(),
                   "block_times_ns": t_blocks.tolist(), "block_work_of_adhesion_sl_J_m2": block_w,
                   "drift": drift, "wetting": wet, "fit_error": r.fit_error, "cap_height_A": r.cap_height_A,
                   "fit_rms_A": r.fit_rms_A, "n_frames": int(r.n_frames), "n_water_molecules": n_water,
                   "water_model": s["water_model"], "gamma_lv_N_m": gamma}
        return Analysis(quantities=q, curves=curves, figures={"density_map": _figure(draw)}, notes=notes,
                        details=details)


class SurfaceTension(Workflow):
    """SPC/E film: gamma_lv from the pressure tensor, bulk density from the profile."""
    name = "surface_tension"

    def forcefield_files(self, s):
        return _water_ff_names(s["water_model"])

    def plan(self, s, run_dir):
        ff = _ff(self.forcefield_files(s))
        seed = int(s["seed"])
        film = water_slab(s["lx_A"], s["ly_A"], s["film_thickness_A"], vacuum=s["vacuum_A"], seed=seed)
        data = run_dir / "system.data"
        write_data(film, ff, data)
        n = film.n_atoms
        fi = s["frame_interval"] or s["sample_interval"]
        groups = {"water_O": film.group("water_O")}

        def define(step: int) -> list[str]:
            return _common_define(s, "all") + _shake(ff) + _thermostat("all", s, step) + [
                "variable pxx equal pxx", "variable pyy equal pyy", "variable pzz equal pzz",
                "variable lz equal lz"]

        leg = Leg(name="film", fresh=lambda d: _fresh_from_data(ff, data, s, groups), define=define,
                  prepare=lambda d: _minimize_water(s), restart_head=_restart_head(s),
                  stages=_stages(_equil(s, "all", 1), Stage("sample", _steps(s, "sample_steps"))),
                  columns={"pe": "v_pe", "temp": "v_temp", "pxx": "v_pxx", "pyy": "v_pyy", "pzz": "v_pzz",
                           "lz": "v_lz"},
                  sample_interval=s["sample_interval"], chunk_steps=s["chunk_steps"], n_atoms=n,
                  frames=Frames("water_O", fi))
        ow = ff.atom_type("OW")
        info = {"film": dict(film.info), "box_A": film.cell.tolist(), "n_molecules": int(film.info["n_molecules"]),
                "lj_epsilon_kcal": ow.epsilon, "lj_sigma_A": ow.sigma}
        return Plan(legs=[leg], timestep_fs=s["timestep_fs"], n_atoms=n,
                    seeds={"structure": seed, "velocities": _seed(seed, 3, 1), "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        s = ctx.settings
        info = ctx.plan.system_info
        d = ctx.samples("film")
        steps, ids, pos, box = ctx.frames("film")
        area = float(info["box_A"][0] * info["box_A"][1])
        nb = min(s["n_blocks"], max(2, len(steps)))
        dens = A.slab_density(pos[:, :, 2], WATER_MASS, area, lz_A=None, bin_A=s["bin_A"], n_blocks=nb)
        rho_n = U.kg_per_m3_to_g_per_cm3(dens["value"]) * U.AVOGADRO / WATER_MASS * 1e-24     # O per A^3
        tail = A.lj_tail_correction(info["lj_epsilon_kcal"], info["lj_sigma_A"], rho_n, s["cutoff_A"],
                                    width_A=dens["width_A"])
        st = A.surface_tension(d["pxx"], d["pyy"], d["pzz"], d["lz"], tail_correction_N_per_m=tail,
                               n_blocks=s["n_blocks"])
        q = {"surface_tension": _q(st["value"], st["stderr"], "N/m",
                                   kind="Kirkwood-Buff from the pressure tensor, LJ tail correction included"),
             "surface_tension_uncorrected": _q(st["value_uncorrected"], st["stderr"], "N/m",
                                               kind="LJ truncated at the cutoff, no tail correction"),
             "density": _q(dens["value"], dens["stderr"], "kg/m^3", kind="liquid density (tanh fit)")}
        prof = dens["profile"]
        curves = {"density_profile": (["z_m", "density_kg_m3"], np.column_stack([prof["z"], prof["density"]])),
                  "pressure_tensor": (["step", "pxx_Pa", "pyy_Pa", "pzz_Pa", "lz_m"],
                                      np.column_stack([d["step"], U.atm_to_Pa(d["pxx"]), U.atm_to_Pa(d["pyy"]),
                                                       U.atm_to_Pa(d["pzz"]), U.angstrom_to_m(d["lz"])]))}
        notes = [f"Coulomb: PPPM with kspace_modify slab 3.0 (long-ranged); Lennard-Jones: truncated at "
                 f"{s['cutoff_A']:g} A in the dynamics, its long-range part added analytically "
                 f"(Blokhuis et al. 1995, tanh profile of width {dens['width_A']:.2f} A): "
                 f"{tail * 1e3:.2f} mN/m.",
                 "reference: SPC/E 63.6 mN/m at 300 K (Vega & de Miguel, J. Chem. Phys. 126 (2007) 154707); "
                 "liquid density 0.997 g/cm^3 (experiment, 298 K)."]

        def draw(ax):
            ax.plot(prof["z_A"], prof["density"], lw=1)
            ax.set_xlabel("z - centre (Å)")
            ax.set_ylabel("density (kg/m³)")
            ax.set_title(f"ρ = {dens['value']:.0f} kg/m³, γ = {st['value'] * 1e3:.1f} ± "
                         f"{st['stderr'] * 1e3:.1f} mN/m")
        return Analysis(quantities=q, curves=curves, figures={"density_profile": _figure(draw)}, notes=notes,
                        details={"tail_correction_N_per_m": tail, "interface_width_A": dens["width_A"],
                                 "half_thickness_A": dens["half_thickness_A"],
                                 "rho_vapour_kg_m3": dens["rho_vapour"]})


WORKFLOWS: dict[str, type[Workflow]] = {"adhesion": Adhesion, "pulloff": PullOff,
                                        "contact_angle": ContactAngleWorkflow, "surface_tension": SurfaceTension}


def get_workflow(name: str) -> Workflow:
    try:
        return WORKFLOWS[name]()
    except KeyError:
        raise KeyError(f"unknown workflow {name!r}; known: {sorted(WORKFLOWS)}") from None
