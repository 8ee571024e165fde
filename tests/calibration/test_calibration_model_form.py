"""The model-form parts of the MD values the set carries (issue 44): W_F with and without the static TraPPE tail, z0
from the same W as dgamma, the like-for-like and rate-extrapolated pull-off validation, and the SAM layer's
thickness and unmeasured or measured Poisson ratio. Synthetic results with known answers; no LAMMPS."""
from __future__ import annotations

import math

import numpy as np
import pytest

from calibration.mdset import MAPPING, build_parameter_set
from calibration.validation import VALIDATION, like_for_like_work, pulloff_validation, rate_extrapolation
from md.analysis import MAUGIS_LJ93

OTS = next(s.recipe for s in MAPPING if s.key == "surfaces.sam.work_of_adhesion")
PULL_OTS = next(pull for pull, adh in VALIDATION if adh == OTS)


def _q(**kv):
    return {k: dict(v) for k, v in kv.items()}


def _ots(w=0.0617, tail=0.0193, out=0.0668, back=0.0565, sigma0=1.8686e8, z0_committed=3.67e-10, **extra):
    """An OTS adhesion result like the committed one: W_F the out/back mean with the static tail included, its z0
    formed with the outward W (no ``work_of_adhesion_used``)."""
    q = _q(work_of_adhesion_free_energy={"value": w, "stderr": 0.0037, "units": "J/m^2", "discretisation_error": 0.0029,
                                         "systematic_hysteresis": 0.5 * (out - back), "value_out": out,
                                         "value_back": back, "stderr_out": 0.0045, "stderr_back": 0.0058},
           dispersion_tail_work={"value": tail, "stderr": None, "units": "J/m^2"},
           peak_traction_sigma0={"value": sigma0, "stderr": 6.7e6, "units": "Pa", "discretisation_error": 3.3e6},
           interaction_range_z0={"value": z0_committed, "stderr": 3e-11, "units": "m"}, **extra)
    return {"recipe": OTS, "fidelity": "quick", "run_hash": "c" * 64, "quantities": q}


def test_w_ots_carries_half_the_static_tail_as_a_model_form_systematic():
    """W_F = 0.0617 with a 0.0193 tail: the set keeps 0.0617 (TraPPE was fitted with its tail), its stderr is
    hypot(stat, grid, half the hysteresis, half the tail), and the entry gives the value without the tail."""
    table, rows = build_parameter_set({OTS: _ots()}, "paper", "cal")
    cal = table["meta"]["calibration"]["surfaces.sam.work_of_adhesion"]
    assert table["surfaces"]["sam"]["work_of_adhesion"] == 0.0617
    assert cal["stderr"] == pytest.approx(math.hypot(0.0037, 0.0029, 0.00515, 0.00965), rel=1e-9)
    mf = cal["model_form"]
    assert mf["without_tail"] == pytest.approx(0.0617 - 0.0193) and mf["used"] == "with_tail"
    assert "Martin & Siepmann" in mf["why"]
    # a W_F without a tail (bare silica) has no such term
    bare = _ots()
    del bare["quantities"]["dispersion_tail_work"]
    cal0 = build_parameter_set({OTS: bare}, "paper", "cal")[0]["meta"]["calibration"]["surfaces.sam.work_of_adhesion"]
    assert "systematic_tail" not in cal0 and cal0["stderr"] == pytest.approx(math.hypot(0.0037, 0.0029, 0.00515))


def test_z0_is_formed_with_the_w_the_set_uses():
    """A committed z0 formed with the outward W (0.0668) is recomputed as 1.026 x the set's W (0.0617) / sigma0;
    the entry keeps the committed value beside it. A z0 that already names its W is taken as it is."""
    table, _ = build_parameter_set({OTS: _ots()}, "paper", "cal")
    z = table["surfaces"]["sam"]["interaction_range"]
    assert z == pytest.approx(MAUGIS_LJ93 * 0.0617 / 1.8686e8, rel=1e-9)
    cal = table["meta"]["calibration"]["surfaces.sam.interaction_range"]
    assert cal["value_committed"] == 3.67e-10 and cal["work_of_adhesion_used"] == 0.0617
    new = _ots()
    new["quantities"]["interaction_range_z0"].update(value=3.4e-10, work_of_adhesion_used=0.0617)
    assert build_parameter_set({OTS: new}, "paper", "cal")[0]["surfaces"]["sam"]["interaction_range"] == 3.4e-10


