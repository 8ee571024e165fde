"""Every reproduction claim on single discrete-summit surfaces: the project's finding beside the paper's model.

Each discrete seed's bundle (``samples.bundle`` and ``seed_runs.single_surface_runs``) is judged by the same
functions that judge the averaged law (``sampled_claims``, ``checks``), so a claim has one definition; the t_a
line's per-surface form is ``seed_runs``' wet run at v* (``wet_flips``: the claim holds exactly when it sticks).
A claim's ``single_surfaces`` block: how many surfaces, how many decided, on how many it holds, the Wilson 95 %
interval of that fraction (Wilson, J. Am. Stat. Assoc. 22 (1927) 209), the failing seeds, and where the fraction
departs from the paper's model's verdict, the mechanism in a sentence with its numbers. Seeds never decide a verdict.
"""
from __future__ import annotations

import math

from .checks import ESCAPE_TREND, FIG7, TIME_RISES, escape_trend, fig7_entry, time_rises_entry
from .sampled_claims import NAMES, bundle_claims, rebounds
from .seed_runs import SWEEP_DURATION_RTOL
from .verdict import FAIL, NOT_EVALUABLE, PASS, REPRODUCTION, entry, not_evaluable, proportion
from .wet_checks import T_A_CLAIM

#: The claims judged on whole sweeps, which the seed's own runs (`seed_runs`) answer.
SWEEP_CLAIMS = (FIG7, TIME_RISES, ESCAPE_TREND, T_A_CLAIM)


def seed_claims(set_name: str, b: dict) -> dict[str, dict]:
    """Every reproduction claim judged on one seed's bundle `b`: {name: entry}."""
    out = {c["name"]: c for c in bundle_claims(set_name, b)}
    if "error" in b or "escape_sigma" not in b:
        why = b.get("error") or "the seed's single-surface runs were not made"
        return {**out, **{n: not_evaluable(n, set_name, REPRODUCTION, "", "", why) for n in SWEEP_CLAIMS}}
    out[ESCAPE_TREND] = escape_trend(set_name, list(b["escape_sigma"].items()))
    sweeps = {f"sigma_{x * 1e9:g}nm": {"points": pts} for x, pts in sorted(b["sweep_sigma"].items())}
    out[TIME_RISES] = time_rises_entry(set_name, sweeps, SWEEP_DURATION_RTOL)
    drops = sorted(b["drops_sigma"].items())
    out[FIG7] = fig7_entry(set_name, [x for x, _ in drops], [(rebounds(d) or [0.0])[0] for _, d in drops],
                           [len(rebounds(d)) for _, d in drops], [d["status"] == "max_bounces" for _, d in drops])
    out[T_A_CLAIM] = _t_a_entry(set_name, b["t_a"])
    return out


def _t_a_entry(set_name: str, t: dict) -> dict:
    thr = "with menisci the dry impacts that outlast t_a stick (the wet impact at v* near the band edge sticks)"
    if t.get("holds") is None:
        return not_evaluable(T_A_CLAIM, set_name, REPRODUCTION, thr, "1", t.get("reason", "not run"), dict(t))
    return entry(T_A_CLAIM, set_name, REPRODUCTION, dict(t), thr, None, 0.0, "1",
                 None if t["holds"] else "the wet impact at v* rebounds", PASS if t["holds"] else FAIL)


def attach(set_name: str, claims: list[dict], seeds: list[dict], nominal: dict | None) -> None:
    """Give every reproduction entry of `claims` its `single_surfaces` block from the discrete `seeds` (bundles), in
    label order (the pool returns them as its workers finish)."""
    seeds = sorted(seeds, key=lambda b: (len(b["label"]), b["label"]))
    per_seed = [seed_claims(set_name, b) for b in seeds]
    for c in claims:
        if c["kind"] != REPRODUCTION:
            continue
        if not seeds:
            c["single_surfaces"] = {"n": 0, "note": "no discrete-summit seeds were run (--seeds 0)"}
            continue
        c["single_surfaces"] = single_surfaces(c, [p[c["name"]] for p in per_seed], seeds, nominal or {})


def single_surfaces(claim: dict, claims: list[dict], seeds: list[dict], nominal: dict) -> dict:
    """The block (module docstring) of `claim` (the averaged law's entry), from its entries `claims` on `seeds`.
    Where none is decided (the t_a line: no single surface has a rebounding impact as long as t_a), the Wilson
    interval is that of the fraction of surfaces on which the claim has a subject at all."""
    decided = [c for c in claims if c["state"] in (PASS, FAIL)]
    p = proportion(c["state"] == PASS for c in decided)
    out = {"n": len(claims), "decided": len(decided), "holds": p["k"] if p else 0,
           "holds_fraction": p["fraction"] if p else None, "wilson95": p["wilson95"] if p else None,
           "failing": [b["label"] for c, b in zip(claims, seeds) if c["state"] == FAIL]}
    q = proportion(c["state"] == NOT_EVALUABLE for c in claims)
    if q and q["k"]:
        out["undecided"] = {"k": q["k"], "n": q["n"], "wilson95": q["wilson95"],
                            "seeds": [{"label": b["label"], "reason": c.get("reason")}
                                      for c, b in zip(claims, seeds) if c["state"] == NOT_EVALUABLE]}
    state = claim["state"]
    departs = (p is None and claims) or (p is not None and ((state == PASS and p["fraction"] < 1.0)
                                                          or (state == FAIL and p["fraction"] > 0.0)))
    if departs:
        out["mechanism"] = mechanism(claim, claims, seeds, nominal)
    return out


