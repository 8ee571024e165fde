"""Figures of an impact run. Functions take `ax=None`, return the axes and never call plt.show().

Figures are built with matplotlib's object API (`matplotlib.figure.Figure`), never through pyplot's
global state, so importing this module never switches a user's backend (a notebook keeps its own).

Plot units (nm, ns, ms, uN) are converted here, at the edge; data stay in SI.
"""
from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.figure import Figure

from nanoimpact.fileio import atomic_save_figure


def height_vs_time(trace: dict, ax=None, label: str | None = None):
    """Gap of the body's lowest point (nm) against time (ms)."""
    ax = ax or Figure(figsize=(7, 3.5)).subplots()
    ax.plot(np.asarray(trace["t"]) * 1e3, np.asarray(trace["gap"]) * 1e9, lw=1.0, label=label)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("height above datum (nm)")
    ax.grid(alpha=0.3)
    return ax


def force_vs_time(trace: dict, bounces: list[dict], ax=None, max_impacts: int = 12):
    """Contact force (uN) against time since touch (ns), one line per impact."""
    ax = ax or Figure(figsize=(7, 3.5)).subplots()
    t = np.asarray(trace["t"])
    force = np.asarray(trace["force"])
    phase = np.asarray(trace["phase"])
    cmap = matplotlib.colormaps["viridis"]
    shown = bounces[:max_impacts]
    for k, b in enumerate(shown):
        sel = phase == b["index"]
        if not np.any(sel):
            continue
        ax.plot((t[sel] - b["t_contact"]) * 1e9, force[sel] * 1e6, lw=1.0,
                color=cmap(k / max(len(shown) - 1, 1)), label=f"impact {b['index'] + 1}")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("time since touch (ns)")
    ax.set_ylabel("contact force (uN)")
    ax.grid(alpha=0.3)
    if shown:
        ax.legend(fontsize=7, ncol=2)
    return ax


