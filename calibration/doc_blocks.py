"""Blocks of the docs pages whose numbers committed results hold, generated from those results.

A page marks each block ``<!-- generated: NAME -->`` ... ``<!-- /generated -->`` (the markers of
``md.report_tables``, which renders docs/md.md's result and cost tables); this module renders the blocks that quote
the pull-off prediction (``docs/figures/pulloff_sei.json``, written by ``benchmarks/pulloff_sei.py``), the
committed pull-off results (``inputs/md/results/<recipe>-quick/result.json``) and the benchmarks' committed jsons
(``docs/figures/``: the MD engine, MD on two ranks, the silica slab's lateral stress). It reads
files (and the builder's lattice constant), so the numbers on the page are those of the committed files, and
``tests/test_generated_docs.py`` fails when they disagree.

    python -m calibration.doc_blocks            # rewrite the marked blocks in place
    python -m calibration.doc_blocks --check    # exit 1 if a page's block differs from its files; write nothing
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Callable

from nanoimpact.fileio import atomic_write_text

ROOT = Path(__file__).resolve().parents[1]
RESULTS_DIR = ROOT / "inputs" / "md" / "results"
SEI_JSON = ROOT / "docs" / "figures" / "pulloff_sei.json"

#: The pull-off runs the SEI table's second part lists, in this order: the calibration's validation runs (four tip
#: positions) and the one-position runs they replaced.
PULLOFF_RUNS = ("pulloff_silica_positions", "pulloff_ots_positions", "pulloff_silica", "pulloff_ots")


def _nn(x: float) -> str:
    """Newtons in nN, two decimals."""
    return f"{x * 1e9:.2f}"


def _sei_row(sei: dict) -> str:
    """One surface's SEI row after its first cell (nN)."""
    cut = sei["laws"]["cut"]
    wide = next(v for v in cut["maps"].values() if v["bin_A"] == cut["central_map"]["bin_A"]
                and v["reach_A"] > cut["central_map"]["reach_A"])
    full = f" ({_nn(sei['laws']['full']['pull_off_force_N'])} with the tail)" if "full" in sei["laws"] else ""
    dmt = _nn(sei["dmt_2piRW_N"]) + (" (W_F with the tail)" if "full" in sei["laws"] else "")
    return (f"| {_nn(sei['measured']['pull_off_force_N'])} ± {_nn(sei['measured']['stderr_N'])} | "
            f"{_nn(cut['pull_off_force_N'])}{full} | {', '.join(_nn(x) for x in cut['per_registry_N'])} | "
            f"{_nn(wide['pull_off_force_N'])} | {dmt} | {sei['tabor_flat_slab']['mu']:.2f} "
            f"({sei['tabor_flat_slab']['lambda']:.2f}) |")


def _pulloff_row(recipe: str, results_dir: Path) -> str:
    data = json.loads((results_dir / f"{recipe}-quick" / "result.json").read_text())
    force = data["quantities"]["pull_off_force"]
    speed = force.get("speed_m_s")
    per = [p["max_tensile_force_N"] for p in data["details"].get("per_position", []) if p["speed_m_s"] == speed]
    spread = f"{_nn(min(per))}–{_nn(max(per))}" if per else "one position"
    diff = data["details"].get("speed_difference")
    paired = (f"{diff['speeds_m_s'][1]:g} − {diff['speeds_m_s'][0]:g} m/s: {_nn(diff['mean_N'])} ± "
              f"{_nn(diff['stderr_N'])}" if diff else "")
    return f"| `{recipe}` | {speed:g} | {_nn(force['value'])} ± {_nn(force['stderr'])} | {spread} | {paired} |"


def pulloff_sei(sei_json: Path = SEI_JSON, results_dir: Path = RESULTS_DIR) -> str:
    """docs/md.md's pull-off tables: the SEI prediction per surface, then the committed pull-off runs."""
    sei = json.loads(Path(sei_json).read_text())
    label = {"silica": "silica", "ots": "OTS"}
    lines = ["| surface | measured F (nN) | SEI, registry average (nN) | SEI per registry (nN) | SEI, reach 1.5× (nN) "
             "| DMT 2πRW_F (nN) | Tabor μ (λ), flat-slab W_F, z0 |",
             "|---|---|---|---|---|---|---|"]
    for surface, r in sei.items():
        lines.append(f"| {label.get(surface, surface)}, R = {r['radius_m'] * 1e9:g} nm (`{r['pulloff_recipe']}`) "
                     + _sei_row(r))
    lines += ["", "| run | speed (m/s) | F (nN) | per position (nN) | paired speed difference (nN) |",
              "|---|---|---|---|---|"]
    lines += [_pulloff_row(recipe, results_dir) for recipe in PULLOFF_RUNS]
    return "\n".join(lines)




