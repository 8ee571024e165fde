"""The literature's own range for each MD-calibrated value, the wider window the calibration accepts, and where a
calibrated value lies against both.

A :class:`Target` keeps two things apart. ``low``-``high`` is the range the cited source itself gives (``source``);
a value is reported "inside the literature range" only when it lies there. ``accept_low``-``accept_high`` is the
calibration's acceptance window, a declared choice with its reason (``accept_reason``): MD with published force
fields is not fitted to these quantities, so the window allows a stated margin around the literature. Nothing is
tuned to move a value into either. :func:`verdict` places a value with its stderr against both;
:func:`comparison_lines` and :func:`range_cell` give the report's words for it; :func:`target_figure` draws the
values against the ranges (``md_vs_literature.png`` of a calibration). A key without a literature value (the
silica-silica work of adhesion of this IFF surface) has no target and the report says so.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence


@dataclass(frozen=True)
class Target:
    """The literature's range [low, high] for scene key `key` in its SI unit `unit`, cited in `source`, and the
    calibration's acceptance window [accept_low, accept_high] (the literature range where not given) with its
    reason. low == high is a single published value."""

    key: str
    low: float
    high: float
    unit: str
    source: str
    accept_low: float | None = None
    accept_high: float | None = None
    accept_reason: str = ""

    @property
    def window(self) -> tuple[float, float]:
        """The acceptance window (low, high)."""
        return (self.low if self.accept_low is None else self.accept_low,
                self.high if self.accept_high is None else self.accept_high)


@dataclass(frozen=True)
class Verdict:
    """Where a value with its stderr lies against a target.

    `inside`: inside the literature range [low, high]. `distance_sigma`: 0 inside it; else (value - nearest
    bound) / stderr, positive above the range, negative below (infinite when the stderr is 0 or missing).
    `inside_2sigma`: the literature range is within two stderrs of the value. `accepted`: inside the acceptance
    window (which contains the literature range)."""

    inside: bool
    distance_sigma: float
    inside_2sigma: bool
    text: str
    accepted: bool = False


_ACCEPT = ("acceptance window, a choice: MD with published force fields that were not fitted to this quantity "
           "is accepted within this margin of the literature")
_CH3 = ("2 gamma_CH3 with gamma_CH3 = 20-24 mJ/m^2, the surface free energy quoted for close-packed "
        "CH3-terminated monolayers, so 0.040-0.048 J/m^2")
_SILICA_ANGLE = ("water on clean hydroxylated silica: below 10-20 deg in experiment; IFF Q3 surfaces at 4.7 "
                 "OH/nm^2 are wetted (Emami et al., Chem. Mater. 26 (2014) 2647)")
_Z0 = ("the contact separation D0 = 0.165 nm that gives surface energies from Hamaker constants (Israelachvili, "
       "Intermolecular and Surface Forces, 3rd ed. (2011)) to the equilibrium spacing of about 0.3 nm usual in "
       "Tabor's parameter (Tabor, J. Colloid Interface Sci. 58 (1977) 2; Johnson & Greenwood, J. Colloid "
       "Interface Sci. 192 (1997) 326)")

#: One target per calibrated scene key (SI units). Angles in degrees, as the scene keys take them.
TARGETS: tuple[Target, ...] = (
    Target("surfaces.sam.work_of_adhesion", 0.040, 0.048, "J/m^2", _CH3, 0.035, 0.060, _ACCEPT),
    Target("surfaces.body.contact_angle", 0.0, 20.0, "deg", _SILICA_ANGLE, 0.0, 30.0, _ACCEPT),
    Target("surfaces.substrate.contact_angle", 0.0, 20.0, "deg", _SILICA_ANGLE, 0.0, 30.0, _ACCEPT),
    Target("surfaces.sam.contact_angle", 105.0, 112.0, "deg",
           "105-112 deg advancing, water on OTS (Wasserman et al., Langmuir 5 (1989) 1074)", 105.0, 120.0, _ACCEPT),
    Target("menisci.surface_tension", 0.0636, 0.0636, "N/m",
           "SPC/E at 300 K: 63.6 mN/m (Vega & de Miguel, J. Chem. Phys. 126 (2007) 154707)", 0.0616, 0.0656,
           "acceptance window, a choice: within 2 mN/m of the water model's published value"),
    Target("surfaces.interaction_range", 0.165e-9, 0.3e-9, "m", _Z0, 0.15e-9, 0.5e-9,
           "acceptance window, a choice: 'a few angstrom' around the literature's spacings"),
    Target("surfaces.sam.interaction_range", 0.165e-9, 0.3e-9, "m", _Z0, 0.15e-9, 0.5e-9,
           "acceptance window, a choice: 'a few angstrom' around the literature's spacings"),
)


def target_of(key: str, targets: Sequence[Target] = TARGETS) -> Target | None:
    """The target for scene key `key`, or None where the literature gives no value."""
    return next((t for t in targets if t.key == key), None)


def verdict(value: float, stderr: float | None, target: Target) -> Verdict:
    """Where `value` +- `stderr` lies against `target`'s literature range and acceptance window (see Verdict)."""
    if value is None or not math.isfinite(value):
        return Verdict(False, math.nan, False, "no value")
    lo, hi = target.window
    accepted = lo <= value <= hi
    if target.low <= value <= target.high:
        return Verdict(True, 0.0, True, "inside", accepted)
    gap = value - (target.high if value > target.high else target.low)
    sd = float(stderr) if stderr else 0.0
    dist = gap / sd if sd > 0 else math.copysign(math.inf, gap)
    side = "above" if gap > 0 else "below"
    text = f"{abs(dist):.1f} sigma {side}" if math.isfinite(dist) else f"{side} (no stderr)"
    return Verdict(False, dist, abs(dist) <= 2.0, text, accepted)


