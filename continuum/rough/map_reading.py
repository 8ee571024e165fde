"""Which channel of an AFM file is the height map, and how it is levelled.

Channel. A file holds several channels (SurfaceTopography's reader lists them as `channels`, each with a name,
a grid, a physical size and a data kind). Only a channel of heights describes the surface: phase, amplitude,
deflection, error, friction, current, force and the like do not, even where the reader files them under a
length unit (NanoScope stores AmplitudeError and Phase with the scan's lateral unit; SurfaceTopography 1.27 then
calls them heights). A channel counts as a height channel when SurfaceTopography's data kind is HEIGHT and its
name holds none of `NOT_HEIGHT` (case-insensitive). The scene may name the channel (`topography_channel`: the
file's index, or the name as the file spells it, or SurfaceTopography's `channel_id` "Height#2" for a repeated
name); otherwise, with several height channels, the closed-loop sensor channel is preferred (a name holding
"sensor": NanoScope "ZSensor", Nanosurf "Z-Axis Sensor"): it measures the scanner's position with a capacitive
or strain sensor, where the piezo drive ("Height", "Z-Axis") is the voltage sent to the scanner and carries its
hysteresis and creep (Eaton & West, *Atomic Force Microscopy*, OUP 2010, §2.3 and §7.2). Without a sensor
channel the first height channel is taken. Either way a warning names the channels left out, since they read
the same surface differently.

Levelling (`topography_detrend`). 'plane': the least-squares plane is removed (SurfaceTopography's
`detrend(detrend_mode="height")`; a periodic map only loses its mean). 'line': each scan line loses its own
least-squares line, offset and tilt (SurfaceTopography's `scan_line_align(direction="x", mode="mean",
degree=1)`: x is the fast scan axis, scan lines are the columns of the height array); this removes the
line-to-line offsets a drifting feedback leaves, and with them any real height change across the slow axis.
'none': only the mean height is removed. The record gives the variance the mode removed and, for every mode,
the share of the plane-levelled variance carried by the scan lines' mean heights (their offsets): above
`MAX_LINE_OFFSET_SHARE` under 'plane' a warning says the offsets, not the surface, dominate the statistics
(audit 3, finding 4: 80 % on a Nanosurf scan).
"""
from __future__ import annotations

import numpy as np

__all__ = ["NOT_HEIGHT", "DETREND_MODES", "MAX_LINE_OFFSET_SHARE", "is_height_channel", "select_channel",
           "level", "channel_label"]

#: Words in a channel's name that mark data other than heights.
NOT_HEIGHT = ("phase", "amplitude", "deflection", "error", "friction", "lateral", "current", "force", "voltage",
              "potential", "adhesion", "dissipation", "deformation", "stiffness", "modulus", "frequency", "peakforce")
#: Words that mark a closed-loop (sensor) height channel, preferred among several height channels.
SENSOR = ("sensor",)
DETREND_MODES = ("plane", "line", "none")
#: Above this share of the plane-levelled variance in the scan lines' offsets, 'plane' levelling warns.
MAX_LINE_OFFSET_SHARE = 0.25


def channel_label(ch) -> str:
    return f"{ch.index} ({ch.name!r})"


def is_height_channel(ch) -> bool:
    """A channel of heights: SurfaceTopography's data kind HEIGHT and no `NOT_HEIGHT` word in its name."""
    name = (ch.name or "").lower().replace(" ", "").replace("-", "")
    return bool(ch.is_height_channel) and not any(word in name for word in NOT_HEIGHT)


def _size_m(ch):
    """(grid points, physical size in m or None) of a channel, to compare channels of one file."""
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor

    sizes = ch.physical_sizes
    unit = ch.lateral_unit if isinstance(ch.lateral_unit, str) else None
    if sizes is None or unit is None:
        return tuple(ch.nb_grid_pts), None
    try:
        factor = get_unit_conversion_factor(unit, "m")
    except Exception:  # an unknown unit name: compare the numbers as given
        factor = 1.0
    return tuple(ch.nb_grid_pts), tuple(round(float(s) * factor, 15) for s in sizes)


