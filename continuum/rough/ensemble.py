"""An ensemble of discrete summit realisations: member seeds, each member's outcome, and the distributions.

Where only a few summits carry an impact (expected contacts N_c = eta A_nom int phi_s of a few), the
Greenwood-Williamson average describes no single impact: a realisation's contact count fluctuates by about
sqrt(N_c), and each summit's hysteresis loop is a sizeable part of the impact energy. The prediction is then a
distribution over realisations of the same summit statistics (docs/model.md, "Few summits: ensembles"). Each
member is one seeded realisation (`continuum.laws.discrete_roller`, surfaces.roughness.mode = 'discrete'); this
module holds what is pure about an ensemble: how member seeds follow from one master seed, what a member's
run reduces to (`MemberOutcome`), and the statistics reported in result.json -> ensemble (`EnsembleResult`):
stick probabilities as counts of members with their Wilson 95 % interval (`continuum.output.proportions`), with the
members whose run a numerical cap ended (`censored`) apart from those stuck or at rest.

Seeds: numpy's `SeedSequence(master).generate_state(members, uint64)`, each word's top bit cleared (the scene's
seed range is 0 .. 2^63 - 1). SeedSequence hashes the master seed into well-mixed, independent streams
(O'Neill, PCG; numpy's recommended way to seed parallel generators), so members of one master seed do not
share draws, and the same master seed and size give the same members on any executor.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from ..output.proportions import wilson_interval

#: Percentiles reported for the rebound count, the first rebound height and the escape velocity.
PERCENTILES = (5, 25, 50, 75, 95)
#: numpy's percentile method for them ('linear': interpolated between order statistics, numpy's default).
PERCENTILE_METHOD = "linear"


def member_seeds(master: int, members: int) -> tuple[int, ...]:
    """The `members` seeds (0 .. 2^63 - 1) of an ensemble with master seed `master` (reproducible)."""
    if members < 1:
        raise ValueError(f"members = {members!r}: must be >= 1")
    words = np.random.SeedSequence(int(master)).generate_state(int(members), dtype=np.uint64)
    return tuple(int(w) & (2**63 - 1) for w in words)


@dataclass(frozen=True)
class MemberOutcome:
    """What one realisation did (SI): its seed, how the run ended, and each rebound height."""

    seed: int
    status: str
    """How the run ended: stuck, rest, max_bounces, max_time (`continuum.dynamics.driver.ImpactRun.status`)."""
    rebound_heights: tuple[float, ...]
    """Height (m, above the realisation's datum) of each rebound, in order; a contact that never let go adds none."""
    release_height: float | None
    """The release height used (m), None for a scene given an impact velocity."""
    max_contacts: int
    """Most summits attached at once during the run."""
    wall_s: float
    energy_error: float = 0.0
    """The run's energy audit: largest error of its energy books against the first impact's kinetic energy."""
    menisci: Mapping[str, Any] | None = None
    """The member's capillary bridges where its summits carry them (`continuum.laws.wet.WetRoughRoller.diagnostics`:
    longest contact, t_a, contacts with bridges, most summits bridged at once); None: a dry member."""
    escape: Mapping[str, Any] | None = None
    """The member's escape velocity where the ensemble was asked for it (`continuum.dynamics.escape.escape_velocity`:
    escape_velocity, lower, upper (m/s), runs), or {"escape_velocity": None, "reason": ...}; None: not asked."""

    @property
    def stuck(self) -> bool:
        """The body ended held by adhesion (the driver's 'stuck')."""
        return self.status == "stuck"

    @property
    def rebounds(self) -> int:
        return len(self.rebound_heights)

    @property
    def stuck_at_first_impact(self) -> bool:
        """Held at the first impact: no rebound at all and the run ended stuck."""
        return self.stuck and self.rebounds == 0

    @property
    def first_rebound(self) -> float:
        """First rebound height (m); 0 where the body stuck at the first impact."""
        return self.rebound_heights[0] if self.rebound_heights else 0.0

    def to_record(self) -> dict:
        return {"seed": self.seed, "status": self.status, "rebounds": self.rebounds,
                "rebound_heights": list(self.rebound_heights), "max_contacts": self.max_contacts,
                "energy_error": self.energy_error, "wall_s": self.wall_s,
                **({"menisci": dict(self.menisci)} if self.menisci is not None else {}),
                **({"escape": dict(self.escape)} if self.escape is not None else {})}

    @classmethod
    def from_record(cls, rec: Mapping[str, Any], release_height: float | None) -> "MemberOutcome":
        return cls(seed=int(rec["seed"]), status=str(rec["status"]),
                   rebound_heights=tuple(float(h) for h in rec["rebound_heights"]), release_height=release_height,
                   max_contacts=int(rec["max_contacts"]), wall_s=float(rec["wall_s"]),
                   energy_error=float(rec["energy_error"]),
                   menisci=rec.get("menisci"), escape=rec.get("escape"))


def _percentiles(values: Sequence[float]) -> dict[str, float]:
    q = np.percentile(np.asarray(values, float), PERCENTILES, method=PERCENTILE_METHOD)
    return {f"p{p}": float(v) for p, v in zip(PERCENTILES, q)}


#: How a run ended without the body held or rebounding clear: its run was cut by a numerical limit.
CENSORING_STATUSES = ("max_bounces", "max_time")


def _proportion(count: int, members: int) -> dict:
    """count of members, the fraction and its Wilson 95 % interval (`continuum.output.proportions`)."""
    lo, hi = wilson_interval(count, members)
    return {"count": int(count), "members": int(members), "value": count / members, "interval": [lo, hi],
            "interval_rule": "Wilson score 95 % (Wilson 1927)"}


def first_impact_record(outcomes: Sequence["MemberOutcome"]) -> dict:
    """Stuck at the first impact (held by adhesion, no rebound): count, members, Wilson interval; apart from it the
    members that rebounded clear of the first impact, those whose first contact ended at rest under gravity, and
    those `censored` (the run's max_time ended it inside the first contact)."""
    n = len(outcomes)
    stuck = sum(o.stuck_at_first_impact for o in outcomes)
    rebounded = sum(o.rebounds > 0 for o in outcomes)
    censored = sum(o.rebounds == 0 and o.status in CENSORING_STATUSES for o in outcomes)
    return {**_proportion(stuck, n), "rebounded": rebounded, "censored": censored,
            "rest": n - stuck - rebounded - censored}


def within_run_record(outcomes: Sequence["MemberOutcome"]) -> dict:
    """Stuck by the end of the run: count, members, Wilson interval, and apart from them the members `censored`
    (still bouncing when numerics.max_bounces or max_time ended the run: their fate is not known) and those that
    came to rest, rebounded clear (gravity off) or otherwise did not stick. `bounds`: the fraction if no censored
    member would have stuck and if every one would."""
    n = len(outcomes)
    stuck = sum(o.stuck for o in outcomes)
    censored = sum(o.status in CENSORING_STATUSES for o in outcomes)
    return {**_proportion(stuck, n), "censored": censored,
            "censored_by": {s: sum(o.status == s for o in outcomes) for s in CENSORING_STATUSES},
            "not_stuck": {s: sum(o.status == s for o in outcomes) for s in ("rest", "escaped")},
            "bounds": {"no_censored_member_sticks": stuck / n, "every_censored_member_sticks": (stuck + censored) / n},
            "means": "held by adhesion ('stuck') before numerics.max_bounces or max_time ended the run"}


def first_impact_summary(outcomes: Sequence["MemberOutcome"]) -> dict:
    """What a first-impact ensemble (a tail model's, a cutoff's) reports: the stick probability at the first impact
    and the first rebound's percentiles (m and, with a release height, over it; 0 for a member held)."""
    first = np.array([o.first_rebound for o in outcomes], float)
    rec = {"members": len(outcomes), "stick_probability_first_impact": first_impact_record(outcomes),
           "first_rebound_m": _percentiles(first)}
    h0 = outcomes[0].release_height if outcomes else None
    if h0:
        rec["first_rebound_over_h0"] = {k: v / h0 for k, v in rec["first_rebound_m"].items()}
    return rec


def _menisci_summary(outcomes: Sequence[MemberOutcome]) -> dict:
    """result.json -> ensemble -> menisci: whether the members carry bridges and how many formed."""
    wet = [o.menisci for o in outcomes if o.menisci is not None]
    if not wet:
        return {"carried": False, "why": "the members' summits carry no bridges (dry, hydrophobic or menisci off)"}
    return {"carried": True, "members": len(wet), "condensation_time_s": float(wet[0]["condensation_time_s"]),
            "members_with_bridges": sum(m["contacts_with_bridges"] > 0 for m in wet),
            "max_bridged_summits": _percentiles([m["max_bridges"] for m in wet]),
            "law": "a bridge on each summit, the mean field's law and clock (continuum.laws.discrete_bridges)"}


@dataclass(frozen=True)
class EnsembleResult:
    """The members of one ensemble and the distributions they give (SI; heights also as fractions of h0)."""

    master_seed: int
    outcomes: tuple[MemberOutcome, ...]
    executor: str
    wall_s: float
    source: Mapping[str, Any] = field(default_factory=lambda: {"source": "statistics"})
    """What the members realise: {"source": "statistics"} (draws from sigma, summit_density, summit_radius given as
    numbers) or {"source": "map_statistics", "tail_model": ...} (draws from a height map's measured distributions,
    `continuum.rough.tail`); never copies of a map."""
    members_rule: Mapping[str, Any] = field(default_factory=lambda: {"rule": "fixed"})
    """How the member count was set: {"rule": "fixed"} (surfaces.roughness.members), or the 'auto' rule's target,
    cap, batch and why it stopped (`continuum.dynamics.ensemble_run`)."""
    escape_rel_tol: float | None = None
    """Relative bracket width of each member's escape velocity; None where the scene did not ask for them."""

    @property
    def members(self) -> int:
        return len(self.outcomes)

    @property
    def seeds(self) -> tuple[int, ...]:
        return tuple(o.seed for o in self.outcomes)

    @property
    def stick_probability_first_impact(self) -> float:
        """Fraction of members held at the first impact."""
        return sum(o.stuck_at_first_impact for o in self.outcomes) / self.members

    @property
    def stick_probability(self) -> float:
        """Fraction of members held by adhesion by the end of the run (numerics.max_bounces / max_time)."""
        return sum(o.stuck for o in self.outcomes) / self.members

    def rebound_counts(self) -> np.ndarray:
        return np.array([o.rebounds for o in self.outcomes], int)

    def first_rebounds(self) -> np.ndarray:
        """First rebound heights (m), 0 for members held at the first impact."""
        return np.array([o.first_rebound for o in self.outcomes], float)

    def to_record(self, mean_field: Mapping[str, Any] | None = None) -> dict:
        """result.json -> ensemble. `mean_field`: the mean-field run's rebounds and first rebound, for comparison."""
        h0 = self.outcomes[0].release_height if self.outcomes else None
        first = self.first_rebounds()
        rec: dict = {
            "members": self.members, "master_seed": self.master_seed, "seeds": list(self.seeds), **self.source,
            "release_height_m": h0,
            "seed_rule": "numpy SeedSequence(master_seed).generate_state(members, uint64), top bit cleared",
            "members_rule": dict(self.members_rule),
            "stick_probability": {"first_impact": first_impact_record(self.outcomes),
                                  "within_run": within_run_record(self.outcomes)},
            "percentiles": list(PERCENTILES), "percentile_method": PERCENTILE_METHOD,
            "rebounds": {**_percentiles(self.rebound_counts()), "mean": float(np.mean(self.rebound_counts()))},
            "first_rebound_m": {**_percentiles(first), "mean": float(np.mean(first)), "std": float(np.std(first)),
                                "stuck_counts_as": 0.0},
            "status_counts": {s: sum(o.status == s for o in self.outcomes)
                              for s in sorted({o.status for o in self.outcomes})},
            "max_contacts": _percentiles([o.max_contacts for o in self.outcomes]),
            "energy_audit_max_relative_error": max(o.energy_error for o in self.outcomes),
            "menisci": _menisci_summary(self.outcomes),
            "escape_velocity": self.escape_record(),
            "executor": self.executor, "wall_s": self.wall_s,
            "member_runs": [o.to_record() for o in self.outcomes]}
        if h0:
            rec["first_rebound_over_h0"] = {k: v / h0 for k, v in rec["first_rebound_m"].items()
                                            if isinstance(v, float) and k != "stuck_counts_as"}
        if mean_field is not None:
            rec["mean_field"] = dict(mean_field)
        return rec

    def escape_velocities(self) -> np.ndarray:
        """The members' escape velocities (m/s), in member order, NaN where a member has none."""
        return np.array([(o.escape or {}).get("escape_velocity") or math.nan for o in self.outcomes], float)

    def escape_record(self) -> dict:
        """result.json -> ensemble -> escape_velocity: percentiles over the members' escape velocities (each the
        geometric middle of its bisection bracket), or why there are none."""
        if self.escape_rel_tol is None:
            return {"requested": False, "why": "surfaces.roughness.escape_velocities is false (the default): "
                                               "set it true for each member's escape velocity"}
        v = self.escape_velocities()
        found = v[np.isfinite(v)]
        rec: dict = {"requested": True, "rel_tol": self.escape_rel_tol, "members_with_value": int(found.size),
                     "rule": "each member's smallest first-impact speed from which it rebounds: bracketed by "
                             "halving/doubling the first-impact speed, bisected "
                             "(continuum.dynamics.escape.escape_velocity)",
                     "without_value": {str(o.seed): (o.escape or {}).get("reason", "not run")
                                       for o, x in zip(self.outcomes, v) if not math.isfinite(x)}}
        if found.size:
            rec["m_per_s"] = {**_percentiles(found), "mean": float(np.mean(found)), "std": float(np.std(found)),
                              "min": float(np.min(found)), "max": float(np.max(found))}
        return rec

    @classmethod
    def from_record(cls, rec: Mapping[str, Any], release_height: float | None) -> "EnsembleResult":
        outcomes = tuple(MemberOutcome.from_record(m, release_height) for m in rec["member_runs"])
        source = {k: rec[k] for k in ("source", "tail_model", "map_summits") if k in rec} or {"source": "statistics"}
        escape = rec.get("escape_velocity") or {}
        return cls(master_seed=int(rec["master_seed"]), outcomes=outcomes, executor=str(rec["executor"]),
                   wall_s=float(rec["wall_s"]), source=source, members_rule=rec.get("members_rule", {"rule": "fixed"}),
                   escape_rel_tol=escape.get("rel_tol") if escape.get("requested") else None)
