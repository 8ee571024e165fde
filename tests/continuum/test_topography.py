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
from continuum.rough import map_reading
from continuum.rough.datum import FOOTPRINT_BAND
from continuum.rough.map_scans import FEW_SUMMITS, data_depth, pooled_statistics, scan_record
from continuum.rough.summit_stats import spectral_summits
from continuum.rough.surface_map import scene_scans
from continuum.rough.topography import (
    MIN_SUMMITS,
    HeightMap,
    Synthesis,
    TopographyError,
    identify_summits,
    load_height_map,
    map_summits,
    summit_statistics,
)
from continuum.scene import SceneError, resolve_scene

ROOT = Path(__file__).resolve().parents[2]
DI3 = ROOT / "inputs" / "topographies" / "di-3.di"
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
    wide = identify_summits(h, 1e-6 / 128, cutoff=8e-6 / 128, edge_band=2 * margin)      # a wider band, by keyword
    assert wide.area == pytest.approx((1e-6 - 4 * margin) ** 2, rel=1e-12)
    assert wide.x.min() >= 2 * margin - half_pixel and set(zip(wide.x, wide.y)) <= set(zip(s.x, s.y))


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


def _fine(seed: int) -> np.ndarray:
    """128^2 heights (m, rms 1 nm), nothing shorter than 4 pixels: written as nm on 2 um it holds 135 summits at a
    4-pixel cutoff (seed 9) with beta = 2.9 um; scaled heights scale beta inversely."""
    return np.asarray(_synthetic(128, 4, seed=seed).heights())


def _di3_variant(tmp_path: Path, name: str, replacements) -> Path:
    """The shipped NanoScope file with equal-length edits to its text header (channel names, one image's scan
    size): a file SurfaceTopography reads, with the channels a bad-input case needs."""
    data = DI3.read_bytes()
    header, rest = data[:40960], data[40960:]
    for old, new, nth in replacements:
        assert len(old) == len(new)
        at = [k for k in range(len(header)) if header.startswith(old, k)][nth]
        header = header[:at] + new + header[at + len(old):]
    (tmp_path / name).write_bytes(header + rest)
    return tmp_path / name


def _bad_cases(tmp_path: Path):
    good = np.asarray(_synthetic(64, 8, seed=9).heights())
    no_height = _di3_variant(tmp_path, "no_height.di", [(b'[ZSensor] "Height Sensor"', b'[PhaseXY] "Phase  Sensor"', 0),
                                                        (b'[Height] "Height"', b'[Phase2] "Phase2"', 0)])
    disagree = _di3_variant(tmp_path, "disagree.di", [(b"Scan Size: 10 10 ~m", b"Scan Size: 20 20 ~m", -1)])
    cut = 0.16e-6
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
        # the channel and the levelling (issue 41, point 4)
        ({"topography": str(no_height), "summit_cutoff": cut}, "topography", "has no height channel"),
        ({"topography": str(DI3), "topography_channel": "Topography", "summit_cutoff": cut}, "topography_channel",
         "the file has channels 0 ('ZSensor')"),
        ({"topography": str(DI3), "topography_channel": 2, "summit_cutoff": cut}, "topography_channel",
         "does not hold heights"),
        ({"topography": str(DI3), "topography_channel": 7, "summit_cutoff": cut}, "topography_channel",
         "the file has channels"),
        ({"topography": str(disagree), "summit_cutoff": cut}, "topography", "disagree in grid or size"),
        ({"topography": [], "summit_cutoff": cut}, "topography", "a list of one or more items"),
        ({"topography": str(DI3), "topography_detrend": "curvature", "summit_cutoff": cut}, "topography_detrend",
         "one of 'plane', 'line', 'none'"),
        ({"topography": str(DI3), "topography_channel": "", "summit_cutoff": cut}, "topography_channel",
         "a name (a non-empty string)"),
        # the range of validity (point 5): summits flatter than the 5 um roller are refused
        ({"topography": str(_write_text_map(tmp_path / "flat.txt", _fine(9) * 1e8)), "summit_cutoff": 6.25e-8},
         "summit_cutoff", "flatter than the body"),
        ({"synthetic": {"hurst": 0.8, "rms_height": 1e-9, "short_cutoff": 1e-7, "size": 1e-6, "grid_points": 64},
          "topography_detrend": "line"}, "topography_detrend", "is for a measured map"),
    ]


