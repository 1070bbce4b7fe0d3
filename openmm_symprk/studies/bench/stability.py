"""Largest stable step per method and scene, by a geometric scan and bisection.

A probe is a short run at one step size (:class:`~.runs.RunSpec` with role "probe") from the scene's
shared state.  It **fails** on

* blow-up: NaN or infinite positions/velocities, a velocity above 1e5 nm/ps, or OpenMM's own NaN error;
* energy: max |E - E0| above 0.1 kT(300 K) per degree of freedom (about 10 % of the energy a system at
  300 K holds; a stable method at a sane step stays 2-4 orders of magnitude below);
* constraints: a relative bond-length error above 1e-3 (CCMA at tolerance 1e-10 that stopped
  converging; SETTLE is exact).

Failures are recorded (with the time they happened), never raised.  The search starts at ``h0``,
multiplies the step by ``grow`` while probes pass (up to ``cap``; no failure up to the cap is reported
as such), divides it while they fail, then bisects between the last passing and first failing step
until they differ by less than ``rel_tol``.  The answer is the last passing step.

On the harmonic toy a failure is decided exactly instead of by waiting: the scene is linear, so one
step of the compiled program from two unit states per oscillator gives its 2x2 one-step matrix, and
the run blows up if and only if an eigenvalue has modulus above 1 (+1e-6 for round-off).  The probe
at step h uses 4096 oscillators with frequencies spread evenly over [omega_max/2, omega_max], i.e. it
checks every h*omega in [x/2, x] (x = h*omega_max) on a grid finer than 4e-4; the passing probes of the
scan below it (steps in ratios of 1.25 < 2, from x = 0.5) cover the rest, so the answer is the largest
x with every h*omega in (0, x] stable: the definition of the catalogue's stability intervals.
Narrow resonance bands are caught (blanes-moan-srkn11b-6 is unstable only for h*omega in [3.1414,
3.1423], growing by 1.0004 per step: a finite run would miss it).
"""
from __future__ import annotations

import warnings

import numpy as np

from ...methods.stability import spectral_radius
from .records import StabilityRecord
from .runs import RunSpec, Unsupported, base_record, bench_row, engine, execute, is_blowup, label

#: Oscillators in the linear probe, over [omega_max/2, omega_max]: spacing x/8192 < 4e-4 at x < 3.3 and
#: < 7.4e-4 at x = 6, below the narrowest band known (7.6e-4 wide, sofroniou-spaletta-10 at 3.1411).
LINEAR_PROBE_N = 4096
#: Round-off allowance on the spectral radius of a measured one-step matrix.
LINEAR_TOLERANCE = 1e-6

_probe_systems: dict = {}


def _dense_harmonic(omega_max: float):
    from ..core import toys

    key = float(omega_max)
    if key not in _probe_systems:
        omega = 0.5 * omega_max * (1 + np.arange(LINEAR_PROBE_N) / (LINEAR_PROBE_N - 1))
        _probe_systems[key] = (omega, toys.harmonic_system(omega))
    return _probe_systems[key]


def linear_probe(spec: RunSpec, scene):
    """One step of the spec's row on the dense harmonic spectrum; fails if the one-step map grows."""
    from ...systems.scenes import Scene

    omega_max = scene.linear["omega_max"]
    omega, system = _dense_harmonic(omega_max)
    n = len(omega)
    q, w = 1e-3, 1e-3 * omega_max  # column 1: (q, 0) on the x axis; column 2: (0, w) on the y axis
    x0, v0 = np.zeros((n, 3)), np.zeros((n, 3))
    x0[:, 0] = q
    v0[:, 1] = w
    probe_scene = Scene(scene.name, system, x0, v0, "", invariants=())
    platform = spec.platform or scene.platform
    rec = base_record(spec, probe_scene, platform)
    rec.n_oscillators = n
    row = spec.spec_row
    row = row.replace(temperature=0.0) if row.thermostat else row
    try:  # (x0, v0) as given, also for a leapfrog row: the map of its own state
        eng = engine(row, probe_scene, platform, spec.threads, start=False)
    except Unsupported as exc:
        rec.update(status="unsupported", failure=str(exc).split(". ")[0])
        return rec
    rec.update(force_evals_per_step=row.evals_per_step(False), force_evals_per_ps=row.evals_per_ps(False))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            eng.step(1)
        x, v, _, _ = eng.sample(energy=False)
    except Exception as exc:
        if not is_blowup(exc):
            raise
        rec.update(failed=True, status="failed", failure="blow-up in one step", steps_done=1)
        return rec
    rec.steps_done = 1
    # one-step matrix in the scaled coordinates (x/q, v/w)
    m11, m21 = x[:, 0] / q, v[:, 0] / w
    m12, m22 = x[:, 1] / q, v[:, 1] / w
    radius = spectral_radius(m11, m12, m21, m22)
    bad = ~(radius <= 1 + LINEAR_TOLERANCE)
    rec.spectral_radius = float(np.nanmax(np.where(np.isfinite(radius), radius, np.inf)))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        rec.x_first_unstable = float(spec.h_ps * omega[i])  # lowest unstable h*omega in this probe
        rec.update(failed=True, status="failed",
                   failure=f"blow-up: one-step map grows by {radius[i]:.6g} at h*omega = {spec.h_ps * omega[i]:.5f}")
    return rec


