"""Run the equipartition study: replica states, NVE runs in parallel, kept on disk as they finish.

    from openmm_symprk.studies.equipartition import presets, run_study
    result = run_study(presets.quick(), "equipartition-quick", workers=2)

``<out>/states/<model>-<key>.npz`` holds the replica states (:func:`~..core.replicas.water_box_replicas`) and
``<out>/runs/<key>.npz`` + ``.json`` one finished run each; a key (:attr:`~..core.study.Run.key`) hashes everything a
run depends on (model, box, equilibration, row label, replica, lengths), so a second call with the same settings
reuses every finished run and computes only what is missing, and a changed setting never reuses a stale one.
Workers are spawned processes (scripts need the ``if __name__ == "__main__":`` guard for ``workers > 1``).
"""
from __future__ import annotations

import os

from ..core import Run, RunStore, Study, write_json, write_text
from ..core.options import check_settings
from ..core.replicas import BOX_STATE_KEYS, water_box_replicas, water_box_scene
from ..core.rows import Row
from ..core.timing import seconds_per_ps
from .report import summarise
from ...support.errors import InputError

__all__ = ["run_study", "run_of", "load_runs", "EquipartitionStudy"]

_RUN_KEYS = BOX_STATE_KEYS + ("settle_ps", "length_ps", "sample_fs")

#: Version of what a run stores (2: T_trans without the kinetic energy of the box's centre of mass; 3: the
#: states of BOX_STATE_VERSION 2); a run stored by another version is never reused.  The error bars are computed at
#: summary time from the stored series, so a change of estimator needs no new version: calling the study again
#: re-summarises.
RUN_VERSION = 3


def run_of(cfg: dict, model: str, label: str, replica: int, cost: float = 1.0) -> Run:
    """The NVE run of the row ``label`` on ``model``'s box from ``replica``: keyed by the row, the replica, the box's
    and the run's settings, the model and :data:`RUN_VERSION`."""
    label = Row.parse(label).label
    return Run(label, replica, {k: cfg[k] for k in _RUN_KEYS}, model, (label, replica),
               {"model": model, "row": label, "replica": replica}, cost,
               context={"model": model, "version": RUN_VERSION})


def work(shared: dict, label: str, replica: int):
    """One NVE run in whatever process executes it (the box is built once per process and settings)."""
    from .runs import run_nve

    cfg, model = shared["cfg"], shared["model"]
    return run_nve(water_box_scene(cfg, model), shared["x"][replica], shared["v"][replica], label, cfg)


def load_runs(cfg: dict, out: str) -> dict:
    """{(model, label): [(arrays, info) per finished replica]}: every finished replica in ``out`` made with these
    settings, also those beyond ``cfg["replicas"]`` (from an earlier call that asked for more)."""
    found = {(model, Row.parse(lab).label): [] for model, rows in cfg["models"].items() for lab in rows}
    store = RunStore(out, create=False)
    for key in sorted(store.keys()):
        info = store.info(key)
        try:
            ident, replica = (info["model"], Row.parse(info["row"]).label), int(info["replica"])
        except (TypeError, ValueError, KeyError):
            continue
        if ident in found and key == run_of(cfg, *ident, replica).key:
            arrays = store.arrays(key)
            if arrays is not None:
                found[ident].append((arrays, dict(info, row=ident[1])))
    for reps in found.values():
        reps.sort(key=lambda rep: rep[1]["replica"])
    return found


def _check(cfg):
    check_settings(cfg, ("replicas", "n_waters"), ("length_ps", "sample_fs", "equilibrate_ps", "cutoff_nm",
                                                   "temperature"))
    for model, labels in cfg["models"].items():
        rows = [Row.parse(lab) for lab in labels]
        for row in rows:
            row.require_kick_drift(f"{model}: rigid water (constraints, or the rigid-body engine)")
        if Row.parse(cfg["reference"]) not in rows:
            raise InputError(f"{model}: the reference row {cfg['reference']!r} is not among its rows")


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
        self.states = {model: water_box_replicas(cfg, model, self.out, self.log) for model in cfg["models"]}
        runs = []
        for model, labels in cfg["models"].items():
            for row in map(Row.parse, labels):
                cost = row.evals_per_ps(True) * (cfg["length_ps"] + cfg["settle_ps"])
                runs += [run_of(cfg, model, row.label, r, cost) for r in range(int(cfg["replicas"]))]
        return runs

    def shared(self, runs) -> dict:
        return {model: {"cfg": self.cfg, "model": model, "x": x, "v": v} for model, (x, v) in self.states.items()}

    def stored(self, run, info):
        if info["status"] != "ok":
            self.log(f"{info['model']} {info['row']} replica {info['replica']}: {info['status']}")

    def summarise(self, runs) -> dict:
        from .report import chart, format_summary

        timings = _timings(self.cfg, self.states, self.log) if self.timing else {}
        summary = summarise(self.cfg, load_runs(self.cfg, self.out), timings)
        write_text(os.path.join(self.out, "summary.txt"), format_summary(summary) + "\n")
        write_json(os.path.join(self.out, "results.json"), summary)
        self.chart(chart, summary, os.path.join(self.out, "equipartition.png"))
        return summary


def run_study(cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True, log=print,
              scheduler: str | None = None, report_only: bool = False) -> dict:
    """Run (or finish, or only re-summarise: ``report_only``, see :meth:`~openmm_symprk.studies.core.study.Study.run`) the study in ``out``; returns the summary (see
    :func:`..core.temperatures.summarise`) and writes ``summary.txt``, ``results.json`` and ``equipartition.png`` there."""
    return EquipartitionStudy(cfg, out, workers, timing, progress, log, scheduler).run(report_only)


def _timings(cfg, states, log) -> dict:
    """Seconds per simulated ps of each row on replica 0, timed in turns in blocks of 50 fs
    (:func:`..core.timing.seconds_per_ps`)."""
    out = {}
    for model, labels in cfg["models"].items():
        (x, v), rows = states[model], {row.label: row for row in map(Row.parse, labels)}
        times = seconds_per_ps(rows, water_box_scene(cfg, model), x[0], v[0], 50.0, cfg.get("threads", 1))
        out.update({(model, lab): s for lab, s in times.items()})
        log(f"{model}: timed {len(rows)} rows in turns")
    return out
