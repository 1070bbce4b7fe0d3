"""One run of the bench: one row (a :class:`~..core.rows.Row` label: method and step) on one scene, from the scene's
shared state.

:class:`RunSpec` names the run; :func:`execute` turns (spec, scene payload) into a plain-dict record and
never raises for a failing integrator (blow-up, NaN, unsupported method, OpenMM error): the failure is
the record.  What a record holds (units nm, ps, Da, kJ/mol):

* ``energy_error``: max |E - E0| over the samples; ``energy_error_per_dof`` divides it by the degrees of
  freedom; ``drift_per_ns_per_dof``: slope of a least-squares line through E(t) - E0, per ns, per DOF.
* ``dP``: max |P - P0|; ``dL_rel``: max |L - L0| / |L0| (about the origin) -- only where the scene has
  that invariant (None otherwise).
* ``constraint_error``: max relative bond-length error max |r - d| / d.
* ``traj_error``: RMS position error (nm) at the final time against the exact solution (toys); for the
  molecular scenes the sweep fills it in against the reference run (see :mod:`.sweep`).
* ``force_evals_per_step`` (:meth:`~..core.rows.Row.evals_per_step`) and ``force_evals_per_ps``;
  ``wall_per_step`` and ``wall_per_ps`` (seconds) from uninterrupted ``step(n)`` calls after the measured segment
  (sampling clears OpenMM's force cache, so it is not timed), in turns with the same calls of OpenMM's
  VerletIntegrator on the same scene: ``wall_vs_verlet_paired`` is the ratio of the two minima (see :func:`_time`).
* ``failed`` / ``failure``: blow-up ("blow-up: ..."), energy error above the scene's threshold, or a
  constraint error above 1e-3 (see :mod:`.stability`); ``status`` is "ok", "failed", "unsupported"
  (the method cannot run this system, e.g. an implicit tableau with constraints) or "error".

The bench names its rows without their step (:func:`bench_name`: a catalogue name, ``openmm-verlet``,
``openmm-langevin``, ``openmm-mts<n>``, ``<method>[/<inner>]@mts<n>``); a record keeps that name and the step.
OpenMM's leapfrog integrators start from v(-h/2) (:class:`~..core.engine.RowEngine`), which gives them the same
position trajectory as velocity Verlet from (x0, v0).
"""
from __future__ import annotations

import math
import time
import traceback
from dataclasses import asdict, dataclass

import numpy as np
import openmm as mm

from ...physics import angular_momentum, linear_momentum
from ...stats import drift
from ...systems.properties import constraint_violation
from ...systems.scenes import Scene
from ..core.engine import RowEngine
from ..core.rows import Row
from ..core.timing import time_rows
from ..core.units import kT, kt_per_ns_per_dof
from .records import RunRecord
from ...support.errors import InputError

#: Constraint tolerance for every run (SETTLE ignores it; CCMA iterates to it) ...
CONSTRAINT_TOLERANCE = 1e-10
#: ... but production scenes run with OpenMM's default, as users do.
PRODUCTION_CONSTRAINT_TOLERANCE = 1e-5
#: Failure thresholds (see stability.py for their rationale).
KT300 = kT(300.0)
ENERGY_THRESHOLD_KT = 0.1  # kT(300 K) per degree of freedom
CONSTRAINT_THRESHOLD = 1e-3  # relative bond-length error
SPEED_LIMIT = 1e5  # nm/ps: a velocity above this is a blow-up


@dataclass(frozen=True)
class RunSpec:
    scene: str
    row: str  # a Row label: who, step, thermostat (at the scene's temperature), seed
    n_steps: int
    n_samples: int = 50
    role: str = "run"  # "run", "reference", "probe" (stability: stop at the first failure), "linear-probe"
    platform: str | None = None  # None: the scene's platform
    timing_s: float = 0.0  # seconds of uninterrupted stepping to time (0: no timing)
    threads: int = 1  # CPU platform threads

    @property
    def spec_row(self) -> Row:
        return Row.parse(self.row)

    @property
    def h_ps(self) -> float:
        return self.spec_row.h_ps

    @property
    def length_ps(self) -> float:
        return self.n_steps * self.h_ps

    def to_dict(self) -> dict:
        return asdict(self)

    def record_fields(self) -> dict:
        """The record's fields of the run: the spec with its row as the bench's name, its step and its seed."""
        row = self.spec_row
        out = {k: v for k, v in asdict(self).items() if k != "row"}
        return dict(out, method=bench_name(row), step_fs=row.step_fs, seed=row.seed)


