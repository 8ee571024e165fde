"""`nanoimpact calibrate RECIPE.toml`: MD jobs -> calibrated parameter set -> paper cases -> report.

Steps (each timed in the report):
1. MD jobs: every recipe the mapping needs (calibration.mdset.MAPPING) at --md-fidelity, as
   independent jobs on the executor. A committed result (inputs/md/results/<recipe>-<fidelity>/) is
   used only if its run_hash equals the hash md would compute now (same recipe content, force-field
   files and workflow protocol version); otherwise md's own engine runs it, reusing its hashed cache. One made
   under other nanoimpact or LAMMPS versions is used, its versions named in the report, or refused (run again)
   with `same_versions` (--require-same-versions).
2. The set: calibration.mdset.build_parameter_set on the recipe's base set, written atomically to
   inputs/params/<name>.toml (or --params-out), every value with its MD run hash in [meta].
3. The paper's dry, wet and SAM cases for the base set, the recipe's `compare_sets` (default: the literature
   `silicon` set) and the new set
   (continuum.paper.report.make_paper, on the same executor as the MD jobs), into OUT/paper. The sampled
   claims are judged on the paper's averaged model: for the new set over the Latin-hypercube rows of step 4 (the
   same draws), so a calibrated claim's holds_fraction covers the calibration's own uncertainty; the paper
   command's discrete-summit seeds are reported beside each claim (single_surfaces) and decide nothing.
   3b. Claim attribution (calibration.attribution): when a claim holds with the base set and fails with the new
   one, each group of MD values is put back to the base values alone and the paper's cases run again (no
   figures), into OUT/attribution; the claims that hold again name the value that broke them.
4. Uncertainty: a Latin hypercube over the calibrated values (normal with their MD stderr, truncated to each
   key's allowed range) and the user's ranges (uniform) from the recipe's [uncertainty] table; each sample reruns
   the recipe's scene, giving first rebound heights, rebound counts and the escape velocity as median and
   5-95 % bands (OUT/uncertainty.csv, OUT/uncertainty.png); every band says which inputs it covers.
5. OUT/report.md.
"""
from __future__ import annotations

import csv
import io
import logging
import math
import os
import platform
import re
import time
import tomllib
from pathlib import Path

import numpy as np

from continuum.api import FIELD_BY_PATH as SCENE_FIELDS
from nanoimpact import data
from nanoimpact.errors import DataNotFound, InputError
from nanoimpact.executors import Failure, executor
from nanoimpact.fields import REQUIRED, Field, Resolved, frozen_dataclass, section_members
from nanoimpact.fields import json_schema as json_schema_of
from nanoimpact.fileio import atomic_save_figure, atomic_write_text

from .attribution import attribute_claims
from .mdset import (
    build_parameter_set,
    committed_result,
    fallbacks_needed,
    recipes_first,
    recipes_needed,
    write_parameter_set,
)
from .report import CalibrationReport, ValueRow
from .sampling import sample_inputs, truncation, uncertainty_sample

log = logging.getLogger(__name__)


class CalibrationError(InputError):
    """An invalid calibration recipe: names the key, the value and what is allowed (one line, exit code 2)."""


#: Keys of a calibration recipe: top level, and its [uncertainty] table.
RECIPE_KEYS = ("name", "base", "description", "compare_sets", "uncertainty")
#: Sets whose paper cases a calibration runs beside its base and the new set, unless the recipe says otherwise.
DEFAULT_COMPARE_SETS = ("silicon",)
UNCERTAINTY_KEYS = ("samples", "seed", "scene", "max_bounces", "ranges", "overrides")
DEFAULT_UNCERTAINTY_SCENE = "rough_silica"
_SET_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")


def _short(value) -> object:
    """A value for a one-line message: tables shown as {...}."""
    return "{...}" if isinstance(value, dict) else value


