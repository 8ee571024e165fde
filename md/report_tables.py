"""The result and cost tables of ``docs/md.md``, generated from the committed MD results.

Every number in those tables is read from a committed ``inputs/md/results/<recipe>-<fidelity>/result.json``, so a
rerun that replaces a result changes the tables with it, and ``tests/md/test_md_docs.py`` fails when the page and the
results disagree. Regenerate with ``python -m md.report_tables`` (rewrites the marked blocks of ``docs/md.md``).

A result is a **calibration input** when its folder holds no recipe of its own, its recipe is one of the shipped
recipes (``inputs/md/<recipe>.toml``) and it ran at ``quick``: that is the result ``nanoimpact calibrate`` reads
when its run hash is current. Every other committed result is a **study** (a size, run-length, start or fidelity
variant whose recipe file lies beside its result): the calibration never reads it.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from md.recipe import RECIPE_DIR
from nanoimpact.fileio import atomic_write_text

RESULTS_DIR = RECIPE_DIR / "results"
DOC_PATH = RECIPE_DIR.parent.parent / "docs" / "md.md"
CALIBRATION_FIDELITY = "quick"

#: Quantities shown per workflow, in this order (result.json holds them all).
SHOWN: dict[str, tuple[str, ...]] = {
    "adhesion": ("work_of_adhesion_free_energy", "work_of_adhesion", "entropic_term_TdS", "dispersion_tail_work",
                 "peak_traction_sigma0", "interaction_range_z0"),
    "pulloff": ("pull_off_force", "work_of_adhesion_eff_dmt", "work_of_adhesion_eff_jkr", "residual_drag_force"),
    "contact_angle": ("contact_angle", "contact_angle_as_simulated", "work_of_adhesion_sl", "contact_angle_drift"),
    "surface_tension": ("surface_tension", "density"),
    "wsl_ti": ("work_of_adhesion_sl", "contact_angle", "spreading_coefficient", "dispersion_tail_work_sl"),
}

#: SI unit of result.json -> (unit shown, factor).
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "J/m^2": ("mJ/m²", 1e3), "N": ("nN", 1e9), "m": ("nm", 1e9), "Pa": ("MPa", 1e-6), "N/m": ("mN/m", 1e3),
    "deg": ("°", 1.0), "deg/ns": ("°/ns", 1.0), "kg/m^3": ("kg/m³", 1.0),
}


@dataclass(frozen=True)
class CommittedResult:
    """One committed result: its folder name, whether the calibration reads it, and its result.json."""

    folder: str
    calibration_input: bool
    data: dict[str, Any]


def committed_results(results_dir: Path = RESULTS_DIR) -> list[CommittedResult]:
    """Every committed result under ``results_dir``, sorted by folder name."""
    out = []
    for path in sorted(results_dir.glob("*/result.json")):
        data = json.loads(path.read_text())
        own_recipe = any(path.parent.glob("*.toml"))
        shipped = (RECIPE_DIR / f"{data['recipe']}.toml").is_file()
        out.append(CommittedResult(path.parent.name, shipped and not own_recipe
                                   and data["fidelity"] == CALIBRATION_FIDELITY, data))
    return out


def _number(x: float) -> str:
    """Three significant digits, trailing zeros kept (64.0, not 64)."""
    return f"{x:#.3g}".rstrip(".") if x != 0 else "0"


def _decimals(error: float) -> int:
    """Decimals that show ``error`` (> 0) to its second significant digit."""
    return min(6, max(0, 1 - math.floor(math.log10(error))))


def _with_error(value: float, stderr: float) -> tuple[str, str]:
    """Value and stderr to the stderr's second significant digit (the usual way to quote a measurement)."""
    d = _decimals(stderr)
    return f"{value:.{d}f}", f"{stderr:.{d}f}"


def _quantity_cells(q: dict[str, Any]) -> tuple[str, str, str]:
    """(value, stderr, unit) of one quantity, in display units."""
    unit, factor = DISPLAY_UNITS.get(q.get("units", ""), (q.get("units", ""), 1.0))
    if q.get("value") is None:
        return "–", "–", unit
    if q.get("stderr"):
        return (*_with_error(q["value"] * factor, q["stderr"] * factor), unit)
    return _number(q["value"] * factor), "–" if q.get("stderr") is None else "0", unit


