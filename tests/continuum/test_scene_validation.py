"""Scene files are validated at the edge: each bad input is refused with the key, the value and what is allowed."""
import copy
import math
import subprocess
import sys
from pathlib import Path

import pytest

from continuum.scene import SceneError, resolve_scene
from continuum.schema import schema_markdown

ROOT = Path(__file__).resolve().parents[2]

GOOD = {
    "name": "t",
    "release_height": 100e-9,
    "body": {"shape": "cylinder", "radius": 5e-6, "length": 3.28e-3, "mass": 0.6e-9},
    "surfaces": {
        "work_of_adhesion": 0.0,
        "body": {"youngs_modulus": 169e9, "poisson_ratio": 0.22},
        "substrate": {"youngs_modulus": 169e9, "poisson_ratio": 0.22, "contact_angle": 30.0},
    },
}


def _with(path, value, base=GOOD):
    table = copy.deepcopy(base)
    node = table
    *parents, leaf = path.split(".")
    for p in parents:
        node = node.setdefault(p, {})
    if value is _DELETE:
        del node[leaf]
    else:
        node[leaf] = value
    return table


_DELETE = object()

BAD = [
    # (key that must be named, dotted path to change, bad value, words the message must contain)
    ("body.radius", "body.radius", -1e-6, ">= 1e-09"),
    ("body.radius", "body.radius", 0.0, ">= 1e-09"),
    ("body.radius", "body.radius", "5um", "a number"),
    ("body.mass", "body.mass", 0.0, "> 0"),
    ("body.mass", "body.mass", True, "a number"),
    ("body.shape", "body.shape", "cube", "'cylinder', 'sphere'"),
    ("body.length", "body.length", _DELETE, "required for a cylinder"),
    ("body.mass", "body.density", 2330.0, "exactly one of body.mass and body.density"),
    ("surfaces.body.poisson_ratio", "surfaces.body.poisson_ratio", 0.5, "< 0.5"),
    ("surfaces.body.poisson_ratio", "surfaces.body.poisson_ratio", -0.1, ">= 0"),
    ("surfaces.substrate.youngs_modulus", "surfaces.substrate.youngs_modulus", -169e9, ">= 1e+06"),
    ("surfaces.substrate.youngs_modulus", "surfaces.substrate.youngs_modulus", float("nan"), "finite"),
    ("surfaces.substrate.contact_angle", "surfaces.substrate.contact_angle", 190.0, "<= 180"),
    ("surfaces.substrate.contact_angle", "surfaces.substrate.contact_angle", -5.0, ">= 0"),
    ("surfaces.work_of_adhesion", "surfaces.work_of_adhesion", -0.1, ">= 0"),
    ("environment.relative_humidity", "environment.relative_humidity", 1.5, "<= 1"),
    ("environment.temperature", "environment.temperature", 0.0, "> 0"),
    ("environment.gravity", "environment.gravity", -9.81, ">= 0"),
    ("environment.gravity", "environment.gravity", 0.0, "must be > 0 when the body is released"),
    ("release_height", "release_height", -1e-9, "> 0"),
    ("release_height", "impact_velocity", 0.1, "exactly one of release_height and impact_velocity"),
    ("release_height", "release_height", _DELETE, "exactly one of release_height and impact_velocity"),
    ("numerics.max_bounces", "numerics.max_bounces", 2.5, "an integer"),
    ("numerics.max_bounces", "numerics.max_bounces", 0, ">= 1"),
    ("numerics.rtol", "numerics.rtol", 0.1, "<= 0.001"),
    ("numerics.fidelity", "numerics.fidelity", "ultra", "'fast', 'standard', 'reference'"),
    ("physics.adhesion_law", "physics.adhesion_law", "magic", "'none', 'jkr'"),
    ("physics.adhesion_law", "physics.adhesion_law", "jkr", "2-D JKR is not implemented"),
    ("body.colour", "body.colour", "red", "unknown key"),
    ("surfaces.body.youngs_modulus", "surfaces.body.youngs_modulus", _DELETE, "is required"),
    ("contact", "contact", "fractal", "'smooth'"),
    ("physics.detachment", "physics.detachment", "peel", "'displacement', 'load'"),
]


@pytest.mark.parametrize("key,path,value,words", BAD,
                         ids=[f"{p}=<deleted>" if v is _DELETE else f"{p}={v!r}" for _, p, v, _ in BAD])
def test_bad_scene_is_refused_naming_key_value_and_range(key, path, value, words):
    with pytest.raises(SceneError) as err:
        resolve_scene(table=_with(path, value))
    assert err.value.key == key
    message = str(err.value)
    assert key in message and words in message


def test_at_least_twenty_distinct_bad_inputs_are_covered():
    assert len({(p, repr(v)) for _, p, v, _ in BAD}) >= 20


def test_sphere_jkr_needs_positive_work_of_adhesion():
    table = _with("body", {"shape": "sphere", "radius": 1e-6, "density": 2200.0})
    table["physics"] = {"adhesion_law": "jkr"}
    with pytest.raises(SceneError) as err:
        resolve_scene(table=table)
    assert err.value.key == "surfaces.work_of_adhesion"