def bench_name(row: Row) -> str:
    """The bench's name of a row, without its step: ``openmm-langevin``, ``openmm-mts<n>``,
    ``<method>[/<inner>]@mts<n>`` or the row's who."""
    if row.who == "langevin":
        return "openmm-langevin"
    if row.who == "openmm-mts":
        return f"openmm-mts{row.mts}"
    if row.mts:
        return f"{row.method}{'/' + row.inner if row.inner else ''}@mts{row.mts}"
    return row.who


def label(method: str) -> str:
    return {"openmm-verlet": "OpenMM Verlet", "openmm-langevin": "OpenMM Langevin"}.get(method, method)


#: The precision the bench runs a GPU platform in.
PRECISION = {"OpenCL": "double", "CUDA": "mixed", "HIP": "mixed"}


class Unsupported(Exception):
    """The method cannot run on this system."""


def bench_row(method: str, step_fs: float, scene: Scene | None = None, temperature=None) -> Row:
    """The :class:`~..core.rows.Row` of a bench row name at ``step_fs`` (its thermostat, if any, at the scene's
    temperature unless ``temperature`` is given).  The bench's names are row labels without the step:
    ``openmm-verlet``, ``openmm-langevin``, ``openmm-mts<n>``, ``<method>[/<inner>]@mts<n>`` (the scene's slow force
    group 1 once per step, group 0 n times) or a catalogue name."""
    row = Row.parse(method, step_fs=step_fs)
    if row.thermostat:
        t = temperature if temperature is not None else (scene.temperature if scene is not None else row.temperature)
        row = row.replace(temperature=float(t))
    return row


def canonical_row(name: str) -> str:
    """The canonical name of a bench row (catalogue aliases resolved); ValueError naming what is accepted."""
    try:
        return bench_name(Row.parse(name, step_fs=1.0))
    except InputError as exc:
        raise InputError(f"{exc}. Bench rows are catalogue names, openmm-verlet, openmm-langevin, openmm-mts<n> "
                         f"(OpenMM's MTSIntegrator) or <method>[/<inner>]@mts<n> (multiple time stepping)") from None


def engine(row: Row, scene: Scene, platform: str, threads: int = 1, start: bool = True, x=None, v=None) -> RowEngine:
    """The row running on ``scene`` (a GPU platform in :data:`PRECISION`); Unsupported when the method cannot run
    the scene's System."""
    from ...integrators import ConstraintSupportError

    tolerance = PRODUCTION_CONSTRAINT_TOLERANCE if scene.purpose == "production" else CONSTRAINT_TOLERANCE
    spec = f"{platform}:{PRECISION[platform]}" if platform in PRECISION else platform
    try:
        return RowEngine(row, scene, x, v, platform=spec, threads=threads, constraint_tolerance=tolerance,
                         start=start, quiet=True, tolerance=CONSTRAINT_TOLERANCE)
    except ConstraintSupportError as exc:
        raise Unsupported(str(exc)) from None


def base_record(spec: RunSpec, scene: Scene, platform: str) -> RunRecord:
    fields = dict(spec.record_fields(), platform=platform)
    return RunRecord(**fields, label=label(fields["method"]), length_ps=spec.length_ps, n_atoms=scene.n_atoms,
                     n_dof=scene.n_dof)


def _failure(rec, reason, t):
    """Record the first failure; a later blow-up is appended to it."""
    if not rec.failed:
        rec.update(failed=True, failure=reason, fail_time_ps=t, status="failed")
    elif reason.startswith("blow-up") and "blow-up" not in rec.failure:
        rec.failure += f"; then {reason} at {t:.4g} ps"


