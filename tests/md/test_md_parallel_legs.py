"""Legs in parallel (``nanoimpact md --jobs J``): which legs wait for which (:func:`md.engine.plan.leg_dependencies`),
the scheduler's order and overlap, a failing leg stopping the run, and -- with LAMMPS -- the same samples as the
one-process run on the adhesion recipe with the richest dependency graph (anneal, contacts, chains out and back).

The scheduler tests replace the leg runner with a stand-in that logs its start and end to a file and, where a test
needs an order, waits for another leg's event there (the forked children inherit it): the order they assert is
forced by events, not by sleeps, so a loaded machine cannot reorder it. They need no LAMMPS.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from md.engine import runner
from md.engine.lammps import MDRunError
from md.engine.plan import Leg, Plan, Stage, leg_dependencies


def _leg(name: str, after=None, steps: int = 10) -> Leg:
    return Leg(name=name, fresh=lambda d: [], define=lambda step: [], prepare=lambda d: [],
               restart_head=lambda p: [], stages=[Stage("run", steps)], columns={}, sample_interval=1,
               chunk_steps=steps, n_atoms=1, after=after)


def _plan(legs) -> Plan:
    return Plan(legs=list(legs), timestep_fs=1.0, n_atoms=1, seeds={}, forcefield_files=[])


def test_a_leg_without_after_waits_for_every_earlier_leg_and_named_ones_only_for_those():
    legs = [_leg("a", ()), _leg("b", ("a",)), _leg("c", ("a",)), _leg("d")]
    w = leg_dependencies(legs)
    assert w == {"a": frozenset(), "b": {"a"}, "c": {"a"}, "d": {"a", "b", "c"}}


@pytest.mark.parametrize("legs, word", [
    ([_leg("a", ("b",)), _leg("b", ())], "'b', which is not a leg planned before it"),   # a later leg
    ([_leg("a", ("zz",))], "'zz'"),                                                     # an unknown one
    ([_leg("a", ()), _leg("a", ())], "appears twice"),
])
def test_a_wait_for_a_later_or_unknown_leg_is_refused_naming_both(legs, word):
    with pytest.raises(ValueError, match="plan: leg") as info:
        leg_dependencies(legs)
    assert word in str(info.value)


#: How long a stand-in leg waits for an event before it fails the run (a scheduler that never lets the event happen
#: fails the test instead of hanging it); reached only on failure.
EVENT_TIMEOUT_S = 60.0


def _events(record: Path) -> list[str]:
    return record.read_text().splitlines() if record.exists() else []


def _log(record: Path, event: str) -> None:
    """Append one event line; O_APPEND writes of a short line are atomic across the forked legs."""
    fd = os.open(record, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
    try:
        os.write(fd, (event + "\n").encode())
    finally:
        os.close(fd)


def _await(record: Path, events) -> None:
    """Block until every event in ``events`` is in ``record`` (another leg has reached it); raise if it never is."""
    deadline = time.monotonic() + EVENT_TIMEOUT_S
    while not set(events) <= set(_events(record)):
        if time.monotonic() > deadline:
            raise RuntimeError(f"still waiting for {sorted(set(events) - set(_events(record)))}")
        time.sleep(0.005)


def _stand_in(record: Path, gates: dict[str, tuple] | None = None, fail: str | None = None,
              spawn: str | None = None):
    """A leg runner that logs ``start <leg> <ranks>`` and ``end <leg>`` to ``record`` and commits a done state. A
    leg named in ``gates`` first waits for the events listed there, so the order the tests assert is forced by
    events, never by how long a leg sleeps. Leg ``spawn`` first starts a long-lived subprocess (as an mpirun would),
    writes its pid beside ``record`` and logs ``spawned <leg>``; leg ``fail`` raises after its gate."""
    gates = gates or {}

    def run_leg(leg, leg_dir, np_=1, **_):
        _log(record, f"start {leg.name} {np_}")
        if leg.name == spawn:
            child = subprocess.Popen(["sleep", "120"])
            (record.parent / "grandchild.pid").write_text(str(child.pid))
            _log(record, f"spawned {leg.name}")
        _await(record, gates.get(leg.name, ()))
        if leg.name == fail:
            raise RuntimeError(f"boom in {leg.name}")
        leg_dir.mkdir(parents=True, exist_ok=True)
        (leg_dir / "state.json").write_text(json.dumps({"done": True, "step": leg.total_steps}))
        _log(record, f"end {leg.name}")
    return run_leg


def _order(record: Path) -> list[str]:
    """``start x`` / ``end x`` events in the order they happened (ranks dropped)."""
    return [" ".join(e.split()[:2]) for e in _events(record) if e.split()[0] in ("start", "end")]


def test_legs_start_when_what_they_read_is_done_and_independent_ones_overlap(tmp_path, monkeypatch):
    """b and c each wait for the other's start: they can only finish if the scheduler runs them side by side."""
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {"b": ("start c 1",), "c": ("start b 1",)}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    legs = [_leg("a", ()), _leg("b", ("a",)), _leg("c", ("a",)), _leg("d")]
    states = runner._run_legs_parallel(_plan(legs), tmp_path, jobs=2, np_=1, resume=False, bar=None,
                                       extra_commands=())
    assert all(states[n]["done"] for n in "abcd")
    at = {e: k for k, e in enumerate(_order(record))}
    assert at["start b"] > at["end a"] and at["start c"] > at["end a"]       # they read a's restart
    assert at["start d"] > max(at["end b"], at["end c"])                     # after=None: waits for all


