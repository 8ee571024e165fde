"""Moved to the shared leaf package: `nanoimpact.executors` (so continuum's paper runner can use it too).

This module only re-exports it for code not yet updated; import from `nanoimpact.executors`.
"""
from nanoimpact.executors import (NAMES, ON_ERROR, Dask, Failure, Local, Processes,  # noqa: F401
                                  check_executor, executor)
