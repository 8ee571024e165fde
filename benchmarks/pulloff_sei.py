"""The pull-off predicted by surface-element integration (SEI) against the committed MD pull-offs.

    .venv/bin/python benchmarks/pulloff_sei.py [--json docs/figures/pulloff_sei.json] [--bins 1 2 3]

For each surface (bare silica, OTS): the asperity of the pull-off recipe the calibration validates that surface
with (``calibration.mdset.VALIDATION``; the json names it) is built at quick (the
workflow's own builder, nothing runs), its atoms' heights binned into a lateral height map
(:func:`md.analysis.pulloff.tip_height_map`); the flat-slab traction law is the registry-averaged mean force per
area of the committed quick result of the adhesion recipe the calibration reads for that surface's W
(``calibration.mdset.MAPPING``; the json names it) (``details.pmf_windows``: ``mean_force_kcal_mol_A`` over
``details.energy.area_A2`` against ``separation_A``; with the TraPPE tail force ``tail_force_kcal_mol_A`` added for
the "full" law). The map's reach is the covering radius of the outermost sites (their hexagonal lattice, spacing
a/sqrt 2 of cristobalite): the smallest at which a flat face of the same crystal maps flat, so the flat-slab law
applies to it unchanged; larger reaches widen every protrusion (the spread over ``--reach`` shows by how much).
SEI (Bhattacharjee & Elimelech 1997): F(D) = sum sigma(D + h_cell) dA; the prediction is its most
tensile value. The MD pull-off runs with the plain cutoff (no tail), so the "cut" law is the like-for-like one.
Also printed: DMT 2 pi R W_F with the flat-slab W_F, and Tabor's parameter from the flat-slab W_F and z0 with E* of
silica on silica (md.analysis.pulloff.SILICA_E_STAR_PA).

What the prediction leaves out: the asperity is the builder's, not minimised (the silanol H and chain ends move by
a fraction of an angstrom when minimised); rigid surfaces (the DMT limit, Tabor mu < 0.2 for silica); the law is
that of two commensurate crystalline faces in the flat-slab registries, not of the dome's stepped facets against
the flat; for OTS the tip's chains all point along z. ``--bins`` checks that the grid is fine enough.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from calibration.mdset import MAPPING, VALIDATION  # noqa: E402
from md import units as U  # noqa: E402
from md.analysis.pulloff import (  # noqa: E402
    SILICA_E_STAR_PA,
    surface_element_pull_off,
    tabor_parameter,
    tabulated_traction,
    tip_height_map,
)
from md.build.silica import CRISTOBALITE_A  # noqa: E402
from md.recipe import RECIPE_DIR, load_recipe  # noqa: E402
from md.workflows import get_workflow  # noqa: E402
from nanoimpact.fileio import atomic_write_text  # noqa: E402

RESULTS = RECIPE_DIR / "results"
#: the adhesion recipe whose flat-slab law stands for each surface: the one the calibration reads its W from
ADHESION = {surface: next(s.recipe for s in MAPPING if s.key == key)
            for surface, key in (("silica", "surfaces.work_of_adhesion"), ("ots", "surfaces.sam.work_of_adhesion"))}
#: the measured pull-off each prediction is held against: the validation pull of that adhesion recipe
PULLOFF = {surface: next(pull for pull, adh in VALIDATION if adh == ADHESION[surface]) for surface in ADHESION}


def traction_law(adhesion: dict, with_tail: bool, registry: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(separation m, traction Pa, positive = repulsive) of a committed adhesion result: the registry average, or
    one registry's curve."""
    w = adhesion["details"]["pmf_windows"]
    f = np.asarray(w["mean_force_kcal_mol_A"] if registry is None else
                   w["per_registry_mean_force_kcal_mol_A"][registry], float)
    if with_tail:
        f = f + np.asarray(w["tail_force_kcal_mol_A"], float)
    area_m2 = adhesion["details"]["energy"]["area_A2"] * 1e-20
    return U.angstrom_to_m(np.asarray(w["separation_A"], float)), U.kcal_per_mol_A_to_N(f) / area_m2


#: nearest-neighbour spacing of the outermost sites of the (111) face (silanols; OTS: one chain per site), the
#: short side a/sqrt 2 of its rectangular surface cell; its hexagonal covering radius is this / sqrt 3
SITE_SPACING_A = CRISTOBALITE_A / math.sqrt(2.0)
COVERING_RADIUS_A = SITE_SPACING_A / math.sqrt(3.0)


def tip_map(recipe: str, bin_A: float, reach_A: float) -> dict:
    """Height map (m) of the asperity of ``recipe`` at quick, built by the workflow's builder."""
    wf = get_workflow("pulloff")
    system, _ = wf.build(load_recipe(recipe).typed_settings("quick"))
    tip = system.group("adsorbate")
    pos = system.positions[tip]
    m = tip_height_map(pos[:, :2], pos[:, 2], system.cell[:2], bin_A, reach_A=reach_A)
    return dict(m, heights=U.angstrom_to_m(m["heights"]), cell_area=m["cell_area"] * 1e-20)