def test_a_gate_that_never_opens_fails_the_run_instead_of_hanging_it(tmp_path, monkeypatch):
    """Negative control of the test above: with one job, b waits for c's start in vain and the run fails."""
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {"b": ("start c 1",)}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    monkeypatch.setattr(sys.modules[__name__], "EVENT_TIMEOUT_S", 0.5)
    with pytest.raises(MDRunError, match="still waiting for"):
        runner._run_legs_parallel(_plan([_leg("a", ()), _leg("b", ("a",)), _leg("c", ("a",))]), tmp_path,
                                  jobs=1, np_=1, resume=False, bar=None, extra_commands=())


@pytest.mark.parametrize("fill, expected", [
    (True, {"a": 6, "b": 3, "c": 3, "d": 6, "e": 3, "f": 3}),     # a and d run alone; e ends alone but began beside f
    (False, {n: 3 for n in "abcdef"}),
])
def test_fill_cores_gives_a_lone_leg_every_core_and_shared_legs_their_own(tmp_path, monkeypatch, fill, expected):
    """jobs = 2 of np = 3 ranks: a leg that starts with nothing else running or able to start takes 2 x 3 ranks;
    legs that start side by side keep 3 each, also the one left running alone when its neighbour ends (e waits for
    f's end)."""
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {"e": ("end f",)}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    legs = [_leg("a", ()), _leg("b", ("a",)), _leg("c", ("a",)), _leg("d"), _leg("e", ("d",)), _leg("f", ("d",))]
    runner._run_legs_parallel(_plan(legs), tmp_path, jobs=2, np_=3, resume=False, bar=None, extra_commands=(),
                              fill=fill)
    ranks = {e.split()[1]: int(e.split()[2]) for e in _events(record) if e.startswith("start ")}
    assert ranks == expected
    assert _order(record)[-2:] == ["end f", "end e"]


def test_fill_cores_without_jobs_is_refused_in_one_line_naming_both():
    from md.cli import run
    from nanoimpact.errors import UsageError
    with pytest.raises(UsageError, match=r"--fill-cores .* --jobs J >= 2; got --jobs 1"):
        run(["adhesion_ots_equilibrated", "--fidelity", "smoke", "--fill-cores"])


def test_the_leg_with_the_longest_chain_behind_it_starts_first(tmp_path, monkeypatch):
    """x (100 steps) stands alone; y (10) starts a chain y -> z (1000). In plan order one job would run x, y, z,
    leaving the long z to the end; by critical path it runs y (1010 behind it), z (1000), then x (100). Two jobs
    start y beside x and z the moment y ends. Equal paths keep plan order."""
    legs = [_leg("x", (), 100), _leg("y", (), 10), _leg("z", ("y",), 1000)]
    waits = leg_dependencies(legs)
    assert runner.critical_paths(legs, waits, {"x": 100, "y": 10, "z": 1000}) == {"x": 100, "y": 1010, "z": 1000}
    assert runner.critical_paths(legs, waits, {"x": 100, "y": 0, "z": 400}) == {"x": 100, "y": 400, "z": 400}
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    runner._run_legs_parallel(_plan(legs), tmp_path, jobs=1, np_=1, resume=False, bar=None, extra_commands=())
    assert [e for e in _order(record) if e.startswith("start")] == ["start y", "start z", "start x"]
    record.unlink()
    same = [_leg("p", (), 10), _leg("q", (), 10), _leg("r", (), 10)]
    runner._run_legs_parallel(_plan(same), tmp_path / "same", jobs=1, np_=1, resume=False, bar=None,
                              extra_commands=())
    assert [e for e in _order(record) if e.startswith("start")] == ["start p", "start q", "start r"]


