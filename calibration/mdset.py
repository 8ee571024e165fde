"""MD results -> a calibrated continuum parameter set (inputs/params/NAME.toml), with provenance.

Which MD quantity feeds which scene key (`MAPPING`), SI in and out; the only conversion is none:
scene files take contact angles in degrees, as the MD results give them. Everything the MD does
not measure (moduli, roughness statistics, SAM thickness) comes from a named base set, with the base set's
origin ([meta.origin], continuum.origins); an MD value's origin is `md` with its run hash. A choice of the
base set that the project can replace by a measured or derived value (`REPLACED_CHOICES`: the summit modulus
becomes the materials' E*, the adhesion law the Tabor parameter's pick, the paper's additive wet adhesion the
wet work of adhesion) is left out of the calibrated set.

Work of adhesion: the MD adhesion workflow gives the energy difference dE/A (`work_of_adhesion`)
and, by thermodynamic integration of the mean force over separation windows, the free energy of
separation (`work_of_adhesion_free_energy`, with its statistical stderr and the window grid's
`discretisation_error`). The Dupre work of adhesion the JKR/GW summits need is a free energy
(Israelachvili, Intermolecular and Surface Forces, 3rd ed., section 17.2), so the free energy is used when
the result has it, with stderr = hypot(statistical, discretisation, systematic), the systematic being half the
out-and-back hysteresis where the run pulled its windows back (the mean of the two directions is the estimate,
md.analysis.hysteresis: the true reversible work lies between them); dE/A is recorded beside it
([meta.calibration] -> `energy_estimate`), and a result without the free energy falls back to dE/A, which
the set's origin and the report then name as "not a free energy". Runs of an older adhesion protocol (whose
windows started outside the adhesive well) do not match the run hash and are not read.

Which adhesion runs: bare silica from `adhesion_silica_registries` (six quasi-random lateral registries over the
primitive cell, each with its own zero-load contact, windows denser over the force peak), not the three-registry
`adhesion_silica`, whose z0 error is too wide to use. The spread over registries is part of W_F's
stderr (md.analysis). OTS from `adhesion_ots_equilibrated` (both SAMs annealed before contact, three quasi-random
registries over the primitive cell, each with its own zero-load contact, the windows pulled out and back), not
`adhesion_ots`, whose two registries are one and whose one-way windows go straight from the builder.

Interaction range z0: from the flat-slab mean-force curve of the adhesion workflow:
z0 = 1.026 W_F / sigma0 (Maugis 1992, the LJ 9-3 law), with sigma0 the curve's peak tensile traction, so that
the continuum's Maugis-Dugdale stress 1.03 dgamma / z0 reproduces the measured sigma0 with the W_F used for
dgamma; its stderr (from the peak fit's covariance and W_F's error) goes into the uncertainty bands like every
other. An adhesion result without a flat-slab z0 falls back to the pull-off z0 (a 9-3 fit
against the rigid holder's travel: it absorbs the asperity's compliance and overstates z0), and the origin's
note says so. The pull-off results are otherwise a validation: F / (2 pi R) (DMT, the limit an MD-scale asperity is
in) is compared with W_F in [meta.validation] (calibration.validation: like for like, rate-extrapolated).

SAM layer: the small-strain tangent confined modulus of the SAM stack between the OTS slabs at the annealed thickness,
the per-SAM thickness it used (surfaces.sam.thickness: the continuum's layer then has the measured stiffness per
area), and the Poisson ratio that converts it -- measured where the run sampled the SAM's stress, else the set's
declared value with its spread in E's stderr (calibration.sam_layer); a tangent from fewer than four repulsive
windows is not used.

W_F with the static TraPPE tail (OTS): the set's value keeps the tail (TAIL_CHOICE) and its stderr holds half the
tail as a model-form systematic; [meta.calibration] gives the value with and without it. z0 is formed with the W_F
the set uses (a committed result whose z0 used the outward W gets it recomputed from its own sigma0).

A value outside the scene schema's range, or not finite, or a contact angle the analysis could not
measure (0 deg: a film, 180 deg: no contact yet -- what smoke runs give) is not used: the base set's
value is kept for that key, and [meta.rejected] and the report name the MD run and the value.
"""
from __future__ import annotations

import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from calibration.sam_layer import (
    LAYER_QUANTITIES,
    THICKNESS_QUANTITIES,
    thickness_record,
    with_layer_quantities,
    young_with_nu,
)
from calibration.validation import VALIDATION, pulloff_validation
from continuum.api import FIELD_BY_PATH, SceneError, check_origins, check_value, find_params, flatten
from nanoimpact import data
from nanoimpact.fileio import atomic_write_text


@dataclass(frozen=True)
class Source:
    """Scene key <- MD recipe, quantities in order of preference; ``fallback`` (another recipe) is used only
    when this recipe's result has none of the quantities (``note`` says what the fallback value is)."""

    key: str
    recipe: str
    quantities: tuple[str, ...]
    fallback: "Source | None" = None
    note: str = ""


