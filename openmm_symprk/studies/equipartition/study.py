"""Run the equipartition study: replica states, NVE runs in parallel, kept on disk as they finish.

    from openmm_symprk.studies.equipartition import presets, run_study
    result = run_study(presets.quick(), "equipartition-quick", workers=2)

``<out>/states/<model>.npz`` holds the replica states and ``<out>/runs/<key>.npz`` + ``.json`` one finished run
each; a key hashes everything a run depends on (model, box, equilibration, row, replica, lengths), so a second
call with the same settings reuses every finished run and computes only what is missing, and a changed
setting never reuses a stale one.  Workers are spawned processes (scripts need the ``if __name__ ==
"__main__":`` guard for ``workers > 1``).
"""
from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import multiprocessing as mp
import os

import numpy as np

from ...support import require
from ..folders import FolderLock, write_json
from .report import summarise

__all__ = ["run_study", "run_key", "load_runs"]

#: What a replica state depends on.  Not the number of replicas: replica r is the same state whatever that number,
#: so a study asked for more replicas later extends the chain and reuses every finished run.
_STATE_KEYS = ("n_waters", "cutoff_nm", "temperature", "seed", "equilibrate_ps", "spacing_ps", "threads")
_RUN_KEYS = _STATE_KEYS + ("settle_ps", "length_ps", "sample_fs")


def _hash(obj) -> str:
    return hashlib.sha1(json.dumps(obj, sort_keys=True).encode()).hexdigest()[:16]


#: Version of what a run stores (2: T_trans without the kinetic energy of the box's centre of mass); a run
#: stored by another version is never reused.
RUN_VERSION = 2


def run_key(cfg: dict, model: str, method: str, step_fs: float, replica: int) -> str:
    return _hash({"cfg": {k: cfg[k] for k in _RUN_KEYS}, "model": model, "row": [method, float(step_fs)],
                  "replica": int(replica), "version": RUN_VERSION})


def _states(cfg, model, out, log):
    """The model's replica states (at least ``cfg["replicas"]``), built or extended and kept in ``<out>/states``."""
    from .runs import build_box, replica_states

    path = os.path.join(out, "states", f"{model}-{_hash({k: cfg[k] for k in _STATE_KEYS})}.npz")
    start = None
    if os.path.exists(path):
        with np.load(path) as d:
            start = d["x"], d["v"]
        if len(start[0]) >= int(cfg["replicas"]):
            return start
    os.makedirs(os.path.dirname(path), exist_ok=True)
    x, v = replica_states(build_box(cfg, model), cfg, log, start=start)
    tmp = f"{path}.tmp{os.getpid()}.npz"
    np.savez(tmp, x=x, v=v)
    os.replace(tmp, path)
    return x, v


_boxes: dict = {}


