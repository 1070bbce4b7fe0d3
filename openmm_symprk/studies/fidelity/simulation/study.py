"""Run the fidelity study: the rigid-water box's replica states, one run per (row, replica), kept on disk.

    from openmm_symprk.studies.fidelity import presets
    from openmm_symprk.studies.fidelity.simulation import run_study
    summary = run_study(presets.quick(), "fidelity-quick", workers=2)

``<out>/states/<model>-<key>.npz`` holds the replica states (:func:`~...core.replicas.water_box_replicas`: the same
file, key and states as ``symprk equipartition`` makes for the same box and equilibration settings),
``<out>/runs/<key>.json`` (+ .npz) one finished run each; a key (:attr:`~...core.study.Run.key`) hashes everything a
run depends on (box, states, row label, replica, lengths, the observables' settings), so a second call reuses every
finished run and a changed setting never reuses a stale one.
"""
from __future__ import annotations

import os
import warnings

from ....systems.checks import ConservationWarning
from ...core import Run, Study, write_json, write_text
from ...core.options import check_settings
from ...core.replicas import BOX_STATE_KEYS, BOX_STATE_VERSION, water_box_replicas, water_box_scene
from ..rowspec import check_row, foreign_rows, label, to_row
from ....support.errors import InputError

__all__ = ["FidelityStudy", "run_study", "run_of", "replica_counts", "temperature_view", "RUN_KEYS", "RUN_VERSION"]

#: What a run depends on besides its row and replica (the observables are computed in the run: their settings too).
RUN_KEYS = BOX_STATE_KEYS + ("model", "settle_ps", "omega_ps", "omega_fs", "omega_max_lag_ps", "length_ps",
                             "sample_fs", "rdf_every", "msd_window_ps", "tau_fit", "rdf_r_min_nm")
#: Version of what a run stores; a run stored by another version is never reused (2: rows stored as their labels;
#: leapfrog integrators started from v(-h/2); blow-ups recorded as "unstable at step N"; 3: leapfrog rows' velocities
#: brought to the positions' time in every velocity-based observable, the omega ACF's zero and minimum read between
#: its samples, its curve kept in the run).  A preset names the version its runs have (``run_version``: issue 26's
#: stored runs are version 2).
RUN_VERSION = 3
#: The file of the rows' wall time per simulated ps, timed in turns (kept so that --report-only remakes the cost
#: columns on any machine; a run that times again replaces it).
TIMINGS = "timings.json"
#: The file of the box's properties for the modified-energy model (computed once from the states and the NVT
#: reference's runs, whose series are not committed).
MODEL = "model.json"


def run_of(cfg: dict, row, replica: int, cost: float = 1.0) -> Run:
    """The run of ``row`` (a label) from ``replica``: keyed by the row, the replica, the settings of
    :data:`RUN_KEYS` (and the equilibrator, where the config names one), the states' and the runs' versions."""
    lab = check_row(row)
    keys = RUN_KEYS + (("equilibrator",) if "equilibrator" in cfg else ())
    return Run(lab, replica, {k: cfg[k] for k in keys}, "box", (lab, replica), {"row": lab, "replica": replica}, cost,
               context={"states": BOX_STATE_VERSION, "version": int(cfg.get("run_version", RUN_VERSION))})


def references(cfg: dict, rows: list) -> dict:
    """{ensemble: canonical label} of the study's references: ``cfg["references"]`` (default: the first row for
    NVE); ValueError where a reference is not among the rows or not of its ensemble."""
    given = dict(cfg.get("references") or {"NVE": rows[0]})
    out = {}
    for ens, lab in given.items():
        if ens not in ("NVE", "NVT"):
            raise InputError(f"references: ensemble {ens!r}; known: NVE, NVT")
        lab = check_row(lab)
        if lab not in rows:
            raise InputError(f"the {ens} reference {lab!r} is not among the rows")
        r = to_row(lab)
        if r.ensemble != ens or not r.is_ours or r.hmr_da is not None or r.mts:
            raise InputError(f"the {ens} reference must be an {ens} row of this package without HMR or MTS, got {lab!r}")
        out[ens] = lab
    if "NVE" not in out:
        raise InputError("references: an NVE reference is needed")
    return out