_PULLOFF_Z0 = ("fallback: the adhesion result has no flat-slab z0; this z0 is a 9-3 fit with a free offset to the "
               "pull-off curve against the rigid holder's travel, so it absorbs the asperity's compliance (an "
               "overestimate)")

_DROPLET = ("fallback: no W_SL by thermodynamic integration (wsl_silica); this is the droplet's angle, and the quick "
            "silica droplet keeps the angle it is started at (a pinned contact line: the committed "
            "contact_angle_silica and contact_angle_silica_flatstart results end near their different starting "
            "angles), so it measures the start, not the surface")

_DROPLET_OTS = ("fallback: no W_SL by thermodynamic integration (wsl_ots); this is the quick R0 = 2 nm droplet's "
                "angle, which is not size-converged (the committed contact_angle_ots_long and "
                "contact_angle_ots_large results, R0 = 2 and 3 nm, differ by about 2 sigma, so take +-4 deg for the "
                "droplet size; docs/md.md, contact angles)")

MAPPING: tuple[Source, ...] = (
    Source("surfaces.work_of_adhesion", "adhesion_silica_registries",
           ("work_of_adhesion_free_energy", "work_of_adhesion")),
    Source("surfaces.sam.work_of_adhesion", "adhesion_ots_equilibrated",
           ("work_of_adhesion_free_energy", "work_of_adhesion")),
    Source("surfaces.body.contact_angle", "wsl_silica", ("contact_angle",),
           fallback=Source("surfaces.body.contact_angle", "contact_angle_silica", ("contact_angle",), note=_DROPLET)),
    Source("surfaces.substrate.contact_angle", "wsl_silica", ("contact_angle",),
           fallback=Source("surfaces.substrate.contact_angle", "contact_angle_silica", ("contact_angle",),
                           note=_DROPLET)),
    Source("surfaces.sam.contact_angle", "wsl_ots", ("contact_angle",),
           fallback=Source("surfaces.sam.contact_angle", "contact_angle_ots", ("contact_angle",), note=_DROPLET_OTS)),
    Source("menisci.surface_tension", "surface_tension_spce", ("surface_tension",)),
    Source("surfaces.interaction_range", "adhesion_silica_registries", ("interaction_range_z0",),
           fallback=Source("surfaces.interaction_range", "pulloff_silica", ("interaction_range_z0",),
                           note=_PULLOFF_Z0)),
    Source("surfaces.sam.interaction_range", "adhesion_ots_equilibrated", ("interaction_range_z0",),
           fallback=Source("surfaces.sam.interaction_range", "pulloff_ots", ("interaction_range_z0",),
                           note=_PULLOFF_Z0)),
    Source("surfaces.body.work_of_adhesion_sl", "wsl_silica", ("work_of_adhesion_sl",)),
    Source("surfaces.substrate.work_of_adhesion_sl", "wsl_silica", ("work_of_adhesion_sl",)),
    Source("surfaces.sam.work_of_adhesion_sl", "wsl_ots", ("work_of_adhesion_sl",)),
    Source("surfaces.sam.thickness", "adhesion_ots_equilibrated", THICKNESS_QUANTITIES),
    Source("surfaces.sam.layer_modulus", "adhesion_ots_equilibrated", LAYER_QUANTITIES),
)

def recipes_needed(mapping=MAPPING) -> list[str]:
    """MD recipes a calibration may need, in mapping order, each once (fallback recipes -- the pull-offs, also the
    validation runs -- after the first ones)."""
    first = [s.recipe for s in mapping]
    return list(dict.fromkeys(first + [s.fallback.recipe for s in mapping if s.fallback is not None]))


def recipes_first(mapping=MAPPING, validation=VALIDATION) -> list[str]:
    """The recipes every calibration runs: the preferred recipe of every key and the validation runs (the
    pull-offs), in :func:`recipes_needed` order. A fallback recipe runs only when :func:`fallbacks_needed` asks."""
    want = {s.recipe for s in mapping}
    first = [r for r in recipes_needed(mapping) if r in want]
    return list(dict.fromkeys(first + [pull for pull, _ in validation]))


def fallbacks_needed(results: dict[str, dict], mapping=MAPPING) -> list[str]:
    """The fallback recipes whose preferred result (in ``results``) has none of the key's quantities -- the same
    test :func:`build_parameter_set` applies -- and that ``results`` does not hold yet."""
    out = [s.fallback.recipe for s in mapping if s.fallback is not None and
           not any(q in (results.get(s.recipe) or {}).get("quantities", {}) for q in s.quantities)]
    return [r for r in dict.fromkeys(out) if r not in results]