FIGURES = ROOT / "docs" / "figures"
RANKS_JSON = FIGURES / "md_ranks_bench.json"
ENGINE_JSON = FIGURES / "md_engine_bench.json"


def md_engine(path: Path = ENGINE_JSON) -> str:
    """docs/benchmarks.md's in-process against ``lmp -in`` table from ``benchmarks/bench_md_engine.py``'s json: times
    summed over the repeats, throughput ratio = plain time / in-process time."""
    data = json.loads(Path(path).read_text())
    total = {k: sum(r[k] for r in data["rows"]) for k in ("inprocess_loop_s", "plain_loop_s", "inprocess_lammps_wall_s",
                                                          "plain_wall_s", "inprocess_run_recipe_wall_s")}
    per = ", ".join(f"{x:.3f}" for x in data["ratio_loop_per_repeat"])
    rows = [("dynamics (LAMMPS `Loop time`)", total["inprocess_loop_s"], total["plain_loop_s"],
             f"**{data['ratio_loop']:.3f}** (per repeat {per})"),
            ("all LAMMPS work (set-up, minimisation, chunk files)", total["inprocess_lammps_wall_s"],
             total["plain_wall_s"], f"{data['ratio_lammps_wall']:.3f}"),
            ("the whole `run_recipe` call (plus Python: sample parsing, npz frames, result.json)",
             total["inprocess_run_recipe_wall_s"], total["plain_wall_s"], f"{data['ratio_whole_run']:.3f}")]
    lines = [f"| measure | in process (s, {data['repeats']} repeats) | `lmp -in` (s) | throughput ratio in-process / "
             "plain |", "|---|---|---|---|"]
    lines += [f"| {name} | {inproc:.2f} | {plain:.2f} | {ratio} |" for name, inproc, plain, ratio in rows]
    return "\n".join(lines)
#: ``benchmarks/bench_md_ranks.py``'s case names -> the table's words.
RANK_CASES = {"one rank": "one rank, in process", "two ranks, default grid": "two ranks, LAMMPS's default grid",
              "two ranks, engine grid": "two ranks, the engine's grid (`processors * * 1`)"}


def md_ranks(path: Path = RANKS_JSON) -> str:
    """docs/benchmarks.md's processor-grid table from ``benchmarks/bench_md_ranks.py``'s json."""
    rows = json.loads(Path(path).read_text())["rows"]
    best = max(r["speedup_vs_one_rank"] for r in rows)
    lines = ["| case | processor grid | dynamics `Loop time` (s) | speed-up against one rank | pair time per rank, "
             "min / max (s, last chunk) |", "|---|---|---|---|---|"]
    for r in rows:
        up = f"{r['speedup_vs_one_rank']:.2f}"
        pair = r["last_chunk_sections"]["Pair"]
        lines.append(f"| {RANK_CASES.get(r['case'], r['case'])} | {r['grid']} | {r['dynamics_loop_s']:.2f} | "
                     f"{f'**{up}**' if r['speedup_vs_one_rank'] == best and best > 1 else up} | "
                     f"{pair['min_s']:.2f} / {pair['max_s']:.2f} |")
    return "\n".join(lines)


def _signed(x: float, digits: int) -> str:
    return f"{x:+.{digits}f}".replace("-", "−")


