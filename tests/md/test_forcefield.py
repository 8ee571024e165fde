"""Force-field parameter files (inputs/forcefields/*.toml) and md.system.forcefield. No LAMMPS needed."""
from __future__ import annotations

import math
import shutil

import pytest

from md.system.forcefield import (
    FORCEFIELD_DIR,
    R_KCAL_PER_MOL_K,
    TWO_TO_ONE_SIXTH,
    ForceFieldError,
    PairCoeff,
    available_forcefields,
    combine,
    epsilon_from_published,
    lammps_pair_coeffs,
    lammps_type_ids,
    load_forcefield,
    mix,
    sigma_from_published,
)

ALL = available_forcefields()
CHARGE_TOL = 1e-6


def with_requirements(name):
    ff = load_forcefield(name)
    return combine(*[load_forcefield(r) for r in ff.requires], ff) if ff.requires else ff


def test_expected_files_present():
    for name in ("silica_interface", "ots_trappe_ua", "water_spce", "water_tip4p2005"):
        assert name in ALL
    assert (FORCEFIELD_DIR / "README.md").exists()


@pytest.mark.parametrize("name", ALL)
def test_every_file_loads_with_source(name):
    ff = load_forcefield(name)
    assert ff.name == name
    src = ff.sources[0]
    assert src["citation"].strip() and src["doi"].strip()
    assert src.get("table", "").strip() or src.get("file", "").strip()
    assert ff.units["lammps_units"] == "real" and ff.units["energy"] == "kcal/mol"
    assert ff.atom_types
    n = len(ff.atom_types)
    assert len(ff.pair_coeffs) == n * (n + 1) // 2


@pytest.mark.parametrize("name", ALL)
def test_every_parameter_has_a_source_note(name):
    ff = load_forcefield(name)
    for t in (*ff.atom_types, *ff.bond_types, *ff.angle_types, *ff.dihedral_types):
        assert t.source_note.strip(), t.name


# ------------------------------------------------------------------------------------------------ charges

@pytest.mark.parametrize("name", ALL)
def test_declared_charge_groups_are_neutral(name):
    ff = with_requirements(name)
    groups = [g for g in ff.charge_groups if g.family == load_forcefield(name).families[0]]
    assert groups, f"{name} declares no neutral charge group"
    for g in groups:
        assert abs(ff.total_charge(g.composition)) < CHARGE_TOL, g.name


def test_spce_water_neutral():
    ff = load_forcefield("water_spce")
    assert ff.atom_type("OW").charge == pytest.approx(-0.8476)
    assert ff.atom_type("HW").charge == pytest.approx(0.4238)
    assert abs(ff.total_charge({"OW": 1, "HW": 2})) < CHARGE_TOL


def test_tip4p2005_water_neutral():
    ff = load_forcefield("water_tip4p2005")
    assert abs(ff.total_charge({"OW4": 1, "HW4": 2})) < CHARGE_TOL
    assert ff.extras["tip4p"]["om_distance"] == pytest.approx(0.1546)


def test_silica_units_neutral():
    ff = load_forcefield("silica_interface")
    q = {t.name: t.charge for t in ff.atom_types}
    assert (q["SC4"], q["OC23"], q["OC24"], q["HOY"]) == pytest.approx((1.1, -0.55, -0.675, 0.4))
    assert abs(ff.total_charge({"SC4": 1, "OC24": 4, "HOY": 4})) < CHARGE_TOL      # Si(OH)4
    assert abs(ff.total_charge({"SC4": 1, "OC23": 2})) < CHARGE_TOL                # SiO2 (Q4)
    assert abs(ff.total_charge({"SC4": 1, "OC23": 1.5, "OC24": 1, "HOY": 1})) < CHARGE_TOL  # Q3 surface unit


def test_ots_chain_neutral_free_and_grafted():
    ff = combine("silica_interface", "ots_trappe_ua")
    chain = {"CH3": 1, "CH2": 17}
    assert abs(ff.total_charge(chain)) < CHARGE_TOL
    free = {**chain, "SIH": 1, "OC24": 3, "HOY": 3}                                # C18H37-Si(OH)3
    assert abs(ff.total_charge(free)) < CHARGE_TOL
    # grafting: (HO)3Si-OH + HO-Si(OH)2R -> (HO)3Si-O-Si(OH)2R + H2O.
    surface_silanol = {"SC4": 1, "OC24": 4, "HOY": 4}
    before = ff.total_charge(surface_silanol) + ff.total_charge(free)
    removed = ff.atom_type("HOY").charge + ff.atom_type("OC24").charge + ff.atom_type("HOY").charge
    retype = ff.atom_type("OC23").charge - ff.atom_type("OC24").charge               # surface O: OC24 -> OC23
    grafted = {"SC4": 1, "OC24": 5, "HOY": 5, "OC23": 1, "SIH": 1, **chain}
    assert abs(before - removed + retype - ff.total_charge(grafted)) < CHARGE_TOL
    assert abs(ff.total_charge(grafted)) < CHARGE_TOL
    # head unit alone, bridging O counted half
    assert abs(ff.total_charge({**chain, "SIH": 1, "OC24": 2, "HOY": 2, "OC23": 0.5})) < CHARGE_TOL