def test_bad_maps_are_one_line_naming_the_key_and_nothing_is_written(tmp_path, capsys, monkeypatch):
    def started(*a, **k):
        raise AssertionError("work started: a bad map got through")

    monkeypatch.setattr("continuum.dynamics.impact.run_impact", started)
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


# ----------------------------------------------------------------------------- channel and levelling (issue 41, 4)
def test_the_height_channel_is_chosen_by_name_or_as_the_closed_loop_sensor():
    """The shipped NanoScope scan holds ZSensor, AmplitudeError, Phase and Height. Unnamed, the closed-loop
    ZSensor runs and a warning names Height; by name (any case) or index, Height runs, without that warning;
    the levelled map is SurfaceTopography's own plane-detrended channel in metres."""
    from SurfaceTopography import open_topography

    reader = open_topography(str(DI3))
    assert [map_reading.is_height_channel(c) for c in reader.channels] == [True, False, False, True]
    default = load_height_map(DI3)
    assert default.source["channel_name"] == "ZSensor" and default.source["channel_chosen_as"].startswith("the closed")
    assert len(default.warnings) == 1 and "3 ('Height')" in default.warnings[0]
    for spec in ("Height", "height", 3):
        named = load_height_map(DI3, channel=spec)
        assert named.source["channel"] == 3 and named.warnings == ()
    expected = reader.topography(channel_index=3).to_unit("m").detrend("height").heights()
    np.testing.assert_allclose(load_height_map(DI3, channel="Height").heights, expected - expected.mean(),
                               rtol=0, atol=1e-9 * np.std(expected))


def _offset_lines(tmp_path: Path, offset_rms_nm: float, seed: int = 5) -> tuple[Path, Path, np.ndarray]:
    """(map with scan-line offsets, the same map without them, the offsets in nm): a 2 um Gaussian map, rms 1 nm,
    plus a random offset on each scan line (lines run along x: heights[:, j] + o_j) and a tilt."""
    surface = _fine(seed) * 1e9 + 0.02 * np.arange(128)[:, None]
    offsets = np.random.default_rng(seed).normal(0.0, offset_rms_nm, 128)
    return (_write_text_map(tmp_path / "lines.txt", surface + offsets[None, :]),
            _write_text_map(tmp_path / "clean.txt", surface), offsets)


def test_line_levelling_removes_scan_line_offsets_exactly_and_plane_warns(tmp_path):
    """Offsets of 3 nm rms on a 1 nm rms surface: 'plane' leaves them in, and warns with their share of the
    variance (computed here from SurfaceTopography's plane-levelled map); 'line' removes each line's offset and
    tilt, so the map with offsets levels to exactly the map without (a line fit removes a constant exactly), and
    is SurfaceTopography's scan_line_align; the variance each mode removed is the raw map's minus the result's."""
    from SurfaceTopography import open_topography

    noisy, clean, offsets = _offset_lines(tmp_path, 3.0)
    plane = load_height_map(noisy, detrend="plane")
    levelled = open_topography(str(noisy)).topography().to_unit("m").detrend("height").heights()
    share = np.var(levelled.mean(axis=0)) / np.var(levelled)
    record = plane.source["detrend"]
    assert record["mode"] == "plane" and share > 0.8
    assert record["line_offset_share_of_plane_levelled_variance"] == pytest.approx(share, rel=1e-9)
    assert len(plane.warnings) == 1 and f"{share:.0%}" in plane.warnings[0] and "'line'" in plane.warnings[0]

    line = load_height_map(noisy, detrend="line")
    assert line.warnings == () and line.source["detrend"]["mode"] == "line"
    np.testing.assert_allclose(line.heights, load_height_map(clean, detrend="line").heights, rtol=0,
                               atol=2e-13)           # the text files round heights to 1e-4 nm
    reference = open_topography(str(noisy)).topography().to_unit("m").scan_line_align(direction="x", mode="mean",
                                                                                         degree=1).heights()
    np.testing.assert_allclose(line.heights, reference - reference.mean(), rtol=0, atol=1e-15)
    raw = np.var(open_topography(str(noisy)).topography().to_unit("m").heights())
    for mode, result in (("plane", plane), ("line", line)):
        assert result.source["detrend"]["variance_removed_m2"] == pytest.approx(raw - np.var(result.heights),
                                                                               rel=1e-9), mode
    none = load_height_map(noisy, detrend="none")
    assert none.source["detrend"]["variance_removed_m2"] == pytest.approx(0.0, abs=1e-12 * raw)
    assert load_height_map(clean, detrend="plane").warnings == ()           # no offsets, no warning