def md_lateral_stress(folder: Path = FIGURES) -> str:
    """docs/benchmarks.md's lateral-stress table from ``benchmarks/md_lateral_stress.py``'s json per lattice constant
    (``md_lateral_stress_a<A>.json``), then where sigma_bulk changes sign (linear between the bracketing lattices)."""
    from md import CRISTOBALITE_A

    runs = sorted(((float(p.stem.rpartition("_a")[2]), p.stem.rpartition("_a")[2], json.loads(p.read_text()))
                   for p in Path(folder).glob("md_lateral_stress_a*.json")), reverse=True)
    lines = ["| cubic a (Å) | t (Å) | atoms | S (N/m) | Sxx / Syy (N/m) | σ_bulk (GPa) |", "|---|---|---|---|---|---|"]
    for a, label, run in runs:
        builder = a == CRISTOBALITE_A
        bulk = f"{_signed(run['sigma_bulk_Pa'] * 1e-9, 2)} ± {run['sigma_bulk_stderr_Pa'] * 1e-9:.2f}"
        for i, r in enumerate(run["rows"]):
            cells = [label + (" (the builder's)" if builder else "") if i == 0 else "", f"{r['si_span_A']:.2f}",
                     str(r["atoms"]), f"{_signed(r['S_N_per_m'], 3)} ± {r['S_stderr_N_per_m']:.3f}",
                     f"{_signed(r['Sxx_N_per_m'], 2)} / {_signed(r['Syy_N_per_m'], 2)}",
                     (f"**{bulk}**" if builder else bulk) if i == 0 else ""]
            lines.append("| " + " | ".join(cells) + " |")
    bracket = [(lo, hi) for hi, lo in zip(runs, runs[1:]) if lo[2]["sigma_bulk_Pa"] < 0.0 <= hi[2]["sigma_bulk_Pa"]]
    if bracket:
        (a1, l1, r1), (a2, l2, r2) = bracket[0]
        s1, s2 = r1["sigma_bulk_Pa"], r2["sigma_bulk_Pa"]
        zero = a1 + (a2 - a1) * (-s1) / (s2 - s1)
        thin = next(run for a, _, run in runs if a == CRISTOBALITE_A)["rows"][0]
        lines += ["", f"σ_bulk = 0 by linear interpolation between {l1} and {l2} Å: a ≈ {zero:.2f} Å, "
                  f"{100 * (1 - zero / CRISTOBALITE_A):.1f} % below the builder's {CRISTOBALITE_A:g} Å. The thinnest "
                  f"slab at the builder's lattice ({thin['si_span_A']:.0f} Å) carries S/t = "
                  f"{thin['S_N_per_m'] / (thin['si_span_A'] * 1e-10) * 1e-9:.1f} GPa, surface stress included."]
    return "\n".join(lines)


#: page (relative to the repository) -> {block name: renderer}.
BLOCKS: dict[str, dict[str, Callable[[], str]]] = {
    "docs/md.md": {"md-pulloff-sei": pulloff_sei},
    "docs/benchmarks.md": {"md-engine": md_engine, "md-ranks": md_ranks,
                           "md-lateral-stress": md_lateral_stress},
}


def _block_re(name: str) -> re.Pattern[str]:
    return re.compile(rf"(<!-- generated: {re.escape(name)} -->)(.*?)(<!-- /generated -->)", re.S)


def render(text: str, blocks: dict[str, str], page: str = "page") -> str:
    """``text`` with each named block replaced by its content (each marker must occur exactly once)."""
    for name, body in blocks.items():
        pattern = _block_re(name)
        if len(pattern.findall(text)) != 1:
            raise ValueError(f"{page}: marker <!-- generated: {name} --> must occur exactly once")
        text = pattern.sub(lambda m, b=body: f"{m.group(1)}\n{b}\n{m.group(3)}", text)
    return text


def rendered(root: Path = ROOT) -> dict[str, tuple[str, str]]:
    """page -> (its text now, its text with every block regenerated)."""
    out = {}
    for page, blocks in BLOCKS.items():
        text = (root / page).read_text()
        out[page] = (text, render(text, {name: make() for name, make in blocks.items()}, page))
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m calibration.doc_blocks", description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if a page's block is stale; write nothing")
    args = p.parse_args(argv)
    stale = [page for page, (now, new) in rendered().items() if now != new]
    if args.check:
        for page in stale:
            print(f"stale: {page} (run python -m calibration.doc_blocks)", file=sys.stderr)
        return 1 if stale else 0
    for page, (_, new) in rendered().items():
        if page in stale:
            atomic_write_text(ROOT / page, new)
            print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