# --------------------------------------------------------------------------------------------- conversions

def test_sigma_conversions():
    assert sigma_from_published(3.0, "sigma") == 3.0
    assert sigma_from_published(4.15, "rmin") == pytest.approx(4.15 / TWO_TO_ONE_SIXTH)
    assert sigma_from_published(2.075, "rmin_half") == pytest.approx(sigma_from_published(4.15, "rmin"))
    with pytest.raises(ForceFieldError):
        sigma_from_published(1.0, "diameter")


@pytest.mark.parametrize("name", ALL)
def test_stored_sigma_matches_published(name):
    for t in load_forcefield(name).atom_types:
        if t.published_radius is not None:
            assert t.sigma == pytest.approx(sigma_from_published(t.published_radius, t.published_radius_kind),
                                            abs=5e-4), t.name
        if t.published_epsilon is not None:
            assert t.epsilon == pytest.approx(epsilon_from_published(t.published_epsilon, t.published_epsilon_unit),
                                              rel=1e-4, abs=1e-9), t.name


def test_lj_minimum_is_at_charmm_rmin():
    """With the stored sigma, 4 eps[(s/r)^12 - (s/r)^6] has its minimum -eps at r = 2 * Rmin/2 (CHARMM)."""
    sc4 = load_forcefield("silica_interface").atom_type("SC4")
    r_min = TWO_TO_ONE_SIXTH * sc4.sigma
    assert r_min == pytest.approx(2 * 2.075, abs=1e-4)
    u = lambda r: 4 * sc4.epsilon * ((sc4.sigma / r) ** 12 - (sc4.sigma / r) ** 6)
    assert u(r_min) == pytest.approx(-sc4.epsilon)
    assert u(r_min * 0.999) > u(r_min) < u(r_min * 1.001)


def test_iff_charmm_and_cvff_files_agree():
    """A/B of cvff_interface_v1_5.frc (lines 4191, 4203-4205): A = eps r0^12, B = 2 eps r0^6."""
    silica = load_forcefield("silica_interface")
    cvff_ab = {"SC4": (2426940.0, 950.17), "OC23": (164569.0, 188.54), "OC24": (371804.0, 425.96),
               "HOY": (0.0399, 0.04890)}
    for name, (a, b) in cvff_ab.items():
        r0 = (2 * a / b) ** (1 / 6)
        eps = b * b / (4 * a)
        t = silica.atom_type(name)
        assert TWO_TO_ONE_SIXTH * t.sigma == pytest.approx(r0, abs=2e-3), name
        assert t.epsilon == pytest.approx(eps, rel=2e-3, abs=0), name


def test_trappe_conversions():
    ots = load_forcefield("ots_trappe_ua")
    assert ots.atom_type("CH3").epsilon == pytest.approx(98.0 * R_KCAL_PER_MOL_K, rel=1e-5, abs=0)
    assert ots.atom_type("CH2").epsilon == pytest.approx(46.0 * R_KCAL_PER_MOL_K, rel=1e-5, abs=0)
    bend = {a.name: a for a in ots.angle_types}["CH2-CH2-CH2"]
    assert bend.style == "harmonic"
    assert bend.coeffs == pytest.approx((62500.0 * R_KCAL_PER_MOL_K / 2.0, 114.0), rel=1e-5, abs=0)
    tors = {d.name: d for d in ots.dihedral_types}["CH2-CH2-CH2-CH2"]
    assert tors.style == "opls"
    expect = [2 * c * R_KCAL_PER_MOL_K for c in (355.03, -68.19, 791.32)] + [0.0]
    assert tors.coeffs == pytest.approx(expect, abs=2e-5)
    # trans (180 deg) is the torsional minimum with value 0
    k1, k2, k3, k4 = tors.coeffs
    e = lambda p: 0.5 * (k1 * (1 + math.cos(p)) + k2 * (1 - math.cos(2 * p)) + k3 * (1 + math.cos(3 * p))
                         + k4 * (1 - math.cos(4 * p)))
    assert e(math.pi) == pytest.approx(0.0, abs=1e-12)
    assert all(e(math.radians(d)) >= 0 for d in range(0, 361, 5))
    cc = {b.name: b for b in ots.bond_types}["CH2-CH2"]
    assert cc.coeffs == pytest.approx((502416.0 / 2 / 100 / 4.184, 1.54), rel=1e-4, abs=0)


