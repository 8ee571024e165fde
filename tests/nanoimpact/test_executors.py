"""nanoimpact.executors: argument checks, failures collected or cancelling the rest, and workers that end
with their parent however it dies (SIGKILL included)."""
from __future__ import annotations

import functools
import json
import os
import select
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import psutil
import pytest

from conftest import require_backend
from nanoimpact.errors import InputError
from nanoimpact.executors import Failure, executor, one_line

ROOT = Path(__file__).resolve().parents[2]


# module-level jobs: picklable, importable by spawned workers (pytest puts tests/ on sys.path, which they inherit)
def square_or_fail(x):
    if x == 3:
        raise ValueError("three is refused\nsecond line of the message")
    return x * x


def marked_job(task):
    """Leaves a marker when it starts; sleeps; fails if asked."""
    index, delay, fail, folder = task
    Path(folder, f"{index}").touch()
    time.sleep(delay)
    if fail:
        raise RuntimeError(f"job {index} failed on purpose")
    return index


def test_bad_arguments_are_refused_naming_the_value():
    with pytest.raises(InputError, match=r"workers = 0: an integer >= 1"):
        executor("processes", workers=0)
    with pytest.raises(ValueError, match=r"workers = -2"):
        executor("dask", workers=-2)
    with pytest.raises(ValueError, match=r"workers = 1.5"):
        executor("local", workers=1.5)
    with pytest.raises(ValueError, match="executor = 'slurm': one of local, processes, dask"):
        executor("slurm")
    with pytest.raises(ValueError, match="--scheduler = 'tcp://x:1': goes with --executor dask"):
        executor("processes", scheduler="tcp://x:1")
    with pytest.raises(ValueError, match="on_error = 'skip'"):
        executor("local").map(square_or_fail, [1], on_error="skip")


def test_one_line_reason():
    assert one_line(ValueError("a\nb")) == "ValueError: a"
    assert one_line(KeyError()) == "KeyError"
    assert len(one_line(RuntimeError("x" * 1000))) == 400


@pytest.mark.parametrize("name", ["local", "processes"])
def test_collect_yields_a_failure_for_the_failed_item_and_goes_on(name):
    with executor(name, workers=2) as ex:
        got = dict(ex.map(square_or_fail, [1, 2, 3, 4], on_error="collect"))
    assert {k: v for k, v in got.items() if k != 2} == {0: 1, 1: 4, 3: 16}
    assert isinstance(got[2], Failure) and got[2].index == 2 and got[2].error == "ValueError"
    assert got[2].reason == "ValueError: three is refused" == str(got[2])


@pytest.mark.parametrize("name", ["local", "processes"])
def test_raise_propagates_the_error(name):
    with pytest.raises(ValueError, match="three is refused"):
        with executor(name, workers=2) as ex:
            dict(ex.map(square_or_fail, [1, 2, 3, 4]))


def test_first_failure_cancels_the_queued_jobs_and_stops_the_running_ones(tmp_path):
    # 2 workers, 12 jobs of 60 s; job 0 fails at once. Without cancellation every job would start and the
    # pool would take minutes to close; with it, only the jobs already handed to the workers start (at
    # most workers + 1 waiting in the pool's call queue), and the running ones are stopped
    tasks = [(0, 0.0, True, str(tmp_path))] + [(i, 60.0, False, str(tmp_path)) for i in range(1, 12)]
    with pytest.raises(RuntimeError, match="job 0 failed on purpose"):
        with executor("processes", workers=2) as ex:
            for _ in ex.map(marked_job, tasks):
                pass
    started = sorted(int(p.name) for p in tmp_path.iterdir())
    assert 0 in started and len(started) <= 4, started