#: Recipes whose result depends on the water model (settings.water_model); one model throughout a calibration.
WATER_RECIPES = ("contact_angle_silica", "contact_angle_ots", "surface_tension_spce", "wsl_silica", "wsl_ots")


def water_model_mismatch(results: dict[str, dict]) -> str | None:
    """Why the water-derived values cannot be combined, or None. Young-Dupre and the meniscus force use
    gamma_lv cos(theta): an angle measured with one water model and gamma_lv of another describe no liquid
    (SPC/E's gamma_lv is 63.6 mN/m, TIP4P/2005's 69.3, at 300 K; Vega & de Miguel, J. Chem. Phys. 126 (2007)
    154707), so a calibration mixing them keeps the base set's values for all of them."""
    models = {r: (results[r].get("settings") or {}).get("water_model") for r in WATER_RECIPES if results.get(r)}
    if len({m for m in models.values() if m}) > 1:
        return "water models differ (" + ", ".join(f"{r}: {m}" for r, m in models.items()) + \
            "): an angle and gamma_lv of different models cannot be combined; use one model throughout"
    return None


def _wets(q: dict, name: str):
    """A droplet that wets (status 'wets') gives only an upper bound: theta in [0, bound]. It enters as the
    uniform distribution on that interval, mean bound/2 and stderr bound/sqrt(12), so the uncertainty bands
    cover every angle the run allows (quantity `contact_angle_upper_bound`)."""
    if name != "contact_angle" or q.get(name, {}).get("status") != "wets":
        return None
    bound = (q.get("contact_angle_upper_bound") or {}).get("value")
    if bound is None or not math.isfinite(bound) or bound <= 0.0:
        return None
    return "contact_angle_upper_bound", 0.5 * float(bound), float(bound) / math.sqrt(12.0), "deg"


def _pick(result: dict, source: Source):
    """(quantity name, value, stderr, units) chosen from a result, or (None, reason)."""
    q = result.get("quantities", {})
    for name in source.quantities:
        wets = _wets(q, name)
        if wets is not None:
            return wets
        if name not in q:
            continue
        v = q[name].get("value")
        if v is None or not math.isfinite(v):
            continue
        return name, float(v), _combined_stderr(q[name]), q[name].get("units", "")
    return None, f"none of {source.quantities} is finite in the result"


def _combined_stderr(rec: dict) -> float | None:
    """The error a quantity enters the set with: its statistical stderr, in quadrature with a quadrature's grid
    error (``discretisation_error``), for an out-and-back W_F half the hysteresis (``systematic_hysteresis``: the
    reversible work lies between the two directions) and, for a W_F with the static TraPPE tail, half the tail
    (``systematic_tail``, :func:`_with_model_form`); None without a finite statistical stderr."""
    e = rec.get("stderr")
    if e is None or not math.isfinite(e):
        return None
    extra = [float(rec[k]) for k in ("discretisation_error", "systematic_hysteresis", "systematic_tail")
             if rec.get(k) is not None and math.isfinite(rec[k])]
    return math.hypot(float(e), *extra)


def _ti_wets(result: dict) -> bool:
    """A W_SL by thermodynamic integration at or above 2 gamma_lv: theta = 0 is then Young-Dupre's answer (complete
    wetting, a measured spreading coefficient), not a droplet analysis's film mark."""
    return result.get("workflow") == "wsl_ti" and \
        (result.get("quantities", {}).get("contact_angle") or {}).get("status") == "wets"


def _rejection(key: str, value: float, quantity: str, result: dict | None = None) -> str | None:
    if quantity == "contact_angle" and value <= 0.0 and result is not None and _ti_wets(result):
        return None
    if quantity == "contact_angle" and (value <= 0.0 or value >= 180.0):
        return f"{value:g} deg is the analysis's 'no droplet contact / film' mark, not a measured angle"
    try:
        check_value(FIELD_BY_PATH[key], value, "md")
    except SceneError as exc:
        return f"outside the scene schema: {exc.allowed}"
    return None


def _set_nested(table: dict, key: str, value) -> None:
    *parents, leaf = key.split(".")
    node = table
    for p in parents:
        node = node.setdefault(p, {})
    node[leaf] = value


def _get_nested(table: dict, key: str):
    node = table
    for p in key.split("."):
        if not isinstance(node, dict) or p not in node:
            return None
        node = node[p]
    return node


#: Base-set choices a calibration replaces, where the base declares them `chosen`, by what the project measures
#: or derives from the materials (the key is left out of the calibrated set, so the loader's default applies).
REPLACED_CHOICES = {
    "surfaces.roughness.summit_modulus": "the pair's effective modulus E* of the two materials (the bodies' "
                                         "Young's moduli and Poisson ratios, whose origins the set gives); a SAM "
                                         "with a layer modulus enters through the coated-summit model",
    "physics.adhesion_law": "'auto': the MD-measured range z0 lets the summits' Tabor parameter pick JKR, "
                            "Maugis-Dugdale or DMT",
    "menisci.solid_adhesion": "'wet' (the default): inside a bridge the solids adhere with the work of adhesion "
                              "under the liquid, from the MD-measured dgamma, gamma_lv and contact angles",
}