#: The calibration recipe's keys (ranges and overrides are tables of scene keys, checked with the scene's fields).
FIELDS = (
    Field("name", str, "", "Name of the calibrated set: letters, digits, '_' and '-' (it names "
          "params/<name>.toml).", REQUIRED),
    Field("base", str, "", "Parameter set (name or file) the MD values go into; every value MD does not measure "
          "comes from it.", REQUIRED),
    Field("description", str, "", "Free text written into the set.", ""),
    Field("compare_sets", list, "", "Parameter sets (names or files) whose paper cases run beside the base and the "
          "new set; may be empty.", list(DEFAULT_COMPARE_SETS), item=str, empty_ok=True),
    Field("uncertainty.samples", int, "", "Latin-hypercube samples.", 16, low=2, high=10000),
    Field("uncertainty.seed", int, "", "Seed of the sampling.", 0, low=0, high=2**63 - 1),
    Field("uncertainty.scene", str, "", "Scene each sample reruns (name or file).", DEFAULT_UNCERTAINTY_SCENE),
    Field("uncertainty.max_bounces", int, "", "Impacts per sample.", 6, low=1,
          high=int(SCENE_FIELDS["numerics.max_bounces"].high)),
)
FIELD_BY_KEY = {f.key: f for f in FIELDS}


def _as_dict(self) -> dict:
    """The recipe as plain JSON-ready data (calibration.json's `calibration`)."""
    import dataclasses

    return dataclasses.asdict(self)


#: A checked calibration recipe (`load_calibration`), generated from the key declarations above; the names of the
#: parameter sets and the uncertainty scene are resolved to what was found (a shipped name stays a name).
Uncertainty = frozen_dataclass(
    "Uncertainty", [*section_members(FIELDS, "uncertainty"),
                    ("ranges", Resolved(dict, "", "{dotted scene key: (low, high)}: user ranges (uniform), each "
                                                  "checked by the scene key's own declaration.")),
                    ("overrides", Resolved(dict, "", "{dotted scene key: value}: scene overrides of every sample."))],
    doc="The [uncertainty] table of a calibration recipe: Latin-hypercube samples of one scene.", module=__name__)
CalibrationRecipe = frozen_dataclass(
    "CalibrationRecipe", [*section_members(FIELDS, ""),
                          ("path", Resolved(str, "", "The recipe file read.")),
                          ("uncertainty", Resolved(Uncertainty, "", "The [uncertainty] table."))],
    doc="A checked calibration recipe (`load_calibration`).", module=__name__, namespace={"to_dict": _as_dict})


def _get(table: dict, key: str, origin: str):
    """The recipe's value of `key` (its default when absent), checked by its field."""
    f = FIELD_BY_KEY[key]
    value = table.get(key.rsplit(".", 1)[-1], f.default)
    if value is REQUIRED:
        raise CalibrationError(key, None, f"is required: {f.doc}", origin)
    return f.check(value, origin, error=CalibrationError)


def json_schema() -> dict:
    """JSON Schema of a calibration recipe (inputs/calibration/*.toml)."""
    doc = json_schema_of(((f.key, f) for f in FIELDS), title="nanoimpact calibration recipe",
                         description="A calibration recipe: MD results -> parameter set -> the paper's cases, "
                                     "with uncertainty bands. See docs/calibration.md.")
    unc = doc["properties"]["uncertainty"]
    unc["properties"]["ranges"] = {
        "type": "object", "description": "{\"dotted.scene.key\" = [low, high]}: user ranges (uniform) of real-valued "
                                         "scene keys", "additionalProperties": {"type": "array", "minItems": 2,
                                                                               "maxItems": 2,
                                                                               "items": {"type": "number"}}}
    unc["properties"]["overrides"] = {"type": "object", "description": "{\"dotted.scene.key\" = value}: scene "
                                      "overrides for every sample (scene keys and values, docs/scenes.md)"}
    return doc


