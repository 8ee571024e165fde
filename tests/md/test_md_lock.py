"""One writer per run directory.

Two runs of one recipe at one fidelity started together on one cache would write into the same run directory and
report numbers neither run alone gives. The engine (:func:`md.engine.runner.run_job`, under
:func:`md.workflows.run_recipe`) holds :func:`nanoimpact.lock.run_lock` on it; the second waits and reuses the
first's result, or stops with RunBusy (exit 75) under ``--no-wait``. No test here times anything: what shows that a
process waited or got in is what it logged and whether it raised.

The lock tests need no LAMMPS (a child process holds the lock); the two ``md`` tests run smoke MD.
"""
from __future__ import annotations

import json
import logging
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from nanoimpact.errors import EXIT_BUSY, RunBusy
from nanoimpact.lock import lock_path, read_holder, run_lock

REPO = Path(__file__).resolve().parents[2]
HOST = socket.gethostname()
RECIPE = "surface_tension_spce"

_HOLD = """
import sys, time
from nanoimpact.lock import run_lock
with run_lock(sys.argv[1]):
    print("locked", flush=True)
    time.sleep(float(sys.argv[2]))
"""


def _hold(run_dir: Path, seconds: float) -> subprocess.Popen:
    """A child process that takes the lock of ``run_dir`` and keeps it ``seconds``; returns once it holds it."""
    child = subprocess.Popen([sys.executable, "-c", _HOLD, str(run_dir), str(seconds)], cwd=REPO,
                             stdout=subprocess.PIPE, text=True)
    line = child.stdout.readline()
    assert line.strip() == "locked", f"the child did not take the lock (exit {child.poll()})"
    return child


# ------------------------------------------------------------------------------------ the lock (no LAMMPS)

def test_a_second_process_is_refused_with_one_line_naming_the_holder(tmp_path):
    run_dir = tmp_path / "cache" / "recipe-smoke-0123456789abcdef"
    child = _hold(run_dir, 120)
    try:
        with pytest.raises(RunBusy) as info:
            with run_lock(run_dir, wait=False):
                pytest.fail("got a lock another process holds")
        msg = str(info.value)
        assert "\n" not in msg
        assert str(run_dir) in msg and f"PID {child.pid} on {HOST} (since " in msg and "wait for it" in msg
        assert info.value.exit_code == EXIT_BUSY == 75
        with pytest.raises(RunBusy, match=rf"still in use by PID {child.pid} .* after waiting 0.5 s"):
            with run_lock(run_dir, timeout=0.5):
                pytest.fail("got a lock another process holds")
    finally:
        child.kill()
        child.wait()


def test_a_waiting_process_gets_the_lock_when_the_holder_is_done(tmp_path, caplog):
    run_dir = tmp_path / "recipe-smoke-0123456789abcdef"
    caplog.set_level(logging.INFO, logger="nanoimpact.lock")
    child = _hold(run_dir, 1.5)
    with run_lock(run_dir, wait=True):
        assert read_holder(run_dir).pid == os.getpid()
    assert child.wait(timeout=30) == 0          # it finished its block (it held the lock when we asked: logged)
    assert f"waiting for PID {child.pid} on {HOST} to finish {run_dir}" in caplog.text
    assert caplog.text.count("waiting for PID") == 1
    assert not lock_path(run_dir).exists()      # a holder deletes its lock file when it lets go


def test_a_holder_killed_with_sigkill_releases_the_lock_at_once(tmp_path):
    run_dir = tmp_path / "recipe-smoke-0123456789abcdef"
    child = _hold(run_dir, 600)
    with pytest.raises(RunBusy, match=f"PID {child.pid}"):
        with run_lock(run_dir, wait=False):
            pass
    os.kill(child.pid, signal.SIGKILL)
    assert child.wait(timeout=30) == -signal.SIGKILL
    assert read_holder(run_dir).pid == child.pid        # the file outlives its holder ...
    with run_lock(run_dir, wait=False):                 # ... the lock does not: got at once, without waiting
        assert read_holder(run_dir).pid == os.getpid()


