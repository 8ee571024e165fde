"""Modelling error of the rough-contact levels against an independent boundary-element reference.

    .venv/bin/python benchmarks/bench_accuracy.py --quick [--json FILE] [--png FILE]
    .venv/bin/python benchmarks/bench_accuracy.py [--map FILE --cutoff M [--size M]] [--grid N] [--json FILE]

One rough patch, one cohesive law, one quasi-static approach-retraction cycle (the rigid separation s of the flat
above the heights' mean plane stepped down and back, each state in equilibrium). Compared at every s: the force
and the real contact area; per cycle: the pull-off force (largest tension on retraction) and the hysteresis
energy (the loop's area). Levels:

* `bem` (the reference): Tamaas boundary elements on the whole map, Dugdale law with sigma0 = 1.03 dgamma/z0 and
  range rho = z0/1.03, so the project's Maugis-Dugdale summit law and the reference share the cohesive law
  (continuum/rough/bem_reference.py); repeated on the half grid for its discretisation error, and the first-order
  Richardson value 2 F(n) - F(n/2) (the order measured on a sphere in tests/continuum/test_bem_reference.py);
* `gw_direct_md`: the GW mean field with the summits' statistics counted on the map (direct route), all
  summits of the mean tip radius, Maugis-Dugdale summits, truncated at the tallest expected of N;
* `gw_spectral_md`: the same with Nayak's spectral-moment statistics (continuum/rough/summit_stats.py);
* `gw_direct_jkr`: `gw_direct_md` with JKR summits (what the rough scenes used before the regime picked the law);
* `discrete_md`: the map's own summits, each at its own height, all of the mean tip radius, Maugis-Dugdale;
* `discrete_md_own_radii`: the same, each summit with its own tip radius.
The summit levels see the same band-limited surface as the reference: the map low-pass filtered at the summit
cutoff, summits identified on the reference grid (continuum/rough/topography.py).

The patch: `--quick` and the default use a periodic self-affine synthesis (continuum/rough/topography.py's
`Synthesis`), synthesised on a 64^2 grid and Fourier-interpolated (exact for a band-limited map) onto the BEM
grids: 128^2 (quick) or 256^2. `--map FILE` takes a height map (the shipped synthetic map, an AFM file), filtered
at `--cutoff` and Fourier-resampled to `--grid`; such maps are treated as periodic (a measured map's edges are
not: its wrap-around step is part of that reference). Materials: the `calibrated` set's work of adhesion and z0,
the contact modulus of its body and substrate. Writes JSON (the numbers and curves) and a PNG.
"""
from __future__ import annotations

import argparse
import importlib.metadata
import json
import math
import os
import platform
import sys
import time
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
from SurfaceTopography import Topography

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import accuracy_impact  # noqa: E402

from continuum.reference.hertz import effective_modulus  # noqa: E402
from continuum.reference.maugis import md_parameter  # noqa: E402
from continuum.rough.bem_convergence import (  # noqa: E402
    GridRun,
    cohesive_zone_length,
    convergence,
    dugdale_crack_zone,
    single_summit_ladder,
)
from continuum.rough.bem_impact import Roller, roller_gw_cycle  # noqa: E402
from continuum.rough.bem_reference import bem_cycle, dugdale_range  # noqa: E402
from continuum.rough.branch_laws import make_summit_law  # noqa: E402
from continuum.rough.cutoff_match import (  # noqa: E402
    CUTOFF_PIXELS,
    discrete_loss,
    fourier_resample,  # noqa: E402
    match_cutoff,
    reference_estimate,
)
from continuum.rough.gw_branches import GWBranchSurface  # noqa: E402
from continuum.rough.quasistatic import discrete_cycle, gw_cycle, separation_path  # noqa: E402
from continuum.rough.summit_stats import direct_summary, spectral_summits  # noqa: E402
from continuum.rough.summits import SummitStatistics, expected_max_height  # noqa: E402
from continuum.rough.topography import Synthesis, identify_summits, load_height_map, synthesise_height_map  # noqa: E402
from nanoimpact import data  # noqa: E402
from nanoimpact.fileio import atomic_save_figure, atomic_write_json  # noqa: E402
from nanoimpact.provenance import git_commit  # noqa: E402

