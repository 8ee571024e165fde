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
    energies (:func:`md.analysis.energy_separation_work`). That is an *energy*: with ``free_energy = "pmf"`` the
    mean force between the slabs (``compute group/group`` with ``kspace yes``) is also sampled in windows that
    form chains (each from its neighbour's last state), reach into compression and repeat at several lateral
    registries, and is integrated from its zero-force point (thermodynamic integration along the separation):
    the free energy of separation, T dS = dE - dF, and from the same flat-slab curve sigma0 and
    z0 = 1.026 W_F / sigma0. Dispersion beyond the cutoff is added for TraPPE pairs as a static correction on the
    run's own frames (:func:`md.analysis.lj_tail_between`). Every stderr from the statistical inefficiency.
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
    held contact and extrapolates (:func:`md.analysis.rate_extrapolation`).
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

#: TraPPE-UA pseudo-atoms (Martin & Siepmann, J. Phys. Chem. B 102 (1998) 2569): any pair with one of them is a
#: "TraPPE pair" whose dispersion beyond the cutoff is added (TraPPE was fitted with 14 A + analytic tails). The
#: OTS head Si (SIH) carries IFF LJ and stays with IFF's plain cutoff.
TRAPPE_UA = ("CH3", "CH2")
#: explicit-sum radius of the static dispersion tail (smeared images beyond); the cutoff study in every adhesion
#: result compares 20, 30 and 40 A
TAIL_R_MAX_A = 20.0
#: frames stored for the tail: per contact leg, per window (registry 0)
TAIL_FRAMES_CONTACT = 5
TAIL_FRAMES_WINDOW = 2
#: a window with fewer effectively independent force samples than this is flagged
MIN_WINDOW_NEFF = 10


class Adhesion(Workflow):
    """Work of adhesion of two slabs: energy route, and optionally the free energy by force integration.

    Version 3 (this protocol): the force-integration windows form chains -- each window starts from its
    neighbour's last state, the first (at contact) from the contact leg's last state -- outwards (dense near
    contact) and inwards (``pmf_compress_windows`` pressed into the contact, so the mean force turns repulsive and
    the bottom of the well lies inside the grid); ``lateral_registries`` chains at different lateral offsets of the
    upper slab are averaged; every mean and stderr comes from the statistical inefficiency with automated
    equilibration detection; z0 and sigma0 come from the flat-slab curve; dispersion beyond the cutoff is added for
    TraPPE pairs (``dispersion_tail``). Version 2 started every window from the contact (1 + 3-5 ps each) at one
    registry and integrated from the first window; version 1 started them from the minimised build, 2.8 A wider
    than the 300 K contact (W_F 0.006 against dE/A 0.123 J/m^2 for silica)."""
    name = "adhesion"
    version = 3

    def forcefield_files(self, s):
        return ["silica_interface"] + (["ots_trappe_ua"] if "ots" in s["surfaces"] else [])

    def windows(self, s) -> np.ndarray:
        """Nominal separations from contact (A): the compressed chain (negative, innermost first) and the outward
        chain (0 first, quadratically spaced to separation_A)."""
        n = int(s["pmf_windows"])
        out = s["separation_A"] * (np.arange(n) / (n - 1)) ** 2
        m = int(s["pmf_compress_windows"])
        inward = -s["pmf_compress_A"] * np.arange(m, 0, -1) / m if m else np.zeros(0)
        return np.concatenate([inward, out])

    @staticmethod
    def chains(s) -> list[tuple[str, float, str | None]]:
        """(leg-name suffix, nominal separation, suffix of the leg it continues from) in run order: the contact
        window, the inward chain, the outward chain."""
        n, m = int(s["pmf_windows"]), int(s["pmf_compress_windows"])
        out = s["separation_A"] * (np.arange(n) / (n - 1)) ** 2
        rows = [("o00", 0.0, None)]
        prev = "o00"
        for k in range(1, m + 1):
            rows.append((f"i{k:02d}", -s["pmf_compress_A"] * k / m, prev))
            prev = f"i{k:02d}"
        prev = "o00"
        for k in range(1, n):
            rows.append((f"o{k:02d}", float(out[k]), prev))
            prev = f"o{k:02d}"
        return rows

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
        tail = _tail_applies(s, system)
        study = s["dispersion_tail"] == "trappe"   # contact frames for the cutoff study, even without TraPPE atoms
        if study:
            groups["tailset"] = np.arange(system.n_atoms)
        n = system.n_atoms
        area = float(system.cell[0] * system.cell[1])
        contact_dir = run_dir / "legs" / "contact"
        minimized = contact_dir / "minimized.data"
        setup_groups = lambda: ["group held union lower_fixed upper_back", "group mobile subtract all held"]
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_back": "v_zback"}
        si = s["sample_interval"]

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

        def frames(sample_key: str, per_leg: int, on: bool = True) -> Frames | None:
            return Frames("tailset", _round_up(_steps(s, sample_key) / per_leg, si)) if on else None

        base = dict(define=None, restart_head=_restart_head(s), columns=columns,
                    sample_interval=si, chunk_steps=s["chunk_steps"], n_atoms=n)
        sample = Stage("sample", _steps(s, "sample_steps"))
        contact = Leg(name="contact", fresh=fresh_contact,
                      prepare=lambda d: ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"]
                      + _minimize(s, d / "minimized.data") + ["unfix back_min", _BACK_RIGID],
                      stages=_stages(_equil(s, "mobile", 1), sample),
                      frames=frames("sample_steps", TAIL_FRAMES_CONTACT, study),
                      **{**base, "define": define(True, 1)})
        legs = [
            contact,
            Leg(name="separated", fresh=fresh_from_minimized(s["separation_A"]), prepare=lambda d: ["reset_timestep 0"],
                stages=_stages(_equil(s, "mobile", 2), sample), **{**base, "define": define(False, 2)}),
        ]
        registries = []
        if s["free_energy"] == "pmf":
            # a chain: each window continues (positions and velocities) from its neighbour's last restart, moved
            # rigidly by the difference of the nominal separations; the first from the contact leg's last state,
            # moved laterally to the registry's offset
            pmf_equil = Stage("equilibrate", _steps(s, "pmf_equilibrate_steps"), (), sampled=False)
            pmf_sample = Stage("sample", _steps(s, "pmf_sample_steps"))
            stages = _stages(pmf_equil, pmf_sample)
            total = sum(st.steps for st in stages)
            cell = (float(system.cell[0]) / s["nx"], float(system.cell[1]) / s["ny"])
            registries = _registry_offsets(int(s["lateral_registries"]), cell)
            nominal = {}

            def from_leg(prev_dir: Path, prev_total: int, move: tuple[float, float, float]):
                def f(leg_dir: Path) -> list[str]:
                    cmds = _restart_head(s)(prev_dir / f"restart.{prev_total}") + [f"timestep {s['timestep_fs']:g}"]
                    if any(abs(x) > 0 for x in move):
                        cmds.append(f"displace_atoms upper move {move[0]:.6f} {move[1]:.6f} {move[2]:.6f} units box")
                    return cmds
                return f

            salt = 10
            for r, (dx, dy) in enumerate(registries):
                for suffix, d_nom, prev in self.chains(s):
                    name = f"pmf_r{r}_{suffix}"
                    if prev is None:
                        fresh = from_leg(contact_dir, contact.total_steps, (dx, dy, d_nom))
                    else:
                        fresh = from_leg(run_dir / "legs" / f"pmf_r{r}_{prev}", total, (0.0, 0.0, d_nom - nominal[prev]))
                    nominal[suffix] = d_nom
                    legs.append(Leg(name=name, fresh=fresh, prepare=lambda _d: ["reset_timestep 0"], stages=stages,
                                    frames=frames("pmf_sample_steps", TAIL_FRAMES_WINDOW, tail and r == 0),
                                    info={"shift_A": float(d_nom), "registry": r, "offset_A": [dx, dy],
                                          "continues": f"pmf_r{r}_{prev}" if prev else "contact"},
                                    **{**base, "define": define(False, salt)}))
                    salt += 1
        info = {"area_A2": area, "box_A": system.cell.tolist(), "surfaces": list(s["surfaces"]), "face": face,
                "n_lower": int(len(groups["lower"])), "n_upper": int(len(groups["upper"])),
                "lower": _summary(lower), "upper": _summary(upper), "dispersion_tail": s["dispersion_tail"],
                "tail_applies": bool(tail), "tail_study": bool(study),
                "registry_offsets_A": [list(o) for o in registries]}
        return Plan(legs=legs, timestep_fs=s["timestep_fs"], n_atoms=n,
                    seeds={"structure_lower": seed, "structure_upper": seed + 10, "velocities": _seed(seed, 3, 1),
                           "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    # ------------------------------------------------------------------------------------------ analysis
    def _tail(self, ctx, mode: str, leg: str, r_max: float = TAIL_R_MAX_A, frames=None) -> dict:
        """Static LJ interaction beyond the cutoff between the two slabs on the stored frames of ``leg``:
        per-frame energies (kcal/mol) and forces on the upper slab along +z (kcal/mol/A)."""
        info = ctx.plan.system_info
        cache = self.__dict__.setdefault("_tail_cache", {})
        if (ctx.run_dir, mode) not in cache:
            ids_all, types_all = _read_data_types(ctx.run_dir / "system.data")
            cache[(ctx.run_dir, mode)] = (_tail_pair_table(_ff(ctx.plan.forcefield_files), mode),
                                          dict(zip(ids_all.tolist(), (types_all - 1).tolist())))
        (names, eps, sig, inc), type_of = cache[(ctx.run_dir, mode)]
        steps, ids, pos, box = ctx.frames(leg) if frames is None else frames
        if not len(steps):
            return {"energy": np.zeros(0), "force_z": np.zeros(0), "pairs": 0}
        t = np.array([type_of[int(i)] for i in ids])
        low = ids <= info["n_lower"]
        es, fs, pairs = [], [], 0
        for k in range(len(steps)):
            r = A.lj_tail_between(pos[k][low], t[low], pos[k][~low], t[~low], eps, sig, inc, box[k][:2],
                                  ctx.settings["cutoff_A"], r_max)
            es.append(r["energy"])
            fs.append(r["force_z"])
            pairs = r["pairs"]
        return {"energy": np.array(es), "force_z": np.array(fs), "pairs": pairs}

    def analyse(self, ctx):
        s = ctx.settings
        info = ctx.plan.system_info
        area = info["area_A2"]
        conv = U.kcal_per_mol_A2_to_J_per_m2(1.0) / area           # kcal/mol -> J/m^2 over this interface
        con, sep = ctx.samples("contact"), ctx.samples("separated")
        w = A.energy_separation_work(con["pe"], sep["pe"], area)
        notes = [ENERGY_NOT_FREE_ENERGY,
                 "every mean and stderr comes from the statistical inefficiency with automated equilibration "
                 "detection (Chodera, J. Chem. Theory Comput. 12 (2016) 1799; md.analysis.timeseries_stats)."]
        details: dict[str, Any] = {"energy": {k: v for k, v in w.items() if k not in ("value", "stderr", "units")}}
        zs = A.timeseries_stats(con["z_back"])
        zc = zs["mean"]
        details["contact_back_z_A"] = {"mean": zc, "stderr": zs["stderr"], "g": zs["g"]}
        # ---- dispersion beyond the cutoff (static, on the contact leg's frames)
        tail_on = bool(info.get("tail_applies"))
        w_tail_static, tail_det = 0.0, {"mode": s["dispersion_tail"], "applied": tail_on}
        if tail_on:
            tc = self._tail(ctx, "trappe", "contact")
            u = tc["energy"]
            kt = U.kT_kcal_per_mol(s["temperature_K"])
            w_tail_static = -float(np.mean(u)) * conv
            # second-order check: the free-energy perturbation -kT ln <exp(-U/kT)> against the mean
            fep = -kt * (np.log(np.mean(np.exp(-(u - u.min()) / kt))) - u.min() / kt) if len(u) else float("nan")
            tail_det.update(contact_energy_kcal=u.tolist(), static_work_J_m2=w_tail_static,
                            fep_minus_mean_J_m2=float(-(fep - np.mean(u)) * conv) if len(u) else None,
                            r_max_A=TAIL_R_MAX_A, pairs_per_frame=tc["pairs"])
        if info.get("tail_study") and len(ctx.frames("contact")[0]):
            # cutoff study on the last contact frame: explicit sum to 20/30/40 A (+ smeared beyond), the TraPPE pairs
            # (applied) and every pair (IFF included: reported, not applied)
            st, ids, pos, box = ctx.frames("contact")
            last = (st[-1:], ids, pos[-1:], box[-1:])
            study = {}
            for mode in ("trappe", "all"):
                for rm in (20.0, 30.0, 40.0):
                    e = self._tail(ctx, mode, "contact", rm, frames=last)["energy"]
                    study[f"{mode}_{rm:g}A_J_m2"] = -float(e[0]) * conv
            tail_det["cutoff_study_last_contact_frame"] = study
        q = {"work_of_adhesion": _q(w["value"] + w_tail_static, w["stderr"], "J/m^2",
                                    kind="energy per area (not a free energy)" + (
                                        "; dispersion beyond the cutoff for TraPPE pairs included (static)"
                                        if tail_on else "")),
             "interface_area": _q(U.angstrom_to_m(U.angstrom_to_m(area)), 0.0, "m^2")}
        details["energy"]["cutoff_only_J_m2"] = w["value"]
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
        if s["free_energy"] != "pmf":
            notes.append("free energy not estimated at this fidelity (free_energy = 'none'); the quick and "
                         "production recipes integrate the mean force over separation to measure T dS.")
            details["dispersion_tail"] = tail_det
            return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)
        # ---- the windows: per registry, per window: measured separation, mean force and its stderr
        suffixes = [c[0] for c in self.chains(s)]
        n_reg = len(info["registry_offsets_A"])
        d_A = np.full((n_reg, len(suffixes)), np.nan)
        f_m, f_e = np.full_like(d_A, np.nan), np.full_like(d_A, np.nan)
        g_w, neff_w = np.full_like(d_A, np.nan), np.full_like(d_A, np.nan)
        for r in range(n_reg):
            for k, suf in enumerate(suffixes):
                win = ctx.samples(f"pmf_r{r}_{suf}")           # one read of the window's samples
                st = A.timeseries_stats(win["fz"])
                d_A[r, k] = float(np.mean(win["z_back"])) - zc
                f_m[r, k], f_e[r, k], g_w[r, k], neff_w[r, k] = st["mean"], st["stderr"], st["g"], st["n_eff"]
        order = np.argsort(d_A[0])
        d_A, f_m, f_e, g_w, neff_w = (a[:, order] for a in (d_A, f_m, f_e, g_w, neff_w))
        suffixes = [suffixes[i] for i in order]
        dsep = d_A.mean(axis=0)
        avg = A.registry_average(f_m, f_e)
        fbar, ebar = np.asarray(avg["mean"]), np.asarray(avg["stderr"])
        # tail force per window (registry 0's frames; the tail hardly depends on the registry) and the tail energy
        # left at the last window (the integral of the tail force from there to infinity)
        f_tail = np.zeros_like(fbar)
        u_tail_last = 0.0
        if tail_on:
            for k, suf in enumerate(suffixes):
                tw = self._tail(ctx, "trappe", f"pmf_r0_{suf}")
                if len(tw["force_z"]):
                    f_tail[k] = float(np.mean(tw["force_z"]))
                    if k == len(suffixes) - 1:
                        u_tail_last = float(np.mean(tw["energy"]))
        f_tot = fbar + f_tail
        ti_cut = A.force_integration_work(dsep, fbar, ebar, area)
        ti = A.force_integration_work(dsep, f_tot, ebar, area)
        wf = ti["value"] - u_tail_last * conv
        wf_pchip = ti["value_pchip"] - u_tail_last * conv
        wf_err, wf_disc = ti["stderr"], ti["discretisation_error"]
        per_reg = [A.force_integration_work(d_A[r], f_m[r], f_e[r], area) for r in range(n_reg)]
        w_reg = np.array([p["value"] for p in per_reg])
        if n_reg >= 2:
            reg_avg = A.registry_average(w_reg, [p["stderr"] for p in per_reg])
            wf_err = max(wf_err, reg_avg["stderr"])
        w_e = w["value"] + w_tail_static
        tds = w_e - wf
        repulsive = bool(ti["repulsive_end"])
        q["work_of_adhesion_free_energy"] = _q(
            wf, wf_err, "J/m^2", kind="free energy per area (force integration from the zero-force point of the "
            "registry-averaged mean-force curve, trapezoid rule" + ("; dispersion beyond the cutoff for TraPPE pairs "
                                                                   "included" if tail_on else "") + ")",
            discretisation_error=wf_disc, value_pchip=wf_pchip, repulsive_end=repulsive,
            registry_spread=float(np.std(w_reg, ddof=1)) if n_reg >= 2 else 0.0, registries=n_reg)
        q["entropic_term_TdS"] = _q(tds, math.hypot(w["stderr"], wf_err), "J/m^2",
                                    kind="T dS / A = (dE - dF) / A", discretisation_error=wf_disc)
        if tail_on:
            q["dispersion_tail_work"] = _q(wf - ti_cut["value"], None, "J/m^2",
                                           kind="static dispersion beyond the cutoff for TraPPE pairs, in W_F: "
                                                "tail force integrated over the windows + tail energy left at "
                                                "the last window")
        # ---- z0 and sigma0 from the flat-slab curve
        zsig: dict[str, Any] = {}
        try:
            pk = A.traction_peak(dsep, f_tot, ebar, area)
            pk_disc = pk["discretisation_error"] if np.isfinite(pk["discretisation_error"]) else 0.0
            rng = A.flat_slab_range(wf, math.hypot(wf_err, wf_disc), pk["sigma0"], math.hypot(pk["stderr"], pk_disc))
            q["peak_traction_sigma0"] = _q(pk["sigma0"], pk["stderr"], "Pa",
                                           kind=f"maximum tensile traction of the flat-slab mean-force curve "
                                                f"({pk['method']}: the vertex of the quadratic through the three "
                                                f"windows around the most attractive one)",
                                           discretisation_error=pk["discretisation_error"],
                                           separation_m=U.angstrom_to_m(pk["separation_A"]))
            q["interaction_range_z0"] = _q(rng["z0"], rng["stderr"], "m",
                                           kind="z0 = 1.026 W_F / sigma0 (Maugis 1992, LJ 9-3 law), from the "
                                                "flat-slab mean-force curve", dugdale_range_h0_m=rng["h0"])
            zsig.update(peak=pk, z0=rng)
        except ValueError as exc:
            zsig["error"] = str(exc)
            notes.append(f"z0 and sigma0 not measured: {exc}")
        try:
            fit = A.fit_traction_law(dsep, f_tot, offset=True, force_stderr=ebar)
            zsig["lj93_fit"] = {"z0_A": fit["z0"], "z0_stderr_A": fit["stderr"]["z0"],
                                "w_J_m2": fit["w"] * conv, "w_stderr_J_m2": fit["stderr"]["w"] * conv,
                                "peak_Pa": float(U.kcal_per_mol_A3_to_Pa(fit["peak"] / area)),
                                "offset_A": fit["offset"], "rms_kcal_mol_A": fit["rms"]}
        except (ValueError, RuntimeError) as exc:
            zsig["lj93_fit"] = {"error": str(exc)}
        details["flat_slab_law"] = zsig
        short = [suffixes[k] for k in range(len(suffixes)) if np.nanmin(neff_w[:, k]) < MIN_WINDOW_NEFF]
        details["pmf_windows"] = {
            "separation_A": dsep.tolist(), "mean_force_kcal_mol_A": fbar.tolist(), "stderr_kcal_mol_A": ebar.tolist(),
            "tail_force_kcal_mol_A": f_tail.tolist(), "window": suffixes,
            "per_registry_mean_force_kcal_mol_A": f_m.tolist(), "per_registry_stderr_kcal_mol_A": f_e.tolist(),
            "statistical_inefficiency": g_w.tolist(), "n_eff": neff_w.tolist(),
            "decorrelation_time_ps": ((g_w - 1) / 2 * s["sample_interval"] * dt * 1e-3).tolist(),
            "registry_work_J_m2": w_reg.tolist(), "registry_offsets_A": info["registry_offsets_A"],
            "zero_force_separation_A": ti["zero_force_separation_A"], "repulsive_end": repulsive,
            "windows_with_few_samples": short, "cutoff_only_work_J_m2": ti_cut["value"]}
        tail_det.update(tail_energy_last_window_kcal=u_tail_last)
        details["dispersion_tail"] = tail_det
        pmf = ti["pmf_J_per_m2"]
        curves["pmf"] = (["separation_m", "mean_force_N", "mean_force_stderr_N", "tail_force_N", "pmf_J_per_m2"],
                         np.column_stack([U.angstrom_to_m(dsep), U.kcal_per_mol_A_to_N(f_tot),
                                          U.kcal_per_mol_A_to_N(ebar), U.kcal_per_mol_A_to_N(f_tail), pmf]))
        notes.append(
            f"free energy of separation from {len(suffixes)} windows x {n_reg} lateral registr"
            f"{'y' if n_reg == 1 else 'ies'} ({dsep[0]:+.2f} to {dsep[-1]:.2f} A from the contact leg's mean back "
            f"height {zc:.2f} A; chains: each window continues from its neighbour): dF/A = {wf:.4f} +/- {wf_err:.4f} "
            f"J/m^2 (trapezoid from the zero-force point {ti['zero_force_separation_A']:+.2f} A; PCHIP gives "
            f"{wf_pchip:.4f}, grid error about {wf_disc:.4f}); T dS/A = {tds:.4f} J/m^2. The stderr is statistical "
            f"(and the registries' spread); the discretisation error is given beside it.")
        if not repulsive:
            notes.append("NO REPULSIVE END: no window before the most attractive one has a repulsive mean force, so "
                         "the bottom of the adhesive well lies inside the innermost window and W_F is a lower bound: "
                         "raise pmf_compress_A.")
        if short:
            notes.append(f"windows with fewer than {MIN_WINDOW_NEFF} effectively independent samples: {short} "
                         f"(lengthen pmf_sample_steps).")
        if tail_on:
            notes.append(f"dispersion beyond the {s['cutoff_A']:g} A cutoff for TraPPE pairs (any pair with a CH2/CH3 "
                         f"united atom) added as a static correction measured on this run's frames: "
                         f"{wf - ti_cut['value']:+.4f} J/m^2 in W_F (tail force per window + tail energy left at the "
                         f"last window), {w_tail_static:+.4f} J/m^2 in dE/A (contact frames). IFF pairs keep the plain "
                         f"cutoff IFF was parametrised with.")

        def draw_pmf(ax):
            for r in range(n_reg):
                ax.plot(d_A[r], f_m[r], ".", ms=3, alpha=0.6, label=f"registry {r}")
            ax.errorbar(dsep, f_tot, yerr=ebar, marker="o", ms=3, lw=1, color="k", label="mean (+ tail)")
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlabel("separation from contact (Å)")
            ax.set_ylabel("mean force on upper slab (kcal/mol/Å)")
            ax.set_title(f"dF/A = {wf:.3f} ± {wf_err:.3f} (stat.) ± {wf_disc:.3f} (grid) J/m²")
            ax.legend(fontsize=7)
        figures["pmf"] = _figure(draw_pmf)
        return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)




def _tail_applies(s: Mapping[str, Any], system: System) -> bool:
    return s["dispersion_tail"] == "trappe" and bool(np.isin(system.types, TRAPPE_UA).any())


def _tail_pair_table(ff: ForceField, mode: str):
    """(type names in LAMMPS order, epsilon, sigma, include) for :func:`md.analysis.lj_tail_between`: 'trappe' =
    pairs with a TraPPE united atom, 'all' = every pair."""
    names = [a.name for a in ff.atom_types]
    nt = len(names)
    eps, sig, inc = np.zeros((nt, nt)), np.ones((nt, nt)), np.zeros((nt, nt), bool)
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            p = ff.pair(a, b)
            eps[i, j], sig[i, j] = p.epsilon, p.sigma
            inc[i, j] = mode == "all" or a in TRAPPE_UA or b in TRAPPE_UA
    return names, eps, sig, inc & (eps > 0)


def _read_data_types(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(ids, LAMMPS type numbers) from the Atoms section of a data file (``atom_style full``)."""
    lines = Path(path).read_text().splitlines()
    start = next(i for i, l in enumerate(lines) if l.strip().startswith("Atoms"))
    rows = []
    for l in lines[start + 2:]:
        s = l.split("#")[0].split()
        if not s:
            if rows:
                break
            continue
        rows.append((int(s[0]), int(s[2])))
    arr = np.array(rows, int)
    order = np.argsort(arr[:, 0])
    return arr[order, 0], arr[order, 1]


def _coprime_step(n: int) -> int:
    g = max(1, int(round(0.618 * n)))
    while math.gcd(g, n) != 1:
        g += 1
    return g


def _registry_offsets(n: int, cell: tuple[float, float]) -> list[tuple[float, float]]:
    """n lateral offsets (A) of the upper slab over one surface cell: the rank-1 lattice (k/n, {k g/n}), g coprime
    to n near 0.618 n (k = 0 is no offset)."""
    g = _coprime_step(n)
    return [(round(cell[0] * k / n, 6), round(cell[1] * ((k * g) % n) / n, 6)) for k in range(n)]


def _summary(system: System) -> dict[str, Any]:
    keep = ("builder", "polymorph", "face", "n_atoms", "silanol_density_top", "silanol_density_bottom", "chains",
            "coverage_nm2", "thickness_A", "radius_requested_A", "silanol_density_dome", "total_charge")
    return {k: system.info[k] for k in keep if k in system.info}


# ================================================================================================ pull-off

class PullOff(Workflow):
    """Asperity approach-hold-retract against a flat at constant holder speed.

    Version 2 (this protocol): the moving asperity is not dragged by the thermostat (``tip_thermostat``:
    'comoving' thermostats only its thermal motion, a temp/com bias; the flat has its own thermostat), the residual
    drag on the asperity is measured from the holder's reaction and reported; ``retract_repeats`` independent
    retractions per speed give the pull-off force a spread; the OTS asperity carries >= 4 chains per nm^2 of
    projected cap. Version 1 thermostatted every mobile atom in the lab frame: at 30-40 m/s a drag gamma M v of
    10-13 nN on the asperity against pull-off forces of 0.2-0.5 nN."""
    name = "pulloff"
    version = 2

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
        tip_mobile = np.setdiff1d(groups["tip"], groups["holder_rigid"])
        n = system.n_atoms
        dt = s["timestep_fs"]
        si = s["sample_interval"]
        seed = int(s["seed"])
        v_app = U.m_per_s_to_angstrom_per_fs(s["approach_speed_m_s"])
        n_app = _round_up(s["approach_distance_A"] / (v_app * dt), si)
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_holder": "v_zh", "tip_zmin": "v_tipmin",
                   "flat_zmax": "v_flatmax", "f_holder": "f_hold_holder[3]", "p_tip": "v_ptip"}

        def define(salt: int):
            def d(step: int) -> list[str]:
                return _common_define(s, "mobile") + [
                    "neigh_modify exclude group flat_fixed flat_fixed",
                    "neigh_modify exclude group holder_rigid holder_rigid",
                    "fix hold_flat flat_fixed setforce 0.0 0.0 0.0",
                    "fix hold_holder holder_rigid setforce 0.0 0.0 0.0",
                    "fix move_holder holder_rigid nve",
                    "compute gg tip group/group flat kspace yes",
                    "variable zh equal xcm(holder_rigid,z)", "variable tipmin equal bound(tip,zmin)",
                    "variable flatmax equal bound(flat,zmax)",
                    "variable ptip equal mass(tip_mobile)*vcm(tip_mobile,z)"] + \
                    _pulloff_thermostat(s, step, salt)
            return d

        def fresh(leg_dir: Path) -> list[str]:
            return _fresh_from_data(ff, data, s, groups) + [
                "group held union flat_fixed holder_rigid", "group mobile subtract all held",
                "group flat_mobile subtract flat flat_fixed", "group tip_mobile subtract tip holder_rigid"]

        vz = lambda v: f"velocity holder_rigid set 0.0 0.0 {v:.10g} units box"
        approach = Leg(
            name="approach", fresh=fresh, define=define(0), prepare=lambda d: _minimize(s, d / "minimized.data"),
            restart_head=_restart_head(s),
            stages=_stages(_equil(s, "mobile", 1, (vz(0.0),)), Stage("approach", n_app, (vz(-v_app),)),
                           Stage("hold", _steps(s, "hold_steps"), (vz(0.0),))),
            columns=columns, sample_interval=si, chunk_steps=s["chunk_steps"], n_atoms=n,
            info={"v_approach_A_fs": v_app})
        legs = [approach]
        approach_dir = run_dir / "legs" / "approach"
        repeats = int(s["retract_repeats"])
        t = s["temperature_K"]
        for k, v in enumerate(s["retract_speeds_m_s"]):
            v_ret = U.m_per_s_to_angstrom_per_fs(v)
            n_ret = _round_up(s["retract_distance_A"] / (v_ret * dt), si)
            for j in range(repeats):
                def fresh_retract(leg_dir: Path, _total=approach.total_steps) -> list[str]:
                    return _restart_head(s)(approach_dir / f"restart.{_total}") + [f"timestep {dt:g}"]
                stages = [Stage("retract", n_ret, (vz(v_ret),))]
                if repeats > 1:     # independent pulls: fresh velocities, then hold_steps more in contact
                    stages = _stages(Stage("rehold", _steps(s, "hold_steps"), (
                        f"velocity mobile create {t:g} {_seed(seed, 7, k, j)} mom yes rot no dist gaussian",
                        vz(0.0)), sampled=False)) + stages
                legs.append(Leg(name=f"retract_{k}" + (f"_{j}" if j else ""), fresh=fresh_retract,
                                define=define(100 + 10 * k + j), prepare=lambda d: ["reset_timestep 0"],
                                restart_head=_restart_head(s), stages=stages, columns=columns, sample_interval=si,
                                chunk_steps=s["chunk_steps"], n_atoms=n,
                                info={"speed_m_s": v, "v_A_fs": v_ret, "repeat": j}))
        info.update(n_flat=int(len(groups["flat"])), n_tip=int(len(groups["tip"])),
                    tip_mobile_mass_g_mol=float(system.masses[tip_mobile].sum()), tip_thermostat=s["tip_thermostat"])
        return Plan(legs=legs, timestep_fs=dt, n_atoms=n,
                    seeds={"structure_asperity": seed, "structure_flat": seed + 20, "velocities": _seed(seed, 3, 1),
                           "thermostat_base": seed, **({"sam_asperity": seed + 30} if s["surface"] == "ots" else {})},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        s = ctx.settings
        info = ctx.plan.system_info
        R_m = U.angstrom_to_m(s["asperity_radius_A"])
        ids, pos = _read_data_positions(ctx.leg_dir("approach") / "minimized.data")
        n_flat = info["n_flat"]
        # ids 1..n_flat are the flat (place_on puts the substrate first)
        flat_top = pos[:n_flat, 2].max()
        tip_bottom = pos[n_flat:, 2].min()
        s0 = tip_bottom - flat_top
        app = ctx.samples("approach", False)
        # the holder's height at the minimised start: it does not move before the approach stage, so the first
        # sample of the equilibration has it exactly
        zh0 = float(app["z_holder"][0])
        sep = lambda d: s0 + (d["z_holder"] - zh0)
        dt = ctx.plan.timestep_fs
        curves, figures, pulls = {}, {}, []
        retracts = [l for l in ctx.plan.legs if l.name.startswith("retract_")]
        smooth = None
        for l in retracts:
            d = ctx.samples(l)
            n = len(d["step"])
            smooth = max(5, (n // 25) | 1) if n >= 15 else None
            r = A.pull_off_analysis(sep(d), d["fz"], smooth=smooth, radius_m=R_m)
            r["local_noise"] = _local_noise(r, smooth)
            r["drag"] = _residual_drag(d, dt)
            pulls.append((l.info["speed_m_s"], l.info.get("repeat", 0), l.name, r))
            curves[f"pulloff_curve_{l.name}"] = (
                ["separation_m", "force_N", "force_smoothed_N"],
                np.column_stack([r["curve"]["separation"], r["curve"]["force"], r["curve"]["force_smoothed"]]))
        d_app = ctx.samples("approach", False)
        curves["approach_curve"] = (["step", "stage", "separation_m", "force_N"],
                                    np.column_stack([d_app["step"], d_app["stage"], U.angstrom_to_m(sep(d_app)),
                                                     U.kcal_per_mol_A_to_N(d_app["fz"])]))
        speeds = sorted({v for v, *_ in pulls})
        per_speed = []
        for v in speeds:
            rs = [r for vv, _, _, r in pulls if vv == v]
            fs = np.array([r["max_tensile_force"] for r in rs])
            if len(rs) >= 2:
                f_err, how = float(fs.std(ddof=1) / math.sqrt(len(rs))), f"spread of {len(rs)} pulls"
            else:
                f_err, how = rs[0]["local_noise"], "force noise of one curve near its maximum"
            per_speed.append({"speed_m_s": float(v), "force": float(fs.mean()), "stderr": f_err, "how": how,
                              "forces": fs.tolist(), "results": rs})
        slow = per_speed[0]
        best = slow["results"][0]
        F, f_err = slow["force"], slow["stderr"]
        z0q = _z0_quantity(best) if len(slow["results"]) == 1 else _z0_mean([r for r in slow["results"]])
        drag = np.array([r["drag"]["value"] for r in slow["results"]])
        drag_err = np.array([r["drag"]["stderr"] for r in slow["results"]])
        v_slow = U.m_per_s_to_angstrom_per_fs(slow["speed_m_s"])
        gamma_lab = U.g_per_mol_A_per_fs2_to_kcal_per_mol_A(info["tip_mobile_mass_g_mol"] * v_slow /
                                                           s["thermostat_damping_fs"])
        err = lambda x: x / (2 * math.pi * R_m) if x else None
        q = {"pull_off_force": _q(F, f_err, "N", speed_m_s=slow["speed_m_s"], repeats=len(slow["results"]),
                                  kind=f"maximum tensile force on retraction (mean of {len(slow['results'])}; "
                                       f"stderr: {slow['how']})"),
             "separation_at_max_tension": _q(best["separation_at_max"], None, "m"),
             "interaction_range_z0": z0q,
             "work_of_adhesion_eff_jkr": _q(F / (1.5 * math.pi * R_m), f_err / (1.5 * math.pi * R_m) if f_err else None,
                                            "J/m^2", kind="F / (1.5 pi R)"),
             "work_of_adhesion_eff_dmt": _q(F / (2 * math.pi * R_m), err(f_err), "J/m^2",
                                            kind="F / (2 pi R): compare with the flat-slab W_F (DMT limit; at MD "
                                                 "scale the contact is DMT-like, Tabor mu ~ 0.06)"),
             "residual_drag_force": _q(float(U.kcal_per_mol_A_to_N(drag.mean())),
                                       float(U.kcal_per_mol_A_to_N(math.sqrt(np.sum(drag_err ** 2)) / len(drag))),
                                       "N", kind="mean thermostat force on the moving asperity along the pulling "
                                                 "axis on retraction (holder reaction - interaction + momentum change)",
                                       lab_frame_drag_N=float(U.kcal_per_mol_A_to_N(-gamma_lab)))}
        notes = [f"separation = gap between the lowest asperity atom and the highest flat atom at the minimised "
                 f"start ({s0:.2f} A) plus the rigid holder's travel (no correction for the asperity's or the "
                 f"flat's deformation); force = compute group/group (asperity body vs flat, kspace yes), "
                 f"positive = repulsive.",
                 f"pull-off force: mean of {len(slow['results'])} retraction(s) at {slow['speed_m_s']:g} m/s; "
                 f"stderr: {slow['how']}.",
                 f"thermostat on the asperity: '{s['tip_thermostat']}'"
                 + {"comoving": " (its thermal motion only: compute temp/com bias, so no drag on its motion; the flat "
                                "has its own thermostat)",
                    "none": " (the asperity runs NVE; only the flat is thermostatted)",
                    "lab": " (lab frame, every mobile atom: the old protocol; it drags the moving asperity)"}[
                     s["tip_thermostat"]]
                 + f"; residual drag measured {q['residual_drag_force']['value'] * 1e9:+.3f} nN against "
                   f"{-gamma_lab * U.kcal_per_mol_A_to_N(1.0) * 1e9:.2f} nN that a lab-frame thermostat "
                   f"(gamma M v) would apply.",
                 f"validation, not calibration: at MD scale (R = {s['asperity_radius_A']:g} A) the contact is "
                 f"DMT-like (Tabor mu ~ 0.06), so F / (2 pi R) = {F / (2 * math.pi * R_m):.4f} J/m^2 is the number "
                 f"to compare with the flat-slab work of adhesion W_F (the calibration report does).",
                 f"R = {s['asperity_radius_A']:g} A (the requested radius of the carved, faceted dome)."]
        if s["surface"] == "ots":
            g = info.get("asperity_sam", {})
            notes.append(f"OTS chains on the asperity: {g.get('chains')} on dome silanols within "
                         f"graft_max_polar_deg of the apex ({g.get('chains_per_projected_nm2', float('nan')):.2f} per "
                         f"nm^2 of projected cap, lateral spacing >= {g.get('min_spacing_A', float('nan')):.2f} A); "
                         "they point along the pulling axis, not along the local normal (the builder grafts along "
                         "one axis); the chain-end surface is the dome translated by the chain vector, so its "
                         "curvature radius is still R.")
        details = {"per_speed": [{"speed_m_s": p["speed_m_s"], "max_tensile_force_N": p["force"],
                                  "stderr_N": p["stderr"], "forces_N": p["forces"]} for p in per_speed],
                   "pulls": [{"leg": name, "speed_m_s": float(v), "repeat": j,
                              "max_tensile_force_N": r["max_tensile_force"],
                              "separation_at_max_m": r["separation_at_max"], "z0_m": r["z0"],
                              "z0_stderr_m": r["z0_stderr"], "z0_zero_to_min_m": r["z0_zero_to_min"],
                              "zero_force_separation_m": r["zero_force_separation"],
                              "local_noise_N": r["local_noise"],
                              "residual_drag_N": float(U.kcal_per_mol_A_to_N(r["drag"]["value"])),
                              "residual_drag_stderr_N": float(U.kcal_per_mol_A_to_N(r["drag"]["stderr"])),
                              "traction_fit": {k: v for k, v in r["traction_fit"].items()
                                               if isinstance(v, (int, float, str, dict))}}
                             for v, j, name, r in pulls],
                   "s0_A": float(s0), "holder_z0_A": zh0, "smoothing_window": smooth,
                   "lab_frame_drag_estimate_N": float(U.kcal_per_mol_A_to_N(-gamma_lab)),
                   "tip_mobile_mass_g_mol": info["tip_mobile_mass_g_mol"]}
        if len(speeds) >= 2:
            ext = A.rate_extrapolation(np.array(speeds), np.array([p["force"] for p in per_speed]),
                                       target_rate=float(min(speeds)) / 10.0, temperature_K=s["temperature_K"])
            q["pull_off_force_extrapolated"] = _q(ext["F0"], ext["stderr"], "N",
                                                  kind=f"F = a + b ln(v) fitted to {len(speeds)} speeds, "
                                                       f"evaluated at {ext['target_rate']:g} m/s")
            details["rate_extrapolation"] = ext
            notes.append("rate scan: F = a + b ln(v) (Bell-Evans) extrapolated one decade below the slowest "
                         "simulated speed; valid only while the Bell-Evans regime holds.")

        def draw(ax):
            for (v, j, name, r) in pulls:
                c = r["curve"]
                ax.plot(c["separation"] * 1e9, c["force"] * 1e9, lw=0.5, alpha=0.5)
                ax.plot(c["separation"] * 1e9, c["force_smoothed"] * 1e9, lw=1.5, label=f"{name} {v:g} m/s")
            ax.plot(U.angstrom_to_m(sep(d_app)) * 1e9, U.kcal_per_mol_A_to_N(d_app["fz"]) * 1e9, lw=0.5,
                    color="grey", label="approach/hold")
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlabel("separation (nm)")
            ax.set_ylabel("force on asperity (nN)")
            ax.set_title(f"pull-off {F * 1e9:.3f} nN, R = {s['asperity_radius_A']:g} Å")
            ax.legend(fontsize=7)
        figures["pulloff_curve"] = _figure(draw)
        return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)


def _thermostat_fix(name: str, group: str, settings: Mapping[str, Any], step: int, salt: int) -> list[str]:
    """A named thermostat fix on ``group`` (Langevin + nve, or Nose-Hoover nvt)."""
    t = settings["temperature_K"]
    damp = settings["thermostat_damping_fs"]
    if settings["thermostat"] == "nose-hoover":
        return [f"fix {name} {group} nvt temp {t:g} {t:g} {damp:g}"]
    return [f"fix {name} {group} langevin {t:g} {t:g} {damp:g} {_seed(settings['seed'], 17, salt, step)} zero yes",
            f"fix {name}_nve {group} nve"]


def _pulloff_thermostat(s: Mapping[str, Any], step: int, salt: int) -> list[str]:
    """The pull-off thermostats (recipe ``tip_thermostat``): the flat's mobile atoms always; the asperity's mobile
    atoms in its own frame ('comoving': a temp/com bias, so drag and noise act on the thermal velocities only and
    sum to zero over the asperity), not at all ('none': NVE), or -- the version-1 protocol -- together with the
    flat in the lab frame ('lab')."""
    mode = s["tip_thermostat"]
    if mode == "lab":
        return _thermostat("mobile", s, step, salt)
    cmds = _thermostat_fix("thermo_flat", "flat_mobile", s, step, 2 * salt)
    if mode == "comoving":
        cmds += ["compute tip_com tip_mobile temp/com"] + \
            _thermostat_fix("thermo_tip", "tip_mobile", s, step, 2 * salt + 1) + ["fix_modify thermo_tip temp tip_com"]
    else:
        cmds += ["fix integrate_tip tip_mobile nve"]
    return cmds


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


def _residual_drag(d: Mapping[str, np.ndarray], dt_fs: float, block: int = 10) -> dict[str, float]:
    """Mean thermostat force on the moving asperity's mobile atoms along z over a retraction (kcal/mol/A).

    Newton for the asperity: dP/dt = F_thermostat + F_flat->asperity + F_holder->asperity, and the holder's
    setforce reports f_holder = F_asperity->holder + F_flat->holder; with F_gg = compute group/group of the whole
    upper body (asperity + holder) against the flat, F_thermostat = dP/dt + f_holder - F_gg. Per block of
    ``block`` samples: the time average of f_holder - F_gg (trapezoid) plus the block's momentum change over its
    duration -- the momentum term cancels the asperity's vibrations, which would otherwise swamp the mean. The value
    is the mean over blocks (= the whole leg's), the stderr from the blocks' statistical inefficiency."""
    x = np.asarray(d["f_holder"], float) - np.asarray(d["fz"], float)
    t = np.asarray(d["step"], float) * dt_fs
    p = np.asarray(d["p_tip"], float)
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
        return _q(r["z0"], e if e is not None and np.isfinite(e) else None, "m",
                  kind="z0 of the LJ 9-3 traction law fitted to the retraction curve (stderr from the fit's "
                       "covariance; includes the asperity's compliance)")
    zm = r["z0_zero_to_min"]
    return _q(zm / (3 ** (1 / 6) - 1) if np.isfinite(zm) else float("nan"), None, "m",
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
    return _q(avg["mean"], avg["stderr"], "m", kind=f"mean z0 of the LJ 9-3 law fitted to {z.size} retraction "
                                                    f"curves (includes the asperity's compliance)")


#: lateral spacing of grafted chains on the asperity: tried in this order until the cap holds the target coverage
#: (a crystalline dome's silanols pair up at 4.3-4.4 A in projection; polyethylene's nearest chains are 4.46 A
#: apart, TraPPE CH2 sigma 3.95 A); the builder's default for flat SAMs is 4.4 A
GRAFT_SPACINGS_A = (4.4, 4.35, 4.3)
#: the dome's chains stand along the pulling axis (the flat SAM's builder default is 15 deg off it)
DOME_CHAIN_TILT_DEG = 0.0


def _independent_sites(xy: np.ndarray, cell_xy, spacing: float, order: np.ndarray, exact_max: int = 60,
                       restarts: int = 200, seed: int = 0) -> list[int]:
    """A largest set of sites (indices into ``xy``) no two closer than ``spacing`` laterally (periodic): exact
    branch and bound up to ``exact_max`` sites, else the best of ``restarts`` randomised min-degree greedy passes.
    Ties prefer sites early in ``order`` (nearest the apex)."""
    n = len(xy)
    d = xy[:, None, :] - xy[None, :, :]
    d -= np.asarray(cell_xy)[None, None, :] * np.round(d / np.asarray(cell_xy)[None, None, :])
    close = (np.hypot(d[..., 0], d[..., 1]) < spacing) & ~np.eye(n, dtype=bool)
    adj = [set(np.flatnonzero(close[i]).tolist()) for i in range(n)]
    rank = {int(i): r for r, i in enumerate(order)}
    if n <= exact_max:
        best: list[list[int]] = [[]]

        def rec(cand: set, chosen: list):
            if len(chosen) + len(cand) <= len(best[0]):
                return
            if not cand:
                best[0] = list(chosen)
                return
            v = max(cand, key=lambda u: (len(adj[u] & cand), -rank[u]))
            if not adj[v] & cand:
                rec(cand - {v}, chosen + [v])
                return
            rec(cand - adj[v] - {v}, chosen + [v])
            rec(cand - {v}, chosen)
        rec(set(range(n)), [])
        return sorted(best[0], key=lambda i: rank[i])
    rng = np.random.default_rng(seed)
    best_set: list[int] = []
    for it in range(restarts):
        cand = set(range(n))
        chosen = []
        noise = rng.random(n) if it else np.zeros(n)
        while cand:
            v = min(cand, key=lambda u: (len(adj[u] & cand) + noise[u], rank[u]))
            chosen.append(v)
            cand -= adj[v] | {v}
        if len(chosen) > len(best_set):
            best_set = chosen
    return sorted(best_set, key=lambda i: rank[i])


def _chain_clearance(asp: System, sites: np.ndarray, chain_length: int, tilt_deg: float = 0.0,
                     clearance_A: float = 2.6) -> np.ndarray:
    """True for the sites whose chain -- straight, ``tilt_deg`` from +z towards +x, as :func:`md.builders.ots_sam`
    grafts it -- keeps ``clearance_A`` from every heavy atom of the asperity from 4 A above the anchor O to the
    chain's end. Near the rim of a stepped dome a chain along the pulling axis can run into the dome above its site
    (an 80 deg cap at smoke without this check: an overlap the minimiser cannot undo)."""
    from scipy.spatial import cKDTree

    t = math.radians(tilt_deg)
    axis = np.array([math.sin(t), 0.0, math.cos(t)])
    heavy = np.flatnonzero(~np.isin(asp.types, ["HOY"]))
    tree = cKDTree(asp.positions[heavy])
    length = 1.54 * math.cos(math.radians(33.0)) * (chain_length + 1)     # all-trans axial length, A
    ts = np.arange(4.0, length + 0.5, 0.7)
    ok = np.ones(len(sites), bool)
    for k, site in enumerate(sites):
        pts = asp.positions[site] + ts[:, None] * axis[None, :]
        hits = tree.query_ball_point(pts, clearance_A)
        ok[k] = not any(heavy[h] != site for hs in hits for h in hs)
    return ok


def _graft_dome(asp: System, s: Mapping[str, Any], seed: int) -> tuple[System, dict[str, Any]]:
    """OTS chains on the dome silanols within ``graft_max_polar_deg`` of the apex (asperity tip up), at the SAM's
    coverage ``sam_coverage`` per nm^2 of the cap's projected area (the chains point along the pulling axis, so
    their lateral packing is what counts): the sites are a largest set no two closer than the spacing laterally
    (:data:`GRAFT_SPACINGS_A`, tried in order until one holds the target), the ones nearest the apex kept.
    Version 1 drew sites in random order at 4.4 A and reached 2.65 chains/nm^2 on the quick R = 1.2 nm dome."""
    R = float(s["asperity_radius_A"])
    centre = np.array(asp.info["centre_A"])
    dome = np.asarray(asp.group("silanol_O_dome"), int)
    p = asp.positions[dome] - centre
    cosang = p[:, 2] / np.maximum(np.linalg.norm(p, axis=1), 1e-9)
    keep = cosang >= math.cos(math.radians(s["graft_max_polar_deg"]))
    sites, cos_k = dome[keep], cosang[keep]
    clear = _chain_clearance(asp, sites, s["chain_length"], DOME_CHAIN_TILT_DEG)
    n_blocked = int((~clear).sum())
    sites, cos_k = sites[clear], cos_k[clear]
    if not len(sites):
        raise ValueError("no dome silanols within graft_max_polar_deg of the apex: nothing to graft on")
    cap = math.pi * (R * math.sin(math.radians(s["graft_max_polar_deg"]))) ** 2      # projected area, A^2
    cell_area = float(asp.cell[0] * asp.cell[1])
    n_target = max(1, int(round(s["sam_coverage"] * cap / 100.0)))
    order = np.argsort(-cos_k, kind="stable")               # apex first
    xy = asp.positions[sites, :2]
    chosen, spacing = [], GRAFT_SPACINGS_A[0]
    for spacing in GRAFT_SPACINGS_A:
        chosen = _independent_sites(xy, asp.cell[:2], spacing, order, seed=seed)
        if len(chosen) >= n_target:
            break
    chosen = chosen[:n_target]
    last = None
    for n in range(len(chosen), 0, -1):
        grp = sites[np.array(chosen[:n], int)]
        try:
            sam = ots_sam(with_groups(asp, graft_sites=grp), coverage=(n + 0.49) / (cell_area / 100.0),
                          chain_length=s["chain_length"], seed=seed, site_group="graft_sites",
                          min_spacing=spacing - 1e-6, tilt_deg=DOME_CHAIN_TILT_DEG)
            break
        except ValueError as exc:
            last = exc
    else:
        raise ValueError(f"no OTS chain fits on the dome: {last}")
    chains = int(sam.info["chains"])
    return sam, {"chains": chains, "requested_chains": n_target, "cap_projected_area_nm2": cap / 100.0,
                 "chains_per_projected_nm2": chains / (cap / 100.0), "sites": int(len(sites)),
                 "sites_blocked_by_the_dome": n_blocked, "min_spacing_A": float(spacing)}


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
