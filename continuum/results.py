"""The one place where impact results touch the disk: result.json, timeseries.csv, figures.

Writes are atomic: everything is written into a temporary sibling folder first and then moved
into place with os.replace, so an interrupted or failed run never leaves half-written files.
`load_result(DIR)` reads a result back and refuses a schema version it does not understand.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from nanoimpact.fileio import json_leaf

#: Bump the major number on incompatible changes to result.json.
SCHEMA_VERSION = "1.0"

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
        (tmp / "result.json").write_text(dumps(result) + "\n")
        write_timeseries(tmp / "timeseries.csv", trace)
        for name, draw in (figures or {}).items():
            draw(tmp / name)
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
    if version.split(".")[0] != SCHEMA_VERSION.split(".")[0]:
        raise ResultSchemaError(f"{path}: schema_version {version!r} is not compatible with {SCHEMA_VERSION!r}")
    return Result(data, folder)
