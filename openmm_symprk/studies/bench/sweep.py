"""Scenes x methods x step sizes, run in parallel and kept on disk as they finish: the bench on the studies'
skeleton (:class:`BenchStudy`, a :class:`~..core.study.Study`).

    from openmm_symprk.studies.bench import presets
    from openmm_symprk.studies.bench.sweep import run_sweep
    results = run_sweep(presets.quick(), "bench-results/quick", workers=2)

Jobs (:mod:`openmm_symprk.studies.core.jobs`, the machinery every study shares) are generators that yield
:class:`~.runs.RunSpec` s and receive their records: a plain run is one spec; a stability search
(:func:`~.stability.driver`) yields probe after probe; each spec is a run of the study (:func:`run_of`: its key).
Every record is stored (:class:`~.store.Store`) the moment it arrives, before anything else happens, so an
interrupted sweep (Ctrl-C, a crash, a killed job) keeps every finished run; ``resume=True`` replays the jobs, takes every
stored record from disk instead of recomputing it (a stability search replays its probes in the same
order, so it continues where it stopped) and submits only what is missing.  Runs whose record says
"error" (an exception, not an integrator failure) are retried.

On an interruption the queued runs are dropped, the running ones get a few seconds to finish (what
finishes is stored), then the worker processes are stopped.  Scripts that call :func:`run_sweep` with
``workers > 1`` need the usual ``if __name__ == "__main__":`` guard (workers are spawned).

Up to ``workers + 1`` runs are in flight at a time, the most expensive ready one first (estimated from
steps x force evaluations x the scene's cost per evaluation), so that long runs do not trail at the end.
"""
from __future__ import annotations

import json
import os
import time
import warnings

from ..core import FolderLock, FolderLockedError, Run, Study, progress_bar, write_json, write_text
from ..core.jobs import Job, single
from . import presets
from .records import RunRecord
from ..core.rows import Row
from .runs import RunSpec, bench_row, label
from .store import Store
from ...support.errors import InputError, SymprkError


class SweepExistsError(SymprkError, FileExistsError):
    """The output folder already holds finished runs and resume was not asked for."""


class SweepLockedError(FolderLockedError):
    """Another sweep is running on the same output folder."""


def _evals(method):
    """Force evaluations per step of a row (a cost estimate for scheduling)."""
    return Row.parse(method, step_fs=1.0).evals_per_step()


# -- scenes --------------------------------------------------------------------------------------
def prepare_scenes(config: dict, out: str, reuse: bool = True, log=print) -> dict:
    """Build (or, with ``reuse``, load the saved copy of) every scene of ``config``."""
    from ...systems.scenes import load_scene, save_scene
    from ..core.scenes import build, user_scene

    folder = os.path.join(out, "scenes")
    result = {}
    for name, sc in config["scenes"].items():
        params = sc.get("params", {})
        path = os.path.join(folder, name + ".json")
        scene = None
        if reuse and os.path.exists(path):
            with open(path) as fh:
                saved = json.load(fh)["info"].get("meta", {}).get("params")
            if saved == json.loads(json.dumps(params)):
                scene = load_scene(folder, name)
        if scene is None:
            t = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                scene = user_scene(name=name, **params) if sc.get("builder") == "user" else build(name, **params)
            scene.name = name
            scene.meta = dict(scene.meta, params=params)
            save_scene(scene, folder)
            log(f"built scene {name}: {scene.description} ({time.perf_counter() - t:.1f} s)")
        if sc.get("platform"):
            scene.platform = sc["platform"]
        result[name] = scene
    return result


