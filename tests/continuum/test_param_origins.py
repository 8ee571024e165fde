"""Every value of a parameter set carries its origin ([meta.origin]: md, topography, material or chosen), and the
loader refuses a set that does not account for a value."""
from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

from continuum.origins import ORIGIN_KINDS, OriginError, check_origins
from continuum.scene import flatten, resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SETS = sorted((ROOT / "inputs" / "params").glob("*.toml"))


def _set(path: Path) -> tuple[dict, dict]:
    raw = tomllib.loads(path.read_text())
    return raw.get("meta") or {}, flatten(raw, str(path), skip=("meta",))


@pytest.mark.parametrize("path", SETS, ids=lambda p: p.stem)
def test_every_shipped_value_has_an_origin_of_a_known_kind(path):
    meta, flat = _set(path)
    origin = check_origins(meta, flat, str(path))
    assert set(origin) == set(flat)
    assert "sources" not in meta                        # one mechanism: the origin table
    for key, entry in origin.items():
        need = ORIGIN_KINDS[entry["kind"]]
        assert entry[need].strip(), key
    chosen = origin.get("surfaces.roughness.summit_modulus")
    if chosen is not None and chosen["kind"] == "chosen":
        assert len(chosen["reason"]) > 40               # says why, not just "chosen"


def test_the_calibrated_set_measures_what_the_project_can_and_declares_the_rest():
    meta, flat = _set(ROOT / "inputs" / "params" / "calibrated.toml")
    origin = meta["origin"]
    # the summits' modulus is the materials' E*: no chosen summit modulus, and the bodies' moduli are materials
    assert "surfaces.roughness.summit_modulus" not in flat
    for side in ("body", "substrate"):
        assert origin[f"surfaces.{side}.youngs_modulus"]["kind"] == "material"
    # the regime picks the law, and bridges use the wet work of adhesion: the calibrated set declares neither
    assert "physics.adhesion_law" not in flat and "menisci.solid_adhesion" not in flat
    # an md origin names the committed MD result it was read from
    mds = {k: e for k, e in origin.items() if e["kind"] == "md"}
    assert {"surfaces.work_of_adhesion", "surfaces.interaction_range", "surfaces.sam.interaction_range"} <= set(mds)
    for key, entry in mds.items():
        assert entry["run_hash"] == meta["calibration"][key]["run_hash"]
        result = ROOT / "inputs" / "md" / "results" / f"{entry['recipe']}-quick" / "result.json"
        assert json.loads(result.read_text())["run_hash"] == entry["run_hash"], key
    assert meta["replaced"]["surfaces.roughness.summit_modulus"]["base_value"] == 10e9


@pytest.mark.parametrize("path", SETS, ids=lambda p: p.stem)
def test_every_shipped_set_gives_each_materials_hardness_with_its_source(path):
    """The summits' plasticity index needs a hardness (issue 42): each partner's, a material value with its
    source, in the range nanoindentation measures for silicon and fused silica (8-13 GPa)."""
    meta, flat = _set(path)
    for side in ("body", "substrate"):
        key = f"surfaces.{side}.hardness"
        assert 8e9 <= flat[key] <= 13e9, key
        entry = meta["origin"][key]
        assert entry["kind"] == "material" and entry["source"].strip(), key


def _write(tmp_path, origin_lines: str, body: str = "[surfaces]\nwork_of_adhesion = 0.3\n") -> Path:
    path = tmp_path / "mine.toml"
    path.write_text("[meta.origin]\n" + origin_lines + body if origin_lines is not None else body)
    return path


GOOD = {"name": "g", "contact": "smooth", "release_height": 1e-7,
        "body": {"shape": "sphere", "radius": 1e-6, "mass": 1e-12},
        "surfaces": {side: {"youngs_modulus": 1e11, "poisson_ratio": 0.2} for side in ("body", "substrate")}}


@pytest.mark.parametrize("origin, key", [
    (None, "surfaces.work_of_adhesion"),                                                     # no table at all
    ('"surfaces.body.youngs_modulus" = { kind = "material", source = "x" }\n', "surfaces.work_of_adhesion"),
    ('"surfaces.work_of_adhesion" = { kind = "guessed", reason = "x" }\n', "surfaces.work_of_adhesion.kind"),
    ('"surfaces.work_of_adhesion" = { kind = "chosen" }\n', "surfaces.work_of_adhesion.reason"),
    ('"surfaces.work_of_adhesion" = { kind = "chosen", reason = " " }\n', "surfaces.work_of_adhesion.reason"),
    ('"surfaces.work_of_adhesion" = { kind = "md", recipe = "adhesion_silica" }\n',
     "surfaces.work_of_adhesion.run_hash"),
    ('"surfaces.work_of_adhesion" = { kind = "topography", file = "a.di" }\n', "surfaces.work_of_adhesion.sha256"),
    ('"surfaces.work_of_adhesion" = { kind = "material" }\n', "surfaces.work_of_adhesion.source"),
])
def test_a_value_without_a_valid_origin_is_a_one_line_error_naming_the_key(tmp_path, origin, key):
    path = _write(tmp_path, origin)
    with pytest.raises(OriginError) as err:
        resolve_scene(table=GOOD, params=str(path))
    text = str(err.value)
    assert "\n" not in text and f"{key} = " in text and str(path) in text


def test_an_origin_for_a_value_the_set_does_not_give_is_refused(tmp_path):
    path = _write(tmp_path, '"surfaces.work_of_adhesion" = { kind = "chosen", reason = "a test value" }\n'
                            '"surfaces.body.youngs_modulus" = { kind = "material", source = "x" }\n')
    with pytest.raises(OriginError, match="meta.origin.surfaces.body.youngs_modulus"):
        resolve_scene(table=GOOD, params=str(path))


def test_a_set_whose_values_all_have_origins_loads(tmp_path):
    path = _write(tmp_path, '"surfaces.work_of_adhesion" = { kind = "chosen", reason = "a test value" }\n')
    assert resolve_scene(table=GOOD, params=str(path)).scene.surfaces.work_of_adhesion == 0.3


@pytest.mark.parametrize("params, law", [("paper", "jkr"), ("calibrated", "auto"), ("silicon", "auto")])
def test_only_the_paper_set_declares_its_adhesion_law(params, law):
    for scene in ("rough_silica", "rough_ots", "wet_silica", "wet_ots"):
        resolved = resolve_scene(scene, params=params)
        assert resolved.scene.physics.adhesion_law == law
        assert resolved.sources["physics.adhesion_law"] == (f"params:{params}" if law == "jkr" else "default")
