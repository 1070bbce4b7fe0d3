"""The study skeleton (studies/core) on a toy study: plan, run one, store atomically under its key, summarise;
a second call reuses every run, an interrupted one keeps what finished, replicas are paired with a reference."""
import json
import os

import numpy as np
import pytest

from openmm_symprk.stats import paired, series_stats
from openmm_symprk.studies.core import FolderLock, FolderLockedError, Run, RunStore, Study, write_json
from openmm_symprk.studies.core.jobs import Job
from openmm_symprk.studies.core.store import run_key as row_key

SETTINGS = {"length_ps": 1.0}
#: The toy's rows by name: a run is keyed by its row's label.
LABELS = {"ref": "verlet 1 fs", "a": "verlet 2 fs", "b": "verlet 3 fs", "c": "verlet 5 fs", "broken": "verlet 4 fs"}


def run_key(row, replica):
    """The key of a toy run: the one key function, as every study's runs have it."""
    return row_key(LABELS[row], replica, SETTINGS)


def toy_work(shared, row, replica):
    """A 'run': a noisy series whose mean is the row's offset plus the replica's own offset (shared by rows)."""
    if row == "broken":
        raise RuntimeError("this row always fails")
    rng = np.random.default_rng(1000 * replica + len(row))
    x = shared["offsets"][replica] + shared["shift"][row] + rng.normal(scale=0.1, size=200)
    return {"x": x}, {"status": "ok", "mean": round(float(x.mean()), 6)}


class ToyStudy(Study):
    command = "symprk toy"
    work = toy_work

    def __init__(self, out, rows, replicas=4, **kw):
        super().__init__(out, progress=False, log=lambda *a: None, **kw)
        self.rows, self.replicas, self.calls = rows, replicas, 0

    def plan(self):
        """One run per row (a label) and replica."""
        return [Run(LABELS[row], r, SETTINGS, "toy", (row, r), {"row": row, "replica": r}, cost=r)
                for row in self.rows for r in range(self.replicas)]

    def shared(self, runs):
        self.calls += len(runs)
        return {"toy": {"offsets": [0.0, 5.0, -3.0, 2.0, 1.0, 7.0], "shift": {"ref": 0.0, "a": 0.0, "b": 0.05,
                                                                                 "broken": 0.0}}}

    def summarise(self, runs):
        res = self.results(runs, ("row",))
        per = {row: {i["replica"]: (series_stats(a["x"]).mean, series_stats(a["x"]).se) for a, i in reps}
               for (row,), reps in res.items()}
        return {row: paired(per[row], per["ref"]) for row in per if row != "ref"}


def test_a_study_runs_stores_reuses_and_pairs(tmp_path):
    out = str(tmp_path / "toy")
    study = ToyStudy(out, ["ref", "a", "b"])
    res = study.run()
    assert study.calls == 12 and len(RunStore(out)) == 12
    # the replicas' offsets (5 units apart) cancel in the paired difference: 0.05 resolved, "a" matches
    assert res["b"].mean == pytest.approx(0.05, abs=0.02) and res["b"].se < 0.02
    assert abs(res["a"].mean) < 3 * res["a"].se
    key = run_key("b", 2)
    with open(os.path.join(out, "runs", key + ".json")) as fh:
        assert json.load(fh) == {"status": "ok", "mean": pytest.approx(-2.95, abs=0.05), "row": "b", "replica": 2}
    again = ToyStudy(out, ["ref", "a", "b"], replicas=5)  # one more replica per row: only those run
    res5 = again.run()
    assert again.calls == 3 and res5["b"].replicas == 5


def test_an_exception_in_a_run_stops_the_study_and_keeps_what_finished(tmp_path):
    """(A run that fails as a run, e.g. blows up, returns its status instead: an exception is a bug.)"""
    out = str(tmp_path / "toy")
    with pytest.raises(RuntimeError, match="always fails"):
        ToyStudy(out, ["ref", "broken"], replicas=2).run()
    kept = RunStore(out).keys()
    assert run_key("ref", 1) in kept  # in flight beside the broken run, finished
    assert not any(run_key("broken", r) in kept for r in range(2))
    res = ToyStudy(out, ["ref", "a"], replicas=2).run()  # the next call continues from what was kept
    assert res["a"].replicas == 2


def test_the_folder_is_locked_while_a_study_runs(tmp_path):
    lock = FolderLock(str(tmp_path), "symprk toy")
    try:
        with pytest.raises(FolderLockedError, match="another symprk toy is running"):
            ToyStudy(str(tmp_path), ["ref"]).run()
    finally:
        lock.release()
    with pytest.raises(ValueError, match="workers must be >= 1"):
        ToyStudy(str(tmp_path), ["ref"], workers=0)


