"""Where independent jobs run: in this process, in a local process pool, or on Dask.

One interface for every layer (continuum's paper runner, calibration's pipelines and sweeps):
`executor(name, workers, scheduler)` returns an object with

* `map(fn, items, on_error="raise")`: submits every job at once and returns an iterator of
  (item index, result) in the order the jobs finish. `fn` and the items must be picklable
  (module-level functions) for `processes` and `dask`.
  - `on_error="raise"` (default): the first job that fails cancels every queued job and its
    exception propagates; `close()` then also stops the jobs still running.
  - `on_error="collect"`: a failed job yields a `Failure` (index, error class, one-line reason)
    in place of its result, and the others go on.
* `close(cancel=None)`, and `with executor(...) as ex:` (an exception leaving the block cancels).
* `describe()`: one line saying where the jobs run (and, for Dask, where its dashboard is).

Executors:

* `local`: serial, in this process (no server).
* `processes`: a local pool of `workers` processes (default: the CPU count), forked when this process
  runs a single thread, else spawned.
* `dask`: dask.distributed. Without `scheduler`, a LocalCluster of `workers` (default 2)
  single-threaded worker processes is started and closed; with `scheduler` (tcp://host:port)
  the Client connects to an existing cluster, e.g. one dask-jobqueue's SLURMCluster started
  (docs/calibration.md). Its dashboard address is logged when it starts.

Workers of `processes` and of a Dask LocalCluster end when the process that started them dies,
however it dies (SIGKILL included, as a batch scheduler's time limit does): each sets Linux's
parent-death signal (prctl PR_SET_PDEATHSIG, SIGTERM) and runs a watchdog thread that exits the
worker once its parent process has changed (the only mechanism off Linux). Workers of an external
Dask cluster belong to that cluster and are left alone.
"""
from __future__ import annotations

import ctypes
import importlib.util
import logging
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
from concurrent.futures import CancelledError, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Iterator

from . import data
from .errors import BackendUnavailable, InputError, RunFailed

log = logging.getLogger(__name__)

NAMES = ("local", "processes", "dask")
ON_ERROR = ("raise", "collect")

#: Seconds between two looks of the watchdog thread at the worker's parent.
WATCHDOG_INTERVAL_S = 0.5


# ----------------------------------------------------------------------------- failures
def one_line(exc: BaseException, limit: int = 400) -> str:
    """'ErrorClass: first line of the message' (at most `limit` characters)."""
    text = next((ln.strip() for ln in str(exc).splitlines() if ln.strip()), "")
    line = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return line if len(line) <= limit else line[:limit - 3] + "..."


@dataclass(frozen=True)
class Failure:
    """A job that raised, yielded in place of its result by `map(..., on_error="collect")`."""

    index: int
    error: str                  # the exception's class name
    reason: str                 # 'ErrorClass: first line of its message'
    exception: BaseException | None = field(default=None, repr=False, compare=False)

    @classmethod
    def of(cls, index: int, exc: BaseException) -> "Failure":
        return cls(index, type(exc).__name__, one_line(exc), exc)

    def __str__(self) -> str:
        return self.reason


class _Carried:
    """`fn` for a worker process or a Dask worker, whose error must come back pickled: an exception that does not
    survive pickling (a foreign class whose `__init__` the default reduction cannot call again) would break the
    pool (`BrokenProcessPool`) or lose the message; it is sent back as `RunFailed` with its one line instead. The
    project's own errors survive as they are (`nanoimpact.errors.NanoimpactError.__reduce__`).

    The caller's user data folder (`--data`, `nanoimpact.data.set_user_root`) travels with it: a spawned process or
    a Dask worker does not inherit it, and would look a user's parameter set up in the shipped data alone."""

    def __init__(self, fn: Callable):
        self.fn = fn
        self.data_root = data.user_root()
        self.__name__ = getattr(fn, "__name__", type(fn).__name__)     # Dask names its tasks after it

    def __call__(self, item):
        if self.data_root is not None and data.user_root() != self.data_root:
            data.set_user_root(self.data_root)
        try:
            return self.fn(item)
        except Exception as exc:                # noqa: BLE001 -- re-raised as it is, or as its one line
            if _survives_pickling(exc):
                raise
            raise RunFailed(one_line(exc)) from None


def _survives_pickling(exc: BaseException) -> bool:
    try:
        back = pickle.loads(pickle.dumps(exc))
    except Exception:                           # noqa: BLE001 -- any failure of the round trip
        return False
    return type(back) is type(exc) and str(back) == str(exc)


def _check_on_error(on_error: str) -> None:
    if on_error not in ON_ERROR:
        raise InputError("on_error", on_error, "one of " + ", ".join(ON_ERROR))


