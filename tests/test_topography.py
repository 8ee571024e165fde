"""Surfaces from height maps (continuum.rough.topography, summit_stats, surface_map): summit statistics checked
against closed forms and against SurfaceTopography's own estimators, the scene keys' precedence, and bad maps
refused in one line with nothing written. Every map is built here (numpy, written in formats SurfaceTopography
reads); none is a stored fixture except the shipped synthetic map the shipped scene names."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from SurfaceTopography.Generation import fourier_synthesis

from calibration.cli import main
from continuum.rough.summit_stats import spectral_summits
from continuum.rough.topography import (MIN_SUMMITS, HeightMap, Synthesis, TopographyError, identify_summits,
                                        load_height_map, summit_statistics)
from continuum.scene import SceneError, resolve_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = {"name": "t", "params": "paper", "contact": "rough", "release_height": 100e-9,
         "body": {"shape": "cylinder", "radius": 5e-6, "length": 3.28e-3, "mass": 0.6e-9},
         "physics": {"adhesion_law": "jkr"}}


def _synthetic(n: int, short_px: float, seed: int, hurst: float = 0.8):
    """A periodic self-affine Gaussian map of n^2 points on 1 um^2, nothing shorter than short_px pixels."""
    size = 1e-6
    return fourier_synthesis((n, n), (size, size), hurst, rms_height=1e-9, short_cutoff=short_px * size / n,
                             rng=np.random.default_rng(seed), unit="m")


def _write_text_map(path: Path, heights_nm: np.ndarray, size_um: float | None = 2.0) -> Path:
    header = ["# Channel: Height"] + ([f"# Width: {size_um} µm", f"# Height: {size_um} µm"] if size_um else [])
    rows = [" ".join(f"{v:.4f}" for v in row) for row in heights_nm.T]
    path.write_text("\n".join(header + ["# Value units: nm"] + rows) + "\n")
    return path


# ----------------------------------------------------------------------------- spectral route
def test_spectral_moments_match_surfacetopographys_rms_estimators():
    """m0, m2, m4 of the spectral route (profile moments from SurfaceTopography's areal PSD moments) against
    SurfaceTopography's rms height, rms gradient and rms curvature at the same cutoff: m0 = h_rms^2,
    2 m2 = |grad h|_rms^2, (8/3) m4 = <(lap h)^2> = (2 kappa_rms)^2. The rms estimators differentiate with
    finite-difference stencils (symbol 2 sin(q dx/2)/dx instead of q), so they fall short of the spectral moments
    by at most (q_c dx)^2/12 (slope) and (q_c dx)^2/6 (curvature) at the cutoff wavevector q_c: the tolerance.
    A wrong profile/areal factor (1/2, 3/8) misses by tens of per cent."""
    n, size = 256, 1e-6
    topo = _synthetic(n, 16, seed=5)
    assert spectral_summits(topo, 16 * size / n).m0 == pytest.approx(topo.rms_height_from_area() ** 2, rel=1e-9)
    cutoff = 20 * size / n                               # no lattice wavevector lies on |q| = q_c
    s = spectral_summits(topo, cutoff)
    qdx = 2 * np.pi / cutoff * size / n
    slope = 2 * s.m2 / topo.rms_gradient(short_wavelength_cutoff=cutoff) ** 2 - 1
    curvature = 8 / 3 * s.m4 / (2 * topo.rms_curvature_from_area(short_wavelength_cutoff=cutoff)) ** 2 - 1
    assert 0 <= slope <= qdx**2 / 12
    assert 0 <= curvature <= qdx**2 / 6


def test_profile_moments_are_the_direction_averaged_ones():
    """The isotropic conversion m2 = M2/2, m4 = 3 M4/8 against profile moments taken along x and y directly
    (spectral derivatives of the periodic map). The realisation is only statistically isotropic: with ~10^4
    independent modes in the band the x and y moments scatter by about 1 %; tolerance 5 %."""
    topo = _synthetic(256, 8, seed=11)
    h = np.asarray(topo.heights())
    n, size = h.shape[0], topo.physical_sizes[0]
    q = 2 * np.pi * np.fft.fftfreq(n, d=size / n)
    hq = np.fft.fft2(h)
    qx, qy = np.meshgrid(q, q, indexing="ij")
    power = np.abs(hq) ** 2 / n**4                          # Parseval: mean of h^2 = sum |hq|^2 / n^4
    m2 = np.sum((qx**2 + qy**2) / 2 * power)                 # mean of <h_x^2> and <h_y^2>
    m4 = np.sum((qx**4 + qy**4) / 2 * power)                 # mean of <h_xx^2> and <h_yy^2>
    s = spectral_summits(topo, 8 * size / n)
    assert s.m2 == pytest.approx(m2, rel=0.05)
    assert s.m4 == pytest.approx(m4, rel=0.05)
    assert s.alpha >= 1.5                                  # Nayak's lower bound for an isotropic surface


# ----------------------------------------------------------------------------- direct route
@pytest.mark.parametrize("wavelength_px", [16, 32])
def test_direct_route_on_an_egg_box(wavelength_px):
    """h = A cos(kx) cos(ky) has maxima at (0, 0) and (lambda/2, lambda/2) of every lambda^2 cell: density
    2/lambda^2, mean curvature A k^2 (radius 1/(A k^2)), height A. The central-difference quadratic's curvature
    is low by the factor sinc^2(k dx/2) ~ 1 - (k dx)^2/12: the tolerance."""
    n, dx, amp = 256, 1e-9, 2e-9
    lam = wavelength_px * dx
    x = np.arange(n) * dx
    k = 2 * np.pi / lam
    h = amp * np.cos(k * x)[:, None] * np.cos(k * x)[None, :]
    s = identify_summits(h, dx, cutoff=lam / 2, periodic=True)
    assert s.count == 2 * (n // wavelength_px) ** 2
    assert s.density == pytest.approx(2 / lam**2, rel=1e-12)
    bias = (k * dx) ** 2 / 12
    assert np.allclose(s.curvature, amp * k**2, rtol=1.2 * bias)
    assert np.allclose(s.height, amp, rtol=1e-9)
    assert np.allclose(s.x / (lam / 2), np.round(s.x / (lam / 2)), rtol=0, atol=1e-6)


def test_nayak_density_against_a_direct_count_on_a_large_gaussian_surface():
    """Nayak's summit density m4/(6 pi sqrt 3 m2) is exact for an isotropic Gaussian surface; the direct count
    on a 2048^2 realisation filtered at 16 pixels (about 3000 summits) scatters by at most 1/sqrt(N) (summits
    of a Gaussian field are more regular than Poisson points): tolerance 3/sqrt(N)."""
    topo = _synthetic(2048, 16, seed=2)
    hmap = HeightMap(heights=np.asarray(topo.heights()), pixel_size=tuple(topo.pixel_size),
                     physical_size=tuple(topo.physical_sizes), periodic=True, rms_height=topo.rms_height_from_area())
    stats = summit_statistics(hmap, 16 * topo.pixel_size[0], "spectral")
    n = stats.direct.count
    assert n > 2000
    assert stats.direct.summit_density == pytest.approx(stats.spectral.summit_density, rel=3 / math.sqrt(n))
    assert stats.summit_density == stats.spectral.summit_density and stats.route == "spectral"


def test_identify_summits_on_a_non_periodic_map_keeps_off_the_edges():
    """A measured (non-periodic) map is mirror-stitched for the filter; summits within cutoff/2 of an edge are
    not counted (the fold makes maxima there), and the area they are counted on shrinks accordingly."""
    h = np.asarray(_synthetic(128, 8, seed=3).heights())
    s = identify_summits(h, 1e-6 / 128, cutoff=8e-6 / 128)
    margin = 4e-6 / 128
    assert s.count > MIN_SUMMITS
    half_pixel = 0.5e-6 / 128                              # the fitted summit may sit half a pixel off its grid point
    assert s.x.min() >= margin - half_pixel and s.x.max() <= 1e-6 - margin + half_pixel
    assert s.area == pytest.approx((1e-6 - 2 * margin) ** 2, rel=1e-12)


# ----------------------------------------------------------------------------- maps and scenes
def test_a_text_map_is_read_in_si_units_and_detrended(tmp_path):
    """Heights written in nm with a tilt come back in metres, the plane removed: rms equals SurfaceTopography's
    detrended rms of the same file (and of the untilted map)."""
    base = np.asarray(_synthetic(64, 8, seed=4).heights()) * 1e9
    tilt = 0.5 * np.arange(64)[:, None] + 0.2 * np.arange(64)[None, :]
    path = _write_text_map(tmp_path / "m.txt", base + tilt, size_um=2.0)
    hmap = load_height_map(path)
    assert hmap.physical_size == pytest.approx((2e-6, 2e-6))
    assert hmap.source["sha256"] and hmap.source["unit_in_file"] == "nm"
    from SurfaceTopography import open_topography
    ref = open_topography(str(path)).topography().detrend("height").rms_height_from_area() * 1e-9
    assert hmap.rms_height == pytest.approx(ref, rel=1e-12)
    assert abs(np.mean(hmap.heights)) < 1e-6 * hmap.rms_height


def test_a_tip_radius_sets_the_cutoff_surfacetopography_finds(tmp_path):
    """tip_radius instead of summit_cutoff: the cutoff is SurfaceTopography's scanning-probe reliability cutoff
    of the map for that tip, and the record says where it came from; a map pickles (process executors)."""
    import pickle

    from SurfaceTopography import open_topography
    heights = np.asarray(_synthetic(256, 8, seed=6).heights()) * 1e9
    path = _write_text_map(tmp_path / "tip.txt", heights, size_um=1.0)
    tip = 3e-7                                             # blunt enough for a cutoff on this map (0.1 um is not)
    expected = open_topography(str(path)).topography().to_unit("m").detrend("height") \
        .scanning_probe_reliability_cutoff(tip)
    r = resolve_scene(table={**SCENE, "surfaces": {"roughness": {"topography": str(path), "tip_radius": tip}}})
    assert r.surface["cutoff"] == pytest.approx(expected, rel=1e-6)
    assert r.surface["cutoff_from"].startswith("tip_radius")
    hmap = load_height_map(path)
    assert np.array_equal(pickle.loads(pickle.dumps(hmap)).heights, hmap.heights)


def test_shipped_topography_scene_takes_its_statistics_from_the_map():
    """rough_topography: sigma, summit_density and summit_radius come from the map (sigma is the summit heights'
    standard deviation), replacing the parameter set's, which the surface block lists."""
    r = resolve_scene("rough_topography")
    block, rough = r.surface, r.scene.surfaces.roughness
    assert r.sources["surfaces.roughness.summit_radius"] == "topography"
    assert rough.sigma == block["summit_height_std"] and rough.summit_density == block["summit_density"]
    assert rough.summit_radius == block["routes"]["direct"]["summit_radius"]
    assert set(block["replaced"]) == {"surfaces.roughness.summit_density", "surfaces.roughness.summit_radius"}
    assert block["source"]["kind"] == "file" and len(block["source"]["sha256"]) == 64


def test_synthetic_scene_records_its_parameters_and_runs():
    from continuum import run_scene
    r = run_scene("rough_synthetic", overrides={"numerics.max_bounces": 1, "numerics.fidelity": "fast"})
    surface = r.record["surface"]
    assert surface["source"]["kind"] == "synthesis" and surface["source"]["hurst"] == 0.8
    assert surface["cutoff"] == 0.3125e-6 and surface["route"] == "direct"
    assert r.record["scene"]["sources"]["surfaces.roughness.sigma"] == "synthetic"


def test_plain_statistics_and_smooth_scenes():
    """A rough scene without a map records source 'statistics'; smooth contact has no surface block."""
    assert resolve_scene("rough_silica").surface["source"]["kind"] == "statistics"
    assert resolve_scene("hertz_roller").surface is None


@pytest.mark.parametrize("extra, key", [
    ({"sigma": 5e-9}, "surfaces.roughness.sigma"),                     # given in the scene and by the map
    ({"synthetic": {"hurst": 0.8, "rms_height": 1e-9, "short_cutoff": 1e-7, "size": 2e-6}},
     "surfaces.roughness.topography"),                                  # two maps
    ({"summit_cutoff": None}, "surfaces.roughness.summit_cutoff"),     # no cutoff for a measured map
    ({"tip_radius": 1e-8}, "surfaces.roughness.tip_radius"),           # cutoff and tip radius both
])
def test_conflicting_map_keys_are_refused(extra, key):
    rough = {"topography": "synthetic_selfaffine.txt", "summit_cutoff": 0.3125e-6, **extra}
    rough = {k: v for k, v in rough.items() if v is not None}
    with pytest.raises(SceneError, match=rf"^<scene>: {key} = "):
        resolve_scene(table={**SCENE, "surfaces": {"roughness": rough}})


def test_map_keys_without_a_map_or_on_smooth_contact_are_refused():
    with pytest.raises(SceneError, match="summit_cutoff = 1e-07: is for a height map"):
        resolve_scene(table={**SCENE, "surfaces": {"roughness": {"sigma": 5e-9, "summit_cutoff": 1e-7}}})
    smooth = {**SCENE, "contact": "smooth", "body": {"shape": "sphere", "radius": 1e-6, "mass": 1e-12}}
    with pytest.raises(SceneError, match="topography = 'synthetic_selfaffine.txt': a height map is for contact"):
        resolve_scene(table={**smooth, "surfaces": {"roughness": {"topography": "synthetic_selfaffine.txt"}}})


# ----------------------------------------------------------------------------- bad maps: one line, nothing written
def _npy(tmp_path: Path, heights: np.ndarray) -> Path:
    np.save(tmp_path / "map.npy", heights)
    return tmp_path / "map.npy"


def _bad_cases(tmp_path: Path):
    good = np.asarray(_synthetic(64, 8, seed=9).heights())
    nan = good.copy()
    nan[3, 4] = np.nan
    garbage = tmp_path / "garbage.di"
    garbage.write_bytes(b"\x00\x01 not a topography \xff" * 50)
    return [
        ({"topography": str(tmp_path / "missing.txt"), "summit_cutoff": 1e-7}, "topography", "file not found"),
        ({"topography": str(garbage), "summit_cutoff": 1e-7}, "topography", "SurfaceTopography cannot read it"),
        ({"topography": str(_npy(tmp_path, good)), "topography_unit": "m", "summit_cutoff": 1e-7},
         "topography_size", "gives no physical size"),
        ({"topography": str(_npy(tmp_path, good)), "topography_size": [1e-6], "summit_cutoff": 1e-7},
         "topography_unit", "gives no height unit"),
        ({"topography": str(_write_text_map(tmp_path / "sized.txt", good * 1e9)), "topography_size": [1e-6],
          "summit_cutoff": 1e-7}, "topography_size", "has its own physical size"),
        ({"topography": str(_write_text_map(tmp_path / "tiny.txt", good[:8, :8] * 1e9)), "summit_cutoff": 1e-7},
         "topography", "8 x 8 pixels"),
        ({"topography": str(_write_text_map(tmp_path / "nan.txt", nan * 1e9)), "summit_cutoff": 1e-7},
         "topography", "undefined"),
        ({"topography": str(_write_text_map(tmp_path / "few.txt", good * 1e9)), "summit_cutoff": 1e-6},
         "topography", "summit statistics need >= 20"),
        ({"topography": str(_write_text_map(tmp_path / "px.txt", good * 1e9)), "summit_cutoff": 5e-8},
         "summit_cutoff", "must be >= 4 pixels"),
        ({"synthetic": {"hurst": 0.8, "rms_height": 1e-9, "short_cutoff": 1e-8, "size": 1e-6, "grid_points": 64}},
         "synthetic.short_cutoff", "must be >= 4 pixels"),
        ({"synthetic": {"hurst": 0.8, "rms_height": 1e-9, "short_cutoff": 1e-7, "size": 1e-6, "grid_points": 63}},
         "synthetic.grid_points", "must be even"),
    ]


def test_bad_maps_are_one_line_naming_the_key_and_nothing_is_written(tmp_path, capsys, monkeypatch):
    def started(*a, **k):
        raise AssertionError("work started: a bad map got through")

    monkeypatch.setattr("continuum.impact.run_impact", started)
    for k, (rough, key, expect) in enumerate(_bad_cases(tmp_path)):
        scene = tmp_path / f"scene{k}.toml"
        body = "\n".join(f"{a} = {b!r}" for a, b in SCENE["body"].items())
        lines = ['params = "paper"', 'contact = "rough"', "release_height = 1e-7", "[body]", body,
                 "[physics]", 'adhesion_law = "jkr"', "[surfaces.roughness]"]
        synth = rough.pop("synthetic", None)
        lines += [f"{a} = {b!r}".replace("'", '"') for a, b in rough.items()]
        if synth:
            lines += ["[surfaces.roughness.synthetic]"] + [f"{a} = {b!r}" for a, b in synth.items()]
        scene.write_text("\n".join(lines) + "\n")
        out = tmp_path / f"out{k}"
        code = main(["impact", str(scene), "--out", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1, (key, err)
        assert f"surfaces.roughness.{key} = " in err[0] and expect in err[0], (key, err[0])
        assert not out.exists()


def test_too_few_summits_names_the_synthetic_size():
    s = Synthesis(hurst=0.8, rms_height=1e-9, short_cutoff=2.5e-7, size=1e-6, grid_points=64)
    hmap = load_height_map(synthesis=s)
    with pytest.raises(TopographyError, match=r"synthetic.size = 1e-06: .* holds \d+ summits"):
        summit_statistics(hmap, s.short_cutoff)
