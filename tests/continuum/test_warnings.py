"""Results warn when the elastic model's assumptions fail: yield onset, too few summits."""
from pathlib import Path

from continuum.dynamics.impact import run_impact
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parents[2]
ROLLER = ROOT / "inputs" / "scenes" / "hertz_roller.toml"


def test_hertz_roller_warns_when_peak_pressure_passes_tresca_onset():
    # the paper roller's Hertz peak pressure is ~18 MPa: a 5 MPa yield strength must trigger the warning
    result = run_impact(resolve_scene(ROLLER, overrides={"surfaces.substrate.yield_strength": 5e6,
                                                            "numerics.max_bounces": 1})).to_dict()
    assert any("Tresca" in w or "von Mises" in w for w in result["warnings"])
    result = run_impact(resolve_scene(ROLLER, overrides={"surfaces.substrate.yield_strength": 1e9,
                                                            "numerics.max_bounces": 1})).to_dict()
    assert result["warnings"] == []


def test_rough_contact_warns_when_the_plasticity_index_says_summits_yield():
    # psi = (E*/H) sqrt(sigma/beta): paper set, summit E* 10 GPa, sigma 6 nm, beta 0.2 um -> psi = 1.73 at H = 1 GPa
    scene = ROOT / "inputs" / "scenes" / "rough_silica.toml"
    # the mean field: the warning comes from the regime, which every mode derives alike; an ensemble of 64
    # Thornton-Ning JKR members (Python stepper) would cost ~100 s for the same assertion
    base = {"numerics.max_bounces": 1, "physics.half_space": "off", "numerics.fidelity": "fast",
            "surfaces.roughness.mode": "mean_field"}
    result = run_impact(resolve_scene(scene, overrides={**base, "surfaces.substrate.hardness": 1e9})).to_dict()
    assert any("plasticity index" in w and "most summits yield" in w for w in result["warnings"])
    assert result["models"]["contact_law"]["regime"]["plasticity_index"] > 1
    result = run_impact(resolve_scene(scene, overrides={**base, "surfaces.substrate.hardness": 1e11})).to_dict()
    assert not any("plasticity index" in w for w in result["warnings"])
