"""Why a paper claim fails with the calibrated set: each MD value put back to its base value alone.

The calibrated set is the base set with the MD values written over it. A claim of the founding paper that holds
with the base set and fails with the calibrated one therefore fails because of one MD value, or of several together.
Which one is measured, not guessed. Each *revert* puts one group of MD values back to the base set's values,
with everything else calibrated. The group is the keys fed by one quantity of one MD run, such as the two silica
contact angles from `wsl_silica`. The paper's cases then run with each revert set, and the claims that hold
again name the values that broke them. This is a one-at-a-time sensitivity analysis (Saltelli et al., *Global
Sensitivity Analysis: The Primer*, Wiley 2008, section 1.2.2), done on the pass/fail outcome of each claim.

It answers "which value", not "which interaction of values". A claim that no single revert restores needs
several values together, and the report says so. A claim that fails with the base set too is not the
calibration's doing, and no revert is run for it.

Cost: one run of the paper's cases per group that differs from the base, only when some claim needs it. With the
shipped quick recipe that is up to seven sets of the paper's cases, each a few seconds of CPU
(docs/benchmarks.md). The runs go to the calibration's executor.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

from .mdset import _delete_nested, _set_nested, write_parameter_set

__all__ = ["Revert", "ClaimWhy", "reverts", "revert_table", "explain_claims", "attribute_claims", "acceptance",
           "PHYSICAL_DIRECTION"]

#: Fig 4's loop claim, probed over its declared choices when it fails (continuum.paper.loop_probe).
LOOP_CLAIM = "fig4_ots_loop_smaller_than_silica"
_W_SI, _W_OTS = "surfaces.work_of_adhesion", "surfaces.sam.work_of_adhesion"
_Z_SI, _Z_OTS = "surfaces.interaction_range", "surfaces.sam.interaction_range"
#: Silica stickier than OTS: the margin of a claim that bare silica adheres more than OTS rises with silica's
#: work of adhesion and falls with OTS's; a longer range z0 at the same work lowers the summits' Tabor parameter
#: and with it their hysteresis (Greenwood, Proc. R. Soc. A 453 (1997) 1277), so it acts the other way.
_SILICA_OVER_OTS = {_W_SI: +1, _W_OTS: -1, _Z_SI: -1, _Z_OTS: +1}
#: Bridges pull harder with a larger surface tension and a smaller contact angle (F = 4 pi R gamma cos theta).
_BRIDGES = {"menisci.surface_tension": +1, "surfaces.body.contact_angle": -1, "surfaces.substrate.contact_angle": -1}
#: The sign of d(margin)/d(value) physics predicts for a claim and a measured scene key (claims and keys not
#: listed have no declared direction, so a failure through them is not accepted).
PHYSICAL_DIRECTION = {
    "fig4_ots_loop_smaller_than_silica": _SILICA_OVER_OTS,
    "fig5a_ots_outbounces_silica": _SILICA_OVER_OTS,
    "fig8b_ots_lower_escape_velocity": _SILICA_OVER_OTS,
    "fig8b_ots_impact_shorter_at_the_same_low_velocity": _SILICA_OVER_OTS,
    "fig5a_silica_impacts_weaken_until_it_sticks": {_W_SI: +1, _Z_SI: -1},
    "fig7_sigma3_sticks_at_first_impact": {_W_SI: +1, _Z_SI: -1},
    "fig8a_menisci_end_rebounds_of_impacts_longer_than_t_a": _BRIDGES,
}


@dataclass(frozen=True)
class Revert:
    """One group of MD values put back to the base set's values: the keys one quantity of one MD run feeds."""

    recipe: str
    quantity: str
    keys: tuple[str, ...]
    calibrated: tuple[Any, ...]
    base: tuple[Any, ...]
    """The base set's values (None: the base set has no such key, so the scene's default applies)."""
    units: str
    set_name: str
    """Name (file stem) of the parameter set with this group reverted."""

    @property
    def label(self) -> str:
        return f"{self.recipe} {self.quantity}"

    def describe(self) -> str:
        """`key` calibrated -> base, for every key of the group."""
        def fmt(v):
            return "the scene default" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))
        return ", ".join(f"`{k}` {fmt(c)} -> {fmt(b)} {self.units}".rstrip()
                         for k, c, b in zip(self.keys, self.calibrated, self.base))

    def to_dict(self) -> dict:
        return {"recipe": self.recipe, "quantity": self.quantity, "keys": list(self.keys),
                "calibrated": list(self.calibrated), "base": list(self.base), "units": self.units,
                "set": self.set_name}