def test_lockers_exclude_each_other_and_release_lets_no_two_in(tmp_path):
    """Threads lock through their own open files, so they exclude each other like processes do; every release
    deletes the lock file, and the inode check keeps a waiter on the deleted file from getting in beside a new
    holder. A read-modify-write counter under the lock loses no update."""
    run_dir = tmp_path / "run"
    counter = tmp_path / "counter"
    counter.write_text("0")
    inside, overlap, errors = [0], [0], []

    def work():
        try:
            for _ in range(25):
                with run_lock(run_dir, wait=True, poll_s=0.001):
                    inside[0] += 1
                    overlap[0] = max(overlap[0], inside[0])
                    n = int(counter.read_text())
                    time.sleep(0.0005)
                    counter.write_text(str(n + 1))
                    inside[0] -= 1
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not errors and overlap[0] == 1 and counter.read_text() == "100"
    assert not lock_path(run_dir).exists()


def test_md_no_wait_exits_75_with_one_line_when_the_run_is_busy(tmp_path, capsys):
    """``nanoimpact md --no-wait`` on a run directory another process holds: exit 75, one line, nothing run."""
    from md.cli import main
    from md.engine import cache_root
    from md.recipe import load_recipe
    from md.workflows import get_workflow, run_hash
    recipe = load_recipe(RECIPE)
    digest, _ = run_hash(recipe, "smoke", get_workflow(recipe.workflow).forcefield_files(recipe.settings("smoke")))
    run_dir = cache_root(tmp_path / "cache") / f"{RECIPE}-smoke-{digest[:16]}"
    child = _hold(run_dir, 120)
    try:
        capsys.readouterr()
        code = main([RECIPE, "--fidelity", "smoke", "--cache", str(tmp_path / "cache"), "--out", str(tmp_path / "out"),
                     "--quiet", "--no-wait"])
        err = capsys.readouterr().err
    finally:
        child.kill()
        child.wait()
    assert code == EXIT_BUSY == 75
    lines = [l for l in err.splitlines() if l.strip()]
    assert len(lines) == 1 and f"PID {child.pid} on {HOST}" in lines[0] and str(run_dir) in lines[0], err
    assert "--no-wait" in lines[0]
    assert not run_dir.exists() and not (tmp_path / "out").exists()


# ------------------------------------------------------------------------------------ MD (LAMMPS)