#: Values the calibrated set takes by the project's decision (docs/model.md), neither the base set's nor MD's.
PROJECT_CHOICES = {
    "menisci.condensation_model": (
        "nucleation", "t_a from the thermally activated nucleation of a water bridge at the scene's humidity and "
                      "temperature (Szoszkiewicz & Riedo, PRL 95 (2005) 135502: 0.7-4.2 ms at 40 % RH, 332-299 K) "
                      "instead of the paper's fixed 25 us; the paper set keeps 25 us"),
}


def _base_table(base: str) -> tuple[dict, dict]:
    """(the base set's table without [meta], its [meta.origin])."""
    table = tomllib.loads(Path(find_params(base)).read_text())
    meta = table.pop("meta", {}) or {}
    return table, dict(meta.get("origin") or {})


def _delete_nested(table: dict, key: str) -> None:
    *parents, leaf = key.split(".")
    node = table
    for p in parents:
        node = node.get(p)
        if not isinstance(node, dict):
            return
    node.pop(leaf, None)
    if not node and parents:
        _delete_nested(table, ".".join(parents))


def replace_choices(table: dict, origin: dict) -> dict:
    """Drop the base set's `chosen` values that :data:`REPLACED_CHOICES` names (in place); returns
    {key: {"base_value", "base_reason", "now"}} for [meta.replaced]."""
    out = {}
    for key, now in REPLACED_CHOICES.items():
        entry = origin.get(key) or {}
        if entry.get("kind") != "chosen" or _get_nested(table, key) is None:
            continue
        out[key] = {"base_value": _get_nested(table, key), "base_reason": entry.get("reason"), "now": now}
        _delete_nested(table, key)
        origin.pop(key)
    return out


def _effective_source(src: Source, results: dict) -> Source:
    """The fallback where the preferred result has none of the key's quantities (an older protocol)."""
    if src.fallback is not None and not any(q in (results.get(src.recipe) or {}).get("quantities", {})
                                            for q in src.quantities):
        return src.fallback
    return src


def _with_derived(res: dict | None, source: Source) -> dict | None:
    """The result with what the set reads from it and a committed result may predate: the SAM layer's small-strain
    modulus and thickness (calibration.sam_layer.with_layer_quantities), W_F's model-form part
    (:func:`_with_model_form`) and z0 from the W_F the result reports (:func:`_z0_from_reported_work`)."""
    if res is None:
        return None
    if set(source.quantities) & set(LAYER_QUANTITIES + THICKNESS_QUANTITIES):
        return with_layer_quantities(res)
    if "work_of_adhesion_free_energy" in source.quantities:
        return _with_model_form(res)
    if "interaction_range_z0" in source.quantities:
        return _z0_from_reported_work(res)
    return res


#: why a W_F with the static TraPPE tail is the set's value (docs/md.md, "W_OTS with and without the tail")
TAIL_CHOICE = ("with the tail: TraPPE-UA's CH2/CH3 parameters were fitted to saturated-liquid densities and critical "
               "temperatures in simulations that added the analytic dispersion tail beyond the cutoff (Martin & "
               "Siepmann, J. Phys. Chem. B 102 (1998) 2569), so the force field's dispersion is the full 1/r^6 sum; "
               "the tail is a static, rigid-configuration estimate across a gap, so half of it is a model-form "
               "systematic")


def _with_model_form(res: dict) -> dict:
    """A W_F that includes the static TraPPE tail (``dispersion_tail_work``) gets half the tail as a model-form
    systematic (``systematic_tail``) and its cutoff-only value beside it (``value_cutoff_only``)."""
    q = res.get("quantities") or {}
    w, tail = q.get("work_of_adhesion_free_energy"), (q.get("dispersion_tail_work") or {}).get("value")
    if not w or tail is None or not math.isfinite(tail) or tail == 0.0 or "systematic_tail" in w:
        return res
    w = {**w, "systematic_tail": 0.5 * abs(float(tail)), "value_cutoff_only": float(w["value"]) - float(tail),
         "tail": float(tail)}
    return {**res, "quantities": {**q, "work_of_adhesion_free_energy": w}}