def _ladder(seeds: list[dict], nominal: dict, key: str = "silica") -> tuple[str, float | None]:
    """The summit ladder in numbers: one summit's JKR loop over the drop energy (median over the seeds) and the
    range of summits in contact at once, against the averaged law's fractional count."""
    q = sorted(b[key]["loop_per_summit_over_drop"] for b in seeds if b.get(key, {}).get("loop_per_summit_over_drop"))
    n = [b[key].get("max_contacts") for b in seeds if b.get(key, {}).get("max_contacts") is not None]
    if not q or not n:
        return ("single realisations carry few summits, so the number one realisation puts in reach, not the "
                "averaged law's fractional count, sets each outcome"), None
    share = q[len(q) // 2]
    where = "at sigma = 3 nm" if key == "sigma3" else "at sigma = 6 nm (bare silica)"
    text = (f"every summit a JKR impact reaches takes {share:.3g} of the drop energy {where} (the loop of one summit "
            f"over m g h0), and single realisations put {min(n):g}-{max(n):g} summits in contact at once")
    nom = nominal.get(key, {}).get("max_contacts")
    if nom is not None:
        text += f"; the averaged law spreads {nom:.3g}"
    return text, share


def mechanism(claim: dict, claims: list[dict], seeds: list[dict], nominal: dict) -> str:
    """Why single surfaces depart from the averaged one, in a sentence with its numbers. A JKR impact loses a fixed
    loop per summit it reaches, so what a drop keeps, when it sticks and how long it lasts are set by how many
    summits one realisation puts in reach, a whole number that moves in steps, where the averaged law spreads a
    fractional, smoothly varying one."""
    name = claim["name"]
    if name == T_A_CLAIM:
        longest = [c["values"].get("longest_dry_rebound_s") for c in claims
                   if (c.get("values") or {}).get("longest_dry_rebound_s") is not None]
        t_a = next((c["values"].get("t_a_s") for c in claims if (c.get("values") or {}).get("t_a_s")), None)
        if longest and t_a:
            return (f"on a single surface the longest dry impact that still rebounds lasts {max(longest):.3g} s at "
                    f"most (the averaged law's {claim['values'].get('longest_dry_rebound_s') or math.nan:.3g} s), "
                    f"below t_a = {t_a:.3g} s: the escape is a step in the number of summits reached, not the slow "
                    "near-escape impact whose duration grows without bound on the averaged law, so no bridge forms "
                    "before the impact ends and menisci leave the escape velocity unchanged")
    key = "sigma3" if name == NAMES[3] else "silica"
    text, share = _ladder(seeds, nominal, key)
    if name == NAMES[3] and share:
        text += f", so sticking at the first impact needs >= {math.ceil(1.0 / share):d} of them"
    margins = [c["margin"] for c in claims if c.get("margin") is not None]
    if margins and claim.get("margin") is not None:
        text += (f"; over the surfaces the claim's margin spans {min(margins):.3g} to {max(margins):.3g} "
                 f"{claim['units']}, against the averaged law's {claim['margin']:.3g}")
    if name == ESCAPE_TREND:
        text += _one_summit(seeds)
    return text


def _one_summit(seeds: list[dict]) -> str:
    """Near escape an impact on a single surface reaches only its tallest summit: one summit's JKR loop W stops a
    roller of mass m below v1 = sqrt(2 W / m), whatever sigma, so neighbouring sigmas tie on one escape velocity."""
    v1 = sorted(math.sqrt(2.0 * b["loop"]["silica"] / b["mass_kg"]) for b in seeds
                if (b.get("loop") or {}).get("silica") and b.get("mass_kg"))
    esc = sorted({round(e.get("escape_velocity"), 12) for b in seeds for e in (b.get("escape_sigma") or {}).values()
                  if e.get("escape_velocity")})
    if not v1 or not esc:
        return ""
    return (f"; near escape an impact on a single surface reaches only its tallest summits, and one summit's loop "
            f"stops the roller below sqrt(2 W_loop / m) = {v1[len(v1) // 2]:.3g} m/s whatever sigma: the seeds' escape "
            f"velocities over the four sigmas take {len(esc)} values, {esc[0]:.3g}-{esc[-1]:.3g} m/s, and neighbouring "
            "sigmas tie on one of them")
