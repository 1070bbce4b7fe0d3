"""Where runs execute: in this process, in local worker processes, or on a Dask cluster.

All three give the sweep the same two operations, ``submit(spec_dict, scene_name)`` -> future and
``wait(futures)`` -> the finished ones.  Each worker receives every scene payload once (a process-pool
initializer; ``Client.scatter`` on Dask) and keeps the deserialized scenes in a per-process cache.

Local workers are started with the "spawn" method: OpenMM's CPU platform keeps thread pools that a
forked child must not inherit.  Dask is imported only when a scheduler address is given (install the
``cluster`` extra: ``pip install "openmm_symprk[cluster]"``).
"""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp

from ...support import require

_payloads: dict = {}
_scenes: dict = {}


def _init_worker(payloads):
    _payloads.clear()
    _payloads.update(payloads)
    _scenes.clear()


def _scene(name, payload=None):
    from .registry import BenchScene

    payload = payload if payload is not None else _payloads[name]
    key = (name, payload["fingerprint"])
    if key not in _scenes:
        _scenes[key] = BenchScene.from_payload(payload)
    return _scenes[key]


def work(spec_dict: dict, scene_name: str, payload=None):
    """Run one spec (in whatever process this is); returns (record, arrays)."""
    import warnings

    from .runs import RunSpec
    from .stability import run_spec

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_spec(RunSpec(**spec_dict), _scene(scene_name, payload))


class _Done:
    """A finished 'future' for the in-process executor."""

    def __init__(self, fn, *args):
        try:
            self._result, self._exc = fn(*args), None
        except BaseException as exc:  # noqa: BLE001 - handed back to the caller like a real future
            self._result, self._exc = None, exc

    def result(self):
        if self._exc is not None:
            raise self._exc
        return self._result

    def cancel(self):
        return False

    def done(self):
        return True


class SerialExecutor:
    """Runs each spec at submission, in this process (workers <= 1; tests and debugging)."""

    workers = 1

    def __init__(self, payloads):
        _init_worker(payloads)

    def submit(self, spec_dict, scene_name):
        return _Done(work, spec_dict, scene_name)

    def wait(self, futures):
        return set(futures)

    def shutdown(self, cancel=False, grace: float = 0.0, inflight=()):
        pass


class PoolExecutor:
    """``concurrent.futures.ProcessPoolExecutor`` with ``workers`` spawned processes."""

    def __init__(self, payloads, workers: int):
        self.workers = workers
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                                           initializer=_init_worker, initargs=(payloads,))

    def submit(self, spec_dict, scene_name):
        return self.pool.submit(work, spec_dict, scene_name)

    def wait(self, futures):
        done, _ = cf.wait(futures, return_when=cf.FIRST_COMPLETED)
        return done

    def shutdown(self, cancel=False, grace: float = 3.0, inflight=()):
        """Normal end: wait for the workers.  ``cancel`` (an interrupted sweep): drop queued runs, give
        the running ones ``grace`` seconds to finish (their records are kept by the caller), then stop
        the workers instead of waiting for long runs."""
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

    def __init__(self, payloads, address):
        Client = require("dask.distributed", "cluster", "the bench's --scheduler (DaskExecutor)").Client
        self.client = Client(address)
        info = self.client.scheduler_info()
        self.workers = max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))
        # a list of one: scattering a dict directly would scatter its values one by one
        self.payloads = {k: self.client.scatter([v], broadcast=True)[0] for k, v in payloads.items()}

    def submit(self, spec_dict, scene_name):
        return self.client.submit(work, spec_dict, scene_name, self.payloads[scene_name], pure=False)

    def wait(self, futures):
        wait = require("dask.distributed", "cluster", "the bench's --scheduler (DaskExecutor)").wait

        return set(wait(list(futures), return_when="FIRST_COMPLETED").done)

    def shutdown(self, cancel=False, grace: float = 0.0, inflight=()):
        if cancel:
            for fut in inflight:
                fut.cancel()
        self.client.close()


def make_executor(payloads, workers: int = 1, scheduler: str | None = None):
    if scheduler:
        return DaskExecutor(payloads, scheduler)
    if workers <= 1:
        return SerialExecutor(payloads)
    return PoolExecutor(payloads, workers)