def _pull(forces_by_speed, speeds, radius_A=12.0, dmt=None):
    rows = [{"position": p, "speed_m_s": v, "max_tensile_force_N": f}
            for v, fs in zip(speeds, forces_by_speed) for p, f in enumerate(fs)]
    slow = forces_by_speed[int(np.argmin(speeds))]
    w = float(np.mean(slow)) / (2 * math.pi * radius_A * 1e-10)
    return {"recipe": PULL_OTS, "settings": {"asperity_radius_A": radius_A}, "details": {"per_position": rows},
            "quantities": _q(work_of_adhesion_eff_dmt={"value": dmt or w, "stderr": 0.003},
                             pull_off_force={"value": float(np.mean(slow)), "speed_m_s": min(speeds)})}


def test_the_pulloff_is_compared_with_the_cutoff_only_w_and_extrapolated_in_rate():
    """Forces exactly linear in v at every position (F = F0_p + c v): the linear extrapolation returns mean F0 with
    the positions' spread x t(3) / 2 as its stderr, and the validation compares it (and the slow pull) with W_F less
    the tail, names that W and keeps the tail-included W beside it."""
    f0 = np.array([0.30, 0.36, 0.33, 0.29]) * 1e-9
    c = 2.5e-12
    speeds = [80.0, 40.0]
    forces = [list(f0 + c * v) for v in speeds]
    pull = _pull(forces, speeds)
    r = rate_extrapolation(pull)
    lin = r["linear_v0"]
    assert lin["F_N"] == pytest.approx(f0.mean(), rel=1e-9) and lin["slope"] == pytest.approx(c, rel=1e-9)
    assert lin["F_stderr_N"] == pytest.approx(f0.std(ddof=1) / 2 * 1.1969, rel=1e-3)
    assert r["log_at_10"]["target_m_s"] == 10.0 and "NOT run" in r["note"]
    v = pulloff_validation({OTS: _ots(), PULL_OTS: pull})[PULL_OTS]
    assert v["like_for_like"] is True and v["W_F"] == pytest.approx(0.0617 - 0.0193)
    assert "without the static TraPPE tail" in v["compared_with"] and v["W_F_with_tail"] == 0.0617
    w_err = math.hypot(0.0037, 0.0029, 0.00515)
    assert v["W_F_stderr"] == pytest.approx(w_err, rel=1e-9)
    ex = lin["F_N"] / (2 * math.pi * 12e-10)
    assert v["rate_extrapolated"]["ratio"] == pytest.approx(ex / (0.0617 - 0.0193), rel=1e-9)
    # a pair without a tail is compared with its W_F as it is
    w = like_for_like_work({"work_of_adhesion_free_energy": {"value": 0.19, "stderr": 0.04}})
    assert w["value"] == 0.19 and w["with_tail"] is None and "no tail on either side" in w["compared_with"]
    # one speed: no extrapolation
    assert rate_extrapolation(_pull([forces[0]], [80.0])) == {}


def test_tabor_mu_of_the_coated_pair_uses_the_sam_layers_modulus():
    """With the set's layer modulus E and nu the coated pair's E* = E / (2 (1 - nu^2)), mu = (R W^2/(E*^2 z0^3))^(1/3)
    with W the compared (cutoff-only) W."""
    pull = _pull([[0.4e-9] * 4, [0.5e-9] * 4], [40.0, 80.0])
    adh = _ots()
    table = {"surfaces": {"sam": {"layer_modulus": 4e9, "layer_poisson_ratio": 0.3}}}
    v = pulloff_validation({OTS: adh, PULL_OTS: pull}, table)[PULL_OTS]
    e_star = 4e9 / (2 * (1 - 0.09))
    w = 0.0617 - 0.0193
    assert v["tabor_e_star_Pa"] == pytest.approx(e_star)
    assert v["tabor_mu"] == pytest.approx((12e-10 * w ** 2 / (e_star ** 2 * 3.67e-10 ** 3)) ** (1 / 3), rel=1e-9)