def _flags(q: dict[str, Any]) -> str:
    """What result.json says about a quantity beside its value (status, drift, grid error, repulsive end)."""
    unit, factor = DISPLAY_UNITS.get(q.get("units", ""), (q.get("units", ""), 1.0))
    flags = []
    if q.get("status") not in (None, "measured"):
        flags.append(str(q["status"]))
    if q.get("drifting"):
        flags.append("drift flagged")
    if q.get("repulsive_end") is False:
        flags.append("no repulsive end: lower bound")
    if q.get("discretisation_error") is not None:
        grid = abs(q["discretisation_error"]) * factor
        flags.append(f"grid ± {grid:.{_decimals(grid)}f}" if grid > 0 else "grid ± 0")
    reg = q.get("registries")
    if reg is not None:              # a count (W_F) or the registries averaged over (T dS)
        flags.append(f"{len(reg) if isinstance(reg, (list, tuple)) else reg} registries")
    return "; ".join(flags)


def _row(cells: list[str]) -> str:
    return "| " + " | ".join(cells) + " |"


def results_table(results: list[CommittedResult], calibration_inputs: bool) -> str:
    """One row per shown quantity of every result of the kind asked for."""
    lines = [_row(["result", "quantity", "value", "stderr", "unit", "notes", "run hash"]),
             _row(["---"] * 7)]
    for r in results:
        if r.calibration_input != calibration_inputs:
            continue
        for name in SHOWN.get(r.data["workflow"], ()):
            q = r.data["quantities"].get(name)
            if q is None:
                continue
            lines.append(_row([f"`{r.folder}`", f"`{name}`", *_quantity_cells(q), _flags(q),
                               f"`{r.data['run_hash'][:16]}`"]))
    return "\n".join(lines)


def cost_table(results: list[CommittedResult]) -> str:
    """Size, length and measured speed of every committed run (dynamics only, minimisation not counted)."""
    lines = [_row(["result", "kind", "atoms", "MD steps", "simulated (ns)", "dynamics wall (min)", "ns/day",
                   "M atom-steps/s", "MPI ranks", "finished (UTC)"]), _row(["---"] * 10)]
    for r in results:
        d = r.data
        wall = d["wall_s"]["dynamics"] if isinstance(d["wall_s"], dict) else d["wall_s"]
        lines.append(_row([f"`{r.folder}`", "calibration input" if r.calibration_input else "study",
                           str(d["n_atoms"]), f"{d['steps']:,}", f"{d['steps'] * d['timestep_fs'] * 1e-6:.3g}",
                           f"{wall / 60:.1f}", f"{d['ns_per_day']:.3g}", f"{d['atom_steps_per_s'] * 1e-6:.3g}",
                           "-" if d["np"] is None else str(d["np"]),
                           d["provenance"]["created_utc"][:16].replace("T", " ")]))
    return "\n".join(lines)


def tables(results_dir: Path = RESULTS_DIR) -> dict[str, str]:
    """The generated blocks of docs/md.md, by marker name."""
    results = committed_results(results_dir)
    return {"md-results": results_table(results, True), "md-studies": results_table(results, False),
            "md-cost": cost_table(results)}


def _block_re(name: str) -> re.Pattern[str]:
    return re.compile(rf"(<!-- generated: {re.escape(name)} -->)(.*?)(<!-- /generated -->)", re.S)


def render(text: str, blocks: dict[str, str]) -> str:
    """``text`` with every marked block replaced by its generated content (each marker must be there once)."""
    for name, body in blocks.items():
        pattern = _block_re(name)
        if len(pattern.findall(text)) != 1:
            raise ValueError(f"docs/md.md: marker <!-- generated: {name} --> must occur exactly once")
        text = pattern.sub(lambda m, b=body: f"{m.group(1)}\n{b}\n{m.group(3)}", text)
    return text


def main() -> None:
    """Rewrite the generated blocks of docs/md.md in place."""
    atomic_write_text(DOC_PATH, render(DOC_PATH.read_text(), tables()))


if __name__ == "__main__":  # python -m md.report_tables
    main()
