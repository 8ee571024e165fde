"""The work of adhesion between two surfaces (:class:`Adhesion`).

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
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from md import analysis as A
from md import units as U
from md.build import flip_upside_down, place_on
from md.system.atoms import as_system
from md.system.forcefield import ForceField
from md.system.lammps_data import read_atoms, write_data
from md.engine.plan import Analysis, Frames, Leg, Plan, Stage
from md.system.topology import System

from md.workflows import adhesion_protocol as P
from md.workflows.adhesion_registries import degenerate_registries, primitive_offsets, surface_lattice
from md.workflows.common import (common_define, derived_seed, ENERGY_NOT_FREE_ENERGY, equilibrate_stage,
                                 figure_writer, forcefield_of, fresh_from_data, intersect_ids, minimize_lines,
                                 quantity_record, restart_header_lines, round_up, Settings, silica_face_of,
                                 stage_list, steps_of, surface_slab, system_summary, thermostat_lines, TRAPPE_UA,
                                 Workflow)

# ================================================================================================ adhesion

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


class Adhesion(Workflow):
    """Work of adhesion of two slabs: energy route, and optionally the free energy by force integration.

    The force-integration windows form chains -- each window starts from its neighbour's last state, the first (at
    contact) from the contact leg's last state, so every window starts from the 300 K contact -- outwards (dense
    near contact) and inwards (``pmf_compress_windows`` pressed into the contact, so the mean force turns repulsive
    and the bottom of the well lies inside the grid); ``lateral_registries`` chains at different lateral offsets of
    the upper slab are averaged; every mean and stderr comes from the statistical inefficiency with automated
    equilibration detection; z0 and sigma0 come from the flat-slab curve; dispersion beyond the cutoff is added for
    TraPPE pairs (``dispersion_tail``).

    Bare silica pairs cannot be sheared at contact: their interlocked silanols would land on each other. There a
    registry's first window lifts the upper slab by REGISTRY_LIFT_A, shifts it, and lowers it back in
    REGISTRY_LOWER_STEPS steps, minimising after each with the backs held: a quasi-static approach at the new
    registry (:func:`registry_approach_lines`). ``version`` (4) and :meth:`protocol_version` (3 for SAM pairs,
    whose plans this does not touch) enter the run hash."""
    name = "adhesion"
    version = 4
    yields = {"work_of_adhesion": "J/m^2", "work_of_adhesion_free_energy": "J/m^2",
              "entropic_term_TdS": "J/m^2", "interface_area": "m^2"}

    def forcefield_files(self, s):
        s = self.typed(s)
        return ["silica_interface"] + (["ots_trappe_ua"] if "ots" in s.surfaces else [])

    def protocol_version(self, s) -> int:
        s = self.typed(s)
        return self.version if _lifts_registries(s) else 3

    def windows(self, s) -> np.ndarray:
        """Nominal separations from contact (A): the compressed chain (negative, innermost first) and the outward
        chain (0 first, quadratically spaced to separation_A)."""
        s = self.typed(s)
        out = outward_grid(s)
        m = int(s.pmf_compress_windows)
        inward = -s.pmf_compress_A * np.arange(m, 0, -1) / m if m else np.zeros(0)
        return np.concatenate([inward, out])

    @classmethod
    def chains(cls, s) -> list[tuple[str, float, str | None]]:
        """(leg-name suffix, nominal separation, suffix of the leg it continues from) in run order: the contact
        window, the inward chain, the outward chain."""
        s = cls.typed(s)
        out = outward_grid(s)
        n, m = len(out), int(s.pmf_compress_windows)
        rows = [("o00", 0.0, None)]
        prev = "o00"
        for k in range(1, m + 1):
            rows.append((f"i{k:02d}", -s.pmf_compress_A * k / m, prev))
            prev = f"i{k:02d}"
        prev = "o00"
        for k in range(1, n):
            rows.append((f"o{k:02d}", float(out[k]), prev))
            prev = f"o{k:02d}"
        return rows

    @classmethod
    def return_chain(cls, s) -> list[tuple[str, float, str, str]]:
        """With ``pmf_return``: (suffix, nominal separation, suffix it continues from, the outward window it
        repeats) in run order, from the outermost outward window back through the outward grid (``bKK`` repeats
        ``oKK``) and into compression (``cKK`` repeats ``iKK``); empty without it."""
        s = cls.typed(s)
        if not s.pmf_return:
            return []
        out = outward_grid(s)
        n, m = len(out), int(s.pmf_compress_windows)
        rows, prev = [], f"o{n - 1:02d}"
        for k in range(n - 2, -1, -1):
            rows.append((f"b{k:02d}", float(out[k]), prev, f"o{k:02d}"))
            prev = f"b{k:02d}"
        for k in range(1, m + 1):
            rows.append((f"c{k:02d}", -s.pmf_compress_A * k / m, prev, f"i{k:02d}"))
            prev = f"c{k:02d}"
        return rows

    def plan(self, s, run_dir):
        s = self.typed(s)
        legs = _AdhesionLegs(self, s, run_dir)
        anneal = [legs.anneal()] if s.sam_anneal_steps > 0 else []
        contact = legs.contact()
        windows = legs.windows(contact) if s.free_energy == "pmf" else []
        seed = int(s.seed)
        return Plan(legs=anneal + [contact, legs.separated()] + windows, timestep_fs=s.timestep_fs, n_atoms=legs.system.n_atoms,
                    seeds={"structure_lower": seed, "structure_upper": seed + 10, "velocities": derived_seed(seed, 3, 1),
                           "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=legs.info())

    # ------------------------------------------------------------------------------------------ analysis
    def _tail(self, ctx, mode: str, leg: str, r_max: float = TAIL_R_MAX_A, frames=None) -> dict:
        """Static LJ interaction beyond the cutoff between the two slabs on the stored frames of ``leg``:
        per-frame energies (kcal/mol) and forces on the upper slab along +z (kcal/mol/A)."""
        info = ctx.plan.system_info
        cache = self.__dict__.setdefault("_tail_cache", {})
        if (ctx.run_dir, mode) not in cache:
            ids_all, types_all, _ = read_atoms(ctx.run_dir / "system.data")
            cache[(ctx.run_dir, mode)] = (_tail_pair_table(forcefield_of(ctx.plan.forcefield_files), mode),
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
                                  self.typed(ctx.settings).cutoff_A, r_max)
            es.append(r["energy"])
            fs.append(r["force_z"])
            pairs = r["pairs"]
        return {"energy": np.array(es), "force_z": np.array(fs), "pairs": pairs}

    def analyse(self, ctx):
        return _AdhesionAnalysis(self, ctx).run()


class _AdhesionAnalysis:
    """dE/A from the contact and separated legs and, with ``free_energy = "pmf"``, the free energy from the force
    windows, in the MDAnalysis manner: :meth:`_prepare` (the energy route, the static dispersion tail, the cutoff
    study), :meth:`_single_window` for every window of every registry, :meth:`_conclude` (registry average, force
    integration, z0 and sigma0, the window checks, notes, curves and figures)."""

    def __init__(self, wf: Adhesion, ctx):
        self.wf, self.ctx, self.s, self.info = wf, ctx, wf.typed(ctx.settings), ctx.plan.system_info

    def run(self) -> Analysis:
        self._prepare()
        self._protocol_legs()
        if self.s.free_energy != "pmf":
            self.notes.append("free energy not estimated at this fidelity (free_energy = 'none'); the quick and "
                              "production recipes integrate the mean force over separation to measure T dS.")
            self.details["dispersion_tail"] = self.tail_det
            return self._analysis()
        self.suffixes = [c[0] for c in self.wf.chains(self.s)]
        self.n_reg = len(self.info["registry_offsets_A"])
        shape = (self.n_reg, len(self.suffixes))
        self.d_A, self.f_m, self.f_e, self.g_w, self.neff_w = (np.full(shape, np.nan) for _ in range(5))
        # mean force of the first and the second half of each window's equilibrated samples (those after the
        # detected start t0, as the mean itself)
        self.halves = np.full((2,) + shape, np.nan)
        for r in range(self.n_reg):
            for k, suf in enumerate(self.suffixes):
                self._single_window(r, k, suf)
        return self._conclude()

    def _analysis(self) -> Analysis:
        return Analysis(quantities=self.q, curves=self.curves, figures=self.figures, notes=self.notes,
                        details=self.details)

    # ---- prepare: the energy route and the static tail
    def _prepare(self) -> None:
        ctx, s, info = self.ctx, self.s, self.info
        self.area = area = info["area_A2"]
        self.conv = U.kcal_per_mol_A2_to_J_per_m2(1.0) / area           # kcal/mol -> J/m^2 over this interface
        con, sep = ctx.samples("contact"), ctx.samples("separated")
        self.w = w = A.energy_separation_work(con["pe"], sep["pe"], area)
        self.notes = [ENERGY_NOT_FREE_ENERGY,
                      "every mean and stderr comes from the statistical inefficiency with automated equilibration "
                      "detection (Chodera, J. Chem. Theory Comput. 12 (2016) 1799; md.analysis.timeseries_stats)."]
        self.details: dict[str, Any] = {"energy": {k: v for k, v in w.items() if k not in ("value", "stderr", "units")}}
        zs = A.timeseries_stats(con["z_back"])
        self.zc = zs["mean"]
        self.details["contact_back_z_A"] = {"mean": self.zc, "stderr": zs["stderr"], "g": zs["g"]}
        self._static_tail()
        tail_on = self.tail_on
        self.q = {"work_of_adhesion": quantity_record(w["value"] + self.w_tail_static, w["stderr"], "J/m^2",
                                         kind="energy per area (not a free energy)" + (
                                             "; dispersion beyond the cutoff for TraPPE pairs included (static)"
                                             if tail_on else "")),
                  "interface_area": quantity_record(U.angstrom_to_m(U.angstrom_to_m(area)), 0.0, "m^2")}
        self.details["energy"]["cutoff_only_J_m2"] = w["value"]
        self._energy_curves()

    def _static_tail(self) -> None:
        """Dispersion beyond the cutoff, static, on the contact leg's frames; and the cutoff study on its last frame
        (explicit sum to 20/30/40 A + smeared beyond; the TraPPE pairs, applied, and every pair, IFF included:
        reported, not applied)."""
        ctx, s, info, conv = self.ctx, self.s, self.info, self.conv
        self.tail_on = tail_on = bool(info.get("tail_applies"))
        self.w_tail_static, self.tail_det = 0.0, {"mode": s.dispersion_tail, "applied": tail_on}
        if tail_on:
            tc = self.wf._tail(ctx, "trappe", "contact")
            u = tc["energy"]
            kt = U.kT_kcal_per_mol(s.temperature_K)
            self.w_tail_static = -float(np.mean(u)) * conv
            # second-order check: the free-energy perturbation -kT ln <exp(-U/kT)> against the mean
            fep = -kt * (np.log(np.mean(np.exp(-(u - u.min()) / kt))) - u.min() / kt) if len(u) else float("nan")
            self.tail_det.update(contact_energy_kcal=u.tolist(), static_work_J_m2=self.w_tail_static,
                                 fep_minus_mean_J_m2=float(-(fep - np.mean(u)) * conv) if len(u) else None,
                                 r_max_A=TAIL_R_MAX_A, pairs_per_frame=tc["pairs"])
        if info.get("tail_study") and len(ctx.frames("contact")[0]):
            st, ids, pos, box = ctx.frames("contact")
            last = (st[-1:], ids, pos[-1:], box[-1:])
            study = {}
            for mode in ("trappe", "all"):
                for rm in (20.0, 30.0, 40.0):
                    e = self.wf._tail(ctx, mode, "contact", rm, frames=last)["energy"]
                    study[f"{mode}_{rm:g}A_J_m2"] = -float(e[0]) * conv
            self.tail_det["cutoff_study_last_contact_frame"] = study

    def _energy_curves(self) -> None:
        self.curves: dict[str, tuple[list[str], np.ndarray]] = {}
        self.figures = {}
        self.dt = dt = self.ctx.plan.timestep_fs
        self.all_con, self.all_sep = self.ctx.samples("contact", False), self.ctx.samples("separated", False)
        for name, d in (("energy_contact", self.all_con), ("energy_separated", self.all_sep)):
            self.curves[name] = (["step", "time_s", "stage", "potential_energy_J", "temperature_K"],
                                 np.column_stack([d["step"], U.fs_to_s(d["step"] * dt), d["stage"],
                                                  U.kcal_per_mol_to_J(d["pe"]), d["temp"]]))
        self.figures["energy_timeseries"] = figure_writer(self._draw_energy)

    def _draw_energy(self, ax) -> None:
        w, dt = self.w, self.dt
        for d, lab in ((self.all_con, "contact"), (self.all_sep, "separated")):
            ax.plot(d["step"] * dt * 1e-3, d["pe"], lw=0.8, label=lab)
        ax.set_xlabel("time (ps)")
        ax.set_ylabel("potential energy (kcal/mol)")
        ax.set_title(f"W = {w['value']:.3f} ± {w['stderr']:.3f} J/m² (energy)")
        ax.legend()

    def _protocol_legs(self) -> None:
        """The optional legs (md.workflows.adhesion_protocol): the SAM anneal, each registry's own contact, and a
        note on registries that repeat another."""
        names = {leg.name for leg in self.ctx.plan.legs}
        if "anneal" in names:
            det, notes, curves = P.anneal_record(self.ctx, self.dt)
            self.details["anneal"], self.notes, self.curves = det, self.notes + notes, {**self.curves, **curves}
            self.figures["anneal"] = figure_writer(lambda ax: P.draw_anneal(ax, det))
        if any(n.startswith("contact_r") for n in names):
            self.details["registry_contacts"] = P.registry_contacts_record(
                self.ctx, self.ctx.samples("separated")["pe"], self.area, self.zc, self.w_tail_static)
        if self.s.free_energy == "pmf":
            self.notes += P.degenerate_note(self.info)

    # ---- per window
    def _single_window(self, r: int, k: int, suf: str) -> None:
        """Window ``suf`` of registry ``r``: measured separation, mean force with its stderr, statistical
        inefficiency, and the mean forces of the two halves of the samples the mean uses."""
        win = self.ctx.samples(f"pmf_r{r}_{suf}")           # one read of the window's samples
        st = A.timeseries_stats(win["fz"])
        self.d_A[r, k] = float(np.mean(win["z_back"])) - self.zc
        self.f_m[r, k], self.f_e[r, k], self.g_w[r, k], self.neff_w[r, k] = st["mean"], st["stderr"], st["g"], st["n_eff"]
        fz = np.asarray(win["fz"], float)[int(st["t0"]):]     # the samples the mean uses (after t0)
        if fz.size >= 2:
            self.halves[0, r, k], self.halves[1, r, k] = np.mean(fz[:fz.size // 2]), np.mean(fz[fz.size // 2:])

    # ---- conclude
    def _conclude(self) -> Analysis:
        order = np.argsort(self.d_A[0])
        self.d_A, self.f_m, self.f_e, self.g_w, self.neff_w = (a[:, order] for a in (self.d_A, self.f_m, self.f_e,
                                                                                     self.g_w, self.neff_w))
        self.halves = self.halves[:, :, order]
        self.suffixes = [self.suffixes[i] for i in order]
        self.dsep = self.d_A.mean(axis=0)
        avg = A.registry_average(self.f_m, self.f_e)
        self.fbar, self.ebar = np.asarray(avg["mean"]), np.asarray(avg["stderr"])
        self.estat = np.asarray(avg["stderr_statistical"])
        self._tail_forces()
        self._free_energy()
        self._flat_slab_law()
        self._layer_modulus()
        self._window_checks()
        if self.s.pmf_return:
            P.return_path(self, self.wf.return_chain(self.s))
        self.tail_det.update(tail_energy_last_window_kcal=self.u_tail_last)
        self.details["dispersion_tail"] = self.tail_det
        pmf = self.ti["pmf_J_per_m2"]
        self.curves["pmf"] = (["separation_m", "mean_force_N", "mean_force_stderr_N", "tail_force_N", "pmf_J_per_m2"],
                              np.column_stack([U.angstrom_to_m(self.dsep), U.kcal_per_mol_A_to_N(self.f_tot),
                                               U.kcal_per_mol_A_to_N(self.ebar), U.kcal_per_mol_A_to_N(self.f_tail),
                                               pmf]))
        self.notes += self._pmf_notes()
        self.figures["pmf"] = figure_writer(self._draw_pmf)
        return self._analysis()

    def _tail_forces(self) -> None:
        """Tail force per window (registry 0's frames; the tail hardly depends on the registry) and the tail energy
        left at the last window (the integral of the tail force from there to infinity)."""
        self.f_tail = np.zeros_like(self.fbar)
        self.u_tail_last = 0.0
        if self.tail_on:
            for k, suf in enumerate(self.suffixes):
                tw = self.wf._tail(self.ctx, "trappe", f"pmf_r0_{suf}")
                if len(tw["force_z"]):
                    self.f_tail[k] = float(np.mean(tw["force_z"]))
                    if k == len(self.suffixes) - 1:
                        self.u_tail_last = float(np.mean(tw["energy"]))

    def _free_energy(self) -> None:
        """W_F by force integration from the zero-force point (trapezoid; PCHIP and the grid error beside it) with
        the chained windows' errors correlated (lag-1 from the replicate chains), per registry (each chain an
        independent sample of the whole integral: their Student-t spread bounds the error from below); T dS = dE -
        dF of registry 0, the registry the contact leg's energy belongs to."""
        dsep, ebar, area, conv, w = self.dsep, self.ebar, self.area, self.conv, self.w
        self.f_tot = f_tot = self.fbar + self.f_tail
        self.rho = rho = A.chain_correlation(self.f_m, self.f_e)
        self.ti_cut = A.force_integration_work(dsep, self.fbar, ebar, area, correlation=rho)
        self.ti = ti = A.force_integration_work(dsep, f_tot, ebar, area, correlation=rho)
        self.wf_val = wf = ti["value"] - self.u_tail_last * conv
        self.wf_pchip = ti["value_pchip"] - self.u_tail_last * conv
        wf_err, self.wf_disc = ti["stderr"], ti["discretisation_error"]
        per_reg = [A.force_integration_work(self.d_A[r], self.f_m[r] + self.f_tail, self.f_e[r], area,
                                            correlation=rho) for r in range(self.n_reg)]
        self.w_reg = np.array([p["value"] - self.u_tail_last * conv for p in per_reg])
        self.w_reg_err = np.array([p["stderr"] for p in per_reg])
        if self.n_reg >= 2:
            wf_err = max(wf_err, A.registry_average(self.w_reg, self.w_reg_err)["stderr"])
        self.wf_err = wf_err
        w_e = w["value"] + self.w_tail_static
        # dE/A of every registry with its own zero-load contact (registry 0: the contact leg; the others with
        # registry_contact_steps), each against its own chain's W_F; T dS is their average
        e_reg = {0: (w_e, w["stderr"])} | {int(r): (c["energy_work_J_m2"], c["stderr_J_m2"])
                                           for r, c in self.details.get("registry_contacts", {}).items()}
        self.tds_rec = A.entropic_term(e_reg, {r: (self.w_reg[r], self.w_reg_err[r]) for r in range(self.n_reg)})
        self.tds, self.tds_err = (self.tds_rec["per_registry"][0] if len(self.tds_rec["registries"]) == 1 else
                                  (self.tds_rec["mean"], self.tds_rec["stderr"]))
        self.repulsive = bool(ti["repulsive_end"])
        q, tail_on, n_reg = self.q, self.tail_on, self.n_reg
        q["work_of_adhesion_free_energy"] = quantity_record(
            wf, wf_err, "J/m^2", kind="free energy per area (force integration from the zero-force point of the "
            "registry-averaged mean-force curve, trapezoid rule" + ("; dispersion beyond the cutoff for TraPPE pairs "
                                                                   "included" if tail_on else "") + ")",
            discretisation_error=self.wf_disc, value_pchip=self.wf_pchip, repulsive_end=self.repulsive,
            registry_spread=float(np.std(self.w_reg, ddof=1)) if n_reg >= 2 else 0.0, registries=n_reg)
        regs = self.tds_rec["registries"]
        q["entropic_term_TdS"] = quantity_record(
            self.tds, self.tds_err, "J/m^2", discretisation_error=self.wf_disc,
            kind="T dS / A = (dE - dF) / A of registry 0: dE/A from the zero-load contact leg (registry 0) and W_F of "
                 "registry 0's own chain" if regs == [0] else
                 f"T dS / A = (dE - dF) / A averaged over registries {regs}, each from its own zero-load contact leg "
                 "and its own chain's W_F",
            **({"registry": 0} if regs == [0] else {"registries": regs,
                                                   "per_registry": {str(r): v for r, v in
                                                                    self.tds_rec["per_registry"].items()}}))
        if tail_on:
            q["dispersion_tail_work"] = quantity_record(wf - self.ti_cut["value"], None, "J/m^2",
                                           kind="static dispersion beyond the cutoff for TraPPE pairs, in W_F: "
                                                "tail force integrated over the windows + tail energy left at "
                                                "the last window")

    def _flat_slab_law(self) -> None:
        """z0 and sigma0 from the flat-slab curve (peak traction, Maugis range) and an LJ 9-3 fit beside them."""
        dsep, f_tot, ebar, area, conv, q = self.dsep, self.f_tot, self.ebar, self.area, self.conv, self.q
        zsig: dict[str, Any] = {}
        try:
            pk = A.traction_peak(dsep, f_tot, ebar, area)
            pk_disc = pk["discretisation_error"] if np.isfinite(pk["discretisation_error"]) else 0.0
            rng = A.flat_slab_range(self.wf_val, math.hypot(self.wf_err, self.wf_disc), pk["sigma0"],
                                    math.hypot(pk["stderr"], pk_disc))
            q["peak_traction_sigma0"] = quantity_record(pk["sigma0"], pk["stderr"], "Pa",
                                           kind=f"maximum tensile traction of the flat-slab mean-force curve "
                                                f"({pk['method']}: the vertex of the quadratic through the three "
                                                f"windows around the most attractive one)",
                                           discretisation_error=pk["discretisation_error"],
                                           separation_m=U.angstrom_to_m(pk["separation_A"]))
            q["interaction_range_z0"] = quantity_record(rng["z0"], rng["stderr"], "m",
                                           kind="z0 = 1.026 W_F / sigma0 (Maugis 1992, LJ 9-3 law), from the "
                                                "flat-slab mean-force curve", dugdale_range_h0_m=rng["h0"])
            zsig.update(peak=pk, z0=rng)
        except ValueError as exc:
            zsig["error"] = str(exc)
            self.notes.append(f"z0 and sigma0 not measured: {exc}")
        try:
            fit = A.fit_traction_law(dsep, f_tot, offset=True, force_stderr=ebar)
            zsig["lj93_fit"] = {"z0_A": fit["z0"], "z0_stderr_A": fit["stderr"]["z0"],
                                "w_J_m2": fit["w"] * conv, "w_stderr_J_m2": fit["stderr"]["w"] * conv,
                                "peak_Pa": float(U.kcal_per_mol_A3_to_Pa(fit["peak"] / area)),
                                "offset_A": fit["offset"], "rms_kcal_mol_A": fit["rms"]}
        except (ValueError, RuntimeError) as exc:
            zsig["lj93_fit"] = {"error": str(exc)}
        self.details["flat_slab_law"] = zsig

    def _layer_modulus(self) -> None:
        """The SAM layers' confined modulus from the compression branch (windows pressed into the contact, below the
        zero crossing) of the mean-force curve with its tail (:func:`md.analysis.confined_layer_modulus`); the
        thickness is the builder's (chain length and tilt) of every SAM between the backs. Pairs without a SAM:
        nothing."""
        try:
            t, n_layers = A.sam_layer_thickness_A(self.info)
        except ValueError:
            return
        try:
            lm = A.confined_layer_modulus(self.dsep, self.f_tot, self.ebar, self.area, t)
        except ValueError as exc:
            self.notes.append(f"SAM layer modulus not measured: {exc}")
            self.details["sam_layer_modulus"] = {"error": str(exc)}
            return
        self.q["sam_layer_modulus"] = quantity_record(
            lm["modulus_Pa"], lm["stderr_Pa"], "Pa",
            kind=f"confined (uniaxial-strain) modulus of the SAM layer{'s' if n_layers > 1 else ''} between the "
                 f"backs: -t d sigma / d d over the {lm['windows']} repulsive windows pressed into the contact, "
                 f"t = {t:.1f} A ({n_layers} SAM{'s' if n_layers > 1 else ''}, the builder's thickness); the "
                 "slabs' and the interface's compliance counted as the layers'",
            thickness_m=U.angstrom_to_m(t), layers=n_layers, windows=lm["windows"], strain_max=lm["strain_max"])
        self.details["sam_layer_modulus"] = lm
        if lm["note"]:
            self.notes.append(f"SAM layer modulus: {lm['note']}.")

    def _window_checks(self) -> None:
        """Windows with few independent samples, registries that disagree beyond their stderrs, the window-length
        check (W_F from the halves), and the per-window record."""
        suffixes, s = self.suffixes, self.s
        self.short = [suffixes[k] for k in range(len(suffixes)) if np.nanmin(self.neff_w[:, k]) < MIN_WINDOW_NEFF]
        cons = A.registry_consistency(self.f_m, self.f_e)
        disagree = [suffixes[k] for k in np.flatnonzero(cons["inconsistent"])]
        if disagree:
            self.notes.append(
                f"registries disagree beyond their own stderrs (chi^2 p < 0.01) at {len(disagree)} of {len(suffixes)} "
                f"windows ({', '.join(disagree)}; chi^2/dof up to {np.nanmax(cons['chi2_per_dof']):.3g}): there the "
                "force depends on the registry or a window is too short for its mean, and the registries' spread, "
                "not a window's own stderr, is its error (W_F's stderr takes the larger per window)")
        self.details["pmf_windows"] = {
            "separation_A": self.dsep.tolist(), "mean_force_kcal_mol_A": self.fbar.tolist(),
            "stderr_kcal_mol_A": self.ebar.tolist(), "tail_force_kcal_mol_A": self.f_tail.tolist(), "window": suffixes,
            "per_registry_mean_force_kcal_mol_A": self.f_m.tolist(), "per_registry_stderr_kcal_mol_A": self.f_e.tolist(),
            "statistical_inefficiency": self.g_w.tolist(), "n_eff": self.neff_w.tolist(),
            "decorrelation_time_ps": ((self.g_w - 1) / 2 * s.sample_interval * self.dt * 1e-3).tolist(),
            "registry_work_J_m2": self.w_reg.tolist(), "registry_offsets_A": self.info["registry_offsets_A"],
            "zero_force_separation_A": self.ti["zero_force_separation_A"], "repulsive_end": self.repulsive,
            "windows_with_few_samples": self.short, "cutoff_only_work_J_m2": self.ti_cut["value"],
            "registry_chi2_per_dof": cons["chi2_per_dof"].tolist(), "registries_disagree": disagree,
            "statistical_stderr_kcal_mol_A": self.estat.tolist(), "chain_correlation_lag1": self.rho,
            "registry_work_stderr_J_m2": self.w_reg_err.tolist(),
            "t_factor": A.student_t_factor(self.n_reg) if self.n_reg >= 2 else 1.0,
            "interval_grid_bound_J_m2": self.ti["interval_bounds_J_per_m2"].tolist(),
            "refine_intervals_A": self.ti["refine_intervals_A"], "grid_bound_max_J_m2": self.ti["grid_bound_max"],
            "quadrature_difference_J_m2": self.ti["quadrature_difference"]}
        # tolerance from the windows' within-registry statistical stderrs only: a registry's offset cancels in the
        # difference of its halves, so the registries' spread must not widen it
        first, second = (np.nanmean(h, axis=0) + self.f_tail for h in self.halves)
        wl = A.window_length_check(self.dsep, first, second, self.estat, self.area, correlation=self.rho)
        self.w_half = [wl["first_half_J_m2"] - self.u_tail_last * self.conv,
                       wl["second_half_J_m2"] - self.u_tail_last * self.conv]
        self.half_diff, self.half_err, self.half_ok = wl["difference_J_m2"], wl["difference_stderr_J_m2"], wl["converged"]
        self.details["window_length_check"] = {
            "first_half_J_m2": self.w_half[0], "second_half_J_m2": self.w_half[1], "whole_J_m2": self.wf_val,
            "difference_J_m2": self.half_diff, "difference_stderr_J_m2": self.half_err, "converged": self.half_ok,
            "what": "W_F from the first and the second half of every window's equilibrated samples (after the detected "
                    "start, as W_F itself; same grid, tail, registries): a drift between them means the windows are "
                    "too short for the force to settle. Tolerance: 2 x the difference's stderr from the windows' "
                    "within-registry statistical stderrs (the registries' spread cancels in the difference)"}

    def _pmf_notes(self) -> list[str]:
        dsep, wf, wf_err, n_reg, s = self.dsep, self.wf_val, self.wf_err, self.n_reg, self.s
        half_diff, half_err, w_half = self.half_diff, self.half_err, self.w_half
        notes = [
            f"free energy of separation from {len(self.suffixes)} windows x {n_reg} lateral registr"
            f"{'y' if n_reg == 1 else 'ies'} ({dsep[0]:+.2f} to {dsep[-1]:.2f} A from the contact leg's mean back "
            f"height {self.zc:.2f} A; chains: each window continues from its neighbour): dF/A = {wf:.4f} +/- "
            f"{wf_err:.4f} J/m^2 (trapezoid from the zero-force point {self.ti['zero_force_separation_A']:+.2f} A; "
            f"PCHIP gives {self.wf_pchip:.4f}, grid error {self.wf_disc:.4f}: the larger of the two quadratures' "
            f"difference and the largest interval bound 1/2 |df| dd over the detachment region); T dS/A of "
            f"registr{'y' if len(self.tds_rec['registries']) == 1 else 'ies'} "
            f"{', '.join(map(str, self.tds_rec['registries']))} (each zero-load contact's dE against its own "
            f"chain's W_F) = {self.tds:.4f} +/- {self.tds_err:.4f} J/m^2. "
            f"The stderr is statistical with the chained windows' errors correlated (lag-1 rho = {self.rho:.2f} from "
            f"the replicate chains), and at least the registries' spread of W_F times the Student-t factor of "
            f"{n_reg} registries; the discretisation error is given beside it."]
        if self.ti["refine_intervals_A"]:
            notes.append("windows too sparse: between " + ", ".join(f"{a:+.2f} and {b:+.2f} A" for a, b in
                                                                     self.ti["refine_intervals_A"])
                         + " the mean force changes by more than half the peak attraction in one interval (a "
                           "rupture the grid does not resolve); add windows there.")
        if not self.repulsive:
            notes.append("NO REPULSIVE END: no window before the most attractive one has a repulsive mean force, so "
                         "the bottom of the adhesive well lies inside the innermost window and W_F is a lower bound: "
                         "raise pmf_compress_A.")
        if self.short:
            notes.append(f"windows with fewer than {MIN_WINDOW_NEFF} effectively independent samples: {self.short} "
                         f"(lengthen pmf_sample_steps).")
        notes.append(f"window length: W_F from the first half of every window {w_half[0]:.4f}, from the second half "
                     f"{w_half[1]:.4f} J/m^2 (difference {half_diff:+.4f} +/- {half_err:.4f}: "
                     + ("within 2 stderr" if self.half_ok else
                        "MORE THAN 2 STDERR: the windows are too short for the mean force to settle; lengthen "
                        "pmf_sample_steps") + ").")
        if self.tail_on:
            notes.append(f"dispersion beyond the {s.cutoff_A:g} A cutoff for TraPPE pairs (any pair with a CH2/CH3 "
                         f"united atom) added as a static correction measured on this run's frames: "
                         f"{wf - self.ti_cut['value']:+.4f} J/m^2 in W_F (tail force per window + tail energy left at "
                         f"the last window), {self.w_tail_static:+.4f} J/m^2 in dE/A (contact frames). IFF pairs keep "
                         f"the plain cutoff IFF was parametrised with.")
        return notes

    def _draw_pmf(self, ax) -> None:
        for r in range(self.n_reg):
            ax.plot(self.d_A[r], self.f_m[r], ".", ms=3, alpha=0.6, label=f"registry {r}")
        ax.errorbar(self.dsep, self.f_tot, yerr=self.ebar, marker="o", ms=3, lw=1, color="k", label="mean (+ tail)")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("separation from contact (Å)")
        ax.set_ylabel("mean force on upper slab (kcal/mol/Å)")
        ax.set_title(f"dF/A = {self.wf_val:.3f} ± {self.wf_err:.3f} (stat.) ± {self.wf_disc:.3f} (grid) J/m²")
        ax.legend(fontsize=7)


class _AdhesionLegs:
    """The legs of an adhesion run (:meth:`Adhesion.plan`): the two slabs are built and written on construction;
    :meth:`contact` (upper back one rigid body, free along z at zero load), :meth:`separated` (both backs held,
    ``separation_A`` apart) and, for the free energy, :meth:`windows` (chains of force windows per registry)."""

    def __init__(self, wf: Adhesion, s, run_dir: Path):
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
        self.base = dict(define=None, restart_head=restart_header_lines(s),
                         columns={"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_back": "v_zback"},
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
                "variable zback equal xcm(upper_back,z)"]
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
