"""The one place where impact results touch the disk: result.json, profiles.npz, timeseries.csv, figures.

Writes are atomic: everything is written into a temporary sibling folder first and then moved
into place with os.replace, so an interrupted or failed run never leaves half-written files.
`load_result(DIR)` reads a result back and refuses a schema version it does not understand.

Schema 2.0 keeps the spatial profiles' arrays (`x`, `pressure`, ... : 257 numbers each, two instants per
bounce) out of result.json, in `profiles.npz` beside it (NumPy's zip of .npy arrays, exact float64); each
profile in result.json keeps its scalars and names the file, its array and their rows (`arrays_file`, `arrays_key`,
`array_fields`, `array_lengths`).
Kept inline, the profiles of a 100-bounce run would make result.json megabytes of decimal floats, slow to
encode. `load_result` puts the arrays back, so readers see the record the run
returned; it also reads schema 1.x folders, whose profiles are inline.
"""
from __future__ import annotations

import io
import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from nanoimpact.fileio import atomic_write_bytes, atomic_write_text, json_leaf
from nanoimpact.interrupt import raise_if_interrupted

#: Bump the major number on incompatible changes to result.json.
SCHEMA_VERSION = "2.0"
#: Major versions `load_result` reads (1.x: profiles inline in result.json).
READABLE_MAJORS = ("1", "2")
#: Where the profiles' arrays go, beside result.json.
PROFILES_FILE = "profiles.npz"

TIMESERIES_COLUMNS = (("t", "t_s"), ("gap", "gap_m"), ("velocity", "velocity_m_per_s"),
                      ("force", "force_N"), ("phase", "phase"), ("energy", "energy_J"))


class ResultSchemaError(ValueError):
    """A result folder that is missing, incomplete, or of an incompatible schema version."""


class Result(dict):
    """result.json as a dict whose top-level keys also read as attributes; `.timeseries()` loads the CSV."""

    def __init__(self, data: dict, folder: Path):
        super().__init__(data)
        self.folder = Path(folder)

    def __getattr__(self, key):
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def timeseries(self) -> dict:
        """Columns of timeseries.csv as NumPy arrays keyed by the trace names (t, gap, velocity, ...)."""
        data = np.loadtxt(self.folder / "timeseries.csv", delimiter=",", comments="#", skiprows=1, ndmin=2)
        return {name: data[:, i] for i, (name, _) in enumerate(TIMESERIES_COLUMNS)}


def _json_default(obj):
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def _clean(obj):
    """Replace non-finite floats by None so result.json stays strict JSON."""
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    return obj


#: Lists of at least this many numbers are written on one line (see `dumps`).
_INLINE_MIN = 8


def _encode(obj, level: int) -> str:
    """JSON text of `obj` indented by 2 like json.dumps(indent=2), except that a list of `_INLINE_MIN` or more
    numbers is written on one line (by the C encoder). Arrays become lists, non-finite floats null."""
    pad, inner = "  " * level, "  " * (level + 1)
    if isinstance(obj, np.ndarray):
        if obj.ndim == 1 and obj.size >= _INLINE_MIN and obj.dtype.kind in "fiu":
            values = obj.tolist()
            return json.dumps(values if np.all(np.isfinite(obj)) else [v if math.isfinite(v) else None for v in values])
        obj = obj.tolist()
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = ",\n".join(f"{inner}{json.dumps(str(k) if not isinstance(k, str) else k)}: {_encode(v, level + 1)}"
                            for k, v in obj.items())
        return "{\n" + items + "\n" + pad + "}"
    if isinstance(obj, (list, tuple)):
        if not obj:
            return "[]"
        if len(obj) >= _INLINE_MIN and all(type(v) is float or type(v) is int for v in obj):
            if all(math.isfinite(v) for v in obj):
                return json.dumps(obj)
            return json.dumps([v if math.isfinite(v) else None for v in obj])
        return "[\n" + ",\n".join(inner + _encode(v, level + 1) for v in obj) + "\n" + pad + "]"
    leaf = json_leaf(obj)
    if isinstance(leaf, (dict, list, tuple, np.ndarray)):
        return _encode(leaf, level)
    try:
        return json.dumps(leaf, allow_nan=False)
    except TypeError:
        return json.dumps(leaf, default=_json_default, allow_nan=False)


def dumps(data: dict) -> str:
    """result.json text: indented, with long lists of numbers (profiles: thousands of floats) on one line each.

    The same JSON values as json.dumps(_clean(data), indent=2, default=_json_default); its pure-Python indenting
    encoder took ~4 s for a 100-bounce run's profiles, the C encoder writes each list of numbers at once."""
    return _encode(data, 0)


