"""The LAMMPS legs of an adhesion run (md.workflows.adhesion.Adhesion.plan): the two slabs built and written, the
SAM anneal, the zero-load contact, the separated pair, every registry's own contact and its chains of force windows;
the grid and registry helpers they use. With ``sam_stress`` every leg also samples the SAM atoms' summed per-atom
stress (``compute stress/atom``, Thompson, Plimpton & Mattson, J. Chem. Phys. 131 (2009) 154107) for the layer's
C13/C33 (md.analysis.stress_ratio_poisson)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from md.build import flip_upside_down, place_on
from md.engine.plan import Frames, Leg, Stage
from md.system.atoms import as_system
from md.system.forcefield import ForceField
from md.system.lammps_data import write_data
from md.system.topology import System
from md.workflows.adhesion_registries import degenerate_registries, primitive_offsets, surface_lattice
from md.workflows.common import (
    TRAPPE_UA,
    Settings,
    Workflow,
    common_define,
    derived_seed,
    equilibrate_stage,
    forcefield_of,
    fresh_from_data,
    intersect_ids,
    minimize_lines,
    restart_header_lines,
    round_up,
    silica_face_of,
    stage_list,
    steps_of,
    surface_slab,
    system_summary,
    thermostat_lines,
)

#: the upper slab's back as one rigid body, free along z only (fix aveforce would give equal forces, not equal
#: accelerations, to atoms of different mass and tear the group apart)
_BACK_RIGID = "fix back_rigid upper_back rigid single force * off off on torque * off off off"

#: explicit-sum radius of the static dispersion tail (smeared images beyond); the cutoff study in every adhesion
#: result compares 20, 30 and 40 A
TAIL_R_MAX_A = 20.0
#: frames stored for the tail: per contact leg, per window (registry 0)
TAIL_FRAMES_CONTACT = 5
TAIL_FRAMES_WINDOW = 2
#: a window with fewer effectively independent force samples than this is flagged
MIN_WINDOW_NEFF = 10
#: with ``sam_stress``: the SAM atoms' per-atom stress (LAMMPS compute stress/atom: minus the per-atom pressure
#: tensor times volume, atm A^3 in real units; pair virials split half and half between the two atoms, kspace and
#: bonded terms included), summed over the group ``sam_layers`` (both SAMs), and the sampled columns
SAM_STRESS_LINES = ["compute sam_sa sam_layers stress/atom NULL",
                    "compute sam_stress sam_layers reduce sum c_sam_sa[1] c_sam_sa[2] c_sam_sa[3]"]
SAM_STRESS_COLUMNS = ("sam_sxx", "sam_syy", "sam_szz")


class _AdhesionLegs:
    """The legs of an adhesion run (:meth:`Adhesion.plan`): the two slabs are built and written on construction;
    :meth:`contact` (upper back one rigid body, free along z at zero load), :meth:`separated` (both backs held,
    ``separation_A`` apart) and, for the free energy, :meth:`windows` (chains of force windows per registry)."""

    def __init__(self, wf: Workflow, s, run_dir: Path):
        self.wf, self.s, self.run_dir = wf, s, run_dir
        self.ff = forcefield_of(wf.forcefield_files(s))
        lower_kind, upper_kind = s.surfaces
        self.face = face = silica_face_of(s.surfaces, s.silica_face)
        seed = int(s.seed)
        self.lower = surface_slab(lower_kind, s.nx, s.ny, s.slab_thickness_A, s, seed, face)
        self.upper = surface_slab(upper_kind, s.nx, s.ny, s.slab_thickness_A, s, seed + 10, face)
        self.system = system = as_system(place_on(self.lower, flip_upside_down(self.upper), gap=s.contact_gap_A,
                                                  vacuum=s.separation_A + 15.0))
        self.data = run_dir / "system.data"
        write_data(system, self.ff, self.data)
        self.groups = {"lower": system.group("substrate"), "upper": system.group("adsorbate"),
                       "lower_fixed": intersect_ids(system, "frozen", "substrate"),
                       "upper_back": intersect_ids(system, "frozen", "adsorbate")}
        self.tail = _tail_applies(s, system)
        self.study = s.dispersion_tail == "trappe"   # contact frames for the cutoff study, even without TraPPE atoms
        if self.study:
            self.groups["tailset"] = np.arange(system.n_atoms)
        self.contact_dir = run_dir / "legs" / "contact"
        self.registries: list[tuple[float, float]] = []
        self.lattice = np.zeros((2, 2))
        self.axes = _chain_axes(system) if s.sam_anneal_steps > 0 else np.zeros((0, 2), int)
        if len(self.axes):
            self.groups["chain_axes"] = np.unique(self.axes)
        si = s.sample_interval
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_back": "v_zback"}
        self.sam_stress = bool(s.sam_stress) and "sam" in system.groups and len(system.group("sam")) > 0
        if self.sam_stress:       # the SAM atoms' summed per-atom stress (pressure x volume): the layer's C13/C33
            self.groups["sam_layers"] = system.group("sam")
            columns.update({k: f"c_sam_stress[{i}]" for i, k in enumerate(SAM_STRESS_COLUMNS, start=1)})
        self.base = dict(define=None, restart_head=restart_header_lines(s), columns=columns,
                         sample_interval=si, chunk_steps=s.chunk_steps, n_atoms=system.n_atoms)
        self.sample = Stage("sample", steps_of(s.sample_steps, si))

    @staticmethod
    def setup_groups() -> list[str]:
        return ["group held union lower_fixed upper_back", "group mobile subtract all held"]

    def define(self, upper_free: bool, salt: int):
        s = self.s

        def d(step: int) -> list[str]:
            cmds = common_define(s, "mobile") + [
                "neigh_modify exclude group lower_fixed lower_fixed",
                "neigh_modify exclude group upper_back upper_back",
                "fix hold_lower lower_fixed setforce 0.0 0.0 0.0",
                "compute gg upper group/group lower kspace yes",
                "variable zback equal xcm(upper_back,z)"] + (SAM_STRESS_LINES if self.sam_stress else [])
            if upper_free:      # one rigid body moving along z only, zero load: the contact finds its gap
                cmds += [_BACK_RIGID]
            else:
                cmds += ["fix hold_upper upper_back setforce 0.0 0.0 0.0"]
            return cmds + thermostat_lines("mobile", s, step, salt)
        return d

    def frames(self, sample_steps: int, per_leg: int, on: bool = True) -> Frames | None:
        si = self.s.sample_interval
        return Frames("tailset", round_up(steps_of(sample_steps, si) / per_leg, si)) if on else None

    def anneal(self) -> Leg:
        """``sam_anneal_steps`` of NVT with the slabs ``separation_A`` apart and both backs held, from the minimised
        build with fresh velocities: each surface relaxes alone (SAM chains tilt collectively, silanols reorient)
        before the contact is formed. Frames of the chains' head Si and CH3 give the mean tilt."""
        s, si = self.s, self.s.sample_interval

        def fresh(leg_dir: Path) -> list[str]:
            return fresh_from_data(self.ff, self.data, s, self.groups) + self.setup_groups() + \
                [f"displace_atoms upper move 0.0 0.0 {s.separation_A:.6f} units box"]
        steps = steps_of(s.sam_anneal_steps, si)
        velocity = (f"velocity mobile create {s.temperature_K:g} {derived_seed(s.seed, 3, 5)} mom yes rot no "
                    f"dist gaussian",)
        frames = Frames("chain_axes", round_up(steps / ANNEAL_FRAMES, si)) if len(self.axes) else None
        return Leg(name="anneal", fresh=fresh, prepare=lambda d: minimize_lines(s), after=(),
                   stages=[Stage("anneal", steps, velocity)], frames=frames,
                   info={"chain_axes": self.axes.tolist()}, **{**self.base, "define": self.define(False, 5)})

    def contact(self) -> Leg:
        s = self.s
        annealed = s.sam_anneal_steps > 0

        def fresh_contact(leg_dir: Path) -> list[str]:
            if annealed:        # the annealed pair, the upper slab moved back down by separation_A
                return self.from_leg(self.run_dir / "legs" / "anneal", steps_of(s.sam_anneal_steps, s.sample_interval),
                                     (0.0, 0.0, -s.separation_A))(leg_dir)
            return fresh_from_data(self.ff, self.data, s, self.groups) + self.setup_groups()
        return Leg(name="contact", fresh=fresh_contact, after=("anneal",) if annealed else (),
                   prepare=lambda d: ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"]
                   + minimize_lines(s, d / "minimized.data") + ["unfix back_min", _BACK_RIGID],
                   stages=stage_list(equilibrate_stage(s, "mobile", 1), self.sample),
                   frames=self.frames(s.sample_steps, TAIL_FRAMES_CONTACT, self.study),
                   **{**self.base, "define": self.define(True, 1)})

    def separated(self) -> Leg:
        s = self.s
        minimized, shift = self.contact_dir / "minimized.data", s.separation_A

        def fresh(leg_dir: Path) -> list[str]:
            return fresh_from_data(self.ff, minimized, s, self.groups) + self.setup_groups() + \
                ([f"displace_atoms upper move 0.0 0.0 {shift:.6f} units box"] if shift else [])
        return Leg(name="separated", fresh=fresh, prepare=lambda d: ["reset_timestep 0"], after=("contact",),
                   stages=stage_list(equilibrate_stage(s, "mobile", 2), self.sample),
                   **{**self.base, "define": self.define(False, 2)})

    def from_leg(self, prev_dir: Path, prev_total: int, move: tuple[float, float, float]):
        s = self.s

        def f(leg_dir: Path) -> list[str]:
            cmds = restart_header_lines(s)(prev_dir / f"restart.{prev_total}") + [f"timestep {s.timestep_fs:g}"]
            if any(abs(x) > 0 for x in move):
                cmds.append(f"displace_atoms upper move {move[0]:.6f} {move[1]:.6f} {move[2]:.6f} units box")
            return cmds
        return f

    def windows(self, contact: Leg) -> list[Leg]:
        """A chain per registry: each window continues (positions and velocities) from its neighbour's last restart,
        moved rigidly by the difference of the nominal separations; the first from the contact leg's last state,
        moved laterally to the registry's offset (bare silica: lifted first, lowered back in :meth:`prepare`)."""
        s, system = self.s, self.system
        stages = stage_list(Stage("equilibrate", steps_of(s.pmf_equilibrate_steps, s.sample_interval), (),
                                  sampled=False),
                            Stage("sample", steps_of(s.pmf_sample_steps, s.sample_interval)))
        total = sum(st.steps for st in stages)
        cell = (float(system.cell[0]) / s.nx, float(system.cell[1]) / s.ny)
        low, up = self.groups["lower"], self.groups["upper"]
        self.lattice = surface_lattice([(system.positions[g], system.types[g]) for g in (low, up)],
                                       system.cell[:2], cell)
        n_reg = int(s.lateral_registries)
        self.registries = (primitive_offsets(n_reg, self.lattice) if s.registry_sampling == "primitive"
                           else _registry_offsets(n_reg, cell))
        legs, nominal, salt = [], {}, 10
        for r, (dx, dy) in enumerate(self.registries):
            start = None
            if r > 0 and s.registry_contact_steps > 0:
                legs.append(self.registry_contact(r, (dx, dy), contact))
                start = legs[-1]
            for suffix, d_nom, prev in self.wf.chains(s):
                prepare = lambda _d: ["reset_timestep 0"]
                if prev is None and start is not None:      # from the registry's own zero-load contact
                    fresh = self.from_leg(self.run_dir / "legs" / start.name, start.total_steps, (0.0, 0.0, d_nom))
                elif prev is None and r > 0 and _lifts_registries(s):
                    fresh = self.from_leg(self.contact_dir, contact.total_steps, (dx, dy, d_nom + REGISTRY_LIFT_A))
                    prepare = lambda _d: registry_approach_lines(s)
                elif prev is None:
                    fresh = self.from_leg(self.contact_dir, contact.total_steps, (dx, dy, d_nom))
                else:
                    fresh = self.from_leg(self.run_dir / "legs" / f"pmf_r{r}_{prev}", total,
                                          (0.0, 0.0, d_nom - nominal[prev]))
                nominal[suffix] = d_nom
                came_from = f"pmf_r{r}_{prev}" if prev else (start.name if start is not None else "contact")
                legs.append(Leg(name=f"pmf_r{r}_{suffix}", fresh=fresh, prepare=prepare, stages=stages,
                                after=(came_from,),
                                frames=self.frames(s.pmf_sample_steps, TAIL_FRAMES_WINDOW, self.tail and r == 0),
                                info={"shift_A": float(d_nom), "registry": r, "offset_A": [dx, dy],
                                      "continues": came_from},
                                **{**self.base, "define": self.define(False, salt)}))
                salt += 1
            for suffix, d_nom, prev, repeats in self.wf.return_chain(s):
                legs.append(Leg(name=f"pmf_r{r}_{suffix}", prepare=lambda _d: ["reset_timestep 0"], stages=stages,
                                after=(f"pmf_r{r}_{prev}",),
                                fresh=self.from_leg(self.run_dir / "legs" / f"pmf_r{r}_{prev}", total,
                                                    (0.0, 0.0, d_nom - nominal[prev])),
                                info={"shift_A": float(d_nom), "registry": r, "offset_A": [dx, dy],
                                      "continues": f"pmf_r{r}_{prev}", "repeats": f"pmf_r{r}_{repeats}"},
                                **{**self.base, "define": self.define(False, salt)}))
                nominal[suffix] = d_nom
                salt += 1
        return legs

    def registry_contact(self, r: int, offset: tuple[float, float], contact: Leg) -> Leg:
        """Registry r's own zero-load contact (``registry_contact_steps``): the contact leg's last state moved to
        the offset (bare silica: lifted first and lowered back in minimisation steps), minimised with the backs
        held, then NVT with the upper back one rigid body free along z (as the contact leg), fresh velocities for
        the first fifth (not sampled)."""
        s, si = self.s, self.s.sample_interval
        lift = REGISTRY_LIFT_A if _lifts_registries(s) else 0.0
        approach = registry_approach_lines(s) if lift else minimize_lines(s)
        steps = steps_of(s.registry_contact_steps, si)
        warm = round_up(steps / 5, si)
        velocity = (f"velocity mobile create {s.temperature_K:g} {derived_seed(s.seed, 3, 20 + r)} mom yes rot no "
                    f"dist gaussian",)
        return Leg(name=f"contact_r{r}", after=("contact",),
                   fresh=self.from_leg(self.contact_dir, contact.total_steps, (offset[0], offset[1], lift)),
                   prepare=lambda _d: ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"] + approach
                   + ["unfix back_min", _BACK_RIGID, "reset_timestep 0"],
                   stages=stage_list(Stage("equilibrate", warm, velocity, sampled=False),
                                     Stage("sample", max(steps - warm, si))),
                   info={"registry": r, "offset_A": list(offset)}, **{**self.base, "define": self.define(True, 40 + r)})

    def info(self) -> dict:
        s, system, groups = self.s, self.system, self.groups
        return {"area_A2": float(system.cell[0] * system.cell[1]), "box_A": system.cell.tolist(),
                "surfaces": list(s.surfaces), "face": self.face,
                "n_lower": int(len(groups["lower"])), "n_upper": int(len(groups["upper"])),
                "lower": system_summary(self.lower), "upper": system_summary(self.upper),
                "dispersion_tail": s.dispersion_tail, "tail_applies": bool(self.tail), "tail_study": bool(self.study),
                "registry_offsets_A": [list(o) for o in self.registries],
                "registry_sampling": s.registry_sampling, "surface_lattice_A": self.lattice.tolist(),
                "degenerate_registries": degenerate_registries(self.registries, self.lattice)
                if len(self.registries) else []}



