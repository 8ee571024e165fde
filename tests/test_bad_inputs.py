"""Hundreds of generated bad inputs, each refused the same way: exactly one line on stderr (no traceback),
exit code 2, nothing on stdout, nothing written (issue 12).

Generated from the shipped files: every key of every shipped scene and of every MD recipe's [system] and
one fidelity table (rotating) is given a value of the wrong type and one out of range (and NaN for reals);
an unknown key is added to every table; each file is cut off in the middle of a line (invalid TOML). The
calibration recipes get a missing base set and scene, non-integer seeds and counts, unknown and invalid
`overrides` and `ranges` for every scene key, cross-key conflicts only a full resolve of the uncertainty
scene sees, a broken MD recipe the calibration needs (through --data), and truncations. Options: --workers
and --np below 1 or not integers, --scheduler without --executor dask, --out an existing file, unknown
options and choices.

Every case runs in-process through `calibration.cli.main` (validation fails before any simulation: the
commands that would do work are replaced by ones that fail the test); a handful also run as a subprocess
of the console script.
"""
from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from calibration.cli import main
from continuum.schema import FIELD_BY_PATH, FIELDS
from md.recipe import FIELDS as RECIPE_FIELDS
from nanoimpact import data

ROOT = Path(__file__).resolve().parent.parent
INPUTS = ROOT / "inputs"
SCRIPT = Path(sys.executable).parent / "nanoimpact"
SCENES = sorted((INPUTS / "scenes").glob("*.toml"))
RECIPES = sorted((INPUTS / "md").glob("*.toml"))
CALIBRATIONS = sorted((INPUTS / "calibration").glob("*.toml"))
FIDELITIES = ("smoke", "quick", "production")
OUT = "<OUT>"       # placeholders in argv, filled in per case
INPUT = "<INPUT>"
FILE = "<FILE>"
DIR = "<DIR>"


