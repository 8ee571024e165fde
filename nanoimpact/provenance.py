"""Where the running code came from: its version, the source checkout (if this is one) and its git commit.

An installed package that happens to sit inside some other git checkout (a venv inside a
repository) must not record that repository's commit, so git is asked only when the folder above
the packages is nanoimpact's own source tree (its pyproject.toml and inputs/ beside the packages).
"""
from __future__ import annotations

import functools
import importlib.metadata
import subprocess
from pathlib import Path

_ROOT = Path(__file__).resolve().parent.parent


def package_version() -> str:
    """nanoimpact's version: the installed distribution's, else the source tree's ``nanoimpact.__version__`` (the
    attribute pyproject.toml reads it from), so a checkout run with ``PYTHONPATH`` records what the installed
    package would."""
    try:
        return importlib.metadata.version("nanoimpact")
    except importlib.metadata.PackageNotFoundError:
        from nanoimpact import __version__  # noqa: PLC0415 -- the package's own root, read when asked
        return __version__


def source_checkout() -> Path | None:
    """The repository root when the code runs from nanoimpact's source tree, else None (an installed wheel)."""
    pyproject = _ROOT / "pyproject.toml"
    try:
        ours = pyproject.is_file() and 'name = "nanoimpact"' in pyproject.read_text()
    except OSError:
        return None
    return _ROOT if ours and (_ROOT / "inputs").is_dir() else None


def git_commit() -> str | None:
    """HEAD of the source checkout (with '+dirty' if tracked files have uncommitted changes), or None."""
    root = source_checkout()
    return None if root is None else _commit_of(root)


@functools.lru_cache(maxsize=4)
def _commit_of(root: Path) -> str | None:
    """`git_commit` of the checkout at `root`, asked once per process: the code a process runs is what it imported
    when it started, so the first answer is the one its records should carry; a process pool forked after a first
    call inherits it instead of starting two git processes per run."""
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                              timeout=5)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5).stdout.strip()
        return head.stdout.strip() + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return None