def execute(spec: RunSpec, scene: Scene) -> tuple[RunRecord, dict]:
    """Run ``spec`` on ``scene``; returns (record, arrays).  ``arrays`` holds the final positions of
    molecular accuracy runs (for the trajectory error against the reference), else it is empty."""
    if spec.role == "linear-probe":
        raise ValueError("linear probes are run by stability.run_spec, not by runs.execute")
    platform = spec.platform or scene.platform
    arrays = {}
    try:
        rec = base_record(spec, scene, platform)
    except ValueError as exc:  # a row that does not read (e.g. an unknown method): an error record under its label
        return RunRecord(scene=spec.scene, method=spec.row, step_fs=0.0, n_steps=spec.n_steps, role=spec.role,
                         platform=platform, status="error", failure=f"{type(exc).__name__}: {exc}"), arrays
    t_setup = time.perf_counter()
    try:
        row = spec.spec_row
        eng = engine(row, scene, platform, spec.threads)
        rec.force_evals_per_step = row.evals_per_step(scene.system.getNumConstraints() > 0)
        rec.force_evals_per_ps = rec.force_evals_per_step / spec.h_ps
    except Unsupported as exc:
        rec.update(status="unsupported", failure=str(exc).split(". ")[0])
        return rec, arrays
    except Exception as exc:  # a broken run is a record, never a crashed sweep
        rec.update(status="error", failure=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
        return rec, arrays
    rec.setup_s = time.perf_counter() - t_setup
    try:
        _measure(spec, scene, eng, rec, arrays)
    except Exception as exc:
        if is_blowup(exc):  # e.g. in the timing segment
            rec.blew_up = True
            _failure(rec, _blowup_reason(exc), rec.steps_done * spec.h_ps)
        else:
            rec.update(status="error", failure=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
    return rec, arrays


def is_blowup(exc) -> bool:
    from ...integrators import SimulationBlowUpError

    return isinstance(exc, (SimulationBlowUpError, FloatingPointError)) or (
        isinstance(exc, mm.OpenMMException) and "nan" in str(exc).lower())


def _blowup_reason(exc) -> str:
    import re

    msg = str(exc)
    if isinstance(exc, mm.OpenMMException):
        return "blow-up: OpenMM reports NaN coordinates"
    what = re.search(r": (velocities[^.]*?|positions[^.]*?)\. ", msg)
    step = re.search(r"step (\d+)", msg)
    return f"blow-up: {what.group(1) if what else 'non-finite state'}" + (f" (step {step.group(1)})" if step else "")


def rms_deviation(x, y) -> float:
    """Root-mean-square distance between two (N, 3) position sets (nm)."""
    return float(np.sqrt(np.mean(np.sum((np.asarray(x) - np.asarray(y)) ** 2, axis=1))))


def _state(eng):
    """(x, v, E = kinetic + potential energy) now."""
    x, v, pe, ke = eng.sample()
    return x, v, ke + pe


def _measure(spec, scene, eng, rec, arrays):
    m = scene.masses()
    cons = scene.constraints()
    n_dof = scene.n_dof
    inv = set(scene.invariants)
    x, v, e0 = _state(eng)
    p0, l0 = linear_momentum(v, m), angular_momentum(x, v, m, about="origin")
    rec.E0 = e0
    threshold = ENERGY_THRESHOLD_KT * KT300 * n_dof
    stop_early = spec.role == "probe"
    ts, des = [0.0], [0.0]
    worst_e = worst_p = worst_l = worst_c = 0.0
    marks = sorted({max(1, round(k * spec.n_steps / spec.n_samples)) for k in range(1, spec.n_samples + 1)})
    done = 0
    t_loop = time.perf_counter()
    for mark in marks:
        try:
            eng.step(mark - done)
        except Exception as exc:
            if not is_blowup(exc):
                raise
            rec.blew_up = True
            _failure(rec, _blowup_reason(exc), (done + 1) * spec.h_ps)
            break
        done = mark
        rec.steps_done = done
        t = done * spec.h_ps
        x, v, e = _state(eng)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v)) and np.isfinite(e)) or np.max(np.abs(v)) > SPEED_LIMIT:
            rec.blew_up = True
            _failure(rec, "blow-up: non-finite or runaway state", t)
            break
        de = e - e0
        ts.append(t)
        des.append(de / n_dof)
        worst_e = max(worst_e, abs(de))
        if "momentum" in inv:
            worst_p = max(worst_p, float(np.linalg.norm(linear_momentum(v, m) - p0)))
        if "angular_momentum" in inv:
            worst_l = max(worst_l, float(np.linalg.norm(angular_momentum(x, v, m, about="origin") - l0)
                                         / np.linalg.norm(l0)))
        worst_c = max(worst_c, constraint_violation(x, cons))
        if rec.method != "openmm-langevin" and "energy" in inv and abs(de) > threshold:
            _failure(rec, f"energy error above {ENERGY_THRESHOLD_KT:g} kT per DOF", t)
        if worst_c > CONSTRAINT_THRESHOLD:
            _failure(rec, f"constraint error above {CONSTRAINT_THRESHOLD:g}", t)
        if rec.failed and stop_early:
            break
    loop_s = time.perf_counter() - t_loop
    fit = drift(ts, des) if len(ts) >= 3 else None  # kJ/mol per ps per DOF
    rec.update(energy_error=worst_e, energy_error_per_dof=worst_e / n_dof,
               drift_per_ns_per_dof=fit.slope * 1e3 if fit else None,
               dP=worst_p if "momentum" in inv else None,
               dL_rel=worst_l if "angular_momentum" in inv else None,
               constraint_error=worst_c, trace_t=ts, trace_de_per_dof=des)
    if scene.purpose == "production" and len(ts) > 3:
        # production figures: energy fluctuation and drift per DOF, the drift in kT/ns with its standard error
        rec.update(energy_std_per_dof=float(np.std(des)),
                   drift_kT_per_ns_per_dof=kt_per_ns_per_dof(fit.slope, scene.temperature),
                   drift_kT_stderr=kt_per_ns_per_dof(fit.se, scene.temperature))
    if rec.blew_up:
        # the measured maxima only cover the samples before the blow-up: do not report them as errors
        rec.update(energy_error=None, energy_error_per_dof=None, drift_per_ns_per_dof=None, dP=None, dL_rel=None,
                   energy_std_per_dof=None, drift_kT_per_ns_per_dof=None, drift_kT_stderr=None)
    completed = done == spec.n_steps and not rec.blew_up
    if completed:
        if scene.exact is not None:
            from ..core.toys import exact_state

            xe, _ = exact_state(scene.exact, spec.length_ps)
            rec.traj_error = rms_deviation(x, xe)
        elif scene.purpose == "accuracy" and spec.role in ("run", "reference"):
            arrays["positions"] = x
    if spec.timing_s > 0 and completed and done:
        _time(spec, scene, eng, rec, loop_s / done)


