"""The analysis of an adhesion run (md.workflows.adhesion.Adhesion.analyse): dE/A, the static dispersion tail, the
free energy by force integration over the window chains, the flat-slab law (sigma0, z0 from the same W_F the result
reports), the SAM layer's moduli and Poisson ratio, the window checks, notes, curves and figures."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from md import analysis as A
from md import units as U
from md.build.sam import chain_geometry
from md.engine.plan import Analysis
from md.workflows import adhesion_protocol as P
from md.workflows.adhesion_legs import MIN_WINDOW_NEFF, SAM_STRESS_COLUMNS, TAIL_R_MAX_A
from md.workflows.common import ENERGY_NOT_FREE_ENERGY, Workflow, figure_writer, quantity_record
from md.workflows.plan_records import AdhesionPlanRecord


@dataclass(slots=True)
class _AdhesionResults:
    """What :class:`_AdhesionAnalysis` computes, in one place, filled in as :meth:`~_AdhesionAnalysis.run` goes: the
    energy route and the static tail (:meth:`~_AdhesionAnalysis._prepare`), the per-window arrays (registry x
    window: separation, mean force, stderr, inefficiency, effective samples, halves, SAM stress), the force
    integration and its checks, and the :class:`~md.engine.plan.Analysis` parts (``q`` the quantities, curves,
    figures, notes, details). Slotted: a name not declared here cannot be set."""
    # the energy route and the static tail (_prepare)
    area: float | None = None                  # interface area (A^2)
    conv: float | None = None                  # kcal/mol -> J/m^2 over this interface
    w: dict[str, Any] = field(default_factory=dict)          # dE/A (energy_separation_work)
    notes: list[str] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)
    zc: float | None = None                    # the contact leg's mean upper-back z (A)
    q: dict[str, Any] = field(default_factory=dict)          # the quantities
    tail_on: bool | None = None
    w_tail_static: float | None = None         # the static dispersion tail on dE/A (J/m^2)
    tail_det: dict[str, Any] = field(default_factory=dict)
    curves: dict[str, Any] = field(default_factory=dict)
    figures: dict[str, Any] = field(default_factory=dict)
    dt: float | None = None                    # fs
    all_con: dict[str, np.ndarray] | None = None             # every sample of the contact leg
    all_sep: dict[str, np.ndarray] | None = None             # every sample of the separated leg
    # per window, registry x window (run): separation (A), mean force, stderr, inefficiency, effective samples
    suffixes: list[str] = field(default_factory=list)
    n_reg: int | None = None
    d_A: np.ndarray | None = None
    f_m: np.ndarray | None = None
    f_e: np.ndarray | None = None
    g_w: np.ndarray | None = None
    neff_w: np.ndarray | None = None
    halves: np.ndarray | None = None           # (2, registry, window): the two halves' mean forces
    sam_sig: np.ndarray | None = None          # (3, registry, window): the SAM's summed xx, yy, zz stress
    sam_sig_e: np.ndarray | None = None
    # the registry average and the force integration (_conclude)
    dsep: np.ndarray | None = None             # mean separation per window (A)
    fbar: np.ndarray | None = None             # registry-averaged mean force (kcal/mol/A)
    ebar: np.ndarray | None = None             # its stderr
    estat: np.ndarray | None = None            # its statistical part
    f_tail: np.ndarray | None = None           # the dispersion tail's force per window
    u_tail_last: float | None = None           # the tail energy left at the last window (kcal/mol)
    f_tot: np.ndarray | None = None            # fbar + f_tail
    rho: float | None = None                   # the chained windows' lag-1 error correlation
    ti_cut: dict[str, Any] | None = None       # force integration without the tail
    ti: dict[str, Any] | None = None           # force integration with it
    wf_val: float | None = None                # W_F (J/m^2)
    wf_pchip: float | None = None
    wf_disc: float | None = None               # its grid error
    w_reg: np.ndarray | None = None            # W_F per registry
    w_reg_err: np.ndarray | None = None
    wf_err: float | None = None
    tds_rec: dict[str, Any] | None = None      # T dS (entropic_term)
    tds: float | None = None
    tds_err: float | None = None
    repulsive: bool | None = None              # the mean force is repulsive at the grid's inner end
    energy_registries_agree: bool | None = None
    # the window checks
    short: list[str] = field(default_factory=list)           # windows with too few effective samples
    w_half: list[float] = field(default_factory=list)        # W_F from the first and the second halves
    half_diff: float | None = None
    half_err: float | None = None
    half_ok: bool | None = None


class _AdhesionAnalysis:
    """dE/A from the contact and separated legs and, with ``free_energy = "pmf"``, the free energy from the force
    windows, in the MDAnalysis manner: :meth:`_prepare` (the energy route, the static dispersion tail, the cutoff
    study), :meth:`_single_window` for every window of every registry, :meth:`_conclude` (registry average, force
    integration, z0 and sigma0, the window checks, notes, curves and figures)."""

    def __init__(self, wf: Workflow, ctx):
        self.wf, self.ctx, self.s = wf, ctx, ctx.settings
        self.plan = AdhesionPlanRecord.from_system(ctx.plan.system_info)
        self.results = _AdhesionResults()

    def run(self) -> Analysis:
        res = self.results
        self._prepare()
        self._protocol_legs()
        if self.s.free_energy != "pmf":
            res.notes.append("free energy not estimated at this fidelity (free_energy = 'none'); the quick and "
                             "production recipes integrate the mean force over separation to measure T dS.")
            res.details["dispersion_tail"] = res.tail_det
            return self._analysis()
        res.suffixes = [c[0] for c in self.wf.chains(self.s)]
        res.n_reg = len(self.plan.registry_offsets_A)
        shape = (res.n_reg, len(res.suffixes))
        res.d_A, res.f_m, res.f_e, res.g_w, res.neff_w = (np.full(shape, np.nan) for _ in range(5))
        # mean force of the first and the second half of each window's equilibrated samples (those after the
        # detected start t0, as the mean itself)
        res.halves = np.full((2,) + shape, np.nan)
        # with sam_stress: the SAM atoms' summed xx, yy, zz stress per window (mean and stderr)
        res.sam_sig, res.sam_sig_e = np.full((3,) + shape, np.nan), np.full((3,) + shape, np.nan)
        for r in range(res.n_reg):
            for k, suf in enumerate(res.suffixes):
                self._single_window(r, k, suf)
        return self._conclude()

    def _analysis(self) -> Analysis:
        res = self.results
        return Analysis(quantities=res.q, curves=res.curves, figures=res.figures, notes=res.notes,
                        details=res.details)

    # ---- prepare: the energy route and the static tail
    def _prepare(self) -> None:
        res = self.results
        ctx = self.ctx
        res.area = area = self.plan.area_A2
        res.conv = U.kcal_per_mol_A2_to_J_per_m2(1.0) / area           # kcal/mol -> J/m^2 over this interface
        con, sep = ctx.samples("contact"), ctx.samples("separated")
        res.w = w = A.energy_separation_work(con["pe"], sep["pe"], area)
        res.notes = [ENERGY_NOT_FREE_ENERGY,
                     "every mean and stderr comes from the statistical inefficiency with automated equilibration "
                     "detection (Chodera, J. Chem. Theory Comput. 12 (2016) 1799; md.analysis.timeseries_stats)."]
        res.details: dict[str, Any] = {"energy": {k: v for k, v in w.items() if k not in ("value", "stderr", "units")}}
        zs = A.timeseries_stats(con["z_back"])
        res.zc = zs["mean"]
        res.details["contact_back_z_A"] = {"mean": res.zc, "stderr": zs["stderr"], "g": zs["g"]}
        self._static_tail()
        tail_on = res.tail_on
        res.q = {"work_of_adhesion": quantity_record(w["value"] + res.w_tail_static, w["stderr"], "J/m^2",
                                         kind="energy per area (not a free energy)" + (
                                             "; dispersion beyond the cutoff for TraPPE pairs included (static)"
                                             if tail_on else "")),
                 "interface_area": quantity_record(U.angstrom_to_m(U.angstrom_to_m(area)), 0.0, "m^2")}
        res.details["energy"]["cutoff_only_J_m2"] = w["value"]
        self._energy_curves()

    def _static_tail(self) -> None:
        """Dispersion beyond the cutoff, static, on the contact leg's frames; and the cutoff study on its last frame
        (explicit sum to 20/30/40 A + smeared beyond; the TraPPE pairs, applied, and every pair, IFF included:
        reported, not applied)."""
        res = self.results
        ctx, s, conv = self.ctx, self.s, res.conv
        res.tail_on = tail_on = self.plan.tail_applies
        res.w_tail_static, res.tail_det = 0.0, {"mode": s.dispersion_tail, "applied": tail_on}
        if tail_on:
            tc = self.wf._tail(ctx, self.plan.n_lower, "trappe", "contact")
            u = tc["energy"]
            kt = U.kT_kcal_per_mol(s.temperature_K)
            res.w_tail_static = -float(np.mean(u)) * conv
            # second-order check: the free-energy perturbation -kT ln <exp(-U/kT)> against the mean
            fep = -kt * (np.log(np.mean(np.exp(-(u - u.min()) / kt))) - u.min() / kt) if len(u) else float("nan")
            res.tail_det.update(contact_energy_kcal=u.tolist(), static_work_J_m2=res.w_tail_static,
                                fep_minus_mean_J_m2=float(-(fep - np.mean(u)) * conv) if len(u) else None,
                                r_max_A=TAIL_R_MAX_A, pairs_per_frame=tc["pairs"])
        if self.plan.tail_study and len(ctx.frames("contact")[0]):
            st, ids, pos, box = ctx.frames("contact")
            last = (st[-1:], ids, pos[-1:], box[-1:])
            study = {}
            for mode in ("trappe", "all"):
                for rm in (20.0, 30.0, 40.0):
                    e = self.wf._tail(ctx, self.plan.n_lower, mode, "contact", rm, frames=last)["energy"]
                    study[f"{mode}_{rm:g}A_J_m2"] = -float(e[0]) * conv
            res.tail_det["cutoff_study_last_contact_frame"] = study

    def _energy_curves(self) -> None:
        res = self.results
        res.curves: dict[str, tuple[list[str], np.ndarray]] = {}
        res.figures = {}
        res.dt = dt = self.ctx.plan.timestep_fs
        res.all_con, res.all_sep = self.ctx.samples("contact", False), self.ctx.samples("separated", False)
        for name, d in (("energy_contact", res.all_con), ("energy_separated", res.all_sep)):
            res.curves[name] = (["step", "time_s", "stage", "potential_energy_J", "temperature_K"],
                                np.column_stack([d["step"], U.fs_to_s(d["step"] * dt), d["stage"],
                                                  U.kcal_per_mol_to_J(d["pe"]), d["temp"]]))
        res.figures["energy_timeseries"] = figure_writer(self._draw_energy)

    def _draw_energy(self, ax) -> None:
        res = self.results
        w, dt = res.w, res.dt
        for d, lab in ((res.all_con, "contact"), (res.all_sep, "separated")):
            ax.plot(d["step"] * dt * 1e-3, d["pe"], lw=0.8, label=lab)
        ax.set_xlabel("time (ps)")
        ax.set_ylabel("potential energy (kcal/mol)")
        ax.set_title(f"W = {w['value']:.3f} ± {w['stderr']:.3f} J/m² (energy)")
        ax.legend()

    def _protocol_legs(self) -> None:
        """The optional legs (md.workflows.adhesion_protocol): the SAM anneal, each registry's own contact, and a
        note on registries that repeat another."""
        res = self.results
        names = {leg.name for leg in self.ctx.plan.legs}
        if "anneal" in names:
            det, notes, curves = P.anneal_record(self.ctx, res.dt)
            res.details["anneal"], res.notes, res.curves = det, res.notes + notes, {**res.curves, **curves}
            res.figures["anneal"] = figure_writer(lambda ax: P.draw_anneal(ax, det))
        if any(n.startswith("contact_r") for n in names):
            res.details["registry_contacts"] = P.registry_contacts_record(
                self.ctx, self.ctx.samples("separated")["pe"], res.area, res.zc, res.w_tail_static)
        if self.s.free_energy == "pmf":
            res.notes += P.degenerate_note(self.plan)

    # ---- per window
    def _single_window(self, r: int, k: int, suf: str) -> None:
        """Window ``suf`` of registry ``r``: measured separation, mean force with its stderr, statistical
        inefficiency, and the mean forces of the two halves of the samples the mean uses."""
        res = self.results
        win = self.ctx.samples(f"pmf_r{r}_{suf}")           # one read of the window's samples
        st = A.timeseries_stats(win["fz"])
        res.d_A[r, k] = float(np.mean(win["z_back"])) - res.zc
        res.f_m[r, k], res.f_e[r, k], res.g_w[r, k], res.neff_w[r, k] = (st["mean"], st["stderr"], st["g"],
                                                                         st["n_eff"])
        if SAM_STRESS_COLUMNS[0] in win:
            for c, col in enumerate(SAM_STRESS_COLUMNS):
                ss = A.timeseries_stats(win[col])
                res.sam_sig[c, r, k], res.sam_sig_e[c, r, k] = ss["mean"], ss["stderr"]
        fz = np.asarray(win["fz"], float)[int(st["t0"]):]     # the samples the mean uses (after t0)
        if fz.size >= 2:
            res.halves[0, r, k], res.halves[1, r, k] = np.mean(fz[:fz.size // 2]), np.mean(fz[fz.size // 2:])

    # ---- conclude
    def _conclude(self) -> Analysis:
        res = self.results
        order = np.argsort(res.d_A[0])
        res.d_A, res.f_m, res.f_e, res.g_w, res.neff_w = (a[:, order] for a in (res.d_A, res.f_m, res.f_e,
                                                                                res.g_w, res.neff_w))
        res.halves = res.halves[:, :, order]
        res.sam_sig, res.sam_sig_e = res.sam_sig[:, :, order], res.sam_sig_e[:, :, order]
        res.suffixes = [res.suffixes[i] for i in order]
        res.dsep = res.d_A.mean(axis=0)
        avg = A.registry_average(res.f_m, res.f_e)
        res.fbar, res.ebar = np.asarray(avg["mean"]), np.asarray(avg["stderr"])
        res.estat = np.asarray(avg["stderr_statistical"])
        self._tail_forces()
        self._free_energy()
        self._layer_modulus()
        self._window_checks()
        if self.s.pmf_return:
            P.return_path(self.ctx, self.results, self.wf.return_chain(self.s))
        self._flat_slab_law()
        res.tail_det.update(tail_energy_last_window_kcal=res.u_tail_last)
        res.details["dispersion_tail"] = res.tail_det
        pmf = res.ti["pmf_J_per_m2"]
        res.curves["pmf"] = (["separation_m", "mean_force_N", "mean_force_stderr_N", "tail_force_N", "pmf_J_per_m2"],
                             np.column_stack([U.angstrom_to_m(res.dsep), U.kcal_per_mol_A_to_N(res.f_tot),
                                               U.kcal_per_mol_A_to_N(res.ebar), U.kcal_per_mol_A_to_N(res.f_tail),
                                               pmf]))
        res.notes += self._pmf_notes()
        res.figures["pmf"] = figure_writer(self._draw_pmf)
        return self._analysis()

    def _tail_forces(self) -> None:
        """Tail force per window (registry 0's frames; the tail hardly depends on the registry) and the tail energy
        left at the last window (the integral of the tail force from there to infinity)."""
        res = self.results
        res.f_tail = np.zeros_like(res.fbar)
        res.u_tail_last = 0.0
        if res.tail_on:
            for k, suf in enumerate(res.suffixes):
                tw = self.wf._tail(self.ctx, self.plan.n_lower, "trappe", f"pmf_r0_{suf}")
                if len(tw["force_z"]):
                    res.f_tail[k] = float(np.mean(tw["force_z"]))
                    if k == len(res.suffixes) - 1:
                        res.u_tail_last = float(np.mean(tw["energy"]))

    def _free_energy(self) -> None:
        """W_F by force integration from the zero-force point (trapezoid; PCHIP and the grid error beside it) with
        the chained windows' errors correlated (lag-1 from the replicate chains), per registry (each chain an
        independent sample of the whole integral: their Student-t spread bounds the error from below); T dS = dE -
        dF of registry 0, the registry the contact leg's energy belongs to."""
        res = self.results
        dsep, ebar, area, conv, w = res.dsep, res.ebar, res.area, res.conv, res.w
        res.f_tot = f_tot = res.fbar + res.f_tail
        res.rho = rho = A.chain_correlation(res.f_m, res.f_e)
        res.ti_cut = A.force_integration_work(dsep, res.fbar, ebar, area, correlation=rho)
        res.ti = ti = A.force_integration_work(dsep, f_tot, ebar, area, correlation=rho)
        res.wf_val = wf = ti["value"] - res.u_tail_last * conv
        res.wf_pchip = ti["value_pchip"] - res.u_tail_last * conv
        wf_err, res.wf_disc = ti["stderr"], ti["discretisation_error"]
        per_reg = [A.force_integration_work(res.d_A[r], res.f_m[r] + res.f_tail, res.f_e[r], area,
                                            correlation=rho) for r in range(res.n_reg)]
        res.w_reg = np.array([p["value"] - res.u_tail_last * conv for p in per_reg])
        res.w_reg_err = np.array([p["stderr"] for p in per_reg])
        if res.n_reg >= 2:
            wf_err = max(wf_err, A.registry_average(res.w_reg, res.w_reg_err)["stderr"])
        res.wf_err = wf_err
        w_e = w["value"] + res.w_tail_static
        # dE/A of every registry with its own zero-load contact (registry 0: the contact leg; the others with
        # registry_contact_steps), each against its own chain's W_F; T dS is their average
        e_reg = {0: (w_e, w["stderr"])} | {int(r): (c["energy_work_J_m2"], c["stderr_J_m2"])
                                           for r, c in res.details.get("registry_contacts", {}).items()}
        res.tds_rec = A.entropic_term(e_reg, {r: (res.w_reg[r], res.w_reg_err[r]) for r in range(res.n_reg)})
        res.tds, res.tds_err = (res.tds_rec["per_registry"][0] if len(res.tds_rec["registries"]) == 1 else
                                (res.tds_rec["mean"], res.tds_rec["stderr"]))
        res.repulsive = bool(ti["repulsive_end"])
        q, tail_on, n_reg = res.q, res.tail_on, res.n_reg
        q["work_of_adhesion_free_energy"] = quantity_record(
            wf, wf_err, "J/m^2", kind="free energy per area (force integration from the zero-force point of the "
            "registry-averaged mean-force curve, trapezoid rule" + ("; dispersion beyond the cutoff for TraPPE pairs "
                                                                   "included" if tail_on else "") + ")",
            discretisation_error=res.wf_disc, value_pchip=res.wf_pchip, repulsive_end=res.repulsive,
            registry_spread=float(np.std(res.w_reg, ddof=1)) if n_reg >= 2 else 0.0, registries=n_reg)
        regs = res.tds_rec["registries"]
        e_check = A.registry_consistency(np.array([[v[0]] for v in e_reg.values()]),
                                         np.array([[v[1]] for v in e_reg.values()])) if len(e_reg) >= 2 else None
        res.energy_registries_agree = e_check is None or not bool(np.asarray(e_check["inconsistent"])[0])
        if not res.energy_registries_agree:
            res.notes.append("dE/A and T dS NOT CONVERGED: the registries' own dE/A (each zero-load contact) disagree "
                             "beyond their stderrs (chi^2 p < 0.01); their mean is no converged number")
        q["entropic_term_TdS"] = quantity_record(
            res.tds, res.tds_err, "J/m^2", discretisation_error=res.wf_disc,
            kind="T dS / A = (dE - dF) / A of registry 0: dE/A from the zero-load contact leg (registry 0) and W_F of "
                 "registry 0's own chain" if regs == [0] else
                 f"T dS / A = (dE - dF) / A averaged over registries {regs}, each from its own zero-load contact leg "
                 "and its own chain's W_F",
            converged=res.energy_registries_agree,
            **({"registry": 0} if regs == [0] else {"registries": regs,
                                                   "per_registry": {str(r): v for r, v in
                                                                    res.tds_rec["per_registry"].items()}}))
        if tail_on:
            q["dispersion_tail_work"] = quantity_record(wf - res.ti_cut["value"], None, "J/m^2",
                                           kind="static dispersion beyond the cutoff for TraPPE pairs, in W_F: "
                                                "tail force integrated over the windows + tail energy left at "
                                                "the last window")

    def _flat_slab_law(self) -> None:
        """z0 and sigma0 from the flat-slab curve (peak traction, Maugis range) and an LJ 9-3 fit beside them. z0 =
        1.026 W_F / sigma0 takes the W_F the result reports (with a return chain: the out/back mean, its error with
        half the hysteresis), the same W the continuum's dgamma is, so that its Maugis-Dugdale stress 1.03 dgamma /
        z0 is the measured sigma0 (sigma0 itself from the outward curve)."""
        res = self.results
        dsep, f_tot, ebar, area, conv, q = res.dsep, res.f_tot, res.ebar, res.area, res.conv, res.q
        zsig: dict[str, Any] = {}
        rec = q["work_of_adhesion_free_energy"]
        w_used = float(rec["value"])
        w_err = math.hypot(float(rec["stderr"]), res.wf_disc, float(rec.get("systematic_hysteresis") or 0.0))
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
            res.notes.append(f"z0 and sigma0 not measured: {exc}")
        try:
            fit = A.fit_traction_law(dsep, f_tot, offset=True, force_stderr=ebar)
            zsig["lj93_fit"] = {"z0_A": fit["z0"], "z0_stderr_A": fit["stderr"]["z0"],
                                "w_J_m2": fit["w"] * conv, "w_stderr_J_m2": fit["stderr"]["w"] * conv,
                                "peak_Pa": float(U.kcal_per_mol_A3_to_Pa(fit["peak"] / area)),
                                "offset_A": fit["offset"], "rms_kcal_mol_A": fit["rms"]}
        except (ValueError, RuntimeError) as exc:
            zsig["lj93_fit"] = {"error": str(exc)}
        res.details["flat_slab_law"] = zsig

    def _layer_modulus(self) -> None:
        """The SAM layers' confined modulus from the compression branch (windows pressed into the contact, below the
        zero crossing) of the mean-force curve with its tail (:func:`md.analysis.confined_layer_modulus`); the
        thickness is the builder's (chain length and tilt) of every SAM between the backs. Pairs without a SAM:
        nothing."""
        res = self.results
        try:
            t, n_layers = A.sam_layer_thickness_A(self.plan.system)
        except ValueError:
            return
        self._small_strain_modulus()
        self._layer_poisson()
        try:
            lm = A.confined_layer_modulus(res.dsep, res.f_tot, res.ebar, res.area, t)
        except ValueError as exc:
            res.notes.append(f"SAM layer modulus not measured: {exc}")
            res.details["sam_layer_modulus"] = {"error": str(exc)}
            return
        res.q["sam_layer_modulus"] = quantity_record(
            lm["modulus_Pa"], lm["stderr_Pa"], "Pa",
            kind=f"confined (uniaxial-strain) modulus of the SAM layer{'s' if n_layers > 1 else ''} between the "
                 f"backs: -t d sigma / d d over the {lm['windows']} repulsive windows pressed into the contact, "
                 f"t = {t:.1f} A ({n_layers} SAM{'s' if n_layers > 1 else ''}, the builder's thickness); the "
                 "slabs' and the interface's compliance counted as the layers'",
            thickness_m=U.angstrom_to_m(t), layers=n_layers, windows=lm["windows"], strain_max=lm["strain_max"])
        res.details["sam_layer_modulus"] = lm
        if lm["note"]:
            res.notes.append(f"SAM layer modulus: {lm['note']}.")

    def _small_strain_modulus(self) -> None:
        """The tangent confined modulus at the zero-force point, normalised by the annealed thickness (the anneal's
        mean tilt, the builder's chain at that tilt): what a contact at small load sees (md.analysis.
        small_strain_layer_record). Fewer than four repulsive windows: a note, nothing else."""
        res = self.results
        tilt = A.tilt_of_anneal((res.details.get("anneal") or {}).get("mean_tilt_deg") or [])
        n = int(self.s.chain_length)
        try:
            rec = A.small_strain_layer_record(res.dsep, res.f_tot, res.ebar, res.area, self.plan.system, tilt,
                                              lambda th: float(chain_geometry(n, th)[0][-1][2]))
        except ValueError as exc:
            res.notes.append(f"SAM small-strain modulus not measured: {exc}")
            return
        tg = rec["tangent"]
        res.q["sam_layer_tangent_modulus"] = quantity_record(
            rec["modulus_Pa"], rec["stderr_Pa"], "Pa",
            kind=f"confined modulus of the SAM stack at small strain: the tangent at the zero-force point of a "
                 f"weighted quadratic through the {tg['windows']} repulsive windows, t = {rec['thickness_A']:.1f} A "
                 f"({rec['thickness_source']}); stderr: fit and thickness", thickness_m=rec["thickness_A"] * 1e-10,
            thickness_stderr_m=rec["thickness_stderr_A"] * 1e-10, thickness_per_layer_m=rec["thickness_per_layer_m"],
            layers=rec["layers"], chord_modulus_Pa=tg["chord_modulus_Pa"],
            curvature_delta_chi2=tg["curvature_delta_chi2"], windows=tg["windows"], strain_max=tg["strain_max"])
        res.details["sam_layer_tangent_modulus"] = {k: v for k, v in rec.items() if k != "tangent"} | {"tangent": tg}

    def _layer_poisson(self) -> None:
        """With ``sam_stress``: the SAM stack's C13/C33 and Poisson ratio from its own stress in the compression
        windows (the repulsive windows below the first zero crossing of the mean force with its tail, as the
        modulus; registry-averaged lateral (xx + yy)/2 and normal zz stress, md.analysis.stress_ratio_poisson).
        Without the columns: nothing."""
        res = self.results
        if not np.isfinite(res.sam_sig).any():
            return
        attractive = np.flatnonzero(res.f_tot <= 0.0)
        sel = np.arange(res.dsep.size) < (attractive[0] if attractive.size else res.dsep.size)
        if sel.sum() < 3:
            res.notes.append(f"SAM Poisson ratio not measured: {int(sel.sum())} compression windows (needs three)")
            return
        vol = res.area * A.sam_layer_thickness_A(self.plan.system)[0]          # A^3: stress x volume -> stress
        to_pa = lambda a: U.atm_to_Pa(np.asarray(a, float)) / vol
        avg = [A.registry_average(res.sam_sig[c][:, sel], res.sam_sig_e[c][:, sel]) for c in range(3)]
        lat = 0.5 * (np.asarray(avg[0]["mean"]) + np.asarray(avg[1]["mean"]))
        lat_e = 0.5 * np.hypot(avg[0]["stderr"], avg[1]["stderr"])
        try:
            pr = A.stress_ratio_poisson(res.dsep[sel], to_pa(lat), to_pa(avg[2]["mean"]), to_pa(lat_e),
                                        to_pa(avg[2]["stderr"]))
        except ValueError as exc:
            res.notes.append(f"SAM Poisson ratio not measured: {exc}")
            return
        res.q["sam_poisson_ratio"] = quantity_record(
            pr["poisson_ratio"], pr["poisson_ratio_stderr"], "",
            kind="Poisson ratio of the isotropic layer with the SAM stack's measured C13/C33 = nu / (1 - nu), from "
                 "the SAM atoms' own stress tensor in the compression windows (uniaxial strain)",
            c13_over_c33=pr["c13_over_c33"], c13_over_c33_stderr=pr["c13_over_c33_stderr"], windows=pr["windows"])
        res.details["sam_poisson_ratio"] = pr

    def _window_checks(self) -> None:
        """Windows with few independent samples, registries that disagree beyond their stderrs, the window-length
        check (W_F from the halves), and the per-window record."""
        res = self.results
        suffixes, s = res.suffixes, self.s
        res.short = [suffixes[k] for k in range(len(suffixes)) if np.nanmin(res.neff_w[:, k]) < MIN_WINDOW_NEFF]
        cons = A.registry_consistency(res.f_m, res.f_e)
        disagree = [suffixes[k] for k in np.flatnonzero(cons["inconsistent"])]
        if disagree:
            res.notes.append(
                f"registries disagree beyond their own stderrs (chi^2 p < 0.01) at {len(disagree)} of {len(suffixes)} "
                f"windows ({', '.join(disagree)}; chi^2/dof up to {np.nanmax(cons['chi2_per_dof']):.3g}): there the "
                "force depends on the registry or a window is too short for its mean, and the registries' spread, "
                "not a window's own stderr, is its error (W_F's stderr takes the larger per window)")
        res.details["pmf_windows"] = {
            "separation_A": res.dsep.tolist(), "mean_force_kcal_mol_A": res.fbar.tolist(),
            "stderr_kcal_mol_A": res.ebar.tolist(), "tail_force_kcal_mol_A": res.f_tail.tolist(), "window": suffixes,
            "per_registry_mean_force_kcal_mol_A": res.f_m.tolist(),
            "per_registry_stderr_kcal_mol_A": res.f_e.tolist(),
            "statistical_inefficiency": res.g_w.tolist(), "n_eff": res.neff_w.tolist(),
            "decorrelation_time_ps": ((res.g_w - 1) / 2 * s.sample_interval * res.dt * 1e-3).tolist(),
            "registry_work_J_m2": res.w_reg.tolist(), "registry_offsets_A": self.plan.registry_offsets_A,
            "zero_force_separation_A": res.ti["zero_force_separation_A"], "repulsive_end": res.repulsive,
            "windows_with_few_samples": res.short, "cutoff_only_work_J_m2": res.ti_cut["value"],
            "registry_chi2_per_dof": cons["chi2_per_dof"].tolist(), "registries_disagree": disagree,
            "statistical_stderr_kcal_mol_A": res.estat.tolist(), "chain_correlation_lag1": res.rho,
            "registry_work_stderr_J_m2": res.w_reg_err.tolist(),
            "t_factor": A.student_t_factor(res.n_reg) if res.n_reg >= 2 else 1.0,
            "interval_grid_bound_J_m2": res.ti["interval_bounds_J_per_m2"].tolist(),
            "refine_intervals_A": res.ti["refine_intervals_A"], "grid_bound_max_J_m2": res.ti["grid_bound_max"],
            "quadrature_difference_J_m2": res.ti["quadrature_difference"]}
        # tolerance from the windows' within-registry statistical stderrs only: a registry's offset cancels in the
        # difference of its halves, so the registries' spread must not widen it
        first, second = (np.nanmean(h, axis=0) + res.f_tail for h in res.halves)
        wl = A.window_length_check(res.dsep, first, second, res.estat, res.area, correlation=res.rho)
        res.w_half = [wl["first_half_J_m2"] - res.u_tail_last * res.conv,
                      wl["second_half_J_m2"] - res.u_tail_last * res.conv]
        res.half_diff, res.half_err, res.half_ok = (wl["difference_J_m2"], wl["difference_stderr_J_m2"],
                                                    wl["converged"])
        res.details["window_length_check"] = {
            "first_half_J_m2": res.w_half[0], "second_half_J_m2": res.w_half[1], "whole_J_m2": res.wf_val,
            "difference_J_m2": res.half_diff, "difference_stderr_J_m2": res.half_err, "converged": res.half_ok,
            "what": "W_F from the first and the second half of every window's equilibrated samples (after the detected "
                    "start, as W_F itself; same grid, tail, registries): a drift between them means the windows are "
                    "too short for the force to settle. Tolerance: 2 x the difference's stderr from the windows' "
                    "within-registry statistical stderrs (the registries' spread cancels in the difference)"}

    def _pmf_notes(self) -> list[str]:
        res = self.results
        dsep, wf, wf_err, n_reg, s = res.dsep, res.wf_val, res.wf_err, res.n_reg, self.s
        half_diff, half_err, w_half = res.half_diff, res.half_err, res.w_half
        notes = [
            f"free energy of separation from {len(res.suffixes)} windows x {n_reg} lateral registr"
            f"{'y' if n_reg == 1 else 'ies'} ({dsep[0]:+.2f} to {dsep[-1]:.2f} A from the contact leg's mean back "
            f"height {res.zc:.2f} A; chains: each window continues from its neighbour): dF/A = {wf:.4f} +/- "
            f"{wf_err:.4f} J/m^2 (trapezoid from the zero-force point {res.ti['zero_force_separation_A']:+.2f} A; "
            f"PCHIP gives {res.wf_pchip:.4f}, grid error {res.wf_disc:.4f}: the larger of the two quadratures' "
            f"difference and the largest interval bound 1/2 |df| dd over the detachment region); T dS/A of "
            f"registr{'y' if len(res.tds_rec['registries']) == 1 else 'ies'} "
            f"{', '.join(map(str, res.tds_rec['registries']))} (each zero-load contact's dE against its own "
            f"chain's W_F) = {res.tds:.4f} +/- {res.tds_err:.4f} J/m^2. "
            f"The stderr is statistical with the chained windows' errors correlated (lag-1 rho = {res.rho:.2f} from "
            f"the replicate chains), and at least the registries' spread of W_F times the Student-t factor of "
            f"{n_reg} registries; the discretisation error is given beside it."]
        if res.ti["refine_intervals_A"]:
            notes.append("windows too sparse: between " + ", ".join(f"{a:+.2f} and {b:+.2f} A" for a, b in
                                                                     res.ti["refine_intervals_A"])
                         + " the mean force changes by more than half the peak attraction in one interval (a "
                           "rupture the grid does not resolve); add windows there.")
        if not res.repulsive:
            notes.append("NO REPULSIVE END: no window before the most attractive one has a repulsive mean force, so "
                         "the bottom of the adhesive well lies inside the innermost window and W_F is a lower bound: "
                         "raise pmf_compress_A.")
        if res.short:
            notes.append(f"windows with fewer than {MIN_WINDOW_NEFF} effectively independent samples: {res.short} "
                         f"(lengthen pmf_sample_steps).")
        notes.append(f"window length: W_F from the first half of every window {w_half[0]:.4f}, from the second half "
                     f"{w_half[1]:.4f} J/m^2 (difference {half_diff:+.4f} +/- {half_err:.4f}: "
                     + ("within 2 stderr" if res.half_ok else
                        "MORE THAN 2 STDERR: the windows are too short for the mean force to settle; lengthen "
                        "pmf_sample_steps") + ").")
        if res.tail_on:
            notes.append(f"dispersion beyond the {s.cutoff_A:g} A cutoff for TraPPE pairs (any pair with a CH2/CH3 "
                         f"united atom) added as a static correction measured on this run's frames: "
                         f"{wf - res.ti_cut['value']:+.4f} J/m^2 in W_F (tail force per window + tail energy left at "
                         f"the last window), {res.w_tail_static:+.4f} J/m^2 in dE/A (contact frames). IFF pairs keep "
                         f"the plain cutoff IFF was parametrised with.")
        return notes

    def _draw_pmf(self, ax) -> None:
        res = self.results
        for r in range(res.n_reg):
            ax.plot(res.d_A[r], res.f_m[r], ".", ms=3, alpha=0.6, label=f"registry {r}")
        ax.errorbar(res.dsep, res.f_tot, yerr=res.ebar, marker="o", ms=3, lw=1, color="k", label="mean (+ tail)")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("separation from contact (Å)")
        ax.set_ylabel("mean force on upper slab (kcal/mol/Å)")
        ax.set_title(f"dF/A = {res.wf_val:.3f} ± {res.wf_err:.3f} (stat.) ± {res.wf_disc:.3f} (grid) J/m²")
        ax.legend(fontsize=7)

