"""Where shipped and user data live: scenes, parameter sets, MD recipes, force fields, calibration
recipes and committed MD results.

Shipped data is the repository's top-level `inputs/` folder, installed as the package data
`nanoimpact.inputs` and found through `importlib.resources`, so a wheel installed anywhere finds
it (pyproject maps `inputs/` to `nanoimpact.inputs`). A user data folder, given by the
environment variable `NANOIMPACT_DATA` (or `set_user_root`, which the command line's `--data`
calls), has the same layout and is searched first, so a user's `params/mine.toml` is found by
name beside the shipped sets, and calibrations write their sets there.

A name (`hertz_roller`) is looked up in the folders; anything with a path separator or a
`.toml` suffix is a path and must exist.
"""
from __future__ import annotations

import importlib.resources
import os
from pathlib import Path

from .errors import DataNotFound
from .provenance import source_checkout

__all__ = ["KINDS", "ENV_VAR", "find", "names", "roots", "shipped_root", "user_root",
           "set_user_root", "writable_root", "md_results_dirs", "is_path_spec"]

#: The kinds of shipped data, each a folder of TOML files under `inputs/`.
KINDS = ("scenes", "params", "md", "forcefields", "calibration")
ENV_VAR = "NANOIMPACT_DATA"

_user_root: Path | None = None


def shipped_root() -> Path:
    """The folder of the shipped data (`inputs/` in a checkout, `nanoimpact/inputs` in a wheel)."""
    try:
        root = importlib.resources.files("nanoimpact.inputs")
    except ModuleNotFoundError:        # a source tree on sys.path, not installed: the folder beside us
        return Path(__file__).resolve().parent.parent / "inputs"
    return Path(str(root))


def set_user_root(path: str | Path | None) -> None:
    """Use `path` as the user data folder for this process (None: back to `$NANOIMPACT_DATA`)."""
    global _user_root
    _user_root = Path(path).expanduser() if path is not None else None


def user_root() -> Path | None:
    """The user data folder, if one is set (`set_user_root`, else `$NANOIMPACT_DATA`)."""
    if _user_root is not None:
        return _user_root
    env = os.environ.get(ENV_VAR, "").strip()
    return Path(env).expanduser() if env else None


def roots() -> list[Path]:
    """Folders searched for data, first wins: the user folder (if set), then the shipped data."""
    user = user_root()
    return ([user] if user is not None else []) + [shipped_root()]


def writable_root() -> Path:
    """Where new data (a calibrated parameter set) is written by default.

    The user folder when one is set; else the shipped folder when it is a source checkout (an
    editable install writes `inputs/params/NAME.toml` in the repository, where it is committed);
    else `$XDG_DATA_HOME/nanoimpact` (`~/.local/share/nanoimpact`), never an installed package (a wheel in
    site-packages, a `pip install --target` folder or a `--user` install alike).
    """
    user = user_root()
    if user is not None:
        return user
    shipped = shipped_root()
    checkout = source_checkout()
    if checkout is not None and shipped.resolve() == (checkout / "inputs").resolve() and os.access(shipped, os.W_OK):
        return shipped
    base = os.environ.get("XDG_DATA_HOME", "").strip() or "~/.local/share"
    return Path(base).expanduser() / "nanoimpact"


def _check_kind(kind: str) -> None:
    if kind not in KINDS:
        raise ValueError(f"data kind {kind!r}: one of {', '.join(KINDS)}")


def names(kind: str) -> list[str]:
    """The names available for `kind` (user folder and shipped data together), sorted."""
    _check_kind(kind)
    found: set[str] = set()
    for root in roots():
        folder = root / kind
        if folder.is_dir():
            found.update(p.stem for p in folder.glob("*.toml"))
    return sorted(found)


def is_path_spec(spec: str | Path) -> bool:
    """True when `spec` names a file rather than a shipped name."""
    s = str(spec)
    return isinstance(spec, Path) or s.endswith(".toml") or os.sep in s or "/" in s


def find(kind: str, spec: str | Path, *, key: str | None = None) -> Path:
    """The file for `spec`: an existing path as given, else `<root>/<kind>/<spec>.toml`.

    Raises `DataNotFound` (one line, exit code 2) naming the key, the value and what is available.
    """
    _check_kind(kind)
    key = key or kind
    candidate = Path(spec).expanduser()
    if candidate.is_file():
        return candidate
    if is_path_spec(spec):
        raise DataNotFound(key, str(spec), "file not found")
    for root in roots():
        path = root / kind / f"{spec}.toml"
        if path.is_file():
            return path
    available = ", ".join(names(kind)) or "none"
    raise DataNotFound(key, str(spec), f"no {kind} entry of that name; available: {available}")


def md_results_dirs() -> list[Path]:
    """Folders of committed MD results (`md/results/<recipe>-<fidelity>/`), user folder first."""
    return [root / "md" / "results" for root in roots()]
