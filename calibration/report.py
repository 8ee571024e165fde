"""What a calibration returns and writes: a typed `CalibrationReport` (`calibration.calibrate(...)`), its
`calibration.json` (the same record as before, plus versions) and `report.md`.

One place for the calibration's output files: `CalibrationReport.write(out)` writes both atomically.
"""
from __future__ import annotations

import json
import math
import platform
import sys
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Mapping

from continuum.api import single_text
from nanoimpact import __version__
from nanoimpact.fileio import atomic_write_text

from .targets import comparison_lines, range_cell, target_figure, target_of, verdict

__all__ = ["ValueRow", "CalibrationReport", "versions"]


@dataclass(frozen=True)
class ValueRow:
    """One scene key the calibration maps: where its value came from and whether it was used.

    `status`: 'used' (the MD value is in the set), 'rejected' (the base set's value is kept; `why` says why)
    or 'missing' (no result of `recipe`)."""

    key: str
    recipe: str
    status: str
    base_value: Any = None
    quantity: str | None = None
    value: float | None = None
    stderr: float | None = None
    units: str = ""
    run_hash: str | None = None
    fidelity: str | None = None
    why: str | None = None

    @classmethod
    def from_dict(cls, row: Mapping) -> "ValueRow":
        known = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in row.items() if k in known})

    def to_dict(self) -> dict:
        return asdict(self)


def versions() -> dict:
    """Versions a calibration's numbers depend on (the MD results carry their own, with their run hashes)."""
    import numpy
    import scipy

    return {"nanoimpact": __version__, "python": platform.python_version(), "numpy": numpy.__version__,
            "scipy": scipy.__version__, "platform": sys.platform}


@dataclass(frozen=True)
class CalibrationReport:
    """The result of `calibration.calibrate(...)`.

    `set_path` is the parameter set written; `rows` say for each mapped scene key whether the MD value was used;
    `md_sources` where each MD result came from (committed, md cache, ran); `paper_checks` the founding paper's
    claims for every set run; `bands` the uncertainty bands (median, 5 %, 95 %, n); `timings` wall seconds per
    step. `to_dict()` is `calibration.json`.
    """

    name: str
    set_path: Path
    out: Path
    calibration: Any
    """The checked recipe (`calibration.pipeline.CalibrationRecipe`)."""
    rows: tuple[ValueRow, ...]
    md_sources: Mapping[str, Mapping[str, Any]]
    bands: Mapping[str, Any]
    paper_checks: tuple[Mapping[str, Any], ...]
    timings: Mapping[str, float]
    machine: Mapping[str, Any]
    md_compute_total_s: float
    claim_attribution: Mapping[str, Any] = field(default_factory=dict)
    """Why each claim that fails with the calibrated set fails (`calibration.attribution.attribute_claims`)."""
    validation: Mapping[str, Any] = field(default_factory=dict)
    """Pull-off F / (2 pi R) against the flat-slab W_F per pull-off run
    (`calibration.validation.pulloff_validation`)."""
    versions: Mapping[str, str] = field(default_factory=versions)

    @property
    def set_meta(self) -> Mapping[str, Any]:
        """The written set's [meta] (origins, replaced choices), read from `set_path`."""
        import tomllib

        return tomllib.loads(Path(self.set_path).read_text()).get("meta") or {}

    @property
    def used(self) -> tuple[ValueRow, ...]:
        return tuple(r for r in self.rows if r.status == "used")

    @property
    def not_used(self) -> tuple[ValueRow, ...]:
        return tuple(r for r in self.rows if r.status != "used")

    def claims(self, set_name: str | None = None) -> tuple[Mapping[str, Any], ...]:
        """The paper's claims for `set_name` (default: the calibrated set)."""
        name = set_name or Path(self.set_path).stem
        return tuple(c for c in self.paper_checks if c["set"] == name)

    def to_dict(self) -> dict:
        return {"calibration": self.calibration.to_dict(), "set": str(self.set_path),
                "rows": [r.to_dict() for r in self.rows], "md_sources": dict(self.md_sources),
                "bands": dict(self.bands), "md_compute_total_s": self.md_compute_total_s,
                "timings": dict(self.timings), "machine": dict(self.machine), "versions": dict(self.versions),
                "paper_checks": list(self.paper_checks), "claim_attribution": dict(self.claim_attribution),
                "validation": dict(self.validation)}

    def write(self, out: str | Path | None = None) -> Path:
        """calibration.json, md_vs_literature.png and report.md in `out` (default: the run's folder), each written
    atomically."""
        out = Path(out or self.out)
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out / "calibration.json", json.dumps(self.to_dict(), indent=1, default=str) + "\n")
        target_figure(self.rows, out / "md_vs_literature.png",
                      title=f"calibration `{self.name}`: MD values (+- stderr) against the literature")
        atomic_write_text(out / "report.md", report_markdown(self))
        return out / "report.md"