# -- plan ----------------------------------------------------------------------------------------
def plan(config: dict, scenes: dict) -> list:
    """The jobs of a sweep: runs, one reference run per molecular accuracy scene, stability searches."""
    for name, sc in config["scenes"].items():  # a user's periodic System is measured like a production run
        if scenes[name].purpose == "production" and sc.get("production_rows") and not sc.get("rows"):
            sc.update(production=True, length_ps=sc.get("production_length_ps", sc["length_ps"]),
                      samples=sc.get("production_samples", sc.get("samples", 50)), stability=None)
    presets.check(config)
    jobs = []
    timing = config.get("timing_s", 0.5)
    threads = config.get("threads", 1)
    methods = config["methods"]
    for name, sc in config["scenes"].items():
        scene = scenes[name]
        eval_s = sc.get("eval_s", 1e-3)
        length = sc["length_ps"]
        for m, h in presets.rows_of(config, name):
            n = round(length * 1e3 / h)
            spec = RunSpec(name, bench_row(m, h, scene).label, n, sc.get("samples", 50), "run", timing_s=timing,
                           threads=threads)
            jobs.append(Job(single(spec), n * _evals(m) * eval_s, kind="run", scene=name, method=m))
        if scene.purpose == "accuracy" and scene.exact is None and not sc.get("rows"):
            ref = config.get("reference", presets.REFERENCE)
            h_min = min(sc["steps_fs"])
            n = round(length * 1e3 / h_min) * int(ref["factor"])
            spec = RunSpec(name, bench_row(ref["method"], length * 1e3 / n, scene).label, n, sc.get("samples", 50),
                           "reference", threads=threads)
            jobs.append(Job(single(spec), n * _evals(ref["method"]) * eval_s * 2, kind="reference", scene=name,
                            method=ref["method"]))
        st = sc.get("stability")
        if st and scene.purpose == "accuracy":
            from .stability import driver

            for m in sc.get("methods", methods):
                est = 20 if st.get("linear") else 11
                steps = 1 if st.get("linear") else st["probe_steps"]
                jobs.append(Job(driver(name, m, st, threads=threads, temperature=scene.temperature),
                                steps * _evals(m) * (eval_s if not st.get("linear") else 4096 * 3e-7), est,
                                kind="stability", scene=name, method=m))
    return jobs


# -- execution -----------------------------------------------------------------------------------
_scenes: dict = {}


def work(payload: dict, spec_dict: dict):
    """One spec in whatever process executes it (each scene is rebuilt from its payload once per process);
    returns (record, arrays)."""
    from ...systems.scenes import Scene
    from .stability import run_spec

    key = (payload["info"]["name"], payload["fingerprint"])
    if key not in _scenes:
        _scenes[key] = Scene.from_payload(payload)
    return run_spec(RunSpec(**spec_dict), _scenes[key])


def run_of(spec: RunSpec, fingerprint: str) -> Run:
    """The run of ``spec`` on a scene whose initial state has ``fingerprint``: keyed by the spec's row, the rest of
    the spec and the fingerprint (20 hex digits), so a changed scene never reuses stale runs; executed by
    :func:`work` on the scene's payload."""
    settings = {k: v for k, v in spec.to_dict().items() if k != "row"}
    return Run(spec.row, None, settings, spec.scene, (spec.to_dict(),), context={"scene": fingerprint}, digits=20)


def _runs(gen, fingerprints: dict):
    """The job ``gen`` (it yields RunSpecs and is sent their records) yielding the specs' runs instead."""
    try:
        spec = next(gen)
        while True:
            spec = gen.send((yield run_of(spec, fingerprints[spec.scene])))
    except StopIteration as stop:
        return stop.value