CHILD = textwrap.dedent('''
    """Start an executor, give its workers sleeping jobs, print their pids, wait to be killed."""
    import json, os, sys, time
    from pathlib import Path

    def job(folder):
        Path(folder, str(os.getpid())).touch()
        pow(3, 10**9)          # C code that holds the GIL for minutes: no Python thread of the worker can run
        time.sleep(300)

    def guarded_sleeper():
        import nanoimpact.executors as ex
        ex._set_parent_death_signal = lambda *a: False      # the watchdog alone (as off Linux)
        ex.guard_parent()
        time.sleep(300)

    if __name__ == "__main__":
        kind, folder = sys.argv[1], sys.argv[2]
        if kind == "watchdog":
            import multiprocessing
            p = multiprocessing.get_context("spawn").Process(target=guarded_sleeper)
            p.start()
            time.sleep(2.0)                                   # let it arm the watchdog
            pids = [p.pid]
        else:
            from nanoimpact.executors import executor
            ex = executor(kind, workers=2)
            pids = ex.worker_pids()          # dask: asked of the workers, which cannot answer once in pow
            results = ex.map(job, [folder] * 4)
            deadline = time.time() + 120
            while len(os.listdir(folder)) < 2 and time.time() < deadline:
                time.sleep(0.1)
            pids = pids or ex.worker_pids()  # processes: the pool starts its workers with the first jobs
        print(json.dumps(pids), flush=True)
        time.sleep(300)
''')


