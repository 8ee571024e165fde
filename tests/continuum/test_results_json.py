"""result.json text (continuum.output.results.dumps): the values json.dumps(indent=2) would write, long lists of numbers
on one line. A reader sees the same JSON; only the whitespace differs."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from continuum.output.results import (
    PROFILES_FILE,
    SCHEMA_VERSION,
    ResultSchemaError,
    _clean,
    _json_default,
    dumps,
    load_result,
    write_result_files,
)


def _reference(data):
    return json.loads(json.dumps(_clean(data), indent=2, default=_json_default, allow_nan=False))


def test_dumps_keeps_every_value_of_a_result_like_record():
    profile = {"x": np.linspace(-1e-7, 1e-7, 257), "pressure": np.cos(np.linspace(0, 3, 257)) * 1e6,
               "count": np.arange(12)}
    data = {"schema_version": "1.0", "n_bounces": 2, "stuck": False, "status": "rest", "empty": {}, "none": [],
            "bounces": [{"index": 0, "duration": 1.5e-5, "rebound_height": None, "energy_lost": float("nan"),
                         "profiles": {"max_approach": profile}}, {"index": 1, "duration": np.float64(1.2e-5)}],
            "heights": [1e-9 * k for k in range(20)], "short": [1, 2.5], "nested": [[1.0] * 9, [2.0]],
            "path": Path("/tmp/x"), "flags": [True] * 9, "mixed": [1.0] * 8 + ["a"], "np_int": np.int64(7)}
    assert json.loads(dumps(data)) == _reference(data)


def test_long_number_lists_are_on_one_line_and_the_rest_is_indented():
    text = dumps({"a": list(range(10)), "b": {"c": [1, 2]}})
    assert '"a": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]' in text
    assert text.startswith('{\n  "a"') and '"c": [\n      1,\n      2\n    ]' in text


def test_non_finite_numbers_become_null():
    values = json.loads(dumps({"v": np.array([1.0, np.nan, np.inf] * 4), "w": [math.inf] + [0.0] * 9}))
    assert values["v"][:3] == [1.0, None, None] and values["w"][0] is None


def _profiled_record():
    x = np.linspace(-1e-7, 1e-7, 257)
    bounces = [{"index": k, "duration": 1e-5 * (k + 1),
                "profiles": {"max_approach": {"t": 1e-4 * k, "gap": -1e-9, "force": 1e-6, "x": x,
                                              "pressure": np.cos(x * 1e7 + k) * 1e6, "short": [0.5, 1.0]},
                             "pull_off": {"t": 2e-4, "gap": 1e-10, "force": -1e-9, "x": x.tolist(),
                                          "pressure": (np.sin(x * 1e7) * 1e5).tolist()}}} for k in range(3)]
    bounces.append({"index": 3, "duration": None, "profiles": None})
    return {"schema_version": SCHEMA_VERSION, "n_bounces": 4, "bounces": bounces}


def test_profiles_go_to_the_npz_and_come_back_exactly(tmp_path):
    record = _profiled_record()
    write_result_files(tmp_path, record)
    text = (tmp_path / "result.json").read_text()
    stored = json.loads(text)
    assert len(text) < 5000                                    # 12 arrays of 257 floats would be ~60 kB
    prof = stored["bounces"][1]["profiles"]["max_approach"]
    assert prof["arrays_file"] == PROFILES_FILE and prof["array_fields"] == ["x", "pressure", "short"]
    assert prof["t"] == 1e-4 and "pressure" not in prof
    back = load_result(tmp_path)
    for k in range(3):
        for instant in ("max_approach", "pull_off"):
            want, got = record["bounces"][k]["profiles"][instant], back["bounces"][k]["profiles"][instant]
            assert set(got) == set(want)
            for field in set(want) - {"t", "gap", "force"}:
                assert np.array_equal(np.asarray(got[field]), np.asarray(want[field]))   # float64 both ways
            assert got["t"] == want["t"] and got["force"] == want["force"]
    assert back["bounces"][3]["profiles"] is None
    assert isinstance(record["bounces"][0]["profiles"]["max_approach"]["x"], np.ndarray)   # caller's record kept


def test_a_run_without_profiles_writes_no_npz_and_a_schema_1_folder_still_reads(tmp_path):
    write_result_files(tmp_path, {"schema_version": SCHEMA_VERSION, "bounces": [{"index": 0, "profiles": None}]})
    assert not (tmp_path / PROFILES_FILE).exists()
    old = tmp_path / "old"
    old.mkdir()
    inline = {"schema_version": "1.0", "bounces": [{"index": 0, "profiles": {"max_approach": {"x": [0.0] * 9}}}]}
    (old / "result.json").write_text(json.dumps(inline))
    assert load_result(old)["bounces"][0]["profiles"]["max_approach"]["x"] == [0.0] * 9


def test_a_missing_profiles_file_is_named_in_one_line(tmp_path):
    write_result_files(tmp_path, _profiled_record())
    (tmp_path / PROFILES_FILE).unlink()
    with pytest.raises(ResultSchemaError, match=f"{PROFILES_FILE}.*missing"):
        load_result(tmp_path)
