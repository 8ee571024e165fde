"""What produced a result: package, git commit, input hash, interpreter and library versions."""
from __future__ import annotations

import datetime
import importlib.metadata
import platform
import sys

import numpy
import scipy

from nanoimpact.provenance import git_commit


def package_version() -> str:
    try:
        return importlib.metadata.version("nanoimpact")
    except importlib.metadata.PackageNotFoundError:
        from .. import __version__
        return __version__


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
