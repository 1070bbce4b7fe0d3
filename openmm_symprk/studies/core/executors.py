"""Where runs execute: in this process, in local worker processes, or on a Dask cluster.

All three give a study the same operations: ``submit(name, *args)`` -> a future of ``work(shared[name], *args)``,
``wait(futures)`` -> the finished ones, and ``shutdown``.  ``work`` is a module-level function (it is pickled);
``shared`` maps names to the data every run of that name needs (a scene's payload, a model's replica states),
sent to each worker once: a process-pool initializer, ``Client.scatter`` on Dask.

Local workers are started with the "spawn" method: OpenMM's CPU platform keeps thread pools that a forked child
must not inherit.  Dask is imported only when a scheduler address is given (install the ``cluster`` extra:
``pip install "openmm_symprk[cluster]"``).
"""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import warnings

from ...support import require

__all__ = ["SerialExecutor", "PoolExecutor", "DaskExecutor", "make_executor"]

_shared: dict = {}


def _init_worker(shared):
    _shared.clear()
    _shared.update(shared)


def _quietly(work, payload, args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # e.g. the periodic-box conservation warning, expected in a study
        return work(payload, *args)


def _call(work, name, args):
    """In a pool worker: ``work`` on the shared data of ``name``."""
    return _quietly(work, _shared[name], args)


def _done(fn, *args) -> cf.Future:
    """A finished future of ``fn(*args)`` (the in-process executor's): its result, or the exception it raised."""
    fut = cf.Future()
    try:
        fut.set_result(fn(*args))
    except BaseException as exc:  # noqa: BLE001 - handed back to the caller like a real future
        fut.set_exception(exc)
    return fut


class SerialExecutor:
    """Runs each submission at once, in this process (workers <= 1; tests and debugging)."""

    workers = 1

    def __init__(self, work, shared):
        self.work, self.shared = work, shared

    def submit(self, name, *args):
        return _done(_quietly, self.work, self.shared[name], args)

    def wait(self, futures):
        return set(futures)

    def shutdown(self, cancel=False, grace: float = 0.0, inflight=()):
        pass


class PoolExecutor:
    """``concurrent.futures.ProcessPoolExecutor`` with ``workers`` spawned processes."""

    def __init__(self, work, shared, workers: int):
        self.work, self.workers = work, workers
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                                           initializer=_init_worker, initargs=(shared,))

    def submit(self, name, *args):
        return self.pool.submit(_call, self.work, name, args)

    def wait(self, futures):
        done, _ = cf.wait(futures, return_when=cf.FIRST_COMPLETED)
        return done

    def shutdown(self, cancel=False, grace: float = 3.0, inflight=()):
        """Normal end: wait for the workers.  ``cancel`` (an interrupted study): drop queued runs, give the
        running ones ``grace`` seconds to finish (the caller keeps what finishes), then stop the workers instead
        of waiting for long runs."""
        if not cancel:
            self.pool.shutdown(wait=True)
            return
        for fut in inflight:
            fut.cancel()
        running = [f for f in inflight if not f.done()]
        if running:
            cf.wait(running, timeout=grace)
        procs = list(getattr(self.pool, "_processes", {}).values())  # CPython keeps the workers here
        self.pool.shutdown(wait=False, cancel_futures=True)
        for p in procs:
            if p.is_alive():
                p.terminate()
        for p in procs:
            p.join(timeout=5)


class DaskExecutor:
    """A Dask distributed scheduler at ``address`` (e.g. ``tcp://head:8786``); workers need this package."""

    def __init__(self, work, shared, address):
        Client = require("dask.distributed", "cluster", "a study's --scheduler (DaskExecutor)").Client
        self.work = work
        self.client = Client(address)
        info = self.client.scheduler_info()
        self.workers = max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))
        # a list of one: scattering a dict directly would scatter its values one by one
        self.shared = {k: self.client.scatter([v], broadcast=True)[0] for k, v in shared.items()}

    def submit(self, name, *args):
        return self.client.submit(_quietly, self.work, self.shared[name], args, pure=False)

    def wait(self, futures):
        wait = require("dask.distributed", "cluster", "the bench's --scheduler (DaskExecutor)").wait

        return set(wait(list(futures), return_when="FIRST_COMPLETED").done)

    def shutdown(self, cancel=False, grace: float = 0.0, inflight=()):
        if cancel:
            for fut in inflight:
                fut.cancel()
        self.client.close()


def make_executor(work, shared: dict, workers: int = 1, scheduler: str | None = None):
    """A Dask executor with ``scheduler``, else a pool of ``workers`` processes, else this process."""
    if scheduler:
        return DaskExecutor(work, shared, scheduler)
    if workers <= 1:
        return SerialExecutor(work, shared)
    return PoolExecutor(work, shared, workers)
