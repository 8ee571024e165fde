"""Shared test policy: an optional backend missing is a skip for a developer, a failure in CI.

CI (environment variable CI=true) installs every extra, so a missing backend there means the
install is broken and must fail, never silently skip (ASE's conftest is the model; our CI is stricter).

md_smoke: each shipped MD recipe run at smoke once per session, shared by the md tests that read its result.

Kernel warm-up: a parallel run of the whole suite (the README's `-n 2`) compiles the contact kernel into numba's
cache first, in two processes at once (`continuum.numerics.kernel_warmup`), so that the workers load it instead of
each compiling all of it side by side on a cold cache (a fresh clone, or after any edit of the sources).
"""
import importlib.util
import os
import subprocess
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import pytest


def require_backend(module: str, what: str) -> None:
    """Skip (locally) or fail (CI=true) unless `module` can be imported."""
    if importlib.util.find_spec(module) is not None:
        return
    reason = f'{what} is not installed (md extra missing: pip install "nanoimpact[md]")'
    if os.environ.get("CI", "").strip().lower() == "true":
        pytest.fail(f"CI=true but {reason}; CI must install the md extra", pytrace=False)
    pytest.skip(reason)


def pytest_configure(config):
    """In the controller of a parallel run of the whole suite, before the workers start: the kernel warm-up."""
    if os.environ.get("PYTEST_XDIST_WORKER") or not getattr(config.option, "numprocesses", None):
        return
    if config.args_source != pytest.Config.ArgsSource.TESTPATHS:
        return                          # a chosen set of tests may need no kernel: they compile what they use
    try:
        subprocess.run([sys.executable, "-m", "continuum.numerics.kernel_warmup"], check=True, timeout=900)
    except (OSError, subprocess.SubprocessError) as exc:
        # only the time changes: each worker then compiles the kernels it uses itself
        warnings.warn(f"kernel warm-up failed ({exc}); the workers compile the kernels themselves", stacklevel=1)


#: Test files that take far longer than the others on two workers (`pytest -n 2 --durations=0` on the 2-core machine:
#: the MD smoke runs, the calibration pipeline, the scene-range maps, the paper fixture). `--dist loadfile` hands
#: files to the workers in collection order as they free up, so these go first (longest first): a long file drawn
#: last would leave the other worker idle while it runs. The order of every other test is unchanged.
LONG_FILES = ("tests/md/test_md_workflows.py", "tests/calibration/test_calibration.py",
              "tests/continuum/test_scene_ranges.py", "tests/continuum/test_paper.py")


def pytest_collection_modifyitems(config, items):
    """Queue LONG_FILES first (a stable sort: each file's own tests keep their order)."""
    rank = {name: i for i, name in enumerate(LONG_FILES)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(LONG_FILES)))


@pytest.fixture
def needs_lammps():
    require_backend("lammps", "LAMMPS")


# ------------------------------------------------------------------------------------ MD smoke runs, shared

@dataclass(frozen=True)
class SmokeRun:
    """One recipe's smoke run: the md.workflows.MDResult, the engine's log lines, the --out folder it wrote."""
    outcome: Any
    log: str
    out: Path


@pytest.fixture(scope="session")
def md_smoke_cache(tmp_path_factory) -> Path:
    """The md cache every shared smoke run (md_smoke) goes into; a test may read it (reuse) but not run into it.

    Under pytest-xdist (the README's `-n 2`) every worker has its own session, so the cache sits in the folder
    the workers' temporary folders share: a recipe one worker ran, the other finds by its hash (the md run lock
    makes a worker that asks while the other runs it wait, then reuse it). It is new each pytest run, so
    whatever it holds was run by this run."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        cache = tmp_path_factory.getbasetemp().parent / "md-smoke-cache"
        cache.mkdir(exist_ok=True)
        return cache
    return tmp_path_factory.mktemp("md-smoke-cache")


@pytest.fixture(scope="session")
def md_smoke(md_smoke_cache, tmp_path_factory) -> Callable[[str], SmokeRun]:
    """md_smoke(name): the shipped recipe `name` run at smoke once per session (a fresh run into md_smoke_cache,
    copied to its own --out folder), whichever test asks first; later asks get the same SmokeRun. A smoke run
    proves plumbing only, so the tests that assert on one recipe's smoke result share one run of it instead of
    each running it again. A run that raised is not remembered: the next ask runs it again (and fails again)."""
    require_backend("lammps", "LAMMPS")
    from md.recipe import load_recipe
    from md.workflows import run_recipe
    runs: dict[str, SmokeRun] = {}

    def smoke(name: str) -> SmokeRun:
        if name not in runs:
            lines: list[str] = []
            out = tmp_path_factory.mktemp(f"md-smoke-{name}") / "out"
            outcome = run_recipe(load_recipe(name), "smoke", cache=md_smoke_cache, out=out, progress=False,
                                 echo=lines.append)
            runs[name] = SmokeRun(outcome, "\n".join(lines), out)
        return runs[name]
    return smoke