def split_profiles(result: dict) -> tuple[dict, dict[str, np.ndarray]]:
    """(result.json's record, arrays for profiles.npz): the lists or arrays of numbers of each profile (one instant
    of one bounce) become the rows of one 2-D array keyed ``bounce<k>.<instant>`` (k: the bounce's position;
    shorter rows padded with NaN), and the profile names them: `arrays_file`, `arrays_key`, `array_fields` (row
    order) and `array_lengths`. One array per instant, not one per field: a .npz member costs ~0.2 ms to write,
    so 1400 of them (a 100-bounce run) took 0.25 s. The record passed in is not changed."""
    arrays: dict[str, np.ndarray] = {}
    bounces = []
    for k, bounce in enumerate(result.get("bounces") or []):
        profiles = bounce.get("profiles") if isinstance(bounce, dict) else None
        if not profiles:
            bounces.append(bounce)
            continue
        slim = {}
        for instant, prof in profiles.items():
            if not isinstance(prof, dict):
                slim[instant] = prof
                continue
            keep, rows = {}, {}
            for field, value in prof.items():
                if isinstance(value, np.ndarray) or (isinstance(value, (list, tuple)) and value
                                                     and all(isinstance(v, (int, float)) for v in value)):
                    rows[field] = np.asarray(value, dtype=float).ravel()
                else:
                    keep[field] = value
            if rows:
                key = f"bounce{k}.{instant}"
                table = np.full((len(rows), max(r.size for r in rows.values())), np.nan)
                for i, row in enumerate(rows.values()):
                    table[i, :row.size] = row
                arrays[key] = table
                keep.update(arrays_file=PROFILES_FILE, arrays_key=key, array_fields=list(rows),
                            array_lengths=[r.size for r in rows.values()])
            slim[instant] = keep
        bounces.append({**bounce, "profiles": slim})
    if not arrays:
        return result, arrays
    return {**result, "bounces": bounces}, arrays


def merge_profiles(record: dict, folder: Path) -> dict:
    """The record with each profile's arrays read back from `folder`/profiles.npz (what `split_profiles` took)."""
    named = [p for b in record.get("bounces") or [] if isinstance(b, dict)
             for p in (b.get("profiles") or {}).values() if isinstance(p, dict) and "arrays_key" in p]
    if not named:
        return record
    path = folder / PROFILES_FILE
    if not path.is_file():
        raise ResultSchemaError(f"{path}: result.json names its profile arrays in this file, which is missing")
    with np.load(path) as npz:
        for prof in named:
            table = npz[prof.pop("arrays_key")]
            for row, field, n in zip(table, prof.pop("array_fields"), prof.pop("array_lengths")):
                prof[field] = row[:n].copy()
            prof.pop("arrays_file", None)
    return record


def write_result_files(folder: str | Path, result: dict) -> Path:
    """Write result.json (and profiles.npz when the run has spatial profiles) into an existing `folder`, each file
    atomically and result.json last, so a folder with a result.json holds a complete result."""
    folder = Path(folder)
    record, arrays = split_profiles(result)
    if arrays:
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        atomic_write_bytes(folder / PROFILES_FILE, buf.getvalue())
    atomic_write_text(folder / "result.json", dumps(record) + "\n")
    return folder / "result.json"


def write_timeseries(path: Path, trace: dict) -> None:
    header = ",".join(col for _, col in TIMESERIES_COLUMNS)
    table = np.column_stack([np.asarray(trace[name], dtype=float) for name, _ in TIMESERIES_COLUMNS])
    np.savetxt(path, table, delimiter=",", header=header, comments="",
               fmt=["%.17g", "%.17g", "%.17g", "%.17g", "%d", "%.17g"])


def write_run(out_dir: str | Path, result: dict, trace: dict, figures: dict | None = None) -> Path:
    """Write result.json, timeseries.csv and figures ({name: callable(path)}) atomically into out_dir."""
    out = Path(out_dir)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.tmp-", dir=out.parent))
    try:
        write_result_files(tmp, result)
        write_timeseries(tmp / "timeseries.csv", trace)
        for name, draw in (figures or {}).items():
            draw(tmp / name)
        raise_if_interrupted()              # Ctrl-C before this line leaves no output folder
        if not out.exists():
            os.replace(tmp, out)
        else:
            for item in tmp.iterdir():
                os.replace(item, out / item.name)
            tmp.rmdir()
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return out


def load_result(folder: str | Path) -> Result:
    """Read DIR/result.json, checking that its schema version is one this code understands."""
    folder = Path(folder)
    path = folder / "result.json"
    if not path.is_file():
        raise ResultSchemaError(f"{path}: no result.json in this folder")
    data = json.loads(path.read_text())
    version = str(data.get("schema_version", ""))
    if version.split(".")[0] not in READABLE_MAJORS:
        raise ResultSchemaError(f"{path}: schema_version {version!r} is not compatible with {SCHEMA_VERSION!r} "
                                f"(this code reads major versions {', '.join(READABLE_MAJORS)})")
    return Result(merge_profiles(data, folder), folder)
