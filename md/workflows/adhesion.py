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

from md.workflows.common import (ENERGY_NOT_FREE_ENERGY, TRAPPE_UA, Workflow, common_define, equilibrate_stage, forcefield_of, figure_writer,
                                 fresh_from_data, intersect_ids, minimize_lines, quantity_record, restart_header_lines, round_up, derived_seed,
                                 silica_face_of, stage_list, steps_of, system_summary, surface_slab, thermostat_lines)

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
        n = int(s.pmf_windows)
        out = s.separation_A * (np.arange(n) / (n - 1)) ** 2
        m = int(s.pmf_compress_windows)
        inward = -s.pmf_compress_A * np.arange(m, 0, -1) / m if m else np.zeros(0)
        return np.concatenate([inward, out])

    @classmethod
    def chains(cls, s) -> list[tuple[str, float, str | None]]:
        """(leg-name suffix, nominal separation, suffix of the leg it continues from) in run order: the contact
        window, the inward chain, the outward chain."""
        s = cls.typed(s)
        n, m = int(s.pmf_windows), int(s.pmf_compress_windows)
        out = s.separation_A * (np.arange(n) / (n - 1)) ** 2
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

    def plan(self, s, run_dir):
        s = self.typed(s)
        ff = forcefield_of(self.forcefield_files(s))
        lower_kind, upper_kind = s.surfaces
        face = silica_face_of(s.surfaces, s.silica_face)
        seed = int(s.seed)
        lower = surface_slab(lower_kind, s.nx, s.ny, s.slab_thickness_A, s, seed, face)
        upper = surface_slab(upper_kind, s.nx, s.ny, s.slab_thickness_A, s, seed + 10, face)
        system = as_system(place_on(lower, flip_upside_down(upper), gap=s.contact_gap_A,
                                    vacuum=s.separation_A + 15.0))
        data = run_dir / "system.data"
        write_data(system, ff, data)
        groups = {"lower": system.group("substrate"), "upper": system.group("adsorbate"),
                  "lower_fixed": intersect_ids(system, "frozen", "substrate"),
                  "upper_back": intersect_ids(system, "frozen", "adsorbate")}
        tail = _tail_applies(s, system)
        study = s.dispersion_tail == "trappe"   # contact frames for the cutoff study, even without TraPPE atoms
        if study:
            groups["tailset"] = np.arange(system.n_atoms)
        n = system.n_atoms
        area = float(system.cell[0] * system.cell[1])
        contact_dir = run_dir / "legs" / "contact"
        minimized = contact_dir / "minimized.data"
        setup_groups = lambda: ["group held union lower_fixed upper_back", "group mobile subtract all held"]
        columns = {"pe": "v_pe", "temp": "v_temp", "fz": "c_gg[3]", "z_back": "v_zback"}
        si = s.sample_interval

        def define(upper_free: bool, salt: int):
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

        def fresh_contact(leg_dir: Path) -> list[str]:
            return fresh_from_data(ff, data, s, groups) + setup_groups()

        def fresh_from_minimized(shift: float):
            def f(leg_dir: Path) -> list[str]:
                return fresh_from_data(ff, minimized, s, groups) + setup_groups() + \
                    ([f"displace_atoms upper move 0.0 0.0 {shift:.6f} units box"] if shift else [])
            return f

        def frames(sample_steps: int, per_leg: int, on: bool = True) -> Frames | None:
            return Frames("tailset", round_up(steps_of(sample_steps, si) / per_leg, si)) if on else None

        base = dict(define=None, restart_head=restart_header_lines(s), columns=columns,
                    sample_interval=si, chunk_steps=s.chunk_steps, n_atoms=n)
        sample = Stage("sample", steps_of(s.sample_steps, s.sample_interval))
        contact = Leg(name="contact", fresh=fresh_contact,
                      prepare=lambda d: ["unfix back_rigid", "fix back_min upper_back setforce 0.0 0.0 0.0"]
                      + minimize_lines(s, d / "minimized.data") + ["unfix back_min", _BACK_RIGID],
                      stages=stage_list(equilibrate_stage(s, "mobile", 1), sample),
                      frames=frames(s.sample_steps, TAIL_FRAMES_CONTACT, study),
                      **{**base, "define": define(True, 1)})
        legs = [
            contact,
            Leg(name="separated", fresh=fresh_from_minimized(s.separation_A), prepare=lambda d: ["reset_timestep 0"],
                stages=stage_list(equilibrate_stage(s, "mobile", 2), sample), **{**base, "define": define(False, 2)}),
        ]
        registries = []
        if s.free_energy == "pmf":
            # a chain: each window continues (positions and velocities) from its neighbour's last restart, moved
            # rigidly by the difference of the nominal separations; the first from the contact leg's last state,
            # moved laterally to the registry's offset
            pmf_equil = Stage("equilibrate", steps_of(s.pmf_equilibrate_steps, s.sample_interval), (), sampled=False)
            pmf_sample = Stage("sample", steps_of(s.pmf_sample_steps, s.sample_interval))
            stages = stage_list(pmf_equil, pmf_sample)
            total = sum(st.steps for st in stages)
            cell = (float(system.cell[0]) / s.nx, float(system.cell[1]) / s.ny)
            registries = _registry_offsets(int(s.lateral_registries), cell)
            nominal = {}

            def from_leg(prev_dir: Path, prev_total: int, move: tuple[float, float, float]):
                def f(leg_dir: Path) -> list[str]:
                    cmds = restart_header_lines(s)(prev_dir / f"restart.{prev_total}") + [f"timestep {s.timestep_fs:g}"]
                    if any(abs(x) > 0 for x in move):
                        cmds.append(f"displace_atoms upper move {move[0]:.6f} {move[1]:.6f} {move[2]:.6f} units box")
                    return cmds
                return f

            salt = 10
            for r, (dx, dy) in enumerate(registries):
                for suffix, d_nom, prev in self.chains(s):
                    name = f"pmf_r{r}_{suffix}"
                    prepare = lambda _d: ["reset_timestep 0"]
                    if prev is None and r > 0 and _lifts_registries(s):
                        fresh = from_leg(contact_dir, contact.total_steps, (dx, dy, d_nom + REGISTRY_LIFT_A))
                        prepare = lambda _d: registry_approach_lines(s)
                    elif prev is None:
                        fresh = from_leg(contact_dir, contact.total_steps, (dx, dy, d_nom))
                    else:
                        fresh = from_leg(run_dir / "legs" / f"pmf_r{r}_{prev}", total, (0.0, 0.0, d_nom - nominal[prev]))
                    nominal[suffix] = d_nom
                    legs.append(Leg(name=name, fresh=fresh, prepare=prepare, stages=stages,
                                    frames=frames(s.pmf_sample_steps, TAIL_FRAMES_WINDOW, tail and r == 0),
                                    info={"shift_A": float(d_nom), "registry": r, "offset_A": [dx, dy],
                                          "continues": f"pmf_r{r}_{prev}" if prev else "contact"},
                                    **{**base, "define": define(False, salt)}))
                    salt += 1
        info = {"area_A2": area, "box_A": system.cell.tolist(), "surfaces": list(s.surfaces), "face": face,
                "n_lower": int(len(groups["lower"])), "n_upper": int(len(groups["upper"])),
                "lower": system_summary(lower), "upper": system_summary(upper), "dispersion_tail": s.dispersion_tail,
                "tail_applies": bool(tail), "tail_study": bool(study),
                "registry_offsets_A": [list(o) for o in registries]}
        return Plan(legs=legs, timestep_fs=s.timestep_fs, n_atoms=n,
                    seeds={"structure_lower": seed, "structure_upper": seed + 10, "velocities": derived_seed(seed, 3, 1),
                           "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=info)

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
        s = self.typed(ctx.settings)
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
        w_tail_static, tail_det = 0.0, {"mode": s.dispersion_tail, "applied": tail_on}
        if tail_on:
            tc = self._tail(ctx, "trappe", "contact")
            u = tc["energy"]
            kt = U.kT_kcal_per_mol(s.temperature_K)
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
        q = {"work_of_adhesion": quantity_record(w["value"] + w_tail_static, w["stderr"], "J/m^2",
                                    kind="energy per area (not a free energy)" + (
                                        "; dispersion beyond the cutoff for TraPPE pairs included (static)"
                                        if tail_on else "")),
             "interface_area": quantity_record(U.angstrom_to_m(U.angstrom_to_m(area)), 0.0, "m^2")}
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
        figures["energy_timeseries"] = figure_writer(draw_energy)
        if s.free_energy != "pmf":
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
        # mean force of the first and the second half of each window's equilibrated samples (those after the
        # detected start t0, as the mean itself)
        halves = np.full((2,) + d_A.shape, np.nan)
        for r in range(n_reg):
            for k, suf in enumerate(suffixes):
                win = ctx.samples(f"pmf_r{r}_{suf}")           # one read of the window's samples
                st = A.timeseries_stats(win["fz"])
                d_A[r, k] = float(np.mean(win["z_back"])) - zc
                f_m[r, k], f_e[r, k], g_w[r, k], neff_w[r, k] = st["mean"], st["stderr"], st["g"], st["n_eff"]
                fz = np.asarray(win["fz"], float)[int(st["t0"]):]     # the samples the mean uses (after t0)
                if fz.size >= 2:
                    halves[0, r, k], halves[1, r, k] = np.mean(fz[:fz.size // 2]), np.mean(fz[fz.size // 2:])
        order = np.argsort(d_A[0])
        d_A, f_m, f_e, g_w, neff_w = (a[:, order] for a in (d_A, f_m, f_e, g_w, neff_w))
        halves = halves[:, :, order]
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
        # window length: W_F from each window's first half against its second half (the same grid, tail and
        # registries); windows long enough for their decorrelation give the same W within the errors
        w_half = [A.force_integration_work(dsep, np.nanmean(h, axis=0) + f_tail, ebar * math.sqrt(2.0),
                                           area)["value"] - u_tail_last * conv for h in halves]
        per_reg = [A.force_integration_work(d_A[r], f_m[r], f_e[r], area) for r in range(n_reg)]
        w_reg = np.array([p["value"] for p in per_reg])
        if n_reg >= 2:
            reg_avg = A.registry_average(w_reg, [p["stderr"] for p in per_reg])
            wf_err = max(wf_err, reg_avg["stderr"])
        w_e = w["value"] + w_tail_static
        tds = w_e - wf
        repulsive = bool(ti["repulsive_end"])
        q["work_of_adhesion_free_energy"] = quantity_record(
            wf, wf_err, "J/m^2", kind="free energy per area (force integration from the zero-force point of the "
            "registry-averaged mean-force curve, trapezoid rule" + ("; dispersion beyond the cutoff for TraPPE pairs "
                                                                   "included" if tail_on else "") + ")",
            discretisation_error=wf_disc, value_pchip=wf_pchip, repulsive_end=repulsive,
            registry_spread=float(np.std(w_reg, ddof=1)) if n_reg >= 2 else 0.0, registries=n_reg)
        q["entropic_term_TdS"] = quantity_record(tds, math.hypot(w["stderr"], wf_err), "J/m^2",
                                    kind="T dS / A = (dE - dF) / A", discretisation_error=wf_disc)
        if tail_on:
            q["dispersion_tail_work"] = quantity_record(wf - ti_cut["value"], None, "J/m^2",
                                           kind="static dispersion beyond the cutoff for TraPPE pairs, in W_F: "
                                                "tail force integrated over the windows + tail energy left at "
                                                "the last window")
        # ---- z0 and sigma0 from the flat-slab curve
        zsig: dict[str, Any] = {}
        try:
            pk = A.traction_peak(dsep, f_tot, ebar, area)
            pk_disc = pk["discretisation_error"] if np.isfinite(pk["discretisation_error"]) else 0.0
            rng = A.flat_slab_range(wf, math.hypot(wf_err, wf_disc), pk["sigma0"], math.hypot(pk["stderr"], pk_disc))
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
        cons = A.registry_consistency(f_m, f_e)
        disagree = [suffixes[k] for k in np.flatnonzero(cons["inconsistent"])]
        if disagree:
            notes.append(
                f"registries disagree beyond their own stderrs (chi^2 p < 0.01) at {len(disagree)} of {len(suffixes)} "
                f"windows ({', '.join(disagree)}; chi^2/dof up to {np.nanmax(cons['chi2_per_dof']):.3g}): there the "
                "force depends on the registry or a window is too short for its mean, and the registries' spread, "
                "not a window's own stderr, is its error (W_F's stderr takes the larger per window)")
        details["pmf_windows"] = {
            "separation_A": dsep.tolist(), "mean_force_kcal_mol_A": fbar.tolist(), "stderr_kcal_mol_A": ebar.tolist(),
            "tail_force_kcal_mol_A": f_tail.tolist(), "window": suffixes,
            "per_registry_mean_force_kcal_mol_A": f_m.tolist(), "per_registry_stderr_kcal_mol_A": f_e.tolist(),
            "statistical_inefficiency": g_w.tolist(), "n_eff": neff_w.tolist(),
            "decorrelation_time_ps": ((g_w - 1) / 2 * s.sample_interval * dt * 1e-3).tolist(),
            "registry_work_J_m2": w_reg.tolist(), "registry_offsets_A": info["registry_offsets_A"],
            "zero_force_separation_A": ti["zero_force_separation_A"], "repulsive_end": repulsive,
            "windows_with_few_samples": short, "cutoff_only_work_J_m2": ti_cut["value"],
            "registry_chi2_per_dof": cons["chi2_per_dof"].tolist(), "registries_disagree": disagree}
        # the halves' errors are sqrt(2) of the whole's, so their difference has stderr 2 x the whole's
        half_diff, half_err = w_half[1] - w_half[0], 2.0 * wf_err
        details["window_length_check"] = {
            "first_half_J_m2": w_half[0], "second_half_J_m2": w_half[1], "whole_J_m2": wf,
            "difference_J_m2": half_diff, "difference_stderr_J_m2": half_err,
            "converged": bool(abs(half_diff) <= 2.0 * half_err),
            "what": "W_F from the first and the second half of every window's equilibrated samples (after the detected "
                    "start, as W_F itself; same grid, tail, registries): a drift between them means the windows are "
                    "too short for the force to settle"}
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
        notes.append(f"window length: W_F from the first half of every window {w_half[0]:.4f}, from the second half "
                     f"{w_half[1]:.4f} J/m^2 (difference {half_diff:+.4f} +/- {half_err:.4f}: "
                     + ("within 2 stderr" if abs(half_diff) <= 2.0 * half_err else
                        "MORE THAN 2 STDERR: the windows are too short for the mean force to settle; lengthen "
                        "pmf_sample_steps") + ").")
        if tail_on:
            notes.append(f"dispersion beyond the {s.cutoff_A:g} A cutoff for TraPPE pairs (any pair with a CH2/CH3 "
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
        figures["pmf"] = figure_writer(draw_pmf)
        return Analysis(quantities=q, curves=curves, figures=figures, notes=notes, details=details)




def _tail_applies(s: Mapping[str, Any], system: System) -> bool:
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


def _lifts_registries(s: Mapping[str, Any]) -> bool:
    """Bare silica on bare silica: interlocked silanols cannot be sheared at contact (lift first)."""
    return all(surface == "silica" for surface in s.surfaces)


def registry_approach_lines(s: Mapping[str, Any]) -> list[str]:
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
