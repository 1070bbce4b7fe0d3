"""From stored records to results: trajectory errors against the reference, wall-time ratios to
OpenMM's VerletIntegrator, the cheapest method per accuracy, and the summary tables.

* ``traj_error`` of a molecular run: RMS position difference (nm) at the final time from the reference
  run (``reference.method`` at the smallest step / ``reference.factor``, same initial state).
  ``reference_floor``: the same measure for the most accurate swept run of the reference method
  itself, an upper bound of the reference's own error.
* ``wall_vs_verlet``: wall time per ps divided by OpenMM VerletIntegrator's at the same step size, i.e.
  the ratio of per-step wall times.  Each run times itself and a VerletIntegrator on the same scene in
  alternating calls (``wall_vs_verlet_paired``, see :mod:`.runs`): that is the ratio reported.
  Runs without it (older records) fall back to the median per-step time of the ``openmm-verlet`` runs
  of the scene in the same sweep.
"""
from __future__ import annotations

import math
import platform as _platform
from statistics import median

from ...stats import Estimate, drift, no_larger
from ..core.units import kt_per_ns_per_dof
from .records import SCHEMA_VERSION
from .runs import label, rms_deviation

#: Accuracy targets for "which method is cheapest": RMS trajectory error (nm) ...
TRAJ_TARGETS = (1e-3, 1e-5, 1e-7)
#: ... and max |E - E0| per degree of freedom (kJ/mol).
ENERGY_TARGETS = (1e-2, 1e-3, 1e-4, 1e-6)


def aggregate(config, scenes, jobs, store) -> dict:
    """The results document (plain JSON data, ``schema`` = records.SCHEMA_VERSION) from the finished jobs."""
    runs = [j.result.to_json() for j in jobs if j.kind == "run" and j.result]
    refs = {j.scene: j.result.to_json() for j in jobs if j.kind == "reference" and j.result}
    stab = [j.result.to_json() for j in jobs if j.kind == "stability" and j.result]
    for name, ref in refs.items():
        ref_x = (store.arrays(ref["key"]) or {}).get("positions")
        ref["ref_ok"] = ref_x is not None and ref.get("status") == "ok"
        for r in runs:
            if r["scene"] == name and r.get("has_arrays") and ref_x is not None:
                x = (store.arrays(r["key"]) or {}).get("positions")
                if x is not None:
                    r["traj_error"] = rms_deviation(x, ref_x)
    for name in {r["scene"] for r in runs}:
        verlet = [r["wall_per_step"] for r in runs if r["scene"] == name and r["method"] == "openmm-verlet"
                  and r.get("wall_per_step")]
        base = median(verlet) if verlet else None
        for r in runs:
            if r["scene"] == name:
                r["wall_vs_verlet"] = r.get("wall_vs_verlet_paired") or (
                    (r["wall_per_step"] / base) if (base and r.get("wall_per_step")) else None)
    for name, ref in refs.items():
        own = [r["traj_error"] for r in runs if r["scene"] == name and r["method"] == ref["method"]
               and r.get("traj_error") is not None]
        ref["reference_floor"] = min(own) if own else None
    scene_info = {}
    for name, sc in scenes.items():
        scene_info[name] = {"description": sc.description, "why": sc.why, "n_atoms": sc.n_atoms, "n_dof": sc.n_dof,
                            "constraints": sc.system.getNumConstraints(), "platform": sc.platform,
                            "purpose": sc.purpose, "invariants": list(sc.invariants),
                            "exact": sc.exact is not None, "omega_max": (sc.linear or {}).get("omega_max"),
                            "settings": {k: v for k, v in config["scenes"][name].items() if k != "params"}}
    import openmm

    accurate = [r for r in runs if scenes[r["scene"]].purpose == "accuracy"]
    return {"schema": SCHEMA_VERSION, "config": config, "machine": {"python": _platform.python_version(), "openmm": openmm.__version__,
                                          "cpu": _platform.processor() or _platform.machine(),
                                          "cores": _cores()},
            "scenes": scene_info, "runs": runs, "references": list(refs.values()), "stability": stab,
            "best": best_at_accuracy(accurate),
            "best_energy": best_at_accuracy(accurate, ENERGY_TARGETS, "energy_error_per_dof"),
            "production": {name: production_summary(config["scenes"][name], [r for r in runs if r["scene"] == name],
                                                       scenes[name].temperature)
                           for name, sc in scenes.items() if sc.purpose == "production"}}


def _cores():
    import os

    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count()


def usable(r) -> bool:
    """A run whose error counts: it finished and did not fail."""
    return r.get("status") == "ok" and not r.get("failed")