# ----------------------------------------------------------------------------- a small TOML writer
def _scalar(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v) if math.isfinite(v) else ("nan" if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_scalar(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_scalar(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def dump(table: dict, prefix: str = "") -> str:
    """TOML text of a table: scalars first, then [sub.tables]. (Inline tables for dicts in `inline`.)"""
    lines = [f"{_key(k)} = {_scalar(v)}" for k, v in table.items() if not isinstance(v, dict) or k in _INLINE]
    for k, v in table.items():
        if isinstance(v, dict) and k not in _INLINE:
            name = f"{prefix}{_key(k)}"
            lines += ["", f"[{name}]", dump(v, name + ".")]
    return "\n".join(lines) + "\n"


_INLINE = {"ranges", "overrides"}          # the calibration's dotted-key tables stay inline


def _load(path: Path) -> dict:
    return tomllib.loads(path.read_text())


def _with(table: dict, path: tuple, value) -> dict:
    out = json.loads(json.dumps(table))           # deep copy (plain TOML data)
    node = out
    for k in path[:-1]:
        node = node.setdefault(k, {})
    node[path[-1]] = value
    return out


def _leaves(table: dict, prefix: tuple = ()):
    for k, v in table.items():
        if isinstance(v, dict):
            yield from _leaves(v, prefix + (k,))
        else:
            yield prefix + (k,), v


def _tables(table: dict, prefix: tuple = ()):
    yield prefix
    for k, v in table.items():
        if isinstance(v, dict):
            yield from _tables(v, prefix + (k,))


def _truncations(text: str) -> list[str]:
    """The text cut off in the middle of each `key = value` line (and inside each string): invalid TOML."""
    lines, cuts = text.splitlines(), []
    for i, line in enumerate(lines):
        if line.lstrip().startswith("#") or "=" not in line:
            continue
        head = "\n".join(lines[:i]) + "\n"
        cuts.append(head + line[:line.index("=") + 1] + "\n")
        if '"' in line.split("#")[0]:
            cuts.append(head + line[:line.index('"') + 2])
    bad = []
    for c in cuts:
        try:
            tomllib.loads(c)
        except tomllib.TOMLDecodeError:
            bad.append(c)
    return bad


# ----------------------------------------------------------------------------- value mutations
def _bad_values(kind, low, high, low_open, choices, *, is_list=False, item=None) -> list[tuple[str, object]]:
    """(label, value) pairs a field of this description must refuse."""
    if is_list:
        bad = [("not-a-list", "oops"), ("empty-list", [])]
        if choices:
            bad.append(("bad-item", ["quartz"]))
        elif low is not None:
            bad.append(("item-below", [low - (abs(low) + 1.0)]))
        return bad
    if kind is str:
        bad = [("wrong-type", 12345)]
        if choices:
            bad.append(("not-a-choice", "not_a_choice"))
        return bad
    if kind is bool:
        return [("wrong-type", "yes")]
    bad = [("wrong-type", "oops"), ("bool", True)]
    if kind is int:
        bad.append(("real-for-int", 2.5))
    else:
        bad.append(("nan", float("nan")))
    if low is not None:
        below = low if low_open else low - (abs(low) + 1.0)
        bad.append(("below", int(below) if kind is int else float(below)))
    if high is not None:
        above = high * 10 + 1
        bad.append(("above", int(above) if kind is int else float(above)))
    return bad


def _scene_bad(path: str):
    if path == "params":
        return [("wrong-type", 12345), ("no-such-set", "no_such_set")]
    f = FIELD_BY_PATH[path]
    if f.kind is str and not f.choices:
        return [("wrong-type", 12345)]
    return _bad_values(f.kind, f.low, f.high, f.low_open, f.choices)


def _recipe_field(key: str, workflow: str):
    return next(f for f in RECIPE_FIELDS if f.key == key and workflow in f.workflows)


def _recipe_bad(key: str, workflow: str):
    if key in ("name", "description"):
        return [("wrong-type", 12345)]
    f = _recipe_field(key, workflow)
    return _bad_values(f.kind, f.low, f.high, f.low_open, f.choices, is_list=f.kind is list, item=f.item)


# ----------------------------------------------------------------------------- the cases
def _pick(bad: list, n: int, k: int) -> list:
    """`n` of the mutations, rotating with the running index `k`: every kind is covered across the sample
    while each key costs n cases."""
    return [bad[(k + i) % len(bad)] for i in range(min(n, len(bad)))]


def scene_cases():
    for scene in SCENES:
        table = _load(scene)
        for k, (path, _) in enumerate(_leaves(table)):
            dotted = ".".join(path)
            for label, value in _pick(_scene_bad(dotted), 2, k + len(scene.stem)):
                yield (f"scene-{scene.stem}-{dotted}-{label}", dump(_with(table, path, value)),
                       ["impact", INPUT, "--out", OUT], dotted)
        for t in _tables(table):
            where = ".".join(t + ("bogus_key",))
            yield f"scene-{scene.stem}-unknown-{where}", dump(_with(table, t + ("bogus_key",), 1.0)), \
                ["impact", INPUT, "--out", OUT], where
        for k, text in enumerate(_truncations(scene.read_text())[::3]):
            yield f"scene-{scene.stem}-truncated-{k}", text, ["impact", INPUT, "--out", OUT], "not valid TOML"


def recipe_cases():
    for n, recipe in enumerate(RECIPES):
        table = _load(recipe)
        wf = table["workflow"]
        mutate = FIDELITIES[n % 3]            # every recipe's [system]; one fidelity table each, rotating
        for k, (path, _) in enumerate(_leaves(table)):
            if path[0] == "fidelity" and path[1] != mutate:
                continue
            dotted = ".".join(path)
            for label, value in _pick(_recipe_bad(path[-1], wf), 1, k + n):
                yield (f"md-{recipe.stem}-{dotted}-{label}", dump(_with(table, path, value)),
                       ["md", INPUT, "--fidelity", "smoke", "--out", OUT],
                       "workflow" if path == ("workflow",) else dotted)
        for t in _tables(table):
            if t == ("fidelity",):
                continue
            where = ".".join(t + ("bogus_key",))
            yield f"md-{recipe.stem}-unknown-{where}", dump(_with(table, t + ("bogus_key",), 1)), \
                ["md", INPUT, "--fidelity", "smoke", "--out", OUT], "bogus_key"
        for k, text in enumerate(_truncations(recipe.read_text())[n % 5::9]):
            yield f"md-{recipe.stem}-truncated-{k}", text, ["md", INPUT, "--out", OUT], "not valid TOML"


def _cal(table, path, value):
    return dump(_with(table, path, value))


def calibration_cases():
    quick = _load(INPUTS / "calibration" / "quick.toml")
    argv = ["calibrate", INPUT, "--out", OUT, "--md-cache", "<CASE>/cache", "--params-out", "<CASE>/set.toml"]
    fixed = [
        ("missing-base", ("base",), "no_such_set", "base = 'no_such_set'"),
        ("base-file-missing", ("base",), "nowhere/set.toml", "base = 'nowhere/set.toml'"),
        ("base-wrong-type", ("base",), 3, "base = 3"),
        ("base-empty", ("base",), "", "base = ''"),
        ("name-empty", ("name",), "", "name = ''"),
        ("name-path", ("name",), "../evil", "name = '../evil'"),
        ("name-wrong-type", ("name",), 7, "name = 7"),
        ("description-wrong-type", ("description",), 7, "description = 7"),
        ("unknown-top", ("bogus",), 1, "bogus = 1"),
        ("compare-not-list", ("compare_sets",), "silicon", "compare_sets = 'silicon'"),
        ("compare-missing-set", ("compare_sets",), ["silicon", "no_such_set"], "compare_sets = 'no_such_set'"),
        ("compare-missing-file", ("compare_sets",), ["nowhere/set.toml"], "compare_sets = 'nowhere/set.toml'"),
        ("compare-wrong-type", ("compare_sets",), [3], "compare_sets[0] = 3"),
        ("compare-empty-name", ("compare_sets",), [""], "compare_sets = ['']"),
        ("uncertainty-not-table", ("uncertainty",), 3, "uncertainty = 3"),
        ("unknown-uncertainty-key", ("uncertainty", "bogus"), 1, "uncertainty.bogus = 1"),
        ("missing-scene", ("uncertainty", "scene"), "no_such_scene", "uncertainty.scene = 'no_such_scene'"),
        ("missing-scene-file", ("uncertainty", "scene"), "nowhere/scene.toml", "uncertainty.scene"),
        ("scene-wrong-type", ("uncertainty", "scene"), 5, "uncertainty.scene = 5"),
        ("ranges-not-table", ("uncertainty", "ranges"), [1, 2], "uncertainty.ranges"),
        ("overrides-not-table", ("uncertainty", "overrides"), "x", "uncertainty.overrides"),
    ]
    for key, values in (("seed", (1.5, "1", True, -1, [1])), ("samples", (0, 1, -4, 2.5, "16", 10001, False)),
                        ("max_bounces", (0, -3, 2.5, "30", True, 10**6))):
        fixed += [(f"{key}-{v!r}", ("uncertainty", key), v, f"uncertainty.{key} = ") for v in values]
    for label, path, value, expect in fixed:
        yield f"cal-{label}", _cal(quick, path, value), argv, expect
    # ranges
    ranges = [("unknown-key", "physics.bogus", [1.0, 2.0]), ("unknown-section", "bogus.sigma", [1.0, 2.0]),
              ("int-key", "numerics.grid_points", [32, 64]), ("str-key", "physics.adhesion_law", [1.0, 2.0]),
              ("one-end", "surfaces.roughness.sigma", [5e-9]), ("reversed", "surfaces.roughness.sigma", [7e-9, 5e-9]),
              ("equal", "surfaces.roughness.sigma", [5e-9, 5e-9]), ("not-list", "surfaces.roughness.sigma", "x"),
              ("bool-end", "surfaces.roughness.sigma", [True, 2.0]),
              ("str-end", "surfaces.roughness.sigma", ["a", 1.0])]
    for k, f in enumerate(FIELDS):
        if f.kind is float and f.low is not None and k % 2:
            ranges.append((f"below-{f.path}", f.path, [f.low - (abs(f.low) + 1.0), f.low + 1e-12 + abs(f.low)]))
        if f.kind is float and f.high is not None and not k % 2:
            ranges.append((f"above-{f.path}", f.path, [f.high * 0.5, f.high * 10 + 1]))
    for label, key, value in ranges:
        yield (f"cal-range-{label}", _cal(quick, ("uncertainty", "ranges"), {key: value}), argv,
               f"uncertainty.ranges.{key}")
    # overrides: every scene key with a value it refuses, unknown keys, keys set elsewhere
    for k, f in enumerate(FIELDS):
        if f.path in ("params", "numerics.max_bounces"):
            continue
        bad = [("wrong-type", 12345)] if f.kind is str and not f.choices else \
            _bad_values(f.kind, f.low, f.high, f.low_open, f.choices)
        for label, value in _pick(bad, 2, k):
            yield (f"cal-override-{f.path}-{label}", _cal(quick, ("uncertainty", "overrides"), {f.path: value}), argv,
                   f"uncertainty.overrides.{f.path}")
    for label, key, value in (("unknown", "physics.bogus", "on"), ("unknown-section", "bogus.key", 1.0),
                              ("params", "params", "silicon"), ("max-bounces", "numerics.max_bounces", 3),
                              ("also-a-range", "surfaces.roughness.sigma", 6e-9)):
        yield (f"cal-override-{label}", _cal(quick, ("uncertainty", "overrides"), {key: value}), argv,
               f"uncertainty.overrides.{key}")
    # cross-key rules: only a full resolve of the uncertainty scene with the base set sees them
    cross = [("menisci-dry", {"physics.menisci": "on", "environment.relative_humidity": 0.0},
              "environment.relative_humidity"),
             ("sphere-rough", {"body.shape": "sphere"}, "body.length"),
             ("both-heights", {"impact_velocity": 0.1}, "release_height"),
             ("saturated", {"environment.relative_humidity": 1.0, "physics.menisci": "auto"},
              "environment.relative_humidity"),
             ("sam-layer-no-sam", {"surfaces.sam.layer_modulus": 1e9}, "surfaces.sam.layer_modulus")]
    for label, overrides, expect in cross:
        yield f"cal-cross-{label}", _cal(quick, ("uncertainty", "overrides"), overrides), argv, expect
    for cal in CALIBRATIONS:
        for k, text in enumerate(_truncations(cal.read_text())[::2]):
            yield f"cal-{cal.stem}-truncated-{k}", text, argv, "not valid TOML"


def md_recipe_needed_cases():
    """A broken MD recipe the calibration needs, found first in the user data folder (--data)."""
    from calibration.mdset import recipes_needed

    for name in recipes_needed():
        table = _load(INPUTS / "md" / f"{name}.toml")
        yield (f"cal-needs-{name}", dump(_with(table, ("fidelity", "quick", "timestep_fs"), -1.0)),
               ["--data", "<CASE>/data", "calibrate", "quick", "--out", OUT], "fidelity.quick.timestep_fs",
               f"md/{name}.toml")


def option_cases():
    """(id, argv, expected substring): options refused before any work."""
    cases = []
    for cmd in (["paper"], ["calibrate", "smoke"], ["sweep", "rough_silica", "--vary", "numerics.max_bounces=2"]):
        for v in ("0", "-1", "-16", "x", "1.5", ""):
            cases.append((f"{cmd[0]}-workers-{v or 'empty'}", [*cmd, "--workers", v, "--out", OUT], "--workers"))
    for v in ("0", "-2", "two", "1e3"):
        cases.append((f"md-np-{v}", ["md", "adhesion_silica", "--np", v, "--out", OUT], "--np"))
        cases.append((f"md-jobs-{v}", ["md", "adhesion_silica", "--jobs", v, "--out", OUT], "--jobs"))
        cases.append((f"doctor-np-{v}", ["doctor", "--np", v], "--np"))
    for v in ("0", "-5", "soon", "nan"):
        cases.append((f"doctor-timeout-{v}", ["doctor", "--timeout", v], "--timeout"))
    for cmd in (["calibrate", "smoke"], ["sweep", "rough_silica", "--vary", "numerics.max_bounces=2"]):
        for ex in ("local", "processes"):
            cases.append((f"{cmd[0]}-scheduler-{ex}", [*cmd, "--executor", ex, "--scheduler", "tcp://127.0.0.1:8786",
                                                       "--out", OUT], "--scheduler"))
        cases.append((f"{cmd[0]}-scheduler-default", [*cmd, "--scheduler", "tcp://h:1", "--out", OUT], "--scheduler"))
        cases.append((f"{cmd[0]}-executor-slurm", [*cmd, "--executor", "slurm", "--out", OUT], "--executor"))
    for cmd in (["impact", "hertz_roller"], ["paper"], ["calibrate", "smoke"],
                ["sweep", "rough_silica", "--vary", "numerics.max_bounces=2"], ["md", "adhesion_silica"]):
        cases.append((f"{cmd[0]}-out-file", [*cmd, "--out", FILE], "--out"))
        cases.append((f"{cmd[0]}-unknown-option", [*cmd, "--bogus", "--out", OUT], "--bogus"))
    cases += [
        ("impact-fidelity", ["impact", "hertz_roller", "--fidelity", "ultra", "--out", OUT], "--fidelity"),
        ("impact-params-missing", ["impact", "hertz_roller", "--params", "no_such_set", "--out", OUT], "no_such_set"),
        ("impact-params-truncated", ["impact", "hertz_roller", "--params", INPUT, "--out", OUT], "not valid TOML"),
        ("impact-no-scene", ["impact", "--out", OUT], "scene"),
        ("impact-scene-missing-file", ["impact", "nowhere/x.toml", "--out", OUT], "nowhere/x.toml"),
        ("paper-params-missing", ["paper", "--params", "paper,no_such_set", "--out", OUT], "no_such_set"),
        ("paper-params-empty", ["paper", "--params", ",", "--out", OUT], "--params"),
        ("paper-params-truncated", ["paper", "--params", INPUT, "--out", OUT], "not valid TOML"),
        ("paper-fidelity", ["paper", "--fidelity", "ultra", "--out", OUT], "--fidelity"),
        ("calibrate-md-fidelity", ["calibrate", "smoke", "--md-fidelity", "huge", "--out", OUT], "--md-fidelity"),
        ("calibrate-params-out-dir", ["calibrate", "smoke", "--params-out", DIR, "--out", OUT], "--params-out"),
        ("calibrate-md-cache-file", ["calibrate", "smoke", "--md-cache", FILE, "--out", OUT], "--md-cache"),
        ("calibrate-missing-recipe", ["calibrate", "no_such_recipe", "--out", OUT], "no_such_recipe"),
        ("calibrate-no-recipe", ["calibrate", "--out", OUT], "recipe"),
        ("sweep-no-vary", ["sweep", "rough_silica", "--out", OUT], "--vary"),
        ("sweep-vary-no-equals", ["sweep", "rough_silica", "--vary", "numerics.max_bounces", "--out", OUT], "--vary"),
        ("sweep-vary-unknown-key", ["sweep", "rough_silica", "--vary", "bogus.key=1,2", "--out", OUT], "bogus.key"),
        ("sweep-vary-bad-value", ["sweep", "rough_silica", "--vary", "surfaces.roughness.sigma=6e-9,-1",
                                  "--out", OUT], "surfaces.roughness.sigma"),
        ("sweep-vary-twice", ["sweep", "rough_silica", "--vary", "numerics.max_bounces=2",
                              "--vary", "numerics.max_bounces=3", "--out", OUT], "--vary"),
        ("sweep-missing-scene", ["sweep", "no_such_scene", "--vary", "numerics.max_bounces=2", "--out", OUT],
         "no_such_scene"),
        ("md-fidelity", ["md", "adhesion_silica", "--fidelity", "huge", "--out", OUT], "--fidelity"),
        ("md-missing-recipe", ["md", "no_such_recipe", "--out", OUT], "no_such_recipe"),
        ("md-cache-file", ["md", "adhesion_silica", "--cache", FILE, "--out", OUT], "--cache"),
        ("md-truncated-by-path", ["md", INPUT, "--out", OUT], "not valid TOML"),
        ("unknown-subcommand", ["impacts", "hertz_roller"], "impacts"),
        ("no-subcommand", [], "COMMAND"),
        ("unknown-global-option", ["--bogus", "impact", "hertz_roller", "--out", OUT], "--bogus"),
        ("unknown-global-before-md", ["--bogus", "md", "adhesion_silica", "--out", OUT], "--bogus"),
        ("data-missing", ["--data", "<CASE>/nowhere", "impact", "hertz_roller", "--out", OUT], "--data"),
        ("data-file", ["--data", FILE, "impact", "hertz_roller", "--out", OUT], "--data"),
        ("data-missing-md", ["--data", "<CASE>/nowhere", "md", "adhesion_silica", "--out", OUT], "--data"),
        ("verbose-value", ["impact", "hertz_roller", "--verbose=3", "--out", OUT], "--verbose"),
    ]
    return cases


def _all_cases():
    cases = []
    for gen in (scene_cases, recipe_cases, calibration_cases):
        cases += [pytest.param(text, argv, expect, None, id=cid) for cid, text, argv, expect in gen()]
    cases += [pytest.param(text, argv, expect, where, id=cid) for cid, text, argv, expect, where in
              md_recipe_needed_cases()]
    truncated = _truncations((INPUTS / "params" / "paper.toml").read_text())[0]
    cases += [pytest.param(truncated, argv, expect, None, id=f"option-{cid}") for cid, argv, expect in option_cases()]
    return cases


CASES = _all_cases()


def test_the_sample_is_broad():
    kinds = {"scene": 0, "md": 0, "cal": 0, "option": 0}
    for p in CASES:
        kinds[p.id.split("-")[0]] += 1
    assert len(CASES) >= 600 and all(n >= 40 for n in kinds.values()), kinds


# ----------------------------------------------------------------------------- the check
@pytest.fixture(scope="module")
def no_work():
    """Replace everything that would start a simulation by a failure: a bad input that got through fails
    the test at once instead of running."""
    def started(*a, **k):
        raise AssertionError("work started: validation let a bad input through")

    with pytest.MonkeyPatch.context() as mp:
        for target in ("continuum.dynamics.impact.run_impact", "continuum.paper.report.make_paper",
                       "calibration.pipeline.executor", "calibration.pipeline.md_job", "calibration.sweep.executor",
                       "md.workflows.run_recipe", "md.doctor.run_doctor"):
            mp.setattr(target, started)
        yield


@pytest.fixture(scope="module")
def cases_root(tmp_path_factory):
    return tmp_path_factory.mktemp("bad_inputs")


_numbers = itertools.count()


@pytest.fixture
def case_dir(cases_root):
    """A fresh folder per case (cheaper than tmp_path for hundreds of cases); the user data folder reset."""
    folder = cases_root / f"c{next(_numbers)}"
    folder.mkdir()
    yield folder
    data.set_user_root(None)                                # --data is process-wide


def _fill(argv, case: Path, inp: Path) -> list[str]:
    subs = {OUT: str(case / "out"), INPUT: str(inp), FILE: str(case / "existing.txt"), DIR: str(case / "folder")}
    return [subs.get(a, a).replace("<CASE>", str(case)) for a in argv]


def _snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (p.stat().st_size if p.is_file() else None) for p in folder.rglob("*")}


@pytest.mark.parametrize("text, argv, expect, where", CASES)
def test_bad_input_is_one_line_exit_2_and_nothing_written(no_work, case_dir, capsys, text, argv, expect, where):
    inp = case_dir / "input.toml"
    inp.write_text(text)
    (case_dir / "existing.txt").write_text("keep\n")
    (case_dir / "folder").mkdir()
    if where is not None:                                   # a file in the user data folder (--data)
        (case_dir / "data" / where).parent.mkdir(parents=True)
        (case_dir / "data" / where).write_text(text)
    before = _snapshot(case_dir)
    code = main(_fill(argv, case_dir, inp))
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2, captured.err
    assert len(lines) == 1 and "Traceback" not in captured.err, captured.err
    assert lines[0].startswith("nanoimpact") and expect in lines[0], (expect, lines[0])
    assert captured.out == ""
    assert not (case_dir / "out").exists()
    assert _snapshot(case_dir) == before


# ----------------------------------------------------------------------------- a handful as subprocesses
SUBPROCESS = [
    ["impact", INPUT, "--out", OUT],                                                     # truncated scene
    ["calibrate", "smoke", "--executor", "processes", "--scheduler", "tcp://h:1", "--out", OUT],
    ["paper", "--workers", "-1", "--out", OUT],
    ["md", "adhesion_silica", "--np", "0", "--out", OUT],
]


def test_a_handful_through_the_console_script(tmp_path):
    inp = tmp_path / "input.toml"
    inp.write_text(_truncations((INPUTS / "scenes" / "hertz_roller.toml").read_text())[2])
    procs = [subprocess.Popen([str(SCRIPT), *_fill(argv, tmp_path / f"c{i}", inp)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, cwd=tmp_path) for i, argv in enumerate(SUBPROCESS)]
    for argv, proc in zip(SUBPROCESS, procs):
        out, err = proc.communicate(timeout=120)
        assert proc.returncode == 2, (argv, err)
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and out == "", (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["input.toml"]