# ----------------------------------------------------------------------------- orphaned workers
PR_SET_PDEATHSIG = 1
_guarded_pid: int | None = None        # the process guard_parent armed (a forked child must arm its own)


def _set_parent_death_signal(sig: int = signal.SIGTERM) -> bool:
    """Ask Linux to send `sig` to this process when its parent dies; False where that is not possible."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _proc_stat(pid: int) -> tuple[str, int] | None:
    """(state letter, parent pid) of a process from Linux's /proc; None where unknown."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return fields[0], int(fields[1])
    except (OSError, IndexError, ValueError):
        return None


def _alive(pid: int) -> bool:
    """Whether `pid` runs (a zombie, dead but not yet reaped, does not count)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    stat = _proc_stat(pid)
    return stat is None or stat[0] != "Z"


def _parent_gone(ppid: int, parent_pid: int) -> bool:
    """Whether the process that started this one (`parent_pid`) has died, given the current parent `ppid`."""
    if ppid == parent_pid:
        return False
    stat = _proc_stat(ppid)            # a forkserver between us: its parent is `parent_pid`
    if stat is not None and stat[1] == parent_pid:
        return not _alive(parent_pid)
    return True if stat is not None else not _alive(parent_pid)


def _orphaned(ppid: int) -> None:
    try:
        sys.stderr.write(f"nanoimpact worker {os.getpid()}: its parent (pid {ppid}) is gone; exiting\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass
    os._exit(128 + signal.SIGTERM)


def guard_parent(parent_pid: int | None = None, interval: float = WATCHDOG_INTERVAL_S) -> bool:
    """Make this (worker) process end when its parent process dies, however it dies.

    `parent_pid`: the process that started this one (default: multiprocessing's record of it);
    if it is already gone, this process exits at once. Returns whether the parent-death signal
    was set (Linux); the watchdog thread runs everywhere. Idempotent within a process.
    """
    global _guarded_pid
    if _guarded_pid == os.getpid():
        return True
    _guarded_pid = os.getpid()
    if parent_pid is None:
        parent = multiprocessing.parent_process()
        parent_pid = parent.pid if parent is not None else None
    ppid = os.getppid()
    pdeath = _set_parent_death_signal()
    # the parent may have died before the signal was armed: then nothing would ever deliver it
    if os.getppid() != ppid or (parent_pid is not None and _parent_gone(ppid, parent_pid)):
        _orphaned(parent_pid or ppid)

    def watch() -> None:
        while True:
            time.sleep(interval)
            if os.getppid() != ppid:         # reparented: the parent (or a forkserver between us) died
                _orphaned(ppid)

    threading.Thread(target=watch, name="nanoimpact-parent-watchdog", daemon=True).start()
    return pdeath


def dask_setup(worker) -> None:
    """Dask worker preload (`preload=["nanoimpact.executors"]`): end with the LocalCluster's process."""
    guard_parent()


# ----------------------------------------------------------------------------- executors
class _Base:
    name = ""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(cancel=exc_type is not None)

    def describe(self) -> str:
        return self.name

    def worker_pids(self) -> list[int]:
        """Process ids of the workers (for diagnostics and tests)."""
        return [os.getpid()]


class Local(_Base):
    """Serial, in this process."""

    name = "local"

    def map(self, fn: Callable, items: Iterable, on_error: str = "raise") -> Iterator[tuple[int, Any]]:
        _check_on_error(on_error)
        items = list(items)

        def run():
            for i, item in enumerate(items):
                try:
                    out = fn(item)
                except Exception as exc:        # noqa: BLE001 -- collected or re-raised below
                    if on_error == "raise":
                        raise
                    log.debug("job %d failed: %s", i, one_line(exc))   # collected: the caller reports it
                    out = Failure.of(i, exc)
                yield i, out
        return run()

    def close(self, cancel: bool | None = None) -> None:
        pass

    def describe(self) -> str:
        return "local: serial, in this process"


def _init_pool_worker(parent_pid: int) -> None:
    # a forked worker inherits its parent's Python SIGTERM handler, if any: one the GIL-holding job would
    # delay; the default action ends the worker at once (the parent-death signal and terminate() send SIGTERM)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    guard_parent(parent_pid)


class Processes(_Base):
    """A local pool of worker processes (forked or spawned, guarded against their parent's death).

    Queued jobs are cancelled through the pool's own shutdown (`cancel_futures`), never by cancelling
    futures from outside: Python 3.11's pool then fails on stopping its workers (CPython gh-107219).
    So a map that failed (`raise`) or was left before its end spends the pool: close it.
    """

    name = "processes"

    def __init__(self, workers: int | None):
        self.workers = workers or os.cpu_count() or 1
        # fork where it is safe (this process runs one thread: no lock another thread holds is copied
        # locked): the workers start at once with the modules already imported; else spawn (seconds per
        # worker: each imports numpy, scipy and the job's package again)
        safe_fork = "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1
        self.start_method = "fork" if safe_fork else "spawn"
        self.pool = ProcessPoolExecutor(max_workers=self.workers,
                                        mp_context=multiprocessing.get_context(self.start_method),
                                        initializer=_init_pool_worker, initargs=(os.getpid(),))
        self._procs: dict = {}                  # pid -> Process, every worker the pool started
        self._manager = None                    # the pool's manager thread, to join after a shutdown
        self._aborted = False
        log.debug("processes: a pool of %d worker process(es) (%s)", self.workers, self.start_method)

    def describe(self) -> str:
        return f"processes: a local pool of {self.workers} worker process(es) ({self.start_method})"

    def map(self, fn: Callable, items: Iterable, on_error: str = "raise") -> Iterator[tuple[int, Any]]:
        _check_on_error(on_error)
        futures = {self.pool.submit(_Carried(fn), item): i for i, item in enumerate(items)}
        self._procs.update(self.pool._processes or {})          # noqa: SLF001 -- no public accessor
        self._manager = self.pool._executor_manager_thread or self._manager   # noqa: SLF001

        def results():
            try:
                for fut in as_completed(futures):
                    i = futures[fut]
                    exc = fut.exception()
                    if exc is None:
                        yield i, fut.result()
                    elif on_error == "collect":
                        log.debug("job %d failed: %s", i, one_line(exc))   # collected: the caller reports it
                        yield i, Failure.of(i, exc)
                    else:
                        self._aborted = True
                        n = self._drop_queued(futures)
                        # info: the error itself reaches the caller, which reports it in one line
                        log.info("job %d failed (%s); %d queued job(s) cancelled", i, one_line(exc), n)
                        raise exc
            finally:                            # left before the end: the queued jobs never start
                if not all(f.done() for f in futures):
                    self._drop_queued(futures)
        return results()

    def _drop_queued(self, futures) -> int:
        queued = sum(not (f.running() or f.done()) for f in futures)
        self.pool.shutdown(wait=False, cancel_futures=True)
        return queued

    def worker_pids(self) -> list[int]:
        return sorted(pid for pid, p in self._procs.items() if p.is_alive())

    def close(self, cancel: bool | None = None) -> None:
        """Shut the pool down; with `cancel` (default: after a failed map) queued jobs are dropped and
        running ones stopped, else running and queued jobs finish first."""
        if cancel is None:
            cancel = self._aborted
        if cancel:
            running = [p for p in self._procs.values() if p.is_alive()]
            if running:
                log.info("processes: stopping %d worker(s)", len(running))
            for p in running:
                p.terminate()
            for p in running:
                p.join(timeout=10)
        self.pool.shutdown(wait=True, cancel_futures=cancel)
        if self._manager is not None:
            self._manager.join(timeout=30 if cancel else None)


class Dask(_Base):
    """dask.distributed: a LocalCluster of `workers` processes, or an existing cluster at `scheduler`."""

    name = "dask"

    def __init__(self, workers: int | None, scheduler: str | None):
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError as exc:
            raise BackendUnavailable(f"executor 'dask' needs dask.distributed ({one_line(exc)}); install it with "
                                     "pip install 'nanoimpact[dist]'") from exc
        self.cluster = None
        self._futures: list = []
        self._aborted = False
        self._quieted = None
        if scheduler:
            if workers is not None:
                log.info("dask: --workers %s ignored: the cluster at %s has its own workers", workers, scheduler)
            self.client = Client(scheduler)
            try:
                link = self.client.dashboard_link or ""
            except (KeyError, AttributeError):
                link = ""
            self.where = f"the cluster at {scheduler}"
            self.dashboard = link or "unavailable: the scheduler runs no dashboard"
        else:
            self.workers = workers or 2
            has_bokeh = importlib.util.find_spec("bokeh") is not None
            # the scheduler and nannies run in this process and log every start and stop at INFO (dask's own
            # logger level, which its silence_logs does not touch): quiet them unless everything was asked for
            dask_log = logging.getLogger("distributed")
            if logging.getLogger().getEffectiveLevel() >= logging.WARNING > dask_log.getEffectiveLevel():
                self._quieted = (dask_log, dask_log.level)
                dask_log.setLevel(logging.WARNING)
            # ":0": a free port (the scheduler's HTTP server runs even without bokeh's dashboard);
            # the preload makes every worker end with this process (guard_parent)
            try:
                self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True,
                                            dashboard_address=":0", silence_logs=logging.CRITICAL,
                                            preload=["nanoimpact.executors"])
                self.client = Client(self.cluster)
            except BaseException:
                self._restore_logging()
                if self.cluster is not None:
                    self.cluster.close()
                raise
            self.where = f"a LocalCluster of {self.workers} worker process(es) at {self.cluster.scheduler_address}"
            if not has_bokeh:
                self.dashboard = "unavailable: bokeh is not installed (pip install 'bokeh>=3.1' for it)"
            else:
                self.dashboard = self.cluster.dashboard_link or "unavailable: dask did not start it (see its log)"
        log.info("dask: %s; dashboard %s", self.where, self.dashboard)

    def describe(self) -> str:
        return f"dask: {self.where}; dashboard {self.dashboard}"

    def map(self, fn: Callable, items: Iterable, on_error: str = "raise") -> Iterator[tuple[int, Any]]:
        from dask.distributed import as_completed as dask_completed

        _check_on_error(on_error)
        futures = [self.client.submit(_Carried(fn), item, pure=False) for item in items]
        self._futures = [f for f in self._futures if not f.done()] + futures
        index = {f.key: i for i, f in enumerate(futures)}

        def results():
            try:
                for fut in dask_completed(futures):
                    i = index[fut.key]
                    if fut.status == "finished":
                        yield i, fut.result()
                        continue
                    try:
                        exc = fut.exception() if fut.status == "error" else None
                    except Exception as err:     # noqa: BLE001 -- cancelled, or lost with the scheduler
                        exc = err
                    if exc is None:
                        exc = CancelledError(f"the job's future is {fut.status}")
                    if on_error == "collect":
                        log.debug("job %d failed: %s", i, one_line(exc))   # collected: the caller reports it
                        yield i, Failure.of(i, exc)
                    else:
                        self._aborted = True
                        n = self._cancel(futures)
                        log.info("job %d failed (%s); %d other job(s) cancelled", i, one_line(exc), n)
                        raise exc
            finally:                            # the consumer stopped early: drop what is left
                self._cancel(futures)
        return results()

    def _cancel(self, futures) -> int:
        left = [f for f in futures if not f.done()]
        if left:
            self.client.cancel(left)
        return len(left)

    def worker_pids(self) -> list[int]:
        return sorted(self.client.run(os.getpid).values())

    def close(self, cancel: bool | None = None) -> None:
        """Cancel what is left (default: after a failed map), close the client and a LocalCluster."""
        if cancel is None:
            cancel = self._aborted
        try:
            if cancel:
                self._cancel(self._futures)
            self._futures = []
            self.client.close()
        finally:
            if self.cluster is not None:
                # after a failure the nannies kill the workers still running a job and warn about each (the
                # failure itself reaches the caller, which reports it in one line)
                nanny = logging.getLogger("distributed.nanny")
                level = nanny.level
                if cancel:
                    nanny.setLevel(logging.ERROR)
                try:
                    self.cluster.close()
                finally:
                    nanny.setLevel(level)
            self._restore_logging()

    def _restore_logging(self) -> None:
        if self._quieted is not None:
            logger, level = self._quieted
            logger.setLevel(level)
            self._quieted = None