def test_spce_parameters():
    w = load_forcefield("water_spce")
    o = w.atom_type("OW")
    assert (o.epsilon, o.sigma) == pytest.approx((0.1553, 3.166))
    assert {b.name: b for b in w.bond_types}["OW-HW"].coeffs[1] == 1.0
    assert {a.name: a for a in w.angle_types}["HW-OW-HW"].coeffs[1] == 109.47
    assert all(t.constraint == "shake" for t in (*w.bond_types, *w.angle_types))


# ------------------------------------------------------------------------------------------- cross terms

def test_cross_terms_follow_lorentz_berthelot():
    ff = combine("silica_interface", "ots_trappe_ua", "water_spce")
    assert ff.mixing_rule == "lorentz_berthelot"
    n = len(ff.atom_types)
    assert len(ff.pair_coeffs) == n * (n + 1) // 2
    for p in ff.pair_coeffs:
        a, b = ff.atom_type(p.type_i), ff.atom_type(p.type_j)
        if p.type_i == p.type_j:
            assert p.rule == "self" and (p.epsilon, p.sigma) == (a.epsilon, a.sigma)
        else:
            assert p.rule == "lorentz_berthelot"
            assert p.epsilon == pytest.approx(math.sqrt(a.epsilon * b.epsilon), abs=1e-12)
            assert p.sigma == pytest.approx(0.5 * (a.sigma + b.sigma), abs=1e-12)
    # a few cross terms between families, by hand
    so = ff.pair("SC4", "OW")
    assert (so.epsilon, so.sigma) == pytest.approx((math.sqrt(0.093 * 0.1553), 0.5 * (3.69723 + 3.166)))
    assert ff.pair("CH2", "OW").sigma == pytest.approx(0.5 * (3.95 + 3.166))
    assert ff.pair("HW", "OC24").epsilon == 0.0


def test_geometric_rule_and_overrides_are_recorded():
    ff = combine("silica_interface", "water_spce", rule="geometric",
                 overrides=[("OW", "OC24", 0.2, 3.0, "hypothetical test value")])
    for p in ff.pair_coeffs:
        if p.rule == "geometric":
            a, b = ff.atom_type(p.type_i), ff.atom_type(p.type_j)
            assert p.sigma == pytest.approx(math.sqrt(a.sigma * b.sigma))
    o = ff.pair("OC24", "OW")
    assert (o.rule, o.epsilon, o.sigma, o.note) == ("explicit", 0.2, 3.0, "hypothetical test value")
    assert any("geometric" in n for n in ff.notes)


def test_mixed_rules_need_an_explicit_choice(tmp_path):
    text = (FORCEFIELD_DIR / "water_spce.toml").read_text()
    text = text.replace('rule = "lorentz_berthelot"', 'rule = "geometric"').replace('name = "water_spce"',
                                                                                     'name = "water_geo"')
    text = text.replace('name = "OW"', 'name = "OG"').replace('name = "HW"', 'name = "HG"')
    text = text.replace('"OW"', '"OG"').replace('"HW"', '"HG"').replace("OW = 1, HW = 2", "OG = 1, HG = 2")
    (tmp_path / "water_geo.toml").write_text(text)
    geo = load_forcefield(tmp_path / "water_geo.toml")
    assert geo.mixing_rule == "geometric"
    with pytest.raises(ForceFieldError, match="mixing rules"):
        combine("silica_interface", geo)
    ff = combine("silica_interface", geo, rule="lorentz_berthelot")
    assert ff.pair("SC4", "OG").rule == "lorentz_berthelot"


def test_mix_function():
    assert mix(0.1, 3.0, 0.4, 4.0, "lorentz_berthelot") == pytest.approx((0.2, 3.5))
    assert mix(0.1, 3.0, 0.4, 4.0, "geometric") == pytest.approx((0.2, math.sqrt(12.0)))
    with pytest.raises(ForceFieldError):
        mix(0.1, 3.0, 0.4, 4.0, "sixthpower")


# ------------------------------------------------------------------------------ special bonds, requires

def test_special_bonds_resolution():
    assert combine("silica_interface", "water_spce").special_bonds.lj == (0.0, 0.0, 1.0)
    sb = combine("silica_interface", "ots_trappe_ua", "water_spce").special_bonds
    assert sb.lj == (0.0, 0.0, 0.0) and sb.coul == (0.0, 0.0, 1.0)
    assert sb.lammps() == "special_bonds lj 0 0 0 coul 0 0 1"