def test_the_sam_thickness_is_the_annealed_one_and_a_measured_nu_replaces_the_choice():
    """An anneal at 28 deg: the stack thickness is 2 x the builder's chain height at 28 deg (not the 24 A built), the
    set's SAM thickness that per layer; a result with a measured nu: the set's layer Poisson ratio is that nu with
    origin md, the conversion uses it and E's stderr holds its error through E' = M (1 - 2 nu)/(1 - nu)^2."""
    from md.build.sam import chain_geometry

    d = [-4.0, -3.0, -2.0, -1.0, 0.5, 2.0]
    f = [80.0, 60.0, 40.0, 20.0, -5.0, -1.0]
    res = _ots()
    sam = {"builder": "ots_sam", "thickness_A": 24.0}
    res["system"] = {"area_A2": 530.0, "lower": sam, "upper": sam}
    res["details"] = {"pmf_windows": {"separation_A": d, "mean_force_kcal_mol_A": f, "stderr_kcal_mol_A": [1.0] * 6,
                                      "tail_force_kcal_mol_A": [0.0] * 6},
                      "anneal": {"mean_tilt_deg": [20.0] * 10 + [28.0] * 10}}
    table, _ = build_parameter_set({OTS: res}, "paper", "cal")
    h28 = float(chain_geometry(18, 28.0)[0][-1][2])
    assert table["surfaces"]["sam"]["thickness"] == pytest.approx(h28 * 1e-10, rel=1e-9)
    cal = table["meta"]["calibration"]["surfaces.sam.layer_modulus"]
    m = 20.0 * 2 * h28 / 530.0 * 4184.0 / 6.02214076e23 / 1e-30
    assert cal["confined_modulus"]["value"] == pytest.approx(m, rel=1e-6)
    assert cal["thickness_used"]["per_layer_m"] == pytest.approx(h28 * 1e-10) and "annealed" in \
        cal["thickness_used"]["source"]
    # a measured Poisson ratio (the sam_stress run): used, with its origin, and its error in E's stderr
    res["quantities"]["sam_poisson_ratio"] = {"value": 0.4, "stderr": 0.02, "units": "", "c13_over_c33": 0.4 / 0.6}
    table2, _ = build_parameter_set({OTS: res}, "paper", "cal")
    sam2 = table2["surfaces"]["sam"]
    assert sam2["layer_poisson_ratio"] == 0.4 and table2["meta"]["origin"]["surfaces.sam.layer_poisson_ratio"][
        "kind"] == "md"
    cal2 = table2["meta"]["calibration"]["surfaces.sam.layer_modulus"]
    assert cal2["poisson_ratio"]["measured"] is True
    assert sam2["layer_modulus"] == pytest.approx(m * 1.4 * 0.2 / 0.6, rel=1e-6)
    rel_nu = abs(-2 / 0.2 + 2 / 0.6) * 0.02
    rel_m = cal2["confined_modulus"]["stderr"] / cal2["confined_modulus"]["value"]
    assert cal2["stderr"] == pytest.approx(sam2["layer_modulus"] * math.hypot(rel_m, rel_nu), rel=1e-9)


def test_de_and_tds_are_marked_unconverged_where_the_registries_energies_disagree():
    """Registry 0's dE/A 0.081 +- 0.017 and registries 1, 2 at 0.139 +- 0.004 and 0.111 +- 0.004 (the committed
    OTS pattern): chi^2 p < 0.01, the entry says NOT CONVERGED; three registries within their errors: agree."""
    res = _ots(work_of_adhesion={"value": 0.081, "stderr": 0.017, "units": "J/m^2"})
    res["details"] = {"registry_contacts": {"1": {"energy_work_J_m2": 0.139, "stderr_J_m2": 0.0043},
                                            "2": {"energy_work_J_m2": 0.111, "stderr_J_m2": 0.0044}}}
    cal = build_parameter_set({OTS: res}, "paper", "cal")[0]["meta"]["calibration"]["surfaces.sam.work_of_adhesion"]
    ee = cal["energy_estimate"]
    assert ee["registries_agree"] is False and "NOT CONVERGED" in ee["note_registries"]
    assert ee["per_registry"] == [0.081, 0.139, 0.111]
    res["details"]["registry_contacts"] = {"1": {"energy_work_J_m2": 0.085, "stderr_J_m2": 0.005},
                                           "2": {"energy_work_J_m2": 0.079, "stderr_J_m2": 0.005}}
    cal = build_parameter_set({OTS: res}, "paper", "cal")[0]["meta"]["calibration"]["surfaces.sam.work_of_adhesion"]
    assert cal["energy_estimate"]["registries_agree"] is True and "note_registries" not in cal["energy_estimate"]
