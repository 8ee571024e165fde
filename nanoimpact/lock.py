"""One writer per run directory: an exclusive lock that a killed process cannot leave stuck.

    with run_lock(run_dir, wait=True):      # or wait=False: raise RunBusy at once if another process holds it
        ...                                 # read and write run_dir

How
    ``fcntl.flock(LOCK_EX)`` on a lock file *beside* the run directory, ``<run_dir>.lock`` (beside, not inside,
    so that clearing the run directory with ``shutil.rmtree`` cannot delete the file under its holder). The kernel
    drops the lock when the holder's file descriptor is closed, which happens however the holder ends -- normal
    exit, exception, Ctrl-C, SIGKILL, out-of-memory kill -- so a dead process never leaves the directory locked;
    at worst it leaves the lock *file*, which means nothing: the next locker simply takes it. The holder writes
    its PID, host and start time into the file (for the message a refused or waiting process shows) and deletes
    the file when it lets go (still holding the lock). A locker that got the lock on a file that has meanwhile been
    deleted or replaced (checked by inode) lets go and opens the path again, so that release never lets two
    processes in. Do not delete a lock file by hand while its run is going: the next process would create a
    new file and get in beside the holder.

    The lock is per open file, not per process: two threads of one process that each call :func:`run_lock` on
    the same directory exclude each other too (the second waits, or gets :class:`RunBusy`). It is not
    re-entrant: a thread that already holds the lock and asks again waits for itself (wait=True) or is refused.

Caveat: network file systems
    On a local file system (ext4, xfs, tmpfs, ...) the lock excludes every process of the machine. On NFS, Linux
    clients emulate ``flock`` with POSIX byte-range locks through the NFS lock manager, so it also excludes
    processes on other nodes -- *unless* the share is mounted with ``local_lock=flock``/``local_lock=all`` or
    ``nolock`` (then the lock is local to each node), or the lock manager is not running. Some other network and
    parallel file systems (older Lustre without ``-o flock``, some FUSE file systems, SMB) make ``flock`` local
    to the node or unsupported. If several nodes share one cache directory, check the mount options, or give
    each node its own cache (``--cache`` / ``NANOIMPACT_CACHE``).
"""
from __future__ import annotations

import contextlib
import datetime
import errno
import fcntl
import json
import logging
import os
import socket
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

from nanoimpact.errors import RunBusy

__all__ = ["run_lock", "lock_path", "read_holder", "Holder", "LOCK_SUFFIX"]

LOCK_SUFFIX = ".lock"
log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Holder:
    """Who holds a lock, as it wrote itself into the lock file (fields may be None if it is unreadable)."""
    pid: int | None
    host: str | None
    since: str | None

    def describe(self) -> str:
        pid = "an unknown PID" if self.pid is None else f"PID {self.pid}"
        host = f" on {self.host}" if self.host else ""
        since = f" (since {self.since})" if self.since else ""
        return f"{pid}{host}{since}"


def lock_path(run_dir: str | Path) -> Path:
    """The lock file of ``run_dir``: ``<run_dir>.lock`` beside it."""
    run_dir = Path(run_dir)
    return run_dir.with_name(run_dir.name + LOCK_SUFFIX)


def _parse_holder(raw: bytes) -> Holder | None:
    try:
        doc = json.loads(raw.decode("utf-8"))
        return Holder(int(doc["pid"]), str(doc.get("host") or "") or None, doc.get("since"))
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        return None


def _read_holder_fd(fd: int) -> Holder:
    # the holder writes its record right after it gets the lock: an empty read is a holder between the two
    for attempt in range(5):
        holder = _parse_holder(os.pread(fd, 4096, 0))
        if holder is not None:
            return holder
        time.sleep(0.02 * (attempt + 1))
    return Holder(None, None, None)


def read_holder(run_dir: str | Path) -> Holder | None:
    """The holder recorded in ``run_dir``'s lock file, or None if there is no lock file. The record may be that
    of a process that has died (the file outlives a killed holder); only the lock itself is authoritative."""
    try:
        raw = lock_path(run_dir).read_bytes()
    except FileNotFoundError:
        return None
    return _parse_holder(raw) or Holder(None, None, None)


def _same_file(fd: int, path: Path) -> bool:
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return False
    fst = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (fst.st_dev, fst.st_ino)


def _try_lock(fd: int) -> bool:
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except OSError as exc:
        if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            return False
        raise


def _acquire_once(path: Path) -> tuple[int | None, Holder | None]:
    """Try once: (fd holding the lock, None), or (None, the holder) if another process holds it."""
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            if _try_lock(fd):
                if _same_file(fd, path):
                    return fd, None
                # the file was deleted (its holder let go) or replaced since we opened it: open it again
                os.close(fd)
                continue
            holder = _read_holder_fd(fd)
        except BaseException:
            os.close(fd)
            raise
        os.close(fd)
        return None, holder


@contextlib.contextmanager
def run_lock(run_dir: str | Path, *, wait: bool = True, timeout: float | None = None, poll_s: float = 0.25,
             hint: str = "wait for it to finish and try again, or wait for it (wait=True)",
             on_wait: Callable[[str], None] | None = None) -> Iterator[Path]:
    """Hold the exclusive lock of ``run_dir`` for the ``with`` block; yields the lock file's path.

    ``wait=False``: if another process (or thread) holds it, raise :class:`~nanoimpact.errors.RunBusy` at once,
    one line: the directory, the holder's PID, host and start time, and ``hint`` (the way out). ``wait=True``:
    log ``waiting for PID N on HOST to finish <run_dir>`` (logger ``nanoimpact.lock``, INFO; also passed to
    ``on_wait`` if given) and wait, polling every ``poll_s`` seconds, until it is free -- or raise RunBusy after
    ``timeout`` seconds if one is given. The message is repeated when the holder changes (a third process got
    in first). The parent folder of ``run_dir`` is created if needed; ``run_dir`` itself is not.
    """
    run_dir = Path(run_dir)
    path = lock_path(run_dir)
    path.parent.mkdir(parents=True, exist_ok=True)
    deadline = None if timeout is None else time.monotonic() + float(timeout)
    announced: Holder | None = None
    while True:
        fd, holder = _acquire_once(path)
        if fd is not None:
            break
        if not wait:
            raise RunBusy(f"run directory {run_dir} is in use by {holder.describe()}; {hint}")
        if deadline is not None and time.monotonic() >= deadline:
            raise RunBusy(f"run directory {run_dir} is still in use by {holder.describe()} after waiting "
                          f"{timeout:g} s; {hint}")
        if holder != announced:
            pid = "PID ?" if holder.pid is None else f"PID {holder.pid}"
            host = f" on {holder.host}" if holder.host else ""
            msg = f"waiting for {pid}{host} to finish {run_dir}"
            log.info(msg)
            if on_wait is not None:
                on_wait(msg)
            announced = holder
        time.sleep(poll_s if deadline is None else max(0.0, min(poll_s, deadline - time.monotonic())))
    try:
        # record who holds it, in place (a rename would give the path a new inode, not the one we lock)
        record = {"pid": os.getpid(), "host": socket.gethostname(),
                  "since": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
        os.ftruncate(fd, 0)
        os.pwrite(fd, (json.dumps(record) + "\n").encode("utf-8"), 0)
        yield path
    finally:
        # delete the file while still holding the lock (a waiter that then gets the old inode sees that it is
        # gone and opens the path again), then let go
        with contextlib.suppress(OSError):
            if _same_file(fd, path):
                os.unlink(path)
        os.close(fd)