# ----------------------------------------------------------------------------- report.md
def _fmt(x, spec=".4g"):
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def _work_sentence(rows: tuple[ValueRow, ...]) -> str:
    """What the work-of-adhesion values are: free energies (force integration) or energy differences."""
    used = {r.key: r.quantity for r in rows if "work_of_adhesion" in r.key and r.status == "used"}
    fe = sorted(k for k, q in used.items() if q == "work_of_adhesion_free_energy")
    de = sorted(k for k, q in used.items() if q == "work_of_adhesion")
    parts = []
    if fe:
        parts.append(f"{', '.join(f'`{k}`' for k in fe)}: free energy of separation by force integration (the "
                     "Dupre work JKR needs); its stderr includes the window grid's discretisation error, and dE/A "
                     "is recorded beside it in [meta.calibration]")
    if de:
        parts.append(f"{', '.join(f'`{k}`' for k in de)}: the energy difference dE/A, not a free energy (the run "
                     "has no force integration)")
    return ("Work of adhesion: " + "; ".join(parts) + " (docs/calibration.md).") if parts else ""


def _validation_lines(validation: Mapping[str, Any]) -> list[str]:
    """The pull-off check: F / (2 pi R) (DMT: an MD-scale asperity's Tabor mu, computed from the run and in
    [meta.validation], is small) against the flat-slab W_F of the same pair, as a ratio and in combined stderrs.
    Nothing of it enters the set."""
    if not validation:
        return []
    lines = ["", "**Pull-off validation (DMT, F = 2 pi R W; not used in the set):**", "",
             "| pull-off run | F / (2 pi R) (J/m^2) | flat-slab W_F (J/m^2) | ratio | difference | "
             "residual drag (nN) |",
             "|---|---|---|---|---|---|"]
    for run, v in validation.items():
        diff = v.get("difference_in_stderr")
        drag = v.get("residual_drag_N")
        lines.append(f"| {run} (vs {v.get('adhesion_recipe')}) | {_fmt(v['F_over_2piR'])} +- "
                     f"{_fmt(v.get('F_over_2piR_stderr'), '.2g')} | {_fmt(v['W_F'])} +- "
                     f"{_fmt(v.get('W_F_stderr'), '.2g')} "
                     f"| {v['ratio']:.2f} | {'-' if diff is None else f'{diff:+.1f} sigma'} | "
                     f"{'-' if drag is None else f'{drag * 1e9:+.3f}'} |")
    lines += ["", "Each W is the flat-slab W of the interaction the pull-off runs (like for like): "
              + "; ".join(f"{run}: {v['compared_with']}" + (f" (with the static tail it is {_fmt(v['W_F_with_tail'])})"
                                                             if v.get("W_F_with_tail") is not None else "")
                          for run, v in validation.items() if v.get("compared_with")) + "."]
    rate = {run: v["rate_extrapolated"] for run, v in validation.items() if v.get("rate_extrapolated")}
    if rate:
        lines += ["", "Rate: the pull-off at the run's slowest speed is rate-inflated; per tip position, extrapolated "
                      "linearly in v to v -> 0 (quasi-static) and, beside it, linearly in ln v to 10 m/s (Bell-Evans); "
                      "Student-t stderr over the positions. The 20 and 10 m/s pulls that would test these models are "
                      "not run.", "",
                  "| pull-off run | speeds (m/s) | F/(2 pi R), v -> 0 (linear in v) | ratio to W | difference | "
                  "F/(2 pi R) at 10 m/s (linear in ln v) |", "|---|---|---|---|---|---|"]
        for run, r in rate.items():
            lin, lg = r["linear_v0"], r["log_at_10"]
            lines.append(f"| {run} | {', '.join(f'{x:g}' for x in r['speeds_m_s'])} | {_fmt(lin['F_over_2piR'])} +- "
                         f"{_fmt(lin['F_over_2piR_stderr'], '.2g')} | {r['ratio']:.2f} | "
                         f"{r['difference_in_stderr']:+.1f} sigma | {_fmt(lg['F_over_2piR'])} +- "
                         f"{_fmt(lg['F_over_2piR_stderr'], '.2g')} |")
    off = [run for run, v in validation.items()
           if v.get("difference_in_stderr") is not None and abs(v["difference_in_stderr"]) > 2.0]
    if off:
        lines += ["", f"Beyond 2 combined stderrs: {', '.join(off)}. A carved, stepped dome at one lateral registry "
                      "is not two flat faces averaged over registries (docs/md.md discusses the gap); the set "
                      "uses the flat-slab values."]
    return lines


