"""The analysis of an adhesion run (md.workflows.adhesion.Adhesion.analyse): dE/A, the static dispersion tail, the
free energy by force integration over the window chains, the flat-slab law (sigma0, z0 from the same W_F the result
reports), the SAM layer's moduli and Poisson ratio, the window checks, notes, curves and figures."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from md import analysis as A
from md import units as U
from md.build.sam import chain_geometry
from md.engine.plan import Analysis
from md.workflows import adhesion_protocol as P
from md.workflows.adhesion_legs import MIN_WINDOW_NEFF, SAM_STRESS_COLUMNS, TAIL_R_MAX_A
from md.workflows.common import ENERGY_NOT_FREE_ENERGY, Workflow, figure_writer, quantity_record


class _AdhesionAnalysis:
    """dE/A from the contact and separated legs and, with ``free_energy = "pmf"``, the free energy from the force
    windows, in the MDAnalysis manner: :meth:`_prepare` (the energy route, the static dispersion tail, the cutoff
    study), :meth:`_single_window` for every window of every registry, :meth:`_conclude` (registry average, force
    integration, z0 and sigma0, the window checks, notes, curves and figures)."""

    def __init__(self, wf: Workflow, ctx):
        self.wf, self.ctx, self.s, self.info = wf, ctx, ctx.settings, ctx.plan.system_info

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
        # with sam_stress: the SAM atoms' summed xx, yy, zz stress per window (mean and stderr)
        self.sam_sig, self.sam_sig_e = np.full((3,) + shape, np.nan), np.full((3,) + shape, np.nan)
        for r in range(self.n_reg):
            for k, suf in enumerate(self.suffixes):
                self._single_window(r, k, suf)
        return self._conclude()

    def _analysis(self) -> Analysis:
        return Analysis(quantities=self.q, curves=self.curves, figures=self.figures, notes=self.notes,
                        details=self.details)

    # ---- prepare: the energy route and the static tail
    def _prepare(self) -> None:
        ctx, info = self.ctx, self.info
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
        self.f_m[r, k], self.f_e[r, k], self.g_w[r, k], self.neff_w[r, k] = (st["mean"], st["stderr"], st["g"],
                                                                             st["n_eff"])
        if SAM_STRESS_COLUMNS[0] in win:
            for c, col in enumerate(SAM_STRESS_COLUMNS):
                ss = A.timeseries_stats(win[col])
                self.sam_sig[c, r, k], self.sam_sig_e[c, r, k] = ss["mean"], ss["stderr"]
        fz = np.asarray(win["fz"], float)[int(st["t0"]):]     # the samples the mean uses (after t0)
        if fz.size >= 2:
            self.halves[0, r, k], self.halves[1, r, k] = np.mean(fz[:fz.size // 2]), np.mean(fz[fz.size // 2:])

    # ---- conclude
    def _conclude(self) -> Analysis:
        order = np.argsort(self.d_A[0])
        self.d_A, self.f_m, self.f_e, self.g_w, self.neff_w = (a[:, order] for a in (self.d_A, self.f_m, self.f_e,
                                                                                     self.g_w, self.neff_w))
        self.halves = self.halves[:, :, order]
        self.sam_sig, self.sam_sig_e = self.sam_sig[:, :, order], self.sam_sig_e[:, :, order]
        self.suffixes = [self.suffixes[i] for i in order]
        self.dsep = self.d_A.mean(axis=0)
        avg = A.registry_average(self.f_m, self.f_e)
        self.fbar, self.ebar = np.asarray(avg["mean"]), np.asarray(avg["stderr"])
        self.estat = np.asarray(avg["stderr_statistical"])
        self._tail_forces()
        self._free_energy()
        self._layer_modulus()
        self._window_checks()
        if self.s.pmf_return:
            P.return_path(self, self.wf.return_chain(self.s))
        self._flat_slab_law()
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
        e_check = A.registry_consistency(np.array([[v[0]] for v in e_reg.values()]),
                                         np.array([[v[1]] for v in e_reg.values()])) if len(e_reg) >= 2 else None
        self.energy_registries_agree = e_check is None or not bool(np.asarray(e_check["inconsistent"])[0])
        if not self.energy_registries_agree:
            self.notes.append("dE/A and T dS NOT CONVERGED: the registries' own dE/A (each zero-load contact) disagree "
                              "beyond their stderrs (chi^2 p < 0.01); their mean is no converged number")
        q["entropic_term_TdS"] = quantity_record(
            self.tds, self.tds_err, "J/m^2", discretisation_error=self.wf_disc,
            kind="T dS / A = (dE - dF) / A of registry 0: dE/A from the zero-load contact leg (registry 0) and W_F of "
                 "registry 0's own chain" if regs == [0] else
                 f"T dS / A = (dE - dF) / A averaged over registries {regs}, each from its own zero-load contact leg "
                 "and its own chain's W_F",
            converged=self.energy_registries_agree,
            **({"registry": 0} if regs == [0] else {"registries": regs,
                                                   "per_registry": {str(r): v for r, v in
                                                                    self.tds_rec["per_registry"].items()}}))
        if tail_on:
            q["dispersion_tail_work"] = quantity_record(wf - self.ti_cut["value"], None, "J/m^2",
                                           kind="static dispersion beyond the cutoff for TraPPE pairs, in W_F: "
                                                "tail force integrated over the windows + tail energy left at "
                                                "the last window")

    def _flat_slab_law(self) -> None:
        """z0 and sigma0 from the flat-slab curve (peak traction, Maugis range) and an LJ 9-3 fit beside them. z0 =
        1.026 W_F / sigma0 takes the W_F the result reports (with a return chain: the out/back mean, its error with
        half the hysteresis), the same W the continuum's dgamma is, so that its Maugis-Dugdale stress 1.03 dgamma /
        z0 is the measured sigma0 (sigma0 itself from the outward curve)."""
        dsep, f_tot, ebar, area, conv, q = self.dsep, self.f_tot, self.ebar, self.area, self.conv, self.q
        zsig: dict[str, Any] = {}
        rec = q["work_of_adhesion_free_energy"]
        w_used = float(rec["value"])
        w_err = math.hypot(float(rec["stderr"]), self.wf_disc, float(rec.get("systematic_hysteresis") or 0.0))
        try:
            pk = A.traction_peak(dsep, f_tot, ebar, area)
            pk_disc = pk["discretisation_error"] if np.isfinite(pk["discretisation_error"]) else 0.0
            rng = A.flat_slab_range(w_used, w_err, pk["sigma0"], math.hypot(pk["stderr"], pk_disc))
            q["peak_traction_sigma0"] = quantity_record(pk["sigma0"], pk["stderr"], "Pa",
                                           kind=f"maximum tensile traction of the flat-slab mean-force curve "
                                                f"({pk['method']}: the vertex of the quadratic through the three "
                                                f"windows around the most attractive one)",
                                           discretisation_error=pk["discretisation_error"],
                                           separation_m=U.angstrom_to_m(pk["separation_A"]))
            q["interaction_range_z0"] = quantity_record(rng["z0"], rng["stderr"], "m",
                                           kind="z0 = 1.026 W_F / sigma0 (Maugis 1992, LJ 9-3 law), from the "
                                                "flat-slab mean-force curve, W_F the value this result reports",
                                           dugdale_range_h0_m=rng["h0"], work_of_adhesion_used=w_used)
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
        self._small_strain_modulus()
        self._layer_poisson()
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

    def _small_strain_modulus(self) -> None:
        """The tangent confined modulus at the zero-force point, normalised by the annealed thickness (the anneal's
        mean tilt, the builder's chain at that tilt): what a contact at small load sees (md.analysis.
        small_strain_layer_record). Fewer than four repulsive windows: a note, nothing else."""
        tilt = A.tilt_of_anneal((self.details.get("anneal") or {}).get("mean_tilt_deg") or [])
        n = int(self.s.chain_length)
        try:
            rec = A.small_strain_layer_record(self.dsep, self.f_tot, self.ebar, self.area, self.info, tilt,
                                              lambda th: float(chain_geometry(n, th)[0][-1][2]))
        except ValueError as exc:
            self.notes.append(f"SAM small-strain modulus not measured: {exc}")
            return
        tg = rec["tangent"]
        self.q["sam_layer_tangent_modulus"] = quantity_record(
            rec["modulus_Pa"], rec["stderr_Pa"], "Pa",
            kind=f"confined modulus of the SAM stack at small strain: the tangent at the zero-force point of a "
                 f"weighted quadratic through the {tg['windows']} repulsive windows, t = {rec['thickness_A']:.1f} A "
                 f"({rec['thickness_source']}); stderr: fit and thickness", thickness_m=rec["thickness_A"] * 1e-10,
            thickness_stderr_m=rec["thickness_stderr_A"] * 1e-10, thickness_per_layer_m=rec["thickness_per_layer_m"],
            layers=rec["layers"], chord_modulus_Pa=tg["chord_modulus_Pa"],
            curvature_delta_chi2=tg["curvature_delta_chi2"], windows=tg["windows"], strain_max=tg["strain_max"])
        self.details["sam_layer_tangent_modulus"] = {k: v for k, v in rec.items() if k != "tangent"} | {"tangent": tg}

    def _layer_poisson(self) -> None:
        """With ``sam_stress``: the SAM stack's C13/C33 and Poisson ratio from its own stress in the compression
        windows (the repulsive windows below the first zero crossing of the mean force with its tail, as the
        modulus; registry-averaged lateral (xx + yy)/2 and normal zz stress, md.analysis.stress_ratio_poisson).
        Without the columns: nothing."""
        if not np.isfinite(self.sam_sig).any():
            return
        attractive = np.flatnonzero(self.f_tot <= 0.0)
        sel = np.arange(self.dsep.size) < (attractive[0] if attractive.size else self.dsep.size)
        if sel.sum() < 3:
            self.notes.append(f"SAM Poisson ratio not measured: {int(sel.sum())} compression windows (needs three)")
            return
        vol = self.area * A.sam_layer_thickness_A(self.info)[0]          # A^3: stress x volume -> stress
        to_pa = lambda a: U.atm_to_Pa(np.asarray(a, float)) / vol
        avg = [A.registry_average(self.sam_sig[c][:, sel], self.sam_sig_e[c][:, sel]) for c in range(3)]
        lat = 0.5 * (np.asarray(avg[0]["mean"]) + np.asarray(avg[1]["mean"]))
        lat_e = 0.5 * np.hypot(avg[0]["stderr"], avg[1]["stderr"])
        try:
            pr = A.stress_ratio_poisson(self.dsep[sel], to_pa(lat), to_pa(avg[2]["mean"]), to_pa(lat_e),
                                        to_pa(avg[2]["stderr"]))
        except ValueError as exc:
            self.notes.append(f"SAM Poisson ratio not measured: {exc}")
            return
        self.q["sam_poisson_ratio"] = quantity_record(
            pr["poisson_ratio"], pr["poisson_ratio_stderr"], "",
            kind="Poisson ratio of the isotropic layer with the SAM stack's measured C13/C33 = nu / (1 - nu), from "
                 "the SAM atoms' own stress tensor in the compression windows (uniaxial strain)",
            c13_over_c33=pr["c13_over_c33"], c13_over_c33_stderr=pr["c13_over_c33_stderr"], windows=pr["windows"])
        self.details["sam_poisson_ratio"] = pr

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
            "per_registry_mean_force_kcal_mol_A": self.f_m.tolist(),
            "per_registry_stderr_kcal_mol_A": self.f_e.tolist(),
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
        self.half_diff, self.half_err, self.half_ok = (wl["difference_J_m2"], wl["difference_stderr_J_m2"],
                                                       wl["converged"])
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

