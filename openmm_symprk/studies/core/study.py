"""The skeleton of a study: plan the runs, run one, store it under its key, summarise.

A study subclasses :class:`Study` and gives

* :meth:`Study.plan` -- every run the study needs, each a :class:`Run` (who it is: its row, replica and the settings
  it depends on, hashed into its :attr:`Run.key`; what executing it needs; its cost), or jobs
  (:class:`~.jobs.Job`) that yield runs, each chosen from the results before it (the bench's stability searches);
* :attr:`Study.work` -- a module-level function ``work(shared, *args) -> (arrays, info)`` that does one run in
  whatever process executes it (``shared``: the data :meth:`Study.shared` gives under the run's ``name``);
* :meth:`Study.summarise` -- the results from the stored runs.

:meth:`Study.run` takes the folder's lock, skips every run already stored, executes the rest (in this process,
spawned worker processes or on a Dask cluster, the most expensive first) with a progress bar, stores each run
the moment it finishes (``runs/<key>.json`` with the run's ``meta`` and ``info``, ``runs/<key>.npz`` with its
arrays; :meth:`Study.reused` and :meth:`Study.keep` say how a study reads and writes them), and summarises.  An interrupted study keeps every finished run; calling it again continues.  A study
with per-run trajectory observables keeps them in the arrays, its replicas as runs of one row, and compares
rows replica by replica in :meth:`Study.summarise` (:func:`openmm_symprk.stats.paired`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from functools import cached_property

from ...support import InputError, MissingDependencyError, require
from .executors import make_executor
from .folders import FolderLock, FolderLockedError
from .jobs import Job, run_jobs, single
from .store import RunStore, run_key

__all__ = ["Run", "Study", "progress_bar"]


def progress_bar(total: int, desc: str, enabled: bool = True):
    """A tqdm progress bar (disabled: a silent one with the same methods)."""
    tqdm = require("tqdm", "studies", "openmm_symprk.studies (progress bar)").tqdm

    return tqdm(total=total, desc=desc, unit="run", disable=not enabled, dynamic_ncols=True)


@dataclass
class Run:
    """One run of a study: who it is (``row``, ``replica`` and ``settings``, with ``context``, hashed into its
    :attr:`key`) and what executing it needs (``name``, ``args``)."""

    row: object  # a Row or its label
    replica: int | None  # None: a study without replicas (the bench)
    settings: dict  # the study's settings the run depends on
    name: str  # which entry of Study.shared() the run needs
    args: tuple = ()  # passed to Study.work after the shared data (picklable)
    meta: dict = field(default_factory=dict)  # stored with the run: what identifies it (row, replica, ...)
    cost: float = 1.0  # relative cost, to start the longest runs first
    context: dict = field(default_factory=dict)  # hashed beside the settings: the states' key, the run version ...
    digits: int = 16  # hex digits of the key

    @cached_property
    def key(self) -> str:
        """The run's key: :func:`~.store.run_key` of its row, replica, settings and context."""
        return run_key(self.row, self.replica, self.settings, self.digits, **self.context)


