"""The five MD workflows -- work of adhesion, asperity pull-off, contact angle, liquid-vapour surface tension, W_SL by
thermodynamic integration -- and the front door :func:`run_recipe`.

One module per workflow (:mod:`~md.workflows.adhesion`, :mod:`~md.workflows.pulloff`,
:mod:`~md.workflows.contact_angle`, :mod:`~md.workflows.surface_tension`, :mod:`~md.workflows.wsl_ti`), each
declaring the quantities it yields
(``Workflow.yields``); what they share is :mod:`~md.workflows.common`, the names :mod:`~md.workflows.registry`, the
front door :mod:`~md.workflows.facade`.

What they have in common (the three steps of a workflow, the LAMMPS set-up) is in :mod:`~md.workflows.common`.

The workflows (each module's docstring says what it builds, runs and measures):

``adhesion``         two slabs in contact and separated: dE/A, and the free energy by force integration
``pulloff``          a hemispherical asperity retracted from a flat: pull-off force (validation)
``contact_angle``    a cylindrical droplet on silica or OTS: the angle at the water's plane, W_SL, or "wets"
``surface_tension``  a free-standing water film: gamma_lv from the pressure tensor, with the LJ tail
``wsl_ti``           a water film decoupled from silica or OTS: W_SL by thermodynamic integration, theta or "wets"
"""
from md.workflows.common import ENERGY_NOT_FREE_ENERGY, Workflow
from md.workflows.facade import MDResult, job_for, run_hash, run_recipe
from md.workflows.registry import WORKFLOWS, get_workflow

__all__ = ["get_workflow", "WORKFLOWS", "Workflow", "ENERGY_NOT_FREE_ENERGY", "MDResult", "run_recipe", "run_hash",
           "job_for"]