def replica_counts(cfg: dict, rows: list) -> dict:
    """{label: replicas} of the study's rows: ``cfg["row_replicas"]`` (labels written in any order of the row grammar)
    where it names a row, ``cfg["replicas"]`` for the others; ValueError where it names a row the study does not have
    or a count below 1."""
    default = int(cfg["replicas"])
    out = {lab: default for lab in rows}
    for lab, n in (cfg.get("row_replicas") or {}).items():
        lab = check_row(lab)
        if not isinstance(n, int) or isinstance(n, bool) or n < 1:
            raise InputError(f"row_replicas[{lab!r}] must be an integer >= 1, got {n!r}")
        if lab not in out:
            raise InputError(f"row_replicas names {lab!r}, which is not among the rows")
        out[lab] = n
    return out


def work(shared: dict, row: dict, replica: int):
    """One run in whatever process executes it (the box is built once per process and settings)."""
    from .runs import run_row

    cfg = shared["cfg"]
    return run_row(water_box_scene(cfg, cfg["model"]), shared["x"][replica], shared["v"][replica], row, cfg, replica)


def check(cfg: dict) -> list:
    """The config's rows, checked (step sizes as floats); ValueError naming what is wrong."""
    check_settings(cfg, ("replicas", "n_waters", "rdf_every"),
                   ("length_ps", "sample_fs", "omega_ps", "omega_fs", "equilibrate_ps", "cutoff_nm", "temperature"))
    if float(cfg["omega_fs"]) > 4.0:
        raise InputError(f"omega_fs must be <= 4 fs (the angular-velocity correlation falls to zero within "
                         f"~20 fs), got {cfg['omega_fs']}")
    if cfg.get("model", "spce") not in ("spce", "tip3p"):
        raise InputError(f"model {cfg.get('model')!r}; known: spce, tip3p")
    rows = [check_row(r) for r in cfg["rows"]]
    if not rows:
        raise InputError("no rows")
    foreign = foreign_rows(cfg, rows)
    if foreign:
        model = cfg.get("model", "spce")
        named = "; ".join(f"{lab!r}: {model}'s is {own!r}" if own else f"{lab!r}: none for {model}"
                          for lab, own in foreign.items())
        raise InputError(f"{len(foreign)} row(s) with the thermostat's target lowered for another water model's box, "
                         f"not {model}'s ({named}); "
                         f"openmm_symprk.studies.fidelity.rowspec.for_model(cfg, {model!r}) makes that swap (what "
                         f"--model does)")
    references(cfg, rows)
    dup = sorted({x for x in rows if rows.count(x) > 1})
    if dup:
        raise InputError(f"rows given twice: {', '.join(dup)}")
    replica_counts(cfg, rows)
    return rows