def test_ots_requires_silica_types():
    ots = load_forcefield("ots_trappe_ua")
    assert ots.requires == ("silica_interface",)
    with pytest.raises(ForceFieldError, match="silica_interface"):
        combine(ots, "water_spce")
    ff = combine("silica_interface", ots)
    used = {n for t in (*ff.bond_types, *ff.angle_types, *ff.dihedral_types) for n in t.types} - {"X"}
    assert used <= set(ff.type_names)


def test_conflicting_duplicate_type_rejected(tmp_path):
    text = (FORCEFIELD_DIR / "water_spce.toml").read_text().replace('name = "water_spce"', 'name = "water_x"')
    text = text.replace('name = "OW"', 'name = "SC4"').replace('"OW"', '"SC4"').replace("OW = 1", "SC4 = 1")
    (tmp_path / "water_x.toml").write_text(text)
    with pytest.raises(ForceFieldError, match="SC4"):
        combine("silica_interface", load_forcefield(tmp_path / "water_x.toml"))


def test_loader_rejects_bad_files(tmp_path):
    base = (FORCEFIELD_DIR / "water_spce.toml").read_text()
    bad_sigma = base.replace("sigma = 3.166\n", "sigma = 3.5\n", 1)
    (tmp_path / "bad_sigma.toml").write_text(bad_sigma)
    with pytest.raises(ForceFieldError, match="sigma"):
        load_forcefield(tmp_path / "bad_sigma.toml")
    no_note = base.replace('source_note = "SPC/E oxygen', 'source_note_x = "SPC/E oxygen', 1)
    (tmp_path / "no_note.toml").write_text(no_note)
    with pytest.raises(ForceFieldError, match="source_note"):
        load_forcefield(tmp_path / "no_note.toml")
    bad_units = base.replace('energy = "kcal/mol"', 'energy = "kJ/mol"')
    (tmp_path / "bad_units.toml").write_text(bad_units)
    with pytest.raises(ForceFieldError, match="units"):
        load_forcefield(tmp_path / "bad_units.toml")


def test_requires_are_looked_up_next_to_the_file(tmp_path):
    for n in ("silica_interface", "ots_trappe_ua"):
        shutil.copy(FORCEFIELD_DIR / f"{n}.toml", tmp_path / f"{n}.toml")
    assert load_forcefield(tmp_path / "ots_trappe_ua.toml").requires == ("silica_interface",)
    (tmp_path / "silica_interface.toml").unlink()
    with pytest.raises(FileNotFoundError):
        load_forcefield(tmp_path / "ots_trappe_ua.toml")


# ------------------------------------------------------------------------------------------- LAMMPS text

def test_lammps_pair_coeff_lines():
    ff = combine("silica_interface", "ots_trappe_ua", "water_spce")
    ids = lammps_type_ids(ff)
    lines = lammps_pair_coeffs(ff)
    n = len(ids)
    assert len(lines) == n * (n + 1) // 2
    seen = set()
    for line in lines:
        words = line.split("#")[0].split()
        assert words[0] == "pair_coeff"
        i, j, eps, sig = int(words[1]), int(words[2]), float(words[3]), float(words[4])
        assert 1 <= i <= j <= n
        seen.add((i, j))
        names = {v: k for k, v in ids.items()}
        p = ff.pair(names[i], names[j])
        assert (eps, sig) == pytest.approx((p.epsilon, p.sigma), abs=1e-6)
    assert len(seen) == len(lines)
    # subset and reversed numbering still yields I <= J, with a hybrid sub-style name
    sub = lammps_pair_coeffs(ff, {"OW": 1, "SC4": 2}, substyle="lj/cut/coul/long", comments=False)
    assert sub == ["pair_coeff 1 1 lj/cut/coul/long 0.155300 3.166000",
                   f"pair_coeff 1 2 lj/cut/coul/long {ff.pair('SC4', 'OW').epsilon:.6f} "
                   f"{ff.pair('SC4', 'OW').sigma:.6f}",
                   "pair_coeff 2 2 lj/cut/coul/long 0.093000 3.697230"]


def test_pair_coeff_rejects_unknown_type():
    ff = load_forcefield("water_spce")
    with pytest.raises(KeyError):
        lammps_pair_coeffs(ff, {"XX": 1})


def test_explicit_pair_coeff_dataclass_is_frozen():
    p = PairCoeff("A", "B", 0.1, 3.0, "explicit", "n")
    with pytest.raises(Exception):
        p.epsilon = 0.2