def _dotted(table, key: str, origin: str, prefix: str = "") -> dict:
    """{dotted scene key: value} from a table written with quoted dotted keys, nested tables, or both."""
    if not isinstance(table, dict):
        raise CalibrationError(key, table, "must be a table of {\"dotted.scene.key\" = value}", origin)
    out = {}
    for k, v in table.items():
        if isinstance(v, dict):
            out.update(_dotted(v, key, origin, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def _locate(find, spec: str, recipe: Path) -> Path:
    """`find(spec)` (a name or a path from the working directory), else a relative path from the recipe's
    folder or from the shipped data's parent (shipped recipes write `inputs/scenes/NAME.toml`)."""
    try:
        return find(spec)
    except InputError:
        if not Path(spec).is_absolute():
            for base in (recipe.parent, data.shipped_root().parent):
                if (base / spec).is_file():
                    return base / spec
        raise


def load_calibration(spec: str | Path) -> CalibrationRecipe:
    """Read and check a calibration recipe, whole, before anything runs.

    `spec` is a path or a name (`quick` -> the user data folder's or the shipped
    `calibration/quick.toml`, nanoimpact.data). Checked: the TOML itself; the keys; `name` (it names the
    set's file) and `base` (a parameter set that exists); `[uncertainty]`: `samples` 2..10000, `seed` an
    integer >= 0, `max_bounces` >= 1, `scene` exists, every `ranges` and `overrides` key is a scene key
    (continuum.schema) whose values pass the scene's own checks, and the scene resolves with the base set
    and the overrides at both ends of the ranges (so cross-key rules apply too); and every MD recipe the
    calibration needs (calibration.mdset.MAPPING) loads. The first problem raises CalibrationError.
    """
    path, raw = _read_recipe(spec)
    origin = str(path)
    name, base, description = raw.get("name"), raw.get("base"), raw.get("description", "")
    if not isinstance(name, str) or not _SET_NAME.fullmatch(name):
        raise CalibrationError("name", _short(name), f"is required: {FIELD_BY_KEY['name'].doc}", origin)
    if not isinstance(base, str) or not base:
        raise CalibrationError("base", _short(base), "must be given: a parameter set name or file", origin)
    _get(raw, "description", origin)
    base_file = _find_set(base, "base", path)
    compare = _get(raw, "compare_sets", origin)
    if not all(compare):
        raise CalibrationError("compare_sets", compare, "set names or files cannot be empty", origin)
    compare_files = []
    for c in compare:
        found = _find_set(c, "compare_sets", path)
        compare_files.append(str(found) if data.is_path_spec(c) else c)
    uncertainty = _check_uncertainty(raw.get("uncertainty", {}), path, base, base_file)
    _check_md_recipes(origin)
    # a base set given as a path is kept as the file found (it may have been found from the recipe's folder)
    return CalibrationRecipe(name=name, base=str(base_file) if data.is_path_spec(base) else base,
                             description=description, compare_sets=compare_files, path=str(path),
                             uncertainty=uncertainty)


def _read_recipe(spec: str | Path) -> tuple[Path, dict]:
    """The recipe's file and its TOML table, every top-level key known."""
    try:
        path = data.find("calibration", spec, key="recipe")
    except DataNotFound as exc:
        raise CalibrationError("recipe", str(spec), exc.allowed) from None
    origin = str(path)
    try:
        raw = tomllib.loads(path.read_bytes().decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CalibrationError("recipe", origin, f"is not valid TOML ({exc})") from None
    for key, value in raw.items():
        if key not in RECIPE_KEYS:
            raise CalibrationError(key, _short(value), f"unknown key; keys allowed here: {', '.join(RECIPE_KEYS)}",
                                   origin)
    return path, raw


def _find_set(spec: str, key: str, recipe: Path) -> Path:
    """The parameter set `spec` names (found as `_locate` finds it) after checking it reads; `key` names it."""
    from continuum.api import SceneError, find_params, read_toml

    try:
        found = _locate(find_params, spec, recipe)
        read_toml(found, "params")
    except SceneError as exc:
        raise CalibrationError(key, spec, exc.allowed if exc.key == "params" else str(exc), str(recipe)) from None
    return found


def _check_uncertainty(unc, path: Path, base: str, base_file: Path) -> Uncertainty:
    """`[uncertainty]` checked key by key, then the scene resolved at both ends of the ranges."""
    from continuum.api import SceneError, find_scene

    origin = str(path)
    if not isinstance(unc, dict):
        raise CalibrationError("uncertainty", unc, f"must be a table with keys {', '.join(UNCERTAINTY_KEYS)}", origin)
    for key, value in unc.items():
        if key not in UNCERTAINTY_KEYS:
            raise CalibrationError(f"uncertainty.{key}", _short(value),
                                   f"unknown key; keys allowed here: {', '.join(UNCERTAINTY_KEYS)}", origin)
    samples = _get(unc, "uncertainty.samples", origin)
    seed = _get(unc, "uncertainty.seed", origin)
    max_bounces = _get(unc, "uncertainty.max_bounces", origin)
    scene_spec = unc.get("scene", DEFAULT_UNCERTAINTY_SCENE)
    if not isinstance(scene_spec, str) or not scene_spec:
        raise CalibrationError("uncertainty.scene", _short(scene_spec), "must be a scene name or file", origin)
    try:
        scene_file = _locate(find_scene, scene_spec, path)
    except SceneError as exc:
        raise CalibrationError("uncertainty.scene", scene_spec, exc.allowed, origin) from None
    ranges = _check_ranges(_dotted(unc.get("ranges", {}), "uncertainty.ranges", origin), origin)
    overrides = _check_overrides(_dotted(unc.get("overrides", {}), "uncertainty.overrides", origin), ranges, origin)
    _resolve_at_range_ends(scene_file, scene_spec, base, base_file, ranges, overrides, max_bounces, origin)
    return Uncertainty(samples=samples, seed=seed, scene=str(scene_file), max_bounces=max_bounces, ranges=ranges,
                       overrides=overrides)


def _check_ranges(ranges: dict, origin: str) -> dict:
    """`uncertainty.ranges`: real-valued scene keys, each [low, high] with both ends allowed."""
    from continuum.api import FIELD_BY_PATH, SceneError, check_value

    for key, rng in ranges.items():
        where, f = f"uncertainty.ranges.{key}", FIELD_BY_PATH.get(key)
        if f is None:
            raise CalibrationError(where, rng, "unknown scene key; ranges take real-valued scene keys "
                                   "(docs/scenes.md), e.g. surfaces.roughness.sigma", origin)
        if f.kind is not float:
            raise CalibrationError(where, rng, f"{key} takes {f.allowed()}; ranges take real-valued scene keys "
                                   "only (samples are uniform reals)", origin)
        if not (isinstance(rng, list) and len(rng) == 2
                and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in rng) and rng[0] < rng[1]):
            raise CalibrationError(where, rng, "must be [low, high] with low < high", origin)
        for end in rng:
            try:
                check_value(f, end, origin)
            except SceneError:
                raise CalibrationError(where, rng, f"both ends must be {f.allowed()}", origin) from None
    return ranges


def _check_overrides(overrides: dict, ranges: dict, origin: str) -> dict:
    """`uncertainty.overrides`: scene keys with allowed values, none of them the set, the bounces or a range."""
    from continuum.api import FIELD_BY_PATH, SceneError, check_value

    for key, value in overrides.items():
        where = f"uncertainty.overrides.{key}"
        if key not in FIELD_BY_PATH:
            raise CalibrationError(where, _short(value), "unknown scene key (docs/scenes.md)", origin)
        if key in ("params", "numerics.max_bounces") or key in ranges:
            instead = {"params": "the set is the calibrated one; set `base`",
                       "numerics.max_bounces": "set uncertainty.max_bounces"}.get(key, "it is in uncertainty.ranges")
            raise CalibrationError(where, value, f"cannot be overridden here: {instead}", origin)
        try:
            check_value(FIELD_BY_PATH[key], value, origin)
        except SceneError as exc:
            raise CalibrationError(where, value, exc.allowed, origin) from None
    return overrides


def _resolve_at_range_ends(scene_file, scene_spec, base, base_file, ranges, overrides, max_bounces, origin) -> None:
    """The uncertainty scene resolves with the base set and the overrides at both ends of the ranges, so the
    scene's cross-key rules apply to the samples too."""
    from continuum.api import SceneError, load_scene

    for end in ((0, 1) if ranges else (0,)):
        trial = {**overrides, **{k: r[end] for k, r in ranges.items()}, "numerics.max_bounces": max_bounces}
        try:
            load_scene(scene_file, params=str(base_file), overrides=trial, override_label="uncertainty")
        except SceneError as exc:
            at = f", ranges at their {('low', 'high')[end]} ends" if ranges else ""
            inner = "" if exc.origin in ("", "uncertainty", str(scene_file)) else f" ({exc.origin})"
            raise CalibrationError(exc.key, _short(exc.value), exc.allowed,
                                   f"{origin}: uncertainty.scene {scene_spec!r} with base {base!r} and the "
                                   f"overrides{at}{inner}") from None


def _check_md_recipes(origin: str) -> None:
    """Every MD recipe the calibration needs loads."""
    from md import load_recipe

    for recipe in recipes_needed():
        try:
            load_recipe(recipe)
        except InputError as exc:
            raise CalibrationError(exc.key, _short(exc.value), exc.allowed,
                                   f"{origin}: MD recipe {recipe}, which the calibration needs"
                                   + (f" ({exc.origin})" if exc.origin else "")) from None


def check_run_options(out: str | Path, md_fidelity: str, executor_name: str, workers: int | None,
                      scheduler: str | None, paper_sets) -> None:
    """The options of `calibrate`, checked before anything runs or is written (CalibrationError, one line)."""
    from continuum.api import SceneError, find_params
    from md import FIDELITIES
    from nanoimpact.executors import NAMES

    if Path(out).exists() and not Path(out).is_dir():
        raise CalibrationError("out", str(out), "is an existing file; give a folder (new or existing)")
    if md_fidelity not in FIDELITIES:
        raise CalibrationError("md_fidelity", md_fidelity, f"one of {', '.join(FIDELITIES)}")
    if executor_name not in NAMES:
        raise CalibrationError("executor", executor_name, f"one of {', '.join(NAMES)}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise CalibrationError("workers", workers, "an integer >= 1 (or not given)")
    if scheduler and executor_name != "dask":
        raise CalibrationError("scheduler", scheduler, f"goes with executor 'dask', not {executor_name!r}")
    for s in paper_sets:
        try:
            find_params(s)
        except SceneError as exc:
            raise CalibrationError("paper_sets", s, exc.allowed) from None


# ----------------------------------------------------------------------------- MD jobs
def current_hash(recipe_name: str, fidelity: str) -> str:
    """The run hash md would give `recipe_name` at `fidelity` now."""
    from md import run_hash

    return run_hash(recipe_name, fidelity)[0]


def committed_if_usable(recipe_name: str, fidelity: str, results_dir, same_versions: bool) -> tuple[dict | None, str]:
    """(the committed result of `recipe_name` if its hash is current and, with `same_versions`, it was made under
    the running nanoimpact and LAMMPS versions, else None; what its versions say: 'made with ...' or '')."""
    from md import describe_differences, version_differences

    committed = committed_result(recipe_name, fidelity, None if results_dir is None else Path(results_dir))
    if committed is None or committed.get("run_hash") != current_hash(recipe_name, fidelity):
        return None, ""
    made = describe_differences(version_differences(committed.get("provenance", {})))
    return (None if made and same_versions else committed), made


def md_plan(recipes, fidelity: str, cache: str | None = None, results_dir: str | Path | None = None,
            same_versions: bool = False) -> dict[str, str]:
    """Where each recipe's result will come from, decided before anything runs (hashes and files only): 'committed'
    (a committed result at the current hash, made under the running versions if `same_versions`), 'md cache'
    (a finished run in the cache), 'resumes' (an unfinished run of the current hash in the cache: it goes on from
    its last restart) or 'runs' (from the start)."""
    from md import load_recipe, run_dir_for

    out = {}
    for name in recipes:
        run_dir = run_dir_for(load_recipe(name).name, fidelity, current_hash(name, fidelity), cache)
        if committed_if_usable(name, fidelity, results_dir, same_versions)[0] is not None:
            out[name] = "committed"
        elif (run_dir / "result.json").is_file():
            out[name] = "md cache"
        elif run_dir.is_dir() and any(run_dir.iterdir()):
            out[name] = "resumes"
        else:
            out[name] = "runs"
    return out


def md_job(task: tuple) -> dict:
    """One MD recipe, `(recipe, fidelity, cache, results_dir, same_versions)`: the committed result if its hash is
    current (and its versions the running ones, with same_versions), else md's engine (cached). Picklable."""
    recipe_name, fidelity, cache, results_dir, same_versions = task
    start = time.perf_counter()
    digest = current_hash(recipe_name, fidelity)
    usable, made = committed_if_usable(recipe_name, fidelity, results_dir, same_versions)
    if usable is not None:
        return {"recipe": recipe_name, "result": usable, "source": "committed" + (f" ({made})" if made else ""),
                "wall_s": time.perf_counter() - start}
    committed = committed_result(recipe_name, fidelity, None if results_dir is None else Path(results_dir))
    from md import describe_differences, load_recipe, run_recipe, version_differences

    # resume: a run this job (or a worker that died, or an earlier calibration) left unfinished goes on from its
    # last restart instead of starting again; with nothing to resume it is a fresh run
    outcome = run_recipe(load_recipe(recipe_name), fidelity, cache=cache, resume=True, progress=False, echo=None,
                         same_versions=same_versions)
    cached = describe_differences(version_differences(outcome.result.get("provenance", {}))) if outcome.reused else ""
    note = ("md cache" + (f" ({cached})" if cached else "")) if outcome.reused else "ran"
    if made:
        note += f" (the committed result was {made}; the same versions are required)"
    elif committed is not None:
        note += f" (committed result's hash {str(committed.get('run_hash'))[:16]} is not current {digest[:16]})"
    return {"recipe": recipe_name, "result": outcome.result, "source": note, "wall_s": time.perf_counter() - start}


def _md_wall(result: dict) -> float:
    """Wall time (s) the MD dynamics took, summed over the run's legs (its result's record; 0 if absent).
    Not the last invocation's wall time: a resumed or re-analysed run spent most of its time in earlier ones."""
    w = result.get("wall_s")
    if isinstance(w, dict):
        return float(w.get("dynamics") or w.get("total_this_invocation") or 0.0)
    return float(w or 0.0)


def _band(values) -> dict:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], float)
    if v.size == 0:
        return {"median": None, "p05": None, "p95": None, "n": 0}
    return {"median": float(np.median(v)), "p05": float(np.percentile(v, 5)), "p95": float(np.percentile(v, 95)),
            "n": int(v.size)}


# ----------------------------------------------------------------------------- pipeline
def calibrate(recipe_path: str | Path, out: str | Path, *, md_fidelity: str = "quick", executor_name: str = "local",
              workers: int | None = None, scheduler: str | None = None, params_out: str | Path | None = None,
              md_cache: str | None = None, results_dir: str | Path | None = None,
              paper_sets: tuple | None = None, progress=None, same_versions: bool = False) -> CalibrationReport:
    """Run the whole pipeline; returns the typed CalibrationReport (also written to OUT/calibration.json and
    OUT/report.md).

    `paper_sets`: the sets whose paper cases run beside the base and the new set (default: the recipe's
    `compare_sets`). `same_versions`: refuse committed and cached MD results made under other nanoimpact or LAMMPS
    versions (they are run again); by default they are used and the report names their versions."""
    progress = progress or log.info                 # library code logs; the CLI decides what is shown
    t_all = time.perf_counter()
    cal = load_calibration(recipe_path)             # the whole recipe and the options, before anything runs
    paper_sets = cal.compare_sets if paper_sets is None else paper_sets
    check_run_options(out, md_fidelity, executor_name, workers, scheduler, paper_sets)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timings = {}
    ex = executor(executor_name, workers, scheduler)
    try:
        # 1. MD jobs
        t = time.perf_counter()
        results, sources = _run_md_jobs(ex, cal.name, md_fidelity, executor_name, md_cache, results_dir, progress,
                                        same_versions)
        timings["md_s"] = time.perf_counter() - t
        # 2. the set
        machine = {"cores": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()}
        md_compute = {r: _md_wall(res) for r, res in results.items()}
        table, rows, set_path, keys, samples = _write_set(cal, results, md_fidelity, machine, timings["md_s"],
                                                          md_compute, params_out, progress)
        # 3. the paper's cases
        t = time.perf_counter()
        from continuum.api import DEFAULT_SEEDS, make_paper

        sets = [cal.base, *[s for s in paper_sets if s != cal.base], str(set_path)]
        # the new set's claims judged over the calibration's own Latin-hypercube rows; the seeds reported beside them
        rows_paper = paper_uncertainty(cal.uncertainty, samples, set_path)
        paper = make_paper(sets, out / "paper", executor=ex, progress=lambda m: None,   # the user's executor
                           seeds=DEFAULT_SEEDS, uncertainty=rows_paper)
        timings["paper_s"] = time.perf_counter() - t
        # 3b. why a claim that holds with the base set fails with the new one: each MD value put back alone
        t = time.perf_counter()
        attribution = attribute_claims(table, rows, paper["checks"], Path(set_path).stem, Path(cal.base).stem,
                                       out / "attribution", executor=ex, progress=progress, set_path=str(set_path),
                                       uncertainty_rows=rows_paper[Path(set_path).stem])
        timings["attribution_s"] = time.perf_counter() - t
        # 4. uncertainty
        t = time.perf_counter()
        sample_out = _run_uncertainty(ex, cal.uncertainty, samples, set_path)
        timings["uncertainty_s"] = time.perf_counter() - t
    finally:
        ex.close()
    bands = _bands(sample_out, keys, cal.uncertainty, table)
    _write_uncertainty(out, keys, sample_out, bands)
    timings["total_s"] = time.perf_counter() - t_all
    report = CalibrationReport(name=cal.name, set_path=Path(set_path), out=out, calibration=cal,
                               rows=tuple(ValueRow.from_dict(r) for r in rows), md_sources=sources, bands=bands,
                               paper_checks=tuple(paper["checks"]), timings=timings, machine=machine,
                               md_compute_total_s=sum(md_compute.values()), claim_attribution=attribution,
                               validation=table["meta"].get("validation", {}))
    progress(f"calibrate: report {report.write()}; total {timings['total_s']:.1f} s")
    return report


def _run_md_jobs(ex, name: str, md_fidelity: str, executor_name: str, md_cache, results_dir,
                 progress, same_versions: bool = False) -> tuple[dict, dict]:
    """Every MD recipe the calibration needs, committed, cached or run on `ex`; then the fallbacks whose
    preferred result lacks the key's quantity. Returns (results by recipe, where each came from)."""
    recipes = recipes_first()
    progress(f"calibrate {name}: {len(recipes)} MD recipes at {md_fidelity} on '{executor_name}' (a fallback "
             f"recipe runs only where its preferred result lacks the quantity)")
    plan = md_plan(recipes, md_fidelity, md_cache, results_dir, same_versions)
    todo = [r for r, how in plan.items() if how in ("runs", "resumes")]
    progress("  MD plan: " + "; ".join(f"{how}: {', '.join(r for r, h in plan.items() if h == how)}"
                                       for how in ("committed", "md cache", "resumes", "runs")
                                       if how in plan.values())
             + (f" ({len(todo)} to run: minutes to hours each at quick, docs/md.md has their cost)" if todo else
                " (no MD to run)"))
    results, sources = {}, {}

    def run_md(names):
        tasks = [(r, md_fidelity, md_cache, None if results_dir is None else str(results_dir), same_versions)
                 for r in names]
        for _, job in ex.map(md_job, tasks):
            results[job["recipe"]] = job["result"]
            sources[job["recipe"]] = {"source": job["source"], "wall_s": job["wall_s"],
                                      "run_hash": job["result"].get("run_hash")}
            progress(f"  MD {job['recipe']}: {job['source']} ({job['wall_s']:.1f} s)")

    run_md(recipes)
    extra = fallbacks_needed(results)
    if extra:                   # a preferred result without the key's quantity (an older protocol)
        progress(f"  MD fallbacks needed: {', '.join(extra)}")
        run_md(extra)
    return results, sources


def _write_set(cal: CalibrationRecipe, results: dict, md_fidelity: str, machine: dict, md_s: float,
               md_compute: dict, params_out, progress) -> tuple[dict, list, Path, list, list]:
    """The calibrated parameter set built from the MD results and written, with its Latin-hypercube rows beside it
    (`<name>.uncertainty.csv`, the inputs of each row; `[meta] uncertainty_rows` points to it, so `nanoimpact paper`
    judges the set's claims over them by default, `continuum.paper.samples.set_uncertainty_rows`); the rows are
    written first, so the set never points to a missing file. Returns (table, rows, its path, the sampled keys, the
    samples)."""
    set_path = Path(params_out) if params_out else data.writable_root() / "params" / f"{cal.name}.toml"
    rows_name = f"{set_path.stem}.uncertainty.csv"
    meta = {"md_fidelity": md_fidelity, "machine": machine, "pipeline_md_wall_s": md_s,
            "md_compute_wall_s": md_compute, "md_compute_total_s": sum(md_compute.values()),
            "created_by": f"nanoimpact calibrate {cal.path}"}
    table, rows = build_parameter_set(results, cal.base, cal.name, description=cal.description, extra_meta=meta)
    keys, samples = sample_inputs(table["meta"].get("calibration", {}), cal.uncertainty.ranges,
                                  cal.uncertainty.samples, cal.uncertainty.seed)
    if samples:
        fh = io.StringIO(newline="")
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows({k: s.get(k) for k in keys} for s in samples)
        atomic_write_text(set_path.parent / rows_name, fh.getvalue())
        table["meta"]["uncertainty_rows"] = rows_name
    write_parameter_set(table, set_path, header=(
        f"The `{cal.name}` parameter set, written by `nanoimpact calibrate {cal.path} --md-fidelity "
        f"{md_fidelity}`: MD-measured values on the `{cal.base}` base set; [meta.calibration] gives each "
        "value's stderr and MD run hash, [meta.rejected] what was not used and why."))
    progress(f"  wrote {set_path}" + (f" and its {len(samples)} uncertainty rows ({rows_name})" if samples else ""))
    return table, rows, set_path, keys, samples


def paper_uncertainty(unc: Uncertainty, samples: list[dict], set_path: Path) -> dict[str, list[dict]]:
    """The rows the paper run judges the new set's sampled claims on: each Latin-hypercube sample (`samples`,
    :func:`sample_inputs`) with the recipe's scene overrides, the same rows the uncertainty bands run
    ({set name: [overrides, ...]}, continuum.paper.report.make_paper's `uncertainty`)."""
    return {Path(set_path).stem: [{**unc.overrides, **smp} for smp in samples]}


def _run_uncertainty(ex, unc: Uncertainty, samples: list[dict], set_path: Path) -> list:
    """The Latin-hypercube `samples` of the set's uncertain inputs, each run on `ex`; a sample whose job failed
    (a crash, a lost worker) is counted and reported like a refused one. Returns the outcomes."""
    sample_out = [None] * len(samples)
    tasks = [(unc.scene, str(set_path), {**unc.overrides, **smp}, unc.max_bounces) for smp in samples]
    for i, s in ex.map(uncertainty_sample, tasks, on_error="collect"):
        sample_out[i] = {"overrides": tasks[i][2], "error": s.reason} if isinstance(s, Failure) else s
    return sample_out


def _bands(sample_out: list, keys: list, unc: Uncertainty, table: dict) -> dict:
    """The bands of the first rebound, the rebound count and the escape velocity over the samples that ran."""
    ran = [s for s in sample_out if "error" not in s]
    return {"first_rebound_over_h0": _band(s.get("rebounds_over_h0", [None])[0] if s.get("rebounds_over_h0")
                                           else 0.0 for s in ran),
            "rebound_count": _band(s["rebound_count"] for s in ran),
            "escape_velocity_m_per_s": _band(s.get("escape_velocity") for s in ran),
            "covers": keys or ["(no input with an uncertainty: every band is a single point)"],
            "max_bounces": unc.max_bounces,
            "rebound_count_capped": sum(s["rebound_count"] >= unc.max_bounces for s in ran),
            "samples": len(sample_out), "failed_samples": len(sample_out) - len(ran),
            "left_out": sorted({k for s in ran for k in s.get("left_out", ())}),
            "truncated": truncation(table["meta"].get("calibration", {})),
            "seed": unc.seed, "scene": unc.scene}


def _write_uncertainty(out: Path, keys, samples, bands) -> None:
    from matplotlib.figure import Figure

    fh = io.StringIO(newline="")
    w = csv.writer(fh)
    w.writerow(keys + ["rebound1_over_h0", "rebound2_over_h0", "rebound3_over_h0", "rebound_count",
                       "escape_velocity_m_per_s", "error"])
    for s in samples:
        r = (s.get("rebounds_over_h0") or []) + [None] * 3
        w.writerow([s["overrides"].get(k) for k in keys] + r[:3] +
                   [s.get("rebound_count"), s.get("escape_velocity"), s.get("error", "")])
    atomic_write_text(out / "uncertainty.csv", fh.getvalue())
    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    ok = [s for s in samples if "error" not in s]
    for s in ok:
        ax.plot(range(1, len(s["rebounds_over_h0"]) + 1), s["rebounds_over_h0"], color="0.7", lw=0.7)
    if ok:
        m = max(len(s["rebounds_over_h0"]) for s in ok)
        arr = np.array([(s["rebounds_over_h0"] + [0.0] * m)[:m] for s in ok])
        x = np.arange(1, m + 1)
        ax.fill_between(x, np.percentile(arr, 5, axis=0), np.percentile(arr, 95, axis=0), alpha=0.3,
                        label="5-95 %")
        ax.plot(x, np.median(arr, axis=0), "k-o", ms=3, label="median")
    ax.set_xlabel("bounce")
    ax.set_ylabel("rebound height / h0")
    import textwrap

    ax.set_xticks(range(1, 4))
    ax.set_title("\n".join(textwrap.wrap(f"rebound bands, {bands['samples']} samples; inputs: " +
                                          ", ".join(bands["covers"]), 95)), fontsize=7)
    ax.legend(fontsize=7)
    fig.tight_layout()
    atomic_save_figure(fig, out / "uncertainty.png", dpi=110)
