"""The workflows by name (a recipe's ``workflow`` key)."""
from __future__ import annotations

from md.workflows.adhesion import Adhesion
from md.workflows.common import Workflow
from md.workflows.contact_angle import ContactAngleWorkflow
from md.workflows.pulloff import PullOff
from md.workflows.surface_tension import SurfaceTension
from md.workflows.wsl_ti import WslTI

__all__ = ["WORKFLOWS", "get_workflow"]

WORKFLOWS: dict[str, type[Workflow]] = {"adhesion": Adhesion, "pulloff": PullOff,
                                        "contact_angle": ContactAngleWorkflow, "surface_tension": SurfaceTension,
                                        "wsl_ti": WslTI}


def get_workflow(name: str) -> Workflow:
    try:
        return WORKFLOWS[name]()
    except KeyError:
        raise KeyError(f"unknown workflow {name!r}; known: {sorted(WORKFLOWS)}") from None
