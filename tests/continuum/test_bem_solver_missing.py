"""A scene asking for the summit cutoff the boundary-element reference measures (surfaces.roughness.summit_cutoff_from
= "bem") where Tamaas cannot be imported: one line on stderr naming the key, the value and what it needs, exit 2,
nothing written (no traceback from the first solve). Tamaas is made unimportable by a None entry in sys.modules."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import continuum.rough.cutoff_match as cm
from calibration.cli import main

ROOT = Path(__file__).resolve().parents[2]

_SCENE = (ROOT / "inputs" / "scenes" / "rough_synthetic.toml").read_text()
_PATCH = {"rms_height = 6e-9": "rms_height = 1.2e-9", "short_cutoff = 0.3125e-6": "short_cutoff = 0.03125e-6",
          "long_cutoff = 1.25e-6": "long_cutoff = 0.125e-6", "size = 5e-6": "size = 0.25e-6",
          "grid_points = 128": "grid_points = 64",
          'summit_route = "direct"': 'summit_route = "direct"\nsummit_cutoff_from = "bem"'}


def _scene(tmp_path: Path) -> Path:
    text = _SCENE
    for old, new in _PATCH.items():
        assert old in text, old                  # the shipped scene still has the line this test edits
        text = text.replace(old, new)
    path = tmp_path / "bem_cutoff.toml"
    path.write_text(text)
    return path


def test_bem_cutoff_without_tamaas_is_one_input_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tamaas", None)          # `import tamaas` raises ImportError
    monkeypatch.setenv("NANOIMPACT_CACHE", str(tmp_path / "cache"))   # no cached match to fall back on
    out = tmp_path / "out"
    code = main(["impact", str(_scene(tmp_path)), "--params", "calibrated", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "surfaces.roughness.summit_cutoff_from" in err and "'bem'" in err and "tamaas" in err.lower()
    assert not out.exists() and not (tmp_path / "cache").exists()


def test_bem_cutoff_asks_for_the_solver_only_when_it_runs(tmp_path, monkeypatch):
    """The check sits after the cache lookup: a cached match needs no solver (the refusal is not a blanket one)."""
    calls = []
    monkeypatch.setattr(cm, "require_solver", lambda key, value: calls.append((key, value)))
    monkeypatch.setattr(cm, "bem_cycle", lambda *a, **k: (_ for _ in ()).throw(RuntimeError("stop after check")))
    h = np.random.default_rng(0).normal(size=(16, 16)) * 1e-9
    with pytest.raises(RuntimeError, match="stop after check"):
        cm.measured_cutoff(h, 100e-9, 88.8e9, 0.192, 0.207e-9, grids=(16,), cache=tmp_path)
    assert calls == [(cm.KEY_CUTOFF_FROM, "bem")]
