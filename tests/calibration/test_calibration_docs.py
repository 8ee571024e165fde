"""docs/calibration.md's table "What MD measures and where it goes" names, for every scene key the calibration sets
from MD, the recipe calibration.mdset.MAPPING reads it from (and the fallback recipe where there is one), so the
page cannot go on describing a mapping the code has left."""
from __future__ import annotations

import re
from pathlib import Path

from calibration.mdset import MAPPING

DOC = Path(__file__).resolve().parents[2] / "docs" / "calibration.md"


def _table() -> dict[str, tuple[set[str], str]]:
    """scene key -> (recipes named in its row's recipe cell, the quantity cell)."""
    text = DOC.read_text()
    section = text.split("## What MD measures and where it goes", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or not cells[0].startswith("`surfaces") and not cells[0].startswith("`menisci"):
            continue
        for key in re.findall(r"`([a-z_.]+)`", cells[0]):
            rows[key] = (set(re.findall(r"`([a-z_0-9]+)`", cells[1])), cells[2])
    return rows


def test_every_mapped_key_has_a_row_naming_its_recipe_and_fallback():
    rows = _table()
    assert set(rows) == {s.key for s in MAPPING}
    for src in MAPPING:
        recipes, _ = rows[src.key]
        want = {src.recipe} | ({src.fallback.recipe} if src.fallback else set())
        assert recipes == want, (src.key, recipes, want)
