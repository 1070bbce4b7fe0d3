"""The drift study on the studies' skeleton: replica states per scene, one stored run per (row, replica).

``<out>/states/`` holds the scenes and their replica states (:mod:`openmm_symprk.systems.scenes`), ``<out>/runs/<key>.json`` + ``.npz``
one finished run each.  A run's key hashes everything it depends on (the row, the replica, the run length, the
sampling, the constraint tolerance, the threads and the key of its replica states), so calling the study again
reuses every finished run, and a changed setting never reuses a stale one.  ``summary.txt`` and ``results.json``
are rewritten from the stored runs at every call.
"""
from __future__ import annotations

import os

from ..core import Run, Study, platforms, write_json, write_text
from ..core.options import check_settings
from ..core.replicas import scene_replicas, scene_state_key
from .runs import row_of
from ...support.errors import InputError

__all__ = ["DriftStudy", "run_study", "run_of", "check"]

#: Version of what a run stores (a change never reuses stale runs).
RUN_VERSION = 1
_RUN_KEYS = ("length_ps", "sample_ps", "constraint_tolerance", "threads", "temperature")


def states_key(cfg: dict, scene: str) -> str:
    return scene_state_key(scene, cfg["temperature"], cfg["seed"], cfg["decorrelate_ps"])


def states_of(cfg: dict, scene: str, out: str, log=print) -> dict:
    """The replica states of ``scene`` for ``cfg``, kept in ``<out>/states``
    (:func:`~..core.replicas.scene_replicas`)."""
    return scene_replicas(scene, os.path.join(out, "states"), int(cfg["replicas"]), float(cfg["temperature"]),
                          int(cfg["seed"]), float(cfg["decorrelate_ps"]), int(cfg.get("threads", 1)), log)


def run_of(cfg: dict, row: dict, replica: int, cost: float = 1.0) -> Run:
    """The NVE run of ``row`` (a config's row: name, row label, scene, platform) from ``replica``: keyed by the row,
    the replica, the settings of the run, its scene, platform and replica states, and :data:`RUN_VERSION`."""
    return Run(row["row"], replica, {k: cfg[k] for k in _RUN_KEYS}, row["scene"], (row, replica, cfg),
               {"row": row["name"], "replica": replica, "scene": row["scene"]}, cost,
               context={"scene": row["scene"], "platform": row["platform"], "states": states_key(cfg, row["scene"]),
                        "version": RUN_VERSION})


def check(cfg: dict):
    """ValueError naming the bad value and what is accepted."""
    from ..core.scenes import SCENES

    check_settings(cfg, ("replicas",), ("length_ps", "sample_ps", "temperature", "constraint_tolerance"))
    if float(cfg["decorrelate_ps"]) < 0:
        raise InputError(f"decorrelate_ps must be >= 0, got {cfg['decorrelate_ps']!r}")
    names = [r["name"] for r in cfg["rows"]]
    if len(set(names)) != len(names):
        raise InputError(f"row names must be unique, got {names}")
    for row in cfg["rows"]:
        if row["scene"] not in SCENES:
            raise InputError(f"row {row['name']}: unknown scene {row['scene']!r}; known: {', '.join(SCENES)}")
        step = row_of(row).step_fs  # ValueError naming the catalogue and OpenMM's integrators
        n = float(cfg["length_ps"]) * 1e3 / step
        if round(n) < 3:
            raise InputError(f"row {row['name']}: {cfg['length_ps']} ps is under 3 steps of {step:g} fs")
    for c in cfg["comparisons"]:
        for k in ("row", "ref"):
            if c[k] not in names:
                raise InputError(f"comparison {c}: no row named {c[k]!r} (rows: {', '.join(names)})")


_systems: dict = {}


def work(shared: dict, row: dict, replica: int, cfg: dict):
    """One NVE run in whatever process executes it (each scene's System deserialised once per process)."""
    import openmm as mm

    from .runs import run_nve

    key = (row["scene"], len(shared["xml"]), hash(shared["xml"]))
    if key not in _systems:
        _systems[key] = mm.XmlSerializer.deserialize(shared["xml"])
    return run_nve(_systems[key], shared["x"][replica], shared["v"][replica], row, cfg,
                   seed=int(cfg["seed"]) * 1000 + int(replica) + 1)


class DriftStudy(Study):
    """Rows x replicas of NVE runs, summarised as drifts with error bars and paired verdicts."""

    command = "symprk drift"
    work = work

    def __init__(self, cfg: dict, out: str, workers: int = 1, progress: bool = True, log=print,
                 scheduler: str | None = None):
        check(cfg)
        super().__init__(out, workers, scheduler, progress, log)
        self.cfg = cfg
        self.states: dict = {}
        self.skipped: list = []

    def rows(self) -> list:
        """The rows whose platform this installation has."""
        rows, self.skipped = [], []
        for row in self.cfg["rows"]:
            (rows if platforms.available(row["platform"]) else self.skipped).append(row)
        for row in self.skipped:
            self.log(f"skipping row {row['name']}: no OpenMM platform {row['platform']} here")
        return rows

    def plan(self) -> list:
        cfg = self.cfg
        rows = self.rows()
        self.states = {s: states_of(cfg, s, self.out, self.log) for s in dict.fromkeys(r["scene"] for r in rows)}
        runs = []
        for row in rows:
            cost = float(cfg["length_ps"]) * row_of(row).evals_per_ps() * (10.0 if "pme" in row["scene"] else 1.0)
            runs += [run_of(cfg, row, r, cost) for r in range(int(cfg["replicas"]))]
        return runs

    def shared(self, runs) -> dict:
        return {s: {"xml": st["xml"], "x": st["x"], "v": st["v"]} for s, st in self.states.items()}

    def stored(self, run, info):
        if info["status"] != "ok":
            self.log(f"{info['row']} replica {info['replica']}: {info['status']} ({info.get('failure')})")

    def summarise(self, runs) -> dict:
        from .report import format_summary, summarise

        found = self.results(runs, ("row",))
        summary = summarise(self.cfg, {k[0]: v for k, v in found.items()}, skipped=[r["name"] for r in self.skipped])
        write_json(os.path.join(self.out, "results.json"), summary)
        write_text(os.path.join(self.out, "summary.txt"), format_summary(summary) + "\n")
        if self.cfg.get("study") == "nvt":
            from .chart import work_precision

            self.chart(work_precision, summary, os.path.join(self.out, "nvt-drift.png"))
        return summary


def run_study(cfg: dict, out: str, workers: int = 1, progress: bool = True, log=print,
              scheduler: str | None = None, report_only: bool = False) -> dict:
    """Run (or finish, or only re-summarise: ``report_only``, see :meth:`~openmm_symprk.studies.core.study.Study.run`) the study in ``out``; returns the summary (:func:`.report.summarise`)."""
    return DriftStudy(cfg, out, workers, progress, log, scheduler).run(report_only)