class BenchStudy(Study):
    """The sweep of ``config`` in ``out`` on the studies' skeleton: its jobs (runs, references, stability searches)
    yield runs, stored as typed records (:class:`~.store.Store`); a record whose status is "error" (an exception,
    not an integrator failure) is run again.  Without ``resume`` a folder that holds finished runs is refused
    (:class:`SweepExistsError`)."""

    command = "symprk bench"
    locked_error = SweepLockedError
    work = work

    def __init__(self, config: dict, out: str, workers: int = 2, scheduler: str | None = None, resume: bool = False,
                 charts: bool = True, progress: bool = True, on_result=None, log=print):
        super().__init__(out, max(1, int(workers)), scheduler, progress, log)
        self.config, self.resume, self.charts, self.on_result = config, resume, charts, on_result
        self.scenes: dict = {}
        self.payloads: dict = {}
        self.stats = {"computed": 0, "reused": 0}

    def open_store(self, create: bool = True) -> Store:
        return Store(self.out, create=create)

    def begin(self):
        if not self.resume and len(self.store):
            raise SweepExistsError(f"{self.out} already holds {len(self.store)} finished runs: pass resume=True "
                                   f"(--resume) to continue that sweep, or choose another output folder")

    def plan(self) -> list:
        self.scenes = prepare_scenes(self.config, self.out, reuse=self.resume, log=self.log)
        self.payloads = {name: sc.payload() for name, sc in self.scenes.items()}
        fingerprints = {name: p["fingerprint"] for name, p in self.payloads.items()}
        jobs = plan(self.config, self.scenes)
        for job in jobs:
            job.gen = _runs(job.gen, fingerprints)
        return jobs

    def shared(self, runs) -> dict:
        return self.payloads

    def reused(self, run):
        rec = self.store.get(run.key)
        return None if rec is None or rec.status == "error" else rec

    def keep(self, run, future):
        rec, arrays = _result(future, RunSpec(**run.args[0]))
        self.store.put(run.key, rec, arrays)
        rec = self.store.get(run.key)
        if self.on_result is not None:
            self.on_result(rec)
        return rec

    def execute(self, todo: list) -> dict:
        t0 = time.perf_counter()
        try:
            self.stats = super().execute(todo)
        except KeyboardInterrupt:
            self.log(f"interrupted: {len(self.store)} finished runs are kept in {self.out}; rerun with --resume to "
                     f"continue")
            raise
        self.stats["seconds"] = time.perf_counter() - t0
        return self.stats

    def summarise(self, jobs: list) -> dict:
        from .aggregate import aggregate, format_summary

        results = aggregate(self.config, self.scenes, jobs, self.store)
        results["stats"] = self.stats
        results["out"] = self.out
        write_json(os.path.join(self.out, "results.json"), results)
        write_text(os.path.join(self.out, "summary.txt"), format_summary(results) + "\n")
        if self.charts:
            from .charts import make_charts

            results["charts"] = make_charts(results, os.path.join(self.out, "charts"))
            write_json(os.path.join(self.out, "results.json"), results)
        self.log(f"{self.stats['computed']} runs computed, {self.stats['reused']} taken from {self.out}, "
                 f"{self.stats.get('seconds', 0.0):.0f} s; results in {os.path.join(self.out, 'results.json')}")
        return results

    def retime(self, rounds: int = 3):
        """Time every finished run with a timing again (:func:`.runs.retime`), one at a time in this process,
        under the folder's lock."""
        from .runs import retime

        if not len(Store(self.out, create=False)):
            raise InputError(f"{self.out} holds no finished runs to time again: run the sweep first")
        lock = FolderLock(self.out, self.command, self.locked_error)
        try:
            self.store = self.open_store()
            resume, self.resume = self.resume, True
            try:
                jobs = self.plan()
            finally:
                self.resume = resume
            todo = []
            for job in jobs:
                if job.kind != "run":
                    continue
                run = next(job.gen)
                spec, rec = RunSpec(**run.args[0]), self.store.get(run.key)
                if rec is not None and rec.wall_per_step and spec.timing_s > 0:
                    todo.append((spec, run.key, rec))
            bar = progress_bar(len(todo), "retime", self.progress)
            for spec, key, rec in todo:
                retime(spec, self.scenes[spec.scene], rec, rounds)
                self.store.put(key, rec, self.store.arrays(key) if rec.has_arrays else None)
                bar.update(1)
            bar.close()
            self.log(f"timed {len(todo)} runs again")
        finally:
            lock.release()


def _result(fut, spec):
    try:
        return fut.result()
    except Exception as exc:  # a worker that died or a bug: record it, keep the sweep going
        import traceback

        fields = spec.record_fields()
        rec = RunRecord(**fields, label=label(fields["method"]), status="error",
                        failure=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
        return rec, {}


# -- the whole sweep -----------------------------------------------------------------------------
def run_sweep(config: dict, out: str, workers: int = 2, scheduler: str | None = None, resume: bool = False,
              charts: bool = True, progress: bool = True, on_result=None, log=print) -> dict:
    """Run (or continue) a sweep; write ``<out>/results.json``, ``<out>/summary.txt`` and the charts.

    Returns the results dict (see :func:`.aggregate.aggregate`), with ``stats`` = runs computed now and
    runs taken from disk."""
    return BenchStudy(config, out, workers, scheduler, resume, charts, progress, on_result, log).run()


def retime_sweep(config: dict, out: str, rounds: int = 3, workers: int = 1, charts: bool = True,
                 progress: bool = True, log=print) -> dict:
    """Measure again the timing of every finished run of the sweep in ``out`` (each against a fresh
    VerletIntegrator, in turns, ``rounds`` rounds), one at a time in this process, keeping everything else
    each run measured; then continue the sweep as ``resume=True`` does and rewrite its results.  For a sweep
    that shared its machine with other work: the ratios are taken in turns, but heavy load still blurs them."""
    BenchStudy(config, out, workers, resume=True, charts=charts, progress=progress, log=log).retime(rounds)
    return run_sweep(config, out, workers=workers, resume=True, charts=charts, progress=progress, log=log)