def test_one_job_at_a_time_never_overlaps(tmp_path, monkeypatch):
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    legs = [_leg("a", ()), _leg("b", ()), _leg("c", ())]
    runner._run_legs_parallel(_plan(legs), tmp_path, jobs=1, np_=1, resume=False, bar=None, extra_commands=())
    assert _order(record) == ["start a", "end a", "start b", "end b", "start c", "end c"]


def _until(condition, timeout: float = EVENT_TIMEOUT_S) -> bool:
    """Whether ``condition()`` became true within ``timeout`` seconds (checked every 10 ms): a wait on a state,
    whose limit is reached only when the state never comes."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def _gone(pid: int) -> bool:
    """The process ``pid`` no longer runs (absent, or a zombie nobody has reaped yet)."""
    try:
        state = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return True
    return "\nState:\tZ" in state or "\nState:\tX" in state


def test_a_failing_leg_stops_the_others_and_its_error_names_it(tmp_path, monkeypatch):
    """The slow leg's own subprocess (an mpirun, in a real run) is stopped with it: the child leads a process
    group of its own, and the parent stops the group."""
    record = tmp_path / "record.txt"
    # slow waits for an event that never comes (a leg that would run on); bad fails once slow has its subprocess
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {"slow": ("never",), "bad": ("spawned slow",)},
                                                      fail="bad", spawn="slow"))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    legs = [_leg("slow", ()), _leg("bad", ()), _leg("later", ("bad",))]
    t0 = time.monotonic()
    with pytest.raises(MDRunError, match=r"leg 'bad' failed: RuntimeError: boom in bad"):
        runner._run_legs_parallel(_plan(legs), tmp_path, jobs=2, np_=1, resume=False, bar=None,
                                  extra_commands=())
    assert time.monotonic() - t0 < 20.0                     # the leg that would run on was stopped, not waited for
    assert not any(e.startswith("end") for e in _events(record))   # nothing finished
    assert "start later 1" not in _events(record) and not (tmp_path / "later").exists()
    assert not (tmp_path / "later").exists()
    pid = int((tmp_path / "grandchild.pid").read_text())
    assert _until(lambda: _gone(pid)), "the failed run left its leg's subprocess running"


def test_legs_already_done_are_not_run_again(tmp_path, monkeypatch):
    record = tmp_path / "record.txt"
    monkeypatch.setattr(runner, "_run_leg", _stand_in(record, {}))
    monkeypatch.setattr(runner, "POLL_S", 0.05)
    (tmp_path / "legs" / "a").mkdir(parents=True)
    (tmp_path / "legs" / "a" / "state.json").write_text(json.dumps({"done": True, "step": 10}))
    legs = [_leg("a", ()), _leg("b", ("a",))]
    runner._run_legs_parallel(_plan(legs), tmp_path, jobs=2, np_=1, resume=True, bar=None, extra_commands=())
    assert _order(record) == ["start b", "end b"]


def test_stop_after_chunks_needs_one_job():
    with pytest.raises(ValueError, match="jobs = 1"):
        runner._run_legs(None, _plan([_leg("a", ())]), Path("."), done=0, total=10, np_=1, resume=False,
                         progress=False, stop_after_chunks=1, extra_commands=(), jobs=2)


@pytest.mark.md
def test_two_jobs_give_the_samples_of_one_process_on_the_equilibrated_ots_recipe(needs_lammps, md_smoke, tmp_path):
    """adhesion_ots_equilibrated at smoke: anneal -> contact -> separated, registry 1's own contact, two chains out
    and back. The same recipe with --jobs 2 (a fresh CLI process, so nothing has loaded LAMMPS before the fork)
    must give every leg's samples byte for byte, and the same quantities."""
    one = md_smoke("adhesion_ots_equilibrated").outcome
    cache = tmp_path / "cache"
    code = "import sys; from calibration.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.run([sys.executable, "-c", code, "-q", "md", "adhesion_ots_equilibrated", "--fidelity",
                           "smoke", "--jobs", "2", "--cache", str(cache), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert proc.returncode == 0, proc.stderr[-3000:]
    two_dir = next(p for p in cache.iterdir() if p.is_dir())
    two = json.loads((two_dir / "result.json").read_text())
    assert two["jobs"] == 2 and two["run_hash"] == one.result["run_hash"]
    legs = sorted(p.name for p in (one.run_dir / "legs").iterdir() if p.is_dir())
    assert len(legs) > 5 and legs == sorted(p.name for p in (two_dir / "legs").iterdir() if p.is_dir())
    for leg in legs:
        a = (one.run_dir / "legs" / leg / "samples.csv").read_bytes()
        b = (two_dir / "legs" / leg / "samples.csv").read_bytes()
        assert a == b, f"leg {leg}: samples differ between one process and two jobs"
        assert two["legs"][leg]["ranks"] == [1] and two["legs"][leg]["hosts"] == [runner.leg_host()], leg
    for name, q in one.result["quantities"].items():
        assert two["quantities"][name]["value"] == q["value"], name