def test_sphere_refuses_a_length():
    table = _with("body", {"shape": "sphere", "radius": 1e-6, "density": 2200.0, "length": 1e-3})
    with pytest.raises(SceneError, match="body.length"):
        resolve_scene(table=table)


def test_unknown_section_is_refused():
    with pytest.raises(SceneError, match="unknown key"):
        resolve_scene(table=_with("weather", {"rain": 1}))


def test_good_scene_converts_degrees_and_derives_mass_from_density():
    table = _with("body", {"shape": "sphere", "radius": 1e-6, "density": 2000.0})
    scene = resolve_scene(table=table).scene
    assert scene.surfaces.substrate.contact_angle == pytest.approx(math.pi / 6, rel=1e-15, abs=0)
    assert scene.body.mass == pytest.approx(4 / 3 * math.pi * 1e-18 * 2000.0, rel=1e-15, abs=0)


def test_params_set_is_overridden_by_scene_values_and_sources_recorded(tmp_path):
    pset = tmp_path / "mine.toml"
    pset.write_text("[meta.origin]\n"
                    '"surfaces.work_of_adhesion" = { kind = "chosen", reason = "test" }\n'
                    '"surfaces.body.youngs_modulus" = { kind = "material", source = "test" }\n'
                    "[surfaces]\nwork_of_adhesion = 0.3\n[surfaces.body]\nyoungs_modulus = 1e11\n")
    table = _with("surfaces.body.youngs_modulus", 2e11)
    resolved = resolve_scene(table=table, params=str(pset))
    assert resolved.scene.surfaces.body.youngs_modulus == 2e11
    assert resolved.sources["surfaces.body.youngs_modulus"] == "scene"
    # the GOOD scene sets work_of_adhesion itself; drop it to see the set's value
    table = _with("surfaces.work_of_adhesion", _DELETE)
    resolved = resolve_scene(table=table, params=str(pset))
    assert resolved.scene.surfaces.work_of_adhesion == 0.3
    assert resolved.sources["surfaces.work_of_adhesion"] == "params:mine"
    assert resolved.sources["environment.gravity"] == "default"


def test_command_line_params_replace_the_scenes_set(tmp_path):
    scene_file = ROOT / "inputs" / "scenes" / "hertz_roller.toml"
    alt = tmp_path / "soft.toml"
    origin = "".join(f'"surfaces.{side}.{k}" = {{ kind = "chosen", reason = "a soft test material" }}\n'
                     for side in ("body", "substrate") for k in ("youngs_modulus", "poisson_ratio"))
    alt.write_text("[meta.origin]\n" + origin + "[surfaces.body]\nyoungs_modulus = 1e10\npoisson_ratio = 0.3\n"
                   "[surfaces.substrate]\nyoungs_modulus = 1e10\npoisson_ratio = 0.3\n")
    resolved = resolve_scene(scene_file, params=str(alt))
    assert resolved.scene.surfaces.body.youngs_modulus == 1e10
    assert resolved.params_file == str(alt)


def test_params_set_cannot_carry_unknown_keys(tmp_path):
    pset = tmp_path / "bad.toml"
    pset.write_text("[surfaces]\nstickiness = 3\n")
    with pytest.raises(SceneError, match="surfaces.stickiness"):
        resolve_scene(table=GOOD, params=str(pset))


def test_missing_params_set_lists_the_available_ones():
    with pytest.raises(SceneError, match="available: .*silicon"):
        resolve_scene(table=GOOD, params="no_such_set")


def test_invalid_scene_exits_nonzero_with_one_message_and_writes_nothing(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "inputs" / "scenes" / "hertz_roller.toml").read_text()
                   .replace("radius = 5e-6", "radius = -5e-6"))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "calibration.cli", "impact", str(bad), "--out", str(out)],
                          capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 2
    assert "body.radius = -5e-06" in proc.stderr and ">= 1e-09" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()
    assert not any(tmp_path.glob(".out.tmp-*"))


def test_broken_toml_is_reported_with_the_file():
    with pytest.raises(SceneError, match="not valid TOML"):
        p = ROOT / "tests" / "_broken.toml"
        try:
            p.write_text("release_height = = 3")
            resolve_scene(p)
        finally:
            p.unlink()


def test_every_shipped_scene_is_valid():
    scenes = sorted((ROOT / "inputs" / "scenes").glob("*.toml"))
    assert scenes
    for path in scenes:
        resolve_scene(path)


def test_docs_scenes_md_carries_the_current_schema_table():
    text = (ROOT / "docs" / "scenes.md").read_text()
    assert schema_markdown() in text, "regenerate with: python -m continuum.schema"


def test_overrides_win_and_are_recorded_and_validated():
    scene_file = ROOT / "inputs" / "scenes" / "hertz_roller.toml"
    resolved = resolve_scene(scene_file, overrides={"release_height": 50e-9}, override_label="case sigma3")
    assert resolved.scene.release_height == 50e-9
    assert resolved.sources["release_height"] == "case sigma3"
    with pytest.raises(SceneError) as err:
        resolve_scene(scene_file, overrides={"release_height": -1.0})
    assert err.value.key == "release_height"
    with pytest.raises(SceneError, match="unknown key"):
        resolve_scene(scene_file, overrides={"body.colour": 1})
