"""One impact's record: the driver writes it (`continuum.dynamics.driver.simulate`), the result carries it
(`continuum.output.impact_result.ImpactResult.bounces`) and result.json lists it."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Bounce:
    """One impact. Times in s, speeds in m/s (magnitudes), forces in N, lengths in m, energies in J.

    `max_penetration` is the largest approach -h reached (m); `rebound_height` is the apex of the
    following flight above the touch level (the law's `touch_gap`, where the contact starts and
    from which `simulate`'s release height is measured: a first impact from rest rebounds to
    release height - energy_lost / (m g), so a rebound above the release height would mean energy
    created; None if the body escapes without gravity or stays stuck); `energy_lost` is the mechanical energy lost over
    the contact, from the motion; `energy_booked` is what the law's own loss terms booked over the same contact.
    """

    index: int
    t_contact: float
    t_release: float | None
    duration: float | None
    v_impact: float
    v_rebound: float
    restitution: float
    peak_force: float
    max_penetration: float
    rebound_height: float | None
    energy_lost: float
    energy_booked: float
    profiles: dict | None = None
