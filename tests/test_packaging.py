"""The installed package, not the source tree: the wheel ships the data, and runs on its own.

* the wheel (built offline with the environment's setuptools, `pip wheel --no-build-isolation`,
  from a copy of the sources so the checkout gets no `build/` folder) holds the shipped scenes,
  parameter sets, MD recipes, force fields, calibration recipes and committed MD results -- every
  file under `inputs/` -- and nothing but the project's packages;
* that wheel, installed non-editable (`pip install --no-deps --target T`), runs a shipped scene by
  name from an empty folder. The child interpreter is started with `-I -S`: no site processing, so
  neither the editable install's `.pth` nor its finder (which maps the packages to this checkout) is
  loaded, no PYTHONPATH, no current folder; its `sys.path` is the standard library, T, then the
  environment's site-packages for numpy/scipy/matplotlib. The child checks that every module of
  the project it imported, and the shipped data root, lie under T;
* the package list in pyproject.toml names every folder with an `__init__.py`, so a new subpackage
  cannot be left out of the wheel silently.

Building needs `setuptools>=68` and `wheel` in the environment (the dev extra brings them); in CI
nothing here is skipped.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]
PACKAGES: list[str] = SETUPTOOLS["packages"]
PACKAGE_DIR: dict[str, str] = SETUPTOOLS.get("package-dir", {})
CODE_ROOTS = ("continuum", "md", "calibration", "nanoimpact")
DATA_PACKAGE = "nanoimpact.inputs"
DATA_PREFIX = "nanoimpact/inputs/"
IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", ".*")


def _package_folder(pkg: str) -> Path:
    """Where setuptools takes `pkg` from (package-dir mapping, else the dotted path)."""
    parts = pkg.split(".")
    for i in range(len(parts), 0, -1):
        mapped = PACKAGE_DIR.get(".".join(parts[:i]))
        if mapped is not None:
            return ROOT / mapped / Path(*parts[i:])
    return ROOT / Path(*parts)


def _inputs_files() -> list[str]:
    """Files under inputs/ relative to it: git's tracked ones when it can say, else all on disk."""
    git = shutil.which("git")
    if git and (ROOT / ".git").exists():
        r = subprocess.run([git, "-C", str(ROOT), "ls-files", "-z", "--", "inputs"], capture_output=True,
                           timeout=30)
        if r.returncode == 0:
            return sorted(p[len("inputs/"):] for p in r.stdout.decode().split("\0") if p)
    return sorted(p.relative_to(ROOT / "inputs").as_posix() for p in (ROOT / "inputs").rglob("*")
                  if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")


def _pip(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env.update(PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INPUT="1", PIP_NO_INDEX="1")
    r = subprocess.run([sys.executable, "-m", "pip", *args], capture_output=True, text=True, env=env,
                       timeout=timeout)
    assert r.returncode == 0, f"pip {' '.join(args)} failed ({r.returncode}):\n{r.stdout}\n{r.stderr}"
    return r


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> tuple[Path, Path]:
    """The project's wheel, built offline from a copy of the sources (pyproject, README, packages),
    and that copy."""
    for mod, what in (("setuptools", "setuptools>=68"), ("wheel", "wheel")):
        try:
            __import__(mod)
        except ImportError:
            pytest.fail(f"building the wheel needs {what} in this environment: pip install -e '.[dev]'",
                        pytrace=False)
    base = tmp_path_factory.mktemp("wheel")
    src = base / "src"
    src.mkdir()
    readme = PYPROJECT["project"].get("readme")
    for name in ("pyproject.toml", *([readme] if isinstance(readme, str) else [])):
        shutil.copy2(ROOT / name, src / name)
    tops = {p.split(".")[0] for p in PACKAGES} | {v.split("/")[0] for v in PACKAGE_DIR.values()}
    for top in sorted(tops):
        if (ROOT / top).is_dir():
            shutil.copytree(ROOT / top, src / top, ignore=IGNORE)
    dist = base / "dist"
    _pip("wheel", "-q", "--no-deps", "--no-build-isolation", "-w", str(dist), str(src))
    wheels = sorted(dist.glob("nanoimpact-*.whl"))
    assert len(wheels) == 1, f"expected one wheel in {dist}, found {wheels}"
    return wheels[0], src


@pytest.fixture(scope="module")
def wheel(built) -> Path:
    return built[0]


def test_wheel_ships_the_data_and_only_the_packages(built):
    wheel, src = built
    names = set(zipfile.ZipFile(wheel).namelist())
    required = [
        "scenes/hertz_roller.toml",
        *(f"params/{n}.toml" for n in ("paper", "silicon", "silica", "calibrated")),
        "md/adhesion_silica.toml", "md/pulloff_ots.toml", "md/contact_angle_silica.toml",
        "md/surface_tension_spce.toml",
        "forcefields/silica_interface.toml", "forcefields/water_spce.toml",
        "calibration/quick.toml", "calibration/smoke.toml",
    ]
    missing = [n for n in required if DATA_PREFIX + n not in names]
    assert not missing, f"the wheel lacks shipped data: {missing}"

    results = sorted(ROOT.glob("inputs/md/results/*/result.json"))
    assert results, "no committed MD results found under inputs/md/results/"
    for r in results:
        rel = r.relative_to(ROOT / "inputs").as_posix()
        assert DATA_PREFIX + rel in names, f"the wheel lacks the committed MD result {rel}"

    # every file under inputs/ (git's tracked ones) ships: a new data suffix must join package-data
    unshipped = [f for f in _inputs_files() if DATA_PREFIX + f not in names]
    assert not unshipped, (f"files under inputs/ missing from the wheel (add their suffix to "
                           f"[tool.setuptools.package-data]): {unshipped}")

    # code: every module of every listed package (in the copy built from, which others editing the
    # tree cannot change under us); nothing else at the top level (no tests/, docs/)
    for pkg in PACKAGES:
        folder = src / _package_folder(pkg).relative_to(ROOT)
        wheel_dir = pkg.replace(".", "/")
        for py in folder.glob("*.py"):
            assert f"{wheel_dir}/{py.name}" in names, f"the wheel lacks {wheel_dir}/{py.name}"
    tops = {n.split("/")[0] for n in names}
    dist_info = {t for t in tops if t.endswith(".dist-info")}
    assert len(dist_info) == 1, tops
    assert tops - dist_info == set(CODE_ROOTS), f"unexpected top-level entries in the wheel: {sorted(tops)}"
    entry_points = zipfile.ZipFile(wheel).read(f"{dist_info.pop()}/entry_points.txt").decode()
    assert "nanoimpact = calibration.cli:main" in entry_points


CHILD = r"""
import json, os, sys
target, site_dir, out = sys.argv[1:4]
sys.path[:] = [target] + [p for p in sys.path if p] + [site_dir]
from importlib.metadata import Distribution
dist = next(Distribution.discover(name="nanoimpact", path=[target]))
(ep,) = [e for e in dist.entry_points if e.group == "console_scripts" and e.name == "nanoimpact"]
rc = ep.load()(["impact", "hertz_roller", "--fidelity", "fast", "--quiet", "--out", out])
import continuum, nanoimpact.data
ours = ("continuum", "md", "calibration", "nanoimpact")
report = {
    "rc": rc,
    "continuum": continuum.__file__,
    "shipped_root": str(nanoimpact.data.shipped_root()),
    "scene": str(nanoimpact.data.find("scenes", "hertz_roller")),
    "modules": {n: getattr(m, "__file__", None) for n, m in list(sys.modules.items())
                if n.split(".")[0] in ours},
    "meta_path": [repr(f) for f in sys.meta_path],
    "sys_path": sys.path,
}
with open(os.path.join(out, "child.json"), "w") as f:
    json.dump(report, f)
"""


def test_installed_wheel_runs_a_shipped_scene_away_from_the_sources(wheel, tmp_path):
    target = tmp_path / "site"
    _pip("install", "-q", "--no-deps", "--no-compile", "--target", str(target), str(wheel))
    assert (target / "nanoimpact" / "inputs" / "scenes" / "hertz_roller.toml").is_file()
    assert (target / "bin" / "nanoimpact").is_file(), "the console script was not installed"

    work = tmp_path / "empty"
    work.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    site_dir = sysconfig.get_paths()["purelib"]
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    env["MPLBACKEND"] = "Agg"
    r = subprocess.run([sys.executable, "-I", "-S", "-c", CHILD, str(target), site_dir, str(out)],
                       cwd=work, env=env, capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, f"the installed package failed ({r.returncode}):\n{r.stdout}\n{r.stderr}"
    child = json.loads((out / "child.json").read_text())
    assert child["rc"] == 0, r.stdout + r.stderr
    assert (out / "result.json").is_file()
    result = json.loads((out / "result.json").read_text())
    assert result.get("bounces"), "result.json has no bounces"
    assert list(work.iterdir()) == [], "the run wrote into its working folder"

    tgt = target.resolve()

    def inside(path) -> bool:
        return path is not None and Path(path).resolve().is_relative_to(tgt)

    assert inside(child["continuum"]), f"continuum imported from {child['continuum']}, not {tgt}"
    assert inside(child["shipped_root"]), f"shipped data found at {child['shipped_root']}, not under {tgt}"
    assert inside(child["scene"]), child["scene"]
    strays = {n: f for n, f in child["modules"].items() if f is not None and not inside(f)}
    assert not strays, f"modules imported from outside the installed wheel: {strays}"
    assert not [m for m in child["meta_path"] if "editable" in m.lower()], child["meta_path"]
    root = ROOT.resolve()
    assert not [p for p in child["sys_path"] if Path(p).resolve() == root], child["sys_path"]


def test_package_list_names_every_package_folder():
    listed = set(PACKAGES)
    found = set()
    for top in CODE_ROOTS:
        for init in (ROOT / top).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT)
            if "__pycache__" in rel.parts:
                continue
            found.add(".".join(rel.parts))
    assert found, "no packages found"
    missing = sorted(found - listed)
    assert not missing, f"packages missing from [tool.setuptools] packages in pyproject.toml: {missing}"
    assert DATA_PACKAGE in listed, f"{DATA_PACKAGE} (the shipped data) is not in the package list"
    stale = sorted(p for p in listed if not (_package_folder(p) / "__init__.py").is_file())
    assert not stale, f"listed packages with no folder/__init__.py: {stale}"
    # a folder of code without __init__.py would be left out of the wheel whatever the list says
    bare = sorted({py.parent.relative_to(ROOT).as_posix() for top in CODE_ROOTS for py in (ROOT / top).rglob("*.py")
                   if "__pycache__" not in py.parts and not (py.parent / "__init__.py").is_file()})
    assert not bare, f"folders with Python modules but no __init__.py (not shipped): {bare}"