class Study:
    """Base class of a study in the folder ``out`` (see the module's docstring)."""

    #: The command named in the lock's error and the progress bar.
    command = "symprk study"
    #: What another process gets while this study holds the folder's lock.
    locked_error = FolderLockedError
    #: ``work(shared, *args) -> (arrays, info)``: one run (a module-level function, set by the subclass).
    work = None

    def __init__(self, out: str, workers: int = 1, scheduler: str | None = None, progress: bool = True,
                 log=print):
        if int(workers) < 1:
            raise InputError(f"workers must be >= 1, got {workers!r}")
        self.out, self.workers, self.scheduler, self.progress, self.log = out, int(workers), scheduler, progress, log
        self.store: RunStore | None = None

    # -- to be given by a study -----------------------------------------------------------------------------------
    def plan(self) -> list:
        raise NotImplementedError

    def shared(self, runs: list) -> dict:
        """{name: data} that the given (missing) runs, or jobs, need, shipped to each worker once."""
        return {}

    def summarise(self, runs: list):
        raise NotImplementedError

    def stored(self, run: Run, info: dict):
        """Called in this process after each run is stored (e.g. to log a failed run)."""

    def begin(self):
        """Called under the folder's lock with :attr:`store` open, before :meth:`plan` (e.g. to refuse a folder)."""

    def open_store(self, create: bool = True) -> RunStore:
        """The store of the finished runs (a study with typed records gives its own)."""
        return RunStore(self.out, create=create)

    def reused(self, run: Run):
        """What the job of ``run`` receives from a stored run (its info), or None to execute it."""
        return self.store.info(run.key) if run.key in self.store else None

    def keep(self, run: Run, future):
        """Store the run ``future`` finished (``(arrays, info)``, ``info`` stored with the run's ``meta``) and return
        what its job receives (the stored info)."""
        arrays, info = future.result()
        info = dict(info, **run.meta)
        self.store.put(run.key, info, arrays)
        self.stored(run, info)
        return info

    def chart(self, draw, *args, **kwargs):
        """``draw(*args, **kwargs)``, a study's chart; without matplotlib the log says so (MissingDependencyError
        names the extra that installs it) and the study's tables stand without it.  Any other error, an ImportError
        of a bug included, keeps its traceback."""
        try:
            draw(*args, **kwargs)
        except MissingDependencyError as exc:
            self.log(f"no chart: {exc}")

    # -- the skeleton ---------------------------------------------------------------------------------------------
    def run(self, report_only: bool = False):
        """Run what is missing and return :meth:`summarise` of every planned run.  ``report_only``: run nothing and
        summarise the planned runs already stored (a study still running in another process, or rows given
        fewer replicas than the others; a plan of runs, not jobs); the folder is not locked, and ValueError says
        when nothing is stored."""
        if report_only:
            self.store = self.open_store(create=False)
            if not len(self.store):
                raise InputError(f"no finished runs in {self.out}: run the study without --report-only first")
            runs = self.plan()
            missing = sum(r.key not in self.store for r in runs)
            if missing == len(runs):
                raise InputError(f"none of the {len(runs)} planned runs is stored in {self.out} (other settings?)")
            if missing:
                self.log(f"report only: {missing} of {len(runs)} planned runs are not finished and are left out")
            return self.summarise(runs)
        require("tqdm", "studies", f"{self.command} (progress bar)")  # before any work: states, runs
        os.makedirs(self.out, exist_ok=True)
        lock = FolderLock(self.out, self.command, self.locked_error)
        try:
            self.store = self.open_store()
            self.begin()
            planned = self.plan()
            todo = [p for p in planned if not isinstance(p, Run) or p.key not in self.store]
            done = len(planned) - len(todo)
            if done:
                self.log(f"reusing {done} finished runs in {self.out}")
            if todo:
                self.execute(todo)
            return self.summarise(planned)
        finally:
            lock.release()

    def execute(self, todo: list) -> dict:
        """Run ``todo`` (runs, and jobs that yield runs), storing each run as it finishes (:meth:`keep`); on an
        interruption keep what finished.  Returns {"computed": n, "reused": n}
        (:func:`~openmm_symprk.studies.core.jobs.run_jobs`)."""
        jobs = [p if isinstance(p, Job) else Job(single(p), p.cost) for p in todo]
        executor = make_executor(type(self).work, self.shared(todo), self.workers, self.scheduler)
        bar = progress_bar(sum(j.remaining for j in jobs), self.command.split()[-1] + " runs", self.progress)
        try:
            return run_jobs(jobs, executor, self.reused, lambda ex, run: ex.submit(run.name, *run.args), self.keep,
                            bar)
        finally:
            bar.close()

    def results(self, runs: list, by: tuple) -> dict:
        """The stored runs among ``runs`` grouped by the ``meta`` fields ``by`` (e.g. a row: model, method, step):
        {(values...): [(arrays, info) sorted by the "replica" field when there is one]}; runs not stored are left
        out.  The replicas of a row are what :func:`openmm_symprk.stats.paired` compares with a reference row."""
        out = {}
        for run in runs:
            info = self.store.info(run.key)
            if info is None:
                continue
            arrays = self.store.arrays(run.key) or {}
            out.setdefault(tuple(run.meta[k] for k in by), []).append((arrays, info))
        for reps in out.values():
            reps.sort(key=lambda rep: rep[1].get("replica", 0))
        return out