#: frames of the chain axes stored over the anneal (its mean tilt series)
ANNEAL_FRAMES = 50


def outward_grid(s: Settings) -> np.ndarray:
    """Nominal separations (A) of the outward windows: ``pmf_windows`` quadratically spaced from contact to
    separation_A (dense near contact), with ``pmf_extra_windows_A`` inserted (e.g. over the force peak)."""
    n = int(s.pmf_windows)
    out = s.separation_A * (np.arange(n) / (n - 1)) ** 2
    extra = np.asarray(s.pmf_extra_windows_A, float)
    return np.sort(np.concatenate([out, extra])) if extra.size else out


def _chain_axes(system: System) -> np.ndarray:
    """(head Si, CH3) atom indices of every grafted chain (one molecule id each): the chain axis whose angle to
    the surface normal is the chain's tilt."""
    rows = []
    for i in np.flatnonzero(system.types == "CH3"):
        head = np.flatnonzero((system.mol_ids == system.mol_ids[i]) & (system.types == "SIH"))
        if len(head):
            rows.append((int(head[0]), int(i)))
    return np.array(rows, int).reshape(-1, 2)


def _tail_applies(s: Settings, system: System) -> bool:
    return s.dispersion_tail == "trappe" and bool(np.isin(system.types, TRAPPE_UA).any())


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



#: A registry's first window on bare silica: lift (A) before the lateral shift, and the number of
#: equal steps that lower the slab back, each followed by a minimisation (backs held)
REGISTRY_LIFT_A = 4.0
REGISTRY_LOWER_STEPS = 8


def _lifts_registries(s: Settings) -> bool:
    """Bare silica on bare silica: interlocked silanols cannot be sheared at contact (lift first)."""
    return all(surface == "silica" for surface in s.surfaces)


def registry_approach_lines(s: Settings) -> list[str]:
    """LAMMPS commands that lower the (lifted, shifted) upper slab by REGISTRY_LIFT_A in REGISTRY_LOWER_STEPS equal
    steps, minimising after each (the window's fixes hold both backs), then reset the step counter."""
    step = REGISTRY_LIFT_A / REGISTRY_LOWER_STEPS
    cmds: list[str] = []
    for _ in range(REGISTRY_LOWER_STEPS):
        cmds.append(f"displace_atoms upper move 0.0 0.0 {-step:.6f} units box")
        cmds += minimize_lines(s)
    return cmds


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

