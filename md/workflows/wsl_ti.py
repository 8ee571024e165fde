"""The solid-liquid work of adhesion W_SL by thermodynamic integration (:class:`WslTI`): no droplet, no contact line.

wsl_ti
    A water film on (111) silica (isolated Q3 silanols, the surface every silica recipe shares) or on the OTS SAM
    of every OTS recipe is decoupled from the solid in two stages -- the solid's charges scaled to zero, then the
    solid-water Lennard-Jones pairs switched off through a soft core -- and the solid alone (vacuum above) goes
    through the same charge stage as the reference. On OTS the water-TraPPE dispersion beyond the cutoff is added
    statically from the film leg's framed second half, as on the OTS droplets.
    W_SL A = I_q(reference) - I_q(film) - I_lj(film) (:mod:`md.analysis.free_energy`, which derives it), then theta
    from Young-Dupre, or "wets" with the spreading coefficient when W_SL >= 2 gamma_lv.
    Why: a droplet's contact line can stay pinned for the whole of a short run, so a droplet cannot say whether the
    surface wets, and its angle depends on its size; W_SL measured directly has neither problem (Leroy &
    Mueller-Plathe, Langmuir 31 (2015) 8335).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from md import analysis as A
from md import units as U
from md.build import place_on, water_slab
from md.engine.plan import Analysis, Frames, Leg, Plan, Stage
from md.system.atoms import as_system
from md.system.forcefield import lammps_type_ids
from md.system.topology import System
from md.workflows.common import (
    TRAPPE_UA,
    WATER_MODELS,
    WATER_SOLID_COLUMNS,
    Settings,
    Workflow,
    derived_seed,
    figure_writer,
    forcefield_of,
    leg_temperatures,
    minimize_water_lines,
    quantity_record,
    restart_header_lines,
    silica_face_of,
    stage_list,
    steps_of,
    substrate_water_seeds,
    system_summary,
    thermostat_lines,
    water_forcefield_names,
    water_solid_thermostat_lines,
)
from md.workflows.plan_records import WslPlanRecord
from md.workflows.substrate_water import (
    HELD,
    held_define,
    substrate_leg,
    substrate_of,
    substrate_water_forcefields,
    write_substrate_water,
)

#: gap between the solid's highest atom and the film's lowest one when the film is placed (A)
FILM_GAP_A = 2.5
#: water molecules closer than this to a solid atom when the film is added are deleted (A)
FILM_OVERLAP_A = 2.0
#: vacuum above the film (A); kspace_modify slab 3.0 triples the box for the long-range sum
FILM_VACUUM_A = 20.0
#: the film's centre of mass is tethered along z to where it was placed by this spring (kcal/mol/A^2; LAMMPS
#: ``fix spring tether``): decoupled, the film would otherwise drift. Bound, the film sits below that height, so the
#: spring's energy there is added back (:func:`md.analysis.tether_correction`); what remains is an O(kT)
#: translational term (kT = 0.6 kcal/mol at 300 K), small against W_SL A over any interface of a few nm^2; each
#: result's notes give both.
TETHER_K = 1.0
#: central-difference step of lambda for dU/dlambda (``compute fep`` at lambda +- delta)
FEP_DELTA = 0.002
#: PPPM: Ewald parameter x cutoff (2.625: LAMMPS's own choice at 1e-4 and 12 A) and mesh spacing (A, the slab's
#: tripled z included). Fixed, not estimated: LAMMPS estimates them from the charges present, which differ between
#: the film and the solid-alone reference; with one G and one mesh the PPPM energy is one bilinear form of the
#: charges in both, so the held atoms' huge, constant solid-solid share cancels exactly in I_q(ref) - I_q(film).
PPPM_G_RC = 2.625
PPPM_MESH_A = 1.5
#: silica atom types, in the order the charge stage lists them; an OTS substrate adds its SAM's types after them
#: (:func:`solid_types`)
SOLID_TYPES = ("SC4", "OC23", "OC24", "HOY")
#: configurations of the water O and the SAM's TraPPE sites are stored every this many samples of the film leg's
#: second half (OTS only), for the water-TraPPE dispersion beyond the cutoff
FRAME_EVERY_SAMPLES = 4


def solid_types(system, ff) -> tuple[list[str], list[str]]:
    """(every atom type of the substrate, the charged ones), silica's in :data:`SOLID_TYPES` order first, then the
    SAM's (TraPPE CH2/CH3 and the head Si) in force-field order. The charge stage scales the charged ones, the
    dispersion stage switches off every one of them against the water."""
    sub = set(np.asarray(system.types)[np.asarray(system.group("substrate"), int)].tolist())
    order = list(SOLID_TYPES) + [a.name for a in ff.atom_types if a.name not in SOLID_TYPES]
    present = [t for t in order if t in sub]
    return present, [t for t in present if ff.atom_type(t).charge != 0.0]


def _fft_size(n: int) -> int:
    """the smallest integer >= n whose prime factors are 2, 3 and 5"""
    m = max(1, int(n))
    while True:
        k = m
        for p in (2, 3, 5):
            while k % p == 0:
                k //= p
        if k == 1:
            return m
        m += 1


def pppm_lines(settings, box_A) -> list[str]:
    """``kspace_modify`` fixing the Ewald parameter and the mesh (:data:`PPPM_G_RC`, :data:`PPPM_MESH_A`)."""
    g = PPPM_G_RC / float(settings.cutoff_A)
    lx, ly, lz = (float(x) for x in box_A)
    mesh = [_fft_size(math.ceil(lx / PPPM_MESH_A)), _fft_size(math.ceil(ly / PPPM_MESH_A)),
            _fft_size(math.ceil(3.0 * lz / PPPM_MESH_A))]
    return [f"kspace_modify slab 3.0 gewald {g:.6f} mesh {mesh[0]} {mesh[1]} {mesh[2]} order 5"]


class WslTI(Workflow):
    """W_SL of water on silica or OTS by decoupling a film (charges, then soft-core LJ) minus the solid-alone charge
    stage.

    Legs: *substrate* (the slab minimised with nothing held, then deep Si and bridging O held, equilibrated);
    *film* (the water film added on the substrate's last state, minimised, equilibrated at full coupling; on OTS
    the second half is a sampled stage framing the water O and the CH2/CH3 sites, for the dispersion tail);
    *q0..* (the solid's charges at each Gauss-Legendre node, 1 -> 0, each leg continuing from the last);
    *lj0..* (solid charges 0, solid-water LJ lambda at each node, 1 -> 0); *ref_q0..* (the solid alone, the charge
    nodes again, each starting from the state its film node starts from with the water deleted). Every node
    equilibrates ``ti_equilibrate_steps`` and samples ``ti_sample_steps``; dU/dlambda is sampled every
    ``sample_interval`` steps by two ``compute fep``.

    With the water present, the water and the solid's mobile atoms have a thermostat each
    (:func:`md.workflows.common.split_thermostat_lines`), and both temperatures are sampled and reported: at the
    LJ stage's small lambda, where film and solid barely interact, nothing else could equalise them.

    Each reference node starts from its film node's starting state, water deleted, so the solid's slow
    configuration (silanol orientations, SAM head groups) is the same in both: the solid-solid share of
    dU/dlambda_q is tens of thousands of kcal/mol and must cancel to the few kcal/mol W_SL needs. ``version``
    enters the run hash."""
    name = "wsl_ti"
    version = 3
    yields = {"work_of_adhesion_sl": "J/m^2", "contact_angle": "deg", "spreading_coefficient": "J/m^2",
              "surface_tension_lv": "N/m"}

    def _forcefield_files(self, s: Settings) -> list[str]:
        return substrate_water_forcefields(s)

    def build(self, s: Settings) -> tuple[System, System, System]:
        """(substrate, film, both placed in one box), as :meth:`ContactAngleWorkflow.build` with a film."""
        seed = int(s.seed)
        sub = substrate_of(s)
        wff = forcefield_of(water_forcefield_names(s.water_model))
        film = as_system(water_slab(float(sub.cell[0]), float(sub.cell[1]), float(s.film_thickness_A),
                                    vacuum=2.0, seed=seed + 1, forcefield=wff))
        return sub, film, as_system(place_on(sub, film, gap=FILM_GAP_A, vacuum=FILM_VACUUM_A))

    @classmethod
    def nodes(cls, s) -> dict[str, np.ndarray]:
        return {"q": A.gauss_legendre_unit(s.ti_charge_nodes)[0], "lj": A.gauss_legendre_unit(s.ti_lj_nodes)[0]}

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        legs = _WslLegs(self, s, run_dir)
        return Plan(legs=legs.all(), timestep_fs=s.timestep_fs, n_atoms=legs.system.n_atoms,
                    seeds=substrate_water_seeds(int(s.seed)), forcefield_files=self.forcefield_files(s),
                    system_info=legs.info())

    # ------------------------------------------------------------------------------------------ analysis
    def analyse(self, ctx):
        return _WslAnalysis(ctx, ctx.settings).run()


@dataclass(slots=True)
class _WslResults:
    """What :class:`_WslAnalysis` computes, in one place, filled in as :meth:`~_WslAnalysis.run` goes: the water
    model and its gamma_lv, the lambda nodes, per node and per stage dU/dlambda (whole and by halves), the rows of
    the curves, the integrals ``stages``, W_SL's parts ``w`` with its errors, the tether correction ``tc``, the
    dispersion tail, the angle ``ang`` and its grid and statistical errors. Slotted: a name not declared here cannot
    be set."""
    model: dict[str, Any] = field(default_factory=dict)          # the water model (WATER_MODELS)
    gamma: float | None = None                                   # its gamma_lv (N/m)
    nodes: dict[str, np.ndarray] = field(default_factory=dict)   # node set ('q', 'lj') -> lambda nodes
    stages: dict[str, Any] = field(default_factory=dict)         # stage -> its integral (ti_integral)
    per_node: dict[str, Any] = field(default_factory=dict)       # stage -> per-node dU/dlambda records
    halves: dict[int, dict[str, Any]] = field(default_factory=dict)   # half -> stage -> its integral
    rows: dict[str, list] = field(default_factory=dict)          # stage -> per-node rows of the curves
    half_means: dict[str, tuple] = field(default_factory=dict)   # stage -> (first-half, second-half) node means
    dw_tail: float | None = None                                 # the dispersion tail on W_SL (J/m^2)
    w_half: list[float] = field(default_factory=list)            # W_SL from each half
    half_sigma: float | None = None
    half_ok: bool | None = None
    w_err: float | None = None                                   # W_SL's stderr and grid error together
    th_disc: float | None = None                                 # the angle's grid error (deg)
    th_stat: float | None = None                                 # its statistical error (deg)
    w: dict[str, Any] | None = None                              # W_SL and its parts
    tc: dict[str, Any] | None = None                             # the tether correction
    tail: dict[str, Any] | None = None                           # the dispersion tail (OTS)
    ang: dict[str, Any] | None = None                            # Young-Dupre: theta or 'wets'


class _WslAnalysis:
    """W_SL from the stored dU/dlambda, in the MDAnalysis manner: :meth:`_prepare`, :meth:`_single_node` for every
    lambda node of every stage (film charges, film LJ, solid-alone charges), :meth:`_conclude` (the integrals, the
    tether and dispersion-tail corrections, Young-Dupre, the window-length check, notes, curves and the figure)."""

    #: (stage key, leg-name prefix, node set) in the order the stages are read
    STAGES = (("charge_film", "q", "q"), ("lj_film", "lj", "lj"), ("charge_reference", "ref_q", "q"))

    def __init__(self, ctx, s):
        self.ctx, self.s = ctx, s
        self.plan = WslPlanRecord.from_system(ctx.plan.system_info)
        self.results = _WslResults()

    def run(self) -> Analysis:
        res = self.results
        self._prepare()
        for key, prefix, node_set in self.STAGES:
            for k, x in enumerate(res.nodes[node_set]):
                self._single_node(key, f"{prefix}{k}", x)
            self._conclude_stage(key, res.nodes[node_set])
        return self._conclude()

    def _prepare(self) -> None:
        res = self.results
        res.model = WATER_MODELS[self.s.water_model]
        res.gamma = res.model["gamma_lv_N_m"]
        res.nodes = self.plan.nodes
        res.stages, res.per_node, res.halves = {}, {}, {0: {}, 1: {}}
        res.rows = {key: [] for key, _, _ in self.STAGES}
        res.half_means = {key: ([], []) for key, _, _ in self.STAGES}

    def _single_node(self, key: str, leg: str, x: float) -> None:
        """One node: the mean of dU/dlambda with its stderr (statistical inefficiency, equilibration detected), the
        film's height, and the means of the two halves of the samples the mean uses."""
        res = self.results
        d = self.ctx.samples(leg)
        st = A.timeseries_stats(d["dudl"])
        row = {"lambda": float(x), "mean_kcal_mol": st["mean"], "stderr_kcal_mol": st["stderr"],
               "g": st["g"], "n_eff": st["n_eff"], "n": int(len(d["dudl"])), "t0": int(st["t0"])}
        if "z_film" in d and len(d["z_film"]):
            row["z_film_A"] = float(np.mean(d["z_film"]))
        res.rows[key].append(row)
        used = np.asarray(d["dudl"], float)[int(st["t0"]):]          # the samples the mean uses
        for h, part in enumerate((used[:used.size // 2], used[used.size // 2:])):
            res.half_means[key][h].append(float(np.mean(part)) if part.size else float("nan"))

    def _conclude_stage(self, key: str, lam: np.ndarray) -> None:
        res = self.results
        rows = res.rows[key]
        res.per_node[key] = rows
        res.stages[key] = A.ti_integral(lam, [r["mean_kcal_mol"] for r in rows], [r["stderr_kcal_mol"] for r in rows])
        for h in (0, 1):
            res.halves[h][key] = A.ti_integral(lam, res.half_means[key][h],
                                               [r["stderr_kcal_mol"] * math.sqrt(2.0) for r in rows])

    def _conclude(self) -> Analysis:
        res = self.results
        s, ctx = self.s, self.ctx
        temps = leg_temperatures(ctx, [leg for leg in ctx.plan.legs if leg.name == "film" or
                                       leg.name.startswith(("q", "lj"))], s.temperature_K, second_half=("film",))
        self._work()
        q = self._quantities()
        notes = self._notes() + ([temps["note"]] if temps else []) + self._tail_notes()
        details = {"stages": res.stages, "nodes": res.per_node, "parts_J_m2": res.w, "angle": res.ang,
                   "gamma_lv_N_m": res.gamma,
                   "window_halves_J_m2": {"first": res.w_half[0], "second": res.w_half[1],
                                          "consistent": res.half_ok, "difference_sigma": 2.0 * res.half_sigma},
                   "water_model": s.water_model}
        if res.tail is not None:
            details["dispersion_tail"] = res.tail
        if temps:
            details["temperatures_K"] = temps
        return Analysis(quantities=q, curves=self._curves(), figures={"dudl": figure_writer(self._draw)},
                        notes=notes, details=details)

    def _work(self) -> None:
        """W_SL (J/m^2) with the tether and the dispersion-tail corrections, the halves' W_SL, and the angle."""
        res = self.results
        plan, gamma = self.plan, res.gamma
        w = A.ti_work_of_adhesion_sl(res.stages["charge_film"], res.stages["lj_film"],
                                     res.stages["charge_reference"], plan.area_A2)
        # the tether's energy at full coupling (the film leg's second half), added back
        zf = np.asarray(self.ctx.samples("film", False).get("z_film", []), float)
        tc = A.tether_correction(zf[zf.size // 2:], plan.tether_z_A, plan.tether_k_kcal_mol_A2, plan.area_A2)
        w["value"] += tc["value"]
        w["tether_correction"] = tc
        ti_stderr = w["stderr"]           # the nodes' statistical error alone: what the window-length check tests
        # OTS: the water-TraPPE dispersion beyond the cutoff, static, at full coupling (the film leg's framed half)
        tail = _dispersion_tail(self.ctx, plan, self.s) if plan.tail.ids else None
        if tail is not None:
            w["value"] += tail["value"]
            w["stderr"] = math.hypot(w["stderr"], tail["stderr"])
            w["dispersion_tail"] = tail
        res.dw_tail = tail["value"] if tail is not None else 0.0
        # window length: W_SL from the first half of every node's samples against the second half (the same nodes)
        res.w_half = [A.ti_work_of_adhesion_sl(res.halves[h]["charge_film"], res.halves[h]["lj_film"],
                                               res.halves[h]["charge_reference"], plan.area_A2)["value"]
                      + tc["value"] + res.dw_tail for h in (0, 1)]
        # each half has sqrt(2) x the nodes' stderr, their difference 2 x. The tail and the tether enter both halves
        # alike, so their errors cancel in the difference and stay out of its tolerance (as does the quadrature's)
        res.half_sigma = ti_stderr * 2.0
        res.half_ok = bool(abs(res.w_half[1] - res.w_half[0]) <= 2.0 * res.half_sigma)
        res.w_err = math.hypot(w["stderr"], w["discretisation_error"])        # both count for the angle
        ang = A.angle_from_work_of_adhesion_sl(w["value"], res.w_err, gamma)
        # the quadrature's share of the angle's error, first order (reported apart from the statistical one)
        res.th_disc = res.th_stat = None
        if ang["status"] == "measured":
            res.th_disc = math.degrees(w["discretisation_error"] / (gamma * math.sin(math.radians(ang["theta_deg"]))))
            res.th_stat = math.degrees(w["stderr"] / (gamma * math.sin(math.radians(ang["theta_deg"]))))
        res.w, res.tc, res.tail, res.ang = w, tc, tail, ang

    def _quantities(self) -> dict:
        res = self.results
        w, ang, tail, gamma, model = res.w, res.ang, res.tail, res.gamma, res.model
        kinds = {"measured": "Young-Dupre from the TI W_SL: theta = arccos(W_SL / gamma_lv - 1)",
                 "wets": "0 = wets (W_SL >= 2 gamma_lv; mark, not a measurement): see spreading_coefficient",
                 "dewets": "180 = W_SL <= 0 (mark, not a measurement)"}
        q = {"work_of_adhesion_sl": quantity_record(
                w["value"], w["stderr"], "J/m^2", kind="thermodynamic integration: film decoupled from the solid "
                "(charges, then soft-core LJ) minus the solid-alone charge stage",
                discretisation_error=w["discretisation_error"]),
             "contact_angle": quantity_record(ang["theta_deg"], res.th_stat, "deg",
                                              status=ang["status"], kind=kinds[ang["status"]],
                                              discretisation_error=res.th_disc,
                                              upper_one_stderr_deg=ang["theta_upper_deg"]),
             "spreading_coefficient": quantity_record(ang["spreading_coefficient"], w["stderr"], "J/m^2",
                                                      kind="S = W_SL - 2 gamma_lv (>= 0: wets)"),
             **({"dispersion_tail_work_sl": quantity_record(
                 tail["value"], tail["stderr"], "J/m^2", kind="water-TraPPE dispersion beyond the cutoff, static: "
                 "the SAM's CH2/CH3 sites under the film's lower dividing plane, the water uniform at its bulk "
                 "density above it (md.analysis.dispersion_tail_work); included in work_of_adhesion_sl")}
                if tail is not None else {}),
             "surface_tension_lv": quantity_record(gamma, None, "N/m",
                                                   kind="the water model's published gamma_lv "
                                                        f"({model['gamma_source']})")}
        if ang["status"] == "wets":
            # W_SL - 2 sigma (statistical and quadrature together): the largest angle the run does not exclude
            bound = A.angle_from_work_of_adhesion_sl(w["value"] - 2.0 * res.w_err, 0.0, gamma)["theta_deg"]
            q["contact_angle_upper_bound"] = quantity_record(bound, None, "deg", kind="wets: theta below this "
                                                             "bound (Young-Dupre at W_SL - 2 stderr, "
                                                             "quadrature included)")
        if ang["status"] == "measured":
            wl = A.work_of_adhesion_sl(gamma, ang["theta_deg"], None, ang["stderr_deg"])
            q["gamma_lv_cos_theta"] = quantity_record(wl["gamma_cos_theta"], wl["gamma_cos_theta_stderr"], "N/m",
                                                      kind="gamma_lv cos theta = W_SL - gamma_lv")
        return q

    def _notes(self) -> list[str]:
        res = self.results
        s, w, ang, tail, tc, gamma, model = self.s, res.w, res.ang, res.tail, res.tc, res.gamma, res.model
        w_half, half_sigma = res.w_half, res.half_sigma
        conv = A.KCALMOL_PER_A2_TO_J_PER_M2 / self.plan.area_A2
        return [f"window length: W_SL from the first halves of the nodes' samples {w_half[0] * 1e3:.1f}, from the "
                f"second halves {w_half[1] * 1e3:.1f} mJ/m^2 (difference {(w_half[1] - w_half[0]) * 1e3:+.1f}, 2 sigma "
                f"= {2 * half_sigma * 1e3:.1f}): " + ("consistent, the nodes are long enough for their decorrelation."
                                                     if res.half_ok else "NOT consistent: the nodes still relax; "
                                                     "longer nodes are needed."),
                f"W_SL = {w['value'] * 1e3:.1f} +/- {w['stderr'] * 1e3:.1f} mJ/m^2 (quadrature "
                f"+/- {w['discretisation_error'] * 1e3:.1f}): electrostatic {w['electrostatic'] * 1e3:.1f} +/- "
                f"{w['electrostatic_stderr'] * 1e3:.1f}, dispersion {w['dispersion'] * 1e3:.1f} +/- "
                f"{w['dispersion_stderr'] * 1e3:.1f}, tether {tc['value'] * 1e3:+.1f}"
                + (f", water-TraPPE dispersion beyond the {s.cutoff_A:g} A cutoff {res.dw_tail * 1e3:+.1f} +/- "
                   f"{tail['stderr'] * 1e3:.1f}" if tail is not None else "") + " mJ/m^2.",
                {"measured": f"theta = {ang['theta_deg']:.1f} deg from Young-Dupre with gamma_lv = "
                             f"{gamma * 1e3:.1f} mN/m ({model['name']}).",
                 "wets": f"WETS: W_SL exceeds 2 gamma_lv = {2 * gamma * 1e3:.1f} mJ/m^2 by "
                         f"{ang['spreading_coefficient'] * 1e3:.1f} mJ/m^2 (spreading coefficient); theta = 0.",
                 "dewets": "W_SL <= 0: the film does not bind."}[ang["status"]],
                "no droplet and no contact line: the film covers the periodic solid; the decoupled film is "
                "free-standing, so F(decoupled) - F(coupled) = A W_SL with nothing estimated at the end state "
                "(md.analysis.free_energy).",
                f"the film's centre of mass is tethered along z (k = {TETHER_K:g} kcal/mol/A^2) to where it was "
                f"placed; bound at full coupling it sits {tc['offset_A']:+.2f} A from there, and the spring's "
                f"energy there ({tc['energy_kcal_mol']:.2f} kcal/mol = {tc['value'] * 1e3:.1f} mJ/m^2) is added "
                f"to W_SL (md.analysis.tether_correction); the O(kT) translational term it leaves, "
                f"{U.kT_kcal_per_mol(s.temperature_K):.2f} kcal/mol = "
                f"{U.kT_kcal_per_mol(s.temperature_K) * conv * 1e3:.1f} mJ/m^2 here, is not.",
                "substrate minimised with nothing held, then its deep Si and bridging O held; silanol O and H "
                f"mobile (O-H by SHAKE); water rigid {model['name']} (SHAKE); PPPM throughout (the charge stage "
                "scales the solid's charges, the reference subtracts their solid-solid part)."]

    def _tail_notes(self) -> list[str]:
        tail = self.results.tail
        if tail is None:
            return []
        return [f"the water-TraPPE dispersion beyond the {self.s.cutoff_A:g} A cutoff (which TraPPE was fitted with) "
                f"is added statically: {tail['sites']} CH2/CH3 sites under the film's lower dividing plane "
                f"(z = {tail['plane_z_A']:.2f} A, bulk {tail['number_density_A3']:.4f} molecules/A^3), "
                f"{tail['frames']} frames of the film leg's second half; the IFF pairs and water-water keep the "
                "plain cutoff, as in every recipe."]

    def _curves(self) -> dict:
        rows = []
        for key, code in (("charge_film", 0), ("lj_film", 1), ("charge_reference", 2)):
            for r in self.results.per_node[key]:
                rows.append([code, r["lambda"], U.kcal_per_mol_to_J(r["mean_kcal_mol"]),
                             U.kcal_per_mol_to_J(r["stderr_kcal_mol"]), r["g"], r["n_eff"]])
        return {"dudl_nodes": (["stage_code", "lambda", "dudl_mean_J", "dudl_stderr_J", "g", "n_eff"],
                               np.array(rows, float))}

    def _draw(self, ax) -> None:
        res = self.results
        w, ang = res.w, res.ang
        qf, qr, lj = res.per_node["charge_film"], res.per_node["charge_reference"], res.per_node["lj_film"]
        ax.errorbar([r["lambda"] for r in qf], [a["mean_kcal_mol"] - b["mean_kcal_mol"] for a, b in zip(qf, qr)],
                    yerr=[np.hypot(a["stderr_kcal_mol"], b["stderr_kcal_mol"]) for a, b in zip(qf, qr)],
                    marker="o", lw=1, capsize=2, label="charges: film minus solid alone")
        ax.errorbar([r["lambda"] for r in lj], [r["mean_kcal_mol"] for r in lj],
                    yerr=[r["stderr_kcal_mol"] for r in lj], marker="^", lw=1, capsize=2,
                    label="solid-water LJ (soft core)")
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_xlabel("λ")
        ax.set_ylabel("⟨∂U/∂λ⟩ (kcal/mol)")
        title = {"measured": f"θ = {ang['theta_deg']:.1f}°", "wets": "wets", "dewets": "no binding"}[ang["status"]]
        ax.set_title(f"W_SL = {w['value'] * 1e3:.0f} ± {w['stderr'] * 1e3:.0f} mJ/m², {title}")
        ax.legend(fontsize=7)


class _WslLegs:
    """The legs of a W_SL run (:meth:`WslTI.plan`): the system is built and its two parts written on construction;
    :meth:`all` gives the substrate and film legs, then the film's charge nodes, its LJ nodes and the solid-alone
    charge nodes, each node continuing from the leg before it (the reference nodes from their film node's start)."""

    def __init__(self, wf: "WslTI", s, run_dir: Path):
        self.wf, self.s, self.run_dir = wf, s, run_dir
        self.ff = ff = forcefield_of(wf.forcefield_files(s))
        self.sub, self.film, system = wf.build(s)
        self.system = system
        self.parts = parts = write_substrate_water("wsl_ti", "water film", ff, system, run_dir)
        self.substrate, self.water, self.held = parts.substrate, parts.water, parts.held
        self.water_data = parts.water_data
        self.ids = ids = lammps_type_ids(ff)
        self.all_types, self.charged_types = solid_types(system, ff)
        self.solid_t, self.charged_t = [ids[t] for t in self.all_types], [ids[t] for t in self.charged_types]
        self.water_t = sorted(ids[a.name] for a in forcefield_of(water_forcefield_names(s.water_model)).atom_types)
        self.charge = {ids[t]: ff.atom_type(t).charge for t in self.charged_types}
        # OTS: the water O and the SAM's TraPPE sites are framed in the film leg's second half, for the water-TraPPE
        # dispersion beyond the cutoff (analysis: md.analysis.film_lower_dividing_plane + dispersion_tail_work)
        self.tail_sites, self.c6 = parts.tail_sites, parts.c6
        self.ow = str(np.asarray(system.types)[parts.water_o[0]])
        self.z_film = float(system.positions[parts.water, 2].mean())
        self.nodes = wf.nodes(s)
        self.kspace = pppm_lines(s, system.cell)
        self.common = dict(restart_head=self.head, sample_interval=s.sample_interval, chunk_steps=s.chunk_steps)

    def head(self, path: Path) -> list[str]:
        return restart_header_lines(self.s)(path) + self.kspace

    def base(self, with_water: bool, step: int, salt: int) -> list[str]:
        """Every leg's set-up; with the water: one thermostat on the water, one on the solid's mobile atoms, each
        one's temperature sampled, and the film's tether."""
        s = self.s
        return (held_define(s, self.parts) +
                ([f"fix tether water spring tether {TETHER_K:g} NULL NULL {self.z_film:.4f} 0.0",
                  "variable zw equal xcm(water,z)"] + water_solid_thermostat_lines(s, step, salt)
                 if with_water else thermostat_lines("mobile", s, step, salt)))

    def coupling(self, lam_q: float, lam_lj: float, stage: str, with_water: bool) -> list[str]:
        """the solid's charges at lam_q x their force-field values, solid-water LJ at lam_lj; dU/dlambda of
        ``stage`` ('q' or 'lj') by central differences of two compute fep"""
        charged_t, charge = self.charged_t, self.charge
        cmds = [f"variable lq equal {lam_q:.12g}", f"variable ll equal {lam_lj:.12g}"]
        args = []
        for k in charged_t:
            cmds += [f"variable q{k} equal {charge[k]:.8g}*v_lq",
                     f"variable dqp{k} equal {charge[k] * FEP_DELTA:.8g}",
                     f"variable dqm{k} equal {-charge[k] * FEP_DELTA:.8g}"]
            args.append(f"atom charge {k} v_q{k}")
        pairs = [(i, j) for i in self.solid_t for j in self.water_t] if with_water else []
        args += [f"pair lj/cut/coul/long/soft lambda {i} {j} v_ll" for i, j in pairs]
        cmds.append(f"fix couple all adapt/fep 0 {' '.join(args)} reset no")
        cmds += [f"variable dlp equal {FEP_DELTA:g}", f"variable dlm equal {-FEP_DELTA:g}"]
        if stage == "q":
            plus = " ".join(f"atom charge {k} v_dqp{k}" for k in charged_t)
            minus = " ".join(f"atom charge {k} v_dqm{k}" for k in charged_t)
        else:
            plus = " ".join(f"pair lj/cut/coul/long/soft lambda {i} {j} v_dlp" for i, j in pairs)
            minus = " ".join(f"pair lj/cut/coul/long/soft lambda {i} {j} v_dlm" for i, j in pairs)
        t = self.s.temperature_K
        cmds += [f"compute fepp all fep {t:g} {plus}", f"compute fepm all fep {t:g} {minus}",
                 f"variable dudl equal (c_fepp[1]-c_fepm[1])/{2 * FEP_DELTA:g}"]
        return cmds

    def substrate_leg(self) -> Leg:
        """The slab minimised with nothing held, then deep Si and bridging O held, equilibrated; the soft-core pair
        style and the fixed PPPM of every leg of the run."""
        return substrate_leg(self.s, self.parts, lambda step: self.base(False, step, 0), self.head,
                             self.sub.n_atoms, pair="long/soft", kspace=tuple(self.kspace))

    def film_leg(self, sub_leg: Leg) -> Leg:
        """The water film added on the substrate's last state, minimised, equilibrated at full coupling; on OTS the
        second half is a sampled stage framing the water O and the CH2/CH3 sites, for the dispersion tail."""
        s, ids = self.s, self.ids
        sub_dir = self.run_dir / "legs" / "substrate"

        def fresh_film(leg_dir: Path, _total=sub_leg.total_steps) -> list[str]:
            return self.head(sub_dir / f"restart.{_total}") + [
                f"timestep {s.timestep_fs:g}", f"read_data {self.water_data.as_posix()} add append group water",
                "group mobile subtract all frozen"] + \
                ([f"group framed type {ids[self.ow]} " + " ".join(str(ids[x]) for x in TRAPPE_UA
                                                                   if x in self.all_types)]
                 if len(self.tail_sites) else []) + \
                [f"delete_atoms overlap {FILM_OVERLAP_A:g} water substrate mol yes bond yes compress no"]

        begin = (f"velocity mobile create {s.temperature_K:g} {derived_seed(int(s.seed), 3, 1)} mom yes rot no "
                 f"dist gaussian",)
        if len(self.tail_sites):
            # the equilibration's second half is framed (a sampled stage; its samples are the same series as
            # before); silica, with no tail to add, keeps a single unsampled stage
            n_eq = steps_of(s.equilibrate_steps, s.sample_interval)
            half = (n_eq // 2) // s.chunk_steps * s.chunk_steps or n_eq // 2
            film_stages = stage_list(Stage("equilibrate", n_eq - half, begin, sampled=False),
                                     Stage("sample", half))
            film_frames = Frames("framed", s.sample_interval * FRAME_EVERY_SAMPLES)
        else:
            film_stages = [Stage("equilibrate", steps_of(s.equilibrate_steps, s.sample_interval), begin,
                                 sampled=False)]
            film_frames = None
        return Leg(name="film", fresh=fresh_film, define=lambda step: self.base(True, step, 1),
                   prepare=lambda d: minimize_water_lines(s), stages=film_stages,
                   columns={"pe": "v_pe", "temp": "v_temp", "z_film": "v_zw"} | WATER_SOLID_COLUMNS,
                   n_atoms=self.system.n_atoms, frames=film_frames, **self.common)

    def window(self, name: str, prev: Leg, lam_q: float, lam_lj: float, stage: str, with_water: bool, salt: int,
               info: dict, extra: tuple[str, ...] = ()) -> Leg:
        """One lambda node, continuing from the last restart of ``prev``."""
        s = self.s
        prev_dir = self.run_dir / "legs" / prev.name

        def fresh(leg_dir: Path, _total=prev.total_steps) -> list[str]:
            return self.head(prev_dir / f"restart.{_total}") + [f"timestep {s.timestep_fs:g}", *extra]
        cols = {"dudl": "v_dudl", "pe": "v_pe", "temp": "v_temp"} | (
            {"z_film": "v_zw"} | WATER_SOLID_COLUMNS if with_water else {})
        return Leg(name=name, fresh=fresh,
                   define=lambda step: self.base(with_water, step, salt) + self.coupling(lam_q, lam_lj, stage,
                                                                                         with_water),
                   prepare=lambda d: ["reset_timestep 0"],
                   stages=stage_list(Stage("equilibrate", steps_of(s.ti_equilibrate_steps, s.sample_interval),
                                           sampled=False),
                                     Stage("sample", steps_of(s.ti_sample_steps, s.sample_interval))),
                   columns=cols, n_atoms=self.system.n_atoms if with_water else self.sub.n_atoms, info=info,
                   **self.common)

    def all(self) -> list[Leg]:
        sub_leg = self.substrate_leg()
        film_leg = self.film_leg(sub_leg)
        legs = [sub_leg, film_leg]
        prev, salt = film_leg, 10
        film_starts = []                          # the leg each film charge node starts from
        for k, lam in enumerate(self.nodes["q"]):
            film_starts.append(prev)
            leg = self.window(f"q{k}", prev, float(lam), 1.0, "q", True, salt,
                              {"stage": "charges", "lambda": float(lam), "system": "film"})
            legs.append(leg)
            prev, salt = leg, salt + 1
        for k, lam in enumerate(self.nodes["lj"]):
            leg = self.window(f"lj{k}", prev, 0.0, float(lam), "lj", True, salt,
                              {"stage": "dispersion", "lambda": float(lam), "system": "film"})
            legs.append(leg)
            prev, salt = leg, salt + 1
        # each reference node starts from the state its film node starts from, the water deleted, so that the
        # solid's slow configuration (silanols, SAM heads) is the same in both and its solid-solid share of
        # dU/dlambda_q cancels in the difference
        for k, lam in enumerate(self.nodes["q"]):
            start = film_starts[k]
            legs.append(self.window(f"ref_q{k}", start, float(lam), 1.0, "q", False, salt,
                                    {"stage": "charges", "lambda": float(lam), "system": "solid alone",
                                     "start": f"{start.name}'s last state, water deleted"},
                                    extra=("delete_atoms group water mol yes bond yes compress no",)))
            salt += 1
        return legs

    def info(self) -> dict:
        s, ff, system = self.s, self.ff, self.system
        return {"substrate": system_summary(self.sub), "film": dict(self.film.info), "box_A": system.cell.tolist(),
                "area_A2": float(system.cell[0] * system.cell[1]), "n_substrate": int(len(self.substrate)),
                "n_water_molecules_built": int(len(self.water) // 3),
                "held_atoms": int(len(self.held)), "held": HELD,
                "silica_face": silica_face_of((s.surface,), s.silica_face), "water_model": s.water_model,
                "type_ids": self.ids, "solid_types": self.all_types,
                "solid_charges_e": {x: ff.atom_type(x).charge for x in self.charged_types},
                "surface": s.surface, "tail_site_ids": (self.tail_sites + 1).tolist(), "tail_site_c6_kcal_A6": self.c6,
                "tether": {"k_kcal_mol_A2": TETHER_K, "z_A": self.z_film}, "fep_delta": FEP_DELTA,
                "soft_core": "lj/cut/coul/long/soft n = 1, alpha_LJ = 0.5 (Beutler et al. 1994)",
                "nodes": {k: v.tolist() for k, v in self.nodes.items()}, "pppm": self.kspace[0]}


def _dispersion_tail(ctx, plan: WslPlanRecord, s) -> dict | None:
    """The water-TraPPE dispersion beyond the cutoff (J/m^2, > 0 = more adhesion) per frame of the film leg's
    framed half: the film's lower dividing plane and bulk density from all frames' water O
    (:func:`md.analysis.film_lower_dividing_plane`), each frame's TraPPE sites under it
    (:func:`md.analysis.dispersion_tail_work`); mean and stderr from the statistical inefficiency. None when the
    film leg stored no frames."""
    steps, ids, pos, box = ctx.frames("film")
    if not len(steps):
        return None
    is_site, c6 = plan.tail.framed(ids)
    area = plan.area_A2
    plane = A.film_lower_dividing_plane(pos[:, ~is_site, 2], area, len(steps))
    per_frame = np.array([A.dispersion_tail_work(pos[k, is_site, 2], c6, plane["z_A"], plane["number_density_A3"],
                                                 s.cutoff_A, area) for k in range(len(steps))])
    st = A.timeseries_stats(per_frame, equilibrate=False)
    err = st["stderr"] if np.isfinite(st["stderr"]) else float(np.std(per_frame, ddof=1) if len(per_frame) > 1 else 0.0)
    return {"value": U.kcal_per_mol_A2_to_J_per_m2(st["mean"]), "stderr": U.kcal_per_mol_A2_to_J_per_m2(err),
            "per_frame_J_m2": U.kcal_per_mol_A2_to_J_per_m2(per_frame).tolist(), "g": st["g"],
            "plane_z_A": plane["z_A"], "number_density_A3": plane["number_density_A3"],
            "film_thickness_A": plane["film_thickness_A"], "sites": int(is_site.sum()), "frames": int(len(steps)),
            "cutoff_A": s.cutoff_A}
