"""A disk cache of the sampled bundles: the same inputs and the same code give the same runs.

A discrete seed's bundle (its drops and single-surface runs, ~1-3 s of CPU) or an uncertainty row's (the averaged
law's drops, escape searches and loops, ~4 s) depends on nothing but the resolved scenes of its cases, the sample's
overrides, the fidelity and the code. The key hashes all of them: each case scene's
`ResolvedScene.input_hash` (every resolved value, from the parameter set, its base and the scene file), the
overrides and fidelity, and the bytes of every module of the `continuum` package, so any change to an input or to
the code runs the seed again. Stored as pickles (the bundles hold float-keyed maps) under $NANOIMPACT_CACHE/paper,
else ~/.cache/nanoimpact/paper, written atomically; NANOIMPACT_CACHE=off runs every seed.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import pickle
from pathlib import Path
from typing import Callable

from nanoimpact.compiled_cache import source_hash

from ..scene import resolve_scene
from .cases import Case
from .samples import row_for_scene

log = logging.getLogger(__name__)

#: Bumped when what a cached bundle holds changes shape.
CACHE_VERSION = 1


def code_hash() -> str:
    """SHA-256 over the `continuum` package's modules (path and bytes), computed once per process: the key numba's
    kernel cache also follows (`nanoimpact.compiled_cache.source_hash`)."""
    return source_hash(Path(__file__).resolve().parents[1])


def cache_dir() -> Path | None:
    env = os.environ.get("NANOIMPACT_CACHE")
    if env == "off":
        return None
    return (Path(env).expanduser() if env else Path("~/.cache/nanoimpact").expanduser()) / "paper"


def bundle_key(params: str, overrides: dict, fidelity: str | None, cases: list[Case], kind) -> str:
    """The cache key of one sample's bundle: a seed's or an uncertainty row's (`overrides`), on `cases`; `kind`:
    what the bundle holds (JSON-able: whether it is a full one, whether it has the single-surface runs)."""
    inputs = []
    for c in cases:
        row, _ = row_for_scene(c.path, params, c.overrides, overrides)
        inputs.append(resolve_scene(c.path, params=params, overrides={**c.overrides, **row},
                                    override_label="sample cache key").input_hash)
    blob = json.dumps({"version": CACHE_VERSION, "code": code_hash(), "inputs": inputs, "overrides": overrides,
                       "fidelity": fidelity, "kind": kind}, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()


def cached(key: str, compute: Callable[[], dict]) -> dict:
    """`compute()`'s bundle, from the cache when `key` is there (marked 'cached': True), else computed and stored."""
    folder = cache_dir()
    path = folder / f"bundle-{key[:32]}.pkl" if folder is not None else None
    if path is not None and path.is_file():
        try:
            with path.open("rb") as fh:
                return {**pickle.load(fh), "cached": True}
        except (OSError, pickle.UnpicklingError, EOFError) as exc:     # a damaged entry is run again
            log.warning("seed cache entry %s unreadable (%s): running the seed", path, exc)
    out = compute()
    if path is not None and "error" not in out and "single_surface_error" not in out:
        try:
            folder.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            with tmp.open("wb") as fh:
                pickle.dump(out, fh)
            tmp.replace(path)
        except OSError as exc:
            log.warning("seed cache not written (%s)", exc)
    return out
