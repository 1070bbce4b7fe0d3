"""Jobs: generators of runs, executed with a bounded number in flight, the most expensive ready one first.

A job is a generator that yields the runs it needs and receives each one's result: a plain run is one yield
(:func:`single`); a search (the bench's stability bisection) yields run after run, each chosen from the results
before it.  :func:`run_jobs` takes every run's stored result when there is one (``stored``) and executes the
others (``submit``), keeping each result the moment it arrives (``finish``) before anything else happens.  So a
study called again replays its jobs from disk and continues where it stopped, and on an interruption the queued
runs are dropped, the running ones get a few seconds to finish (what finishes is kept), and the workers stop.
"""
from __future__ import annotations

import heapq
import itertools

__all__ = ["Job", "single", "run_jobs"]


class Job:
    """A generator of runs, with a scheduling ``cost`` (larger first) and an ``estimate`` of how many runs it
    yields (for the progress bar); other keywords are kept as attributes (e.g. ``kind``, ``scene``)."""

    def __init__(self, gen, cost: float = 1.0, estimate: int = 1, **tags):
        self.gen, self.cost, self.estimate = gen, cost, estimate
        self.__dict__.update(tags)
        self.count, self.done, self.result = 0, False, None

    @property
    def remaining(self) -> int:
        return 0 if self.done else max(1, self.estimate - self.count)


def single(run):
    """The job of one run: yields it, returns its result."""
    result = yield run
    return result


def run_jobs(jobs, executor, stored, submit, finish, bar=None, on_result=None) -> dict:
    """Drive ``jobs`` to their ends; returns {"computed": n, "reused": n}.

    ``stored(run)``: the run's kept result, or None to execute it; ``submit(executor, run)``: a future;
    ``finish(run, future)``: keep the future's result and return what the job receives; ``bar``: a progress bar
    (tqdm-like: ``total``, ``n``, ``update``); ``on_result(result)``: called after each computed run is kept."""
    counter = itertools.count()
    ready, inflight = [], {}
    stats = {"computed": 0, "reused": 0}

    def tick():
        if bar is not None:
            bar.total = bar.n + sum(j.remaining for j in jobs)
            bar.update(1)

    def advance(job, result, first=False):
        while True:
            try:
                run = next(job.gen) if first else job.gen.send(result)
            except StopIteration as stop:
                job.done, job.result = True, stop.value
                return
            first = False
            result = stored(run)
            if result is None:
                heapq.heappush(ready, (-job.cost, next(counter), job, run))
                return
            stats["reused"] += 1
            job.count += 1
            tick()

    for job in jobs:
        advance(job, None, first=True)
    try:
        while ready or inflight:
            while ready and len(inflight) < executor.workers + 1:
                _, _, job, run = heapq.heappop(ready)
                inflight[submit(executor, run)] = (job, run)
            for fut in executor.wait(set(inflight)):
                job, run = inflight.pop(fut)
                result = finish(run, fut)
                stats["computed"] += 1
                job.count += 1
                tick()
                if on_result is not None:
                    on_result(result)
                advance(job, result)
    except BaseException:
        executor.shutdown(cancel=True, inflight=list(inflight))
        for fut, (job, run) in inflight.items():  # keep what finished while stopping
            if fut.done() and not fut.cancelled():
                try:
                    fut.result()
                except BaseException:  # noqa: BLE001 - a run that did not finish is not kept
                    continue
                if stored(run) is None:
                    finish(run, fut)
                    stats["computed"] += 1
        raise
    executor.shutdown()
    return stats