def search(h0: float, cap: float, grow: float = 1.25, rel_tol: float = 0.01, floor: float | None = None):
    """Generator: yields step sizes, is sent True (stable) / False (failed), returns (h_stable, h_fail).

    h_stable is None if even ``floor`` failed; h_fail is None if nothing failed up to ``cap``."""
    floor = h0 / 16 if floor is None else floor
    lo = hi = None
    h = h0
    while True:
        ok = yield h
        if ok:
            lo = h
        else:
            hi = h
        if hi is None:
            if h >= cap:
                return lo, None
            h = min(h * grow, cap)
        elif lo is None:
            if h <= floor:
                return None, hi
            h = max(h / grow, floor)
        else:
            if hi - lo <= rel_tol * lo:
                return lo, hi
            h = 0.5 * (lo + hi)


def driver(scene_name: str, method: str, settings: dict, platform=None, threads: int = 1, temperature: float = 300.0):
    """Generator for the sweep: yields probe RunSpecs of the bench row ``method`` (a thermostat at ``temperature``),
    is sent their records, returns the summary.

    ``settings``: linear (bool), h0_fs, cap_fs, grow, rel_tol, probe_steps, samples, omega_max."""
    linear = settings.get("linear", False)
    s = search(settings["h0_fs"], settings["cap_fs"], settings.get("grow", 1.25), settings.get("rel_tol", 0.01))
    probes = []
    h = next(s)
    fail_reason = None
    evals = None
    while True:
        spec = RunSpec(scene_name, bench_row(method, h, temperature=temperature).label,
                       1 if linear else settings["probe_steps"],
                       1 if linear else settings.get("samples", 20),
                       role="linear-probe" if linear else "probe", platform=platform, threads=threads)
        rec = yield spec
        evals = rec.force_evals_per_step or evals
        if rec.status in ("unsupported", "error"):
            return _summary(scene_name, method, settings, None, None, rec.failure, probes, evals, rec.status)
        ok = rec.status == "ok" and not rec.failed
        probes.append([h, ok, rec.failure])
        if not ok:
            fail_reason = rec.failure
        try:
            h = s.send(ok)
        except StopIteration as stop:
            lo, hi = stop.value
            reason = next((p[2] for p in probes if p[0] == hi), fail_reason) if hi is not None else None
            return _summary(scene_name, method, settings, lo, hi, reason, probes, evals, "ok")


def _summary(scene, method, settings, lo, hi, reason, probes, evals, status) -> StabilityRecord:
    out = StabilityRecord(
        scene=scene, method=method, label=label(method), status=status, h_stable_fs=lo, h_fail_fs=hi,
        failure=reason if hi is not None or status != "ok" else f"no failure up to {settings['cap_fs']:g} fs",
        force_evals_per_step=evals, stable_fs_per_eval=(lo / evals) if (lo and evals) else None, probes=probes,
        criterion="linear one-step map" if settings.get("linear") else f"{settings.get('probe_steps')}-step runs",
        rel_tol=settings.get("rel_tol", 0.01))
    if settings.get("linear"):
        out.update(x_stable=lo * 1e-3 * settings["omega_max"] if lo else None, catalogue=catalogue_stability(method))
    return out


def catalogue_stability(method: str):
    """The catalogue's largest stable h*omega for a row (OpenMM's Verlet: 2), or None."""
    if method == "openmm-verlet":
        return 2.0
    if method == "openmm-langevin":
        return None
    from ...methods.catalogue import get_method

    st = get_method(method).stability
    return None if st is None else float(st)


def linear_settings(omega_max: float, rel_tol: float = 1e-4) -> dict:
    """Search settings for the harmonic toy, in h*omega: from 0.5 up to 12 (fs for omega_max)."""
    to_fs = 1e3 / omega_max
    return {"linear": True, "h0_fs": 0.5 * to_fs, "cap_fs": 12.0 * to_fs, "grow": 1.25, "rel_tol": rel_tol,
            "omega_max": omega_max}


def run_spec(spec: RunSpec, scene) -> tuple:
    """(record, arrays) of any spec: linear probes here, everything else by :func:`.runs.execute`."""
    if spec.role == "linear-probe":
        return linear_probe(spec, scene), {}
    return execute(spec, scene)


def largest_stable_step(scene, method: str, settings: dict, platform=None) -> dict:
    """Run one stability search in this process (no sweep, nothing stored); returns its summary.

    ``settings`` as for :func:`driver`, e.g. ``linear_settings(700.0)`` on the harmonic scene."""
    gen = driver(scene.name, method, settings, platform=platform, temperature=scene.temperature)
    spec = next(gen)
    while True:
        rec, _ = run_spec(spec, scene)
        try:
            spec = gen.send(rec)
        except StopIteration as stop:
            return stop.value
