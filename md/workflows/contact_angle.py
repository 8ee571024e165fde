"""The contact angle of a cylindrical droplet (:class:`ContactAngleWorkflow`).

contact_angle
    A cylindrical droplet (periodic along y) on (111) silica with isolated Q3 silanols or on an OTS monolayer.
    The substrate is minimised with nothing held (FIRE at 1 fs), then only its deep Si and bridging O are held
    (silanol O-H by SHAKE) and it is equilibrated alone; the water is added as a cylindrical cap near its expected
    angle; water rigid (SHAKE). Water-oxygen configurations -> :class:`md.analysis.ContactAngle` (an in-memory
    MDAnalysis universe): the angle at the water's own dividing plane, W_SL = gamma_lv (1 + cos theta), a drift
    test of the block angles, and "wets" with an upper bound on the angle when the water spreads into a film.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from md import analysis as A
from md import units as U
from md.build import place_on, water_cap
from md.engine.plan import Analysis, Frames, Leg, Plan, Stage, id_ranges
from md.system.atoms import as_system
from md.system.forcefield import lammps_type_ids
from md.system.topology import System
from md.workflows.common import (
    WATER_MODELS,
    WATER_SOLID_COLUMNS,
    Settings,
    Workflow,
    equilibrate_stage,
    figure_writer,
    forcefield_of,
    intersect_ids,
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
from md.workflows.plan_records import DropletPlanRecord, TailSites
from md.workflows.substrate_water import (
    HELD,
    held_define,
    substrate_leg,
    substrate_of,
    substrate_water_forcefields,
    write_substrate_water,
)

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
    dividing plane (half the bulk density under the droplet): the plane of the solid's atoms is not where the
    liquid ends, and a circle cut there reads a different angle from the same map.

    The water and the substrate's mobile atoms have a thermostat each
    (:func:`md.workflows.common.water_solid_thermostat_lines`: heat crosses a water-solid interface slowly), both
    temperatures sampled and reported. The substrate's FIRE minimisation runs at :data:`FIRE_TIMESTEP_FS` (FIRE's
    steps at a 2 fs timestep make the unconstrained silanol O-H diverge). ``version`` enters the run hash."""
    name = "contact_angle"
    version = 4
    yields = {"contact_angle": "deg", "droplet_bulk_density": "kg/m^3", "base_half_width": "m"}

    def _forcefield_files(self, s: Settings) -> list[str]:
        return substrate_water_forcefields(s)

    def build(self, s) -> tuple[System, System, System]:
        """(substrate, droplet, both placed in one box) -- the substrate's coordinates are those of the combined
        system, so atom ids 1..n_substrate are the same in both legs."""
        seed = int(s.seed)
        sub = substrate_of(s)
        R0 = float(s.droplet_radius_A)
        wff = forcefield_of(water_forcefield_names(s.water_model))
        drop = as_system(water_cap(R0, float(sub.cell[1]), contact_angle_deg=s.droplet_initial_angle_deg,
                                   seed=seed + 1, forcefield=wff))
        system = as_system(place_on(sub, drop, gap=DROPLET_GAP_A, vacuum=max(20.0, R0)))
        return sub, drop, system

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        ff = forcefield_of(self.forcefield_files(s))
        seed = int(s.seed)
        sub, drop, system = self.build(s)
        parts = write_substrate_water("contact_angle", "droplet", ff, system, run_dir)
        water_data, water_o, tail_sites = parts.water_data, parts.water_o, parts.tail_sites
        if s.surface == "silica":
            ref = intersect_ids(system, "silanol_O_top", "substrate")
        else:
            ref = system.group("sam_ch3")
        # the SAM's TraPPE sites go into the frames too: the water-TraPPE dispersion beyond the cutoff is added
        # in the analysis
        framed = np.union1d(np.union1d(water_o, ref), tail_sites)
        n_sub, n = len(parts.substrate), system.n_atoms
        dt = s.timestep_fs

        def define(salt: int, with_water: bool):
            def d(step: int) -> list[str]:
                return held_define(s, parts) + \
                    (["variable nw equal count(water)/3"] + water_solid_thermostat_lines(s, step, salt)
                     if with_water else thermostat_lines("mobile", s, step, salt))
            return d

        sub_leg = substrate_leg(s, parts, define(0, False), restart_header_lines(s), n_sub)
        sub_dir = run_dir / "legs" / "substrate"

        def fresh_droplet(leg_dir: Path, _total=sub_leg.total_steps) -> list[str]:
            # the equilibrated substrate, then the water: ids n_sub+1.. as in the combined build
            return restart_header_lines(s)(sub_dir / f"restart.{_total}") + [
                f"timestep {dt:g}",
                f"read_data {water_data.as_posix()} add append group water",
                f"group framed id {id_ranges(framed)}",
                "group mobile subtract all frozen",
                f"delete_atoms overlap {DROPLET_OVERLAP_A:g} water substrate mol yes bond yes compress no"]

        drop_leg = Leg(name="droplet", fresh=fresh_droplet, define=define(1, True),
                       prepare=lambda d: minimize_water_lines(s), restart_head=restart_header_lines(s),
                       stages=stage_list(equilibrate_stage(s, "mobile", 1),
                                         Stage("sample", steps_of(s.sample_steps, s.sample_interval))),
                       columns={"pe": "v_pe", "temp": "v_temp", "n_water": "v_nw"} | WATER_SOLID_COLUMNS,
                       sample_interval=s.sample_interval, chunk_steps=s.chunk_steps, n_atoms=n,
                       frames=Frames("framed", s.frame_interval or s.sample_interval))
        ids = lammps_type_ids(ff)
        info = {"substrate": system_summary(sub), "droplet": dict(drop.info), "box_A": system.cell.tolist(),
                "n_substrate": int(n_sub), "n_water_molecules_built": int(len(water_o)),
                "held_atoms": int(len(parts.held)), "held": HELD,
                "silica_face": silica_face_of((s.surface,), s.silica_face),
                "water_O_ids": (water_o + 1).tolist(), "surface_ref_ids": (ref + 1).tolist(),
                "surface_ref": "top silanol O" if s.surface == "silica" else "OTS CH3 groups",
                "water_model": s.water_model, "type_ids": ids,
                "tail_site_ids": (tail_sites + 1).tolist(), "tail_site_c6_kcal_A6": parts.c6}
        return Plan(legs=[sub_leg, drop_leg], timestep_fs=dt, n_atoms=n,
                    seeds=substrate_water_seeds(seed), forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        return _DropletAnalysis(ctx, ctx.settings).run()


@dataclass(slots=True)
class _DropletResults:
    """What :class:`_DropletAnalysis` computes, in one place, filled in as :meth:`~_DropletAnalysis.run` goes: the
    solid's plane and the frames (:meth:`~_DropletAnalysis._prepare`), the universe and the contact-angle analysis
    ``r``, the water model, the angle with its blocks and stderr, the dispersion tail, the status ('measured' or
    'wets'), the drift and shape checks, the notes. Slotted: a name not declared here cannot be set."""
    notes: list[str] = field(default_factory=list)
    solid_z: float | None = None                 # the solid's reference plane (A)
    floor: float | None = None                   # lowest z of the density map (A)
    universe: Any = None                         # the frames as an in-memory MDAnalysis universe
    steps: np.ndarray | None = None
    ids: np.ndarray | None = None
    pos: np.ndarray | None = None
    box: np.ndarray | None = None
    r: Any = None                                # md.analysis.ContactAngle's results
    model: dict[str, Any] = field(default_factory=dict)
    gamma: float | None = None                   # the water model's gamma_lv (N/m)
    angle: float | None = None                   # deg
    angle_err: float | None = None               # deg; None where not estimated
    tail: dict[str, Any] | None = None
    status: str | None = None                    # 'measured' or 'wets'
    t_blocks: np.ndarray | None = None           # the blocks' mid times (ns)
    drift: dict[str, Any] | None = None
    shape: dict[str, Any] | None = None


class _DropletAnalysis:
    """The droplet leg's stored water-O configurations -> contact angle, W_SL, drift and shape checks, in the
    MDAnalysis manner: :meth:`_prepare` (the frames as an in-memory universe, the solid's reference plane),
    the per-frame density maps of :class:`md.analysis.ContactAngle` (:meth:`_measure`), :meth:`_conclude` (what the
    map shows, the quantities, the checks, notes, curves and the figure)."""

    def __init__(self, ctx, s):
        self.ctx, self.s = ctx, s
        self.plan = DropletPlanRecord.from_system(ctx.plan.system_info)
        self.results = _DropletResults()

    def run(self) -> Analysis:
        self._prepare()
        self._measure()
        return self._conclude()

    def _prepare(self) -> None:
        res = self.results
        import MDAnalysis as mda
        from MDAnalysis.coordinates.memory import MemoryReader

        steps, ids, pos, box = self.ctx.frames("droplet")
        if not len(steps):
            raise RuntimeError("no stored configurations: sample_steps shorter than frame_interval?")
        is_o = np.isin(ids, self.plan.water_o_ids)
        is_ref = np.isin(ids, self.plan.surface_ref_ids)
        res.solid_z = float(pos[:, is_ref, 2].mean())
        res.floor = res.solid_z - MAP_FLOOR_A
        opos = pos[:, is_o, :].astype(np.float32)
        u = mda.Universe.empty(int(is_o.sum()), trajectory=False)
        u.add_TopologyAttr("type", ["OW"] * int(is_o.sum()))
        dims = np.column_stack([box, np.full((len(box), 3), 90.0)]).astype(np.float32)
        u.load_new(opos, format=MemoryReader, dimensions=dims)
        res.universe, res.steps, res.ids, res.pos, res.box = u, steps, ids, pos, box

    def _measure(self) -> None:
        """The circle fit to every block's density map (md.analysis.ContactAngle: one pass over the frames)."""
        res = self.results
        s = self.s
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ca = A.ContactAngle(res.universe.select_atoms("type OW"), surface_z=res.floor, axis="y",
                                bin_size=s.bin_A, n_blocks=min(s.n_blocks, len(res.steps)),
                                reference="dividing_surface")
            ca.run()
        res.r = ca.results

    def _conclude(self) -> Analysis:
        res = self.results
        s = self.s
        res.model = WATER_MODELS[s.water_model]
        res.gamma = res.model["gamma_lv_N_m"]
        if abs(s.temperature_K - res.model["gamma_T_K"]) > 1.0:
            res.notes.append(f"gamma_lv = {res.gamma * 1e3:.1f} mN/m is the model's value at "
                             f"{res.model['gamma_T_K']:g} K, not at the run's {s.temperature_K:g} K: W_SL and "
                             f"gamma_lv cos theta carry that mismatch.")
        q = self._angle_quantities(self._status())
        self._drift_checks(q)
        res.notes += self._protocol_notes()
        temps = leg_temperatures(self.ctx, [leg for leg in self.ctx.plan.legs if leg.name == "droplet"],
                                 s.temperature_K)
        if temps:
            res.notes.append(temps["note"])
        details = self._details(q)
        if temps:
            details["temperatures_K"] = temps
        return Analysis(quantities=q, curves=self._curves(), figures={"density_map": figure_writer(self._draw)},
                        notes=res.notes, details=details)

    def _status(self) -> str:
        """What the map shows: a measured angle, no contact yet, or a film / a cap too flat to fit ("wets")."""
        res = self.results
        r = res.r
        xc, zc, rad = r.circle
        z_ref, wet = float(r.reference_z), r.wetting
        if np.isfinite(r.angle_deg) and not wet["spans_box"]:
            res.angle, res.angle_err = float(r.angle_deg), r.stderr_deg
            return "measured"
        if np.isfinite(rad) and rad > 0 and (zc - z_ref) / rad > 1 and not wet["spans_box"]:
            res.angle, res.angle_err = 180.0, None
            res.notes.append(f"the fitted circle (centre {zc - z_ref:+.1f} A from the water's plane, r = {rad:.1f} A) "
                             f"lies above the plane: the droplet is not (yet) in contact; reported as 180 deg.")
            return "no_contact"
        res.angle, res.angle_err = 0.0, None
        return "wets"

    def _angle_quantities(self, status: str) -> dict:
        res = self.results
        r, gamma = res.r, res.gamma
        q = {"contact_angle": quantity_record(res.angle, res.angle_err, "deg",
                                 kind={"measured": "circle fit, read at the water's dividing plane",
                                       "no_contact": "180 = no contact (mark, not a measurement)",
                                       "wets": "0 = wets (mark, not a measurement): see contact_angle_upper_bound"}
                                 [status], status=status),
             "droplet_bulk_density": quantity_record(U.g_per_cm3_to_kg_per_m3(r.bulk_density), None, "kg/m^3"),
             "base_half_width": quantity_record(U.angstrom_to_m(r.base_half_width_A), None, "m")}
        q["surface_tension_lv"] = quantity_record(gamma, None, "N/m", kind=f"the water model's published gamma_lv "
                                     f"({res.model['gamma_source']})")
        res.tail = None
        if status == "wets":
            self._wets_quantities(q)
        elif status == "measured":
            status = self._measured_quantities(q)
        res.status = status
        return q

    def _wets_quantities(self, q: dict) -> None:
        res = self.results
        r, wet, gamma = res.r, res.r.wetting, res.gamma
        bound, why = (wet["theta_max_deg"], "the water spans the periodic box (a film); a cap of this volume "
                      f"touches its image at {wet['theta_max_deg']:.1f} deg") if wet["spans_box"] else \
            (wet["theta_resolvable_deg"], f"no circle can be fitted above the excluded layer "
             f"({r.fit_error}); a cap of this volume is that flat below {wet['theta_resolvable_deg']:.1f} deg")
        q["contact_angle_upper_bound"] = quantity_record(bound, None, "deg", kind="wets: theta below this bound")
        wl = A.work_of_adhesion_sl(gamma, bound)
        q["work_of_adhesion_sl"] = quantity_record(wl["value"], None, "J/m^2", kind="lower bound (wets): "
                                      "gamma_lv (1 + cos theta_upper_bound)")
        q["gamma_lv_cos_theta"] = quantity_record(wl["gamma_cos_theta"], None, "N/m", kind="lower bound (wets)")
        res.notes.append(f"wets: theta < {bound:.1f} deg ({why}); W_SL >= {wl['value'] * 1e3:.1f} mJ/m^2. "
                         f"A droplet cannot resolve complete wetting; the dry-surface thermodynamic integration "
                         f"(Leroy & Mueller-Plathe, Langmuir 31 (2015) 8335) would measure W_SL directly.")

    def _measured_quantities(self, q: dict) -> str:
        """W_SL of a measured angle, with the water-TraPPE dispersion tail where the substrate has TraPPE sites;
        returns the status ('wets' if the tail makes the water wet)."""
        res = self.results
        status, gamma = "measured", res.gamma
        tail = _tail_correction(self.plan.tail, self.s, res.r, res.ids, res.pos, res.box, gamma, res.angle,
                                res.angle_err)
        if tail is not None:
            q["contact_angle_as_simulated"] = dict(q["contact_angle"], kind="circle fit at the water's dividing "
                                                   "plane, LJ truncated at the cutoff (as simulated)")
            q["dispersion_tail_work_sl"] = quantity_record(tail["work"], tail["work_stderr"], "J/m^2",
                                                           kind=tail["kind"])
            res.angle, res.angle_err = tail["angle"], tail["angle_stderr"]
            if tail["wets"]:
                status = "wets"
            q["contact_angle"] = quantity_record(res.angle, res.angle_err, "deg", status=status, kind=(
                "circle fit at the water's dividing plane, plus the water-TraPPE dispersion beyond the cutoff "
                "(static: W_SL + dW_tail, md.analysis.dispersion_tail_work)"))
            res.notes.append(tail["note"])
            gamma = tail["details"]["gamma_cut_N_m"]     # the angle was turned through the water as simulated
        res.tail = tail
        wl = A.work_of_adhesion_sl(gamma, res.angle, None, res.angle_err)
        q["work_of_adhesion_sl"] = quantity_record(wl["value"], wl["stderr"], "J/m^2", kind=(
            "Young-Dupre W_SL = gamma_lv (1 + cos theta), this water model's gamma" if tail is None else
            "Young-Dupre W_SL = gamma_cut (1 + cos theta) = W_SL as simulated + dW, with the water's tension as "
            "simulated (its pairs cut at the cutoff)"))
        q["gamma_lv_cos_theta"] = quantity_record(wl["gamma_cos_theta"], wl["gamma_cos_theta_stderr"], "N/m",
                                     kind="gamma_lv cos theta (meniscus force), this water model's gamma")
        return status

    def _drift_checks(self, q: dict) -> None:
        """The drift of the block angles against time, the blocks' independence, the cap's shape and height."""
        res = self.results
        r, steps = res.r, res.steps
        dt_ns = self.ctx.plan.timestep_fs * 1e-6
        res.t_blocks = np.interp(r.block_frames, np.arange(len(steps)), steps.astype(float)) * dt_ns
        res.drift = drift = A.block_drift(r.block_angles_deg, res.t_blocks)
        if res.status != "measured":
            return
        q["contact_angle_drift"] = quantity_record(drift["slope"], drift["stderr"], "deg/ns",
                                      kind="slope of the block angles against time (OLS)",
                                      drifting=bool(drift["drifting"]))
        if drift["drifting"]:
            res.notes.append(f"DRIFTING: the block angles still change by {drift['slope']:+.0f} +/- "
                             f"{drift['stderr']:.0f} deg/ns ({drift['change']:+.1f} deg over the sampled "
                             f"{np.ptp(res.t_blocks) * 1e3:.0f} ps, |slope| > 2 stderr): not equilibrated; the "
                             f"mean depends on where the run stopped.")
        if not r.blocks_independent:
            res.notes.append(f"the droplet's shape (its water's mean height) has a statistical inefficiency of "
                             f"{r.shape_statistical_inefficiency:.0f} frames in {r.n_frames}: the "
                             f"{r.n_blocks_used} block maps are not independent, so the angle's stderr is a lower "
                             f"bound; a longer run is what makes it an error bar.")
        res.shape = shape = A.shape_check(r.density_map, *r.edges, res.floor, r.stderr_deg)
        if shape["circular"] is False:
            by = ", ".join(f"{v:.1f} ({k} A)" for k, v in shape["angles_by_exclude_deg"].items())
            res.notes.append(f"NOT A CIRCULAR CAP: the same map reads {by} above the water's plane and "
                             f"{shape['angle_from_height_deg']:.1f} deg from its area and height; the spread "
                             f"{shape['spread_deg']:.1f} deg exceeds max(3 stderr, 2 deg) = "
                             f"{shape['tolerance_deg']:.1f} deg, so the angle depends on how it is read "
                             f"(pinned or moving contact lines, a sheared mean shape): a systematic the stderr "
                             f"does not hold.")
        h = float(r.cap_height_A)
        if h < 3 * 5.0:
            res.notes.append(f"the cap is {h:.1f} A high, less than 3x the 5 A excluded layer: few interface "
                             f"points carry the fit.")

    def _protocol_notes(self) -> list[str]:
        res = self.results
        s, z_ref = self.s, float(res.r.reference_z)
        return [f"angle read at the water's dividing plane z = {z_ref:.2f} A (half the bulk density under the "
                f"droplet), {z_ref - res.solid_z:+.2f} A from the mean height of the {self.plan.surface_ref} "
                f"({res.solid_z:.2f} A); circle fitted to the half-bulk contour above that plane + 5 A "
                f"(md.analysis.ContactAngle, {res.r.n_frames} frames).",
                "substrate minimised with nothing held, then its deep Si and bridging O held; silanol O and H "
                "mobile (O-H by SHAKE)" + ("; the OTS SAM equilibrated alone before the droplet was placed"
                                            if s.surface == "ots" else "") +
                f"; water rigid {res.model['name']} (SHAKE); the droplet started as a "
                f"{s.droplet_initial_angle_deg:g} deg cylindrical cap.",
                "a cylindrical droplet has a straight contact line: no line-tension correction.",
                f"W_SL and gamma_lv cos theta use gamma_lv = {res.gamma * 1e3:.1f} mN/m of the same water model "
                f"({s.water_model}); combine the angle only with a gamma_lv of that model."]

    def _curves(self) -> dict:
        res = self.results
        ue, ze = res.r.edges
        rho = res.r.density_map
        return {"density_map": (["u_m", "z_m", "density_kg_m3"],
                                np.column_stack([np.repeat(U.angstrom_to_m(0.5 * (ue[1:] + ue[:-1])), len(ze) - 1),
                                                 np.tile(U.angstrom_to_m(0.5 * (ze[1:] + ze[:-1])), len(ue) - 1),
                                                 U.g_per_cm3_to_kg_per_m3(rho.ravel())])),
                "interface_points": (["u_m", "z_m"],
                                     U.angstrom_to_m(np.asarray(res.r.interface_points).reshape(-1, 2)))}

    def _details(self, q: dict) -> dict:
        res = self.results
        r, s, status = res.r, self.s, res.status
        xc, zc, rad = r.circle
        z_ref = float(r.reference_z)
        d_app = self.ctx.samples("droplet", False)
        n_water = int(round(d_app["n_water"][-1])) if len(d_app.get("n_water", [])) else None
        block_w = [A.work_of_adhesion_sl(res.gamma, a)["value"] if np.isfinite(a) else None
                   for a in r.block_angles_deg]
        details = {"status": status, "reference_z_A": z_ref, "surface_z_A": res.solid_z,
                   "reference_above_solid_A": z_ref - res.solid_z, "circle_A": [float(xc), float(zc), float(rad)],
                   "block_angles_deg": np.asarray(r.block_angles_deg).tolist(),
                   "block_times_ns": res.t_blocks.tolist(), "block_work_of_adhesion_sl_J_m2": block_w,
                   "drift": res.drift, "wetting": r.wetting, "fit_error": r.fit_error,
                   "cap_height_A": r.cap_height_A, "fit_rms_A": r.fit_rms_A, "n_frames": int(r.n_frames),
                   "n_water_molecules": n_water, "water_model": s.water_model, "gamma_lv_N_m": res.gamma,
                   "blocks": {"n_blocks_used": int(r.n_blocks_used), "n_blocks_most": int(s.n_blocks),
                              "shape_statistical_inefficiency_frames": float(r.shape_statistical_inefficiency),
                              "independent": bool(r.blocks_independent),
                              "what": "blocks of frames sized to span 2 g of the water's mean height (g its "
                                      "statistical inefficiency), 3 at least, n_blocks at most"}}
        if status == "measured":
            details["shape_check"] = res.shape
        if status in ("measured", "wets") and "dispersion_tail_work_sl" in q:
            details["dispersion_tail"] = res.tail["details"]
        return details

    def _draw(self, ax) -> None:
        res = self.results
        r = res.r
        xc, zc, rad = r.circle
        z_ref = float(r.reference_z)
        ue, ze = r.edges
        ax.pcolormesh(ue, ze, r.density_map.T, cmap="Blues", shading="flat")
        if np.isfinite(rad):
            tt = np.linspace(0, 2 * np.pi, 400)
            cx, cz = xc + rad * np.cos(tt), zc + rad * np.sin(tt)
            keep = cz >= z_ref
            ax.plot(cx[keep], cz[keep], "r-", lw=1.2, label="fitted circle")
        pts = np.asarray(r.interface_points).reshape(-1, 2)
        ax.plot(pts[:, 0], pts[:, 1], "k.", ms=2, label="interface points")
        ax.axhline(z_ref, color="k", lw=0.8, label="water's dividing plane")
        ax.axhline(res.solid_z, color="grey", lw=0.8, ls="--", label=self.plan.surface_ref)
        ax.set_aspect("equal")
        ax.set_xlabel("x (Å, droplet-centred)")
        ax.set_ylabel("z (Å)")
        title = {"measured": f"θ = {res.angle:.1f} ± {(res.angle_err or float('nan')):.1f}°",
                 "no_contact": "no contact", "wets": "wets"}[res.status]
        ax.set_title(f"{title} ({self.s.surface})")
        ax.legend(fontsize=7)


def _truncated_gamma(s, number_density_A3: float, gamma_full: float) -> tuple[float, float]:
    """The liquid-vapour tension of the water as the run simulates it (LJ cut at the run's cutoff, no tail): the
    model's published full-LJ gamma less Blokhuis et al.'s LJ tail at that cutoff for a sharp interface at the
    droplet's own bulk density (md.analysis.lj_tail_correction; a finite interface width lowers the tail by a few
    per cent). Returns (gamma, tail), N/m."""
    ow = forcefield_of(water_forcefield_names(s.water_model)).atom_type("OW")
    tail = A.lj_tail_correction(ow.epsilon, ow.sigma, number_density_A3, s.cutoff_A)
    return gamma_full - tail, tail


def _tail_correction(sites: TailSites, s, r, ids, pos, box, gamma, angle, angle_err):
    """The water-TraPPE dispersion the cutoff leaves out, on a measured angle (None where the substrate has no
    TraPPE site, or a run planned before the sites were stored). Per frame, from the sites' heights under the
    water's dividing plane (the water at its bulk density above it): the r^-6 tail beyond the cutoff
    (md.analysis.dispersion_tail_work) plus the constant u(r_c) the shifted forces miss for every pair inside it
    (md.analysis.cutoff_crossing_work). Young-Dupre with the water's tension as simulated (water-water pairs keep
    the cutoff; `gamma` is the model's full-LJ value, lowered here by the tail at the cutoff):
    cos theta' = cos theta + dW / gamma_cut. Returns the corrected angle and its stderr (first order, the angle's
    and dW's errors independent), dW (J/m^2) with its stderr (statistical inefficiency of the per-frame series),
    a note and the details."""
    if not sites.ids:
        return None
    is_site, c6 = sites.framed(ids)
    if not is_site.any():
        return None
    n_w = U.g_per_cm3_to_kg_per_m3(float(r.bulk_density)) / U.amu_per_A3_to_kg_per_m3(U.WATER_MOLAR_MASS)
    z_ref = float(r.reference_z)
    per_frame = np.array([[f(pos[k, is_site, 2], c6, z_ref, n_w, s.cutoff_A, float(box[k][0] * box[k][1]))
                           for f in (A.dispersion_tail_work, A.cutoff_crossing_work)] for k in range(len(pos))])
    st = A.timeseries_stats(per_frame.sum(axis=1), equilibrate=False)
    dw = U.kcal_per_mol_A2_to_J_per_m2(st["mean"])
    dw_err = U.kcal_per_mol_A2_to_J_per_m2(st["stderr"]) if np.isfinite(st["stderr"]) else None
    gamma_cut, gamma_tail = _truncated_gamma(s, n_w, gamma)
    th = np.radians(angle)
    cos_new = np.cos(th) + dw / gamma_cut
    wets = bool(cos_new >= 1.0)
    new = 0.0 if wets else float(np.degrees(np.arccos(max(cos_new, -1.0))))
    new_err = None
    if not wets and angle_err is not None:
        var = (np.sin(th) * np.radians(angle_err)) ** 2 + ((dw_err or 0.0) / gamma_cut) ** 2
        new_err = float(np.degrees(np.sqrt(var) / max(np.sin(np.radians(new)), 1e-12)))
    beyond, crossing = (U.kcal_per_mol_A2_to_J_per_m2(float(np.mean(per_frame[:, i]))) for i in (0, 1))
    note = (f"water-TraPPE dispersion the {s.cutoff_A:g} A cutoff leaves out, added statically: dW_SL = "
            f"{dw * 1e3:.2f} mJ/m^2 (beyond the cutoff {beyond * 1e3:.2f}, the shifted pairs inside it "
            f"{crossing * 1e3:.2f}; {int(is_site.sum())} CH2/CH3 sites under the water's dividing plane, water at its "
            f"bulk density above it), so theta = {angle:.1f} deg as simulated -> {new:.1f} deg (cos theta + dW / "
            f"gamma_cut, gamma_cut = {gamma_cut * 1e3:.1f} mN/m: the water's tension as simulated, the model's "
            f"{gamma * 1e3:.1f} less its {gamma_tail * 1e3:.1f} mN/m LJ tail); the water-water and IFF pairs keep "
            "the plain cutoff.")
    return {"angle": new, "angle_stderr": new_err, "wets": wets, "work": dw, "work_stderr": dw_err, "note": note,
            "kind": "water-TraPPE dispersion the cutoff leaves out (beyond it and the shifted pairs inside it), per "
                    "area of wetted SAM (static half-space sums)",
            "details": {"per_frame_J_m2": U.kcal_per_mol_A2_to_J_per_m2(per_frame.sum(axis=1)).tolist(),
                        "beyond_cutoff_J_m2": beyond, "inside_cutoff_shift_J_m2": crossing,
                        "gamma_cut_N_m": gamma_cut, "gamma_tail_N_m": gamma_tail,
                        "g": st["g"], "cutoff_A": s.cutoff_A, "water_number_density_A3": n_w,
                        "plane_z_A": z_ref, "sites": int(is_site.sum()), "angle_as_simulated_deg": angle}}