def _z0_from_reported_work(res: dict) -> dict:
    """z0 = 1.026 W_F / sigma0 with the W_F the result reports (the out/back mean), where the committed z0 was formed
    with the outward W (an adhesion result before the analysis used the reported W: its z0 record has no
    ``work_of_adhesion_used``): recomputed from the result's own sigma0 and W_F with md.analysis.flat_slab_range,
    the record says ``recomputed_from_result``. Otherwise the result as it is."""
    q = res.get("quantities") or {}
    z, w, sg = q.get("interaction_range_z0"), q.get("work_of_adhesion_free_energy") or {}, q.get("peak_traction_sigma0")
    if not z or not sg or "work_of_adhesion_used" in z or w.get("value_out") is None:
        return res
    from md import flat_slab_range

    w_err = math.hypot(*[float(w[k]) for k in ("stderr", "discretisation_error", "systematic_hysteresis")
                         if w.get(k) is not None])
    s_err = math.hypot(float(sg.get("stderr") or 0.0), float(sg.get("discretisation_error") or 0.0))
    rng = flat_slab_range(float(w["value"]), w_err, float(sg["value"]), s_err)
    z = {**z, "value": rng["z0"], "stderr": rng["stderr"], "dugdale_range_h0_m": rng["h0"],
         "work_of_adhesion_used": float(w["value"]), "value_committed": z["value"], "recomputed_from_result": True}
    return {**res, "quantities": {**q, "interaction_range_z0": z}}


def _to_scene_units(key: str, value: float, stderr, table: dict, res: dict):
    """(value, stderr, note) in the scene key's meaning: the SAM stack's confined modulus M becomes the layer's
    Young's modulus E = M (1 + nu)(1 - 2 nu) / (1 - nu) (calibration.sam_layer.young_with_nu: the measured nu, else
    the set's with its spread in the stderr); other keys as they are."""
    if key != "surfaces.sam.layer_modulus":
        return value, stderr, ""
    nu = _get_nested(table, "surfaces.sam.layer_poisson_ratio")
    nu = FIELD_BY_PATH["surfaces.sam.layer_poisson_ratio"].default if nu is None else float(nu)
    e, e_err, rec = young_with_nu(value, stderr, nu, res)
    note = (f"confined modulus M = {value / 1e9:.3g} GPa (tangent at the zero-force point) converted to Young's "
            f"modulus with nu = {rec['value']:g} "
            f"({'measured' if rec['measured'] else 'the set' + chr(39) + 's, not measured'}"
            f"; E = M (1 + nu)(1 - 2 nu) / (1 - nu) = {e / value:.3f} M)")
    return e, e_err, (note, rec)


def _implausible(key: str, qname: str, result: dict) -> str | None:
    """Why an MD value that is within the schema's range is still not used: a layer modulus from fewer than four
    repulsive windows (a quadratic's tangent with no degree of freedom to check it)."""
    if qname == "sam_layer_tangent_modulus":
        n = (result.get("quantities", {}).get(qname) or {}).get("windows")
        if n is not None and n < 4:
            return f"only {n} repulsive windows: the compression branch's tangent is unchecked"
    return None


def build_parameter_set(results: dict[str, dict], base: str, name: str, *, description: str = "",
                        mapping=MAPPING, extra_meta: dict | None = None) -> tuple[dict, list[dict]]:
    """The set as a TOML-ready dict and one row per mapped key (used / rejected / missing).

    `results` maps recipe name -> MD result.json dict. `base` is a parameter-set name or file. Every value of the
    set carries its origin ([meta.origin], continuum.origins): `md` with the run hash for a value used here, the
    base set's own origin for a value kept from it; the base's choices in :data:`REPLACED_CHOICES` are left out
    ([meta.replaced] says which and what replaces them).
    """
    table, origin = _base_table(base)
    replaced = replace_choices(table, origin)
    for key, (value, reason) in PROJECT_CHOICES.items():
        _set_nested(table, key, value)
        origin[key] = {"kind": "chosen", "reason": reason}
    rows, calib, rejected = [], {}, {}
    water_mismatch = water_model_mismatch(results)
    for src in mapping:
        src = _effective_source(src, results)
        res = _with_derived(results.get(src.recipe), src)
        row = {"key": src.key, "recipe": src.recipe, "base_value": _get_nested(table, src.key)}
        rows.append(row)
        if res is None:
            row.update(status="missing", why=f"no {src.recipe} result")
            continue
        picked = _pick(res, src)
        if picked[0] is None:
            row.update(status="rejected", why=picked[1], run_hash=res.get("run_hash"))
            rejected[src.key] = {"recipe": src.recipe, "run_hash": res.get("run_hash"), "why": picked[1],
                                 "kept": "base set value"}
            continue
        qname, value, stderr, units = picked
        value, stderr, converted = _to_scene_units(src.key, value, stderr, table, res)
        poisson = None
        if isinstance(converted, tuple):
            converted, poisson = converted
        row.update(quantity=qname, value=value, stderr=stderr, units=units, run_hash=res.get("run_hash"),
                   fidelity=res.get("fidelity"))
        why = (water_mismatch if water_mismatch and src.recipe in WATER_RECIPES
               else _rejection(src.key, value, qname, res) or _implausible(src.key, qname, res))
        if why:
            row.update(status="rejected", why=why)
            rejected[src.key] = {"recipe": src.recipe, "run_hash": res.get("run_hash"), "quantity": qname,
                                 "value": value, "why": why, "kept": "base set value"}
            continue
        row["status"] = "used"
        _set_nested(table, src.key, value)
        calib[src.key] = _calibration_entry(src, res, qname, value, stderr, units)
        if converted:
            calib[src.key]["conversion"] = converted
        if poisson is not None:
            calib[src.key]["poisson_ratio"] = poisson
            calib[src.key]["thickness_used"] = thickness_record(res["quantities"][qname],
                                                                _get_nested(table, "surfaces.sam.thickness"))
            if poisson["measured"]:
                _set_nested(table, "surfaces.sam.layer_poisson_ratio", poisson["value"])
                origin["surfaces.sam.layer_poisson_ratio"] = {
                    "kind": "md", "run_hash": str(res.get("run_hash")), "recipe": src.recipe,
                    "note": f"MD {src.recipe}: nu of the isotropic layer with the SAM stack's measured C13/C33, "
                            f"{poisson['value']:.3g} +- {poisson['stderr']:.2g}"}
        origin[src.key] = _md_origin(src, res, calib[src.key])
    out_meta = {"description": description or f"MD-calibrated set '{name}' on base '{Path(base).stem}'",
                "base": Path(base).stem, "origin": origin, "calibration": calib}
    if replaced:
        out_meta["replaced"] = replaced
    validation = pulloff_validation(results, table)
    if validation:
        out_meta["validation"] = validation
    if rejected:
        out_meta["rejected"] = rejected
    if extra_meta:
        out_meta.update(extra_meta)
    return {"meta": out_meta, **table}, rows


