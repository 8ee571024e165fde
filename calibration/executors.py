"""Where independent jobs run: in this process, in a local process pool, or on Dask.

One interface: `executor(name, workers, scheduler)` returns an object whose `map(fn, items)`
yields (item index, result) as jobs finish, and `close()`. `fn` and the items must be picklable
(module-level functions) for `processes` and `dask`.

* `local`: serial, in process (no server; the default).
* `processes`: concurrent.futures.ProcessPoolExecutor with `workers` processes.
* `dask`: dask.distributed. Without `scheduler`, a LocalCluster of `workers` single-threaded
  worker processes is started and closed; with `scheduler` (tcp://host:port) the Client connects
  to an existing cluster -- e.g. one that dask-jobqueue's SLURMCluster started on a cluster's
  login node, whose `scheduler_address` is passed here (docs/calibration.md).
"""
from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Callable, Iterable, Iterator

NAMES = ("local", "processes", "dask")


class Local:
    name = "local"

    def map(self, fn: Callable, items: Iterable) -> Iterator[tuple[int, object]]:
        for i, item in enumerate(items):
            yield i, fn(item)

    def close(self) -> None:
        pass


class Processes:
    name = "processes"

    def __init__(self, workers: int | None):
        self.pool = ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1)

    def map(self, fn, items):
        futures = {self.pool.submit(fn, item): i for i, item in enumerate(items)}
        for fut in as_completed(futures):
            yield futures[fut], fut.result()

    def close(self):
        self.pool.shutdown()


class Dask:
    name = "dask"

    def __init__(self, workers: int | None, scheduler: str | None):
        from dask.distributed import Client, LocalCluster

        self.cluster = None
        if scheduler:
            self.client = Client(scheduler)
        else:
            self.cluster = LocalCluster(n_workers=workers or 2, threads_per_worker=1, processes=True,
                                        dashboard_address=None)
            self.client = Client(self.cluster)

    def map(self, fn, items):
        from dask.distributed import as_completed as dask_completed

        items = list(items)
        futures = [self.client.submit(fn, item, pure=False) for item in items]
        index = {f.key: i for i, f in enumerate(futures)}
        for fut in dask_completed(futures):
            yield index[fut.key], fut.result()

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def executor(name: str = "local", workers: int | None = None, scheduler: str | None = None):
    """An executor by name; ValueError names the allowed ones."""
    if name == "local":
        if scheduler:
            raise ValueError("--scheduler goes with --executor dask")
        return Local()
    if name == "processes":
        if scheduler:
            raise ValueError("--scheduler goes with --executor dask")
        return Processes(workers)
    if name == "dask":
        return Dask(workers, scheduler)
    raise ValueError(f"executor = {name!r}: one of {', '.join(NAMES)}")
