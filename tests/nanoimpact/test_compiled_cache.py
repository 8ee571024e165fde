"""numba's kernel cache is keyed by the package's sources (nanoimpact.compiled_cache): a change to a module that a
cached kernel calls into compiles the kernel afresh instead of running the old arithmetic."""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

from nanoimpact.compiled_cache import cache_dir_for, source_hash

ROOT = Path(__file__).resolve().parents[2]


def _package(tmp: Path, value: int) -> Path:
    """A package whose cached kernel `a.f` calls `b.g` from another module; only b.py depends on `value`."""
    pkg = tmp / "kpkg"
    pkg.mkdir(exist_ok=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text(textwrap.dedent("""\
        from numba import njit
        from .b import g

        @njit(cache=True)
        def f():
            return g()
        """))
    (pkg / "b.py").write_text(f"from numba import njit\n\n\n@njit(cache=True)\ndef g():\n    return {value}\n")
    os.utime(pkg / "a.py", (1_600_000_000, 1_600_000_000))      # a.py unchanged between the two versions
    return pkg


def _run(tmp: Path, keyed: bool) -> int:
    setup = ("from nanoimpact.compiled_cache import use_source_keyed_cache; "
             f"use_source_keyed_cache(r'{tmp / 'kpkg'}'); ") if keyed else ""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "NANOIMPACT_USER_NUMBA_CACHE_DIR")}
    if not keyed:
        env["NUMBA_CACHE_DIR"] = str(tmp / "plain-cache")
    out = subprocess.run([sys.executable, "-c", setup + "from kpkg.a import f; print(f())"], cwd=tmp, env=env,
                         capture_output=True, text=True, check=True)
    return int(out.stdout.strip())


def test_a_changed_callee_module_recompiles_the_cached_caller(tmp_path):
    for keyed in (False, True):
        d = tmp_path / ("keyed" if keyed else "plain")
        d.mkdir()
        _package(d, 1)
        assert _run(d, keyed) == 1
        _package(d, 2)
        # numba alone keys by the caller's own file: it reloads the caller compiled against the old callee
        assert _run(d, keyed) == (2 if keyed else 1)


def test_the_folder_follows_the_sources_and_the_users_choice(tmp_path):
    pkg = _package(tmp_path, 1)
    first = cache_dir_for(pkg)
    assert first == cache_dir_for(pkg) and first.parent == pkg / "__pycache__"
    (pkg / "b.py").write_text((pkg / "b.py").read_text() + "\n")
    source_hash.cache_clear()
    assert cache_dir_for(pkg) != first
    assert cache_dir_for(pkg, str(tmp_path / "mine")).parent == tmp_path / "mine"


def test_child_processes_use_the_parents_folder():
    """A spawned worker (a Dask worker) inherits NUMBA_CACHE_DIR already keyed: it must not key it again."""
    code = "import continuum, numba; print(numba.config.CACHE_DIR)"
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "NANOIMPACT_USER_NUMBA_CACHE_DIR")}
    parent = subprocess.run([sys.executable, "-c", "import os, continuum, subprocess, sys; print(os.environ["
                             "'NUMBA_CACHE_DIR']); sys.stdout.flush(); subprocess.run([sys.executable, '-c', "
                             f"{code!r}])"], cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    mine, child = parent.stdout.split()
    assert mine == child and Path(mine).name.startswith("numba-")
