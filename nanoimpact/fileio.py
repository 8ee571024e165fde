"""Atomic file writes: a reader never sees a half-written file, a crash never leaves one.

Each write goes to a uniquely named temporary file in the target's folder (so two writers never
share a temporary name), is flushed and fsync'ed, then moved into place with `os.replace`.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write `data` to `path` atomically; returns the path.

    The file gets the permissions a plain `open(path, "w")` would give (0666 less the umask), not the
    0600 of `mkstemp`, so results in a shared cache or output folder stay readable by the group.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 `text` to `path` atomically; returns the path."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def json_leaf(obj: Any) -> Any:
    """A value JSON can hold: NumPy scalars as Python numbers, paths as strings, non-finite floats as None
    (strict JSON has no NaN or Infinity); anything else unchanged."""
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def clean_json(obj: Any) -> Any:
    """`obj` with every mapping, sequence and array turned into JSON containers and every leaf `json_leaf`'d."""
    if isinstance(obj, Mapping):
        return {str(k): clean_json(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return clean_json(obj.tolist())
    return json_leaf(obj)


def atomic_write_json(path: str | Path, obj: Any, *, indent: int | None = 2, default=None) -> Path:
    """Write `obj` as JSON (keys sorted) to `path` atomically; returns the path."""
    text = json.dumps(obj, indent=indent, sort_keys=True, default=default)
    return atomic_write_text(path, text + "\n")


def atomic_save_figure(fig, path: str | Path, **savefig_kw) -> Path:
    """Save a matplotlib Figure to `path` atomically (the format from the suffix); returns the path.
    Rendered to memory first, so a failed render leaves no file at all."""
    import io

    path = Path(path)
    buf = io.BytesIO()
    fig.savefig(buf, format=path.suffix.lstrip(".") or "png", **savefig_kw)
    return atomic_write_bytes(path, buf.getvalue())
