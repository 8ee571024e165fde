"""nanoimpact molecular layer, by job: ``build`` (structures), ``system`` (topology, force fields, LAMMPS data
files), ``engine`` (plans, the run store and the LAMMPS engines), ``workflows`` (the MD workflows and the
front door), ``analysis`` (what the runs measure); SI at the edges, every unit through :mod:`md.units`.

This module is md's public face: what other packages (calibration) use, each name imported from its module on
first use, so ``import md`` stays light.

Running: ``md.run_recipe(recipe, fidelity)`` runs a recipe (or reuses its cached result) and returns an
:class:`md.workflows.MDResult`; ``run_hash`` is the hash a run would have, ``run_dir_for`` its cache folder,
``version_differences``/``describe_differences`` how a result's versions differ from the running ones.
Recipes: ``load_recipe``, ``FIDELITIES``, ``json_schema``. Analysis used downstream: the flat-slab range, the
registry consistency, the SAM layer's modulus records, the pull-off speed extrapolation, the Tabor parameter and
the silica E* it uses; ``chain_geometry`` (the OTS chain's builder geometry); ``CRISTOBALITE_A`` (the builder's
idealised lattice constant).
"""
from __future__ import annotations

import importlib

#: public name -> the module that defines it
_PUBLIC = {
    "run_recipe": "md.workflows.facade", "run_hash": "md.workflows.facade", "MDResult": "md.workflows.facade",
    "run_dir_for": "md.engine.store",
    "version_differences": "md.engine.provenance", "describe_differences": "md.engine.provenance",
    "load_recipe": "md.recipe", "FIDELITIES": "md.recipe", "json_schema": "md.recipe",
    "flat_slab_range": "md.analysis.adhesion", "registry_consistency": "md.analysis.adhesion",
    "poisson_spread": "md.analysis.layer_modulus", "small_strain_layer_record": "md.analysis.layer_modulus",
    "tilt_of_anneal": "md.analysis.layer_modulus", "young_from_confined": "md.analysis.layer_modulus",
    "paired_speed_extrapolation": "md.analysis.pulloff", "tabor_parameter": "md.analysis.pulloff",
    "SILICA_E_STAR_PA": "md.analysis.pulloff",
    "chain_geometry": "md.build.sam", "CRISTOBALITE_A": "md.build.silica",
}

__all__ = sorted(_PUBLIC)


def __getattr__(name: str):
    if name in _PUBLIC:
        return getattr(importlib.import_module(_PUBLIC[name]), name)
    raise AttributeError(f"module 'md' has no attribute {name!r}")