def predict(surface: str, bins: list[float], reaches: list[float]) -> dict:
    adhesion = json.loads((RESULTS / f"{ADHESION[surface]}-quick" / "result.json").read_text())
    pull = json.loads((RESULTS / f"{PULLOFF[surface]}-quick" / "result.json").read_text())
    R = U.angstrom_to_m(pull["settings"]["asperity_radius_A"])
    out = {"surface": surface, "radius_m": R, "adhesion_recipe": ADHESION[surface],
           "adhesion_run_hash": adhesion["run_hash"], "pulloff_recipe": PULLOFF[surface],
           "pulloff_run_hash": pull["run_hash"], "laws": {}}
    laws = {"cut": False} | ({"full": True} if any(adhesion["details"]["pmf_windows"]["tail_force_kcal_mol_A"])
                             else {})
    maps = {(b, r): tip_map(PULLOFF[surface], b, r * COVERING_RADIUS_A) for b in bins for r in reaches}
    for name, tail in laws.items():
        sep, sig = traction_law(adhesion, tail)
        law = tabulated_traction(sep, sig)
        per_bin = {}
        for (b, rr), m in maps.items():
            r = surface_element_pull_off(m["heights"], m["cell_area"], law, (sep.min(), sep.max()), n_grid=300)
            per_bin[f"bin {b:g} A, reach {rr:g} x covering radius"] = {
                "bin_A": b, "reach_A": rr * COVERING_RADIUS_A, "pull_off_force_N": r["pull_off_force"],
                "filled_bins": m["filled"], "bins": list(m["bins"]),
                "apex_separation_at_max_m": r["apex_separation_at_max"]}
        central = per_bin[f"bin {bins[0]:g} A, reach {reaches[0]:g} x covering radius"]
        m = maps[(bins[0], reaches[0])]
        regs = []
        for k in range(len(adhesion["details"]["pmf_windows"]["per_registry_mean_force_kcal_mol_A"])):
            rs, rsig = traction_law(adhesion, tail, k)
            regs.append(surface_element_pull_off(m["heights"], m["cell_area"], tabulated_traction(rs, rsig),
                                                 (rs.min(), rs.max()), n_grid=300)["pull_off_force"])
        out["laws"][name] = {"maps": per_bin, "pull_off_force_N": central["pull_off_force_N"],
                             "per_registry_N": regs,
                             "central_map": {"bin_A": bins[0], "reach_A": reaches[0] * COVERING_RADIUS_A}}
    q = adhesion["quantities"]
    W = q["work_of_adhesion_free_energy"]["value"]
    out["dmt_2piRW_N"] = 2 * math.pi * R * W
    out["flat_slab_W_F_J_m2"] = W
    f = pull["quantities"]["pull_off_force"]
    out["measured"] = {"pull_off_force_N": f["value"], "stderr_N": f["stderr"], "kind": f.get("kind", ""),
                       # each tip position's own force at the reported speed (recipes with tip_positions)
                       "per_position_N": [p["max_tensile_force_N"] for p in pull["details"].get("per_position", [])
                                          if p["speed_m_s"] == f.get("speed_m_s")]}
    z0 = q["interaction_range_z0"]["value"]
    out["tabor_flat_slab"] = dict(tabor_parameter(R, W, SILICA_E_STAR_PA, z0), z0_m=z0, W_J_m2=W,
                                  e_star_Pa=SILICA_E_STAR_PA)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "figures" / "pulloff_sei.json")
    ap.add_argument("--bins", type=float, nargs="+", default=[0.5, 1.0],
                    help="grid spacings (A); the first is the central value")
    ap.add_argument("--reach", type=float, nargs="+", default=[1.0, 1.5],
                    help="reach of the height map in covering radii of the outermost sites; the first is central")
    a = ap.parse_args(argv)
    res = {s: predict(s, a.bins, a.reach) for s in ("silica", "ots")}
    for s, r in res.items():
        m = r["measured"]
        per = ", ".join(f"{x * 1e9:.2f}" for x in m["per_position_N"])
        print(f"{s}: measured ({r['pulloff_recipe']}) {m['pull_off_force_N'] * 1e9:.3f} +- "
              f"{m['stderr_N'] * 1e9:.3f} nN" + (f" (per position {per})" if per else "") + "; "
              f"DMT 2 pi R W_F = {r['dmt_2piRW_N'] * 1e9:.3f} nN; Tabor mu (flat slab, silica E*) = "
              f"{r['tabor_flat_slab']['mu']:.3f}, lambda = {r['tabor_flat_slab']['lambda']:.3f}")
        for name, law in r["laws"].items():
            per = "; ".join(f"{b}: {v['pull_off_force_N'] * 1e9:.3f}" for b, v in law["maps"].items())
            print(f"   SEI ({name} law): {law['pull_off_force_N'] * 1e9:.3f} nN ({per}); per registry "
                  + ", ".join(f"{x * 1e9:.3f}" for x in law["per_registry_N"]) + " nN")
    atomic_write_text(a.json, json.dumps(res, indent=1) + "\n")
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
