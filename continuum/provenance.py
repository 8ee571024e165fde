"""What produced a result: package, git commit, input hash, interpreter and library versions."""
from __future__ import annotations

import datetime
import importlib.metadata
import platform
import subprocess
import sys
from pathlib import Path

import numpy
import scipy

_ROOT = Path(__file__).resolve().parent.parent


def package_version() -> str:
    try:
        return importlib.metadata.version("nanoimpact")
    except importlib.metadata.PackageNotFoundError:
        from . import __version__
        return __version__


def git_commit() -> str | None:
    """HEAD of the source checkout (with '+dirty' if it has uncommitted changes), or None."""
    try:
        head = subprocess.run(["git", "-C", str(_ROOT), "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=5)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "-C", str(_ROOT), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=5).stdout.strip()
        return head.stdout.strip() + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(input_hash: str) -> dict:
    return {
        "package": "nanoimpact",
        "package_version": package_version(),
        "git_commit": git_commit(),
        "input_hash": input_hash,
        "python": sys.version.split()[0],
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "platform": platform.platform(),
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
