"""What the four workflows share: LAMMPS set-up, thermostats, minimisation, SHAKE, stage sizes, the
substrates a recipe names, result quantities and figures, the water models, and the :class:`Workflow`
base class (a workflow plans legs for :mod:`md.engine` and analyses what they stored).

Each workflow (1) builds its system with :mod:`md.build` and writes it with :func:`md.system.lammps_data.write_data`,
(2) plans LAMMPS legs for :mod:`md.engine` -- FIRE minimisation first (the builds start strained), NVT
equilibration, sampling -- and (3) turns the stored samples into SI quantities with :mod:`md.analysis`, every
conversion through :mod:`md.units`.

Common LAMMPS set-up: ``units real``, ``atom_style full``, ``boundary p p f``, ``lj/cut/coul/long`` with PPPM
and ``kspace_modify slab 3.0`` (the Yeh-Berkowitz correction: the empty space above the system is tripled
for the Ewald sum, so periodic images along z do not interact), reflecting walls at the z faces of the box
(an evaporated molecule is turned back instead of being lost), pair coefficients and ``special_bonds`` from
the force-field files. Atoms held fixed (slab backs, whole substrates) are left out of the integrator, feel
``setforce 0 0 0`` during minimisation, and their internal pairs are excluded from the neighbour list.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from md.build import ots_sam, silica_slab
from md.engine.plan import Analysis, Plan, Stage, id_ranges
from md.engine.store import RunContext
from md.recipe import RecipeSettings, settings_class
from md.system.atoms import as_system
from md.system.forcefield import ForceField, combine, load_forcefield
from md.system.lammps_data import lammps_setup_commands
from md.system.topology import System

#: A workflow's frozen settings dataclass (:func:`md.recipe.settings_class`, built once by
#: :meth:`md.recipe.Recipe.typed_settings`): the recipe's resolved settings at one fidelity, one attribute per key.
Settings = RecipeSettings

ENERGY_NOT_FREE_ENERGY = (
    "work_of_adhesion is dE/A, the difference of mean potential energies (separated - contact) per area at "
    "the thermostat temperature: an energy, not the free energy of adhesion (the Dupre work). It neglects "
    "-T dS/A, the change of vibrational/conformational entropy on contact.")


# ================================================================================================ LAMMPS helpers

def derived_seed(base: int, *salt: int) -> int:
    """A LAMMPS-valid seed (1 .. 900 000 000) derived from ``base`` and ``salt``."""
    x = int(base)
    for s in salt:
        x = (x * 1_000_003 + int(s) * 7919 + 12345) % 899_999_989
    return x + 1


def restart_header_lines(settings: Settings) -> Callable[[Path], list[str]]:
    def head(path: Path) -> list[str]:
        return [f"read_restart {Path(path).as_posix()}",
                f"kspace_style pppm {settings.kspace_accuracy:g}", "kspace_modify slab 3.0"] + neighbor_lines()
    return head


def neighbor_lines() -> list[str]:
    return ["neighbor 2.0 bin", "neigh_modify delay 0 every 1 check yes"]


def fresh_from_data(ff: ForceField, data: Path, settings: Settings, groups: Mapping[str, Any],
                    pair: str = "long") -> list[str]:
    cmds = lammps_setup_commands(ff, data, boundary="p p f", pair=pair, cutoff=settings.cutoff_A,
                                 kspace_accuracy=settings.kspace_accuracy)
    cmds += neighbor_lines()
    cmds += [f"timestep {settings.timestep_fs:g}"]
    for name, idx in groups.items():
        if len(idx):
            cmds.append(f"group {name} id {id_ranges(idx)}")
        else:
            cmds.append(f"group {name} empty")
    return cmds


def thermostat_lines(group: str, settings: Settings, step: int, salt: int = 0) -> list[str]:
    t = settings.temperature_K
    damp = settings.thermostat_damping_fs
    if settings.thermostat == "nose-hoover":
        return [f"fix thermostat {group} nvt temp {t:g} {t:g} {damp:g}"]
    return [f"fix thermostat {group} langevin {t:g} {t:g} {damp:g} {derived_seed(settings.seed, 17, salt, step)} "
            f"zero yes", f"fix integrate {group} nve"]


def split_thermostat_lines(groups: Sequence[str], union: str, settings: Settings, step: int,
                           salt: int = 0) -> list[str]:
    """One thermostat per group (``groups`` partition ``union``, the atoms integrated): a Nose-Hoover ``fix nvt``
    each, or a Langevin each (own seeds) with one ``fix nve`` on ``union``.

    Why: one thermostat over water and a solid keeps only their *mean* kinetic energy at T. Heat crosses a
    water-solid interface slowly (the hydrophobic one slowest), so whatever the water's relaxation releases, or a
    start leaves unequal, stays unequal for tens of ps while the shared thermostat scales both alike (a start-up
    imbalance the single thermostat does not remove, not a heat source). The remedy is the standard one for the
    "hot solvent / cold solute" problem:
    separate thermostats per component (Lingenheil, Denschlag, Reichold & Tavan, J. Chem. Theory Comput. 4 (2008)
    1293; GROMACS's separate tc-grps for solvent and solute)."""
    t = settings.temperature_K
    damp = settings.thermostat_damping_fs
    if settings.thermostat == "nose-hoover":
        return [f"fix thermostat{'' if k == 0 else k} {g} nvt temp {t:g} {t:g} {damp:g}" for k, g in enumerate(groups)]
    return [f"fix thermostat{'' if k == 0 else k} {g} langevin {t:g} {t:g} {damp:g} "
            f"{derived_seed(settings.seed, 17, salt, step, k)} zero yes" for k, g in enumerate(groups)] + \
        [f"fix integrate {union} nve"]


def trappe_tail_sites(system: System, ff: ForceField, water_o) -> tuple[np.ndarray, list[float]]:
    """The SAM's TraPPE united atoms (0-based indices; none on bare silica) and their C6 = 4 eps sigma^6 with the
    water O (kcal/mol A^6): what the water-TraPPE dispersion beyond the cutoff sums (``dispersion_tail_work``)."""
    sites = np.array([], int)
    if "sam" in system.groups:
        sam = np.asarray(system.group("sam"), int)
        sites = sam[np.isin(np.asarray(system.types)[sam], TRAPPE_UA)]
    ow = str(np.asarray(system.types)[np.asarray(water_o, int)[0]])
    return sites, [4.0 * p.epsilon * p.sigma**6 for p in (ff.pair(ow, str(x)) for x in np.asarray(system.types)[sites])]


#: sampled columns of :func:`water_solid_thermostat_lines`: the water's and the solid's mobile atoms' temperatures
WATER_SOLID_COLUMNS = {"temp_water": "v_tw", "temp_solid": "v_ts"}


def water_solid_thermostat_lines(settings: Settings, step: int, salt: int = 0) -> list[str]:
    """Groups ``water`` and ``mobile`` given: the solid's mobile atoms as group ``solidmobile``, their and the
    water's temperatures (variables ``tw``, ``ts``: :data:`WATER_SOLID_COLUMNS`) and a thermostat each
    (:func:`split_thermostat_lines`)."""
    return ["group solidmobile subtract mobile water", "compute twater water temp", "compute tsolid solidmobile temp",
            "variable tw equal c_twater", "variable ts equal c_tsolid"] + \
        split_thermostat_lines(("water", "solidmobile"), "mobile", settings, step, salt)


#: a leg's mean water or solid temperature further than this from the thermostat's is flagged (K): 2 % at 300 K,
#: many times the statistical error of a leg's mean temperature (each leg's samples give it: ``leg_temperatures``)
TEMPERATURE_TOLERANCE_K = 6.0


def leg_temperatures(ctx, legs, target: float, second_half: tuple[str, ...] = ()) -> dict:
    """Each leg's mean water and solid temperature (sampled columns ``temp_water``, ``temp_solid``: the sampled
    stages, or the second half of the legs named in ``second_half``), the largest deviations from ``target`` and a
    note that flags any beyond :data:`TEMPERATURE_TOLERANCE_K`. {} for a run planned before the two temperatures
    were sampled (one thermostat over water and solid)."""
    per_leg = {}
    for leg in legs:
        d = ctx.samples(leg.name, leg.name not in second_half)
        if "temp_water" not in d or not len(d["temp_water"]):
            return {}
        skip = len(d["temp_water"]) // 2 if leg.name in second_half else 0
        per_leg[leg.name] = {"water": float(np.mean(d["temp_water"][skip:])),
                             "solid": float(np.mean(d["temp_solid"][skip:]))}
    dev = {k: max((abs(v[k] - target) for v in per_leg.values()), default=0.0) for k in ("water", "solid")}
    bad = [f"{name} ({v['water']:.0f} / {v['solid']:.0f} K)" for name, v in per_leg.items()
           if max(abs(v["water"] - target), abs(v["solid"] - target)) > TEMPERATURE_TOLERANCE_K]
    lo = {k: min(v[k] for v in per_leg.values()) for k in ("water", "solid")}
    hi = {k: max(v[k] for v in per_leg.values()) for k in ("water", "solid")}
    note = (f"temperatures (a thermostat each on the water and on the solid's mobile atoms): the legs' mean water "
            f"temperature {lo['water']:.1f}-{hi['water']:.1f} K, solid {lo['solid']:.1f}-{hi['solid']:.1f} K "
            f"(target {target:g} K): " + ("within " + f"{TEMPERATURE_TOLERANCE_K:g} K on every leg." if not bad else
                                         "OFF TARGET on " + ", ".join(bad) + "."))
    return {"per_leg": per_leg, "max_deviation_K": dev, "off_target_legs": [b.split(" ")[0] for b in bad],
            "tolerance_K": TEMPERATURE_TOLERANCE_K, "note": note}


def common_define(settings: Settings, mobile: str) -> list[str]:
    return ["fix zwalls all wall/reflect zlo EDGE zhi EDGE",
            f"compute tmob {mobile} temp",
            "variable pe equal pe", "variable temp equal c_tmob",
            "thermo_style custom step temp c_tmob pe ke press",
            f"thermo {max(settings.sample_interval, settings.chunk_steps // 4)}",
            "thermo_modify norm no flush yes lost error"]


#: timestep (fs) FIRE runs at, whatever the MD timestep: FIRE grows its step to tmax (LAMMPS default 10) times the
#: timestep, and nothing is constrained while it runs (SHAKE comes afterwards; FIRE breaks SHAKE's restraints, see
#: :func:`minimize_water_lines`), so the silanol O-H bond (IFF 495 kcal/mol/A^2, H: period 9.5 fs) vibrates freely.
#: At 1 fs (steps up to 10 fs, the timestep of every flexible-O-H recipe) the minimisations are stable; at the 2 fs
#: of a SHAKE recipe (steps up to 20 fs, two O-H periods) the O-H integration diverges wherever FIRE's global power
#: test does not see it: in a slab of thousands of atoms a silanol H is lost ("Bond atoms missing").
FIRE_TIMESTEP_FS = 1.0


def minimize_lines(settings: Settings, write: Path | None = None, style: str = "fire") -> list[str]:
    """FIRE (or ``style``) minimisation of ``minimize_steps`` iterations; FIRE at :data:`FIRE_TIMESTEP_FS` when the
    MD timestep is longer, the MD timestep restored afterwards."""
    n = int(settings.minimize_steps)
    cmds = []
    if n > 0:
        dt = float(settings.timestep_fs)
        slow = style == "fire" and dt > FIRE_TIMESTEP_FS
        cmds += ([f"timestep {FIRE_TIMESTEP_FS:g}"] if slow else []) + \
            [f"min_style {style}", f"minimize 0.0 1.0e-3 {n} {10 * n}"] + ([f"timestep {dt:g}"] if slow else [])
    if write is not None:
        cmds.append(f"write_data {write.as_posix()}")
    return cmds + ["reset_timestep 0"]


def minimize_water_lines(settings: Settings, write: Path | None = None) -> list[str]:
    """Minimisation of a system with rigid water: conjugate gradients (FIRE moves SHAKE clusters apart: LAMMPS
    turns SHAKE into restraints while minimising, and FIRE's steps break them; cg does not)."""
    return minimize_lines(settings, write, style="cg")


#: silanol O-H bond (IFF OC24-HOY, 0.945 A): constrained where silanols are mobile at a 2 fs timestep
SILANOL_OH = (("OC24", "HOY"),)

#: TraPPE-UA pseudo-atoms (Martin & Siepmann, J. Phys. Chem. B 102 (1998) 2569): any pair with one of them is a
#: "TraPPE pair" whose dispersion beyond the cutoff is added (TraPPE was fitted with 14 A + analytic tails): in the
#: adhesion windows by explicit sums over the frames, on the water of a contact angle by the half-space form
#: (md.analysis.dispersion_tail_work). The OTS head Si (SIH) carries IFF LJ and stays with IFF's plain cutoff.
TRAPPE_UA = ("CH3", "CH2")


def shake_lines(ff: ForceField, also: tuple[tuple[str, str], ...] = ()) -> list[str]:
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


def substrate_water_seeds(seed: int) -> dict[str, int]:
    """The seeds of a plan that equilibrates a substrate and then adds water to it (contact angle, W_SL by TI):
    structures, both velocity draws and the thermostat's base, as result.json records them."""
    return {"structure_substrate": seed, "structure_water": seed + 1, "velocities_substrate": derived_seed(seed, 3, 0),
            "velocities": derived_seed(seed, 3, 1), "thermostat_base": seed}


def round_up(n: float, k: int) -> int:
    return int(max(k, k * math.ceil(float(n) / k - 1e-9)))


def steps_of(n: int, interval: int) -> int:
    """``n`` MD steps rounded up to a whole number of sample intervals (0 stays 0)."""
    n = int(n)
    return 0 if n == 0 else round_up(n, interval)


def equilibrate_stage(settings: Settings, group: str, salt: int = 0, extra: tuple[str, ...] = ()) -> Stage:
    t = settings.temperature_K
    return Stage("equilibrate", steps_of(settings.equilibrate_steps, settings.sample_interval),
                 (f"velocity {group} create {t:g} {derived_seed(settings.seed, 3, salt)} mom yes rot no dist gaussian",)
                 + extra, sampled=False)


def stage_list(*stages: Stage) -> list[Stage]:
    return [s for s in stages if s.steps > 0]


def forcefield_of(names: list[str]) -> ForceField:
    return load_forcefield(names[0]) if len(names) == 1 else combine(*names)


def intersect_ids(system: System, a: str, b: str) -> np.ndarray:
    return np.intersect1d(system.group(a), system.group(b))


def quantity_record(value: float, stderr: float | None, units: str, **extra) -> dict[str, Any]:
    d = {"value": float(value), "stderr": None if stderr is None or not np.isfinite(stderr) else float(stderr),
         "units": units}
    d.update(extra)
    return d


def figure_writer(draw: Callable) -> Callable[[Path], None]:
    def save(path: Path) -> None:
        from matplotlib.figure import Figure  # object API: no pyplot state, no backend switch
        fig = Figure(figsize=(6.0, 4.2), dpi=110)
        ax = fig.subplots()
        draw(ax)
        fig.tight_layout()
        fig.savefig(path)
    return save


def silica_face_of(surfaces: Sequence[str], silica_face: str) -> str:
    """The cristobalite face of a recipe's silica: the recipe's ``silica_face`` (default
    :data:`md.build.SILICA_FACE` = '111', isolated Q3 silanols) for bare silica; always (111) when an OTS SAM
    is among ``surfaces`` (it is grafted on (111), and the two slabs of a pair must share the lateral cell)."""
    return "111" if "ots" in surfaces else silica_face


def held_deep(system: System, group: str = "frozen") -> np.ndarray:
    """Atoms of ``group`` (the builder's deep layer) that are Si or bridging O: only these are held; silanol O
    and H stay mobile everywhere."""
    idx = np.asarray(system.group(group), int)
    return idx[np.isin(system.types[idx], ["SC4", "OC23"])]


def surface_slab(kind: str, nx: int, ny: int, thickness: float, settings: Settings, seed: int,
                  face: str) -> System:
    a = settings.silica_lattice_A
    if kind == "silica":
        dens = settings.silanol_density if face == "001" else 4.5
        return as_system(silica_slab(nx, ny, thickness=thickness, silanol_density=dens, face=face, seed=seed,
                                     lattice_a=a))
    slab = as_system(silica_slab(nx, ny, thickness=thickness, face="111", silanol_density=4.5, seed=seed,
                                 lattice_a=a))
    return as_system(ots_sam(slab, coverage=settings.sam_coverage, chain_length=settings.chain_length,
                             seed=seed + 1))


# ================================================================================================ base class

class Workflow:
    """``version``, which every workflow declares, counts changes of its simulation protocol and enters the run
    hash (:func:`md.engine.hashing.run_hash`), so raising it invalidates the workflow's cached and committed runs.
    ``protocol_version(settings)`` is the version a run with those settings follows (``version`` unless a change
    touched only some systems: then the others keep the version of their unchanged plans, and their hashes).
    ``yields``: the quantities every result of the workflow reports (name -> SI units); some report more.

    The door: :meth:`plan`, :meth:`forcefield_files` and :meth:`protocol_version` take the settings object the
    engine builds once (:meth:`md.recipe.Recipe.typed_settings`) or, from a caller that holds a recipe's resolved
    mapping, that mapping (typed here, at the door); behind it every method takes the :data:`Settings` object, and
    a workflow writes ``_plan``, ``_forcefield_files`` and, where its versions differ by system,
    ``_protocol_version``. :meth:`analyse` reads the same object from ``ctx.settings``."""
    name = ""
    version: int
    yields: dict[str, str] = {}

    @classmethod
    def typed(cls, settings: Mapping[str, Any] | Settings) -> Settings:
        """``settings`` (a recipe's resolved mapping) as this workflow's frozen settings dataclass
        (:func:`md.recipe.settings_class`: every key an attribute, typed and documented); a settings object is
        returned as it is."""
        kind = settings_class(cls.name)
        return settings if isinstance(settings, kind) else kind(**settings)

    def protocol_version(self, settings: Mapping[str, Any] | Settings) -> int:
        return self._protocol_version(self.typed(settings))

    def forcefield_files(self, settings: Mapping[str, Any] | Settings) -> list[str]:
        return self._forcefield_files(self.typed(settings))

    def plan(self, settings: Mapping[str, Any] | Settings, run_dir: Path) -> Plan:
        return self._plan(self.typed(settings), run_dir)

    def _protocol_version(self, s: Settings) -> int:
        return self.version

    def _forcefield_files(self, s: Settings) -> list[str]:
        raise NotImplementedError

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        raise NotImplementedError

    def analyse(self, ctx: RunContext) -> Analysis:
        raise NotImplementedError



def system_summary(system: System) -> dict[str, Any]:
    keep = ("builder", "polymorph", "face", "n_atoms", "silanol_density_top", "silanol_density_bottom", "chains",
            "coverage_nm2", "thickness_A", "radius_requested_A", "silanol_density_dome", "total_charge")
    return {k: system.info[k] for k in keep if k in system.info}



# ================================================================================================ water

#: Water models a recipe may name: their force-field files and the model's own liquid-vapour surface tension at
#: 300 K (published), which turns every contact angle into W_SL = gamma_lv (1 + cos theta) and gamma_lv cos theta.
#: One model throughout a calibration: the angles and gamma_lv of the menisci must describe the same water.
WATER_MODELS: dict[str, dict[str, Any]] = {
    "spce": {"name": "SPC/E", "forcefields": ["water_spce"], "gamma_lv_N_m": 0.0636, "gamma_T_K": 300.0,
             "gamma_source": "SPC/E, 300 K, Ewald with LJ tail: Vega & de Miguel, J. Chem. Phys. 126 (2007) 154707"},
}


def water_forcefield_names(model: str) -> list[str]:
    return list(WATER_MODELS[model]["forcefields"])
