"""What each workflow's analysis reads of its plan, typed: one frozen record per workflow, built once at the start of
the analysis from the plan's system block (``Plan.system_info``, the mapping ``result.json`` records as ``system``).

A plan builder writes that block (its keys are a result's record, kept as they are); the analysis reads it only
through these records, so the plan-to-analysis contract is declared here and a key the plan did not write fails
at once, named (``KeyError``), instead of wherever a method first needed it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np


@dataclass(frozen=True)
class TailSites:
    """The SAM's TraPPE united atoms stored in the frames (1-based ids; none on bare silica) and their C6 with the
    water O (kcal/mol A^6): what the water-TraPPE dispersion beyond the cutoff sums."""
    ids: tuple[int, ...] = ()
    c6_kcal_A6: tuple[float, ...] = ()

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "TailSites":
        return cls(tuple(int(i) for i in info.get("tail_site_ids") or ()),
                   tuple(float(c) for c in info.get("tail_site_c6_kcal_A6") or ()))

    def framed(self, ids) -> tuple[np.ndarray, np.ndarray]:
        """(mask of the frames' atom ``ids`` that are tail sites, their C6 in the frames' order)."""
        order = {i: k for k, i in enumerate(self.ids)}
        is_site = np.isin(ids, self.ids)
        return is_site, np.asarray(self.c6_kcal_A6, float)[[order[int(i)] for i in np.asarray(ids)[is_site]]]


@dataclass(frozen=True)
class AdhesionPlanRecord:
    """``area_A2`` the interface area (A^2); ``n_lower`` the lower slab's atoms (ids 1..n_lower); the lateral
    registries' offsets (A) and which repeat another (a lattice translation: (registry, the one it repeats)), the
    surface lattice (A); whether the static dispersion tail applies and whether the cutoff study runs; ``system``
    the whole block, for :mod:`md.analysis` functions that read a result's system block (the SAM thickness)."""
    area_A2: float
    n_lower: int
    registry_offsets_A: list[list[float]]
    degenerate_registries: list[tuple[int, int]]
    surface_lattice_A: list[list[float]] | None
    tail_applies: bool
    tail_study: bool
    system: Mapping[str, Any] = field(repr=False, default_factory=dict)

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "AdhesionPlanRecord":
        return cls(area_A2=float(info["area_A2"]), n_lower=int(info["n_lower"]),
                   registry_offsets_A=[list(o) for o in info["registry_offsets_A"]],
                   degenerate_registries=[tuple(p) for p in info.get("degenerate_registries") or ()],
                   surface_lattice_A=info.get("surface_lattice_A"), tail_applies=bool(info.get("tail_applies")),
                   tail_study=bool(info.get("tail_study")), system=info)


@dataclass(frozen=True)
class DropletPlanRecord:
    """The water O and the solid's reference atoms in the frames (1-based ids), what the reference is (for the
    plots), and the TraPPE tail sites."""
    water_o_ids: list[int]
    surface_ref_ids: list[int]
    surface_ref: str
    tail: TailSites

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "DropletPlanRecord":
        return cls(water_o_ids=list(info["water_O_ids"]), surface_ref_ids=list(info["surface_ref_ids"]),
                   surface_ref=str(info["surface_ref"]), tail=TailSites.from_system(info))


@dataclass(frozen=True)
class WslPlanRecord:
    """``area_A2`` the interface (A^2); the lambda nodes of each node set ('q', 'lj'); the film's tether (height
    in A, spring in kcal/mol/A^2); the TraPPE tail sites."""
    area_A2: float
    nodes: dict[str, np.ndarray]
    tether_z_A: float
    tether_k_kcal_mol_A2: float
    tail: TailSites

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "WslPlanRecord":
        return cls(area_A2=float(info["area_A2"]), nodes={k: np.asarray(v, float) for k, v in info["nodes"].items()},
                   tether_z_A=float(info["tether"]["z_A"]),
                   tether_k_kcal_mol_A2=float(info["tether"]["k_kcal_mol_A2"]), tail=TailSites.from_system(info))


@dataclass(frozen=True)
class PullOffPlanRecord:
    """``n_flat`` the flat's atoms (ids 1..n_flat); the tip positions' lateral offsets (A; one position: none
    given, the origin); the tip's mobile mass (g/mol, for the lab-frame drag); the OTS asperity's grafting record
    (empty on silica)."""
    n_flat: int
    tip_offsets_A: list | None
    tip_mobile_mass_g_mol: float
    asperity_sam: Mapping[str, Any]

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "PullOffPlanRecord":
        return cls(n_flat=int(info["n_flat"]), tip_offsets_A=info.get("tip_offsets_A"),
                   tip_mobile_mass_g_mol=float(info["tip_mobile_mass_g_mol"]),
                   asperity_sam=info.get("asperity_sam", {}))

    @property
    def positions(self) -> int:
        return len(self.tip_offsets_A) if self.tip_offsets_A is not None else 1


@dataclass(frozen=True)
class SurfaceTensionPlanRecord:
    """The box (A) and the water O's Lennard-Jones parameters (kcal/mol, A) for the tail correction."""
    box_A: list[float]
    lj_epsilon_kcal: float
    lj_sigma_A: float

    @classmethod
    def from_system(cls, info: Mapping[str, Any]) -> "SurfaceTensionPlanRecord":
        return cls(box_A=[float(x) for x in info["box_A"]], lj_epsilon_kcal=float(info["lj_epsilon_kcal"]),
                   lj_sigma_A=float(info["lj_sigma_A"]))

    @property
    def area_A2(self) -> float:
        return self.box_A[0] * self.box_A[1]
