"""The liquid-vapour surface tension of a water film (:class:`SurfaceTension`).

surface_tension
    A free-standing SPC/E film; gamma = Lz/2 (<Pzz> - (<Pxx> + <Pyy>)/2) from the LAMMPS pressure tensor
    (:func:`md.analysis.surface_tension`) with the analytic LJ tail correction for the truncated LJ term
    (:func:`md.analysis.lj_tail_correction`; Coulomb is long-ranged through PPPM); bulk density from a tanh
    fit of the profile (:func:`md.analysis.slab_density`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from md import analysis as A
from md import units as U
from md.build import water_slab
from md.engine.plan import Analysis, Frames, Leg, Plan, Stage
from md.system.atoms import as_system
from md.system.lammps_data import write_data
from md.units import SPCE_WATER_MOLAR_MASS
from md.workflows.common import (
    Settings,
    Workflow,
    common_define,
    derived_seed,
    equilibrate_stage,
    figure_writer,
    forcefield_of,
    fresh_from_data,
    minimize_water_lines,
    quantity_record,
    restart_header_lines,
    shake_lines,
    stage_list,
    steps_of,
    thermostat_lines,
    water_forcefield_names,
)
from md.workflows.plan_records import SurfaceTensionPlanRecord


class SurfaceTension(Workflow):
    """SPC/E film: gamma_lv from the pressure tensor, bulk density from the profile."""
    name = "surface_tension"
    version = 1
    yields = {"surface_tension": "N/m", "surface_tension_uncorrected": "N/m", "density": "kg/m^3"}

    def _forcefield_files(self, s: Settings) -> list[str]:
        return water_forcefield_names(s.water_model)

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        ff = forcefield_of(self.forcefield_files(s))
        seed = int(s.seed)
        film = as_system(water_slab(s.lx_A, s.ly_A, s.film_thickness_A, vacuum=s.vacuum_A, seed=seed))
        data = run_dir / "system.data"
        write_data(film, ff, data)
        n = film.n_atoms
        fi = s.frame_interval or s.sample_interval
        groups = {"water_O": film.group("water_O")}

        def define(step: int) -> list[str]:
            return common_define(s, "all") + shake_lines(ff) + thermostat_lines("all", s, step) + [
                "variable pxx equal pxx", "variable pyy equal pyy", "variable pzz equal pzz",
                "variable lz equal lz"]

        leg = Leg(name="film", fresh=lambda d: fresh_from_data(ff, data, s, groups), define=define,
                  prepare=lambda d: minimize_water_lines(s), restart_head=restart_header_lines(s),
                  stages=stage_list(equilibrate_stage(s, "all", 1),
                                    Stage("sample", steps_of(s.sample_steps, s.sample_interval))),
                  columns={"pe": "v_pe", "temp": "v_temp", "pxx": "v_pxx", "pyy": "v_pyy", "pzz": "v_pzz",
                           "lz": "v_lz"},
                  sample_interval=s.sample_interval, chunk_steps=s.chunk_steps, n_atoms=n,
                  frames=Frames("water_O", fi))
        ow = ff.atom_type("OW")
        info = {"film": dict(film.info), "box_A": film.cell.tolist(), "n_molecules": int(film.info["n_molecules"]),
                "lj_epsilon_kcal": ow.epsilon, "lj_sigma_A": ow.sigma}
        return Plan(legs=[leg], timestep_fs=s.timestep_fs, n_atoms=n,
                    seeds={"structure": seed, "velocities": derived_seed(seed, 3, 1), "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=info)

    def analyse(self, ctx):
        s = ctx.settings
        plan = SurfaceTensionPlanRecord.from_system(ctx.plan.system_info)
        d = ctx.samples("film")
        steps, ids, pos, box = ctx.frames("film")
        area = plan.area_A2
        nb = min(s.n_blocks, max(2, len(steps)))
        dens = A.slab_density(pos[:, :, 2], SPCE_WATER_MOLAR_MASS, area, lz_A=None, bin_A=s.bin_A, n_blocks=nb)
        rho_n = U.kg_per_m3_to_g_per_cm3(dens["value"]) * U.AVOGADRO / SPCE_WATER_MOLAR_MASS * 1e-24     # O per A^3
        tail = A.lj_tail_correction(plan.lj_epsilon_kcal, plan.lj_sigma_A, rho_n, s.cutoff_A,
                                    width_A=dens["width_A"])
        st = A.surface_tension(d["pxx"], d["pyy"], d["pzz"], d["lz"], tail_correction_N_per_m=tail,
                               n_blocks=s.n_blocks)
        q = {"surface_tension": quantity_record(st["value"], st["stderr"], "N/m",
                                   kind="Kirkwood-Buff from the pressure tensor, LJ tail correction included"),
             "surface_tension_uncorrected": quantity_record(st["value_uncorrected"], st["stderr"], "N/m",
                                               kind="LJ truncated at the cutoff, no tail correction"),
             "density": quantity_record(dens["value"], dens["stderr"], "kg/m^3", kind="liquid density (tanh fit)")}
        prof = dens["profile"]
        curves = {"density_profile": (["z_m", "density_kg_m3"], np.column_stack([prof["z"], prof["density"]])),
                  "pressure_tensor": (["step", "pxx_Pa", "pyy_Pa", "pzz_Pa", "lz_m"],
                                      np.column_stack([d["step"], U.atm_to_Pa(d["pxx"]), U.atm_to_Pa(d["pyy"]),
                                                       U.atm_to_Pa(d["pzz"]), U.angstrom_to_m(d["lz"])]))}
        notes = [f"Coulomb: PPPM with kspace_modify slab 3.0 (long-ranged); Lennard-Jones: truncated at "
                 f"{s.cutoff_A:g} A in the dynamics, its long-range part added analytically "
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
        return Analysis(quantities=q, curves=curves, figures={"density_profile": figure_writer(draw)}, notes=notes,
                        details={"tail_correction_N_per_m": tail, "interface_width_A": dens["width_A"],
                                 "half_thickness_A": dens["half_thickness_A"],
                                 "rho_vapour_kg_m3": dens["rho_vapour"]})