@dataclass(frozen=True)
class ClaimWhy:
    """Why one claim fails with the calibrated set.

    `cause`: 'base fails too' (not the calibration's doing), 'single' (`restored_by` lists each revert that
    alone makes the claim hold again), 'several' (no single revert restores it), 'samples' (it holds on the
    set's own runs and fails over the uncertainty samples or seeds) or 'not run' (`text` says why).
    """

    claim: str
    cause: str
    restored_by: tuple[str, ...]
    text: str

    def to_dict(self) -> dict:
        return {"claim": self.claim, "cause": self.cause, "restored_by": list(self.restored_by), "text": self.text}


def reverts(rows: Iterable[Mapping[str, Any]], set_name: str) -> tuple[Revert, ...]:
    """The groups to revert: the used rows whose value differs from the base set's, grouped by (recipe,
    quantity), in row order. `rows` are the calibration's value rows (dicts or ValueRow.to_dict())."""
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = {}
    for row in rows:
        if row.get("status") != "used" or row.get("value") == row.get("base_value"):
            continue
        groups.setdefault((row["recipe"], row.get("quantity") or ""), []).append(row)
    out = []
    for (recipe, quantity), members in groups.items():
        out.append(Revert(recipe=recipe, quantity=quantity, keys=tuple(r["key"] for r in members),
                          calibrated=tuple(r.get("value") for r in members),
                          base=tuple(r.get("base_value") for r in members), units=members[0].get("units") or "",
                          set_name=f"{set_name}--{recipe}--{quantity}"))
    return tuple(out)


def revert_table(table: Mapping[str, Any], revert: Revert) -> dict:
    """The calibrated set's table with `revert`'s keys back at their base values (a base without the key: the key
    removed, so the scene's default applies), and its [meta] saying so."""
    out = copy.deepcopy(dict(table))
    for key, base in zip(revert.keys, revert.base):
        if base is None:
            _delete_nested(out, key)
        else:
            _set_nested(out, key, base)
    meta = out.setdefault("meta", {})
    meta["description"] = (f"{meta.get('description', 'calibrated set')}, with {revert.label} put back to the base "
                           "set's values (claim attribution)")
    meta["reverted"] = {k: {"calibrated": c, "base": "scene default" if b is None else b}
                        for k, c, b in zip(revert.keys, revert.calibrated, revert.base)}
    # the attribution passes the calibrated set's rows to each run itself (`attribute_claims`' uncertainty_rows);
    # the set's relative pointer to them would not resolve from the attribution's folder
    meta.pop("uncertainty_rows", None)
    base_origin = _base_origin(meta.get("base"))
    for key, base in zip(revert.keys, revert.base):
        (meta.get("calibration") or {}).pop(key, None)
        origin = meta.setdefault("origin", {})
        origin.pop(key, None)
        if base is not None:
            origin[key] = base_origin.get(key) or {"kind": "chosen", "reason": "the base set's value, put back "
                                                   "for claim attribution"}
    return out


def _base_origin(base: str | None) -> dict:
    """The base set's [meta.origin] ({} without a base)."""
    if not base:
        return {}
    import tomllib

    from continuum.api import find_params

    return dict((tomllib.loads(find_params(base).read_text()).get("meta") or {}).get("origin") or {})


def holds_nominally(c: Mapping) -> bool:
    """Whether a claim holds on its set's own (nominal) runs: the state before the samples judged it (the
    reverts run no samples, so a base set's claim is compared on its nominal runs too)."""
    return c.get("nominal_state", c["state"]) == "pass" if "state" in c else bool(c["pass"])


def explain_claims(calibrated: Iterable[Mapping], base: Iterable[Mapping],
                   by_revert: Mapping[str, Iterable[Mapping]], groups: Iterable[Revert]) -> tuple[ClaimWhy, ...]:
    """One ClaimWhy per claim that fails with the calibrated set, from the claims of the calibrated set, the base
    set and each revert set (`by_revert`: revert set name -> its claims). Pure: no run here."""
    base_pass = {c["name"]: holds_nominally(c) for c in base}
    groups = tuple(groups)
    restored = {g.set_name: {c["name"] for c in by_revert.get(g.set_name, ()) if c["pass"]} for g in groups}
    out = []
    for c in calibrated:
        if c["pass"]:
            continue
        name = c["name"]
        if c.get("nominal_state") == "pass":
            out.append(ClaimWhy(name, "samples", (), f"holds on the set's own runs; over its samples: "
                                f"{c.get('reason', 'holds_fraction below the criterion')}"))
            continue
        if name not in base_pass:
            out.append(ClaimWhy(name, "not run", (), "the base set's cases did not evaluate this claim"))
            continue
        if not base_pass[name]:
            out.append(ClaimWhy(name, "base fails too", (),
                                "fails with the base set too: not caused by the calibrated values"))
            continue
        ran = [g for g in groups if g.set_name in by_revert]
        if not ran:
            out.append(ClaimWhy(name, "not run", (), "no MD value differs from the base set's, or no revert ran"))
            continue
        hit = [g for g in ran if name in restored[g.set_name]]
        if hit:
            text = ("holds again when only " + "; or only ".join(g.describe() for g in hit)
                    + (" is put back to the base value" if len(hit) == 1 else " are put back to the base values")
                    + ": " + ("that value is" if len(hit) == 1 else "each of these is") + " enough to break it")
            out.append(ClaimWhy(name, "single", tuple(g.label for g in hit), text))
        else:
            out.append(ClaimWhy(name, "several", (),
                                f"no single MD value put back restores it ({len(ran)} tried: "
                                + ", ".join(g.label for g in ran) + "): it fails through several values together"))
    return tuple(out)