def _calibration_entry(src: Source, res: dict, qname: str, value: float, stderr, units: str) -> dict:
    """The [meta.calibration] entry of a used MD value: value, stderr, run, and what the quantity is."""
    entry = {"value": value, "units": units, "recipe": src.recipe, "quantity": qname,
             "fidelity": res.get("fidelity"), "run_hash": res.get("run_hash")}
    if stderr is not None:
        entry["stderr"] = stderr
    qs = res.get("quantities", {})
    if qname == "contact_angle_upper_bound":
        how = ("W_SL by thermodynamic integration reaches 2 gamma_lv within 2 stderr" if _ti_wets(res) else
               "no angle measurable")
        entry["note"] = (f"MD: the water wets (theta < {2 * value:.3g} deg, {how}); entered as "
                         f"uniform on [0, {2 * value:.3g}] deg: mean and stderr of that interval")
    if qname == "contact_angle" and value <= 0.0:
        entry["note"] = ("MD: W_SL by thermodynamic integration exceeds 2 gamma_lv by more than 2 stderr: the "
                         "water wets completely, theta = 0 (Young-Dupre)")
    if res.get("workflow") == "wsl_ti":
        ws = qs.get("work_of_adhesion_sl") or {}
        entry["work_of_adhesion_sl"] = {"value": ws.get("value"), "stderr": ws.get("stderr"),
                                        "discretisation_error": ws.get("discretisation_error"),
                                        "units": "J/m^2", "note": "W_SL by thermodynamic integration; "
                                        "theta = arccos(W_SL / gamma_lv - 1) of the same water model"}
    if qname in ("contact_angle", "contact_angle_upper_bound"):
        _angle_flags(entry, src, res, qname)
    if qname == "interaction_range_z0":
        _z0_details(entry, src, qs)
    if qname == "sam_layer_tangent_modulus":
        lm = qs[qname]
        entry["confined_modulus"] = {"value": lm.get("value"), "stderr": lm.get("stderr"), "units": "Pa",
                                     "what": "tangent at the zero-force point", "chord_Pa": lm.get("chord_modulus_Pa"),
                                     "curvature_delta_chi2": lm.get("curvature_delta_chi2"),
                                     "windows": lm.get("windows"), "layers": lm.get("layers"),
                                     "strain_max": lm.get("strain_max")}
        entry["rate"] = ("not in the stderr: compression windows at ~7 m/s (strain rate ~1e9 /s), an unrelaxed "
                         "modulus; the slow-loading pass is staged, not run (docs/md.md)")
        if lm.get("derived_from_windows"):
            entry["note"] = ("derived from the run's committed windows (details.pmf_windows, anneal tilt; the result "
                             "predates the quantity) with md.analysis.small_strain_layer_record")
    if qname == "sam_layer_thickness_per_layer":
        entry["note"] = ("the per-SAM thickness the layer modulus is normalised by (" + str(qs[qname].get("source"))
                         + "): the continuum's layer has the stiffness per area the MD measured")
    if qname == "work_of_adhesion_free_energy":
        entry["stderr_statistical"] = qs[qname].get("stderr")
        entry["discretisation_error"] = qs[qname].get("discretisation_error")
        if qs[qname].get("systematic_tail") is not None:
            w = qs[qname]
            entry["systematic_tail"] = w["systematic_tail"]
            entry["model_form"] = {"with_tail": w["value"], "without_tail": w["value_cutoff_only"],
                                   "tail": w["tail"], "used": "with_tail", "systematic": w["systematic_tail"],
                                   "why": TAIL_CHOICE}
        if qs[qname].get("systematic_hysteresis") is not None:
            entry["systematic_hysteresis"] = qs[qname]["systematic_hysteresis"]
            entry["out_and_back"] = {k: qs[qname].get(k) for k in ("value_out", "stderr_out", "value_back",
                                                                    "stderr_back")}
        de = qs.get("work_of_adhesion", {})
        if de.get("value") is not None:
            entry["energy_estimate"] = {"value": de["value"], "stderr": de.get("stderr"),
                                        "note": "dE/A, potential-energy difference (includes T dS/A); "
                                                "recorded, not used"}
            spread = _registry_energy_check(res)
            if spread is not None:
                entry["energy_estimate"].update(spread)
    return entry


