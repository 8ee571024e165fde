"""The Python front door: `continuum.run_scene` and the typed `ImpactResult`; docs/api.md runs as written."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from continuum import ImpactResult, load_scene, read_result, run_scene
from continuum.scene import SceneError

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def hertz() -> ImpactResult:
    return run_scene("hertz_roller", overrides={"numerics.max_bounces": 2})


def test_run_scene_by_name_gives_typed_bounces_matching_the_record(hertz):
    assert hertz.n_bounces == 2 == hertz.record["n_bounces"]
    for typed, raw in zip(hertz.bounces, hertz.record["bounces"]):
        assert typed.restitution == raw["restitution"] and typed.peak_force == raw["peak_force"]
    assert hertz.models["adhesion"].used is False
    assert hertz.models["adhesion"].decided_by == "scene"
    assert "tabor_parameter" in hertz.models["adhesion"].numbers
    assert hertz.regimes["tabor_parameter"] == hertz.record["models"]["regimes"]["tabor_parameter"]


def test_elastic_hertz_roller_rebounds_with_unit_restitution(hertz):
    """No adhesion, no dissipation: e = 1 to the integrator's tolerance (rtol of the scene), and the
    energy books close to the same order."""
    rtol = hertz.record["scene"]["si"]["numerics"]["rtol"]
    for b in hertz.bounces:
        assert b.restitution == pytest.approx(1.0, abs=1e3 * rtol)
    assert hertz.energy_audit.max_relative_error < 1e3 * rtol


def test_result_writes_and_reads_back_the_same_bounces(hertz, tmp_path):
    folder = hertz.write(tmp_path / "run")
    again = read_result(folder)
    assert again.bounces == hertz.bounces
    assert again.timeseries()["t"].shape == hertz.timeseries()["t"].shape
    assert {"result.json", "timeseries.csv", "height.png", "impacts.png"} <= {p.name for p in folder.iterdir()}


def test_load_scene_accepts_a_table_and_overrides_win():
    table = {"name": "t", "params": "paper"}
    resolved = load_scene("hertz_roller", overrides={"body.radius": 2e-3})
    assert resolved.scene.body.radius == 2e-3
    with pytest.raises(SceneError):
        load_scene(table)              # a table without the required keys is refused with a SceneError


def test_bad_override_is_one_line_naming_the_key():
    with pytest.raises(SceneError) as info:
        run_scene("hertz_roller", overrides={"body.radius": -1.0})
    message = str(info.value)
    assert "body.radius" in message and "-1.0" in message and "\n" not in message


def _python_blocks(markdown: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", markdown, flags=re.S)


def test_docs_api_examples_run_as_written(capsys):
    blocks = _python_blocks((ROOT / "docs" / "api.md").read_text())
    assert len(blocks) >= 3
    for code in blocks:
        exec(compile(code, "docs/api.md", "exec"), {"__name__": "docs_api"})
    out = capsys.readouterr().out
    assert "max_bounces 3" in out and "body.radius" in out
