"""Run an ensemble of discrete summit realisations of one rough scene on an executor.

    >>> from continuum import load_scene
    >>> from continuum.dynamics.ensemble_run import run_ensemble
    >>> ens = run_ensemble(load_scene("rough_silica", params="calibrated"), members=64, seed=1, executor="processes")
    >>> ens.stick_probability, ens.stick_probability_first_impact, ens.rebound_counts()

The decisions that do not depend on the realisation (adhesion law, half-space, the summits' modulus and work of
adhesion, the footprint strip) are made once, from the scene's regime, exactly as a single discrete run makes
them (`continuum.model.select`); each member then only draws its summits (`continuum.laws.discrete_roller`, a few
ms) and runs the event-driven driver (on a rigid substrate each contact runs in the compiled kernel,
`continuum.numerics.kernel_laws.LAW_DISCRETE`). A run ends where the driver ends it: a member held by adhesion stops
at 'stuck'. Members go to `nanoimpact.executors` (local, processes, dask): jobs are module-level and picklable.

Every member is an independent realisation of the whole strip under the roller: a Poisson number of summits at
uniform positions with heights drawn from a distribution. Where the scene names a height map, the map supplies
that distribution's statistics (sigma_s, eta, beta at the cutoff, and for the `empirical_gpd` tail model its own
summit heights with a fitted extreme-value tail, `continuum.rough.tail`), never copies of itself: a 0.5 um scan
repeated along a 3.3 mm roller would put thousands of copies of each summit at one x, all touching at once.
`members = "auto"` grows the ensemble in batches until the Wilson interval of its stick probabilities is narrow
enough (`auto_members`). The runs a measured map adds (the other tail model, the cutoff band) are
`continuum.dynamics.map_ensembles`'.
"""
from __future__ import annotations

import logging
import time
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Any

from ..model.regime import Regime
from ..output.proportions import wilson_half_width
from ..rough.ensemble import EnsembleResult, MemberOutcome, member_seeds
from ..scene import ResolvedScene, Scene, SceneError
from .driver import DriverSettings, simulate

log = logging.getLogger(__name__)

#: Relative bracket width of a member's escape velocity: the paper's sampled claims bisect theirs to the same
#: width (continuum.paper.samples.ESCAPE_REL_TOL); result.json -> ensemble -> escape_velocity states it beside
#: the members' spread.
ESCAPE_REL_TOL = 1e-3
#: Halvings or doublings of the first-impact speed tried to bracket a member's escape velocity (a factor 2^40).
MAX_ESCAPE_BRACKET_STEPS = 40
#: Members added per batch by `members = "auto"` (the first batch too): 0/32 already has a Wilson half-width of
#: 0.054, so a clear-cut outcome stops after one or two batches.
AUTO_BATCH = 32


def with_realisation(scene: Scene, mode: str, seed: int | None = None) -> Scene:
    """`scene` with surfaces.roughness.mode (and seed) replaced."""
    rough = scene.surfaces.roughness
    rough = replace(rough, mode=mode) if seed is None else replace(rough, mode=mode, seed=int(seed))
    return replace(scene, surfaces=replace(scene.surfaces, roughness=rough))


def first_impact_only(scene: Scene) -> Scene:
    """`scene` run to its first rebound only (numerics.max_bounces = 1): what a tail model's or a cutoff's
    ensemble reports is the first impact, whose outcome no numerical cap censors."""
    return replace(scene, numerics=replace(scene.numerics, max_bounces=1))


@dataclass(frozen=True)
class MemberPlan:
    """What every member shares (SI): the summits' law inputs, the substrate choice and the strip."""

    work_of_adhesion: float
    summit_e_star: float
    half_space: bool
    footprint_half_width: float
    speed: float
    summit_law: Any = None
    """Tabulated branches (`continuum.rough.branch_laws.SummitLaw`) where the law has no closed form here."""
    heights: Any = None
    """The summit-height distribution members draw from (`continuum.rough.tail.EmpiricalGPD`); None: Gaussian of
    surfaces.roughness.sigma."""
    regime: Any = None
    """The scene's `continuum.model.regime.Regime` at `speed`, shared by every member (a realisation changes none of
    its numbers)."""


