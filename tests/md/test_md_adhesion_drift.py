"""The adhesion analysis's checks on its series: the linear drift test (calibrated stderr, not fooled by a fast
oscillation, drawn on the anneal figure), the chain tilt across periodic boundaries, the hysteresis estimate.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

# ------------------------------------------------------------------------------------ drift, tilt, hysteresis

def _ar1(rng, n, phi):
    x = np.zeros(n)
    e = rng.normal(size=n)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_linear_drift_flags_a_drifting_series_and_its_stderr_is_calibrated():
    """On stationary AR(1) series (phi = 0.9, g = 19) the slope's stderr matches the scatter of the slopes over
    300 seeds (ratio within 0.7-1.3) and at most about 5 % are flagged (1-13 %: the binomial scatter plus the bias
    of an estimated g; both tests must agree, so fewer than either alone); a trend of 0.01 per step (1 sd of the
    noise every 230 steps) is flagged on every seed."""
    from md.analysis.drift import linear_drift
    rng = np.random.default_rng(7)
    t = np.arange(1000.0)
    res = [linear_drift(t, _ar1(rng, 1000, 0.9)) for _ in range(300)]
    slopes = np.array([r["slope"] for r in res])
    assert np.median([r["slope_stderr"] for r in res]) / slopes.std() == pytest.approx(1.0, abs=0.3)
    assert 0.01 <= np.mean([r["drifting"] for r in res]) <= 0.13
    for _ in range(20):
        r = linear_drift(t, _ar1(rng, 1000, 0.9) + 0.01 * t)
        assert r["drifting"] and r["drift"] == pytest.approx(10.0, abs=4 * r["drift_stderr"])
    with pytest.raises(ValueError):
        linear_drift([0.0, 1.0], [1.0, 2.0])


def test_linear_drift_is_not_fooled_by_a_fast_oscillation_over_a_slow_fluctuation():
    """An MD energy's shape: a fast oscillation (AR(2), period 8 samples, its autocorrelation negative within 3
    samples) over a slow AR(1) (phi = 0.98, correlation time 50 samples, a fifth of a 250-sample block). The ACF
    stderr stops at the oscillation's first zero and is under half the slopes' true scatter over 300 seeds, so the
    ACF test alone flags over a quarter of these stationary series; the block-means stderr tracks the scatter
    (0.7-1.3) and the combined test flags about its nominal 5 % (at most 12 %: binomial scatter over 300 seeds
    plus blocks that are only five correlation times long). A trend of 5 block-stderrs is still caught on 9 seeds in
    10."""
    from scipy.signal import lfilter

    from md.analysis.drift import linear_drift
    rng = np.random.default_rng(11)
    n, t = 2000, np.arange(2000.0)
    w = 2.0 * np.pi / 8.0

    def series():
        fast = lfilter([3.0], [1.0, -1.9 * np.cos(w), 0.95 ** 2], rng.normal(size=n))
        return fast + lfilter([1.0], [1.0, -0.98], rng.normal(size=n))

    res = [linear_drift(t, series()) for _ in range(300)]
    slopes = np.array([r["slope"] for r in res])
    assert np.median([r["slope_stderr_acf"] for r in res]) / slopes.std() < 0.5
    assert np.mean([abs(r["slope"]) > r["z_max"] * r["slope_stderr_acf"] for r in res]) > 0.25
    assert np.median([r["slope_stderr"] for r in res]) / slopes.std() == pytest.approx(1.0, abs=0.3)
    assert np.mean([r["drifting"] for r in res]) <= 0.12
    trend = 5.0 * np.median([r["slope_stderr_blocks"] for r in res])
    assert np.mean([linear_drift(t, series() + trend * t)["drifting"] for _ in range(50)]) >= 0.9


def test_anneal_figure_draws_the_drift_tests_line_and_says_what_it_concluded():
    """The anneal figure plots energy and tilt with the second half's fitted line: the dashed energy line has the
    drift test's slope, and the title names the drifting series (energy trends, tilt is flat) or says none."""
    from matplotlib.figure import Figure

    from md.analysis.drift import linear_drift
    from md.workflows.adhesion_protocol import draw_anneal
    rng = np.random.default_rng(3)
    t, tt = np.linspace(0.0, 150.0, 1500), np.linspace(3.0, 150.0, 50)

    def det(trend):
        pe, tilt = -6e4 + _ar1(rng, 1500, 0.5) - trend * t, 25.0 + rng.normal(size=50)
        h, k = len(t) // 2, len(tt) // 2
        return {"time_ps": t, "potential_energy_kcal": pe, "tilt_time_ps": tt, "mean_tilt_deg": tilt,
                "drift_second_half": {"potential_energy_kcal": linear_drift(t[h:], pe[h:]),
                                      "mean_tilt_deg": linear_drift(tt[k:], tilt[k:])}}

    for trend, title in ((0.5, "still drifting: potential_energy_kcal"), (0.0, "no drift")):
        d = det(trend)
        ax = Figure().subplots()
        draw_anneal(ax, d)
        assert title in ax.get_title()
        x, y = ax.lines[1].get_data()
        assert ax.lines[1].get_linestyle() == "--" and x[0] == pytest.approx(t[len(t) // 2])
        assert np.polyfit(x, y, 1)[0] == pytest.approx(d["drift_second_half"]["potential_energy_kcal"]["slope"])


def test_chain_tilt_follows_an_axis_that_reaches_further_sideways_than_half_the_box():
    """Two chains (one on the upper slab, pointing down) tilting from 15 to 40 deg over 26 frames in a 12 A box,
    positions wrapped: a 20 A axis at 40 deg reaches 12.9 A sideways, beyond the minimum image; the tilt is the
    exact angle in every frame."""
    from md.workflows.adhesion_protocol import chain_tilts_deg
    box = np.array([[12.0, 12.0, 80.0]] * 26)
    L = 20.0
    angles = np.radians(np.linspace(15.0, 40.0, 26))
    heads = np.array([[9.5, 5.0, 0.0], [2.0, 2.0, 50.0]])
    pos = []
    for t in angles:
        ends = np.array([[9.5 + L * math.sin(t), 5.0, L * math.cos(t)],
                         [2.0, 2.0 - L * math.sin(t), 50.0 - L * math.cos(t)]])
        frame = np.vstack([heads, ends])
        frame[:, :2] %= 12.0
        pos.append(frame)
    tilts = chain_tilts_deg(np.array([1, 2, 3, 4]), np.array(pos), box, np.array([[0, 2], [1, 3]]))
    assert tilts == pytest.approx(np.degrees(angles), abs=1e-9)


def test_hysteresis_is_the_difference_and_the_estimate_the_mean():
    from md.analysis import hysteresis
    h = hysteresis(0.066, 0.004, 0.046, 0.003)
    assert h["hysteresis"] == pytest.approx(0.020) and h["value"] == pytest.approx(0.056)
    assert h["systematic"] == pytest.approx(0.010) and h["stderr"] == pytest.approx(0.0025)
    assert h["hysteresis_stderr"] == pytest.approx(0.005)