def _chosen_lines(meta: Mapping[str, Any]) -> list[str]:
    """What the set still chooses (origin `chosen`, with each reason), then what it replaced, then a count of the
    rest by origin: first in the report, because a prediction rests on these choices."""
    origin = meta.get("origin") or {}
    chosen = [(k, e) for k, e in origin.items() if e.get("kind") == "chosen"]
    lines = ["## Still chosen", "",
             (f"{len(chosen)} of the set's {len(origin)} values are declared choices, not measurements "
              "([meta.origin], docs/calibration.md):" if chosen else
              f"None: every one of the set's {len(origin)} values is measured or a material constant."), ""]
    lines += [f"- `{k}`: {e['reason']}" for k, e in chosen]
    replaced = meta.get("replaced") or {}
    if replaced:
        lines += ["", "Choices of the base set replaced here:", ""]
        lines += [f"- `{k}`: the base's {v.get('base_value')!r} ({v.get('base_reason')}) gives way to {v.get('now')}"
                  for k, v in replaced.items()]
    kinds: dict[str, int] = {}
    for e in origin.values():
        kinds[e.get("kind")] = kinds.get(e.get("kind"), 0) + 1
    lines += ["", "Origins: " + ", ".join(f"{n} {k}" for k, n in kinds.items()) + ".", ""]
    return lines


LAYER, RADIUS = "surfaces.sam.layer_modulus", "surfaces.roughness.summit_radius"


