"""Where numba keeps the compiled kernels of a package: a folder keyed by the package's source, not by file dates.

numba's on-disk cache (`njit(cache=True)`) checks only the date and size of the file that defines each function.
A kernel that dispatches to functions of other modules (the contact phase calling every law's arithmetic) is
therefore reloaded from its cache after those modules changed, as long as its own file did not: after a
`git pull` or a merge in an editable install it silently runs the old arithmetic of the laws it calls
(seen here: a new summit mode of one module returned the previous mode's forces through the cached contact kernel
of an unchanged one). Keying the cache folder by a hash of every source file of the package makes any change
compile every kernel afresh (about 25 s once), and leaves an unchanged install's cache where it was.

The folder: `$NUMBA_CACHE_DIR/<package>-<hash>` where the user set NUMBA_CACHE_DIR, else
`<package>/__pycache__/numba-<hash>` beside the sources, else (a read-only install)
`~/.cache/nanoimpact/numba/<package>-<hash>`. Folders of earlier sources are left in place (a few MB each).

numba reads its cache folder when each function is decorated, so `use_source_keyed_cache` runs before the package
imports any module that compiles (from the package's `__init__`).
"""
from __future__ import annotations

import functools
import hashlib
import os
import sys
from pathlib import Path

__all__ = ["source_hash", "cache_dir_for", "use_source_keyed_cache"]

#: where the folder the user gave in NUMBA_CACHE_DIR is kept for child processes
_USER_KEY = "NANOIMPACT_USER_NUMBA_CACHE_DIR"


@functools.lru_cache(maxsize=8)
def source_hash(package_dir: Path) -> str:
    """SHA-256 over the package's modules (relative path and bytes, in sorted order)."""
    root = Path(package_dir).resolve()
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK)


def cache_dir_for(package_dir: Path, user_dir: str | None = None) -> Path:
    """The numba cache folder of the package at `package_dir` for its present sources (module docstring);
    `user_dir`: the user's NUMBA_CACHE_DIR, if any."""
    root = Path(package_dir).resolve()
    key = source_hash(root)[:16]
    if user_dir:
        return Path(user_dir).expanduser() / f"{root.name}-{key}"
    beside = root / "__pycache__" / f"numba-{key}"
    if _writable(beside):
        return beside
    return Path("~/.cache/nanoimpact/numba").expanduser() / f"{root.name}-{key}"


def use_source_keyed_cache(package_dir: Path) -> Path:
    """Point numba's cache at `cache_dir_for(package_dir)`: through numba's config where numba is already imported,
    else through NUMBA_CACHE_DIR, which numba reads when it is imported (and the package's pool workers inherit).
    Returns the folder."""
    # the user's own NUMBA_CACHE_DIR ('' for none), kept apart for child processes, which inherit the keyed one
    user = os.environ.get(_USER_KEY, os.environ.get("NUMBA_CACHE_DIR", ""))
    folder = cache_dir_for(package_dir, user or None)
    os.environ[_USER_KEY] = user
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    return folder