#: The default patch: the shipped map's spectrum shape (Hurst 0.8, long cutoff 4x and summit cutoff 8 pixels of
#: the 64^2 base grid), 0.25 um wide and 1.2 nm rms: the Dugdale zone of a summit at touch, sqrt(2 beta rho), spans
#: ~3.5 pixels of the 128^2 grid and ~7 of 256^2 (the reference needs several: tests/continuum/test_bem_reference.py)
#: while the patch holds ~20 summits. The shipped 5 um map (rms 6 nm, summit radii ~2 um) would need ~1000^2.
PATCH = Synthesis(hurst=0.8, rms_height=1.2e-9, short_cutoff=0.25e-6 / 8, size=0.25e-6, grid_points=64,
                  long_cutoff=0.25e-6 / 2, seed=1)


def materials(params: str) -> dict:
    """Work of adhesion, z0 and the pair's contact modulus from a parameter set (SI)."""
    raw = tomllib.loads(data.find("params", params).read_text())
    s = raw["surfaces"]
    e_star = float(effective_modulus(s["body"]["youngs_modulus"], s["body"]["poisson_ratio"],
                                     s["substrate"]["youngs_modulus"], s["substrate"]["poisson_ratio"]))
    sigma0, rho = dugdale_range(s["work_of_adhesion"], s["interaction_range"])
    return {"params": params, "work_of_adhesion": s["work_of_adhesion"], "z0": s["interaction_range"],
            "e_star": e_star, "dugdale_stress": sigma0, "dugdale_range": rho,
            "source": f"inputs/params/{params}.toml: surfaces.work_of_adhesion, surfaces.interaction_range; E* of "
                      "surfaces.body and surfaces.substrate (continuum.reference.hertz.effective_modulus)"}