def _acceptance_text(a: Mapping[str, Any], probe: Mapping[str, Any] | None) -> str:
    """One claim's acceptance line: accepted or not, over how many samples it holds, why; Fig 4's loop claim
    with what its declared choices do to the loop ratio (continuum.paper.loop_probe)."""
    frac = a.get("holds_fraction")
    held = (f"holds on {frac:.2f} of {a.get('samples')} samples" if frac is not None
            else f"{a.get('samples')} samples, none decided")
    text = f"**Acceptance:** {'accepted' if a['accepted'] else 'not accepted'} ({held}): {a['why']}."
    if probe:
        stiff, scan = probe.get("stiff_layer"), probe["summit_radius_scan"]
        kind = probe.get("origins") or {}
        parts = [f"loop ratio {probe['loop_ratio']:.3g} with the set's values"]
        if stiff:
            parts.append(f"{stiff['loop_ratio']:.3g} with the SAM layer as stiff as its substrate "
                         f"({stiff['layer_modulus_Pa']:.3g} Pa instead of the set's "
                         f"{stiff['set_layer_modulus_Pa']:.3g}, {kind.get(LAYER, 'origin not given')})")
        cross = probe.get("crossing_m")
        parts.append(f"over summit radii {scan['radius_m'][0] * 1e6:.2g}-{scan['radius_m'][-1] * 1e6:.2g} um (the "
                     f"set's {probe['set_summit_radius_m'] * 1e6:.2g}, {kind.get(RADIUS, 'origin not given')}) "
                     f"it runs {scan['loop_ratio'][0]:.3g} to "
                     f"{scan['loop_ratio'][-1]:.3g}" + (f", passing 1 between {cross[0] * 1e6:.2g} and "
                                                        f"{cross[1] * 1e6:.2g} um" if cross else ", never passing 1"))
        decides = [f"{w} ({kind.get(k, 'origin not given')})" for w, k, on in
                   (("the compliant layer", LAYER, stiff and stiff["loop_ratio"] < 1), ("the summit radius", RADIUS,
                                                                                         cross)) if on]
        if probe["loop_ratio"] < 1:
            verdict_text = ("With the set's own values the loop of OTS is the smaller; the samples' inputs carry "
                            "the ratio across 1 (its band in `paper-checks.json`).")
        elif decides:
            verdict_text = f"It is decided by {' and '.join(decides)}."
        else:
            verdict_text = "Neither the layer nor the summit radius alone restores it."
        text += " Probed: " + "; ".join(parts) + ". " + verdict_text
    return text


