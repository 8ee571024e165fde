"""The limiting contact pressure of a contacting pair, from each partner's yield strength or hardness.

What it is: the scene keys `surfaces.body.yield_strength`/`hardness` and `surfaces.substrate.yield_strength`/
`hardness` turned into the single limiting contact pressure p_y of the Thornton-Ning law
(`continuum.reference.thornton_ning`), with the checks that name the key that is wrong.

Choices, each with its reason:
* Per partner, the hardness when given, else 2.8 Y (`thornton_ning.limiting_contact_pressure`): the hardness is
  the measured mean pressure of a fully plastic indentation, the state p_y stands for; Y reaches it only through
  Tabor's constraint factor. A substrate may carry both (its yield strength also feeds the line-contact yield
  warning, its hardness the plasticity index of rough contact).
* The pair's p_y is the smaller partner's: plastic flow starts in the softer solid, and the Thornton-Ning law has
  one plastic zone.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from nanoimpact.errors import InputError

from ..reference import thornton_ning as tn

#: The two partners whose material tables may carry a yield key.
PARTNERS = ("surfaces.body", "surfaces.substrate")


@dataclass(frozen=True)
class PartnerLimit:
    """One partner's limiting contact pressure: the key it came from, the value given (Pa) and p_y (Pa)."""

    key: str
    value: float
    limiting_pressure: float


def partner_limits(values: Mapping[str, float | None]) -> list[PartnerLimit]:
    """Each partner's limit from `values` (SI, keyed by scene path: PREFIX.yield_strength, PREFIX.hardness,
    PREFIX.youngs_modulus); partners without a yield key are left out. Raises InputError naming the key."""
    out = []
    for prefix in PARTNERS:
        hardness, strength = values.get(f"{prefix}.hardness"), values.get(f"{prefix}.yield_strength")
        if hardness is None and strength is None:
            continue
        name, value = ("hardness", hardness) if hardness is not None else ("yield_strength", strength)
        p_y = tn.limiting_contact_pressure(**{name: value}, youngs_modulus=values.get(f"{prefix}.youngs_modulus"),
                                           prefix=prefix)
        out.append(PartnerLimit(f"{prefix}.{name}", float(value), float(p_y)))
    return out


def softer_partner(limits: list[PartnerLimit]) -> PartnerLimit | None:
    """The partner with the smaller limiting pressure (None when neither has a yield key)."""
    return min(limits, key=lambda lim: lim.limiting_pressure, default=None)


def check_sphere_limits(limits: list[PartnerLimit], radius: float, work_of_adhesion: float, e_star: float,
                        origin: str = "") -> None:
    """Raise InputError naming the key unless every partner's p_y lies between the adhesive stress scale of the
    sphere's JKR contact and E* (`thornton_ning.check_limiting_pressure`)."""
    for lim in limits:
        try:
            tn.check_limiting_pressure(lim.limiting_pressure, radius, work_of_adhesion, e_star, key=lim.key)
        except InputError as err:
            raise InputError(lim.key, lim.value, f"gives a limiting contact pressure of {lim.limiting_pressure:.4g} "
                             f"Pa; {err.allowed}", origin) from None
