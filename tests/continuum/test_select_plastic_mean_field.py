"""`select_law` with plastic summits in the mean field: the plastic law needs no tables, so the elastic law it
replaces is neither built nor sized (issue 42). A drop whose elastic footprint tables are refused for their cost
runs the plastic mean field; the record keeps the elastic law's datum, regime numbers and summit law."""
from __future__ import annotations

from pathlib import Path

import pytest

from continuum.model.regime import first_impact_speed, regime_of
from continuum.model.select import rough_law, select_law
from continuum.scene import SceneError, resolve_scene

SCENE = Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml"


def _scene(plasticity, release_height=None):
    overrides = {"physics.plasticity": plasticity, "surfaces.roughness.mode": "mean_field"}
    if release_height is not None:
        overrides["release_height"] = release_height
    scene = resolve_scene(SCENE, params="calibrated", overrides=overrides).scene
    speed = first_impact_speed(scene)
    return scene, regime_of(scene, speed)


def test_plastic_mean_field_runs_where_the_elastic_tables_are_refused():
    scene, regime = _scene("off", 100e-6)
    with pytest.raises(SceneError, match="footprint tables"):
        select_law(scene, regime.speed, regime=regime)
    scene, regime = _scene("auto", 100e-6)
    law, models = select_law(scene, regime.speed, regime=regime)
    assert law.name == "rough_roller_gw_plastic_rigid"
    assert models["contact_law"]["table"]["used"] is False


def test_the_record_without_tables_is_the_elastic_laws():
    scene, regime = _scene("off")
    law, full = rough_law(scene, regime=regime)
    none, bare = rough_law(scene, regime=regime, tables=False)
    assert law is not None and none is None
    for key in ("datum", "regime", "summit_law", "mode"):
        assert bare[key] == full[key], key
