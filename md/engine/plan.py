"""What a workflow hands the engine: the plan data model (a leaf: it imports nothing of md).

Vocabulary
    A *run* is one recipe at one fidelity (a :class:`Job`). It consists of *legs* (separate LAMMPS simulations:
    the contact and the separated slabs, one PMF window, one retraction speed, ...), run one after the other, or
    with ``jobs`` > 1 each as soon as the legs it reads from (:attr:`Leg.after`) are done. A
    leg is a list of *stages* (equilibrate, sample, approach, hold, retract) run in *chunks* of ``chunk_steps``.
    A workflow is anything with ``plan(settings, run_dir) -> Plan`` and ``analyse(ctx) -> Analysis``
    (:class:`Planner`); the engine never imports one.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Protocol, Sequence

import numpy as np

__all__ = ["Stage", "Frames", "Leg", "Plan", "Analysis", "Job", "Planner", "id_ranges", "leg_dependencies"]


@dataclass(frozen=True)
class Stage:
    """``steps`` MD steps; ``begin`` commands are issued once when the stage starts (never on resume: velocities
    are in the restart); ``sampled`` marks the stages whose samples the analysis uses (all are stored)."""
    name: str
    steps: int
    begin: tuple[str, ...] = ()
    sampled: bool = True


@dataclass(frozen=True)
class Frames:
    """Configurations of ``group`` (ids and x y z in A) stored every ``interval`` steps of sampled stages."""
    group: str
    interval: int


@dataclass
class Leg:
    """One LAMMPS simulation.

    ``fresh(leg_dir)``: commands that create the system (styles, ``read_data`` or ``read_restart`` of another
    leg, pair coefficients, k-space, groups); ``define(step)``: computes, variables and fixes, issued after every
    (re)start (``step`` is the absolute step, to vary Langevin seeds between restarts); ``prepare(leg_dir)``:
    issued once after ``define`` on a fresh start (minimise, write the minimised structure, ``reset_timestep
    0``); ``restart_head(path)``: what to issue instead of ``fresh`` when continuing from ``path`` (read_restart
    plus the settings a restart file does not hold: k-space, neighbour lists).
    ``columns``: sample name -> LAMMPS ``fix ave/time`` argument (``v_pe``, ``c_gg[3]``).
    """
    name: str
    fresh: Callable[[Path], list[str]]
    define: Callable[[int], list[str]]
    prepare: Callable[[Path], list[str]]
    restart_head: Callable[[Path], list[str]]
    stages: list[Stage]
    columns: dict[str, str]
    sample_interval: int
    chunk_steps: int
    n_atoms: int
    frames: Frames | None = None
    info: dict[str, Any] = field(default_factory=dict)
    #: names of the legs whose output this leg reads (a restart, a minimised structure); ``None``: every earlier
    #: leg, the safe default for a workflow that does not say. With ``jobs`` > 1 the engine starts a leg as soon
    #: as these are done (:func:`leg_dependencies`).
    after: tuple[str, ...] | None = None

    @property
    def total_steps(self) -> int:
        return int(sum(s.steps for s in self.stages))

    def stage_at(self, step: int) -> tuple[int, int, int]:
        """(stage index, stage start, stage end) of the stage that runs the step after ``step``."""
        start = 0
        for k, s in enumerate(self.stages):
            if step < start + s.steps:
                return k, start, start + s.steps
            start += s.steps
        return len(self.stages), start, start


def leg_dependencies(legs: Sequence[Leg]) -> dict[str, frozenset[str]]:
    """Leg name -> the names it must wait for: its ``after``, or every earlier leg where ``after`` is None. A leg
    may wait only for legs planned before it (so the plan's order is always a valid sequential order); a name
    that is unknown or later raises ValueError naming both legs."""
    out: dict[str, frozenset[str]] = {}
    for k, leg in enumerate(legs):
        if leg.name in out:
            raise ValueError(f"plan: leg name {leg.name!r} appears twice")
        if leg.after is None:
            out[leg.name] = frozenset(l.name for l in legs[:k])
            continue
        for name in leg.after:
            if name not in out:
                raise ValueError(f"plan: leg {leg.name!r} waits for {name!r}, which is not a leg planned before it")
        out[leg.name] = frozenset(leg.after)
    return out


@dataclass
class Plan:
    """What a workflow wants run: its legs (in order), the LAMMPS timestep and facts for result.json."""
    legs: list[Leg]
    timestep_fs: float
    n_atoms: int
    seeds: dict[str, int]
    forcefield_files: list[str]
    system_info: dict[str, Any] = field(default_factory=dict)


@dataclass
class Analysis:
    """What a workflow returns: SI quantities ({name: {value, stderr, units}}), curves (CSV name -> (columns,
    rows)), figures (PNG name -> function(path)), notes, and anything else worth keeping (``details``)."""
    quantities: dict[str, dict[str, Any]]
    curves: dict[str, tuple[list[str], np.ndarray]] = field(default_factory=dict)
    figures: dict[str, Callable[[Path], None]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Job:
    """One run as the engine sees it (:func:`md.workflows.job_for` makes it from a recipe): what names it, what
    its hash covers, what ``result.json`` records.

    ``settings`` is the workflow's typed settings object (``Recipe.typed_settings``), built once and handed to
    the workflow's ``plan`` and ``analyse`` as it is; ``settings_record`` the same resolved settings as the
    recipe's mapping (its key order), which ``result.json`` records. ``canonical`` is the recipe's resolved content
    at ``fidelity`` (``Recipe.canonical``); ``source`` the recipe file (or name), ``file_sha256`` its bytes' hash,
    ``content_sha256`` the hash of ``canonical``; ``workflow_version`` (the workflow's protocol version) enters the
    run hash."""
    name: str
    workflow: str
    description: str
    fidelity: str
    settings: Any
    settings_record: Mapping[str, Any]
    canonical: Mapping[str, Any]
    forcefield_files: tuple[str, ...]
    workflow_version: int = 1
    source: str = ""
    file_sha256: str = ""
    content_sha256: str = ""


class Planner(Protocol):
    """The engine's view of a workflow."""

    def plan(self, settings: Any, run_dir: Path) -> Plan: ...

    def analyse(self, ctx: Any) -> Analysis: ...


def id_ranges(indices: Sequence[int]) -> str:
    """0-based atom indices -> LAMMPS ``group ID id`` arguments with ranges (1-based): '1:40 45 47:50'."""
    ids = np.unique(np.asarray(indices, int)) + 1
    if not len(ids):
        return ""
    out, start, prev = [], ids[0], ids[0]
    for i in ids[1:]:
        if i == prev + 1:
            prev = i
            continue
        out.append(f"{start}:{prev}" if prev > start else f"{start}")
        start = prev = i
    out.append(f"{start}:{prev}" if prev > start else f"{start}")
    return " ".join(out)