#: Timing: rounds of (this integrator, then OpenMM's VerletIntegrator); the minimum of each is kept.
TIMING_ROUNDS = 2
#: Step of the paired VerletIntegrator timing (its cost per step does not depend on the step size).
VERLET_TIMING_STEP_FS = 0.5


def _steps_for(seconds, per_step):
    return int(min(100_000, max(10, math.ceil(seconds / max(per_step, 1e-9)))))


def _time(spec, scene, eng, rec, per_step_estimate, rounds=TIMING_ROUNDS):
    """Wall time per step of ``eng`` (continuing from where the measured run ended) and of a fresh OpenMM
    VerletIntegrator on the same scene and platform, taking turns (:func:`..core.timing.time_rows`): the fastest
    block of each is kept, so that load from other processes cancels out of the ratio as far as it can."""
    n_time = _steps_for(spec.timing_s / (2 * rounds), per_step_estimate)
    verlet = engine(Row("openmm-verlet", VERLET_TIMING_STEP_FS), scene, spec.platform or scene.platform, spec.threads)
    verlet.step(2)  # warm up (kernels, force cache)
    t0 = time.perf_counter()
    verlet.advance(10)
    n_verlet = _steps_for(spec.timing_s / (2 * rounds), (time.perf_counter() - t0) / 10)
    try:
        t = time_rows({"own": eng, "verlet": verlet}, {"own": n_time, "verlet": n_verlet}, rounds)
    except Exception as exc:
        if not is_blowup(exc):
            raise
        return  # the run blew up while being timed: no timing
    best, verlet = t["own"].best, t["verlet"].best
    rec.update(wall_per_step=best, wall_per_ps=best / spec.h_ps, timing_steps=n_time * rounds,
               verlet_wall_per_step=verlet, wall_vs_verlet_paired=best / verlet)


def retime(spec: RunSpec, scene: Scene, rec: RunRecord, rounds: int = TIMING_ROUNDS) -> RunRecord:
    """Measure the timing of a finished run again, from the scene's initial state, leaving what the run
    measured untouched: for a sweep whose machine was busy while it ran (``symprk bench --retime``).  The
    paired VerletIntegrator is timed in turns with it, as in the run itself."""
    if not rec.wall_per_step:
        raise InputError(f"run {rec.method} at {rec.step_fs:g} fs on {rec.scene} has no timing to measure again "
                         f"(status {rec.status!r})")
    eng = engine(spec.spec_row, scene, spec.platform or scene.platform, spec.threads)
    eng.step(2)  # warm up (kernels, force cache)
    t0 = time.perf_counter()
    eng.advance(5)
    _time(spec, scene, eng, rec, (time.perf_counter() - t0) / 5, rounds)
    return rec.update(retimed=True)
