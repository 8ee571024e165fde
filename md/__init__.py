"""nanoimpact molecular layer, by job: ``build`` (structures), ``system`` (topology, force fields, LAMMPS data
files), ``engine`` (plans, the run store and the LAMMPS engines), ``workflows`` (the four MD workflows and the
front door), ``analysis`` (what the runs measure); SI at the edges, every unit through :mod:`md.units`.

``md.run_recipe(recipe, fidelity)`` runs a recipe and returns an :class:`md.workflows.MDResult` (imported on
first use, so ``import md`` stays light).
"""
from __future__ import annotations

__all__ = ["run_recipe", "MDResult"]


def __getattr__(name: str):
    if name in __all__:
        from md.workflows import facade
        return getattr(facade, name)
    raise AttributeError(f"module 'md' has no attribute {name!r}")