def test_report_only_summarises_what_is_stored_runs_nothing_and_ignores_the_lock(tmp_path):
    out = str(tmp_path / "toy")
    with pytest.raises(ValueError, match="no finished runs in .*without --report-only"):
        ToyStudy(out, ["ref", "b"]).run(report_only=True)
    ToyStudy(out, ["ref", "b"], replicas=2).run()
    logged = []
    study = ToyStudy(out, ["ref", "b"], replicas=5)
    study.log = logged.append
    lock = FolderLock(out, "symprk toy")  # a study still running in another process
    try:
        res = study.run(report_only=True)
    finally:
        lock.release()
    assert study.calls == 0 and len(RunStore(out)) == 4 and res["b"].replicas == 2
    assert logged == ["report only: 6 of 10 planned runs are not finished and are left out"]
    with pytest.raises(ValueError, match="none of the 4 planned runs is stored"):
        ToyStudy(out, ["a", "c"], replicas=2).run(report_only=True)


def test_a_run_is_its_row_replica_and_settings():
    """A run's key is the one key function of its row (however the label is written), its replica, its settings and
    its context: a change of any of them is another run."""
    run = Run("verlet 2 fs", 3, {"length_ps": 1.0}, "toy", context={"version": 2})
    assert run.key == row_key("verlet 2 fs", 3, {"length_ps": 1.0}, version=2) == \
        Run("verlet  2 fs", 3, {"length_ps": 1.0}, "other", (1,), {"x": 1}, 5.0, {"version": 2}).key
    others = [Run("verlet 1 fs", 3, {"length_ps": 1.0}, "toy", context={"version": 2}),
              Run("verlet 2 fs", 2, {"length_ps": 1.0}, "toy", context={"version": 2}),
              Run("verlet 2 fs", 3, {"length_ps": 2.0}, "toy", context={"version": 2}),
              Run("verlet 2 fs", 3, {"length_ps": 1.0}, "toy", context={"version": 3})]
    assert len({run.key} | {o.key for o in others}) == 5
    assert len(Run("verlet 2 fs", None, {}, "toy", digits=20).key) == 20


def search(row, replica):
    """A job that runs ``row`` on replicas until one's mean exceeds 1 (each run chosen after the one before)."""
    while True:
        info = yield Run(LABELS[row], replica, SETTINGS, "toy", (row, replica), {"row": row, "replica": replica})
        if info["mean"] > 1.0 or replica == 5:
            return replica
        replica += 1


class SearchStudy(ToyStudy):
    """Jobs that yield runs (the bench's stability searches), beside plain runs."""

    def plan(self):
        return [Run(LABELS["ref"], 0, SETTINGS, "toy", ("ref", 0), {"row": "ref", "replica": 0}),
                Job(search("a", 0), kind="search")]

    def execute(self, todo):
        self.stats = super().execute(todo)
        return self.stats

    def summarise(self, planned):
        return [p.result for p in planned if isinstance(p, Job)]


def test_a_study_runs_jobs_that_pick_each_run_from_the_ones_before(tmp_path):
    """Offsets 0, 5: the search stops at replica 1; called again, it replays its runs from the store."""
    out = str(tmp_path / "search")
    study = SearchStudy(out, [])
    assert study.run() == [1] and len(RunStore(out)) == 3
    assert study.stats == {"computed": 3, "reused": 0}  # the plain run and the search's two
    again = SearchStudy(out, [])
    assert again.run() == [1] and len(RunStore(out)) == 3
    assert again.stats == {"computed": 0, "reused": 2}  # the search replayed from the store; the plain run skipped


def test_json_is_written_atomically_and_plainly(tmp_path):
    path = str(tmp_path / "x.json")
    write_json(path, {"a": np.arange(3), "b": np.float32(0.5), "c": float("nan"), "d": (1, 2)})
    with open(path) as fh:
        assert json.load(fh) == {"a": [0, 1, 2], "b": 0.5, "c": None, "d": [1, 2]}
    assert os.listdir(tmp_path) == ["x.json"]


def test_a_study_on_a_dask_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        study = ToyStudy(str(tmp_path / "dask"), ["ref", "b"], replicas=3, scheduler=cluster.scheduler_address)
        res = study.run()
    assert res["b"].replicas == 3 and len(RunStore(str(tmp_path / "dask"))) == 6


def test_the_water_box_is_built_once_per_setting_and_never_reused_for_another():
    """Workers build the box once per process (replicas.water_box_scene); the key holds everything the box depends on,
    so a second study with another density or temperature in the same process gets its own box (the equipartition
    study's key once left the density out)."""
    from openmm_symprk.studies.core.replicas import water_box_scene

    cfg = {"n_waters": 64, "cutoff_nm": 0.55, "density_g_cm3": 0.997, "temperature": 300.0}
    box = water_box_scene(cfg, "spce")
    assert water_box_scene(dict(cfg), "spce") is box
    denser = water_box_scene(dict(cfg, density_g_cm3=1.05), "spce")
    hotter = water_box_scene(dict(cfg, temperature=320.0), "spce")
    edge = lambda sc: sc.system.getDefaultPeriodicBoxVectors()[0][0]._value  # noqa: E731
    assert edge(denser) == pytest.approx(edge(box) * (0.997 / 1.05) ** (1 / 3), rel=1e-6)
    assert hotter is not box and hotter.temperature == 320.0 and box.temperature == 300.0