def attribute_claims(table: Mapping[str, Any], rows: Iterable[Mapping[str, Any]], paper_checks: Iterable[Mapping],
                     set_name: str, base_name: str, out: str | Path, *, executor=None,
                     progress: Callable[[str], None] | None = None, set_path: str | None = None,
                     uncertainty_rows: list[Mapping] | None = None) -> dict:
    """Run the reverts a failing claim needs and explain every claim that fails with `set_name`.

    `table` is the calibrated set as written, `rows` its value rows, `paper_checks` the claims of the paper step
    (with `set_name` and `base_name` among their sets). Revert sets go to OUT/sets/, their paper cases to
    OUT/paper/ (no figures). Returns {"reverts": [...], "claims": [ClaimWhy.to_dict()...], "ran": bool,
    "acceptance": `acceptance`'s entries, "choices": {claim: probe}}: with `set_path` (the set's file), Fig 4's
    loop claim that fails is probed over its declared choices (continuum.paper.loop_probe)."""
    from continuum.api import make_paper

    checks = list(paper_checks)
    cal = [c for c in checks if c["set"] == set_name]
    base = [c for c in checks if c["set"] == base_name]
    base_pass = {c["name"] for c in base if holds_nominally(c)}
    needed = [c for c in cal if not c["pass"] and c.get("nominal_state") != "pass" and c["name"] in base_pass]
    groups = reverts(rows, set_name)
    by_revert: dict[str, list] = {}
    if needed and groups:
        out = Path(out)
        paths = [str(write_parameter_set(revert_table(table, g), out / "sets" / f"{g.set_name}.toml",
                                         header=f"Claim attribution: the `{set_name}` set with {g.label} put "
                                                f"back to the `{base_name}` set's values."))
                 for g in groups]
        if progress:
            progress(f"  claims: {len(needed)} fail with {set_name} and hold with {base_name}; running "
                     f"{len(groups)} revert sets")
        record = make_paper(paths, out / "paper", executor=executor, progress=lambda m: None, draw_figures=False)
        for c in record["checks"]:
            by_revert.setdefault(c["set"], []).append(c)
    whys = explain_claims(cal, base, by_revert, groups)
    choices = {}
    if set_path is not None and any(c["name"] == LOOP_CLAIM and not c["pass"] for c in cal):
        from continuum.api import fig4_choice_probe

        origin = (table.get("meta") or {}).get("origin") or {}
        choices[LOOP_CLAIM] = dict(fig4_choice_probe(str(set_path)), origins={
            k: (origin.get(k) or {}).get("kind", "origin not given")
            for k in ("surfaces.sam.layer_modulus", "surfaces.roughness.summit_radius")})
    return {"reverts": [g.to_dict() for g in groups], "claims": [w.to_dict() for w in whys],
            "ran": bool(by_revert), "choices": choices,
            "acceptance": acceptance(cal, whys, groups, uncertainty_rows,
                                     ((table.get("meta") or {}).get("calibration") or {}).keys())}


def _direction(claim: str, g: Revert) -> tuple[bool | None, str]:
    """Whether putting group `g` back restoring `claim` is the direction physics predicts: the margin is higher
    at the base value, so d(margin)/d(value) has the sign of (base - calibrated); PHYSICAL_DIRECTION says which
    sign physics predicts. (None, why) where no key of the group has a declared direction or a base value."""
    declared = PHYSICAL_DIRECTION.get(claim, {})
    for key, cal, base in zip(g.keys, g.calibrated, g.base):
        if key not in declared or not isinstance(cal, (int, float)) or not isinstance(base, (int, float)):
            continue
        seen = 1 if base > cal else -1
        word = "raises" if declared[key] > 0 else "lowers"
        moved = "lower" if cal < base else "higher"
        text = (f"the measured `{key}` = {cal:.4g} is {moved} than the base {base:.4g}, and a larger value {word} "
                f"the claim's margin")
        return seen == declared[key], text
    return None, f"no declared physical direction for {g.label} on this claim"


