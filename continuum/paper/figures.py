"""Figures mirroring the paper's Figs 4, 5a, 5b, 6, 7 and 8a, and the CSV data behind each.

Every function takes the collected runs, writes `data/<fig>.csv` and returns the figure's axes
(the caller saves them). Display units (nm, ns, us, MPa, uN) are converted here only.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.transforms import blended_transform_factory

from nanoimpact.fileio import atomic_save_figure

from ..output.plots import PNG_FAST
from ..output.results import load_result


def _subplots(*args, figsize, **kw):
    """A new figure and its axes through the object API (no pyplot state, no backend switch)."""
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(*args, **kw)


def write_csv(path: Path, header: list[str], rows) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    with tmp.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)
    tmp.replace(path)


def characteristic(surface, depth_sigmas: float = 2.0, n: int = 400) -> dict:
    """Fig 4: nominal pressure on a first approach to z_max - depth and on the retreat from it.

    Approach: nothing attached yet (zeta* = inf, so zeta_eff = d). Retreat from d_min: zeta* = d_min,
    zeta_eff = max(d_min, d - release stretch). Loop area = closed integral of p dd (J/m^2).
    """
    sigma = surface.stats.sigma
    top = float(surface.z_max)
    d_min = top - depth_sigmas * sigma
    d = np.linspace(d_min, top + 1.2 * surface.release_stretch, n)
    p_app = surface.pressure(d, np.full_like(d, np.inf))
    p_ret = surface.pressure(d, np.full_like(d, d_min))
    loop = float(np.trapezoid(p_app - p_ret, d))
    return {"d": d, "h": (d - top) / sigma, "approach": p_app, "retreat": p_ret, "loop_area": abs(loop)}


def fig4(curves: dict, set_name: str, out: Path):
    fig, axes = _subplots(1, 2, figsize=(10, 3.8))
    for ax, key, title in ((axes[0], "silica", "(a) silica surfaces"), (axes[1], "ots", "(b) SAM on silica")):
        c = curves[key]
        ax.plot(c["h"], c["approach"] / 1e6, label="approach (p_L=0)")
        ax.plot(c["h"], c["retreat"] / 1e6, "--", label="retreat (p_L=-1)")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel("gap below the tallest summit, (d - z_max)/sigma")
        ax.set_ylabel("nominal pressure (MPa)")
        ax.set_title(f"{title}: loop {c['loop_area']:.3g} J/m^2", fontsize=9)
        ax.legend(fontsize=7)
        write_csv(out / "data" / f"fig4_{key}_{set_name}.csv", ["d_m", "h_over_sigma", "p_approach_Pa", "p_retreat_Pa"],
                  zip(c["d"], c["h"], c["approach"], c["retreat"]))
    fig.suptitle(f"Fig 4 ({set_name}): pressure-gap characteristics", fontsize=10)
    return axes[0]


def fig5a(impacts: dict, set_name: str, out: Path):
    fig, ax = _subplots(figsize=(8, 3.8))
    rows = []
    for case, style in (("hertz", "-"), ("rough_silica", "-"), ("rough_ots", "-")):
        if case not in impacts:
            continue
        ts = load_result(impacts[case]["folder"]).timeseries()
        ax.plot(ts["t"] * 1e3, ts["gap"] * 1e9, style, lw=0.8, label=case)
        rows += [(case, t, g) for t, g in zip(ts["t"], ts["gap"])]
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("height above datum (nm)")
    ax.set_title(f"Fig 5a ({set_name}): rebounds of smooth, rough and OTS-covered silicon", fontsize=10)
    ax.legend(fontsize=8)
    write_csv(out / "data" / f"fig5a_{set_name}.csv", ["case", "t_s", "gap_m"], rows)
    return ax


def fig5b(impacts: dict, set_name: str, out: Path):
    fig, ax = _subplots(figsize=(8, 3.8))
    rows = []
    for case in ("hertz", "rough_silica", "rough_ots"):
        if case not in impacts:
            continue
        res = impacts[case]["result"]
        ts = load_result(impacts[case]["folder"]).timeseries()
        b = res["bounces"][0]
        sel = ts["phase"] == 0
        t = (ts["t"][sel] - b["t_contact"]) * 1e9
        ax.plot(t, ts["force"][sel] * 1e6, lw=1.0, label=f"{case} (first impact)")
        rows += [(case, tt * 1e-9, f) for tt, f in zip(t, ts["force"][sel])]
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_xlabel("time since touch (ns)")
    ax.set_ylabel("contact force (uN)")
    ax.set_title(f"Fig 5b ({set_name}): first impact duration and force", fontsize=10)
    ax.legend(fontsize=8)
    write_csv(out / "data" / f"fig5b_{set_name}.csv", ["case", "t_since_touch_s", "force_N"], rows)
    return ax


def fig6(impacts: dict, set_name: str, out: Path):
    res = impacts.get("fig6_halfspace", impacts["rough_silica"])["result"]
    prof = res["bounces"][0].get("profiles") or {}
    fig, axes = _subplots(2, 2, figsize=(10, 6), sharex="col")
    rows = []
    for col, key, title in ((0, "max_approach", "(a) maximum approach"), (1, "pull_off", "(b) pull-off")):
        if key not in prof:
            axes[0, col].set_title(f"{title}: not reached")
            continue
        p = prof[key]
        x = np.asarray(p["x"]) * 1e6
        axes[0, col].plot(x, np.asarray(p["pressure"]) / 1e6)
        axes[0, col].axhline(0, color="k", lw=0.5)
        axes[0, col].set_ylabel("pressure (MPa)")
        axes[0, col].set_title(f"{title}: net force {p['force'] * 1e6:.3g} uN", fontsize=9)
        axes[1, col].plot(x, np.asarray(p["deflection"]) * 1e15)
        axes[1, col].set_ylabel("half-space deflection (fm)")
        axes[1, col].set_xlabel("x across the contact (um)")
        rows += [(key, xx * 1e-6, pp, dd, ss) for xx, pp, dd, ss in
                 zip(x, p["pressure"], p["deflection"], p["separation"])]
    fig.suptitle(f"Fig 6 ({set_name}): rough silica, first impact", fontsize=10)
    write_csv(out / "data" / f"fig6_{set_name}.csv", ["instant", "x_m", "pressure_Pa", "deflection_m", "separation_m"],
              rows)
    return axes[0, 0]


def fig7(impacts: dict, set_name: str, out: Path):
    fig, ax = _subplots(figsize=(8, 3.8))
    rows = []
    entries = []
    for case, item in impacts.items():
        res = item["result"]
        if (res["scene"]["si"]["contact"] != "rough" or res["scene"]["si"]["surfaces"]["sam"] is not None
                or case == "fig6_halfspace"):
            continue
        entries.append((res["scene"]["si"]["surfaces"]["roughness"]["sigma"], res))
    h0 = None
    for sigma, res in sorted(entries, key=lambda e: e[0]):
        h0 = res["scene"]["si"]["release_height"]
        heights = [0.0 if b["rebound_height"] is None else b["rebound_height"] for b in res["bounces"]]
        ax.plot(np.arange(1, len(heights) + 1), np.asarray(heights) / h0, "o-", ms=3, label=f"sigma {sigma * 1e9:g} nm")
        rows += [(sigma, i + 1, h) for i, h in enumerate(heights)]
    if h0:
        ax.axhline(1.0, color="k", ls="--", lw=0.8, label="Hertz")
    ax.set_xlabel("bounce")
    ax.set_ylabel("rebound height / release height")
    ax.set_xscale("log")
    ax.set_title(f"Fig 7 ({set_name}): influence of roughness", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    write_csv(out / "data" / f"fig7_{set_name}.csv", ["sigma_m", "bounce", "rebound_height_m"], rows)
    return ax


def fig8a(sweeps: dict, set_name: str, out: Path, wet: dict | None = None, ax=None):
    """Impact time against impact velocity (mm/s, us): dry curves (Hertz, sigma 3-30 nm) with their escape
    velocities, the t_a line, and the humid sigma = 6 nm sweep near escape (menisci forced on). Crosses: sticks."""
    if ax is None:
        _, ax = _subplots(figsize=(8.5, 5))
    edge = blended_transform_factory(ax.transData, ax.transAxes)
    rows = []
    for case, s in sorted(sweeps.items(), key=lambda kv: (kv[1]["sigma"] or 0.0)):
        label = "Hertz (dry)" if s["sigma"] is None else f"sigma {s['sigma'] * 1e9:g} nm (dry)"
        pts = [p for p in s["points"] if not p["stuck"]]
        stuck = [p for p in s["points"] if p["stuck"]]
        color = None
        if pts:
            line, = ax.loglog([p["v_impact"] * 1e3 for p in pts], [p["duration"] * 1e6 for p in pts], "o-", ms=3,
                              label=label)
            color = line.get_color()
        if stuck:  # a stuck impact never ends: cross at the bottom edge, at its impact velocity
            ax.plot([p["v_impact"] * 1e3 for p in stuck], [0.02] * len(stuck), "x", color=color or "k", ms=5,
                    transform=edge)
        found = (s["escape"] or {}).get("escape_velocity")
        if found and color is not None:
            ax.axvline(s["escape"]["escape_velocity"] * 1e3, color=color, ls=":", lw=0.8)
        rows += [(case, s["sigma"], p["v_impact"], p["v_rebound"], p["duration"], p["stuck"]) for p in s["points"]]
        if found:
            rows.append((case, s["sigma"], s["escape"]["escape_velocity"], "escape_velocity", "", ""))
    si = (wet or {}).get("wet_silica")
    t_a = si["condensation_time"] if si and si["menisci_possible"] else None
    if t_a is not None:
        pts = si["points"]
        dry_free = [p for p in pts if not p["dry"]["stuck"]]
        ax.loglog([p["v_impact"] * 1e3 for p in dry_free], [p["dry"]["duration"] * 1e6 for p in dry_free], "s",
                  mfc="none", mec="k", ms=4, label="sigma 6 nm near escape, dry")
        wet_free = [p for p in pts if not p["wet"]["stuck"]]
        ax.loglog([p["v_impact"] * 1e3 for p in wet_free], [p["wet"]["duration"] * 1e6 for p in wet_free], "s",
                  color="tab:blue", ms=2.5, label="sigma 6 nm with menisci (40 % RH): rebounds")
        # a stuck wet impact never ends: mark it at the time the dry impact would have lasted
        wet_stuck = [p for p in pts if p["wet"]["stuck"] and not p["dry"]["stuck"]]
        if wet_stuck:
            ax.loglog([p["v_impact"] * 1e3 for p in wet_stuck], [p["dry"]["duration"] * 1e6 for p in wet_stuck], "x",
                      color="tab:red", ms=7, mew=1.5, label="with menisci: sticks (at its dry impact time)")
        for esc, ls, name in ((si["escape_dry"], "--", "dry"), (si["escape_wet"], "-", "wet")):
            if esc and esc.get("escape_velocity"):
                ax.axvline(esc["escape_velocity"] * 1e3, color="tab:red" if name == "wet" else "k", ls=ls, lw=0.8,
                           label=f"sigma 6 nm escape velocity, {name}: {esc['escape_velocity'] * 1e3:.4g} mm/s")
        ax.axhline(t_a * 1e6, color="k", ls=":", lw=1.2, label=f"t_a = {t_a * 1e6:g} us (condensation time)")
        rows += [("wet_silica_dry", si["sigma"], p["v_impact"], p["dry"]["v_rebound"], p["dry"]["duration"],
                  p["dry"]["stuck"]) for p in pts]
        rows += [("wet_silica_menisci", si["sigma"], p["v_impact"], p["wet"]["v_rebound"], p["wet"]["duration"],
                  p["wet"]["stuck"]) for p in pts]
        for name, esc in (("wet_silica_dry", si["escape_dry"]), ("wet_silica_menisci", si["escape_wet"])):
            if esc and esc.get("escape_velocity"):
                rows.append((name, si["sigma"], esc["escape_velocity"], "escape_velocity", "", ""))
    ax.set_xlabel("impact velocity (mm/s)")
    ax.set_ylabel("impact time (us)")
    ax.set_title(f"Fig 8a ({set_name}): impact time against impact velocity; x: sticks (dry: on the bottom edge); "
                 "dotted verticals: dry escape velocities", fontsize=8)
    ax.legend(fontsize=6, loc="upper right")
    write_csv(out / "data" / f"fig8a_{set_name}.csv",
              ["case", "sigma_m", "v_impact_m_per_s", "v_rebound_m_per_s", "duration_s", "stuck"], rows)
    return ax


def fig8b(wet: dict, set_name: str, out: Path, ax=None):
    """Bare (wet) vs OTS-covered silica, sigma = 6 nm: impact time against rebound velocity (the paper's
    axes) and, on a second panel, against impact velocity (where the claim is read), down to escape."""
    if ax is None:
        _, (ax, ax2) = _subplots(1, 2, figsize=(11, 4.5))
    else:
        ax2 = None
    rows = []
    for case, label, key in (("wet_silica", "bare silica, 40 % RH", "wet"), ("wet_ots", "OTS-covered", "dry")):
        s = wet.get(case)
        if not s:
            continue
        k = key if key in s["points"][0] else "dry"
        pts = [p for p in s["points"] if not p[k]["stuck"]]
        esc = s["escape_wet"] if k == "wet" else s["escape_dry"]
        if esc and esc.get("escape_velocity"):
            v = esc["escape_velocity"]
            label += f" (escape {v * 1e3:.3g} mm/s, limiting gap {v * v / (2 * s['gravity']) * 1e9:.3g} nm)"
        line, = ax.loglog([p[k]["v_rebound"] * 1e3 for p in pts], [p[k]["duration"] * 1e6 for p in pts], "o-", ms=3,
                          label=label)
        if ax2 is not None:
            ax2.loglog([p["v_impact"] * 1e3 for p in pts], [p[k]["duration"] * 1e6 for p in pts], "o-", ms=3,
                       color=line.get_color(), label=label)
            if esc and esc.get("escape_velocity"):
                ax2.axvline(esc["escape_velocity"] * 1e3, color=line.get_color(), ls=":", lw=0.8)
        if esc and esc.get("escape_velocity"):
            rows.append((case, "escape_velocity", esc["escape_velocity"], "", ""))
        rows += [(case, k, p["v_impact"], p[k]["v_rebound"], p[k]["duration"]) for p in pts]
    ax.set_xlabel("rebound velocity (mm/s)")
    ax.set_ylabel("impact time (us)")
    ax.set_title(f"Fig 8b ({set_name}): 2 nm OTS on 6 nm silica against bare silica", fontsize=9)
    ax.legend(fontsize=7, title="limiting gap = v_esc^2 / 2g", title_fontsize=7)
    if ax2 is not None:
        ax2.set_xlabel("impact velocity (mm/s)")
        ax2.set_ylabel("impact time (us)")
        ax2.set_title("same runs against impact velocity; dotted: escape velocities", fontsize=9)
    write_csv(out / "data" / f"fig8b_{set_name}.csv",
              ["case", "branch", "v_impact_m_per_s", "v_rebound_m_per_s", "duration_s"], rows)
    return ax


def save(ax, path: Path) -> None:
    """Save the figure of `ax` as PNG, atomically (nanoimpact.fileio), with the run figures' fast compression."""
    fig = ax.figure
    fig.tight_layout()
    atomic_save_figure(fig, path, dpi=110, pil_kwargs=PNG_FAST)