def report_markdown(rec: CalibrationReport) -> str:
    cal, t, m = rec.calibration, rec.timings, rec.machine
    lines = [f"# Calibration `{cal.name}` (base `{cal.base}`)", "", *_chosen_lines(rec.set_meta),
             f"Recipe `{cal.path}`; machine: {m['cores']} cores, {m['platform']}, Python {m['python']}; "
             f"nanoimpact {rec.versions.get('nanoimpact')}, NumPy {rec.versions.get('numpy')}, SciPy "
             f"{rec.versions.get('scipy')}. MD compute (the runs themselves, from their results): "
             f"{rec.md_compute_total_s:.0f} s. Pipeline wall time: MD jobs {t['md_s']:.1f} s "
             "(cached or committed runs cost nothing), paper cases "
             f"{t['paper_s']:.1f} s, uncertainty {t['uncertainty_s']:.1f} s, total "
             f"{t['total_s']:.1f} s. Set written to `{rec.set_path}`.", "",
             "## MD values", "", "| scene key | MD recipe | quantity | value | stderr | literature range (accepted) | "
             "against the literature range | status | why / run |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rec.rows:
        tgt = target_of(r.key)
        against = verdict(r.value, r.stderr, tgt).text if tgt and r.value is not None else "-"
        lines.append(f"| `{r.key}` | {r.recipe} | {r.quantity or '-'} | {_fmt(r.value)} "
                     f"{r.units} | {_fmt(r.stderr)} | {range_cell(tgt)} | {against} | {r.status} | "
                     f"{r.why or str(r.run_hash or '')[:16]} |")
    lines += comparison_lines(rec.rows)
    sets = sorted({c["set"] for c in rec.paper_checks})
    lines += _validation_lines(rec.validation)
    lines += ["", "MD jobs: " + "; ".join(f"{k}: {v['source']}" for k, v in rec.md_sources.items()), "",
              "A rejected or missing value keeps the base set's value (with the base set's [meta.origin] entry).",
              _work_sentence(rec.rows),
              "", "## The paper's claims per set", "",
              "Two columns per set: the verdict on the paper's model (the averaged GW surface), and for a reproduction "
              "claim on how many single discrete-summit surfaces it holds (Wilson 95 %; undecided surfaces counted "
              "apart with theirs): the project's finding beyond the paper, which decides nothing.", "",
              "| claim | " + " | ".join(f"{s} (paper's model) | {s} (single surfaces)" for s in sets) + " |",
              "|---|" + "---|---|" * len(sets)]
    by: dict[str, dict] = {}
    for c in rec.paper_checks:
        by.setdefault(c["name"], {})[c["set"]] = (("pass" if c["pass"] else "**fail**"
                                                   if c.get("state", "fail") == "fail" else c["state"]),
                                                  single_text(c) if c.get("kind") == "reproduction" else "-")
    for name, res in by.items():
        lines.append(f"| `{name}` | " + " | ".join(" | ".join(res.get(s, ("-", "-"))) for s in sets) + " |")
    name = Path(rec.set_path).stem
    mine = rec.claims()
    agree = [c["name"] for c in mine if c["pass"]]
    differ = [c for c in mine if not c["pass"]]
    lines += ["", f"**Where the calibrated physics agrees with the paper:** {len(agree)} of {len(mine)} claims hold "
              f"with the `{name}` set.", ""]
    if differ:
        why = {w["claim"]: w for w in (rec.claim_attribution or {}).get("claims", [])}
        lines += [f"**Where it does not** ({len(differ)}), and why: each MD value put back to the base set's "
                  "value alone, the paper's cases run again, and the claims that hold again name it "
                  "(`attribution/`):", ""]
        att = rec.claim_attribution or {}
        accept = {a["claim"]: a for a in att.get("acceptance", [])}
        lines += [f"- `{c['name']}`: needs {c['threshold']}; got {json.dumps(c['values'], default=str)[:300]}"
                  + (f". **Why:** {why[c['name']]['text']}." if c["name"] in why else "")
                  + (" " + _acceptance_text(accept[c["name"]], (att.get("choices") or {}).get(c["name"]))
                     if c["name"] in accept else "")
                  for c in differ]
        n_acc = sum(a["accepted"] for a in accept.values())
        lines += ["", f"**Accepted failures:** {n_acc} of {len(differ)} (a failure is accepted when one measured value "
                      "put back alone restores the claim, or, for a claim that holds on the set's own runs, one "
                      "measured input's spread over the Latin-hypercube rows carries it across (|Spearman rho| >= "
                      "0.5 with its margin), in the direction physics predicts: "
                      "`calibration.attribution.PHYSICAL_DIRECTION`)."]
    b = rec.bands
    lines += ["", "## Uncertainty", "",
              f"{b['samples']} Latin-hypercube samples (seed {b['seed']}) of `{b['scene']}`; inputs covered: "
              f"{', '.join(b['covers'])}; failed samples: {b['failed_samples']}."
              + (f" Left out on this scene, which has no SAM: {', '.join(b['left_out'])}." if b.get("left_out")
                 else ""), "",
              "| output | median | 5 % | 95 % | n |", "|---|---|---|---|---|"]
    trunc = b.get("truncated") or {}
    for key in ("first_rebound_over_h0", "rebound_count", "escape_velocity_m_per_s"):
        v = b[key]
        lines.append(f"| {key} | {_fmt(v['median'])} | {_fmt(v['p05'])} | {_fmt(v['p95'])} | {v['n']} |")
    if b.get("rebound_count_capped"):
        lines += ["", f"**rebound_count is a lower bound:** {b['rebound_count_capped']} of {b['rebound_count']['n']} "
                      f"samples reached the `max_bounces` cap ({b['max_bounces']}) without sticking; raise "
                      "`[uncertainty] max_bounces` for the full count."]
    if trunc:
        lines += ["", "**Truncated inputs:** each calibrated value is sampled from its MD normal truncated to the "
                      "key's allowed range; for " + "; ".join(
                          f"`{k}` ({v['outside']:.1%} of the normal lay outside [{_fmt(v['low'])}, {_fmt(v['high'])}])"
                          for k, v in trunc.items()) + " the truncation moves the samples (the others are normal)."]
    lines += ["", "Figures: `paper/` (Figs 4-8b per set), `uncertainty.png`, `md_vs_literature.png`; data: "
              "`uncertainty.csv`, `calibration.json`, `paper/checks.json`.", ""]
    return "\n".join(lines)
