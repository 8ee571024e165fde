"""`nanoimpact impact` end to end: the files, the schema, the loader, and the help of every subcommand."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from calibration.cli import main
from continuum.output.results import ResultSchemaError, load_result

ROOT = Path(__file__).resolve().parents[2]
KEYS = {"schema_version", "scene", "models", "bounces", "n_bounces", "stuck", "energy_audit", "provenance", "timing"}
BOUNCE_KEYS = {"index", "t_contact", "t_release", "duration", "v_impact", "v_rebound", "restitution",
               "peak_force", "max_penetration", "rebound_height", "energy_lost"}


@pytest.fixture(scope="module")
def jkr_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "jkr"
    assert main(["impact", str(ROOT / "inputs/scenes/jkr_sphere.toml"), "--out", str(out), "--quiet"]) == 0
    return out


def test_impact_writes_result_timeseries_and_figures(jkr_out):
    for name in ("result.json", "timeseries.csv", "height.png", "impacts.png"):
        assert (jkr_out / name).stat().st_size > 0, name
    assert not list(jkr_out.parent.glob(".jkr.tmp-*"))


def test_result_json_has_the_documented_keys_and_records_inputs(jkr_out):
    data = json.loads((jkr_out / "result.json").read_text())
    assert KEYS <= set(data)
    assert data["n_bounces"] == len(data["bounces"]) > 0
    assert BOUNCE_KEYS <= set(data["bounces"][0])
    assert data["scene"]["sources"]["surfaces.body.youngs_modulus"] == "params:silica"
    assert data["scene"]["values"]["body"]["radius"] == 5e-6
    prov = data["provenance"]
    assert len(prov["input_hash"]) == 64 and prov["numpy"] and prov["scipy"] and prov["python"]
    assert data["models"]["contact_law"]["name"] == "jkr_sphere"
    assert data["energy_audit"]["max_relative_error"] < 1e-6


def test_load_result_reads_back_and_checks_the_schema(jkr_out, tmp_path):
    result = load_result(jkr_out)
    assert result.n_bounces == result["n_bounces"]
    series = result.timeseries()
    assert series["t"].shape == series["force"].shape and series["t"].size > 100
    bad = tmp_path / "old"
    bad.mkdir()
    data = json.loads((jkr_out / "result.json").read_text())
    data["schema_version"] = "0.3"
    (bad / "result.json").write_text(json.dumps(data))
    with pytest.raises(ResultSchemaError, match="schema_version"):
        load_result(bad)
    with pytest.raises(ResultSchemaError, match="no result.json"):
        load_result(tmp_path / "nowhere")


def test_same_inputs_give_the_same_input_hash(tmp_path):
    out_a, out_b = tmp_path / "a", tmp_path / "b"
    scene = str(ROOT / "inputs/scenes/hertz_roller_constant_k.toml")
    main(["impact", scene, "--out", str(out_a), "--quiet"])
    main(["impact", scene, "--out", str(out_b), "--quiet", "--fidelity", "fast"])
    a, b = load_result(out_a), load_result(out_b)
    main(["impact", scene, "--out", str(out_b), "--quiet"])
    c = load_result(out_b)
    assert a.provenance["input_hash"] == c.provenance["input_hash"] != b.provenance["input_hash"]
    assert b.scene["sources"]["numerics.fidelity"] == "command line"


@pytest.mark.parametrize("sub", [[], ["impact"], ["doctor"]])
def test_every_subcommand_has_help(sub):
    proc = subprocess.run([sys.executable, "-m", "calibration.cli", *sub, "--help"], capture_output=True,
                          text=True, cwd=ROOT)
    assert proc.returncode == 0 and "usage" in proc.stdout.lower()


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "nanoimpact"   # the venv's bin/, whether or not it is on PATH
    proc = subprocess.run([str(script), "--help"], capture_output=True, text=True)
    assert proc.returncode == 0 and "impact" in proc.stdout