def ensemble_spread(ensemble: dict, ax=None, band: list | None = None):
    """An ensemble's members: first rebound height / h0 against the member's number of rebounds (one dot per
    member, jittered sideways), with the mean-field run's point and the stick probabilities in the legend. Where
    the ensemble has escape velocities (and no `ax` is given), a panel shows their distribution
    (`escape_velocity_spread`); with a height map's cutoff `band` (result.json -> surface.cutoff_band), a panel
    shows it (`cutoff_band_panel`)."""
    escape = ensemble.get("escape_velocity") or {}
    if ax is None and (escape.get("m_per_s") or band):
        extra = [f for f, on in ((escape_velocity_spread, escape.get("m_per_s")), (cutoff_band_panel, band)) if on]
        axes = Figure(figsize=(7 + 4 * len(extra), 3.5)).subplots(
            1, 1 + len(extra), gridspec_kw={"width_ratios": (3,) + (2,) * len(extra), "wspace": 0.3})
        ax = axes[0]
        for draw, right in zip(extra, axes[1:]):
            draw(band if draw is cutoff_band_panel else ensemble, right)
    ax = ax or Figure(figsize=(7, 3.5)).subplots()
    runs = ensemble["member_runs"]
    h0 = ensemble.get("release_height_m") or 1.0
    counts = np.array([m["rebounds"] for m in runs], float)
    first = np.array([m["rebound_heights"][0] if m["rebound_heights"] else 0.0 for m in runs]) / h0
    jitter = np.random.default_rng(0).uniform(-0.15, 0.15, counts.size)     # display only
    p = ensemble["stick_probability"]
    ax.plot(counts + jitter, first, "o", ms=3, alpha=0.6, color="C0",
            label=f"{len(runs)} members: stuck at 1st impact {p['first_impact']['value']:.2f}, "
                  f"within the run {p['within_run']['value']:.2f}"
                  + (f" ({p['within_run']['censored']} censored)" if p["within_run"].get("censored") else ""))
    mf = ensemble.get("mean_field")
    if mf is not None:
        ax.plot([mf["rebounds"]], [mf["first_rebound_m"] / h0], "*", ms=12, color="C3", label="mean field")
    ax.set_xlabel("rebounds before the run ended")
    ax.set_ylabel("first rebound / release height" if ensemble.get("release_height_m") else "first rebound (m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


def cutoff_band_panel(band: list, ax=None):
    """The stick probability at the first impact (Wilson 95 % bars) against the summit cutoff of a height map's
    band (result.json -> surface.cutoff_band), the run's own cutoff marked; each point labelled with beta."""
    ax = ax or Figure(figsize=(5, 3.5)).subplots()
    done = [e for e in band if e.get("evaluated")]
    c = np.array([e["cutoff"] for e in done]) * 1e9
    p = np.array([e["stick_probability"]["value"] for e in done])
    lo = p - np.array([(e["stick_probability"]["interval"] or [v])[0] for e, v in zip(done, p)])
    hi = np.array([(e["stick_probability"]["interval"] or [v, v])[1] for e, v in zip(done, p)]) - p
    ax.errorbar(c, p, yerr=[lo, hi], fmt="o-", color="C0", capsize=3, label="stuck at the 1st impact")
    for e, x, y in zip(done, c, p):
        beta = e["summit_radius"]
        ax.annotate(f"beta {beta * 1e9:.3g} nm" if beta < 1e-6 else f"beta {beta * 1e6:.3g} um", (x, y),
                    textcoords="offset points", xytext=(-20, -14 if y > 0.5 else 8), fontsize=7)
    own = [e["cutoff"] * 1e9 for e in band if e["factor"] == 1.0]
    if own:
        ax.axvline(own[0], color="C3", lw=1, label="the run's cutoff")
    ax.axhline(0.5, color="k", lw=0.5, ls=":")
    ax.set_xscale("log")
    ax.set_xlabel("summit cutoff (nm)")
    ax.set_ylabel("stick probability")
    ax.set_ylim(-0.05, 1.08)
    ax.margins(x=0.15)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


def escape_velocity_spread(ensemble: dict, ax=None):
    """The members' escape velocities (mm/s) as an empirical distribution (fraction of members whose escape
    velocity is at most v), with the 5-95 % band and the median of result.json -> ensemble -> escape_velocity."""
    ax = ax or Figure(figsize=(5, 3.5)).subplots()
    rec = ensemble["escape_velocity"]
    v = np.sort([m["escape"]["escape_velocity"] for m in ensemble["member_runs"]
                 if (m.get("escape") or {}).get("escape_velocity") is not None]) * 1e3
    q = rec["m_per_s"]
    ax.step(v, np.arange(1, v.size + 1) / v.size, where="post", color="C0",
            label=f"{v.size} members (bracket {rec['rel_tol']:.0e} relative)")
    ax.axvspan(q["p5"] * 1e3, q["p95"] * 1e3, color="C0", alpha=0.15, label="5-95 %")
    ax.axvline(q["p50"] * 1e3, color="C3", lw=1, label="median")
    ax.set_xlabel("escape velocity (mm/s)")
    ax.set_ylabel("fraction of members")
    ax.set_ylim(0.0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return ax


#: Margins of the run figures (one axes on 7 x 3.5 in): room for 6-character tick labels, the axis labels and a
#: title. Fixed instead of `tight_layout`, which measured every text extent (0.15 s a figure, a third of the
#: cost of writing a run's figures).
RUN_FIGURE_MARGINS = dict(left=0.11, right=0.98, bottom=0.14, top=0.9)
#: PNG compression: zlib level 1 is ~3x faster to encode than matplotlib's default 6 for these line plots and
#: the files stay small (tens of kB).
PNG_FAST = {"compress_level": 1}


def save(ax, path, title: str | None = None) -> None:
    """Save the figure of `ax` to `path` (PNG, atomically)."""
    fig = ax.figure
    if title:
        ax.set_title(title, fontsize=10)
    fig.subplots_adjust(**RUN_FIGURE_MARGINS)
    atomic_save_figure(fig, path, dpi=120, pil_kwargs=PNG_FAST)