# ----------------------------------------------------------------------------- summits without wrap (issue 41, 1)
def test_summits_of_a_non_periodic_crop_have_the_surface_s_density_and_wrapping_it_does_not():
    """Crops (512^2) of periodic self-affine Gaussian maps (1024^2, H 0.8, nothing below 4 px) are non-periodic
    scans of a surface whose summit density the full periodic maps give. Found as the map is (mirror-stitched,
    edge band trimmed: `map_summits`), the crops' pooled density matches the full maps' within 3/sqrt(N); taken as
    periodic, the filter rings at the wrap-around step and the count is high by more than that (audit 3,
    finding 1), so the comparison can tell the two apart."""
    n, m, size = 1024, 512, 1e-6
    dx = size / n
    counts = {"full": 0, "map": 0, "wrapped": 0}
    areas = {"full": 0.0, "map": 0.0, "wrapped": 0.0}
    for seed in range(3):
        h = np.asarray(fourier_synthesis((n, n), (size, size), 0.8, rms_height=1e-9, short_cutoff=4 * dx,
                                         rng=np.random.default_rng(seed), unit="m").heights())
        crop = h[:m, :m] - h[:m, :m].mean()
        hmap = HeightMap(heights=crop, pixel_size=(dx, dx), physical_size=(m * dx, m * dx), periodic=False,
                         rms_height=float(np.std(crop)))
        for name, s in (("full", identify_summits(h, dx, 8 * dx, periodic=True)), ("map", map_summits(hmap, 8 * dx)),
                        ("wrapped", identify_summits(crop, dx, 8 * dx, periodic=True))):
            counts[name] += s.count
            areas[name] += s.area
    density = {k: counts[k] / areas[k] for k in counts}
    tolerance = 3.0 / math.sqrt(counts["map"])
    assert density["map"] / density["full"] == pytest.approx(1.0, abs=tolerance)
    assert density["wrapped"] / density["full"] > 1.0 + 3.0 / math.sqrt(counts["wrapped"])


# ----------------------------------------------------------------------------- several scans, data depth (issue 41, 2)
def _two_scans(tmp_path: Path) -> tuple[Path, Path]:
    """Two scans of one periodic Gaussian surface (1 um, 1024^2, rms 10 nm): 'small', a 256^2 corner at full
    resolution (250 nm, pixel 0.98 nm), and 'large', the whole surface at every 4th point (1 um, pixel 3.9 nm)."""
    n = 1024
    h = np.asarray(fourier_synthesis((n, n), (1e-6, 1e-6), 0.8, rms_height=1e-8, short_cutoff=4e-6 / n,
                                     rng=np.random.default_rng(11), unit="m").heights()) * 1e9
    return (_write_text_map(tmp_path / "small.txt", h[:256, :256], size_um=0.25),
            _write_text_map(tmp_path / "large.txt", h[::4, ::4], size_um=1.0))