class FidelityStudy(Study):
    """One run per (row, replica) from the replica states of the model's box."""

    command = "symprk fidelity"
    work = work

    def __init__(self, cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True,
                 log=print, scheduler: str | None = None):
        self.rows = check(cfg)
        super().__init__(out, workers, scheduler, progress, log)
        self.cfg, self.timing, self.report_only = cfg, timing, False
        self.states, self.box = None, None

    def plan(self) -> list:
        with warnings.catch_warnings():  # the periodic box's angular-momentum warning: expected here
            warnings.simplefilter("ignore", ConservationWarning)
            return self._plan()

    def _plan(self) -> list:
        cfg = self.cfg
        counts = replica_counts(cfg, self.rows)
        most = max(counts.values())
        if not self.report_only:  # a report reads the stored runs only: it neither needs nor builds states
            self.states = water_box_replicas(dict(cfg, replicas=most), cfg["model"], self.out, self.log)
        self.box = water_box_scene(cfg, cfg["model"])
        rows = [to_row(lab) for lab in self.rows]
        costs = [row.evals_per_ps(True) * (cfg["settle_ps"] + cfg["omega_ps"] + cfg["length_ps"]) for row in rows]
        # replica by replica (within one, the costliest row first): a study stopped part way leaves every row within
        # one replica of the others, which the frontier's joint resampling of the replicas needs
        turn = sum(costs)
        return [run_of(cfg, row.label, r, cost + (most - r) * turn)
                for r in range(most) for row, cost in zip(rows, costs) if r < counts[row.label]]

    def shared(self, runs) -> dict:
        x, v = self.states
        return {"box": {"cfg": self.cfg, "x": x, "v": v}}

    def stored(self, run, info):
        if info["status"] != "ok":
            self.log(f"{info['row']} replica {info['replica']}: {info['status']}")

    def summarise(self, runs) -> dict:
        from ..report import format_summary, markdown_table, summarise

        grouped = {k[0]: v for k, v in self.results(runs, ("row",)).items()}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConservationWarning)
            if self.report_only or not self.timing:
                timings = self.stored_timings()
            else:  # a row that blew up on the replica state the timing starts from has no wall time to measure
                stable = {lab for lab, reps in grouped.items()
                          if any(i.get("replica") == 0 and i.get("status") == "ok" for _, i in reps)}
                timings = self.timings(stable)
        refs = references(self.cfg, self.rows)
        summary = summarise(self.cfg, self.rows, grouped, timings, self.box_edge(), refs,
                            self.model_properties(grouped, refs) if self.cfg.get("tolerances") else None)
        # the temperature view needs each run's time series (<key>.npz), which a committed data set leaves out
        with_series = {lab: [rep for rep in reps if len(rep[0].get("t", ()))] for lab, reps in grouped.items()}
        summary["temperature_view"] = temperature_view(self.cfg, self.rows, with_series, timings)
        write_text(os.path.join(self.out, "summary.txt"), format_summary(summary) + "\n")
        write_text(os.path.join(self.out, "table.md"), markdown_table(summary) + "\n")
        if summary["temperature_view"]:
            from ...core.temperatures import format_summary as temperature_table

            write_text(os.path.join(self.out, "equipartition.txt"),
                       temperature_table(summary["temperature_view"]) + "\n")
        write_json(os.path.join(self.out, "results.json"), summary)
        self.chart(self.charts, summary, timings)
        return summary

    def charts(self, summary: dict, timings: dict):
        """``fidelity.png``, with timings ``fidelity-wall.png`` and, for a frontier, ``frontier.png``."""
        from ..frontier import frontier_chart
        from ..report import chart

        chart(summary, os.path.join(self.out, "fidelity.png"))
        if timings:
            chart(summary, os.path.join(self.out, "fidelity-wall.png"), x="s_per_ps")
        if summary.get("frontier"):
            frontier_chart(summary, os.path.join(self.out, "frontier.png"))

    def model_properties(self, grouped: dict, refs: dict) -> dict | None:
        """The box's properties for the modified-energy model (:func:`..model.box_properties`), kept in
        :data:`MODEL` so that --report-only remakes the model's lines anywhere: computed once, where the NVT
        reference's runs have their potential-energy series on disk; None before."""
        import json

        path = os.path.join(self.out, MODEL)
        try:
            with open(path) as fh:
                return json.load(fh)
        except (FileNotFoundError, json.JSONDecodeError):
            pass
        series = [arrays["pe"] for arrays, info in grouped.get(refs.get("NVT"), [])
                  if info.get("status") == "ok" and len(arrays.get("pe", ()))]
        if self.report_only or not series:
            return None
        from ..model import box_properties

        x, _ = self.states
        props = box_properties(self.box.system, x, self.box.molecules, self.cfg["temperature"], series)
        write_json(path, props)
        return props

    def box_edge(self) -> float:
        import openmm.unit as unit

        return float(self.box.system.getDefaultPeriodicBoxVectors()[0][0].value_in_unit(unit.nanometer))

    def stored_timings(self) -> dict:
        """The rows' wall time per simulated ps last timed in turns in this folder (:data:`TIMINGS`), {} if none."""
        import json

        try:
            with open(os.path.join(self.out, TIMINGS)) as fh:
                return dict(json.load(fh)["s_per_ps"])
        except (FileNotFoundError, json.JSONDecodeError, KeyError):
            return {}

    def timings(self, stable=None) -> dict:
        """Seconds per simulated ps of each available row on replica 0, timed in turns
        (:func:`openmm_symprk.studies.core.timing.time_rows`), so the ratios hold under the machine's load.  The rows
        timed before in this folder are timed again with them (a run of some rows, ``--rows``, keeps one timings file
        whose rows were all timed in the same turns).  ``stable``: the labels whose run from replica 0 finished (this
        call's other rows, unstable there, are not timed); None: every row."""
        from ...core.timing import seconds_per_ps
        from .runs import replica_seed

        x, v = self.states
        chosen = {label(row) for row in self.rows}
        labels = list(self.rows) + [lab for lab in self.stored_timings() if lab not in chosen]
        rows = {r.label: r for r in (to_row(row, self.cfg["temperature"]) for row in labels)
                if stable is None or r.label in stable or r.label not in chosen}  # timed before: ran then
        out = seconds_per_ps(rows, self.box, x[0], v[0], float(self.cfg.get("timing_fs", 50.0)),
                             self.cfg.get("threads", 1), replica_seed(self.cfg, 0))
        self.log(f"timed {len(rows)} rows in turns")
        import platform
        import time

        import openmm as mm

        write_json(os.path.join(self.out, TIMINGS), {
            "s_per_ps": out, "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "machine": f"{platform.machine()} {os.cpu_count()} cores, OpenMM {mm.__version__} CPU platform, "
                       f"{self.cfg.get('threads', 1)} thread(s) per run",
            "how": "each row on replica 0, in turns (studies.core.timing), best of 3 rounds"})
        return out


