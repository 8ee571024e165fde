"""Run an ensemble of discrete summit realisations of one rough scene on an executor.

    >>> from continuum import load_scene
    >>> from continuum.ensemble_run import run_ensemble
    >>> ens = run_ensemble(load_scene("rough_silica", params="calibrated"), members=64, seed=1, executor="processes")
    >>> ens.stick_probability, ens.stick_probability_first_impact, ens.rebound_counts()

The decisions that do not depend on the realisation (adhesion law, half-space, the summits' modulus and work of
adhesion, the footprint strip) are made once, from the scene's regime, exactly as a single discrete run makes
them (`continuum.model.select`); each member then only draws its summits (`continuum.laws.discrete_roller`, a few
ms), or, where the scene names a height map, cuts a patch of the map's summits at a random offset
(`continuum.rough.ensemble.patch_summits`), and runs the event-driven driver (on a rigid substrate each contact runs in the compiled kernel,
`continuum.contact_kernel.LAW_DISCRETE`). A run ends where the driver ends it: a member held by adhesion stops
at 'stuck'. Members go to `nanoimpact.executors` (local, processes, dask): jobs are module-level and picklable.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from .driver import DriverSettings, simulate
from .rough.ensemble import (EnsembleResult, MemberOutcome, SummitField, member_seeds, patch_offset, patch_summits,
                             tiles)
from .scene import ResolvedScene, Scene

log = logging.getLogger(__name__)

#: Relative bracket width of a member's escape velocity: the paper's sampled claims bisect theirs to the same
#: width (continuum.paper.samples.ESCAPE_REL_TOL); result.json -> ensemble -> escape_velocity states it beside
#: the members' spread.
ESCAPE_REL_TOL = 1e-3
#: Halvings or doublings of the first-impact speed tried to bracket a member's escape velocity (a factor 2^40).
MAX_ESCAPE_BRACKET_STEPS = 40


def with_realisation(scene: Scene, mode: str, seed: int | None = None) -> Scene:
    """`scene` with surfaces.roughness.mode (and seed) replaced."""
    rough = scene.surfaces.roughness
    rough = replace(rough, mode=mode) if seed is None else replace(rough, mode=mode, seed=int(seed))
    return replace(scene, surfaces=replace(scene.surfaces, roughness=rough))


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
    field: SummitField | None = None
    """The scene's height map's summits: each member is a patch of it (None: draws from the statistics)."""


def member_plan(scene: Scene, speed: float) -> MemberPlan:
    """The realisation-independent decisions of a discrete run of `scene` at first-impact `speed` (m/s)."""
    from .model import decisions
    from .model.regime import regime_of
    from .model.select import branch_summits
    from .rough.datum import tallest_summit

    regime = regime_of(scene, speed)
    law = decisions.adhesion_decision(scene, regime).law
    rough, body = scene.surfaces.roughness, scene.body
    datum = tallest_summit(rough.sigma, rough.summit_density, body.radius, body.length)
    w = scene.surfaces.interface_work_of_adhesion if law != "none" else 0.0
    return MemberPlan(w, regime.e_star, decisions.half_space_decision(scene, regime).used,
                      datum["footprint_half_width"], speed,
                      decisions.summit_law(law, scene) if branch_summits(law) else None)


def summit_field(resolved: ResolvedScene) -> SummitField | None:
    """The summits of the scene's height map (measured or synthetic), found on the map taken as periodic at the
    cutoff its statistics used (`continuum.rough.topography.identify_summits`); None for a scene without a map."""
    from .rough.surface_map import height_map
    from .rough.topography import identify_summits

    scene_dir = Path(resolved.scene_file).parent if resolved.scene_file else None
    found = height_map(resolved.values, scene_dir)
    if found is None:
        return None
    hmap, cutoff = found
    summits = identify_summits(hmap.heights, hmap.pixel_size, cutoff, periodic=True)
    return SummitField(summits.x, summits.y, summits.height, tuple(hmap.physical_size), bool(hmap.periodic),
                       {"map": dict(hmap.source), "cutoff_m": cutoff})


def source_record(field: SummitField | None, plan: MemberPlan, length: float) -> dict:
    """result.json -> ensemble's `source` (and `patches` for map patches): what the members realise."""
    if field is None:
        return {"source": "statistics"}
    nx, ny = tiles(field, plan.footprint_half_width, length)
    strip = [2.0 * plan.footprint_half_width, length]
    return {"source": "map_patches", "patches": {
        **field.source, "map_size_m": list(field.size), "map_periodic": field.periodic,
        "summits_on_map": int(field.x.size), "strip_m": strip, "tiles": [nx, ny], "tiled": nx * ny > 1,
        "rule": "each member's strip starts at a uniform random point of the map (from its seed); the map "
                "repeats periodically where the strip runs past its edge" +
                ("" if field.periodic else " (this map is not periodic: the copies meet at seams)")}}


def _release(scene: Scene, z_top: float) -> float | None:
    """Release height above the realisation's tallest summit (m), as `continuum.impact` measures it."""
    if scene.release_height is None:
        return None
    if scene.surfaces.roughness.datum == "mean_plane":
        return scene.release_height - z_top
    return scene.release_height