def test_several_scans_take_part_where_they_resolve_the_cutoff_and_their_summits_pool(tmp_path):
    """At 8 nm only the fine scan resolves the cutoff (the coarse one's 3.9 nm pixel would need 15.6 nm): the
    statistics are the fine scan's alone. At 31 nm both take part and their summits pool: count and area add up,
    the density is their ratio. At 200 nm the 250 nm scan spans too few cutoffs and sits out."""
    small, large = _two_scans(tmp_path)
    rough = {"topography": [str(small), str(large)], "summit_cutoff": 8e-9}
    fine = resolve_scene(table={**SCENE, "surfaces": {"roughness": rough}}).surface
    alone = resolve_scene(table={**SCENE, "surfaces": {"roughness": {**rough, "topography": str(small)}}}).surface
    assert [s["used"] for s in fine["scans"]] == [True, False] and "does not resolve" in fine["scans"][1]["why_not"]
    assert fine["summit_density"] == alone["summit_density"] and fine["summit_radius"] == alone["summit_radius"]
    resolved = resolve_scene(table={**SCENE, "surfaces": {"roughness": {**rough, "summit_cutoff": 3.125e-8}}})
    both = resolved.surface
    pooled = scene_scans(resolved.values, None)
    assert len(pooled.used) == 2 and pooled.summits.count == both["routes"]["direct"]["count"]
    assert [s["used"] for s in both["scans"]] == [True, True]
    n = sum(s["summits"] for s in both["scans"])
    area = sum(s["area"] for s in [both["routes"]["direct"]])
    assert both["routes"]["direct"]["count"] == n and both["summit_density"] == pytest.approx(n / area, rel=1e-12)
    # pooled, the scans of one Gaussian surface still meet Nayak's density from their (area-weighted) moments
    assert both["summit_density"] == pytest.approx(both["routes"]["spectral"]["summit_density"], rel=3 / math.sqrt(n))
    margin = [math.ceil(0.5 * 3.125e-8 / px) * px for px in (0.25e-6 / 256, 1e-6 / 256)]
    assert area == pytest.approx((0.25e-6 - 2 * margin[0]) ** 2 + (1e-6 - 2 * margin[1]) ** 2, rel=1e-9)
    used, record = scan_record(load_height_map(small), 2e-7)            # 250 nm spans 1.25 such cutoffs
    assert not used and "spans fewer than 2" in record["why_not"]
    assert scan_record(load_height_map(large), 2e-7)[0]


def test_data_depth_of_the_shipped_scan_against_the_closed_forms():
    """rough_afm_scan: the impact's tallest summit z solves the strip's closed forms (continuum.rough.datum):
    x_f^2 = 2 R (z + 3) sigma_s, N_f = 2 x_f l eta, z = Phi^-1(1 - 1/N_f); the map's tallest summit is recomputed
    from its summits, and the Gaussian's expected tallest of the map's N is Phi^-1(1 - 1/N)."""
    from scipy.special import ndtri

    r = resolve_scene("rough_afm_scan")
    block, depth = r.surface, r.surface["data_depth"]
    sigma, eta = block["summit_height_std"], block["summit_density"]
    z, n_f, x_f = depth["impact_tallest_summit_sigma"], depth["summits_in_footprint"], depth["footprint_half_width_m"]
    assert x_f**2 == pytest.approx(2 * 5e-6 * (z + FOOTPRINT_BAND) * sigma, rel=1e-9)
    assert n_f == pytest.approx(2 * x_f * 3.28e-3 * eta, rel=1e-12)
    assert z == pytest.approx(-ndtri(1.0 / n_f), abs=1e-9)
    hmap = load_height_map(DI3, channel="ZSensor", detrend="line")
    heights = map_summits(hmap, block["cutoff"]).height
    assert depth["summits_on_maps"] == heights.size
    assert depth["tallest_summit_sigma"] == pytest.approx((heights.max() - heights.mean()) / heights.std(), rel=1e-12)
    assert depth["gaussian_expected_tallest_of_map_sigma"] == pytest.approx(-ndtri(1.0 / heights.size), rel=1e-12)
    assert depth["tail_extrapolated"] == (z > depth["tallest_summit_sigma"])
    assert block["source"]["channel_name"] == "ZSensor" and block["source"]["detrend"]["mode"] == "line"