def select_channel(channels, wanted, error, key_file: str, key_channel: str, file_value):
    """(channel, record, warnings): the height channel a scene runs on (see the module docstring). `wanted` is
    None, an index or a name; `error(key, value, allowed)` is raised for a wanted channel that is not in the
    file or holds no heights, a file without height channels, and height channels that disagree in grid or size
    where none is named."""
    listing = ", ".join(channel_label(c) + ("" if is_height_channel(c) else " [not heights]") for c in channels)
    heights = [c for c in channels if is_height_channel(c)]
    warnings = []
    if wanted is None:
        if not heights:
            raise error(key_file, file_value, f"the file has no height channel (channels: {listing})")
        shapes = {_size_m(c) for c in heights}
        if len(shapes) > 1:
            what = "; ".join(f"{channel_label(c)}: {_size_m(c)[0][0]} x {_size_m(c)[0][-1]} points, "
                             f"{_size_m(c)[1]} m" for c in heights)
            raise error(key_file, file_value, f"its height channels disagree in grid or size ({what}): name the "
                                              f"one to run with {key_channel}")
        sensors = [c for c in heights if any(w in (c.name or "").lower() for w in SENSOR)]
        chosen = (sensors or heights)[0]
        why = ("the closed-loop sensor channel" if sensors else "the first height channel") if len(heights) > 1 \
            else "the file's only height channel"
        if len(heights) > 1:
            others = ", ".join(channel_label(c) for c in heights if c.index != chosen.index)
            warnings.append(f"{key_file}: channel {channel_label(chosen)} taken as {why}; the file has other height "
                            f"channels {others}, which read the surface differently: name one with {key_channel} "
                            "to run on it")
    else:
        chosen = _named(channels, wanted, error, key_channel, listing, warnings)
        why = "named in the scene"
        if not is_height_channel(chosen):
            raise error(key_channel, wanted, f"channel {channel_label(chosen)} does not hold heights; height "
                                             "channels: " + (", ".join(channel_label(c) for c in heights) or "none"))
    record = {"channel": chosen.index, "channel_name": chosen.name, "channel_chosen_as": why,
              "channels": [{"index": c.index, "name": c.name, "heights": is_height_channel(c)} for c in channels]}
    return chosen, record, warnings


def _named(channels, wanted, error, key_channel, listing, warnings):
    if isinstance(wanted, int):
        found = [c for c in channels if c.index == wanted]
    else:
        found = [c for c in channels if c.name == wanted] or \
                [c for c in channels if (c.name or "").lower() == str(wanted).lower()] or \
                [c for c in channels if getattr(c, "channel_id", None) == wanted]
    if not found:
        raise error(key_channel, wanted, f"the file has channels {listing}")
    if len(found) > 1:
        warnings.append(f"{key_channel} = {wanted!r} names channels " + ", ".join(channel_label(c) for c in found)
                        + "; the first is taken (give the index to choose)")
    return found[0]


def _line_offset_share(heights: np.ndarray) -> float:
    """Share of the variance of `heights` (zero mean) carried by the mean heights of its scan lines (columns:
    lines run along x, the first index)."""
    total = float(np.var(heights))
    return float(np.var(heights.mean(axis=0)) / total) if total > 0 else 0.0


def level(topo, mode: str, key: str):
    """(levelled SurfaceTopography map, record, warnings) for `mode` in DETREND_MODES (see the module
    docstring) of a map in metres (variances in m^2, about the mean). A periodic map (a synthesis) only loses its
    mean, whatever the mode."""
    raw = np.asarray(topo.heights(), dtype=float)
    var_raw = float(np.var(raw))
    if topo.is_periodic:
        out = topo.detrend(detrend_mode="center")
        return out, {"mode": "mean", "operation": "mean removed (periodic map)", "variance_before_m2": var_raw,
                     "variance_removed_m2": 0.0, "variance_removed_fraction": 0.0}, []
    plane = topo.detrend(detrend_mode="height")
    share = _line_offset_share(np.asarray(plane.heights(), dtype=float))
    if mode == "plane":
        out, operation = plane, "SurfaceTopography detrend(detrend_mode='height'): least-squares plane removed"
    elif mode == "line":
        out = topo.scan_line_align(direction="x", mode="mean", degree=1)
        operation = ("SurfaceTopography scan_line_align(direction='x', mode='mean', degree=1): each scan line's "
                     "least-squares line (offset and tilt) removed")
    else:
        out, operation = topo.detrend(detrend_mode="center"), "mean removed only"
    var_out = float(np.var(np.asarray(out.heights(), dtype=float)))
    record = {"mode": mode, "operation": operation, "variance_before_m2": var_raw, "variance_after_m2": var_out,
              "variance_removed_m2": var_raw - var_out,
              "variance_removed_fraction": (var_raw - var_out) / var_raw if var_raw > 0 else 0.0,
              "line_offset_share_of_plane_levelled_variance": share}
    warnings = []
    if mode == "plane" and share > MAX_LINE_OFFSET_SHARE:
        warnings.append(f"{key} = 'plane': scan-line offsets carry {share:.0%} of the levelled map's variance "
                        f"(> {MAX_LINE_OFFSET_SHARE:.0%}); they set the summit statistics more than the surface does: "
                        "level each line with topography_detrend = 'line' (or say why the offsets are real)")
    return out, record, warnings