#: Rank correlation (Spearman) of a measured input with a claim's margin over the uncertainty rows above which
#: the input is named as what carries the claim across its threshold (a declared choice: |rho| >= 0.5 is a
#: strong monotone association for 16 rows).
RANK_CORRELATION = 0.5


def _through_uncertainty(c: Mapping, rows: list[Mapping] | None, measured: Iterable[str]) -> tuple[bool, str] | None:
    """A claim that holds on its own runs and fails over the Latin-hypercube rows: the measured input whose
    sampled values rank-correlate most with the claim's margin over the rows (scipy.stats.spearmanr), and whether
    the sign is the one physics predicts (PHYSICAL_DIRECTION). None without rows or decided row margins."""
    from scipy.stats import spearmanr

    if not rows:
        return None
    pairs = [(rows[int(m["label"].split()[-1]) - 1], m["margin"]) for m in c.get("sample_margins", [])
             if m["label"].startswith("uncertainty") and m["margin"] is not None and m["state"] != "not_evaluable"]
    if len(pairs) < 5:
        return None
    margins = [max(min(m, 1e300), -1e300) for _, m in pairs]      # stuck impacts give -inf: the rank is what counts
    rho = {k: float(spearmanr([r[k] for r, _ in pairs], margins)[0]) for k in measured
           if all(k in r for r, _ in pairs)}
    rho = {k: v for k, v in rho.items() if v == v}
    if not rho:
        return None
    key = max(rho, key=lambda k: abs(rho[k]))
    declared = PHYSICAL_DIRECTION.get(c["name"], {}).get(key)
    text = f"over {len(pairs)} rows the margin follows the measured `{key}` most (rank correlation {rho[key]:+.2f})"
    if abs(rho[key]) < RANK_CORRELATION:
        return False, text + f", below {RANK_CORRELATION:g}: no measured value carries it"
    if declared is None:
        return False, text + ", a direction physics declares none for"
    ok = bool((rho[key] > 0) == (declared > 0))
    return ok, text + (", the direction physics predicts" if ok else ", the opposite of what physics predicts")


def acceptance(calibrated: Iterable[Mapping], whys: Iterable[ClaimWhy | Mapping],
               groups: Iterable[Revert], rows: list[Mapping] | None = None,
               measured: Iterable[str] = ()) -> list[dict]:
    """Per claim that fails with the calibrated set: accepted when it fails through measured values only, i.e. one
    MD value put back alone restores it (cause 'single') and the direction is the one physics predicts
    (`_direction`), or it holds on its own runs and fails over the uncertainty rows (`rows`, the overrides of
    'uncertainty i' in order) through one measured input's spread (`_through_uncertainty`, over the `measured`
    keys) in that direction; otherwise not accepted, with the reason. Each entry carries the claim's
    holds_fraction and sample count. Pure."""
    by = {c["name"]: c for c in calibrated}
    groups = {g.label: g for g in groups}
    out = []
    for w in whys:
        w = w.to_dict() if isinstance(w, ClaimWhy) else dict(w)
        c = by.get(w["claim"], {})
        entry = {"claim": w["claim"], "accepted": False, "holds_fraction": c.get("holds_fraction"),
                 "samples": c.get("samples"), "cause": w["cause"]}
        spread = _through_uncertainty(c, rows, list(measured)) if w["cause"] == "samples" else None
        if spread is not None:
            entry["accepted"], entry["why"] = spread[0], "holds on the set's own runs; " + spread[1]
        elif w["cause"] != "single":
            entry["why"] = {"base fails too": "fails with the base set too: not a measured value's doing",
                            "several": "no single measured value put back restores it",
                            "samples": "holds on the set's own runs: the spread over its samples fails it",
                            }.get(w["cause"], w["text"])
        else:
            verdicts = [(_direction(w["claim"], groups[label]), label) for label in w["restored_by"] if label in groups]
            physical = [(text, label) for (ok, text), label in verdicts if ok]
            entry["accepted"] = bool(physical)
            entry["why"] = ("; ".join(f"{label}: {text}" for text, label in physical) if physical else
                            "; ".join(f"{label}: {text}" + ("" if ok is None else ", the opposite of what it did")
                                      for (ok, text), label in verdicts) or "the restoring group is unknown")
        out.append(entry)
    return out
