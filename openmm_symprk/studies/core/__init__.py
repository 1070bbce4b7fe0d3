"""The machinery every study shares (in the spirit of MDAnalysis' AnalysisBase: plan, run one, keep, summarise).

* :mod:`.folders` -- the output folder: an exclusive lock, atomic JSON and array files;
* :mod:`.rows` -- the one row type, :class:`~.rows.Row` (a configuration written as one line, its label);
* :mod:`.engine` -- a row running from a state on any platform, and its sampler (:class:`~.engine.RowEngine`);
* :mod:`.timing` -- rows timed in turns;
* :mod:`.scenes`, :mod:`.replicas` -- the named scenes, and the replica states of a scene or a rigid-water box;
* :mod:`.store` -- run keys (a row's label and everything else a run depends on) and finished runs on disk, one
  ``runs/<key>.json`` (+ ``<key>.npz``) each, written atomically;
* :mod:`.executors` -- where runs execute: this process, spawned worker processes, or a Dask cluster;
* :mod:`.jobs` -- generators of runs (one run, or a search that picks each run from the results before it)
  driven to their ends, stored results replayed, a bounded number in flight, the most expensive first;
* :mod:`.study` -- :class:`~.study.Study`: a study plans its runs (:class:`~.study.Run`: a row, a replica and the
  settings it depends on, and its key; or jobs that yield them), runs one, and summarises the stored runs;
  the base class skips what is stored, executes the rest with a progress bar and stores each run the moment it
  finishes, under the folder's lock.
"""
from .folders import FolderLock, FolderLockedError, jsonable, write_json, write_npz, write_text
from .jobs import Job, run_jobs, single
from .store import RunStore, run_key
from .study import Run, Study, progress_bar

__all__ = ["FolderLock", "FolderLockedError", "jsonable", "write_json", "write_npz", "write_text", "Job", "run_jobs", "single", "RunStore", "run_key", "Run",
           "Study", "progress_bar"]
