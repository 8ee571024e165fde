"""One input engine (nanoimpact.fields): scenes, MD recipes and calibration recipes declare each key once, and
that declaration gives the loader's check, the docs tables and the JSON Schemas in inputs/schema/.

The schemas are checked against every shipped input file with the `jsonschema` package (a test dependency),
and against the loaders: for every declared bound, a value just outside it is refused by both the schema and
the loader, and the value at a closed bound is accepted by both.
"""
from __future__ import annotations

import json
import tomllib
from dataclasses import replace
from pathlib import Path

import jsonschema
import pytest

from calibration import schemas
from calibration.pipeline import FIELDS as CALIBRATION_FIELDS
from continuum.schema import FIELDS as SCENE_FIELDS
from md.recipe import FIELDS as RECIPE_FIELDS
from md.recipe import RecipeError
from nanoimpact.errors import InputError
from nanoimpact.fields import REQUIRED, Field, json_schema

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"


def _validator(name: str):
    schema = json.loads((INPUTS / "schema" / f"{name}.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_the_committed_schemas_are_the_declarations():
    assert schemas.stale() == [], "regenerate with: python -m calibration.schemas"


@pytest.mark.parametrize("name, files", [
    ("scene", sorted((INPUTS / "scenes").glob("*.toml")) + sorted((INPUTS / "params").glob("*.toml"))),
    ("md-recipe", sorted((INPUTS / "md").glob("*.toml"))),
    ("calibration", sorted((INPUTS / "calibration").glob("*.toml"))),
])
def test_every_shipped_file_satisfies_its_schema(name, files):
    assert files
    validator = _validator(name)
    for path in files:
        doc = tomllib.loads(path.read_text())
        errors = [f"{'.'.join(map(str, e.path))}: {e.message}" for e in validator.iter_errors(doc)]
        assert not errors, (path.name, errors[:3])
        assert not validator.is_valid({**doc, "no_such_key": 1})      # unknown keys are refused, as the loaders do


def _outside(f: Field) -> list:
    """Values just outside each declared bound (and of the wrong kind)."""
    bad = []
    if f.kind in (int, float):
        if f.low is not None:
            bad.append(f.low if f.low_open else (f.low - 1 if f.kind is int else f.low - max(abs(f.low), 1.0) * 1e-6))
        if f.high is not None:
            bad.append(f.high if f.high_open
                       else (f.high + 1 if f.kind is int else f.high + max(abs(f.high), 1.0) * 1e-6))
        bad.append("1")
    if f.kind is int:
        bad.append(2.5)
    if f.kind is str and f.choices:
        bad.append("not-a-choice")
    if f.kind is bool:
        bad.append(1)
    return bad


def _inside(f: Field) -> list:
    good = []
    if f.kind in (int, float):
        good += [b for b, is_open in ((f.low, f.low_open), (f.high, f.high_open)) if b is not None and not is_open]
    if f.kind is str and f.choices:
        good += list(f.choices)
    return good


def _one(f: Field, value) -> dict:
    """A document holding `value` at the field's own path (nested tables from the dotted key)."""
    doc: dict = {}
    node = doc
    *parents, leaf = f.key.split(".")
    for p in parents:
        node = node.setdefault(p, {})
    node[leaf] = value
    return doc


@pytest.mark.parametrize("fields, error", [(SCENE_FIELDS, InputError), (CALIBRATION_FIELDS, InputError)],
                         ids=["scene", "calibration"])
def test_schema_and_loader_agree_at_every_bound(fields, error):
    """One declaration, two readers: each value outside a bound is refused by the field's check and by the
    JSON Schema; each closed bound and each choice is accepted by both."""
    schema = json_schema(((f.key, f) for f in fields), title="t", required=False)
    validator = jsonschema.Draft202012Validator(schema)
    checked = 0
    for f in fields:
        if f.kind is list:
            continue
        for value in _outside(f):
            with pytest.raises(error):
                f.check(value, "test")
            assert not validator.is_valid(_one(f, value)), (f.key, value)
            checked += 1
        for value in _inside(f):
            assert f.check(value, "test") == value
            assert validator.is_valid(_one(f, value)), (f.key, value)
    assert checked > len(fields)


def test_recipe_fields_agree_with_the_recipe_schema_in_every_section():
    """MD recipe keys are written in [system] or [fidelity.<name>]: a bound violated there is refused by the
    recipe schema, and by the field's check with RecipeError."""
    validator = _validator("md-recipe")
    checked = 0
    for f in RECIPE_FIELDS:
        if f.kind is list or f.section == "top":
            continue
        where = ["system"] if f.section == "system" else (["fidelity", "quick"] if f.section == "fidelity"
                                                          else ["system", "fidelity", "quick"])
        for value in _outside(f):
            with pytest.raises(RecipeError):
                f.check(value, "test", error=RecipeError)
            doc = {"workflow": f.workflows[0]}
            node = doc
            for part in where[:-1] if where[-1] == "quick" else where:
                node = node.setdefault(part, {})
            if where[-1] == "quick":
                node = node.setdefault("quick", {})
            node[f.key] = value
            assert not validator.is_valid(doc), (f.key, where, value)
            checked += 1
    assert checked > 50


def test_a_field_check_names_key_value_and_range_in_one_line():
    f = Field("body.radius", float, "m", "radius", REQUIRED, low=1e-9, high=1.0)
    with pytest.raises(InputError) as info:
        f.check(-1, "scene.toml")
    assert str(info.value).splitlines() == [str(info.value)]
    assert "body.radius = -1" in str(info.value) and ">= 1e-09 and <= 1 m" in str(info.value)
    assert f.check(1) == 1.0 and isinstance(f.check(1), float)        # integers widen for real keys
    with pytest.raises(InputError, match="must be finite"):
        f.check(float("nan"))
    lst = Field("sets", list, "", "sets", [], item=str, empty_ok=True)
    assert lst.check([]) == [] and "any number of" in lst.allowed()
    with pytest.raises(InputError, match=r"sets\[1\] = 3"):
        lst.check(["a", 3])
    with pytest.raises(InputError):
        replace(lst, empty_ok=False).check([])
    pair = Field("surfaces", list, "", "", item=str, choices=("silica", "ots"), length=(2,))
    assert pair.allowed() == "a list of 2 items, each one of 'silica', 'ots'"
    with pytest.raises(InputError):
        pair.check(["silica"])


# ---------------------------------------------------------------------- dataclasses from the declarations
def test_a_generated_dataclass_follows_its_declarations():
    """Type, default, requiredness, unit and doc of each attribute come from the key's declaration."""
    import dataclasses

    from nanoimpact.fields import Resolved, frozen_dataclass

    decl = [("radius", Field("body.radius", float, "m", "Radius.", REQUIRED, low=0.0)),
            ("length", Field("body.length", float, "m", "Length.", None)),
            ("count", Field("body.count", int, "1", "How many.", 3)),
            ("mass", Resolved(float, "kg", "Resolved mass.", key="body.mass"))]
    cls = frozen_dataclass("Thing", decl, doc="A thing.", module=__name__)
    fields = {f.name: f for f in dataclasses.fields(cls)}
    assert list(fields) == ["radius", "length", "count", "mass"]
    assert fields["radius"].type is float and fields["length"].type == (float | None)
    assert fields["count"].default == 3 and fields["length"].default is None
    assert fields["radius"].default is dataclasses.MISSING and fields["mass"].default is dataclasses.MISSING
    assert fields["radius"].metadata["key"] == "body.radius" and fields["mass"].metadata["unit"] == "kg"
    assert "radius [m], from ``body.radius``: Radius." in cls.__doc__
    thing = cls(radius=1.0, mass=2.0)
    assert (thing.length, thing.count) == (None, 3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        thing.radius = 2.0
    with pytest.raises(TypeError):
        cls(1.0, 2.0)                      # keyword-only: no silent mix-up of two floats
    with pytest.raises(TypeError):
        cls(radius=1.0)                    # a required key (and a resolved value) must be given


def test_every_scene_key_lands_in_a_scene_dataclass():
    """One declaration per key: each scene key is an attribute of exactly one generated dataclass (read by
    `_build` from the key), or folded into another value as FOLDED_KEYS says; no attribute names a key that
    is not declared."""
    import dataclasses

    from continuum import scene

    classes = (scene.Scene, scene.Body, scene.Surfaces, scene.Material, scene.Roughness, scene.SAM,
               scene.Environment, scene.Physics, scene.Menisci, scene.Numerics)
    homes: dict[str, list[str]] = {}
    for cls in classes:
        for f in dataclasses.fields(cls):
            if f.metadata.get("key"):
                homes.setdefault(f.metadata["key"], []).append(f"{cls.__name__}.{f.name}")
    declared = {f.path for f in SCENE_FIELDS}
    # Material holds the body's keys; the substrate's same-named keys land in the same attributes
    for key in ("youngs_modulus", "poisson_ratio", "contact_angle", "work_of_adhesion_sl"):
        homes[f"surfaces.substrate.{key}"] = [f"Material.{key}"]
    assert set(homes) <= declared, set(homes) - declared
    missing = declared - set(homes) - set(scene.FOLDED_KEYS)
    assert not missing, f"scene keys with no dataclass attribute: {sorted(missing)}"
    assert all(len(h) == 1 for h in homes.values()), {k: h for k, h in homes.items() if len(h) > 1}


def test_scene_dataclass_attributes_are_in_si_units():
    """Angles are declared in degrees and held in radians; every other unit is the declaration's."""
    import dataclasses
    import math

    from continuum import scene
    from continuum.schema import FIELD_BY_PATH

    for f in dataclasses.fields(scene.Material) + dataclasses.fields(scene.SAM):
        decl = FIELD_BY_PATH.get(f.metadata["key"])
        if decl is not None and decl.degrees:
            assert f.metadata["unit"] == "rad"
    resolved = scene.resolve_scene("rough_silica", params="paper",
                                   overrides={"surfaces.body.contact_angle": 30.0})
    assert resolved.scene.surfaces.body.contact_angle == pytest.approx(math.radians(30.0), rel=1e-15)


@pytest.mark.parametrize("path", sorted((INPUTS / "md").glob("*.toml")), ids=lambda p: p.stem)
def test_md_settings_dataclass_holds_every_resolved_setting(path):
    """A recipe's resolved settings at every fidelity fill its workflow's generated settings dataclass exactly:
    no key without an attribute, no attribute without a key of that workflow."""
    import dataclasses
    import pickle

    from md.recipe import FIDELITIES, load_recipe, settings_class

    recipe = load_recipe(path)
    cls = settings_class(recipe.workflow)
    declared = {f.key for f in RECIPE_FIELDS if f.section != "top" and recipe.workflow in f.workflows}
    assert {f.name for f in dataclasses.fields(cls)} == declared
    for fidelity in FIDELITIES:
        typed = recipe.typed_settings(fidelity)
        assert dataclasses.asdict(typed) == recipe.settings(fidelity)
        assert pickle.loads(pickle.dumps(typed)) == typed
