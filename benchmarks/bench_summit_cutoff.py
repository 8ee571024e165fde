"""How summit density and summit radius depend on the short-wavelength cutoff, by both routes.

    .venv/bin/python benchmarks/bench_summit_cutoff.py [--map FILE ...] [--png PATH] [--json PATH]

For each height map (default: the shipped `inputs/topographies/synthetic_selfaffine.txt`, a self-affine
Gaussian map with nothing shorter than 8 pixels; `--map` adds others, e.g. a NanoScope .di scan) and each cutoff
wavelength from 4 pixels up to the longest that still leaves `MIN_SUMMITS` summits on the map, it runs
`continuum.rough.topography.summit_statistics` and records the spectral (Nayak/McCool) and direct (8-neighbour)
summit density eta, mean summit radius beta and summit-height standard deviation sigma_s. The figure plots eta
and beta against the cutoff, one colour per map, solid spectral and dashed direct. Accuracy, not speed.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from continuum.rough.topography import MIN_SUMMITS, TopographyError, load_height_map, summit_statistics  # noqa: E402
from nanoimpact.fileio import atomic_write_text  # noqa: E402

SHIPPED = ROOT / "inputs" / "topographies" / "synthetic_selfaffine.txt"
PIXELS = (4, 5, 6, 8, 10, 12, 16, 20, 24, 32, 48, 64)


def sweep(path: Path) -> dict:
    """Both routes' statistics of the map at cutoffs of PIXELS pixels (until fewer than MIN_SUMMITS remain)."""
    hmap = load_height_map(path)
    pixel = max(hmap.pixel_size)
    rows = []
    for px in PIXELS:
        try:
            s = summit_statistics(hmap, px * pixel, "direct")
        except TopographyError:
            break
        rows.append({"cutoff_pixels": px, "cutoff_m": px * pixel,
                     "spectral": {"eta": s.spectral.summit_density, "beta": s.spectral.summit_radius,
                                  "sigma_s": s.spectral.summit_height_std, "alpha": s.spectral.alpha},
                     "direct": {"eta": s.direct.summit_density, "beta": s.direct.summit_radius,
                                "sigma_s": s.direct.summit_height_std, "count": s.direct.count}})
    return {"map": path.name, "sha256": hmap.source["sha256"], "grid_points": hmap.source["grid_points"],
            "physical_size_m": list(hmap.physical_size), "pixel_m": pixel, "rms_height_m": hmap.rms_height,
            "min_summits": MIN_SUMMITS, "rows": rows}


def figure(maps: list[dict], path: Path) -> None:
    from matplotlib.figure import Figure  # noqa: PLC0415
    fig = Figure(figsize=(9.0, 3.8))
    axes = fig.subplots(1, 2)
    for k, m in enumerate(maps):
        colour = f"C{k}"
        cut = np.array([r["cutoff_m"] for r in m["rows"]]) * 1e9
        for route, style in (("spectral", "-"), ("direct", "--")):
            eta = np.array([r[route]["eta"] for r in m["rows"]])
            beta = np.array([r[route]["beta"] for r in m["rows"]])
            label = f"{m['map']} ({route})"
            axes[0].loglog(cut, eta, style, marker="o", ms=3, color=colour, label=label)
            axes[1].loglog(cut, beta * 1e9, style, marker="o", ms=3, color=colour, label=label)
    axes[0].set_xlabel("cutoff wavelength (nm)")
    axes[0].set_ylabel("summit density $\\eta$ (1/m$^2$)")
    axes[1].set_xlabel("cutoff wavelength (nm)")
    axes[1].set_ylabel("mean summit radius $\\beta$ (nm)")
    axes[1].legend(fontsize=7)
    fig.suptitle("Summit statistics against the short-wavelength cutoff (solid: spectral, dashed: direct)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=130)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--map", type=Path, action="append", default=[], help="another height map (repeatable)")
    p.add_argument("--png", type=Path, help="write the figure here")
    p.add_argument("--json", type=Path, help="write the numbers here")
    args = p.parse_args(argv)
    maps = [sweep(path) for path in [SHIPPED, *args.map]]
    for m in maps:
        print(f"{m['map']}: {m['grid_points'][0]} x {m['grid_points'][1]} px, pixel {m['pixel_m']:.3g} m, "
              f"rms {m['rms_height_m']:.3g} m")
        print("  cutoff px   cutoff m   eta spectral  eta direct   beta spectral  beta direct  count")
        for r in m["rows"]:
            print(f"  {r['cutoff_pixels']:9d}  {r['cutoff_m']:9.3g}  {r['spectral']['eta']:12.3g} "
                  f"{r['direct']['eta']:11.3g}  {r['spectral']['beta']:13.3g} {r['direct']['beta']:12.3g} "
                  f"{r['direct']['count']:6d}")
    if args.json:
        atomic_write_text(args.json, json.dumps({"maps": maps}, indent=1) + "\n")
    if args.png:
        figure(maps, args.png)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