def best_at_accuracy(runs, targets=TRAJ_TARGETS, key="traj_error") -> dict:
    """Per scene and target: the cheapest usable run (force evaluations per ps; ties: wall time) whose
    ``key`` error reaches the target, among the swept step sizes (Langevin excluded)."""
    out = {}
    for name in sorted({r["scene"] for r in runs}):
        rows = [r for r in runs if r["scene"] == name and usable(r) and r.get(key) is not None
                and r["method"] != "openmm-langevin"]
        if not rows:
            continue
        per = {}
        for t in targets:
            ok = [r for r in rows if r[key] <= t]
            if ok:
                b = min(ok, key=lambda r: (r["force_evals_per_ps"], r["wall_per_ps"] or math.inf))
                per[f"{t:g}"] = {"method": b["method"], "step_fs": b["step_fs"],
                                 "force_evals_per_ps": b["force_evals_per_ps"], "error": b[key]}
            else:
                per[f"{t:g}"] = None
        out[name] = per
    return out


def _fmt(x, spec=".2e"):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return format(x, spec)


def format_runs(results, scene) -> str:
    rows = [r for r in results["runs"] if r["scene"] == scene]
    head = (f"{'method':22s} {'h/fs':>5s} {'f/ps':>8s} {'wall s/ps':>9s} {'xVerlet':>7s} {'traj err':>9s} "
            f"{'max|dE|/dof':>11s} {'drift/ns/dof':>12s} {'|dL|/|L|':>9s} {'|dP|':>9s} {'constr':>8s}  status")
    lines = [head, "-" * len(head)]
    for r in sorted(rows, key=lambda r: (r["step_fs"], r["force_evals_per_ps"] or 0, r["method"])):
        status = r["status"] if not r.get("failed") else f"FAILED: {r['failure']}"
        if r["status"] in ("unsupported", "error"):
            status = f"{r['status']}: {r['failure']}"
        lines.append(
            f"{label(r['method']):22s} {r['step_fs']:5g} {_fmt(r.get('force_evals_per_ps'), '8.0f'):>8s} "
            f"{_fmt(r.get('wall_per_ps'), '9.3g'):>9s} {_fmt(r.get('wall_vs_verlet'), '7.2f'):>7s} "
            f"{_fmt(r.get('traj_error')):>9s} {_fmt(r.get('energy_error_per_dof')):>11s} "
            f"{_fmt(r.get('drift_per_ns_per_dof'), '12.2e'):>12s} {_fmt(r.get('dL_rel')):>9s} {_fmt(r.get('dP')):>9s} "
            f"{_fmt(r.get('constraint_error'), '8.1e'):>8s}  {status}")
    return "\n".join(lines)


def format_stability(results) -> str:
    rows = results["stability"]
    if not rows:
        return "(no stability searches)"
    head = (f"{'scene':15s} {'method':22s} {'stable h/fs':>11s} {'fails at':>9s} {'f/step':>6s} "
            f"{'h/f (fs)':>8s} {'h*w':>8s} {'catalogue':>9s}  failure")
    lines = [head, "-" * len(head)]
    for s in rows:
        lines.append(f"{s['scene']:15s} {label(s['method']):22s} {_fmt(s['h_stable_fs'], '11.4f'):>11s} "
                     f"{_fmt(s['h_fail_fs'], '9.4f'):>9s} {_fmt(s.get('force_evals_per_step'), '6d'):>6s} "
                     f"{_fmt(s.get('stable_fs_per_eval'), '8.3f'):>8s} {_fmt(s.get('x_stable'), '8.4f'):>8s} "
                     f"{_fmt(s.get('catalogue'), '9.4f'):>9s}  {s['failure'] or ''}")
    return "\n".join(lines)


def format_best(results, key="best", what="an RMS trajectory error at the final time", unit="nm") -> str:
    lines = [f"Cheapest run (force evaluations per ps) reaching {what}:"]
    for scene, per in results.get(key, {}).items():
        parts = []
        for t, b in per.items():
            parts.append(f"<= {t} {unit}: " + (f"{b['method']} at {b['step_fs']:g} fs ({b['force_evals_per_ps']:.0f}/ps)"
                                          if b else "none"))
        lines.append(f"  {scene:15s} " + "; ".join(parts))
    return "\n".join(lines)


#: Production scenes: a configuration "matches" the baseline when its energy fluctuation is at most this factor
#: of the baseline's and its drift is no larger within two combined standard errors (drifts over tens of ps are
#: measured with errors of their own size).
FLUCTUATION_SLACK = 1.10


def _speed(r):
    """Wall time per simulated fs in units of the paired VerletIntegrator's time per step (machine-load free)."""
    if r.get("wall_vs_verlet_paired") and r.get("step_fs"):
        return r["wall_vs_verlet_paired"] / r["step_fs"]
    return None


def drift_kT(r: dict, temperature: float = 300.0) -> tuple:
    """(energy drift in kT/ns/DOF, its standard error) of a production run, from its stored energy trace with the
    package's one estimator (:func:`openmm_symprk.stats.drift`), so that summarising stored runs again uses the
    current estimator; the record's own figures when it has no trace (or None, None for a failed run)."""
    if r.get("drift_kT_per_ns_per_dof") is None:
        return None, None
    t, de = r.get("trace_t") or [], r.get("trace_de_per_dof") or []
    if len(t) < 3:
        return r["drift_kT_per_ns_per_dof"], r.get("drift_kT_stderr")
    d = drift(t, de)  # kJ/mol per ps per DOF
    return kt_per_ns_per_dof(d.slope, temperature), kt_per_ns_per_dof(d.se, temperature)