def test_a_gaussian_map_s_tallest_summit_is_where_the_extreme_value_closed_form_puts_it():
    """On a Gaussian surface the tallest of N summits lies near Phi^-1(1 - 1/N) sigma_s (the characteristic
    largest value; its Gumbel spread is about 1/u_N): the record's two numbers agree to within that spread."""
    s = Synthesis(hurst=0.8, rms_height=1e-9, short_cutoff=4e-6 / 512, size=1e-6, grid_points=512, seed=3,
                  long_cutoff=1e-7)
    pooled = pooled_statistics([load_height_map(synthesis=s)], 8e-6 / 512)
    depth = data_depth(pooled, pooled.statistics.summit_height_std, pooled.statistics.summit_density, 5e-6, 3.28e-3)
    u = depth["gaussian_expected_tallest_of_map_sigma"]
    assert depth["summits_on_maps"] > 500
    assert depth["tallest_summit_sigma"] == pytest.approx(u, abs=2.0 / u)


# ----------------------------------------------------------------------------- range of validity (issue 41, 5)
def test_validity_checks_carry_their_numbers_and_warn_where_the_model_is_stretched(tmp_path):
    """A 2 um map (rms 10 nm) at an 8-pixel cutoff: 35 summits (< FEW_SUMMITS) and beta/R between 0.1 and 1:
    two named warnings, each with its numbers, and the checks recorded with value, limit and verdict."""
    path = _write_text_map(tmp_path / "few.txt", _fine(9) * 1e10)
    block = resolve_scene(table={**SCENE, "surfaces": {"roughness": {"topography": str(path),
                                                                     "summit_cutoff": 1.25e-7}}}).surface
    checks = {c["check"]: c for c in block["validity"]}
    ratio = block["summit_radius"] / 5e-6
    n = block["routes"]["direct"]["count"]
    assert 0.1 < ratio < 1.0 and n < FEW_SUMMITS
    assert checks["summit_radius_over_body_radius"]["value"] == pytest.approx(ratio, rel=1e-12)
    assert checks["summit_radius_over_body_radius"]["verdict"] == "warning"
    assert checks["summits_on_maps"] == {"check": "summits_on_maps", "value": n, "limit": FEW_SUMMITS,
                                         "verdict": "warning"}
    assert checks["map_side_over_cutoff"]["value"] == pytest.approx(2e-6 / 1.25e-7) and \
        checks["map_side_over_cutoff"]["verdict"] == "ok"
    text = " | ".join(block["warnings"])
    assert f"{ratio:.2g} of body.radius" in text and f"hold {n} summits" in text
    assert f"{1 / math.sqrt(n):.0%}" in text


def test_an_energy_audit_above_the_scene_s_tolerance_warns_with_its_numbers():
    """numerics.audit_tolerance: a run whose audit error exceeds it carries a warning with the error; one below
    it (the same audit against a looser tolerance) carries none; unset, nothing is checked."""
    from dataclasses import replace

    from continuum import run_scene
    from continuum.output.notices import audit_warnings

    r = run_scene("rough_afm_scan", overrides={"numerics.max_bounces": 1, "numerics.fidelity": "fast",
                                               "numerics.audit_tolerance": 1e-15})
    error = r.record["energy_audit"]["max_relative_error"]
    assert 1e-15 < error < 1.0
    assert [w for w in r.record["warnings"] if w.startswith(f"energy audit error {error:.3g} ")]
    scene = resolve_scene("rough_afm_scan").scene
    assert scene.numerics.audit_tolerance is None and audit_warnings(scene, r.record["energy_audit"]) == []
    loose = replace(scene, numerics=replace(scene.numerics, audit_tolerance=min(1.0, 2 * error)))
    assert audit_warnings(loose, r.record["energy_audit"]) == []


def test_the_shipped_afm_scene_runs_and_result_json_carries_the_reading_warnings():
    """rough_afm_scan runs (one impact) on the real scan; without its channel named, the run's result.json
    warnings hold the channel warning from the surface block."""
    from continuum import run_scene
    from continuum.scene import read_toml

    table = read_toml(ROOT / "inputs" / "scenes" / "rough_afm_scan.toml")
    del table["surfaces"]["roughness"]["topography_channel"]
    table["numerics"] = {"max_bounces": 1, "fidelity": "fast"}
    r = run_scene(table)
    assert r.record["surface"]["source"]["channel_name"] == "ZSensor"
    assert any("3 ('Height')" in w for w in r.record["warnings"])
    assert set(r.record["surface"]["warnings"]) <= set(r.record["warnings"])
