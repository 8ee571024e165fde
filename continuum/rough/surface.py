"""What a summit surface provides to the rough laws: the declared interface of `GWJKRSurface` and
`GWBranchSurface`.

A summit surface is the Greenwood-Williamson average of one summit law over the summit heights: per unit
nominal area, at local separations d and history thresholds zeta (m, arrays broadcast, zeta = +inf
before anything attached), it gives pressure, stiffness, energy, contact measures and the dissipation
of a threshold that rises. The rough rollers (`continuum.laws.rough_roller`, `rough_rigid`, `wet`) and
the estimates use only what is declared here, so either surface (or a new one) can sit under them.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

from .summits import SummitStatistics


@runtime_checkable
class SummitSurface(Protocol):
    """A GW surface of summits with a one-threshold history (SI; per unit nominal area)."""

    stats: SummitStatistics
    """sigma (m), summit density (1/m^2), summit tip radius (m)."""
    z_max: float
    """Tallest summit above the summits' mean plane (m); inf when untruncated."""
    delta_c: float
    """JKR separation approach of one summit (m; 0 without adhesion): the adhesive length scale."""
    pull_off_force: float
    """Pull-off force of one summit (N)."""
    loop_energy: float
    """Energy one summit loses per approach-retreat cycle (J)."""
    release_stretch: float
    """How far a summit is stretched when it lets go, -delta_out >= 0 (m)."""
    attach_stretch: float
    """How far before touching a summit snaps on, -delta_in >= 0 (m; 0 for JKR and DMT)."""
    reach: float
    """Range of the summits' attraction out of contact (m; 0 for JKR and DMT)."""
    kind: str
    """'tabulated' (GW tables, ~2 us per state) or 'generic' (quadrature of any summit law, ~20 us)."""
    law_name: str
    """The summit law's name ('jkr', 'dmt', 'maugis_dugdale', ...)."""
    resolution: object
    """The resolution the surface was built at (a preset name or a spacing multiplier)."""
    build_seconds: float
    """Wall time of building the surface (s)."""

    def effective_threshold(self, d, zeta):
        """The threshold a trial state at d uses (m); also the history update after an accepted step."""

    def pressure(self, d, zeta):
        """Nominal pressure (Pa, + = compressive)."""

    def stiffness(self, d, zeta):
        """dp/dd at fixed stored zeta (Pa/m)."""

    def pressure_parts(self, d, zeta):
        """(compressive, tensile) parts of the pressure (Pa)."""

    def energy(self, d, zeta):
        """Stored energy (J/m^2), zero for free summits."""

    def contact_fraction(self, d, zeta):
        """Real contact area / nominal area (1)."""

    def contacts(self, d, zeta):
        """Attached summits per unit nominal area (1/m^2)."""

    def dissipation(self, zeta_old, zeta_new):
        """Energy lost (J/m^2) when the threshold rises from zeta_old to zeta_new."""

    def describe(self) -> dict:
        """JSON-ready description."""