def _fmt(x: float) -> str:
    return f"{x:.4g}"


def range_cell(target: Target | None) -> str:
    """The report's table cell: the literature range (or value), then the acceptance window."""
    if target is None:
        return "none quoted"
    lit = _fmt(target.low) if target.low == target.high else f"{_fmt(target.low)}-{_fmt(target.high)}"
    lo, hi = target.window
    return f"{lit} {target.unit} (accepted {_fmt(lo)}-{_fmt(hi)})"


def comparison_lines(rows: Iterable) -> list[str]:
    """The report's paragraph on the used values (`calibration.report.ValueRow`-like: key, value, stderr, status)
    against the literature: how many lie inside the literature range, which lie only inside the acceptance
    window (with their distance in stderrs), which lie outside it, then the sources and the windows' reasons."""
    used = [r for r in rows if r.status == "used" and r.value is not None]
    inside, accepted, outside, none = [], [], [], []
    for r in used:
        tgt = target_of(r.key)
        if tgt is None:
            none.append(r)
            continue
        v = verdict(r.value, r.stderr, tgt)
        (inside if v.inside else accepted if v.accepted else outside).append((r, v))

    def named(items):
        return ", ".join(f"`{r.key}` ({v.text} the literature range)" for r, v in items)

    text = (f"**Against the literature** (`calibration/targets.py`, figure `md_vs_literature.png`): "
            f"{len(inside)} of {len(used)} used values inside the literature range"
            + (f"; outside it but inside the acceptance window: {named(accepted)}" if accepted else "")
            + (f"; **outside the acceptance window**: {named(outside)}" if outside else "")
            + (f"; no literature value for {', '.join(f'`{r.key}`' for r in none)}" if none else "") + ".")
    if accepted or outside:
        text += (" No force-field parameter is adjusted toward a target; docs/md.md gives the runs behind each "
                 "value.")
    sources: dict[str, list[str]] = {}
    windows: dict[str, list[str]] = {}
    for r in used:
        tgt = target_of(r.key)
        if tgt is not None:
            sources.setdefault(tgt.source, []).append(r.key)
            if tgt.accept_reason:
                windows.setdefault(tgt.accept_reason, []).append(r.key)

    def listing(groups):
        return "; ".join(f"{', '.join(f'`{k}`' for k in keys)}: {why}" for why, keys in groups.items())

    out = ["", text]
    if sources:
        out += ["", "Literature: " + listing(sources) + "."]
    if windows:
        out += ["", "Acceptance windows: " + listing(windows) + "."]
    return out


#: plot units: (SI unit, factor to the plotted unit, plotted unit's label)
_PLOT_UNITS = {"J/m^2": (1e3, "mJ/m$^2$"), "N/m": (1e3, "mN/m"), "m": (1e9, "nm"), "deg": (1.0, "deg")}


def target_figure(rows: Iterable, path: str | Path, targets: Sequence[Target] = TARGETS, title: str = "") -> Path:
    """A figure of the calibrated values (value +- stderr, one panel per unit) against their literature ranges
    (shaded; the acceptance window lighter); `rows` are :class:`calibration.report.ValueRow`-like (key, value,
    stderr, units, status). Keys with no literature value are drawn without a band. Written atomically; returns the
    path."""
    from matplotlib.figure import Figure

    from nanoimpact.fileio import atomic_save_figure

    rows = [r for r in rows if r.value is not None and r.status == "used"]
    units = list(dict.fromkeys(r.units for r in rows))
    fig = Figure(figsize=(7.5, 1.2 + 1.0 * len(rows)), layout="constrained")
    if not rows:
        ax = fig.add_subplot()
        ax.text(0.5, 0.5, "no MD value was used", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return atomic_save_figure(fig, path, dpi=110)
    heights = [sum(r.units == u for r in rows) for u in units]
    axes = fig.subplots(len(units), 1, squeeze=False, gridspec_kw={"height_ratios": heights})[:, 0]
    for ax, unit in zip(axes, units):
        factor, label = _PLOT_UNITS.get(unit, (1.0, unit))
        mine = [r for r in rows if r.units == unit]
        labelled = False
        for y, r in enumerate(mine):
            t = target_of(r.key, targets)
            if t is not None:
                lo, hi = t.window
                ax.fill_betweenx([y - 0.35, y + 0.35], lo * factor, hi * factor, color="tab:green", alpha=0.1,
                                 lw=0, label=None if labelled else "acceptance window")
                ax.fill_betweenx([y - 0.35, y + 0.35], t.low * factor, t.high * factor, color="tab:green",
                                 alpha=0.35, lw=1.5 if t.low == t.high else 0, edgecolor="tab:green",
                                 label=None if labelled else "literature range")
                labelled = True
                v = verdict(r.value, r.stderr, t)
                color = "tab:blue" if v.inside_2sigma else "tab:red"
            else:
                color = "tab:gray"
            ax.errorbar(r.value * factor, y, xerr=(r.stderr or 0.0) * factor, fmt="o", color=color, capsize=3)
        ax.set_yticks(range(len(mine)), [f"{r.key}\n({r.recipe})" for r in mine], fontsize=7)
        ax.set_ylim(-0.6, len(mine) - 0.4)
        ax.set_xlabel(label)
        ax.grid(axis="x", alpha=0.3)
    for ax in axes:
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="best", fontsize=7)
            break
    axes[0].set_title(title or "calibrated MD values (+- stderr) against the literature; red: > 2 sigma outside "
                      "its range", fontsize=9)
    return atomic_save_figure(fig, path, dpi=110)
