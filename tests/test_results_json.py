"""result.json text (continuum.results.dumps): the values json.dumps(indent=2) would write, long lists of numbers
on one line. A reader sees the same JSON; only the whitespace differs."""
import json
import math
from pathlib import Path

import numpy as np

from continuum.results import _clean, _json_default, dumps


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