def _gone(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return True


@pytest.mark.parametrize("kind", ["processes", "dask", "watchdog"])
def test_workers_end_when_their_parent_is_killed(tmp_path, kind):
    """SIGKILL the process that started the executor (as a batch scheduler's time limit does): its workers
    must not outlive it. Their jobs hold the GIL, as a long C computation does: dask's own watch of its parent
    (a thread) cannot run then, the parent-death signal still ends them. `watchdog`: the fallback thread alone,
    without the parent-death signal (as off Linux), in a worker that sleeps."""
    if kind == "dask":
        require_backend("distributed", "dask.distributed")
    script = tmp_path / "child.py"
    script.write_text(CHILD)
    markers = tmp_path / "started"
    markers.mkdir()
    log = open(tmp_path / "child.log", "w")
    child = subprocess.Popen([sys.executable, str(script), kind, str(markers)], cwd=ROOT, stdout=subprocess.PIPE,
                             stderr=log, text=True)
    pids: list[int] = []
    try:
        ready, _, _ = select.select([child.stdout], [], [], 150)
        assert ready, f"the child printed no worker pids in 150 s:\n{(tmp_path / 'child.log').read_text()[-3000:]}"
        pids = json.loads(child.stdout.readline())
        assert len(pids) == (1 if kind == "watchdog" else 2) and all(not _gone(p) for p in pids)
        if kind != "watchdog":
            assert sorted(int(p.name) for p in markers.iterdir()) == sorted(pids)   # they were running jobs
        os.kill(child.pid, signal.SIGKILL)
        child.wait(10)
        # the workers must end; the limit only keeps a failing run from hanging (their sleeping jobs run 300 s),
        # it is not a speed requirement
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not all(_gone(p) for p in pids):
            time.sleep(0.05)
        left = [p for p in pids if not _gone(p)]
        assert not left, f"workers {left} outlived their killed parent"
    finally:
        if child.poll() is None:
            child.kill()
        for p in pids:                                  # only the workers this test started
            if not _gone(p):
                os.kill(p, signal.SIGKILL)
        log.close()


@pytest.mark.parametrize("name", ["local", "processes"])
def test_the_paper_runner_runs_on_the_executor_it_is_given_and_leaves_it_open(tmp_path, monkeypatch, name):
    """What calibrate does with the user's executor (the paper's case lists cut to one cheap case here)."""
    from continuum.paper import run
    from continuum.paper.cases import Case

    hertz = Case("hertz", "hertz_roller.toml", {"numerics.max_bounces": 1}, ("8a",))
    monkeypatch.setattr(run, "dry_cases", lambda: [hertz])
    monkeypatch.setattr(run, "wet_cases", lambda: [])
    monkeypatch.setattr(run, "fig8_cases", lambda: [hertz])
    lines = []
    with executor(name, workers=2) as ex:
        got = run.run_paper(["paper"], tmp_path / "paper", executor=ex, progress=lines.append)
        assert dict(ex.map(square_or_fail, [2])) == {0: 4}          # still open: its owner closes it
    assert set(got["impacts"]) == {("hertz", "paper")} and set(got["sweeps"]) == {("hertz", "paper")}
    assert (tmp_path / "paper" / "cases" / "hertz" / "paper" / "result.json").is_file()
    assert set(got["curves"]) == {"paper"}                           # Fig 4's curves: a pool task per set
    assert lines[0].startswith("paper: 3 runs for set(s) paper on " + ex.describe())   # impact, sweep, curves


# ------------------------------------------------------------------------------ errors that come back from workers
PACKAGES = ("nanoimpact", "continuum", "md", "calibration")


@functools.lru_cache(maxsize=None)
def project_exception_classes() -> tuple[str, ...]:
    """'module:Class' of every exception class the project defines, found in the source (a class whose base is a
    built-in exception or another such class), so a new one without a case below fails the test."""
    import builtins
    import re

    known = {n for n in dir(builtins) if isinstance(getattr(builtins, n), type)
             and issubclass(getattr(builtins, n), BaseException)}
    defs = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            module = ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
            for name, bases in re.findall(r"^class (\w+)\(([^)]*)\):", path.read_text(), re.M):
                defs.append((module, name, {b.strip().split(".")[-1] for b in bases.split(",")}))
    found: set[str] = set()
    while True:
        more = {f"{m}:{c}" for m, c, bases in defs if bases & known} - found
        if not more:
            return tuple(sorted(found))
        found |= more
        known |= {x.split(":")[1] for x in more}


def make_error(name: str) -> BaseException:
    """An instance of the project exception class `name` ('module:Class'), built as the code raises it."""
    import importlib

    module, attr = name.split(":")
    c = getattr(importlib.import_module(module), attr)
    if issubclass(c, InputError):
        return c("surfaces.sigma", -1.0, "a length > 0 (m)", "user/params/mine.toml")
    if name.endswith(":MDRunError"):
        return c("LAMMPS stopped", "ERROR: lost atoms", Path("/tmp/leg/log.lammps"))
    return c(f"{c.__name__}: what went wrong")


def project_errors() -> dict[str, BaseException]:
    return {name: make_error(name) for name in project_exception_classes()}


def raise_project_error(name):
    raise make_error(name)


def _same(a: BaseException, b: BaseException) -> bool:
    return type(a) is type(b) and str(a) == str(b) and a.__dict__ == b.__dict__


def test_every_project_error_survives_pickling_with_its_message_and_fields():
    import pickle

    errors = project_errors()
    assert {"nanoimpact.errors:InputError", "continuum.scene:SceneError", "md.engine.lammps:MDRunError",
            "calibration.pipeline:CalibrationError"} <= set(errors)
    for name, exc in errors.items():
        back = pickle.loads(pickle.dumps(exc))
        assert _same(back, exc), name
    e = pickle.loads(pickle.dumps(errors["continuum.scene:SceneError"]))
    assert (e.key, e.value, e.allowed, e.origin, e.exit_code) == ("surfaces.sigma", -1.0, "a length > 0 (m)",
                                                                  "user/params/mine.toml", 2)


@pytest.mark.parametrize("name", ["processes", "dask"])
def test_every_project_error_comes_back_from_a_worker_as_it_was_raised(name):
    """Raised inside a pool process or a Dask worker, each error reaches the caller with its class, message and
    fields (an InputError whose __init__ needs key, value and allowed once broke the pool on the way back)."""
    if name == "dask":
        require_backend("dask.distributed", "dask.distributed")
    errors = project_errors()
    names = sorted(errors)
    with executor(name, workers=2) as ex:
        got = dict(ex.map(raise_project_error, names, on_error="collect"))
        for i, n in enumerate(names):
            assert isinstance(got[i], Failure) and _same(got[i].exception, errors[n]), n
        with pytest.raises(InputError, match=r"mine.toml: surfaces.sigma = -1.0: a length > 0 \(m\)"):
            dict(ex.map(raise_project_error, ["continuum.scene:SceneError"]))


class Unpicklable(Exception):
    def __init__(self, a, b):
        super().__init__(f"needs {a} and {b}")


def raise_unpicklable(_):
    raise Unpicklable(1, 2)


def test_a_foreign_error_that_cannot_be_pickled_comes_back_as_its_one_line_not_a_broken_pool():
    from nanoimpact.errors import RunFailed

    with executor("processes", workers=1) as ex:
        with pytest.raises(RunFailed, match="Unpicklable: needs 1 and 2"):
            dict(ex.map(raise_unpicklable, [0]))