def patch(args) -> tuple[dict, dict]:
    """(grids: n -> heights (m) on n^2 points, description) of the band-limited periodic patch."""
    n_ref = args.grid or (128 if args.quick else 256)
    if args.map:
        hmap = load_height_map(args.map, size=args.size)
        wrapped = Topography(np.array(hmap.heights), hmap.physical_size, periodic=True)   # as the BEM sees it
        topo = wrapped.shortcut(cutoff_wavelength=args.cutoff)
        cutoff, source = args.cutoff, dict(hmap.source)
        base = np.asarray(topo.heights())
    else:
        synthesis = replace(PATCH, rms_height=args.rms or PATCH.rms_height)
        hmap = synthesise_height_map(synthesis)
        topo, cutoff, source = hmap.topography(), synthesis.short_cutoff, dict(hmap.source)
        base = np.asarray(topo.heights())
    periodic = Topography(base - base.mean(), topo.physical_sizes, periodic=True)
    grids = {}
    for n in (n_ref // 4, n_ref // 2, n_ref):
        if cutoff < 4 * float(topo.physical_sizes[0]) / n:
            if n == n_ref // 4:
                continue                                 # the ladder's coarsest rung only where it holds the map
            raise SystemExit(f"--grid {n_ref}: the cutoff {cutoff:.3g} m spans fewer than 4 pixels of the {n}^2 grid")
        if n >= base.shape[0]:
            grids[n] = np.asarray(periodic.interpolate_fourier((n, n)).heights()) if n > base.shape[0] else base
        else:
            grids[n] = fourier_resample(base, n)   # Fourier truncation: exact for the band-limited patch
    return grids, {"source": source, "size_m": float(topo.physical_sizes[0]), "cutoff_m": float(cutoff),
                   "base_grid": list(base.shape), "rms_height_m": float(np.std(grids[n_ref])),
                   "reference_grid": n_ref, "periodic_topography": periodic}


def summit_sets(h: np.ndarray, desc: dict) -> dict:
    """The map's summits (direct) and both routes' GW statistics."""
    size, cutoff = desc["size_m"], desc["cutoff_m"]
    summits = identify_summits(h, size / h.shape[0], cutoff, periodic=True)
    direct = direct_summary(summits)
    spectral = spectral_summits(desc.pop("periodic_topography"), cutoff)
    keep = np.isfinite(summits.radius)
    return {"summits": summits, "own_radii": summits.radius[keep], "own_heights": summits.height[keep],
            "own_x": summits.x[keep], "grid": h.shape[0],
            "direct": direct, "spectral": spectral, "area": size * size,
            "record": {"count": summits.count, "direct": vars(direct), "spectral": vars(spectral),
                       "not_convex": int((~keep).sum())}}


def path_for(h: np.ndarray, sets: dict, mat: dict, quick: bool, depth: float | None = None) -> np.ndarray:
    """Separations: from 2 rho above the tallest point down to the mean summit height + half a summit std (or
    `depth` below the tallest point), in
    steps of rho/8 (quick) or rho/16: a summit's loop spans about delta_c ~ rho, and each force jump inside a step
    costs the trapezoid loop area at most |jump| step / 2."""
    z = sets["summits"].height
    top = float(np.max(h))
    deepest = top - depth if depth else float(np.mean(z) + 0.5 * np.std(z))
    rho = mat["dugdale_range"]
    return separation_path(top + 2 * rho, deepest, rho / (8 if quick else 16))


def _gw_level(route: str, law_name: str, sets: dict, mat: dict, path: np.ndarray, roller: Roller | None = None):
    """GW mean field of one route's statistics with one summit law; its cycle, under a flat (the patch's face) or
    under `roller` (strips across the patch, `bem_impact.roller_gw_cycle`)."""
    st = sets[route]
    stats = SummitStatistics(st.summit_height_std, st.summit_density, st.summit_radius)
    n_summits = st.summit_density * sets["area"]
    z_max = float(expected_max_height(max(n_summits, 2.0)))
    n = sets["grid"]
    lowest = path.min() + (float(roller.drop(np.arange(n) * roller.size / n, n).min()) if roller else 0.0)
    delta_max = 1.5 * (st.mean_summit_height + z_max * stats.sigma - lowest) + 10 * mat["z0"]
    law = make_summit_law(law_name, stats.radius, mat["work_of_adhesion"], mat["e_star"], z0=mat["z0"],
                          delta_max=delta_max)
    surface = GWBranchSurface(stats, law, z_max=z_max)
    if roller is not None:
        return roller_gw_cycle(surface, roller, n, path, st.mean_summit_height)
    return gw_cycle(surface, sets["area"], path, st.mean_summit_height)


def _discrete_level(own_radii: bool, sets: dict, mat: dict, path: np.ndarray, roller: Roller | None = None):
    """The map's summits at their own heights, Maugis-Dugdale, of the mean radius or each of its own; under a flat
    or under `roller` (each summit lowered by the roller's drop over it)."""
    z = sets["own_heights"]
    if roller is not None:
        z = z - roller.drop(sets["own_x"], sets["grid"])
    delta_max = 1.5 * float(z.max() - path.min()) + 10 * mat["z0"]
    make = lambda beta: make_summit_law("maugis_dugdale", beta, mat["work_of_adhesion"], mat["e_star"],   # noqa: E731
                                        z0=mat["z0"], delta_max=delta_max)
    if not own_radii:
        return discrete_cycle(make(sets["direct"].summit_radius), z, path)
    cycles = [discrete_cycle(make(float(b)), [zi], path) for b, zi in zip(sets["own_radii"], z)]
    first = cycles[0]
    return type(first)(path, np.sum([c.force for c in cycles], axis=0),
                       np.sum([c.contact_area for c in cycles], axis=0), first.turn)


LEVELS = {
    "gw_direct_md": ("GW mean field, direct-route statistics, Maugis-Dugdale summits",
                     lambda s, m, p, r=None: _gw_level("direct", "maugis_dugdale", s, m, p, r)),
    "gw_spectral_md": ("GW mean field, spectral-moment statistics (Nayak), Maugis-Dugdale summits",
                       lambda s, m, p, r=None: _gw_level("spectral", "maugis_dugdale", s, m, p, r)),
    "gw_direct_jkr": ("GW mean field, direct-route statistics, JKR summits",
                      lambda s, m, p, r=None: _gw_level("direct", "jkr", s, m, p, r)),
    "discrete_md": ("the map's summits at their own heights, mean tip radius, Maugis-Dugdale",
                    lambda s, m, p, r=None: _discrete_level(False, s, m, p, r)),
    "discrete_md_own_radii": ("the map's summits at their own heights and tip radii, Maugis-Dugdale",
                              lambda s, m, p, r=None: _discrete_level(True, s, m, p, r)),
}


def _impact_rows(levels: list[dict], impact: dict, half: int) -> None:
    """Each level's roller impact into its row: the record, first-rebound error against the reference's
    (`impact_rel_error`) and against the rebound the reference's loss extrapolated to zero pixel gives, stick."""
    ref = impact["reference"]
    ref_imp, e_ext = ref["impact"], ref["restitution_at_extrapolated_loss"]
    h0 = impact["body"]["drop_height_m"]
    for row in levels:
        out = ref["half_grid_impact"] if row["name"] == f"bem_half_grid_{half}" else impact["levels"][row["name"]]
        row["impact"] = out
        row["impact_seconds"] = out["seconds"]
        row["impact_rel_error"] = accuracy_impact.rebound_error(out, ref_imp)
        if "stuck" in out:
            row["stuck"] = out["stuck"]
            row["impact_stick_agrees"] = out["stuck"] == ref_imp["stuck"]
        row["impact_rel_error_vs_extrapolated"] = (
            (out["rebound_height_m"] - h0 * e_ext**2) / (h0 * e_ext**2)
            if e_ext and "rebound_height_m" in out else math.nan)


def cutoff_match(h: np.ndarray, desc: dict, mat: dict, path: np.ndarray, conv: dict):
    """The summit cutoff at which the discrete level (mean radius) loses the reference's loss per cycle, on the
    reference's patch and path (`continuum.rough.cutoff_match`); cutoffs in pixels of the map as given."""
    base_pixel = desc["size_m"] / desc["base_grid"][0]
    pixel = desc["size_m"] / h.shape[0]
    ladder = [discrete_loss(h, desc["size_m"], c * base_pixel, mat["e_star"], mat["work_of_adhesion"], mat["z0"],
                            path) for c in CUTOFF_PIXELS if c * base_pixel >= 4 * pixel]
    upper = conv["grids"][-1]["hysteresis_energy_J"]
    return match_cutoff(ladder, reference_estimate(conv), upper, conv["converged"])


def _rel(value: float, ref: float) -> float:
    return (value - ref) / ref if ref else math.nan


def _area_error(cycle, ref) -> float:
    """RMS over the approach states where the reference touches of (A - A_ref), over the reference's largest
    approach area."""
    k = ref.turn + 1
    touch = ref.contact_area[:k] > 0
    if not touch.any():
        return math.nan
    diff = cycle.contact_area[:k][touch] - ref.contact_area[:k][touch]
    return float(np.sqrt(np.mean(diff**2)) / np.max(ref.contact_area[:k]))


def _row(name: str, description: str, seconds: float, cycle, ref, rich: dict) -> dict:
    return {"name": name, "description": description, "seconds": seconds,
            "pull_off_force_N": cycle.pull_off_force, "hysteresis_energy_J": cycle.hysteresis_energy,
            "pull_off_rel_error": _rel(cycle.pull_off_force, ref.pull_off_force),
            "hysteresis_rel_error": _rel(cycle.hysteresis_energy, ref.hysteresis_energy),
            "area_rel_error": _area_error(cycle, ref),
            "pull_off_rel_error_vs_richardson": _rel(cycle.pull_off_force, rich["pull_off_force_N"]),
            "hysteresis_rel_error_vs_richardson": _rel(cycle.hysteresis_energy, rich["hysteresis_energy_J"])}


def reference(grids: dict, desc: dict, mat: dict, path: np.ndarray) -> tuple[dict, dict]:
    """BEM on the ladder of grids (the reference grid, its half and, where the map allows, its quarter); (record
    with `bem_convergence`, cycles by grid)."""
    cycles, runs = {}, {}
    for n in sorted(grids):
        cyc, stats = bem_cycle(grids[n], desc["size_m"], mat["e_star"], mat["work_of_adhesion"], mat["z0"], path)
        cycles[n], runs[n] = cyc, stats.to_json()
    fine = max(grids)
    coarse = sorted(grids)[-2]
    ladder = [GridRun(n, desc["size_m"] / n, cycles[n].pull_off_force, cycles[n].hysteresis_energy,
                      runs[n]["seconds"], runs[n]["unconverged"], runs[n]["cpu_seconds"]) for n in sorted(grids)]
    zone = cohesive_zone_length(mat["e_star"], mat["work_of_adhesion"], mat["z0"])
    conv = convergence(ladder, zone, desc["size_m"])
    conv["dugdale_crack_zone_m"] = dugdale_crack_zone(mat["e_star"], mat["work_of_adhesion"], mat["z0"])
    conv["solvers"] = {str(n): runs[n] for n in sorted(grids)}
    f, c = cycles[fine], cycles[coarse]
    rich = {"pull_off_force_N": 2 * f.pull_off_force - c.pull_off_force,
            "hysteresis_energy_J": 2 * f.hysteresis_energy - c.hysteresis_energy}
    record = {"name": "bem", "grid": fine, "seconds": runs[fine]["seconds"], "pull_off_force_N": f.pull_off_force,
              "hysteresis_energy_J": f.hysteresis_energy, "solver": runs[fine], "half_grid": {
                  "grid": coarse, "pull_off_force_N": c.pull_off_force, "hysteresis_energy_J": c.hysteresis_energy,
                  "solver": runs[coarse]},
              "richardson": rich,
              "discretisation_rel": {"pull_off": _rel(rich["pull_off_force_N"], f.pull_off_force),
                                     "hysteresis": _rel(rich["hysteresis_energy_J"], f.hysteresis_energy)},
              "bem_convergence": conv,
              "note": "errors of the levels are relative to the reference grid's values; discretisation_rel is "
                      "the first-order Richardson estimate's distance from them (the reference's own error)"}
    return record, cycles


def figure(result: dict, path_png: Path) -> None:
    """Force against separation (whole cycle and the tensile part), contact area on approach, relative errors, and
    (where the result has it) the roller's force under each level against its separation; drawn from the result's
    curves."""
    from matplotlib.figure import Figure

    curves = result["curves"]
    s_nm = np.asarray(curves["separation_m"]) * 1e9
    k = int(np.argmin(s_nm)) + 1
    pull = result["reference"]["pull_off_force_N"] * 1e6
    roller = result.get("impact", {}).get("curves")
    fig = Figure(figsize=(17.5 if roller else 14, 3.8))
    ax_f, ax_t, ax_a, ax_e, *ax_r = fig.subplots(1, 5 if roller else 4)
    for name, c in curves.items():
        if name == "separation_m":
            continue
        style = {"color": "k", "lw": 2} if name == "bem" else {"lw": 1}
        force, area = np.asarray(c["force_N"]) * 1e6, np.asarray(c["contact_area_m2"]) * 1e18
        for ax in (ax_f, ax_t):
            line, = ax.plot(s_nm[:k], force[:k], label=name, **style)
            ax.plot(s_nm[k - 1:], force[k - 1:], ls="--", color=line.get_color(), lw=style["lw"])
        ax_a.plot(s_nm[:k], area[:k], color=line.get_color(), lw=style["lw"])
    ax_f.set(xlabel="separation s (nm)", ylabel="force (uN; + compressive)",
             title="approach (solid), retraction (dashed)")
    ax_t.set(xlabel="separation s (nm)", ylim=(-2.0 * pull, 1.0 * pull), title="the tensile part")
    for ax in (ax_f, ax_t):
        ax.axhline(0, color="0.7", lw=0.5)
    ax_f.legend(fontsize=7)
    ax_a.set(xlabel="separation s (nm)", ylabel="real contact area on approach (nm^2)", yscale="log")
    names = [r["name"] for r in result["levels"]]
    x = np.arange(len(names))
    ax_e.bar(x - 0.2, [100 * r["pull_off_rel_error"] for r in result["levels"]], 0.4, label="pull-off")
    ax_e.bar(x + 0.2, [100 * r["hysteresis_rel_error"] for r in result["levels"]], 0.4, label="hysteresis")
    ax_e.axhline(0, color="k", lw=0.5)
    ax_e.set_xticks(x, names, rotation=60, ha="right", fontsize=7)
    ax_e.set(ylabel=f"error against BEM {result['reference']['grid']}^2 (%)")
    ax_e.legend(fontsize=7)
    if roller:
        ax = ax_r[0]
        ax.plot(np.asarray(roller["separation_m"]) * 1e9, np.asarray(roller["bem"]) * 1e6, color="k", lw=2,
                label="bem")
        for name, c in roller.items():
            if name not in ("separation_m", "bem"):
                ax.plot(np.asarray(c["separation_m"]) * 1e9, np.asarray(c["force_N"]) * 1e6, lw=1, label=name)
        ax.axhline(0, color="0.7", lw=0.5)
        ax.set(xlabel="separation s (nm)", ylabel="force on the roller (uN)",
               title="the roller's tables, to each level's turn")
        ax.legend(fontsize=7)
    fig.tight_layout()
    atomic_save_figure(fig, path_png, dpi=110)


def markdown(result: dict) -> str:
    """The levels' table (docs/benchmarks.md) from a result."""
    ref = result["reference"]
    rows = ["| level | seconds | pull-off error | hysteresis error | contact-area error (approach) | "
            "pull-off error vs Richardson |", "|---|---|---|---|---|---|",
            f"| `bem` {ref['grid']}^2 (reference) | {ref['seconds']:.1f} | {ref['pull_off_force_N']:.3g} N | "
            f"{ref['hysteresis_energy_J']:.3g} J | | "
            f"Richardson shift {100 * ref['discretisation_rel']['pull_off']:+.1f} % |"]
    for r in result["levels"]:
        rows.append(f"| `{r['name']}` | {r['seconds']:.2f} | {100 * r['pull_off_rel_error']:+.0f} % | "
                    f"{100 * r['hysteresis_rel_error']:+.0f} % | {100 * r['area_rel_error']:.0f} % | "
                    f"{100 * r['pull_off_rel_error_vs_richardson']:+.0f} % |")
    return "\n".join(rows)


def markdown_bem(result: dict) -> str:
    """The reference's pixel ladder, the impact per level and the summit cutoff it measures (docs/benchmarks.md,
    between the `bench_accuracy:bem` markers; tests/test_accuracy_docs.py checks the page against the JSON)."""
    conv, body = result["bem_convergence"], result["impact"]
    rows = ["| grid | pixel (nm) | cohesive zone (pixels) | pull-off (N) | loss per cycle (J) | seconds (CPU) | "
            "unconverged states |", "|---|---|---|---|---|---|---|"]
    rows += [f"| {g['grid']}² | {g['pixel_m'] * 1e9:.3g} | {g['zone_pixels']:.1f} | {g['pull_off_force_N']:.3g} | "
             f"{g['hysteresis_energy_J']:.3g} | {g['seconds']:.1f} ({g['cpu_seconds']:.1f}) | "
             f"{g['unconverged_states']} |" for g in conv["grids"]]
    verdict = (f"Converged: the two finest grids' losses within {100 * conv['tolerance']:.0f} %."
               if conv["converged"] else f"`not_converged`: {conv['not_converged']}.")
    one = conv.get("single_summit", {"grids": []})
    verdict += "" if not one["grids"] else ("\n\nOne summit of the patch's mean tip radius "
                f"({one['radius_m'] * 1e9:.3g} nm, a "
                f"{one['cell_m'] * 1e9:.3g} nm cell, flat {one['depth_m'] * 1e9:.2g} nm below the apex): the summit "
                f"law loses {one['summit_law_loss_J']:.3g} J per cycle and pulls off at "
                f"{one['summit_law_pull_off_N']:.3g} N; the reference, by pixel: " + "; ".join(
                    f"{g['pixel_m'] * 1e9:.3g} nm: pull-off {g['pull_off_force_N']:.3g} N, loss "
                    f"{g['hysteresis_energy_J']:.3g} J ({g['loss_over_summit_law']:.0f}x the summit law's)"
                    for g in one["grids"]) + ".")
    ref = body["reference"]
    ref_i = ref["impact"]
    n_ref = result["reference"]["grid"]
    imp = ["| level | first rebound h1 (m) | h1/h0 = e² | sticks | impact_rel_error | vs extrapolated reference | "
           "turn − table's turn (steps) | energy audit | seconds (cycle + impact) |",
           "|---|---|---|---|---|---|---|---|---|",
           f"| `bem` {n_ref}² (reference) | {ref_i['rebound_height_m']:.4g} | {ref_i['restitution'] ** 2:.4f} | "
           f"{'yes' if ref_i['stuck'] else 'no'} | | | {ref_i['turn_shift_over_step']:+.1e} | "
           f"{ref_i['energy_audit_max_relative_error']:.0e} | {ref['seconds']:.1f} |"]
    for r in result["levels"]:
        i = r["impact"]
        if "restitution" not in i:
            imp.append(f"| `{r['name']}` | not run: {i['not_run']} | | | | | | | |")
            continue
        imp.append(f"| `{r['name']}` | {i['rebound_height_m']:.4g} | {i['restitution'] ** 2:.4f} | "
                   f"{'yes' if i['stuck'] else 'no'} | {100 * r['impact_rel_error']:+.1f} % | "
                   f"{100 * r.get('impact_rel_error_vs_extrapolated', math.nan):+.1f} % | "
                   f"{i['turn_shift_over_step']:+.1e} | {i['energy_audit_max_relative_error']:.0e} | "
                   f"{r['seconds'] + r['impact_seconds']:.2f} |")
    e_ext = ref["restitution_at_extrapolated_loss"]
    head = (f"Body: {body['shape']}, radius {body['radius_m'] * 1e6:.3g} µm, {body['mass_kg']:.3g} kg, at "
            f"{body['impact_velocity_m_s']:.3g} m/s (K0 = {body['impact_energy_J']:.3g} J, drop height h0 = "
            f"{body['drop_height_m']:.3g} m: it turns at the reference table's deepest state, "
            f"{body['table_depth_m'] * 1e9:.3g} nm below the composite surface's top); at the turn "
            f"{body['summits_reached_at_turn']} of the patch's {body['summits_on_patch']} summits are reached and "
            f"the band within the cohesive range spans x/L = {body['reach_band_x_over_L'][0]:.2f}–"
            f"{body['reach_band_x_over_L'][1]:.2f}. Each level's force is its quasi-static cycle under the roller, "
            "tabulated and integrated through the impact driver (first impact). The reference's loss per roller "
            "cycle: " + ", ".join(f"{g['hysteresis_energy_J']:.3g} J on {n}²" for n, g in ref["grids"].items())
            + f"; extrapolated to zero pixel {ref['loss_richardson_J']:.3g} J, which would give h1/h0 = "
            + (f"{e_ext ** 2:.4f}" if e_ext else "none (not positive)") + ".")
    cut = result["summit_cutoff"]
    match = result["cutoff_match"]
    ladder = ", ".join(f"{r['cutoff_m'] * 1e9:.3g} nm: {r['summits']} summits, {r['loss_J']:.2g} J"
                       for r in match["ladder"])
    cut_line = ("Summit cutoff measured by the reference (`summit_cutoff`, kind `bem`): "
                + (f"{cut['cutoff_m'] * 1e9:.3g} nm" if cut["cutoff_m"] else "none")
                + f", match error {100 * cut['match_error']:+.0f} % against {cut['reference_loss_J']:.3g} J ("
                + ("converged reference" if cut["reference_converged"] else "unconverged reference: extrapolated")
                + "); at the finest grid's loss, its upper bound: "
                + (f"{cut['cutoff_at_upper_bound_m'] * 1e9:.3g} nm" if cut["cutoff_at_upper_bound_m"] else "none")
                + f". Discrete loss per cycle by cutoff: {ladder}.")
    load = result.get("load_average_1min", {})
    cost = (f"Whole run: {result['wall_s']:.0f} s wall, {result.get('cpu_s', math.nan):.0f} s CPU, 1-minute load "
            f"average {load.get('start', math.nan):.1f} at the start and {load.get('end', math.nan):.1f} at the end "
            f"({result['machine']['cores']} cores, shared).")
    return "\n".join(rows + ["", verdict, "", head, ""] + imp + ["", cut_line, "", cost])


def run(args) -> dict:
    start, cpu, load0 = time.perf_counter(), time.process_time(), os.getloadavg()[0]
    mat = materials(args.params)
    grids, desc = patch(args)
    n_ref = desc["reference_grid"]
    sets = summit_sets(grids[n_ref], desc)
    path = path_for(grids[n_ref], sets, mat, args.quick, args.depth)
    ref_record, bem = reference(grids, desc, mat, path)
    ref = bem[n_ref]
    half = n_ref // 2
    cycles, levels = {"bem": ref, f"bem_{half}": bem[half]}, []
    levels.append(_row(f"bem_half_grid_{half}", "the reference on the half grid (numerical error only)",
                       ref_record["half_grid"]["solver"]["seconds"], bem[half], ref, ref_record["richardson"]))
    for name, (description, build) in LEVELS.items():
        t0 = time.perf_counter()
        cycles[name] = build(sets, mat, path)
        levels.append(_row(name, description, time.perf_counter() - t0, cycles[name], ref, ref_record["richardson"]))
    impact = accuracy_impact.compare(grids, desc, mat, sets, {n: b for n, (_, b) in LEVELS.items()}, args.quick)
    _impact_rows(levels, impact, half)
    match = cutoff_match(grids[n_ref], desc, mat, path, ref_record["bem_convergence"])
    ref_record["bem_convergence"]["single_summit"] = single_summit_ladder(
        sets["direct"].summit_radius, mat["e_star"], mat["work_of_adhesion"], mat["z0"],
        grids=(16, 32, 64) if args.quick else (16, 32, 64, 128))
    beta = sets["direct"].summit_radius
    pixel = desc["size_m"] / n_ref
    surface = {k: v for k, v in desc.items()}
    surface.update(summits=sets["record"], pixel_m=pixel,
                   maugis_lambda_mean_summit=float(md_parameter(beta, mat["work_of_adhesion"], mat["e_star"],
                                                                mat["dugdale_stress"])),
                   touch_zone_radius_pixels=math.sqrt(2 * beta * mat["dugdale_range"]) / pixel)
    result = {"benchmark": "benchmarks/bench_accuracy.py", "mode": "quick" if args.quick else "full",
              "machine": {"cores": os.cpu_count(), "platform": platform.platform(),
                          "python": platform.python_version()},
              "provenance": {"git_commit": git_commit(), "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                             "tamaas": importlib.metadata.version("tamaas"), "numpy": np.__version__,
                             "command": "benchmarks/bench_accuracy.py " + " ".join(sys.argv[1:])},
              "materials": mat, "surface": surface,
              "path": {"start_m": float(path[0]), "deepest_m": float(path.min()), "states": int(path.size)},
              "reference": ref_record, "bem_convergence": ref_record["bem_convergence"],
              "impact": {**impact["body"], "reference": impact["reference"], "curves": impact["curves"]},
              "summit_cutoff": match.origin(), "cutoff_match": match.to_json(), "levels": levels,
              "curves": {"separation_m": path.tolist(), **{n: {"force_N": c.force.tolist(),
                                                                "contact_area_m2": c.contact_area.tolist()}
                                                            for n, c in cycles.items()}},
              "wall_s": time.perf_counter() - start, "cpu_s": time.process_time() - cpu,
              "load_average_1min": {"start": load0, "end": os.getloadavg()[0]}}
    return result


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="128^2 reference (else 256^2), coarser separation steps")
    p.add_argument("--map", type=Path, help="a height map SurfaceTopography reads (default: the synthetic patch)")
    p.add_argument("--cutoff", type=float, help="summit cutoff wavelength (m); required with --map")
    p.add_argument("--size", type=float, help="physical size (m) of a map whose file has none")
    p.add_argument("--grid", type=int, help="reference grid points per side (the half grid is also run)")
    p.add_argument("--depth", type=float, help="deepest state this far (m) below the tallest point (default: down "
                                               "to the mean summit height + half a summit std)")
    p.add_argument("--rms", type=float, help="rms height (m) of the synthetic patch (default 0.6 nm)")
    p.add_argument("--params", default="calibrated", help="parameter set giving dgamma, z0 and the moduli")
    p.add_argument("--json", type=Path, help="write the numbers and curves here")
    p.add_argument("--png", type=Path, help="write the figure here")
    p.add_argument("--replot", type=Path, help="only draw --png (if given) and print the table from this JSON")
    args = p.parse_args(argv)
    if args.replot:
        old = json.loads(args.replot.read_text())
        if args.png:
            figure(old, args.png)
        print(markdown(old))
        if "bem_convergence" in old:
            print(markdown_bem(old))
        return
    if args.map and not args.cutoff:
        p.error("--map needs --cutoff (the summit cutoff wavelength, m)")
    result = run(args)
    ref = result["reference"]
    print(f"reference: BEM {ref['grid']}^2, {ref['seconds']:.1f} s, pull-off {ref['pull_off_force_N']:.4g} N, "
          f"hysteresis {ref['hysteresis_energy_J']:.4g} J; Richardson shift {ref['discretisation_rel']}")
    print(f"{'level':24s} {'seconds':>8s} {'pull-off err':>13s} {'hysteresis err':>15s} {'area err':>9s} "
          f"{'pull-off vs R':>14s} {'hyst. vs R':>11s}")
    for r in result["levels"]:
        print(f"{r['name']:24s} {r['seconds']:8.2f} {r['pull_off_rel_error']:+13.3f} "
              f"{r['hysteresis_rel_error']:+15.3f} {r['area_rel_error']:9.3f} "
              f"{r['pull_off_rel_error_vs_richardson']:+14.3f} {r['hysteresis_rel_error_vs_richardson']:+11.3f}")
    conv = result["bem_convergence"]
    print("bem_convergence: " + ", ".join(f"{g['grid']}^2 ({g['zone_pixels']:.1f} px/zone): pull-off "
                                          f"{g['pull_off_force_N']:.4g} N, loss {g['hysteresis_energy_J']:.4g} J"
                                          for g in conv["grids"]))
    print("converged" if conv["converged"] else f"not converged: {conv['not_converged']}")
    body = result["impact"]
    ref_i = body["reference"]["impact"]
    print(f"roller impact: R {body['radius_m']:.3g} m, K0 {body['impact_energy_J']:.4g} J, v "
          f"{body['impact_velocity_m_s']:.3g} m/s, h0 {body['drop_height_m']:.4g} m; reference h1 "
          f"{ref_i['rebound_height_m']:.4g} m (e = {ref_i['restitution']:.4f}), stuck {ref_i['stuck']}")
    for r in result["levels"]:
        imp = r["impact"]
        print(f"  {r['name']:24s} " + (f"h1 {imp['rebound_height_m']:.4g} m, e = {imp['restitution']:.4f}, stuck "
                                       f"{imp['stuck']}, rebound error {r['impact_rel_error']:+.3f} "
                                       f"({r['impact_seconds']:.2f} s)" if "restitution" in imp else imp["not_run"]))
    cut = result["summit_cutoff"]
    print(f"summit_cutoff (kind bem): {cut['cutoff_m']} m, match error {cut['match_error']:+.3f}; {cut['note']}")
    print(f"total {result['wall_s']:.1f} s wall, {result['cpu_s']:.1f} s CPU, load average "
          f"{result['load_average_1min']['start']:.1f} -> {result['load_average_1min']['end']:.1f}")
    if args.json:
        atomic_write_json(args.json, result)
    if args.png:
        figure(result, args.png)


if __name__ == "__main__":
    main()