def _md(cache: Path, out: Path, *extra: str) -> subprocess.Popen:
    # not --quiet: that would also hide the INFO line "waiting for PID ..." the test looks for (stderr)
    return subprocess.Popen([sys.executable, "-m", "calibration.cli", "md", RECIPE, "--fidelity", "smoke",
                             "--cache", str(cache), "--out", str(out), *extra],
                            cwd=out.parent, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.md
def test_two_simultaneous_runs_on_one_cache_report_the_single_runs_numbers(md_smoke, md_smoke_cache, tmp_path):
    """Two runs started together on one fresh cache. One runs, the other waits for it (and says so) and then reuses
    its finished result: both exit 0 with byte-identical result.json files.

    The reference is a run alone in its own cache: the session's smoke run of the recipe (md_smoke, in process,
    shared with test_md_workflows; it shares no file with the other two). Same recipe, seeds and binary on one
    rank: LAMMPS is deterministic across processes here, so the numbers are compared for equality, not within a
    tolerance -- the samples and frames of the two run directories are bit-identical too. Without the lock both
    runs would write into one run directory and report a value the single run does not give."""
    alone_run = md_smoke(RECIPE)
    t0 = time.monotonic()
    procs = {k: _md(tmp_path / "shared", tmp_path / f"out_{k}") for k in ("a", "b")}
    res = {k: (p, *p.communicate(timeout=900)) for k, p in procs.items()}
    wall = time.monotonic() - t0
    for k, (p, out, err) in res.items():
        assert p.returncode == 0, f"{k}: exit {p.returncode}\n{out}\n{err[-3000:]}"
    # what the engine did is logged on stderr (INFO); the printed summary (stdout) says "(cached)"
    reused = [k for k in ("a", "b") if "reusing cached result" in res[k][2]]
    assert len(reused) == 1, "exactly one of the two must have waited and reused the other's run"
    waiter, runner = reused[0], ({"a", "b"} - set(reused)).pop()
    assert "(cached)" in res[waiter][1] and "wrote " in res[runner][2]
    run_dir = next(p for p in (tmp_path / "shared").iterdir())
    assert f"waiting for PID {procs[runner].pid} on {HOST} to finish {run_dir}" in res[waiter][2]
    assert sorted(p.name for p in (tmp_path / "shared").iterdir()) == [run_dir.name]     # no lock file left

    ra, rb = ((tmp_path / f"out_{k}" / "result.json").read_bytes() for k in ("a", "b"))
    assert ra == rb
    shared = json.loads(ra)
    alone = json.loads((alone_run.out / "result.json").read_text())
    assert shared["run_hash"] == alone["run_hash"]
    assert shared["quantities"] == alone["quantities"]                      # bit-identical, see the docstring
    gamma = shared["quantities"]["surface_tension"]["value"]
    alone_dir = alone_run.outcome.run_dir
    # run alone by this pytest run: here, or (pytest-xdist) by the other worker into the new shared smoke cache
    assert alone_dir != run_dir and (not alone_run.outcome.reused or alone_dir.parent == md_smoke_cache)
    for f in ("legs/film/samples.csv",
              *(str(p.relative_to(run_dir)) for p in (run_dir / "legs/film/frames").iterdir())):
        assert (run_dir / f).read_bytes() == (alone_dir / f).read_bytes(), f
    print(f"\ngamma_lv: alone {alone['quantities']['surface_tension']['value']!r}, simultaneous {gamma!r} (both); "
          f"wall {wall:.1f} s")


_KILLED_AFTER = """
import os, signal, sys
import md.engine.runner as E
from md.workflows import run_recipe
from md.recipe import load_recipe

class SigKill(Exception):                # raised where the test hook would stop the run: die like kill -9
    def __init__(self, *args):
        os.kill(os.getpid(), signal.SIGKILL)

E.Interrupted = SigKill
run_recipe(load_recipe(sys.argv[1]), "smoke", cache=sys.argv[2], progress=False, echo=None,
             stop_after_chunks=int(sys.argv[3]))
"""


@pytest.mark.md
def test_a_run_killed_with_sigkill_is_resumed_by_another_process(needs_lammps, tmp_path):
    """A run SIGKILLed after 4 of 6 chunks, holding the lock: its lock is gone at once, its restart files stay,
    and ``--resume --no-wait`` in another process continues it from step 400 to a complete result."""
    from md.cli import main
    from md.engine import read_samples
    from md.recipe import load_recipe
    cache = tmp_path / "cache"
    child = subprocess.Popen([sys.executable, "-c", _KILLED_AFTER, RECIPE, str(cache), "4"], cwd=REPO,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _, err = child.communicate(timeout=900)
    assert child.returncode == -signal.SIGKILL, err[-3000:]
    run_dir = next(p for p in cache.iterdir() if p.is_dir())
    leg = run_dir / "legs" / "film"
    state = json.loads((leg / "state.json").read_text())
    assert state["step"] == 400 and not state["done"] and (leg / state["restart"]).is_file()
    assert not (run_dir / "result.json").exists()
    assert read_holder(run_dir).pid == child.pid         # its lock file is left behind; its lock is not
    code = main([RECIPE, "--fidelity", "smoke", "--cache", str(cache), "--out", str(tmp_path / "out"), "--quiet",
                 "--resume", "--no-wait"])
    assert code == 0
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["legs"]["film"]["resumed_from"] == 400
    s = load_recipe(RECIPE).settings("smoke")
    total = s["equilibrate_steps"] + s["sample_steps"]
    assert read_samples(leg / "samples.csv")["step"].tolist() == list(range(s["sample_interval"], total + 1,
                                                                             s["sample_interval"]))
    assert not lock_path(run_dir).exists()