def production_summary(scene_config: dict, runs: list, temperature: float = 300.0) -> dict:
    """Per production scene: every row's ns/day, its speed against the baseline (OpenMM's VerletIntegrator at 2 fs,
    or at its largest good step) measured in the same run, its energy drift and fluctuation, whether it matches
    the baseline's accuracy, and the fastest row that does."""
    good = [r for r in runs if usable(r) and r.get("energy_std_per_dof") is not None]
    spec = scene_config.get("baseline", ["openmm-verlet", 2.0])
    if spec == "largest-good openmm-verlet":
        verlets = [r for r in good if r["method"] == "openmm-verlet"]
        base = max(verlets, key=lambda r: r["step_fs"]) if verlets else None
    else:
        base = next((r for r in good if r["method"] == spec[0] and r["step_fs"] == float(spec[1])), None)
    base_drift = Estimate(*drift_kT(base, temperature)) if base is not None else None
    rows = []
    for r in runs:
        d, d_err = drift_kT(r, temperature)
        row = {"method": r["method"], "step_fs": r["step_fs"], "status": r["status"] if not r.get("failed") else
               f"failed: {r.get('failure')}", "ns_per_day": 86.4 / r["wall_per_ps"] if r.get("wall_per_ps") else None,
               "drift": d, "drift_err": d_err,
               "fluctuation": r.get("energy_std_per_dof"), "speedup": None, "matches": None}
        if base is not None and _speed(base) and _speed(r):
            row["speedup"] = _speed(base) / _speed(r)
        if base is not None and r in good:
            row["matches"] = bool(no_larger(Estimate(d, d_err or 0.0), Estimate(base_drift.mean, base_drift.se or 0.0))
                                  and r["energy_std_per_dof"] <= FLUCTUATION_SLACK * base["energy_std_per_dof"])
        rows.append(row)
    winners = sorted((row for row in rows if row["matches"] and row["speedup"]), key=lambda row: -row["speedup"])
    return {"baseline": None if base is None else {"method": base["method"], "step_fs": base["step_fs"]},
            "rows": rows, "best": winners[0] if winners else None}


def format_production(results, scene) -> str:
    summary = results.get("production", {}).get(scene)
    if not summary:
        return ""
    base = summary["baseline"]
    head = (f"{'row':28s} {'h/fs':>5s} {'ns/day':>8s} {'x base':>7s} {'drift kT/ns/DOF':>20s} {'std(E)/DOF':>11s} "
            f"{'matches':>8s}  status")
    lines = [f"baseline: {label(base['method'])} at {base['step_fs']:g} fs" if base else "baseline: none usable",
             head, "-" * len(head)]
    for row in sorted(summary["rows"], key=lambda row: -(row["speedup"] or 0)):
        drift = (f"{row['drift']:+.2e} +- {row['drift_err']:.1e}" if row["drift"] is not None else "-")
        matches = "-" if row["matches"] is None else ("yes" if row["matches"] else "no")
        lines.append(f"{label(row['method']):28s} {row['step_fs']:5g} {_fmt(row['ns_per_day'], '8.2f'):>8s} "
                     f"{_fmt(row['speedup'], '7.2f'):>7s} {drift:>20s} {_fmt(row['fluctuation'], '11.2e'):>11s} "
                     f"{matches:>8s}  {row['status']}")
    best = summary["best"]
    lines.append("fastest row at the baseline's drift and fluctuation: "
                 + (f"{label(best['method'])} at {best['step_fs']:g} fs, {best['speedup']:.2f}x the baseline"
                    if best else "none"))
    return "\n".join(lines)


def format_summary(results) -> str:
    out = [f"symprk bench ({results['config']['mode']}): OpenMM {results['machine']['openmm']}, "
           f"{results['machine']['cores']} cores"]
    for name, info in results["scenes"].items():
        if info["purpose"] == "production":
            out += ["", f"== {name}: {info['description']} [{info['platform']}; NVE production runs]",
                    format_production(results, name)]
            continue
        ref = next((r for r in results["references"] if r["scene"] == name), None)
        src = "exact solution" if info["exact"] else (
            f"reference {ref['method']} at {ref['step_fs']:.4g} fs (floor {_fmt(ref.get('reference_floor'))} nm)"
            if ref else "no trajectory reference")
        out += ["", f"== {name}: {info['description']} [{info['platform']}; errors vs {src}]",
                format_runs(results, name)]
    if results.get("stability"):
        out += ["", "== largest stable step", format_stability(results)]
    if results.get("best"):
        out += ["", format_best(results), "", format_best(results, "best_energy", "a max |E - E0| per DOF", "kJ/mol")]
    return "\n".join(out)