def member_plan(scene: Scene, speed: float, heights=None, regime: Regime | None = None) -> MemberPlan:
    """The realisation-independent decisions of a discrete run of `scene` at first-impact `speed` (m/s), its
    members drawing summit heights from `heights` (None: Gaussian); `regime`: the scene's, derived once by the
    caller (`continuum.dynamics.impact.run_impact`) at the same speed, else derived here."""
    from ..model import decisions
    from ..model.regime import regime_of
    from ..model.select import branch_summits
    from ..rough.tail import strip_half_width

    if regime is None:
        regime = regime_of(scene, speed)
    elif regime.speed != speed:
        raise ValueError(f"member_plan: the regime was derived at {regime.speed!r} m/s, the plan asked for at "
                         f"{speed!r} m/s")
    law = decisions.adhesion_decision(scene, regime).law
    rough, body = scene.surfaces.roughness, scene.body
    half = strip_half_width(heights, rough.sigma, rough.summit_density, body.radius, body.length)
    w = scene.surfaces.interface_work_of_adhesion if law != "none" else 0.0
    return MemberPlan(w, regime.e_star, decisions.half_space_decision(scene, regime).used, half, speed,
                      decisions.summit_law(law, scene, regime.e_star) if branch_summits(law) else None, heights,
                      regime)


def _release(scene: Scene, z_top: float) -> float | None:
    """Release height above the realisation's tallest summit (m), as `continuum.dynamics.impact` measures it."""
    if scene.release_height is None:
        return None
    if scene.surfaces.roughness.datum == "mean_plane":
        return scene.release_height - z_top
    return scene.release_height


def member_law(scene: Scene, seed: int, plan: MemberPlan) -> tuple[Scene, Any]:
    """(the member's scene, its discrete law) for realisation `seed`: the strip's summits drawn from the plan's
    height distribution."""
    from ..model import factory
    from ..model.select import member_summit_law  # plastic summits where they yield, bridges where humid
    from ..rough.gw import SummitStatistics

    member = with_realisation(scene, "discrete", seed)
    rough = member.surfaces.roughness
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    law = factory.discrete_roller(member, stats, plan.work_of_adhesion, plan.summit_e_star, plan.half_space,
                                  plan.footprint_half_width, plan.summit_law, heights=plan.heights)
    return member, member_summit_law(member, law, plan.regime)


def member_escape(law, member: Scene, speed: float, rel_tol: float) -> dict:
    """The realisation's escape velocity (m/s): the first-impact speed `speed` halved until the body sticks or
    doubled until it rebounds (at most MAX_ESCAPE_BRACKET_STEPS times), then bisected to `rel_tol`
    (`continuum.dynamics.escape.escape_velocity`, single impacts on virgin summits); {'escape_velocity': None, 'reason'}
    where no bracket is found (summits without adhesion never hold the body)."""
    from .escape import escape_velocity, single_impact

    mass, g, rtol = member.body.mass, member.environment.gravity, member.numerics.rtol
    v, lo, hi = speed, None, None
    for _ in range(MAX_ESCAPE_BRACKET_STEPS):
        if single_impact(law, mass, g, v, rtol, series=False).stuck:
            lo, v = v, 2.0 * v
        else:
            hi, v = v, 0.5 * v
        if lo is not None and hi is not None:
            return {**escape_velocity(law, mass, g, lo, hi, rel_tol=rel_tol, rtol=rtol), "rel_tol": rel_tol}
    return {"escape_velocity": None, "reason": f"no bracket within {MAX_ESCAPE_BRACKET_STEPS} halvings or "
                                               f"doublings of {speed:.3g} m/s"}