def _registry_energy_check(res: dict) -> dict | None:
    """Whether the registries' own dE/A (each zero-load contact: registry 0 the contact leg, the others
    details.registry_contacts) agree within their stderrs (md.analysis.registry_consistency: p < 0.01 = disagree).
    Where they disagree, dE/A and T dS = dE - dF are not converged (the per-registry values in ``per_registry``).
    None with fewer than two registries."""
    from md import registry_consistency

    q, contacts = res.get("quantities") or {}, (res.get("details") or {}).get("registry_contacts") or {}
    de = q.get("work_of_adhesion") or {}
    vals = [(de.get("value"), de.get("stderr"))] + [(c.get("energy_work_J_m2"), c.get("stderr_J_m2"))
                                                    for c in contacts.values()]
    vals = [(float(v), float(e)) for v, e in vals if v is not None and e]
    if len(vals) < 2:
        return None
    v, e = np.array(vals).T
    cons = registry_consistency(v[:, None], e[:, None])
    bad = bool(np.asarray(cons["inconsistent"])[0])
    out = {"per_registry": v.tolist(), "per_registry_stderr": e.tolist(),
           "registry_chi2_per_dof": float(np.asarray(cons["chi2_per_dof"])[0]), "registries_agree": not bad}
    if bad:
        out["note_registries"] = ("NOT CONVERGED: the registries' dE/A disagree beyond their stderrs (chi^2 p < 0.01), "
                                  "so dE/A and T dS = dE - dF are not converged numbers")
    return out


def _angle_flags(entry: dict, src: Source, res: dict, qname: str) -> None:
    """A droplet angle's caveats in the entry's note: drifting block angles, a non-circular cap, a fallback."""
    qs = res.get("quantities", {})
    flags = []
    if qname == "contact_angle" and (qs.get("contact_angle_drift") or {}).get("drifting"):
        entry["drifting"] = True
        flags.append("the block angles still drift (see the MD result's notes): not equilibrated")
    shape = (res.get("details") or {}).get("shape_check") or {}
    if qname == "contact_angle" and shape.get("circular") is False:
        entry["not_circular"] = True
        flags.append(f"the mean droplet is not a circular cap: its readings spread by "
                     f"{shape.get('spread_deg', float('nan')):.1f} deg, a systematic the stderr does not hold")
    if flags:
        entry["note"] = "; ".join(flags)
    if src.note:
        entry["note"] = src.note + ("; " + entry["note"] if "note" in entry else "")


def _z0_details(entry: dict, src: Source, qs: dict) -> None:
    """z0's peak traction sigma0 and Dugdale range, and the fallback's note."""
    q = qs["interaction_range_z0"]
    if src.note:
        entry["note"] = src.note
    if "peak_traction_sigma0" in qs:
        sg = qs["peak_traction_sigma0"]
        entry["sigma0"] = {"value": sg.get("value"), "stderr": sg.get("stderr"), "units": "Pa",
                           "note": "peak tensile traction of the flat-slab curve; the continuum's "
                                   "Maugis-Dugdale stress is 1.03 dgamma / z0"}
    if q.get("dugdale_range_h0_m") is not None:
        entry["dugdale_range_h0"] = q["dugdale_range_h0_m"]
    if q.get("recomputed_from_result"):
        entry["work_of_adhesion_used"] = q["work_of_adhesion_used"]
        entry["value_committed"] = q["value_committed"]
        entry["note"] = ("z0 = 1.026 W_F / sigma0 recomputed from the result's sigma0 with the W_F the set uses (the "
                         "out/back mean; md.analysis.flat_slab_range): the committed z0 used the outward W_F")


