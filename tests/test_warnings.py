"""Results warn when the elastic model's assumptions fail: yield onset, too few summits."""
from pathlib import Path

from continuum.impact import run_impact
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parent.parent
ROLLER = ROOT / "inputs" / "scenes" / "hertz_roller.toml"


def test_hertz_roller_warns_when_peak_pressure_passes_tresca_onset():
    # the paper roller's Hertz peak pressure is ~18 MPa: a 5 MPa yield strength must trigger the warning
    result, _ = run_impact(resolve_scene(ROLLER, overrides={"surfaces.substrate.yield_strength": 5e6,
                                                            "numerics.max_bounces": 1}))
    assert any("Tresca" in w or "von Mises" in w for w in result["warnings"])
    result, _ = run_impact(resolve_scene(ROLLER, overrides={"surfaces.substrate.yield_strength": 1e9,
                                                            "numerics.max_bounces": 1}))
    assert result["warnings"] == []
