"""Fig 4's loop ratio (OTS-covered silica over bare silica) under the declared choices it rests on.

The adhesive loop of a summit grows with the work of adhesion and falls with the contact modulus: in the
JKR limit the hysteresis of one summit scales as w^(5/3) R^(4/3) E*^(-2/3) (Maugis, *Contact, Adhesion and
Rupture of Elastic Solids*, Springer 2000, ch. 5), and below a Tabor parameter mu = (R w^2 / (E*^2 z0^3))^(1/3)
of about 1 it fades towards the DMT limit, which has none (Greenwood, Proc. R. Soc. A 453 (1997) 1277). Two
inputs of the loop ratio are declared rather than measured: the SAM's layer modulus (a compliant layer lowers
the coated summits' E*, Perriot & Barthel 2004, and so raises both their loop and their mu) and the summit
radius R (chosen with the summit density; mu ~ R^(1/3)). ``fig4_choice_probe`` reruns the ratio with the layer
as stiff as the substrate under it and over a range of summit radii, so a report can say which choice decides
the claim.
"""
from __future__ import annotations

import math

import numpy as np

from ..model import select_law
from .cases import FIG4_ELASTIC, MEAN_FIELD, RIGID, Case
from .figures import characteristic
from .run import resolve_case

#: Summit radii (m) the probe scans: a decade and a half either side of the shipped sets' 0.2 um.
PROBE_RADII = tuple(np.geomspace(0.05e-6, 2e-6, 9))


def loop_area(scene: str, params: str, overrides: dict, fidelity: str | None = None) -> float:
    """Fig 4's loop area (J/m^2) of `scene` (rough_silica.toml or rough_ots.toml) with `params` and `overrides`,
    on the averaged summits of a rigid substrate (the paper's figure)."""
    case = Case("probe", scene, {**MEAN_FIELD, "physics.half_space": RIGID, **FIG4_ELASTIC, **overrides})
    law, _ = select_law(resolve_case(case, params, fidelity).scene, 0.0)
    return characteristic(law.surface)["loop_area"]


def loop_ratio(params: str, silica: dict, ots: dict, fidelity: str | None = None) -> float:
    """Loop area of OTS-covered silica over bare silica's, each scene with its overrides."""
    a = loop_area("rough_silica.toml", params, silica, fidelity)
    b = loop_area("rough_ots.toml", params, ots, fidelity)
    return b / a if a > 0 else math.inf


def fig4_choice_probe(params: str, fidelity: str | None = None) -> dict:
    """The loop ratio as the set gives it, with the SAM layer as stiff as the substrate (no compliant layer;
    None when the set declares no layer modulus), and at each of PROBE_RADII on both surfaces; `crossing_m`
    brackets the summit radius where the ratio passes 1 (None when it does not within the scan)."""
    ots = resolve_case(Case("probe", "rough_ots.toml", MEAN_FIELD), params, fidelity).scene.surfaces
    stiff = None
    if ots.sam is not None and ots.sam.layer_modulus is not None:
        e_sub = ots.substrate.youngs_modulus
        stiff = {"layer_modulus_Pa": e_sub, "set_layer_modulus_Pa": ots.sam.layer_modulus,
                 "loop_ratio": loop_ratio(params, {}, {"surfaces.sam.layer_modulus": e_sub}, fidelity)}
    radius = {"surfaces.roughness.summit_radius": None}
    ratios = []
    for r in PROBE_RADII:
        radius["surfaces.roughness.summit_radius"] = float(r)
        ratios.append(loop_ratio(params, radius, radius, fidelity))
    crossing = next(([float(a), float(b)] for a, b, x, y in zip(PROBE_RADII, PROBE_RADII[1:], ratios, ratios[1:])
                     if (x - 1.0) * (y - 1.0) < 0), None)
    return {"loop_ratio": loop_ratio(params, {}, {}, fidelity), "set_summit_radius_m":
            ots.roughness.summit_radius, "stiff_layer": stiff,
            "summit_radius_scan": {"radius_m": [float(r) for r in PROBE_RADII], "loop_ratio": ratios},
            "crossing_m": crossing}