def _md_origin(src: Source, res: dict, entry: dict) -> dict:
    """The [meta.origin] entry of a used MD value: kind 'md', the run hash, and one line saying what was measured."""
    qname, value, units, stderr = entry["quantity"], entry["value"], entry["units"], entry.get("stderr")
    kind = {"work_of_adhesion": "potential-energy difference dE/A (not a free energy)",
            "work_of_adhesion_free_energy": "free energy of separation by force integration, stderr "
                                            "incl. the window grid's discretisation error",
            "contact_angle_upper_bound": "the water wets: uniform on [0, the run's upper bound]",
            "sam_layer_tangent_modulus": "Young's modulus of the SAM layer from the small-strain tangent of the "
                                         "compression branch of the flat-slab force curve at the annealed thickness, "
                                         "converted with the layer Poisson ratio" + (
                                             "; derived from the run's committed windows"
                                             if (res.get("quantities", {}).get("sam_layer_tangent_modulus") or {}).get(
                                                 "derived_from_windows") else ""),
            "sam_layer_thickness_per_layer": "per-SAM thickness at the anneal's mean tilt, the one the layer "
                                             "modulus is normalised by",
            "interaction_range_z0": ("z0 = 1.026 W_F / sigma0 from the flat-slab force curve, W_F the set's" + (
                                         " (recomputed from the result's sigma0)" if (res.get("quantities", {}).get(
                                             "interaction_range_z0") or {}).get("recomputed_from_result") else "")
                                     if src.recipe.startswith("adhesion") else
                                     "z0 of a 9-3 fit to the pull-off curve: " + src.note)}.get(qname, qname)
    if res.get("workflow") == "wsl_ti" and "work_of_adhesion_sl" in entry:
        ws = entry["work_of_adhesion_sl"]
        w_err = math.hypot(ws.get("stderr") or 0.0, ws.get("discretisation_error") or 0.0)
        kind = (f"Young-Dupre from W_SL = {ws['value']:.4g} +- {w_err:.2g} J/m^2 by thermodynamic integration"
                + (", >= 2 gamma_lv: the water wets" if _ti_wets(res) else ""))
    err = f"+- {stderr:.3g}" if stderr is not None else "(no stderr)"
    return {"kind": "md", "run_hash": str(res.get("run_hash")), "recipe": src.recipe,
            "note": f"MD {src.recipe} at {res.get('fidelity')} ({kind}): {value:.6g} {err} {units}"}


# ----------------------------------------------------------------------------- TOML writing
def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        if isinstance(v, float) and not math.isfinite(v):
            return '"nan"'
        return repr(v)
    if v is None:
        return '""'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return json.dumps(str(v))


def _inline(d: dict) -> str:
    return "{ " + ", ".join(f"{json.dumps(k)} = {_inline(v) if isinstance(v, dict) else _toml_value(v)}"
                            for k, v in d.items()) + " }"


def to_toml(table: dict, header: str = "") -> str:
    """Serialise a set (nested dicts of scalars; [meta] sub-tables of dicts become inline tables)."""
    lines = [f"# {line}" for line in header.splitlines()] if header else []

    def emit(prefix: str, node: dict):
        scalars = {k: v for k, v in node.items() if not isinstance(v, dict)}
        tables = {k: v for k, v in node.items() if isinstance(v, dict)}
        if prefix:
            lines.append(f"\n[{prefix}]")
        for k, v in scalars.items():
            lines.append(f"{json.dumps(k) if '.' in k else k} = {_toml_value(v)}")
        for k, v in tables.items():
            key = json.dumps(k) if "." in k else k
            if prefix.startswith("meta") and any(isinstance(x, dict) for x in v.values()):
                lines.append(f"\n[{prefix}.{key}]")
                for kk, vv in v.items():
                    lines.append(f"{json.dumps(kk)} = {_inline(vv) if isinstance(vv, dict) else _toml_value(vv)}")
            else:
                emit(f"{prefix}.{key}" if prefix else key, v)

    emit("", table)
    return "\n".join(lines) + "\n"


def write_parameter_set(table: dict, path: Path, header: str = "") -> Path:
    """Write atomically and check that the file parses back and that every value has its origin."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = to_toml(table, header)
    parsed = tomllib.loads(text)
    if parsed.get("surfaces") != table.get("surfaces"):
        raise RuntimeError("parameter set did not round-trip through TOML")
    check_origins(parsed.get("meta"), flatten(parsed, str(path), skip=("meta",)), str(path))
    atomic_write_text(path, text)
    return path


def committed_result(recipe: str, fidelity: str, results_dir: Path | None = None) -> dict | None:
    """The committed result of `recipe` at `fidelity` (`md/results/<recipe>-<fidelity>/result.json` in the user
    data folder, then in the shipped data; or in `results_dir` alone when given), or None."""
    folders = [Path(results_dir)] if results_dir is not None else data.md_results_dirs()
    for folder in folders:
        path = folder / f"{recipe}-{fidelity}" / "result.json"
        if path.is_file():
            return json.loads(path.read_text())
    return None
