"""Published ranges for the MD-calibrated values, and where each calibrated value lies against its range.

Issue 11 asks every calibrated value to fall inside the published range for its quantity, with an error bar, and
the report to say so where it does not (never by tuning a force field). :data:`TARGETS` holds one range per scene
key, in the key's SI unit, with the source; :func:`verdict` places a value with its stderr against it;
:func:`target_figure` draws the calibrated values against the ranges (``md_vs_literature.png`` of a calibration).
A key without a published range (the silica-silica work of adhesion of this IFF surface) has no target and the
report says so.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

__all__ = ["Target", "Verdict", "TARGETS", "target_of", "verdict", "target_figure"]


@dataclass(frozen=True)
class Target:
    """A published range [low, high] for scene key `key` in its SI unit `unit`, with its `source`."""

    key: str
    low: float
    high: float
    unit: str
    source: str


@dataclass(frozen=True)
class Verdict:
    """Where a value with its stderr lies against a target.

    `distance_sigma`: 0 inside [low, high]; else (value - nearest bound) / stderr, positive above the range,
    negative below (infinite when the stderr is 0 or missing). `inside_2sigma`: the range is within two stderrs of
    the value (a value outside the range but within its own error bar of it is not a miss)."""

    inside: bool
    distance_sigma: float
    inside_2sigma: bool
    text: str


_CH3 = ("2 gamma_CH3 with gamma_CH3 = 20-24 mJ/m^2 for CH3-terminated monolayers (0.040-0.048 J/m^2); issue 11 "
        "allows 0.035-0.060")
_SILICA_ANGLE = ("hydroxylated silica is wetted (< 10-20 deg, experiment); IFF Q3 surfaces at 4.7 OH/nm^2 wet "
                 "(Emami et al., Chem. Mater. 26 (2014) 2647); issue 11: below 20-30 deg")
_Z0 = ("issue 11: 'z0 of a few angstrom'; 0.15-0.5 nm spans the contact separation D0 = 0.165 nm that gives surface "
       "energies from Hamaker constants (Israelachvili, Intermolecular and Surface Forces, 3rd ed. (2011)) and the "
       "equilibrium spacing of about 0.3 nm usual in Tabor's parameter (Tabor, J. Colloid Interface Sci. 58 (1977) 2; "
       "Johnson & Greenwood, J. Colloid Interface Sci. 192 (1997) 326), the continuum's default")

#: One published range per calibrated scene key (SI units). Angles in degrees, as the scene keys take them.
TARGETS: tuple[Target, ...] = (
    Target("surfaces.sam.work_of_adhesion", 0.035, 0.060, "J/m^2", _CH3),
    Target("surfaces.body.contact_angle", 0.0, 30.0, "deg", _SILICA_ANGLE),
    Target("surfaces.substrate.contact_angle", 0.0, 30.0, "deg", _SILICA_ANGLE),
    Target("surfaces.sam.contact_angle", 105.0, 120.0, "deg",
           "105-112 deg advancing on OTS (Wasserman et al., Langmuir 5 (1989) 1074); issue 11: about 105-120 deg"),
    Target("menisci.surface_tension", 0.0616, 0.0656, "N/m",
           "SPC/E at 300 K: 63.6 mN/m (Vega & de Miguel, J. Chem. Phys. 126 (2007) 154707); issue 11: within 2 mN/m"),
    Target("surfaces.interaction_range", 0.15e-9, 0.5e-9, "m", _Z0),
    Target("surfaces.sam.interaction_range", 0.15e-9, 0.5e-9, "m", _Z0),
)


def target_of(key: str, targets: Sequence[Target] = TARGETS) -> Target | None:
    """The published range for scene key `key`, or None where none is quoted."""
    return next((t for t in targets if t.key == key), None)


def verdict(value: float, stderr: float | None, target: Target) -> Verdict:
    """Where `value` +- `stderr` lies against `target` (see :class:`Verdict`)."""
    if value is None or not math.isfinite(value):
        return Verdict(False, math.nan, False, "no value")
    if target.low <= value <= target.high:
        return Verdict(True, 0.0, True, "inside")
    gap = value - (target.high if value > target.high else target.low)
    sd = float(stderr) if stderr else 0.0
    dist = gap / sd if sd > 0 else math.copysign(math.inf, gap)
    side = "above" if gap > 0 else "below"
    text = f"{abs(dist):.1f} sigma {side}" if math.isfinite(dist) else f"{side} (no stderr)"
    return Verdict(False, dist, abs(dist) <= 2.0, text)


#: plot units: (SI unit, factor to the plotted unit, plotted unit's label)
_PLOT_UNITS = {"J/m^2": (1e3, "mJ/m$^2$"), "N/m": (1e3, "mN/m"), "m": (1e9, "nm"), "deg": (1.0, "deg")}


def target_figure(rows: Iterable, path: str | Path, targets: Sequence[Target] = TARGETS, title: str = "") -> Path:
    """A figure of the calibrated values (value +- stderr, one panel per unit) against their published ranges
    (shaded); `rows` are :class:`calibration.report.ValueRow`-like (key, value, stderr, units, status). Keys with
    no published range are drawn without a band. Written atomically; returns the path."""
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
                ax.fill_betweenx([y - 0.35, y + 0.35], t.low * factor, t.high * factor, color="tab:green", alpha=0.25,
                                 lw=0, label=None if labelled else "published range")
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
    axes[0].set_title(title or "calibrated MD values (+- stderr) against published ranges; red: > 2 sigma outside",
                      fontsize=9)
    return atomic_save_figure(fig, path, dpi=110)
