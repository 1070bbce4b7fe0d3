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

import os

import numpy as np

from ..core import Run, Study, run_key as hash_key, write_json, write_npz, write_text
from .report import summarise

__all__ = ["run_study", "run_key", "state_key", "replica_state_set", "load_runs", "EquipartitionStudy"]

#: What a replica state depends on.  Not the number of replicas: replica r is the same state whatever that number,
#: so a study asked for more replicas later extends the chain and reuses every finished run.
STATE_KEYS = ("n_waters", "cutoff_nm", "density_g_cm3", "temperature", "seed", "equilibrate_ps", "spacing_ps",
              "threads")
_RUN_KEYS = STATE_KEYS + ("settle_ps", "length_ps", "sample_fs")

#: Version of the replica states (2: the box at a stated density, 0.997 g/cm^3, instead of Modeller's 0.864, and
#: each state's total momentum zero).
STATE_VERSION = 2

#: Version of what a run stores (2: T_trans without the kinetic energy of the box's centre of mass; 3: the
#: states of STATE_VERSION 2); a run stored by another version is never reused.  The error bars are computed at
#: summary time from the stored series, so a change of estimator needs no new version: calling the study again
#: re-summarises.
RUN_VERSION = 3


def run_key(cfg: dict, model: str, method: str, step_fs: float, replica: int) -> str:
    return hash_key({"cfg": {k: cfg[k] for k in _RUN_KEYS}, "model": model, "row": [method, float(step_fs)],
                     "replica": int(replica), "version": RUN_VERSION})


def state_key(cfg: dict) -> str:
    """The key of a model's replica states: what they depend on (not the number of replicas)."""
    return hash_key({"cfg": {k: cfg[k] for k in STATE_KEYS}, "version": STATE_VERSION})


def replica_state_set(cfg: dict, model: str, out: str, log=print):
    """The model's replica states (x, v), at least ``cfg["replicas"]`` of them, built or extended and kept in
    ``<out>/states/<model>-<key>.npz``: every study of rigid water boxes (equipartition, fidelity) with the
    same state settings starts from these same states."""
    from .runs import build_box, replica_states

    path = os.path.join(out, "states", f"{model}-{state_key(cfg)}.npz")
    start = None
    if os.path.exists(path):
        with np.load(path) as d:
            start = d["x"], d["v"]
        if len(start[0]) >= int(cfg["replicas"]):
            return start
    os.makedirs(os.path.dirname(path), exist_ok=True)
    x, v = replica_states(build_box(cfg, model), cfg, log, start=start)
    write_npz(path, {"x": x, "v": v})
    return x, v


_boxes: dict = {}


def work(shared: dict, method: str, step_fs: float, replica: int):
    """One NVE run in whatever process executes it (the box is built once per process and model)."""
    from .runs import build_box, run_nve

    cfg, model = shared["cfg"], shared["model"]
    key = (model, cfg["n_waters"], cfg["cutoff_nm"])
    if key not in _boxes:
        _boxes[key] = build_box(cfg, model)
    return run_nve(_boxes[key], shared["x"][replica], shared["v"][replica], method, step_fs, cfg)


def load_runs(cfg: dict, out: str) -> dict:
    """{(model, method, step_fs): [(arrays, info) per finished replica]}: every finished replica in ``out`` made
    with these settings, also those beyond ``cfg["replicas"]`` (from an earlier call that asked for more)."""
    from ..core import RunStore

    wanted = {(model, method, float(h)) for model, rows in cfg["models"].items() for method, h in rows}
    found = {row: [] for row in wanted}
    if not os.path.isdir(os.path.join(out, "runs")):
        return found
    store = RunStore(out)
    for key in sorted(store.keys()):
        info = store.info(key)
        try:
            row = (info["model"], info["method"], float(info["step_fs"]))
        except (TypeError, ValueError, KeyError):
            continue
        if row not in wanted or key != run_key(cfg, *row, info["replica"]):
            continue
        arrays = store.arrays(key)
        if arrays is not None:
            found[row].append((arrays, info))
    for reps in found.values():
        reps.sort(key=lambda rep: rep[1]["replica"])
    return found


def _check(cfg):
    for k in ("replicas", "n_waters"):
        if int(cfg[k]) < 1:
            raise ValueError(f"{k} must be >= 1, got {cfg[k]!r}")
    for k in ("length_ps", "sample_fs", "equilibrate_ps", "cutoff_nm", "temperature"):
        if not float(cfg[k]) > 0:
            raise ValueError(f"{k} must be positive, got {cfg[k]!r}")
    from ..core.rows import Row

    for model, rows in cfg["models"].items():
        for method, h in rows:
            Row(method, 1.0).require_kick_drift(f"{model}: rigid water (constraints, or the rigid-body engine)")
            if not float(h) > 0:
                raise ValueError(f"{model}: step size of {method} must be positive, got {h!r}")
        if list(cfg["reference"]) not in [[m, float(h)] for m, h in rows]:
            raise ValueError(f"{model}: the reference row {cfg['reference']} is not among its rows")


class EquipartitionStudy(Study):
    """Replica states per water model, then one NVE run per (model, row, replica)."""

    command = "symprk equipartition"
    work = work

    def __init__(self, cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True,
                 log=print, scheduler: str | None = None):
        _check(cfg)
        super().__init__(out, workers, scheduler, progress, log)
        self.cfg, self.timing = cfg, timing
        self.states = {}

    def plan(self) -> list:
        cfg = self.cfg
        self.states = {model: replica_state_set(cfg, model, self.out, self.log) for model in cfg["models"]}
        runs = []
        for model, rows in cfg["models"].items():
            for method, h in rows:
                for r in range(int(cfg["replicas"])):
                    runs.append(Run(run_key(cfg, model, method, h, r), model, (method, float(h), r),
                                    {"model": model, "method": method, "step_fs": float(h), "replica": r},
                                    force_cost([method, h], cfg)))
        return runs

    def shared(self, runs) -> dict:
        return {model: {"cfg": self.cfg, "model": model, "x": x, "v": v} for model, (x, v) in self.states.items()}

    def stored(self, run, info):
        if info["status"] != "ok":
            self.log(f"{info['model']} {info['method']} {info['step_fs']} fs replica {info['replica']}: "
                     f"{info['status']}")

    def summarise(self, runs) -> dict:
        from .report import chart, format_summary

        timings = _timings(self.cfg, self.states, self.log) if self.timing else {}
        summary = summarise(self.cfg, load_runs(self.cfg, self.out), timings)
        write_text(os.path.join(self.out, "summary.txt"), format_summary(summary) + "\n")
        write_json(os.path.join(self.out, "results.json"), summary)
        try:
            chart(summary, os.path.join(self.out, "equipartition.png"))
        except ImportError as exc:  # MissingDependencyError says which extra installs matplotlib
            self.log(f"no chart: {exc}")
        return summary


def run_study(cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True, log=print,
              scheduler: str | None = None, report_only: bool = False) -> dict:
    """Run (or finish, or only re-summarise: ``report_only``, see :meth:`~openmm_symprk.studies.core.study.Study.run`) the study in ``out``; returns the summary (see
    :func:`.report.summarise`) and writes ``summary.txt``, ``results.json`` and ``equipartition.png`` there."""
    return EquipartitionStudy(cfg, out, workers, timing, progress, log, scheduler).run(report_only)


def force_cost(row, cfg) -> float:
    """Force evaluations of one run of a row (to start the longest first)."""
    from .runs import force_evals_per_step

    method, h = row
    return force_evals_per_step(method) * (cfg["length_ps"] + cfg["settle_ps"]) * 1000.0 / float(h)


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
