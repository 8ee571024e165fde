"""Provenance of the validation data (benchmarks/validation): every data set has a full citation and
every number says where in its source it is and whether it was printed or read from a figure; every
swept band states its reason."""
from __future__ import annotations

import csv
import tomllib
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent.parent / "benchmarks" / "validation"
HOW = {"printed", "printed as a bound", "read from figure"}

with open(HERE / "datasets.toml", "rb") as fh:
    DATASETS = {k: v for k, v in tomllib.load(fh).items() if isinstance(v, dict) and "file" in v}


def test_there_are_at_least_three_data_sets():
    assert len(DATASETS) >= 3


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_data_set_is_cited_and_every_number_traced(name):
    ds = DATASETS[name]
    for key in ("citation", "doi", "where", "title", "kind"):
        assert ds.get(key), f"{name}: {key} missing"
    with open(HERE / ds["file"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert rows, f"{name}: no rows"
    for row in rows:
        assert row["where_in_source"].strip(), f"{name}: a row without where_in_source"
        assert row["how_obtained"] in HOW, f"{name}: how_obtained = {row['how_obtained']!r}"


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_bands_and_constants_say_why(name):
    ds = DATASETS[name]
    for key, value in ds.get("bands", {}).items():
        if not key.endswith("_reason"):
            assert len(value) == 2 and value[0] < value[1], f"{name}: band {key} = {value}"
            assert ds["bands"].get(f"{key}_reason"), f"{name}: band {key} has no reason"
    for part in ("body", "substrate", "liquid"):
        if part in ds:
            assert ds[part].get("source"), f"{name}.{part}: constants without a source"