def run_member(scene: Scene, seed: int, plan: MemberPlan, escape_rel_tol: float | None = None) -> MemberOutcome:
    """One realisation (seed) of `scene` run to the end, and with `escape_rel_tol` its escape velocity bisected to
    that relative width; module-level so that executors can pickle it."""
    start = time.perf_counter()
    member, law = member_law(scene, seed, plan)
    n = member.numerics
    release = _release(member, float(law.z_top))
    if release is not None and release <= 0.0:
        raise ValueError(f"member seed {seed}: the release height lies below the realisation's tallest summit")
    # a member keeps its rebounds, not its time series or profiles: no samples inside steps, no snapshots (the
    # steps and events are the same)
    settings = DriverSettings(rtol=n.rtol, max_bounces=n.max_bounces, max_time=n.max_time,
                              rest_fraction=n.rest_fraction, samples_per_flight=2, samples_per_step=0,
                              profiles=False)
    run = simulate(law, member.body.mass, member.environment.gravity, release_height=release,
                   impact_velocity=member.impact_velocity, settings=settings)
    heights = tuple(float(b.rebound_height) for b in run.bounces if b.rebound_height is not None)
    diagnostics = law.diagnostics()
    contacts = int(diagnostics["max_contacts"])
    escape = member_escape(law, member, plan.speed, escape_rel_tol) if escape_rel_tol is not None else None
    return MemberOutcome(seed=int(seed), status=run.status, rebound_heights=heights, release_height=release,
                         max_contacts=contacts, wall_s=time.perf_counter() - start,
                         energy_error=float(run.audit["max_relative_error"]), escape=escape,
                         menisci=diagnostics.get("menisci"))


def _member_job(job: tuple) -> MemberOutcome:
    scene, seed, plan, escape_rel_tol = job
    return run_member(scene, seed, plan, escape_rel_tol)


@contextmanager
def open_executor(executor: Any = None, workers: int | None = None):
    """An open `nanoimpact.executors` executor: `executor` itself if it is one, else the named one (None:
    'local') opened here with `workers` and closed on exit."""
    from nanoimpact.executors import executor as make_executor

    if executor is not None and not isinstance(executor, str):
        yield executor
        return
    if (executor or "local") != "local":
        from ..numerics.compiled_contact import warm_up
        warm_up()                       # forked workers inherit the loaded kernel
    ex = make_executor(executor or "local", workers)
    try:
        yield ex
    finally:
        ex.close()


def _run_jobs(ex, jobs: list) -> list[MemberOutcome]:
    outcomes: list = [None] * len(jobs)
    for i, outcome in ex.map(_member_job, jobs):
        outcomes[i] = outcome
    return outcomes


def auto_members(target: float, cap: int, batch: int, first_impact: bool = True, within_run: bool = True):
    """The 'auto' rule as a function of the outcomes so far: (stop?, why). Stop once the Wilson 95 % half-width of
    each watched stick probability (first impact; within the run) is below `target`, or at `cap` members."""
    def verdict(outcomes: list[MemberOutcome]) -> tuple[bool, str]:
        n = len(outcomes)
        widths = {}
        if first_impact:
            widths["first_impact"] = wilson_half_width(sum(o.stuck_at_first_impact for o in outcomes), n)
        if within_run:
            widths["within_run"] = wilson_half_width(sum(o.stuck for o in outcomes), n)
        text = ", ".join(f"{k} {v:.3g}" for k, v in widths.items())
        if all(v < target for v in widths.values()):
            return True, f"Wilson 95 % half-width below {target:g} at {n} members ({text})"
        if n >= cap:
            return True, f"member cap {cap} reached with Wilson 95 % half-width {text} (target {target:g})"
        return False, text
    return verdict


def run_members(sc: Scene, plan: MemberPlan, master: int, members: int | str, ex, escape_rel_tol: float | None,
                target: float, cap: int, first_impact_watch_only: bool = False) -> tuple[list[MemberOutcome], dict]:
    """The members' outcomes on the open executor `ex`, and how their number was set: `members` of them, or for
    'auto' batches of AUTO_BATCH until `auto_members` stops (seeds are a prefix of one SeedSequence stream, so
    a larger ensemble keeps the members of a smaller one)."""
    if members != "auto":
        return _run_jobs(ex, [(sc, s, plan, escape_rel_tol) for s in member_seeds(master, int(members))]), \
            {"rule": "fixed"}
    stop = auto_members(target, cap, AUTO_BATCH, within_run=not first_impact_watch_only)
    outcomes: list[MemberOutcome] = []
    while True:
        n = min(len(outcomes) + AUTO_BATCH, cap)
        seeds = member_seeds(master, n)[len(outcomes):]
        outcomes += _run_jobs(ex, [(sc, s, plan, escape_rel_tol) for s in seeds])
        done, why = stop(outcomes)
        log.info("ensemble auto: %d members, %s", len(outcomes), why)
        if done:
            return outcomes, {"rule": "auto", "target_half_width": target, "member_cap": cap, "batch": AUTO_BATCH,
                              "watched": ["first_impact"] + ([] if first_impact_watch_only else ["within_run"]),
                              "stopped": why}


