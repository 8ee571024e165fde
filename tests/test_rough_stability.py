"""Rough impacts are stable and honest across the parameter ranges users sweep (issues 3 and 12).

A coarse grid over sigma 0.1-100 nm, release height 1 nm-10 um, work of adhesion 0-1 J/m^2 and
summit E* 1 MPa-1 TPa, JKR summits on a rigid substrate, each run bounded (3 impacts, `standard`
preset): every run ends with finite numbers and an energy audit within tolerance (relative to the
run's energy turnover: where adhesion releases far more energy than the impact brings, table errors
scale with that energy), or is refused with a one-line `SceneError` that names the key, the value
and the way out (the averaged model's range, or its tables' memory and time bounds; docs/model.md,
"Bounded cost"). Nothing else may escape: no MemoryError, no solver traceback.
Every point with sigma >= 1 nm, release >= 10 nm, 5 GPa <= E* <= 200 GPa and work of adhesion
<= 0.5 J/m^2 must run, not be refused. Automatic model choices at the extremes, the memory and time
bounds themselves: tests/test_extremes.py.
"""
import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from continuum.impact import run_impact
from continuum.scene import SceneError, resolve_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "inputs" / "scenes" / "rough_silica.toml"
SIGMAS = (0.1e-9, 5e-9, 100e-9)
RELEASES = (1e-9, 100e-9, 10e-6)
WORKS = (0.0, 0.1, 1.0)
MODULI = (1e6, 20e9, 1e12)
AUDIT_TOLERANCE = 1e-3          # `standard` preset, relative to the run's energy turnover (see docs/model.md);
                                # `standard` reaches ~1e-6 of the impact energy (tests/test_rough_laws.py)


def must_run(sigma, release, work, modulus):
    return sigma >= 1e-9 and release >= 10e-9 and 5e9 <= modulus <= 200e9 and work <= 0.5


@pytest.mark.parametrize("sigma,release,work,modulus", list(itertools.product(SIGMAS, RELEASES, WORKS, MODULI)))
def test_rough_impact_runs_or_refuses_clearly(sigma, release, work, modulus):
    overrides = {"surfaces.roughness.sigma": sigma, "release_height": release,
                 "surfaces.work_of_adhesion": work, "surfaces.roughness.summit_modulus": modulus,
                 "physics.adhesion_law": "jkr" if work > 0 else "none", "physics.half_space": "off",
                 "numerics.fidelity": "standard", "numerics.max_bounces": 3, "numerics.max_time": 1.0}
    try:
        result, trace = run_impact(resolve_scene(SCENE, overrides=overrides, override_label="stability sweep"))
    except SceneError as exc:           # a refusal says why in one line, naming the key and the way out
        assert not must_run(sigma, release, work, modulus), f"refused inside the required range: {exc}"
        message = str(exc)
        assert "\n" not in message and message.startswith("surfaces.roughness.sigma = ")
        assert "use " in message
        return
    for key in ("t", "gap", "velocity", "force", "energy"):
        assert np.all(np.isfinite(trace[key])), key
    assert result["n_bounces"] >= 1
    audit = result["energy_audit"]["max_error_over_turnover"]
    assert math.isfinite(audit) and audit < AUDIT_TOLERANCE
