"""`nanoimpact paper`: run, draw, check, summarise. Writes into one output folder (see run.py)."""
from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Callable

from ..output.provenance import provenance
from ..output.results import dumps
from . import checks, figures
from .checks import NOMINAL_ONLY
from .run import fig4_curves, run_paper
from .sampled_claims import judged_over_samples, loop_claim
from .samples import nominal_bundle, set_uncertainty_rows
from .single_surfaces import attach as attach_single_surfaces
from .verdict import REPRODUCTION, VERIFICATION, over_samples, single_text
from .wet_checks import evaluate_wet


def _fmt(x, spec=".4g"):
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def summary_table(set_name: str, impacts: dict) -> list[str]:
    lines = [f"### Parameter set `{set_name}`", "",
             "| case | impacts | rebounds > 1e-3 h0 | status | first rebound / h0 | first impact duration (ns) "
             "| first peak force (uN) | energy audit | wall (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for case, item in sorted(impacts.items()):
        res = item["result"]
        h0 = res["scene"]["si"]["release_height"]
        b = res["bounces"][0]
        reb = checks.rebounds(res)
        lines.append(f"| {case} | {res['n_bounces']} | {len(reb)} | {res['status']} | "
                     f"{_fmt(reb[0] / h0 if reb else 0.0)} | {_fmt(b['duration'] * 1e9 if b['duration'] else None)} | "
                     f"{_fmt(b['peak_force'] * 1e6)} | {res['energy_audit']['max_relative_error']:.1e} | "
                     f"{item['wall_s']:.1f} |")
    return lines


def regime_lines(set_name: str, impacts: dict) -> list[str]:
    out = []
    for case in ("rough_silica", "rough_ots"):
        if case not in impacts:
            continue
        res = impacts[case]["result"]
        law = res["models"]["contact_law"]
        reg = law.get("regime", {})
        ek = res["energy_audit"]["reference_energy"]
        first_loss = res["bounces"][0]["energy_booked"]
        out.append(f"- `{case}`: sigma/delta_c = {_fmt(reg.get('sigma_over_delta_c'))}, Fuller-Tabor theta = "
                   f"{_fmt(reg.get('fuller_tabor_theta'))}, Tabor mu = {_fmt(reg.get('tabor_parameter'))} "
                   f"(z0 = {reg.get('tabor_z0', 0) * 1e9:.2g} nm), summit E* = "
                   f"{_fmt(reg.get('summit_e_star', 0) / 1e9)} GPa; "
                   "hysteresis loss of the first impact / its kinetic energy = "
                   f"{_fmt(first_loss / ek if ek else None)}; "
                   f"summits in the footprint {_fmt(law['datum']['summits_in_footprint'])}, most attached at once "
                   f"{_fmt(res['models'].get('diagnostics', {}).get('max_contacts'))}; "
                   f"z_max = {_fmt(law['z_max'] * 1e9)} nm")
    return out


def explain(set_name: str, impacts: dict, set_checks: list[dict]) -> list[str]:
    """What happens under this set and why, in the regime numbers (for summary.md)."""
    failed = [c["name"] for c in set_checks if c["state"] == "fail" and c["kind"] == REPRODUCTION]
    res = impacts.get("rough_silica", {}).get("result")
    if res is None:
        return []
    reg = res["models"]["contact_law"].get("regime", {})
    loss = res["bounces"][0]["energy_booked"] / res["energy_audit"]["reference_energy"]
    contacts = res["models"].get("diagnostics", {}).get("max_contacts", 0.0)
    mu = reg.get("tabor_parameter", 0.0)
    lines = [f"What happens with `{set_name}`: the first impact of rough silica loses {loss:.3g} of its kinetic "
             f"energy to summit hysteresis, with at most {contacts:.3g} summits attached at once."]
    if contacts < 10:
        lines.append("Fewer than 10 summits carry the impact, so the GW average is at the edge of its validity "
                     "(the discrete mode shows the spread of single realisations).")
    if mu < 1:
        lines.append(f"The Tabor parameter of the summits is {mu:.2g} < 1: the summits sit on the DMT side of the "
                     "JKR-DMT transition, where the JKR loop the model uses overstates the hysteresis.")
    if failed:
        lines.append("Reproduction claims that fail: " + ", ".join(f"`{n}`" for n in failed) + ". "
                     + ("With so little energy lost per impact the roller keeps bouncing: no stiction within the "
                        "run, and the roughness trends become too weak to order cleanly." if loss < 0.05 else
                        "See the regime numbers above."))
    else:
        lines.append("No reproduction claim fails (see the table for those not evaluable).")
    return lines


def wet_lines(set_name: str, wet: dict, impacts: dict) -> list[str]:
    """Wet and SAM section of summary.md: meniscus decisions of the drops, escape velocities, t_a."""
    out = ["Wet and SAM (40 % RH, sigma = 6 nm, rigid substrate):", ""]
    for case in ("wet_silica", "wet_ots"):
        if case in impacts:
            m = impacts[case]["result"]["models"]["menisci"]
            out.append(f"- drop `{case}`: menisci {'used' if m.get('used') else 'left out'}: {m.get('why')}")
    si, ots = wet.get("wet_silica"), wet.get("wet_ots")
    if si:
        e_d, e_w = (si["escape_dry"] or {}).get("escape_velocity"), (si["escape_wet"] or {}).get("escape_velocity")
        t_a = si["condensation_time"]
        if si["menisci_possible"]:
            free = [p["wet"]["duration"] for p in si["points"] if not p["wet"]["stuck"]]
            outlast = [p for p in si["points"] if not p["dry"]["stuck"] and p["dry"]["duration"] >= t_a]
            out.append(f"- bare silica: escape velocity {_fmt(e_d)} m/s dry, {_fmt(e_w)} m/s with menisci "
                       f"(t_a = {_fmt(t_a)} s); {len(outlast)} dry impacts near escape outlast t_a and still rebound, "
                       f"{sum(p['wet']['stuck'] for p in outlast)} of them stick with menisci; the longest wet impact "
                       f"that rebounds lasts {_fmt(max(free, default=0.0))} s (t_a {_fmt(t_a)} s); limiting gap "
                       f"{_fmt(e_w * e_w / (2 * si['gravity']) if e_w else None)} m with menisci, "
                       f"{_fmt(e_d * e_d / (2 * si['gravity']) if e_d else None)} m dry")
            m = si.get("menisci") or {}
            out.append(f"- solid adhesion inside a bridge: {m.get('solid_adhesion')} (solid pull taken per compressed "
                       f"bridged summit {_fmt(m.get('solid_pull'))} N, bridge pull F0 {_fmt(m.get('bridge_pull_off'))} "
                       f"N); t_a = {_fmt(t_a)} s declared, {_fmt(si.get('condensation_time_nucleation'))} s by the "
                       f"nucleation estimate")
            out.append("- " + t_a_study_line(si))
        else:
            out.append(f"- bare silica: no menisci ({si['why_no_menisci']}); escape velocity {_fmt(e_d)} m/s")
    if ots:
        e_o = (ots["escape_dry"] or {}).get("escape_velocity")
        g = ots["gravity"]
        out.append(f"- OTS: no bridges ({ots['why_no_menisci']}); escape velocity {_fmt(e_o)} m/s, limiting gap "
                   f"{_fmt(e_o * e_o / (2 * g) if e_o else None)} m")
    return out


def t_a_study_line(si: dict) -> str:
    """Fig 8a's t_a claim along t_a: where it flips below and above the declared value and where it holds."""
    study = si.get("t_a_study") or {}
    longest = si.get("longest_dry_rebound_s")
    flips = "; ".join(f"{f['from']} -> {f['to']} at {_fmt(f['t_a_s'])} s" for f in study.get("flips", []))
    held = study.get("holds_in_s")
    def span(r):
        return " - ".join(_fmt(x) if x is not None else "beyond the scan" for x in r) + " s"

    anywhere = ", ".join(span(r) for r in study.get("holds_anywhere_s") or [])
    where = (f"holds for t_a in {span(held)}" if held else
             f"at the declared t_a {study.get('state_at_t_a', '-')}; holds for t_a in {anywhere or 'no range scanned'}")
    scan = study.get("grid_s") or [None, None]
    return (f"t_a study of `fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a` (scanned {_fmt(scan[0])}-"
            f"{_fmt(scan[1])} s, flips to {study.get('rel_tol', 0):.0%}): {where}; {flips or 'no flip in the scan'}; "
            f"above {_fmt(longest)} s (the longest dry impact that still rebounds) it has no subject")


def _of_set(collected: dict, set_name: str) -> tuple[dict, dict, dict]:
    """A set's impacts, sweeps and wet sweeps from the collected runs, keyed by case."""
    return tuple({c: v for (c, s), v in collected[kind].items() if s == set_name}
                 for kind in ("impacts", "sweeps", "wet"))


def set_claims(set_name: str, collected: dict) -> list[dict]:
    """Every checks.json entry of one set: verification first, then reproduction."""
    impacts, sweeps, wet = _of_set(collected, set_name)
    results = {c: v["result"] for c, v in impacts.items()}
    curves = collected["curves"][set_name]
    out = checks.verify_dry(set_name, results, sweeps, {k: {"loop_area": v["loop_area"]} for k, v in curves.items()})
    bundles = {c: v["bundle"] for (c, s), v in collected.get("bundles", {}).items() if s == set_name}
    rows = [b for b in bundles.values() if not b.get("seed")]
    seeds = [b for b in bundles.values() if b.get("seed")]
    out += checks.reproduce_dry(set_name, results, sweeps, [b for b in rows if "error" not in b])
    out += evaluate_wet(set_name, wet, results)
    nominal = nominal_bundle(results, sweeps, wet, curves)
    if nominal is not None:
        out += judged_over_samples(set_name, nominal, rows)
    elif curves:                    # a run cut to Fig 4: its loop claim from the curves, on the nominal set alone
        loops = {"loop": {k: v["loop_area"] for k, v in curves.items()}}
        out.append(over_samples(loop_claim(set_name, loops), [], NOMINAL_ONLY))
    attach_single_surfaces(set_name, out, seeds if nominal is not None else [], nominal)
    return sorted(out, key=lambda c: c["kind"] != VERIFICATION)


def _band_text(key: str, b: dict) -> str:
    """A band (min-max, median) or a proportion (k of n, Wilson 95 % interval) as one phrase."""
    if "fraction" in b:
        lo, hi = b["wilson95"]
        return f"{key} {b['k']} of {b['n']} (95 % {lo:.2f}-{hi:.2f})"
    return f"{key} {_fmt(b['min'])}-{_fmt(b['max'])} (median {_fmt(b['median'])}, n {b['n']})"


def _source_text(c: dict) -> str:
    src = c.get("threshold_source") or {}
    return f"paper ({src['section']})" if src.get("source") == "paper" else src.get("source", "")


def claim_tables(set_checks: list[dict]) -> list[str]:
    """summary.md's tables: verification checks, then the reproduction claims judged on the paper's model with the
    single surfaces beside them, then each departure's mechanism."""
    ver = [c for c in set_checks if c["kind"] == VERIFICATION]
    rep = [c for c in set_checks if c["kind"] == REPRODUCTION]
    lines = ["Verification (the code solves its equations; the same for any set):", "",
             "| check | state | margin | tolerance | units | reason |", "|---|---|---|---|---|---|"]
    lines += [f"| `{c['name']}` | {c['state']} | {_fmt(c['margin'])} | {_fmt(c['tolerance'])} | {c['units']} | "
              f"{c.get('reason', '')} |" for c in ver]
    rows = max((c.get("sampled", {}).get("uncertainty", 0) for c in rep), default=0)
    lines += ["", "Reproduction, judged on the paper's model (the averaged GW surface of its eqs 10-11; pass needs the "
              "margin above its tolerance" + (f" and holds_fraction >= 0.9 over the nominal run and {rows} "
                                              "uncertainty rows" if rows else "; no uncertainty rows were used: each "
                                              "claim is judged on the set's nominal runs") + "). Beside it, the "
              "project's finding beyond the paper: on how many single discrete-summit surfaces the claim holds "
              "(Wilson 95 % interval; undecided surfaces, with no subject or a margin inside its tolerance, counted "
              "apart with theirs):", "",
              "| claim | paper's model | single surfaces: holds (95 %) | holds_fraction | uncertainty rows | margin "
              "| tolerance | units | threshold | reason | bands |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in rep:
        bands = "; ".join(_band_text(k, b) for k, b in (c.get("bands") or {}).items() if b)
        lines.append(f"| `{c['name']}` | {c['state']} | {single_text(c)} | {_fmt(c.get('holds_fraction'), '.3g')} | "
                     f"{c.get('sampled', {}).get('uncertainty', 0)} | {_fmt(c['margin'])} | {_fmt(c['tolerance'])} | "
                     f"{c['units']} | {_source_text(c)} | {c.get('reason', '')} | {bands} |")
    departs = [f"- `{c['name']}`: {c['single_surfaces']['mechanism']}." for c in rep
               if (c.get("single_surfaces") or {}).get("mechanism")]
    if departs:
        lines += ["", "Where single surfaces depart from the paper's model, and why:", "", *departs]
    notes = [f"- `{c['name']}`: {c['sampled']['note']}" for c in rep if c.get("sampled", {}).get("note")]
    return lines + (["", "Not judged over uncertainty rows, and why:", "", *notes] if notes else [])


def make_paper(sets: list[str], out: str | Path, *, fidelity: str | None = None, workers: int | None = None,
               executor_name: str = "processes", scheduler: str | None = None, executor=None,
               progress: Callable[[str], None] = print, draw_figures: bool = True, seeds: int = 0,
               uncertainty: dict[str, list[dict]] | None = None, case_figures: bool = False) -> dict:
    """Run every case for every set into `out`; returns {"checks": [...], "wall_s": ...}.

    The sampled reproduction claims run on the nominal set, on `seeds` discrete-summit seeds per set (the command
    line's default is samples.DEFAULT_SEEDS; callers that only need pass/fail of the nominal runs, such as the
    calibration's reverts, leave 0) and on the `uncertainty` rows ({set name: [scene overrides, ...]}, e.g.
    `samples.read_uncertainty_csv` of a calibration's uncertainty.csv, or the calibration's own draws); a set that
    points to its rows (`[meta] uncertainty_rows`, `samples.set_uncertainty_rows`) is judged over them unless
    `uncertainty` names it.

    `draw_figures=False` draws none of Figs 4-8b (the claims, summary.md and checks.json are the same): for callers
    that want the claims alone, such as the calibration's claim attribution. `case_figures=True` also draws each
    impact case's own height.png and impacts.png beside its result.json (`nanoimpact paper --case-figures`).

    Where the runs go: `executor` (an open nanoimpact.executors object, e.g. the calibration's), else a new
    `executor_name` executor with `workers` and `scheduler` (default: a local pool of CPU-count processes)."""
    out = Path(out)
    start = time.perf_counter()
    uncertainty = {**set_uncertainty_rows(sets), **(uncertainty or {})}

    def draw(set_name: str, collected: dict) -> None:
        """A set's figures, drawn here while the pool runs the next set (~5 s of matplotlib per set)."""
        impacts, sweeps, wet = _of_set(collected, set_name)
        curves = collected["curves"].get(set_name) or fig4_curves(
            set_name if set_name in sets else next(s for s in sets if Path(s).stem == set_name), fidelity)
        collected["curves"][set_name] = curves
        figures.save(figures.fig4(curves, set_name, out), out / f"fig4_{set_name}.png")
        figures.save(figures.fig5a(impacts, set_name, out), out / f"fig5a_{set_name}.png")
        figures.save(figures.fig5b(impacts, set_name, out), out / f"fig5b_{set_name}.png")
        figures.save(figures.fig6(impacts, set_name, out), out / f"fig6_{set_name}.png")
        figures.save(figures.fig7(impacts, set_name, out), out / f"fig7_{set_name}.png")
        figures.save(figures.fig8a(sweeps, set_name, out, wet), out / f"fig8a_{set_name}.png")
        figures.save(figures.fig8b(wet, set_name, out), out / f"fig8b_{set_name}.png")

    collected = run_paper(sets, out, fidelity=fidelity, workers=workers, executor_name=executor_name,
                          scheduler=scheduler, executor=executor, progress=progress,
                          on_set_done=draw if draw_figures else None, seeds=seeds, uncertainty=uncertainty,
                          case_figures=case_figures)
    all_checks, summary = [], ["# nanoimpact paper: dry, wet and SAM cases", "",
                               f"Parameter sets: {', '.join(sets)}; fidelity: {fidelity or 'scene default'}. "
                               "h0 = release height; a rebound counts if it rises above 1e-3 h0.", ""]
    for set_name in (Path(s).stem for s in sets):
        impacts, sweeps, wet = _of_set(collected, set_name)
        set_checks = set_claims(set_name, collected)
        all_checks += set_checks
        summary += summary_table(set_name, impacts) + ["", "Regime:", ""] + regime_lines(set_name, impacts) + [""]
        summary += claim_tables(set_checks) + [""]
        summary += explain(set_name, impacts, set_checks) + [""]
        esc = {c: (s["escape"] or {}).get("escape_velocity") for c, s in sweeps.items()}
        summary += ["Escape velocities (m/s): " + ", ".join(f"{c} {_fmt(v)}" for c, v in sorted(esc.items())), ""]
        summary += wet_lines(set_name, wet, impacts) + [""]
    wall = time.perf_counter() - start
    summary += [("Each case's own figures (height.png, impacts.png) are in cases/<case>/<set>/ beside its result.json."
                 if case_figures else "Each case's result.json and timeseries.csv are in cases/<case>/<set>/; its own "
                 "figures (height.png, impacts.png) are drawn there with `nanoimpact paper --case-figures`."), ""]
    summary += [f"Total wall time {wall:.1f} s (runs {collected['total_wall_s']:.1f} s).", ""]
    record = {"checks": all_checks, "sets": sets, "fidelity": fidelity, "wall_s": wall, "seeds": seeds,
              "uncertainty_samples": {k: len(v) for k, v in (uncertainty or {}).items()},
              "provenance": provenance(input_hash="paper:" + ",".join(sets))}
    tmp = out / "checks.json.tmp"
    tmp.write_text(dumps(record) + "\n")
    tmp.replace(out / "checks.json")
    (out / "summary.md.tmp").write_text("\n".join(summary))
    (out / "summary.md.tmp").replace(out / "summary.md")
    json.loads((out / "checks.json").read_text())
    return record