def ensemble_source(heights, tail_model: str) -> dict:
    """result.json -> ensemble's `source`: statistics given as numbers, or a map's distributions."""
    if tail_model == "gaussian" and heights is None:
        return {"source": "statistics", "tail_model": "gaussian"}
    return {"source": "map_statistics", "tail_model": tail_model}


def run_ensemble(scene: Scene | ResolvedScene, members: int | str | None = None, seed: int | None = None,
                 executor: Any = None, workers: int | None = None, escape: bool | None = None,
                 escape_rel_tol: float = ESCAPE_REL_TOL, heights=None, first_impact: bool = False,
                 regime: Regime | None = None) -> EnsembleResult:
    """Run `members` discrete realisations (an int, or 'auto'; default surfaces.roughness.members) of the rough
    `scene` with seeds derived from `seed` (default surfaces.roughness.seed), their summit heights drawn from
    `heights` (None: Gaussian of surfaces.roughness.sigma; a ResolvedScene with a map and tail_model
    'empirical_gpd': the map's fitted model, `continuum.dynamics.map_ensembles.map_tail`). `executor`: None or a name
    ('local', 'processes', 'dask'; None is 'local') opened and closed here with `workers`, or an open
    `nanoimpact.executors` executor. `escape` (default surfaces.roughness.escape_velocities): also bisect each
    member's escape velocity to `escape_rel_tol` (`member_escape`). `first_impact`: run each member to its first
    rebound only. `regime`: the scene's, derived once by the caller at its first-impact speed (`member_plan`)."""
    from ..model.regime import first_impact_speed

    sc = scene.scene if isinstance(scene, ResolvedScene) else scene
    if sc.contact != "rough":
        raise ValueError("an ensemble of summit realisations needs contact = 'rough'")
    rough = sc.surfaces.roughness
    tail_model = rough.tail_model
    if heights is None and tail_model != "gaussian":
        if not isinstance(scene, ResolvedScene) or scene.surface is None or "cutoff" not in scene.surface \
                or scene.surface.get("cutoff") is None:
            raise SceneError("surfaces.roughness.tail_model", tail_model, "needs a height map (topography or "
                             "[surfaces.roughness.synthetic]); a scene given by its statistics has the 'gaussian' "
                             "tail", getattr(scene, "scene_file", "") or "")
        from .map_tail import map_tail
        heights = map_tail(scene)[0]
    if first_impact:
        sc = first_impact_only(sc)
    members = rough.members if members is None else members
    if members != "auto":
        members = int(members)
        if members < 1:
            raise ValueError(f"members = {members!r}: must be >= 1")
    master = rough.seed if seed is None else int(seed)
    plan = member_plan(sc, first_impact_speed(sc), heights, regime)
    escape = bool(rough.escape_velocities) if escape is None else bool(escape)
    tol = float(escape_rel_tol) if escape else None
    start = time.perf_counter()
    with open_executor(executor, workers) as ex:
        outcomes, rule = run_members(sc, plan, master, members, ex, tol, rough.target_half_width,
                                     rough.max_members, first_impact_watch_only=first_impact)
        where = ex.describe()
    wall = time.perf_counter() - start
    log.info("ensemble of %d members (master seed %d) on %s: %.2f s", len(outcomes), master, where, wall)
    return EnsembleResult(master_seed=master, outcomes=tuple(outcomes), executor=where, wall_s=wall,
                          source=ensemble_source(heights, tail_model), escape_rel_tol=tol, members_rule=rule)

