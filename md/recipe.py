"""MD recipe files (``inputs/md/*.toml``): one table of fields drives validation, defaults and ``docs/md.md``.

A recipe names a workflow, describes the physical system once (``[system]``) and sizes it three times,
once per fidelity (``[fidelity.smoke]``, ``[fidelity.quick]``, ``[fidelity.production]``: box sizes, steps,
timestep, thermostat, sampling, seed). Units are the molecular layer's edge units: lengths in angstrom
(keys end in ``_A``), times in fs (``_fs``) or steps, temperatures in K; the pulling speeds are written in
m/s (``_m_s``) and converted by :mod:`md.units` where LAMMPS needs A/fs.

Validation is strict and happens once, here: an unknown key, a key that does not belong to the recipe's
workflow, a value of the wrong type or outside its range raises :class:`RecipeError`, whose message names
the key (``fidelity.smoke.timestep_fs``), the value and what is allowed -- the same way continuum scene files
are checked. A few keys may appear in ``[system]`` (the paper value) and be overridden in a fidelity table
(a smaller asperity or droplet for a smoke run): they are marked ``both`` in the schema.

``python -m md.recipe`` prints the schema as a markdown table (used in ``docs/md.md``).
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping

from nanoimpact import data as shipped_data
from nanoimpact import fields
from nanoimpact.errors import DataNotFound, InputError
from nanoimpact.fields import REQUIRED

__all__ = ["RecipeError", "Recipe", "Field", "RecipeField", "FIELDS", "WORKFLOWS", "FIDELITIES", "SURFACES",
           "load_recipe", "parse_recipe", "schema_markdown", "RECIPE_DIR"]

#: The shipped MD recipes (inputs/md, installed as package data); names are looked up in the user data
#: folder first (nanoimpact.data).
RECIPE_DIR = shipped_data.shipped_root() / "md"
WORKFLOWS = ("adhesion", "pulloff", "contact_angle", "surface_tension", "wsl_ti")
FIDELITIES = ("smoke", "quick", "production")
SURFACES = ("silica", "ots")
THERMOSTATS = ("nose-hoover", "langevin")
ALL = WORKFLOWS


#: Keys that define a run of a workflow only on some systems: workflow -> {key: (system key, value)}; elsewhere the
#: key keeps its default in the settings but stays out of the run's identity (`Recipe.canonical`, hence the run
#: hash). On silica the SAM keys change nothing in a W_SL run, so they stay out of its hash. (The other workflows
#: hash their SAM keys on every surface, as their committed results were hashed.)
CONDITIONAL_KEYS: dict[str, dict[str, tuple[str, Any]]] = {
    "wsl_ti": {"sam_coverage": ("surface", "ots"), "chain_length": ("surface", "ots")}}

#: Options whose neutral value runs exactly the protocol a workflow ran before the option existed: workflow ->
#: {key: neutral value}. At that value the key stays out of the run's identity (`Recipe.canonical`), because the
#: run it describes is the same run; any other value enters the hash. A protocol option added to a workflow is
#: registered here with the value that reproduces the runs already committed.
#: The builder's cubic lattice constant of beta-cristobalite (A; md.build.silica.CRISTOBALITE_A, Wyckoff 1925),
#: the neutral value of ``silica_lattice_A``: every committed silica result was built with it.
BUILDER_LATTICE_A = 7.16

NEUTRAL_KEYS: dict[str, dict[str, Any]] = {
    "pulloff": {"flat_thermostat": "mobile", "tip_positions": 1, "silica_lattice_A": BUILDER_LATTICE_A},
    "adhesion": {"registry_sampling": "rank1", "registry_contact_steps": 0, "sam_anneal_steps": 0,
                 "pmf_return": False, "pmf_extra_windows_A": (), "silica_lattice_A": BUILDER_LATTICE_A,
                 "sam_stress": False},
    "contact_angle": {"silica_lattice_A": BUILDER_LATTICE_A},
    "wsl_ti": {"silica_lattice_A": BUILDER_LATTICE_A}}


class RecipeError(InputError):
    """An invalid recipe: names the key, the value and what is allowed."""


@dataclass(frozen=True)
class RecipeField(fields.Field):
    """One recipe key (`nanoimpact.fields.Field`: type, unit, range, default, doc, the check and the JSON
    Schema), plus where it may be written and for which workflows.

    ``section``: 'top', 'system', 'fidelity' or 'both' (system value, overridable per fidelity).
    ``workflows``: the workflows the key belongs to.
    """
    section: str = "top"
    workflows: tuple[str, ...] = ALL


def Field(key: str, section: str, kind: type, unit: str, doc: str, default: Any = REQUIRED, low: float | None = None,
          high: float | None = None, low_open: bool = False, choices: tuple[str, ...] = (),
          workflows: tuple[str, ...] = ALL, item: type | None = None, length: tuple[int, ...] = ()) -> RecipeField:
    """A recipe key, declared as the table below reads: key, section, kind, unit, doc, default, then the range."""
    return RecipeField(key, kind, unit, doc, default, low=low, high=high, low_open=low_open, choices=choices,
                       item=item, length=length, section=section, workflows=workflows)


_ADH, _PULL, _CA, _ST, _TI = ("adhesion",), ("pulloff",), ("contact_angle",), ("surface_tension",), ("wsl_ti",)
_SURF = ("adhesion", "pulloff", "contact_angle")

FIELDS: tuple[Field, ...] = (
    # ---------------------------------------------------------------- top level
    Field("workflow", "top", str, "", "What the recipe computes.", REQUIRED, choices=WORKFLOWS),
    Field("name", "top", str, "", "Recipe name (default: file name without .toml); names output folders.", None),
    Field("description", "top", str, "", "Free text copied into result.json.", ""),
    # ---------------------------------------------------------------- system
    Field("temperature_K", "system", float, "K", "Thermostat temperature.", 300.0, low=1.0, high=2000.0),
    Field("surfaces", "system", list, "", "Adhesion: the lower and the upper surface (the upper slab is flipped "
          "to face the lower one).", REQUIRED, choices=SURFACES, workflows=_ADH, item=str, length=(2,)),
    Field("surface", "system", str, "", "Pull-off: the coating of both the asperity and the flat; contact "
          "angle and W_SL by TI: the substrate.", REQUIRED, choices=SURFACES, workflows=_PULL + _CA + _TI),
    Field("silica_face", "system", str, "", "Cristobalite face of every bare silica surface: '111' = isolated Q3 "
          "silanols at 4.50 OH/nm^2 (nearest silanol O-O 5.06 A), IFF's hydrophilic Q3 surface and the shared "
          "default of all recipes; '001' = geminal/vicinal pairs 2.53 A apart, 3.9-7.8 OH/nm^2 (silanol_density). "
          "OTS is always grafted on (111).", "111", choices=("111", "001"), workflows=_SURF + _TI),
    Field("silanol_density", "system", float, "OH/nm^2", "Silanol density requested on the (001) face "
          "(silica_face = '001'); the (111) face has 4.50 fixed.", 4.7, low=3.9, high=7.8,
          workflows=_SURF + _TI),
    Field("silica_lattice_A", "system", float, "A", "Cubic lattice constant every silica slab, asperity and OTS "
          "substrate is built with (beta-cristobalite, Fd-3m). 7.16 is the ideal cell (Wyckoff 1925) every committed "
          "result used; under IFF a free (111) slab at 7.16 is stretched in plane by about 3 GPa and relaxed near "
          "7.02 (benchmarks/md_lateral_stress.py). A protocol option: at 7.16 it stays out of the run hash.",
          BUILDER_LATTICE_A, low=6.8, high=7.4, workflows=_SURF + _TI),
    Field("sam_coverage", "system", float, "chains/nm^2", "OTS grafting density (cristobalite (111) holds at "
          "most 4.50).", 4.5, low=0.5, high=4.5, workflows=_SURF + _TI),
    Field("chain_length", "system", int, "carbons", "OTS alkyl chain length (C18 for OTS).", 18, low=2, high=30,
          workflows=_SURF + _TI),
    Field("separation_A", "system", float, "A", "Adhesion: distance the upper slab is moved away for the "
          "separated state; must exceed the cutoff.", 20.0, low=5.0, high=60.0, workflows=_ADH),
    Field("contact_gap_A", "system", float, "A", "Adhesion: initial gap between the two slabs before "
          "minimisation.", 3.0, low=1.0, high=6.0, workflows=_ADH),
    Field("dispersion_tail", "system", str, "", "Adhesion: Lennard-Jones dispersion beyond the cutoff for TraPPE "
          "pairs (every pair with a CH2/CH3 united atom: OTS-OTS, silica-OTS, water-OTS), which TraPPE was fitted "
          "with (14 A + analytic tails). 'trappe' adds it as a static correction measured on the run's own "
          "configurations (explicit sum to 20 A over all periodic images, smeared beyond) to W and to every "
          "window's mean force; IFF pairs keep IFF's plain 12 A cutoff. 'none' leaves it out.", "trappe",
          choices=("trappe", "none"), workflows=_ADH),
    Field("asperity_radius_A", "both", float, "A", "Pull-off: radius R of the hemispherical asperity.",
          REQUIRED, low=5.0, high=100.0, workflows=_PULL),
    Field("graft_max_polar_deg", "system", float, "deg", "Pull-off with OTS: chains are grafted on dome "
          "silanols within this polar angle of the apex (chains point along the pulling axis).", 60.0,
          low=10.0, high=80.0, workflows=_PULL),
    Field("droplet_radius_A", "both", float, "A", "Contact angle: equivalent radius R0 of the droplet (its "
          "cross-section holds as much water as a circle of radius R0).", REQUIRED, low=8.0, high=200.0,
          workflows=_CA),
    Field("droplet_initial_angle_deg", "system", float, "deg", "Contact angle: the droplet starts as a "
          "cylindrical cap with this angle on the substrate (90 = half-cylinder); start near the expected angle.",
          90.0, low=10.0, high=170.0, workflows=_CA),
    Field("water_model", "system", str, "", "Water model; one model throughout a calibration (the contact "
          "angles and gamma_lv must come from the same water).", "spce", choices=("spce",), workflows=_CA + _ST + _TI),
    # ---------------------------------------------------------------- fidelity: numerics shared by all
    Field("timestep_fs", "fidelity", float, "fs", "MD timestep.", REQUIRED, low=0.1, high=4.0),
    Field("thermostat", "fidelity", str, "", "NVT thermostat.", "nose-hoover", choices=THERMOSTATS),
    Field("thermostat_damping_fs", "fidelity", float, "fs", "Thermostat relaxation time.", 100.0, low=1.0,
          high=1e5),
    Field("minimize_steps", "fidelity", int, "1", "FIRE minimisation iterations before dynamics (builds start "
          "strained).", 1000, low=0, high=1_000_000),
    Field("equilibrate_steps", "fidelity", int, "steps", "NVT steps discarded before sampling.", REQUIRED,
          low=0, high=100_000_000),
    Field("sample_steps", "fidelity", int, "steps", "NVT steps sampled.", REQUIRED, low=1, high=1_000_000_000,
          workflows=_ADH + _CA + _ST),
    Field("sample_interval", "fidelity", int, "steps", "Steps between stored samples.", REQUIRED, low=1,
          high=1_000_000),
    Field("frame_interval", "fidelity", int, "steps", "Steps between stored configurations (density maps and "
          "profiles); a multiple of sample_interval.", None, low=1, high=1_000_000, workflows=_CA + _ST),
    Field("chunk_steps", "fidelity", int, "steps", "Steps per chunk: samples are appended and a restart file "
          "written after every chunk (the unit of --resume and of the progress bar); a multiple of "
          "sample_interval.", REQUIRED, low=1, high=100_000_000),
    Field("seed", "fidelity", int, "1", "Base random seed (structure, velocities, Langevin noise derive from "
          "it).", 1, low=1, high=900_000_000),
    Field("cutoff_A", "fidelity", float, "A", "Lennard-Jones and real-space Coulomb cutoff.", 12.0, low=6.0,
          high=20.0),
    Field("kspace_accuracy", "fidelity", float, "1", "PPPM relative force accuracy.", 1e-5, low=1e-8,
          high=1e-3),
    Field("n_blocks", "fidelity", int, "1", "Blocks of the block-wise fits (contact-angle maps: the most, fewer "
          "when the droplet's shape decorrelates fewer times; density profiles); time-series errors use the "
          "statistical inefficiency instead (md.analysis.timeseries_stats).",
          5, low=2, high=1000),
    # ---------------------------------------------------------------- fidelity: adhesion
    Field("nx", "fidelity", int, "cells", "Surface cells along x (cristobalite (001): 7.16 A; (111): 5.06 A).",
          REQUIRED, low=1, high=200, workflows=_ADH + _CA + _TI),
    Field("ny", "fidelity", int, "cells", "Surface cells along y ((001): 7.16 A; (111): 8.77 A).", REQUIRED,
          low=1, high=200, workflows=_ADH + _CA + _TI),
    Field("slab_thickness_A", "fidelity", float, "A", "Silica slab thickness (outermost Si planes).", REQUIRED,
          low=2.0, high=200.0, workflows=_ADH + _CA + _TI),
    Field("free_energy", "fidelity", str, "", "Adhesion: 'pmf' also integrates the mean force between the "
          "slabs over separation (free energy of separation, hence T dS); 'none' reports the energy only.",
          "none", choices=("none", "pmf"), workflows=_ADH),
    Field("pmf_windows", "fidelity", int, "1", "Adhesion, free_energy = 'pmf': windows from contact outwards "
          "(quadratically spaced from contact to separation_A, dense near contact); each starts from its "
          "inner neighbour's last state (a chain).", 12, low=2, high=200, workflows=_ADH),
    Field("pmf_compress_windows", "fidelity", int, "1", "Adhesion PMF: windows pressed into the contact "
          "(uniformly spaced down to -pmf_compress_A, a chain from the contact window inwards), so the mean "
          "force turns repulsive and the bottom of the adhesive well lies inside the grid.", 4, low=0, high=100,
          workflows=_ADH),
    Field("pmf_compress_A", "fidelity", float, "A", "Adhesion PMF: how far the innermost window is pressed "
          "into the contact.", 2.0, low=0.1, high=10.0, workflows=_ADH),
    Field("lateral_registries", "fidelity", int, "1", "Adhesion PMF: lateral offsets of the upper slab (a "
          "rank-1 lattice over one surface cell, the first at zero); each has its own chain of windows; the "
          "force curves are averaged and their spread enters the error.", 1, low=1, high=16, workflows=_ADH),
    Field("registry_sampling", "fidelity", str, "", "Adhesion PMF: how the lateral offsets are chosen. 'rank1' = "
          "the rank-1 lattice over the rectangular surface cell (k/n, {k g/n}); on the centred (111) cell some of its "
          "offsets are lattice translations of the slab (n = 2: the centring vector), which repeat registry 0 and "
          "are named in the notes. 'primitive' = quasi-random offsets (R2 sequence) over the primitive cell of the "
          "slab's own lateral lattice (found from the built slabs' heavy atoms), lattice translations and offsets "
          "closer than 1 A to another excluded.", "rank1", choices=("rank1", "primitive"), workflows=_ADH),
    Field("registry_contact_steps", "fidelity", int, "steps", "Adhesion PMF: steps of a zero-load contact leg of "
          "its own for every registry after the first (upper back rigid and free along z, as the contact leg), "
          "started from the contact leg's last state moved to the registry's offset; its window chain starts from "
          "it. 0 = the chain starts from the contact leg's last state directly (bare silica: lowered in "
          "minimisation steps).", 0, low=0, high=100_000_000, workflows=_ADH),
    Field("sam_anneal_steps", "fidelity", int, "steps", "Adhesion: steps of NVT at temperature_K of the two slabs "
          "apart (separation_A, backs held) before the contact is formed; its energy and mean chain tilt series "
          "are tested for a remaining linear drift. 0 = the slabs go from the builder into the contact leg.", 0,
          low=0, high=100_000_000, workflows=_ADH),
    Field("pmf_return", "fidelity", bool, "", "Adhesion PMF: after the outward chain reaches separation_A, a "
          "return chain through the same windows back into compression (each from its outer neighbour's last "
          "state); W_F out and back, their hysteresis, and W_F = their mean with half the hysteresis as a "
          "systematic error.", False, workflows=_ADH),
    Field("pmf_extra_windows_A", "fidelity", list, "A", "Adhesion PMF: separations from contact inserted into the "
          "outward grid (e.g. over the force peak); each strictly between 0 and separation_A and apart from the "
          "grid's own windows.", (), low=0.0, high=60.0, workflows=_ADH, item=float),
    Field("sam_stress", "fidelity", bool, "", "Adhesion: sample the SAM atoms' summed per-atom stress tensor (compute "
          "stress/atom) in every leg, so the compression windows give the layer's C13/C33 and Poisson ratio "
          "(md.analysis.stress_ratio_poisson). false = not sampled (the protocol of every committed run).", False,
          workflows=_ADH),
    Field("pmf_equilibrate_steps", "fidelity", int, "steps", "Adhesion PMF: steps per window discarded.", 1000,
          low=0, high=100_000_000, workflows=_ADH),
    Field("pmf_sample_steps", "fidelity", int, "steps", "Adhesion PMF: steps per window sampled.", 5000, low=1,
          high=100_000_000, workflows=_ADH),
    # ---------------------------------------------------------------- fidelity: pull-off
    Field("flat_nx", "fidelity", int, "cells", "Pull-off: flat cells along x; 0 = the asperity's holder size.",
          0, low=0, high=200, workflows=_PULL),
    Field("flat_ny", "fidelity", int, "cells", "Pull-off: flat cells along y; 0 = the asperity's holder size.",
          0, low=0, high=200, workflows=_PULL),
    Field("flat_thickness_A", "fidelity", float, "A", "Pull-off: thickness of the flat.", REQUIRED, low=2.0,
          high=200.0, workflows=_PULL),
    Field("holder_thickness_A", "fidelity", float, "A", "Pull-off: thickness of the asperity's holder slab.",
          REQUIRED, low=2.0, high=100.0, workflows=_PULL),
    Field("asperity_margin_A", "fidelity", float, "A", "Pull-off: holder extends this far beyond the dome on "
          "each side.", 10.0, low=2.0, high=100.0, workflows=_PULL),
    Field("initial_gap_A", "fidelity", float, "A", "Pull-off: gap between the apex and the flat at the start.",
          6.0, low=2.0, high=30.0, workflows=_PULL),
    Field("approach_distance_A", "fidelity", float, "A", "Pull-off: holder travel towards the flat.", REQUIRED,
          low=0.5, high=100.0, workflows=_PULL),
    Field("approach_speed_m_s", "fidelity", float, "m/s", "Pull-off: holder speed on approach.", REQUIRED,
          low=0.01, high=2000.0, workflows=_PULL),
    Field("hold_steps", "fidelity", int, "steps", "Pull-off: steps in contact at rest.", 0, low=0,
          high=100_000_000, workflows=_PULL),
    Field("retract_distance_A", "fidelity", float, "A", "Pull-off: holder travel away from the flat (beyond "
          "the cutoff so the curve returns to zero).", REQUIRED, low=0.5, high=200.0, workflows=_PULL),
    Field("retract_speeds_m_s", "fidelity", list, "m/s", "Pull-off: holder speeds on retraction; more than one "
          "(a rate scan, extrapolated to low rate from three or more) only at production, two at any fidelity "
          "with tip_positions > 1.", REQUIRED, low=0.01, high=2000.0,
          workflows=_PULL, item=float),
    Field("retract_repeats", "fidelity", int, "1", "Pull-off: independent retractions per speed, each from the "
          "held contact with fresh velocities and hold_steps more of holding; the pull-off force is their mean, "
          "its stderr their spread.", 1, low=1, high=20, workflows=_PULL),
    Field("tip_thermostat", "fidelity", str, "", "Pull-off: how the moving asperity is thermostatted. "
          "'comoving': its thermal motion only (compute temp/com bias: no drag on the asperity's motion); "
          "'none': the asperity runs NVE (only the flat is thermostatted); 'lab': the old lab-frame thermostat "
          "on every mobile atom (drags the asperity: ~gamma M v).", "comoving",
          choices=("comoving", "none", "lab"), workflows=_PULL),
    Field("flat_thermostat", "fidelity", str, "", "Pull-off: which of the flat's mobile atoms are thermostatted "
          "(in the lab frame). 'mobile': all of them, the OTS flat's SAM included, whose chain ends the tip drags "
          "along (Langevin friction m gamma v on every chain end that follows the tip, transmitted into the "
          "measured force); 'silica': only the flat's silica (Si, O, silanol H; the SAM, head groups included, "
          "runs NVE and exchanges heat through its bonds), so nothing the tip moves is thermostatted in the lab "
          "frame. With 'silica' (or tip_positions > 1) the thermostat force on the flat is measured as the tip's "
          "(Newton for the flat's mobile atoms) and reported.", "mobile", choices=("mobile", "silica"),
          workflows=_PULL),
    Field("tip_positions", "fidelity", int, "1", "Pull-off: lateral positions of the tip over the flat (the first "
          "at zero offset, the rest quasi-random, R2 sequence, over the primitive cell of the flat's surface "
          "lattice, lattice translations excluded); each has its own approach and hold (its own contact) and its "
          "own retractions at every speed, so the spread over positions includes the geometric variance. With "
          "more than one, up to two retraction speeds are allowed below production.", 1, low=1, high=16,
          workflows=_PULL),
    # ---------------------------------------------------------------- fidelity: contact angle
    Field("substrate_equilibrate_steps", "fidelity", int, "steps", "Contact angle: NVT steps of the substrate "
          "alone (minimised with nothing held, then its deep Si and bridging O held) before the droplet is "
          "placed: equilibrates the SAM / silanols the water lands on (W_SL by TI: before the film).", 1000,
          low=1, high=100_000_000, workflows=_CA + _TI),
    Field("bin_A", "fidelity", float, "A", "Contact angle / surface tension: bin size of density maps and "
          "profiles.", 1.0, low=0.1, high=10.0, workflows=_CA + _ST),
    # ---------------------------------------------------------------- fidelity: surface tension
    Field("lx_A", "fidelity", float, "A", "Surface tension: water film box x.", REQUIRED, low=10.0, high=500.0,
          workflows=_ST),
    Field("ly_A", "fidelity", float, "A", "Surface tension: water film box y.", REQUIRED, low=10.0, high=500.0,
          workflows=_ST),
    Field("film_thickness_A", "fidelity", float, "A", "Surface tension / W_SL by TI: water film thickness.",
          REQUIRED, low=8.0, high=500.0, workflows=_ST + _TI),
    Field("vacuum_A", "fidelity", float, "A", "Surface tension: vacuum above and below the film.", 25.0,
          low=10.0, high=500.0, workflows=_ST),
    # ---------------------------------------------------------------- fidelity: W_SL by thermodynamic integration
    Field("ti_charge_nodes", "fidelity", int, "1", "W_SL by TI: Gauss-Legendre nodes of the charge stage (the "
          "solid's charges scaled 1 -> 0; run on the film and on the solid alone).", 5, low=1, high=32,
          workflows=_TI),
    Field("ti_lj_nodes", "fidelity", int, "1", "W_SL by TI: Gauss-Legendre nodes of the dispersion stage (the "
          "solid-water Lennard-Jones pairs switched off through a soft core).", 7, low=1, high=32, workflows=_TI),
    Field("ti_equilibrate_steps", "fidelity", int, "steps", "W_SL by TI: steps per node discarded (each node "
          "continues from the previous one).", 1000, low=0, high=100_000_000, workflows=_TI),
    Field("ti_sample_steps", "fidelity", int, "steps", "W_SL by TI: steps per node sampled (dU/dlambda every "
          "sample_interval steps).", 5000, low=1, high=100_000_000, workflows=_TI),
)


def _fields(section: str, workflow: str) -> dict[str, RecipeField]:
    out: dict[str, RecipeField] = {}
    for f in FIELDS:
        if workflow not in f.workflows:
            continue
        if f.section == section or (f.section == "both" and section == "system"):
            out.setdefault(f.key, f)
    if section == "fidelity":     # 'both' keys may be overridden per fidelity (their fidelity Field if any)
        for f in FIELDS:
            if f.section == "both" and workflow in f.workflows:
                out.setdefault(f.key, replace(f, section="fidelity", default=None))
    return out


class RecipeSettings:
    """What every workflow's settings dataclass is (:data:`SETTINGS_CLASSES`): a recipe's resolved settings at one
    fidelity, one typed attribute per key. A workflow receives this object from the engine, built once
    (:meth:`Recipe.typed_settings`)."""
    __slots__ = ()


def _settings_dataclass(workflow: str) -> type:
    members: dict[str, RecipeField] = {}
    for section in ("system", "fidelity"):
        for key, f in _fields(section, workflow).items():
            members.setdefault(key, f)
    title = "".join(part.title() for part in workflow.split("_"))
    return fields.frozen_dataclass(
        f"{title}Settings", list(members.items()), module=__name__, bases=(RecipeSettings,),
        doc=f"The resolved settings of a recipe of the {workflow!r} workflow at one fidelity "
            "([system] overlaid with the fidelity's "
            "table; `Recipe.typed_settings`), in the recipe's units (file units: Å, fs, K).")


#: One frozen settings dataclass per workflow, generated from the key declarations (module attributes, so that
#: pickle finds them): AdhesionSettings, PulloffSettings, ContactAngleSettings, SurfaceTensionSettings.
SETTINGS_CLASSES: dict[str, type] = {w: _settings_dataclass(w) for w in WORKFLOWS}
globals().update({cls.__name__: cls for cls in SETTINGS_CLASSES.values()})


def settings_class(workflow: str) -> type:
    """The frozen settings dataclass of `workflow` (its keys' declarations give each attribute's type, default,
    unit and doc)."""
    return SETTINGS_CLASSES[workflow]


def _check(f: RecipeField, path: str, value: Any, origin: str) -> Any:
    return f.check(value, origin, error=RecipeError, name=path)


def _unknown(path: str, allowed: Mapping[str, Field], workflow: str | None) -> str:
    other = sorted({f.key for f in FIELDS if f.key == path.rsplit(".", 1)[-1]} - set(allowed))
    hint = (f" ({other[0]!r} belongs to another workflow, not {workflow!r})" if other and workflow else "")
    return f"unknown key{hint}; keys allowed here: {', '.join(sorted(allowed))}"


@dataclass(frozen=True)
class Recipe:
    """A validated recipe. ``system`` and each ``fidelity[name]`` hold every key with defaults filled in."""
    name: str
    workflow: str
    description: str
    system: Mapping[str, Any]
    fidelity: Mapping[str, Mapping[str, Any]]
    path: Path | None = None
    file_sha256: str = ""
    raw: Mapping[str, Any] = field(default_factory=dict)

    def settings(self, fidelity: str) -> dict[str, Any]:
        """System values overlaid with the fidelity table (fidelity wins for the 'both' keys set there)."""
        if fidelity not in self.fidelity:
            raise RecipeError("fidelity", fidelity, f"must be one of {', '.join(FIDELITIES)}", self.origin)
        merged = dict(self.system)
        for k, v in self.fidelity[fidelity].items():
            if v is not None or k not in merged:
                merged[k] = v
        return merged

    @property
    def origin(self) -> str:
        return str(self.path) if self.path else self.name

    def typed_settings(self, fidelity: str) -> RecipeSettings:
        """`settings(fidelity)` as the workflow's frozen settings dataclass (`settings_class`): attributes typed,
        documented and defaulted from the key declarations, e.g. ``recipe.typed_settings("quick").timestep_fs``."""
        return settings_class(self.workflow)(**self.settings(fidelity))

    def canonical(self, fidelity: str) -> dict[str, Any]:
        """What defines a run at ``fidelity``: workflow, name and the resolved settings (comments, key order
        and the other fidelity tables do not matter), less the keys that do not apply to this system
        (:data:`CONDITIONAL_KEYS`) and the protocol options at their neutral value (:data:`NEUTRAL_KEYS`)."""
        settings = self.settings(fidelity)
        for key, (when, value) in CONDITIONAL_KEYS.get(self.workflow, {}).items():
            if settings.get(when) != value:
                settings.pop(key, None)
        for key, neutral in NEUTRAL_KEYS.get(self.workflow, {}).items():
            if key in settings and _is_neutral(settings[key], neutral):
                settings.pop(key)
        return {"name": self.name, "workflow": self.workflow, "fidelity": fidelity, "settings": settings}

    def canonical_sha256(self, fidelity: str) -> str:
        text = json.dumps(self.canonical(fidelity), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


def _is_neutral(value: Any, neutral: Any) -> bool:
    """``value`` equals the neutral value; a list and a tuple with the same items are equal (a list key read from
    TOML is a list, its default a tuple)."""
    if isinstance(value, (list, tuple)) and isinstance(neutral, (list, tuple)):
        return list(value) == list(neutral)
    return value == neutral


def parse_recipe(table: Mapping[str, Any], *, name: str = "recipe", origin: str = "", path: Path | None = None,
                 file_sha256: str = "") -> Recipe:
    """Validate a recipe table (as read from TOML); raises :class:`RecipeError` on the first problem."""
    table = dict(table)
    top = {f.key: f for f in FIELDS if f.section == "top"}
    wf = table.get("workflow", REQUIRED)
    if wf is REQUIRED:
        raise RecipeError("workflow", None, f"is required: {top['workflow'].allowed()}", origin)
    wf = _check(top["workflow"], "workflow", wf, origin)
    sys_fields = _fields("system", wf)
    fid_fields = _fields("fidelity", wf)
    for key, value in table.items():
        if key in ("system", "fidelity"):
            if not isinstance(value, dict):
                raise RecipeError(key, value, "must be a table", origin)
            continue
        if key not in top:
            raise RecipeError(key, value, _unknown(key, {**top, "system": None, "fidelity": None}, wf), origin)
    rname = _check(top["name"], "name", table["name"], origin) if "name" in table else name
    desc = _check(top["description"], "description", table.get("description", ""), origin)

    def section(values: Mapping[str, Any], fields: Mapping[str, Field], prefix: str) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for key, value in values.items():
            path_ = f"{prefix}.{key}"
            if key not in fields:
                if isinstance(value, dict):
                    raise RecipeError(path_, "{...}", _unknown(path_, fields, wf), origin)
                raise RecipeError(path_, value, _unknown(path_, fields, wf), origin)
            out[key] = _check(fields[key], path_, value, origin)
        for key, f in fields.items():
            if key not in out:
                if f.default is REQUIRED:
                    raise RecipeError(f"{prefix}.{key}", None, f"is required: {f.allowed()}", origin)
                out[key] = f.default
        return out

    system = section(table.get("system", {}), sys_fields, "system")
    fid_table = table.get("fidelity", {})
    for key in fid_table:
        if key not in FIDELITIES:
            raise RecipeError(f"fidelity.{key}", "{...}", f"unknown fidelity; allowed: {', '.join(FIDELITIES)}",
                              origin)
    fidelity: dict[str, dict[str, Any]] = {}
    for fname in FIDELITIES:
        if fname not in fid_table:
            raise RecipeError(f"fidelity.{fname}", None, "is required: every recipe sizes smoke, quick and "
                              "production", origin)
        if not isinstance(fid_table[fname], dict):
            raise RecipeError(f"fidelity.{fname}", fid_table[fname], "must be a table", origin)
        fidelity[fname] = section(fid_table[fname], fid_fields, f"fidelity.{fname}")
        _cross_check(wf, system, fidelity[fname], fname, origin)
    return Recipe(name=rname, workflow=wf, description=desc, system=MappingProxyType(system),
                  fidelity=MappingProxyType({k: MappingProxyType(v) for k, v in fidelity.items()}), path=path,
                  file_sha256=file_sha256, raw=MappingProxyType(dict(table)))


#: the deepest rigid step one compression window may take from its neighbour (A): a rigid step of several A into
#: two OTS SAMs overlaps their chains (LAMMPS stops at the first step with "Bond atoms missing").
MAX_COMPRESS_STEP_A = 1.0


def _cross_check(wf: str, system: Mapping[str, Any], fid: Mapping[str, Any], fname: str, origin: str) -> None:
    p = f"fidelity.{fname}"
    if fid["chunk_steps"] % fid["sample_interval"]:
        raise RecipeError(f"{p}.chunk_steps", fid["chunk_steps"],
                          f"must be a multiple of sample_interval = {fid['sample_interval']}", origin)
    fi = fid.get("frame_interval")
    if fi is not None and fi % fid["sample_interval"]:
        raise RecipeError(f"{p}.frame_interval", fi,
                          f"must be a multiple of sample_interval = {fid['sample_interval']}", origin)
    if wf == "adhesion" and system["separation_A"] <= fid["cutoff_A"] + 2.0:
        raise RecipeError("system.separation_A", system["separation_A"],
                          f"must exceed the cutoff + 2 A = {fid['cutoff_A'] + 2.0:g} A of {p} (separated slabs "
                          f"must not interact through the Lennard-Jones term)", origin)
    if wf == "adhesion" and fid["free_energy"] == "pmf" and fid["pmf_compress_windows"] >= 1:
        step = fid["pmf_compress_A"] / fid["pmf_compress_windows"]
        if step > MAX_COMPRESS_STEP_A:
            need = math.ceil(fid["pmf_compress_A"] / MAX_COMPRESS_STEP_A)
            raise RecipeError(f"{p}.pmf_compress_A", fid["pmf_compress_A"],
                              f"over pmf_compress_windows = {fid['pmf_compress_windows']} presses {step:g} A per "
                              f"window; allowed <= {MAX_COMPRESS_STEP_A:g} A (each window moves the slab rigidly "
                              f"from its neighbour: 4 A at once overlapped OTS chains and LAMMPS lost bond atoms); "
                              f"use pmf_compress_windows >= {need} or a smaller pmf_compress_A", origin)
    if wf == "adhesion":
        _check_extra_windows(system, fid, p, origin)
    if wf == "pulloff":
        speeds = fid["retract_speeds_m_s"]
        allowed = 2 if fid["tip_positions"] > 1 else 1
        if len(speeds) > allowed and fname != "production":
            raise RecipeError(f"{p}.retract_speeds_m_s", speeds,
                              "a rate scan (more than one speed) is run only at production; give one speed (two "
                              "with tip_positions > 1)", origin)
        if fid["flat_thermostat"] == "silica" and fid["tip_thermostat"] == "lab":
            raise RecipeError(f"{p}.flat_thermostat", fid["flat_thermostat"], "'silica' needs tip_thermostat "
                              "'comoving' or 'none' ('lab' thermostats every mobile atom together)", origin)
        if len(set(speeds)) != len(speeds):
            raise RecipeError(f"{p}.retract_speeds_m_s", speeds, "speeds must be distinct", origin)
    if wf == "contact_angle" and system["surface"] == "ots" and fid["nx"] < 2:
        raise RecipeError(f"{p}.nx", fid["nx"], "must be >= 2", origin)


def _check_extra_windows(system: Mapping[str, Any], fid: Mapping[str, Any], p: str, origin: str) -> None:
    """Extra PMF windows lie strictly inside the outward grid and at least 0.05 A from its windows and each other
    (two windows at one separation would be one window sampled twice)."""
    extra = sorted(fid["pmf_extra_windows_A"])
    sep, n = system["separation_A"], fid["pmf_windows"]
    grid = [sep * (k / (n - 1)) ** 2 for k in range(n)]
    for k, d in enumerate(extra):
        if not 0.0 < d < sep:
            raise RecipeError(f"{p}.pmf_extra_windows_A", list(extra), f"{d:g} must lie strictly between 0 and "
                              f"separation_A = {sep:g} A", origin)
        near = min(abs(d - g) for g in grid + extra[:k] + extra[k + 1:])
        if near < 0.05:
            raise RecipeError(f"{p}.pmf_extra_windows_A", list(extra), f"{d:g} A lies within 0.05 A of another "
                              f"window (grid {', '.join(f'{g:.2f}' for g in grid)} A)", origin)


def load_recipe(spec: str | Path) -> Recipe:
    """A recipe from a path, or a name in ``inputs/md`` (``adhesion_silica`` -> inputs/md/adhesion_silica.toml)."""
    try:
        p = shipped_data.find("md", spec, key="recipe")
    except DataNotFound as exc:
        raise RecipeError("recipe", str(spec), exc.allowed) from None
    data = p.read_bytes()
    try:
        table = tomllib.loads(data.decode())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise RecipeError("recipe", str(p), f"is not valid TOML ({exc})") from None
    return parse_recipe(table, name=p.stem, origin=str(p), path=p.resolve(),
                        file_sha256=hashlib.sha256(data).hexdigest())


_WHERE = {"top": "top level", "system": "[system]", "fidelity": "[fidelity.*]", "both": "[system], [fidelity.*]"}


def schema_markdown() -> str:
    """The schema as a markdown table (generated for docs/md.md, so it cannot drift)."""
    return fields.markdown_table(FIELDS, [
        ("key", lambda f: f"`{f.key}`"), ("where", lambda f: _WHERE[f.section]),
        ("workflows", lambda f: "all" if f.workflows == ALL else ", ".join(f.workflows)),
        ("type", RecipeField.type_name), ("unit", lambda f: f.unit), ("allowed", RecipeField.allowed),
        ("default", RecipeField.default_text), ("meaning", lambda f: f.doc)])


def json_schema() -> dict:
    """JSON Schema of an MD recipe file: top-level keys, [system] and [fidelity.smoke|quick|production]. Keys of
    every workflow are listed (each key's description names its workflows); the loader also refuses a key of
    another workflow and checks the cross-key rules."""
    def doc(f: RecipeField) -> RecipeField:
        wfs = "all workflows" if f.workflows == ALL else "workflows: " + ", ".join(f.workflows)
        return replace(f, doc=f"{f.doc} ({wfs})")

    pairs = [(f.key, doc(f)) for f in FIELDS if f.section == "top"]
    pairs += [(f"system.{f.key}", replace(doc(f), default=None)) for f in FIELDS if f.section in ("system", "both")]
    for name in FIDELITIES:
        seen = set()
        for f in FIELDS:
            if f.section in ("fidelity", "both") and f.key not in seen:
                seen.add(f.key)
                pairs.append((f"fidelity.{name}.{f.key}", replace(doc(f), default=None)))
    return fields.json_schema(pairs, title="nanoimpact MD recipe",
                              description="An MD recipe (inputs/md/*.toml; lengths in angstrom, times in fs or steps, "
                                          "temperatures in K). See docs/md.md.")


if __name__ == "__main__":  # python -m md.recipe -> the table for docs/md.md
    print(schema_markdown())
