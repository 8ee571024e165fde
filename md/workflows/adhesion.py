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

from pathlib import Path

import numpy as np

from md import analysis as A
from md.engine.plan import Plan
from md.system.lammps_data import read_atoms
from md.workflows.adhesion_analysis import _AdhesionAnalysis
from md.workflows.adhesion_legs import TAIL_R_MAX_A, _AdhesionLegs, _lifts_registries, _tail_pair_table, outward_grid
from md.workflows.common import Settings, Workflow, derived_seed, forcefield_of

# ================================================================================================ adhesion

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
    registry (:func:`registry_approach_lines`). ``version`` and :meth:`protocol_version` (the older protocol for
    SAM pairs, whose plans this does not touch) enter the run hash."""
    name = "adhesion"
    version = 4
    yields = {"work_of_adhesion": "J/m^2", "work_of_adhesion_free_energy": "J/m^2",
              "entropic_term_TdS": "J/m^2", "interface_area": "m^2"}

    def _forcefield_files(self, s: Settings) -> list[str]:
        return ["silica_interface"] + (["ots_trappe_ua"] if "ots" in s.surfaces else [])

    def _protocol_version(self, s: Settings) -> int:
        return self.version if _lifts_registries(s) else 3

    def windows(self, s) -> np.ndarray:
        """Nominal separations from contact (A): the compressed chain (negative, innermost first) and the outward
        chain (0 first, quadratically spaced to separation_A)."""
        out = outward_grid(s)
        m = int(s.pmf_compress_windows)
        inward = -s.pmf_compress_A * np.arange(m, 0, -1) / m if m else np.zeros(0)
        return np.concatenate([inward, out])

    @classmethod
    def chains(cls, s) -> list[tuple[str, float, str | None]]:
        """(leg-name suffix, nominal separation, suffix of the leg it continues from) in run order: the contact
        window, the inward chain, the outward chain."""
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

    def _plan(self, s: Settings, run_dir: Path) -> Plan:
        legs = _AdhesionLegs(self, s, run_dir)
        anneal = [legs.anneal()] if s.sam_anneal_steps > 0 else []
        contact = legs.contact()
        windows = legs.windows(contact) if s.free_energy == "pmf" else []
        seed = int(s.seed)
        return Plan(legs=anneal + [contact, legs.separated()] + windows, timestep_fs=s.timestep_fs,
                    n_atoms=legs.system.n_atoms,
                    seeds={"structure_lower": seed, "structure_upper": seed + 10,
                           "velocities": derived_seed(seed, 3, 1), "thermostat_base": seed},
                    forcefield_files=self.forcefield_files(s), system_info=legs.info())

    # ------------------------------------------------------------------------------------------ analysis
    def _tail(self, ctx, n_lower: int, mode: str, leg: str, r_max: float = TAIL_R_MAX_A, frames=None) -> dict:
        """Static LJ interaction beyond the cutoff between the two slabs (the lower one atom ids 1..``n_lower``)
        on the stored frames of ``leg``: per-frame energies (kcal/mol) and forces on the upper slab along +z
        (kcal/mol/A)."""
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
        low = ids <= n_lower
        es, fs, pairs = [], [], 0
        for k in range(len(steps)):
            r = A.lj_tail_between(pos[k][low], t[low], pos[k][~low], t[~low], eps, sig, inc, box[k][:2],
                                  ctx.settings.cutoff_A, r_max)
            es.append(r["energy"])
            fs.append(r["force_z"])
            pairs = r["pairs"]
        return {"energy": np.array(es), "force_z": np.array(fs), "pairs": pairs}

    def analyse(self, ctx):
        return _AdhesionAnalysis(self, ctx).run()