@pytest.mark.parametrize("name", ["adhesion_ots_equilibrated", "adhesion_silica_registries", "pulloff_ots_positions"])
def test_every_leg_waits_for_exactly_the_legs_whose_files_it_reads(name, tmp_path):
    """The declared graph against the commands: the leg directories a leg's set-up names (a restart, a minimised
    structure) are the legs it waits for -- no more (it would lose parallelism), no fewer (it would read a file
    that is not there yet). Planned at smoke; nothing runs."""
    from md.recipe import load_recipe
    from md.workflows import get_workflow
    from md.workflows.facade import job_for
    rec = load_recipe(name)
    plan = get_workflow(rec.workflow).plan(job_for(rec, "smoke").settings, tmp_path)
    waits = leg_dependencies(plan.legs)
    names = {leg.name for leg in plan.legs}
    assert all(leg.after is not None for leg in plan.legs)
    for leg in plan.legs:
        text = " ".join(leg.fresh(tmp_path / "legs" / leg.name))
        read = {n for n in names if f"/legs/{n}/" in text}
        assert read == set(waits[leg.name]), (leg.name, read, waits[leg.name])
    assert any(len(w) == 0 for w in waits.values())
    assert sum(1 for w in waits.values() if len(w) <= 1) == len(plan.legs)


def test_a_parent_killed_outright_leaves_no_leg_running(tmp_path):
    """SIGKILL runs no clean-up in the parent; its children (process groups of their own, out of reach of the
    terminal's signals) must still stop rather than run on holding the run's lock: they ask the kernel for a
    SIGTERM when their parent dies."""
    code = f"""
import os, time
from pathlib import Path
from md.engine import runner
from md.engine.plan import Leg, Plan, Stage

def run_leg(leg, leg_dir, **_):
    Path({str(tmp_path)!r}, "child.pid").write_text(str(os.getpid()))
    time.sleep(120)

runner._run_leg = run_leg
leg = Leg(name="a", fresh=lambda d: [], define=lambda s: [], prepare=lambda d: [], restart_head=lambda p: [],
          stages=[Stage("run", 10)], columns={{}}, sample_interval=1, chunk_steps=10, n_atoms=1, after=())
runner._run_legs_parallel(Plan(legs=[leg], timestep_fs=1.0, n_atoms=1, seeds={{}}, forcefield_files=[]),
                          Path({str(tmp_path)!r}), jobs=2, np_=1, resume=False, bar=None, extra_commands=())
"""
    parent = subprocess.Popen([sys.executable, "-c", code])
    pid_file = tmp_path / "child.pid"
    assert _until(lambda: pid_file.exists() and pid_file.read_text()), "the leg never started"
    child = int(pid_file.read_text())
    parent.kill()
    parent.wait()
    alive = not _until(lambda: _gone(child))
    if alive:
        os.kill(child, 9)
    assert not alive, "a leg ran on after its parent was killed"


def test_a_checkout_run_without_the_installed_package_records_the_source_trees_version(monkeypatch):
    """A source checkout run with PYTHONPATH (no installed metadata) records the version from the source tree (the
    attribute pyproject.toml reads), as the installed package would; the run hash holds no version at all."""
    import importlib.metadata

    import nanoimpact
    from md.engine import hashing
    from nanoimpact.provenance import package_version

    installed = package_version()
    key = hashing.run_hash({"name": "r"}, "quick", [], 1)

    def missing(name):
        raise importlib.metadata.PackageNotFoundError(name)
    monkeypatch.setattr(importlib.metadata, "version", missing)
    assert package_version() == nanoimpact.__version__ == installed
    assert hashing.run_hash({"name": "r"}, "quick", [], 1) == key
