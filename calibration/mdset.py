"""MD results -> a calibrated continuum parameter set (inputs/params/NAME.toml), with provenance.

Which MD quantity feeds which scene key (`MAPPING`), SI in and out; the only conversion is none:
scene files take contact angles in degrees, as the MD results give them. Everything the MD does
not measure (moduli, roughness statistics, SAM thickness) comes from a named base set, with the base set's
origin ([meta.origin], continuum.model.origins); an MD value's origin is `md` with its run hash. A choice of the
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
the set's origin and the report then name as "not a free energy". (The adhesion workflow before version
2 started its windows outside the adhesive well and gave W_F 20x too small; those runs no longer match
the run hash and are not read.)

Which adhesion runs: bare silica from `adhesion_silica_registries` (six quasi-random lateral registries over the
primitive cell, each with its own zero-load contact, windows denser over the force peak), not the three-registry
`adhesion_silica`, whose z0 error was too wide to use (md-review-2). The spread over registries is part of W_F's
stderr (md.analysis). OTS from `adhesion_ots_equilibrated` (both SAMs annealed before contact, three quasi-random
registries over the primitive cell, each with its own zero-load contact, the windows pulled out and back), not
`adhesion_ots`, whose two registries were one and whose one-way windows went straight from the builder (md-review-2).

Interaction range z0: from the flat-slab mean-force curve of the adhesion workflow (version 3):
z0 = 1.026 W_F / sigma0 (Maugis 1992, the LJ 9-3 law), with sigma0 the curve's peak tensile traction, so that
the continuum's Maugis-Dugdale stress 1.03 dgamma / z0 reproduces the measured sigma0 with the W_F used for
dgamma; its stderr (from the peak fit's covariance and W_F's error) goes into the uncertainty bands like every
other. An adhesion result without a flat-slab z0 (before version 3) falls back to the pull-off z0 (a 9-3 fit
against the rigid holder's travel: it absorbs the asperity's compliance and overstates z0), and the origin's
note says so. The pull-off results are otherwise a validation: F / (2 pi R) (DMT, the limit an MD-scale asperity is
in) is compared with W_F in [meta.validation].

SAM layer modulus: the confined (uniaxial-strain) modulus M of the SAMs between the adhesion_ots slabs, from the
compression branch of the same flat-slab curve (md.analysis.confined_layer_modulus: the repulsive windows pressed
into the contact, t = both SAMs' builder thickness). A result that predates the quantity has it derived here from
its committed windows (details.pmf_windows, system) with the same function, and the origin says so. The scene key is
Young's modulus of an isotropic layer, so E = M (1 + nu)(1 - 2 nu) / (1 - nu) with the set's layer Poisson ratio
(surfaces.sam.layer_poisson_ratio, itself a declared choice); a modulus from fewer than three repulsive windows
(a line without a check of its linearity) is not used.

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

from continuum.model.origins import check_origins
from continuum.scene import SceneError, check_value, find_params, flatten
from continuum.schema import FIELD_BY_PATH

from nanoimpact import data
from nanoimpact.fileio import atomic_write_text

#: Committed MD results shipped with the package (inputs/md/results, installed as package data).
RESULTS_DIR = data.shipped_root() / "md" / "results"


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
            "silica droplet keeps the angle it is started at (pinned contact line: 18 deg from a 20 deg start, 39 deg "
            "from 40 deg), so it measures the start, not the surface")

_DROPLET_OTS = ("fallback: no W_SL by thermodynamic integration (wsl_ots); this is the quick R0 = 2 nm droplet's "
                "angle after 60 ps (116.8 deg); sampled 150 ps, R0 = 2 nm reads 118.2 +- 0.8 and R0 = 3 nm "
                "111.4 +- 3.1 deg, 2.1 sigma apart, so take +-4 deg for the droplet size (contact-angle version 4: "
                "docs/md.md)")

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
    Source("surfaces.sam.layer_modulus", "adhesion_ots_equilibrated", ("sam_layer_modulus",)),
)

#: pull-off results compared with the flat-slab work of adhesion (DMT: F = 2 pi R W): validation, not calibration
#: (both pull-offs over four tip positions, each its own contact, so their stderr holds the geometric spread, with a
#: thermostat on the flat's silica only, so nothing the tip drags feels a lab-frame friction)
VALIDATION = (("pulloff_silica_positions", "adhesion_silica_registries"),
              ("pulloff_ots_positions", "adhesion_ots_equilibrated"))


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
    error (``discretisation_error``) and, for an out-and-back W_F, half the hysteresis (``systematic_hysteresis``:
    the reversible work lies between the two directions); None without a finite statistical stderr."""
    e = rec.get("stderr")
    if e is None or not math.isfinite(e):
        return None
    extra = [float(rec[k]) for k in ("discretisation_error", "systematic_hysteresis")
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
    """The result with ``sam_layer_modulus`` derived from its committed windows where the source asks for it and
    the run predates the quantity (md.analysis.confined_layer_modulus on details.pmf_windows: the mean force with
    its dispersion tail, the registry-averaged stderrs, both SAMs' builder thickness); the record says
    ``derived_from_windows``. A result without windows, or whose compression branch gives no modulus, is returned
    as it is (the key then has none of its quantities)."""
    if res is None or "sam_layer_modulus" not in source.quantities or \
            "sam_layer_modulus" in (res.get("quantities") or {}):
        return res
    from md.analysis import confined_layer_modulus, sam_layer_thickness_A

    win, system = (res.get("details") or {}).get("pmf_windows"), res.get("system") or {}
    try:
        t, layers = sam_layer_thickness_A(system)
        force = np.add(win["mean_force_kcal_mol_A"], win.get("tail_force_kcal_mol_A") or 0.0)
        lm = confined_layer_modulus(win["separation_A"], force, win["stderr_kcal_mol_A"], system["area_A2"], t)
    except (KeyError, TypeError, ValueError):
        return res
    q = {"value": lm["modulus_Pa"], "stderr": lm["stderr_Pa"], "units": "Pa", "windows": lm["windows"],
         "layers": layers, "thickness_m": t * 1e-10, "strain_max": lm["strain_max"], "derived_from_windows": True}
    return {**res, "quantities": {**res["quantities"], "sam_layer_modulus": q}}


def _to_scene_units(key: str, value: float, stderr, table: dict):
    """(value, stderr, note) in the scene key's meaning: the SAMs' confined modulus M becomes the layer's Young's
    modulus E = M (1 + nu)(1 - 2 nu) / (1 - nu) with the set's layer Poisson ratio; other keys as they are."""
    if key != "surfaces.sam.layer_modulus":
        return value, stderr, ""
    from md.analysis import young_from_confined

    nu = _get_nested(table, "surfaces.sam.layer_poisson_ratio")
    nu = FIELD_BY_PATH["surfaces.sam.layer_poisson_ratio"].default if nu is None else float(nu)
    factor = young_from_confined(1.0, nu)
    return value * factor, None if stderr is None else stderr * factor, (
        f"confined modulus M = {value / 1e9:.3g} GPa converted to Young's modulus with the set's layer Poisson "
        f"ratio nu = {nu:g} (E = M (1 + nu)(1 - 2 nu) / (1 - nu) = {factor:.3f} M)")


def _implausible(key: str, qname: str, result: dict) -> str | None:
    """Why an MD value that is within the schema's range is still not used: a layer modulus from fewer than three
    repulsive windows rests on a line whose linearity nothing checks."""
    if qname == "sam_layer_modulus":
        n = (result.get("quantities", {}).get(qname) or {}).get("windows")
        if n is not None and n < 3:
            return f"only {n} repulsive windows: the compression branch's linearity is unchecked"
    return None


def build_parameter_set(results: dict[str, dict], base: str, name: str, *, description: str = "",
                        mapping=MAPPING, extra_meta: dict | None = None) -> tuple[dict, list[dict]]:
    """The set as a TOML-ready dict and one row per mapped key (used / rejected / missing).

    `results` maps recipe name -> MD result.json dict. `base` is a parameter-set name or file. Every value of the
    set carries its origin ([meta.origin], continuum.model.origins): `md` with the run hash for a value used here, the
    base set's own origin for a value kept from it; the base's choices in :data:`REPLACED_CHOICES` are left out
    ([meta.replaced] says which and what replaces them).
    """
    table, origin = _base_table(base)
    replaced = replace_choices(table, origin)
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
            rejected[src.key] = {"recipe": src.recipe, "run_hash": res.get("run_hash"), "why": picked[1]}
            continue
        qname, value, stderr, units = picked
        value, stderr, converted = _to_scene_units(src.key, value, stderr, table)
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
        origin[src.key] = _md_origin(src, res, calib[src.key])
    out_meta = {"description": description or f"MD-calibrated set '{name}' on base '{Path(base).stem}'",
                "base": Path(base).stem, "origin": origin, "calibration": calib}
    if replaced:
        out_meta["replaced"] = replaced
    validation = pulloff_validation(results)
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
    if qname == "sam_layer_modulus":
        lm = qs[qname]
        entry["confined_modulus"] = {"value": lm.get("value"), "stderr": lm.get("stderr"), "units": "Pa",
                                     "windows": lm.get("windows"), "layers": lm.get("layers"),
                                     "strain_max": lm.get("strain_max")}
        if lm.get("derived_from_windows"):
            entry["note"] = ("derived from the run's committed windows (details.pmf_windows; the result predates the "
                             "quantity) with md.analysis.confined_layer_modulus")
    if qname == "work_of_adhesion_free_energy":
        entry["stderr_statistical"] = qs[qname].get("stderr")
        entry["discretisation_error"] = qs[qname].get("discretisation_error")
        if qs[qname].get("systematic_hysteresis") is not None:
            entry["systematic_hysteresis"] = qs[qname]["systematic_hysteresis"]
            entry["out_and_back"] = {k: qs[qname].get(k) for k in ("value_out", "stderr_out", "value_back",
                                                                    "stderr_back")}
        de = qs.get("work_of_adhesion", {})
        if de.get("value") is not None:
            entry["energy_estimate"] = {"value": de["value"], "stderr": de.get("stderr"),
                                        "note": "dE/A, potential-energy difference (includes T dS/A); "
                                                "recorded, not used"}
    return entry


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


def _md_origin(src: Source, res: dict, entry: dict) -> dict:
    """The [meta.origin] entry of a used MD value: kind 'md', the run hash, and one line saying what was measured."""
    qname, value, units, stderr = entry["quantity"], entry["value"], entry["units"], entry.get("stderr")
    kind = {"work_of_adhesion": "potential-energy difference dE/A (not a free energy)",
            "work_of_adhesion_free_energy": "free energy of separation by force integration, stderr "
                                            "incl. the window grid's discretisation error",
            "contact_angle_upper_bound": "the water wets: uniform on [0, the run's upper bound]",
            "sam_layer_modulus": "Young's modulus of the SAM layer from the confined modulus of the compression "
                                 "branch of the flat-slab force curve, converted with the set's layer Poisson "
                                 "ratio" + ("; derived from the run's committed windows"
                                           if (res.get("quantities", {}).get("sam_layer_modulus") or {}).get(
                                               "derived_from_windows") else ""),
            "interaction_range_z0": ("z0 = 1.026 W_F / sigma0 from the flat-slab force curve"
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


def pulloff_validation(results: dict[str, dict]) -> dict:
    """F / (2 pi R) of each pull-off (DMT) against the flat-slab W_F of the same surfaces: the ratio and the
    difference in units of the combined stderr, and Tabor's parameter of the pair from the current results
    (:func:`_tabor`), which says how far DMT is the right limit. Validation only: nothing here enters the set."""
    out = {}
    for pull, adh in VALIDATION:
        rp, ra = results.get(pull), results.get(adh)
        if not rp or not ra:
            continue
        qp, qa = rp.get("quantities", {}), ra.get("quantities", {})
        dmt = qp.get("work_of_adhesion_eff_dmt", {})
        wf = qa.get("work_of_adhesion_free_energy") or qa.get("work_of_adhesion") or {}
        v1, v2 = dmt.get("value"), wf.get("value")
        if v1 is None or v2 is None or not (math.isfinite(v1) and math.isfinite(v2)) or v2 == 0:
            continue
        e1, e2 = dmt.get("stderr") or 0.0, _combined_stderr(wf) or 0.0      # W_F's error as the set carries it
        err = math.hypot(e1, e2)
        drag = qp.get("residual_drag_force", {})
        out[pull] = {"F_over_2piR": v1, "F_over_2piR_stderr": e1 or None, "W_F": v2, "W_F_stderr": e2 or None,
                     "ratio": v1 / v2, "difference_in_stderr": (v1 - v2) / err if err > 0 else None,
                     "adhesion_recipe": adh, "residual_drag_N": drag.get("value"),
                     "note": "pull-off F / (2 pi R) (DMT) against the flat-slab work of adhesion; validation only",
                     **_tabor(rp, qa, v2)}
    return out


def _tabor(pull: dict, adhesion_q: dict, work: float) -> dict:
    """Tabor's mu and Maugis' lambda of a pull-off (md.analysis.pulloff.tabor_parameter) from the current results:
    R the pull-off's asperity radius, W the flat-slab W_F, z0 the flat-slab range, E* of silica on silica
    (md.analysis.pulloff.SILICA_E_STAR_PA, a declared choice: the MD asperity's moduli are not measured). For an
    OTS pair the layers are far more compliant than silica, so its mu is larger than this. Empty when a number
    is missing."""
    from md.analysis.pulloff import SILICA_E_STAR_PA, tabor_parameter

    radius_A = (pull.get("settings") or {}).get("asperity_radius_A")
    z0 = (adhesion_q.get("interaction_range_z0") or {}).get("value")
    if not radius_A or not z0 or not work > 0:
        return {}
    t = tabor_parameter(radius_A * 1e-10, work, SILICA_E_STAR_PA, z0)
    return {"tabor_mu": t["mu"], "maugis_lambda": t["lambda"], "tabor_e_star_Pa": SILICA_E_STAR_PA,
            "tabor_note": "R of the pull-off, W_F and z0 of the flat slabs, E* of silica on silica"}


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