def _check_workers(workers) -> None:
    if workers is None:
        return
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError("workers", workers, "an integer >= 1 (leave it out for the default)")


def check_executor(name: str = "local", workers: int | None = None, scheduler: str | None = None) -> None:
    """Refuse a bad choice before anything starts: InputError (a ValueError) naming the value, BackendUnavailable
    when dask is asked for and not installed."""
    if name not in NAMES:
        raise InputError("executor", name, "one of " + ", ".join(NAMES))
    _check_workers(workers)
    if scheduler and name != "dask":
        raise InputError("--scheduler", scheduler, f"goes with --executor dask, not --executor {name}")
    if name == "dask" and (importlib.util.find_spec("dask") is None
                           or importlib.util.find_spec("distributed") is None):
        raise BackendUnavailable("--executor dask needs dask.distributed, which is not installed: "
                                 "pip install \"nanoimpact[dist]\"")


def executor(name: str = "local", workers: int | None = None, scheduler: str | None = None):
    """An executor by name (`local`, `processes`, `dask`); InputError (a ValueError) for a bad argument,
    BackendUnavailable when dask.distributed is missing."""
    check_executor(name, workers, scheduler)
    if name == "local":
        return Local()
    if name == "processes":
        return Processes(workers)
    return Dask(workers, scheduler)