def _work(cfg, model, method, step_fs, x, v):
    """One run in a worker process (the box is built once per process and model)."""
    import warnings

    from .runs import build_box, run_nve

    key = (model, cfg["n_waters"], cfg["cutoff_nm"])
    if key not in _boxes:
        _boxes[key] = build_box(cfg, model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the periodic-box conservation warning is expected here
        return run_nve(_boxes[key], x, v, method, step_fs, cfg)


def _paths(out, key):
    return os.path.join(out, "runs", f"{key}.json"), os.path.join(out, "runs", f"{key}.npz")


def load_runs(cfg: dict, out: str) -> dict:
    """{(model, method, step_fs): [(arrays, info) per finished replica]}: every finished replica in ``out`` made
    with these settings, also those beyond ``cfg["replicas"]`` (from an earlier call that asked for more)."""
    wanted = {(model, method, float(h)) for model, rows in cfg["models"].items() for method, h in rows}
    found = {row: [] for row in wanted}
    folder = os.path.join(out, "runs")
    for name in sorted(os.listdir(folder)) if os.path.isdir(folder) else []:
        if not name.endswith(".json"):
            continue
        jpath, npath = _paths(out, name[:-5])
        try:
            with open(jpath) as fh:
                info = json.load(fh)
            row = (info["model"], info["method"], float(info["step_fs"]))
        except (OSError, ValueError, KeyError):
            continue
        if row not in wanted or name[:-5] != run_key(cfg, *row, info["replica"]) or not os.path.exists(npath):
            continue
        with np.load(npath) as d:
            found[row].append(({k: d[k] for k in d.files}, info))
    for reps in found.values():
        reps.sort(key=lambda rep: rep[1]["replica"])
    return found


def _save(out, key, arrays, info):
    jpath, npath = _paths(out, key)
    tmp = f"{npath}.tmp{os.getpid()}.npz"
    np.savez(tmp, **arrays)
    os.replace(tmp, npath)
    write_json(jpath, info)


def _check(cfg):
    for k in ("replicas", "n_waters"):
        if int(cfg[k]) < 1:
            raise ValueError(f"{k} must be >= 1, got {cfg[k]!r}")
    for k in ("length_ps", "sample_fs", "equilibrate_ps", "cutoff_nm", "temperature"):
        if not float(cfg[k]) > 0:
            raise ValueError(f"{k} must be positive, got {cfg[k]!r}")
    from ...methods.catalogue import get_method
    from .presets import RIGID_PREFIX

    for model, rows in cfg["models"].items():
        for method, h in rows:
            m = get_method(method[len(RIGID_PREFIX):] if method.startswith(RIGID_PREFIX) else method)
            if not m.is_splitting:
                raise ValueError(f"{model}: row {method} is a {m.family} method; rigid water (constraints, or the "
                                 f"rigid-body engine) runs kick/drift splittings and compositions only, e.g. "
                                 f"verlet, omelyan-2, pefrl, yoshida-4 (symprk methods lists their families)")
            if not float(h) > 0:
                raise ValueError(f"{model}: step size of {method} must be positive, got {h!r}")
        if list(cfg["reference"]) not in [[m, float(h)] for m, h in rows]:
            raise ValueError(f"{model}: the reference row {cfg['reference']} is not among its rows")


def run_study(cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True, log=print) -> dict:
    """Run (or finish) the study in ``out``; returns the summary (see :func:`.report.summarise`) and writes
    ``summary.txt``, ``results.json`` and ``equipartition.png`` there."""
    _check(cfg)
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    lock = FolderLock(out, "symprk equipartition")
    try:
        todo = []
        states = {model: _states(cfg, model, out, log) for model in cfg["models"]}
        for model, rows in cfg["models"].items():
            for method, h in sorted(rows, key=lambda r: -force_cost(r, cfg)):
                for r in range(int(cfg["replicas"])):
                    key = run_key(cfg, model, method, h, r)
                    if not os.path.exists(_paths(out, key)[0]):
                        todo.append((key, model, method, float(h), r))
        n_all = sum(len(rows) for rows in cfg["models"].values()) * int(cfg["replicas"])
        if n_all - len(todo):
            log(f"reusing {n_all - len(todo)} finished runs in {out}")
        _execute(todo, cfg, states, out, workers, progress, log)
        runs = load_runs(cfg, out)
        timings = _timings(cfg, states, log) if timing else {}
        summary = summarise(cfg, runs, timings)
        from .report import chart, format_summary

        text = format_summary(summary)
        with open(os.path.join(out, "summary.txt"), "w") as fh:
            fh.write(text + "\n")
        write_json(os.path.join(out, "results.json"), summary)
        try:
            chart(summary, os.path.join(out, "equipartition.png"))
        except ImportError:
            log("matplotlib is not installed: no chart (pip install matplotlib)")
        return summary
    finally:
        lock.release()


def force_cost(row, cfg) -> float:
    """Force evaluations of one run of a row (to start the longest first)."""
    from .runs import force_evals_per_step

    method, h = row
    return force_evals_per_step(method) * (cfg["length_ps"] + cfg["settle_ps"]) * 1000.0 / float(h)


def _execute(todo, cfg, states, out, workers, progress, log):
    if not todo:
        return
    bar = None
    if progress:
        tqdm = require("tqdm", "studies", "openmm_symprk.studies.equipartition (progress bar)").tqdm

        bar = tqdm(total=len(todo), desc="equipartition runs", unit="run")

    def done(key, model, method, h, r, result):
        arrays, info = result
        info.update(model=model, method=method, step_fs=h, replica=r)
        _save(out, key, arrays, info)
        if bar is not None:
            bar.update(1)
        if info["status"] != "ok":
            log(f"{model} {method} {h} fs replica {r}: {info['status']}")

    try:
        if workers <= 1:
            for key, model, method, h, r in todo:
                x, v = states[model]
                done(key, model, method, h, r, _work(cfg, model, method, h, x[r], v[r]))
            return
        with cf.ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
            futures = {pool.submit(_work, cfg, model, method, h, states[model][0][r], states[model][1][r]):
                       (key, model, method, h, r) for key, model, method, h, r in todo}
            try:
                for fut in cf.as_completed(futures):
                    done(*futures[fut], fut.result())
            except BaseException:
                for f in futures:
                    f.cancel()
                raise
    finally:
        if bar is not None:
            bar.close()


def _timings(cfg, states, log) -> dict:
    """Seconds per simulated ps of each row on replica 0, measured in turns (studies.timing.interleaved), so
    the ratios between rows hold under the machine's load."""
    from ..timing import interleaved
    from .runs import build_box, make_engine

    out = {}
    for model, rows in cfg["models"].items():
        box = build_box(cfg, model)
        x, v = states[model]
        engines = {(m, float(h)): make_engine(box, x[0], v[0], m, float(h), cfg.get("threads", 1)) for m, h in rows}
        steps = {k: max(1, int(round(0.05 / (k[1] * 1e-3)))) for k in engines}  # 50 fs per block
        res = interleaved({k: e.step for k, e in engines.items()}, steps, rounds=3)
        for k, tm in res.items():
            out[(model,) + k] = tm.best / (k[1] * 1e-3)
        log(f"{model}: timed {len(rows)} rows in turns")
    return out