def member_law(scene: Scene, seed: int, plan: MemberPlan) -> tuple[Scene, Any, tuple[float, float] | None]:
    """(the member's scene, its discrete law, its patch offset on the map or None) for realisation `seed`."""
    from .model import factory
    from .rough.gw import SummitStatistics

    member = with_realisation(scene, "discrete", seed)
    rough = member.surfaces.roughness
    stats = SummitStatistics(rough.sigma, rough.summit_density, rough.summit_radius)
    offset = summits = None
    if plan.field is not None:
        offset = patch_offset(plan.field, seed)
        summits = patch_summits(plan.field, offset, plan.footprint_half_width, member.body.length)
    law = factory.discrete_roller(member, stats, plan.work_of_adhesion, plan.summit_e_star, plan.half_space,
                                  plan.footprint_half_width, plan.summit_law, summits)
    from .model.select import member_summit_law  # plastic summits where they yield, bridges where humid
    return member, member_summit_law(member, law, plan.speed), offset


def member_escape(law, member: Scene, speed: float, rel_tol: float) -> dict:
    """The realisation's escape velocity (m/s): the first-impact speed `speed` halved until the body sticks or
    doubled until it rebounds (at most MAX_ESCAPE_BRACKET_STEPS times), then bisected to `rel_tol`
    (`continuum.escape.escape_velocity`, single impacts on virgin summits); {'escape_velocity': None, 'reason'}
    where no bracket is found (summits without adhesion never hold the body)."""
    from .escape import escape_velocity, single_impact

    mass, g, rtol = member.body.mass, member.environment.gravity, member.numerics.rtol
    v, lo, hi = speed, None, None
    for _ in range(MAX_ESCAPE_BRACKET_STEPS):
        if single_impact(law, mass, g, v, rtol).stuck:
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
    member, law, offset = member_law(scene, seed, plan)
    n = member.numerics
    release = _release(member, float(law.z_top))
    if release is not None and release <= 0.0:
        raise ValueError(f"member seed {seed}: the release height lies below the realisation's tallest summit")
    # a member keeps its rebounds, not its time series: no samples inside steps (the steps are the same)
    settings = DriverSettings(rtol=n.rtol, max_bounces=n.max_bounces, max_time=n.max_time,
                              rest_fraction=n.rest_fraction, samples_per_flight=2, samples_per_step=0)
    run = simulate(law, member.body.mass, member.environment.gravity, release_height=release,
                   impact_velocity=member.impact_velocity, settings=settings)
    heights = tuple(float(b.rebound_height) for b in run.bounces if b.rebound_height is not None)
    diagnostics = law.diagnostics()
    contacts = int(diagnostics["max_contacts"])
    escape = member_escape(law, member, plan.speed, escape_rel_tol) if escape_rel_tol is not None else None
    return MemberOutcome(seed=int(seed), status=run.status, rebound_heights=heights, release_height=release,
                         max_contacts=contacts, wall_s=time.perf_counter() - start,
                         energy_error=float(run.audit["max_relative_error"]), patch_offset=offset, escape=escape,
                         menisci=diagnostics.get("menisci"))


def _member_job(job: tuple) -> MemberOutcome:
    scene, seed, plan, escape_rel_tol = job
    return run_member(scene, seed, plan, escape_rel_tol)


def run_ensemble(scene: Scene | ResolvedScene, members: int | None = None, seed: int | None = None,
                 executor: Any = None, workers: int | None = None, escape: bool | None = None,
                 escape_rel_tol: float = ESCAPE_REL_TOL) -> EnsembleResult:
    """Run `members` discrete realisations of the rough `scene` (default surfaces.roughness.members) with seeds
    derived from `seed` (default surfaces.roughness.seed). `executor`: None or a name ('local', 'processes',
    'dask'; None is 'local') opened and closed here with `workers`, or an open `nanoimpact.executors` executor.
    `escape` (default surfaces.roughness.escape_velocities): also bisect each member's escape velocity to
    `escape_rel_tol` (`member_escape`)."""
    from nanoimpact.executors import executor as make_executor

    from .model.regime import first_impact_speed

    sc = scene.scene if isinstance(scene, ResolvedScene) else scene
    if sc.contact != "rough":
        raise ValueError("an ensemble of summit realisations needs contact = 'rough'")
    rough = sc.surfaces.roughness
    members = rough.members if members is None else int(members)
    master = rough.seed if seed is None else int(seed)
    seeds = member_seeds(master, members)
    field = summit_field(scene) if isinstance(scene, ResolvedScene) else None
    plan = replace(member_plan(sc, first_impact_speed(sc)), field=field)
    escape = bool(rough.escape_velocities) if escape is None else bool(escape)
    tol = float(escape_rel_tol) if escape else None
    jobs = [(sc, s, plan, tol) for s in seeds]
    start = time.perf_counter()
    own = executor is None or isinstance(executor, str)
    if own and (executor or "local") != "local":
        from .compiled_contact import warm_up
        warm_up()                       # forked workers inherit the loaded kernel
    ex = make_executor(executor or "local", workers) if own else executor
    try:
        outcomes: list = [None] * members
        for i, outcome in ex.map(_member_job, jobs):
            outcomes[i] = outcome
        where = ex.describe()
    finally:
        if own:
            ex.close()
    wall = time.perf_counter() - start
    log.info("ensemble of %d members (master seed %d) on %s: %.2f s", members, master, where, wall)
    return EnsembleResult(master_seed=master, outcomes=tuple(outcomes), executor=where, wall_s=wall,
                          source=source_record(field, plan, sc.body.length), escape_rel_tol=tol)