def temperature_view(cfg: dict, rows: list, grouped: dict, timings: dict) -> dict | None:
    """The equipartition study's table (:func:`openmm_symprk.studies.core.temperatures.summarise`: T_rot -
    T_trans, T_trans, PE per molecule, drift, the published Verlet trend, the cheapest match) of this study's
    stored runs of the package's NVE rows without HMR: every such run keeps the equipartition study's time
    series (t, T_trans, T_rot, pe, etot), so the view needs no run of its own.  None without such rows."""
    from ...core.temperatures import summarise

    nve = [to_row(r) for r in rows]
    nve = [r.label for r in nve if r.is_ours and r.ensemble == "NVE" and r.hmr_da is None and not r.mts]
    if not nve or not any(grouped.get(lab) for lab in nve):
        return None
    model = cfg["model"]
    view = {k: cfg[k] for k in ("n_waters", "cutoff_nm", "density_g_cm3", "temperature", "settle_ps", "length_ps",
                                "sample_fs")}
    view.update(reference=nve[0], models={model: nve})
    return summarise(view, {(model, lab): grouped.get(lab, []) for lab in nve},
                     {(model, lab): timings[lab] for lab in nve if lab in timings})


def run_study(cfg: dict, out: str, workers: int = 2, timing: bool = True, progress: bool = True, log=print,
              scheduler: str | None = None, report_only: bool = False) -> dict:
    """Run (or finish, or only re-summarise: ``report_only``, see :meth:`~openmm_symprk.studies.core.study.Study.run`) the study in ``out``; returns the summary (:func:`..report.summarise`)
    and writes ``summary.txt``, ``equipartition.txt`` (:func:`temperature_view`), ``results.json``, ``fidelity.png`` (bias against force evaluations per ps) and,
    with timing, ``fidelity-wall.png`` (against wall time per simulated ps) there."""
    if cfg.get("frozen") and not report_only:
        raise InputError(f"the {cfg['frozen']} study is kept as it ran (its runs are of version "
                         f"{cfg.get('run_version')}, made by earlier code): remake its report with --report-only; new "
                         f"measurements run with --preset frontier")
    if int(cfg.get("run_version", RUN_VERSION)) != RUN_VERSION and not report_only:
        raise InputError(f"runs of version {cfg.get('run_version')} cannot be made any more (this code makes version "
                         f"{RUN_VERSION}): use --report-only")
    study = FidelityStudy(cfg, out, workers, timing, progress, log, scheduler)
    study.report_only = bool(report_only)
    return study.run(report_only)
