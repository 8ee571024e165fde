"""nanoimpact.data and nanoimpact.provenance: names found in the user folder first, new sets written only
into a source checkout or the user's folders, never into an installed package; git asked only in a checkout."""
from __future__ import annotations

from pathlib import Path

import pytest

from nanoimpact import data, provenance
from nanoimpact.errors import DataNotFound

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _no_user_root(monkeypatch):
    monkeypatch.delenv(data.ENV_VAR, raising=False)
    data.set_user_root(None)
    yield
    data.set_user_root(None)


def test_shipped_names_are_found_by_name_and_paths_must_exist(tmp_path):
    assert data.find("scenes", "hertz_roller").name == "hertz_roller.toml"
    with pytest.raises(DataNotFound) as info:
        data.find("scenes", "no_such_scene")
    assert "hertz_roller" in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(DataNotFound):
        data.find("params", str(tmp_path / "missing.toml"))


def test_user_folder_is_searched_first_and_written_to(tmp_path, monkeypatch):
    (tmp_path / "params").mkdir()
    (tmp_path / "params" / "paper.toml").write_text("# a user's own paper set\n")
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path))
    assert data.find("params", "paper") == tmp_path / "params" / "paper.toml"
    assert data.writable_root() == tmp_path


def test_checkout_writes_into_inputs_but_an_installed_copy_never_does(tmp_path, monkeypatch):
    assert provenance.source_checkout() == ROOT
    assert data.writable_root() == ROOT / "inputs"
    # an installed copy (wheel, --target or --user install): no pyproject.toml of ours above the packages
    monkeypatch.setattr(data, "shipped_root", lambda: tmp_path / "site" / "nanoimpact" / "inputs")
    monkeypatch.setattr(data, "source_checkout", lambda: None)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "xdg"))
    assert data.writable_root() == tmp_path / "xdg" / "nanoimpact"


def test_git_commit_is_not_read_outside_a_source_checkout(monkeypatch):
    monkeypatch.setattr(provenance, "source_checkout", lambda: None)
    assert provenance.git_commit() is None
