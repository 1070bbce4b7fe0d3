"""The rigid-water temperature table: the equipartition study's report, and the fidelity study's temperature view
of its own runs (pure numerics).

Per model and row (a Row label): T_rot - T_trans, T_trans, potential energy per molecule and the NVE energy drift
(kT/ns per degree of freedom) of the replica runs' time series (t, T_trans, T_rot, pe, etot), each the mean over
replicas with the larger of the within- and between-replica standard errors (:mod:`openmm_symprk.stats`); the cost
in force evaluations per ps and in wall seconds per simulated ps (measured in turns, relative to the reference row).
A row *matches* the reference when its T_rot - T_trans and potential energy per molecule both lie within 2 combined
standard errors of the reference's, compared replica by replica: every row runs from the same replica states, so
each replica's total energy (and with it much of the scatter of T and the potential energy between replicas) is
shared, and the mean of the per-replica differences (``vs_ref``) is far more precise than the difference of the
means.
"""
from __future__ import annotations

import numpy as np

from ...stats import Estimate, agrees, combine, drift, paired, series_stats
from .rows import Row
from .units import kt_per_ns_per_dof

ZERO = Estimate(0.0, 0.0, 0, 0.0, 0.0)

__all__ = ["summarise", "format_summary"]


#: Quantities compared with the reference replica by replica.
PAIRED = ("dT", "pe")


def _row_stats(reps, n_waters, temperature):
    per = {"dT": [], "T_trans": [], "T_rot": [], "pe": [], "drift": []}
    taus = []
    replicas = [int(info["replica"]) for _, info in reps]
    dof = 6 * n_waters - 3
    for arrays, _ in reps:
        t = arrays["t"]
        ok = np.isfinite(arrays["etot"])
        dt = float(t[1] - t[0]) if len(t) > 1 else 1.0
        d = series_stats(arrays["T_rot"][ok] - arrays["T_trans"][ok], dt)
        taus.append(d.tau)
        per["dT"].append(d)
        per["T_trans"].append(series_stats(arrays["T_trans"][ok], dt))
        per["T_rot"].append(series_stats(arrays["T_rot"][ok], dt))
        per["pe"].append(series_stats(arrays["pe"][ok] / n_waters, dt))
        slope, se = drift(t[ok], arrays["etot"][ok])  # kJ/mol/ps
        per["drift"].append((kt_per_ns_per_dof(slope, temperature, dof), kt_per_ns_per_dof(se, temperature, dof)))
    out = {}
    for k, vals in per.items():
        if k == "drift":
            out[k] = combine([a for a, _ in vals], [b for _, b in vals])
        else:
            out[k] = combine([s.mean for s in vals], [s.se for s in vals])
    out["tau_ps"] = float(np.mean(taus))
    out["per_replica"] = {k: {r: (float(v.mean), float(v.se)) for r, v in zip(replicas, per[k])} for k in PAIRED}
    return out


def summarise(cfg: dict, runs: dict, timings: dict | None = None) -> dict:
    """The results from the finished runs ({(model, label): [(arrays, info)]}) of the rows ``cfg["models"]``
    ({model: [label, ...]}, ``cfg["reference"]`` among them) and the optional timings ({(model, label): wall
    seconds per simulated ps})."""
    timings = timings or {}
    ref_label = Row.parse(cfg["reference"]).label
    models = {}
    for model, labels in cfg["models"].items():
        table = []
        for spec in map(Row.parse, labels):
            reps = runs.get((model, spec.label), [])
            good = [(a, i) for a, i in reps if i.get("status") == "ok"]
            failed = [i["status"] for a, i in reps if i.get("status") != "ok"]
            row = {"method": spec.who, "step_fs": spec.step_fs, "label": spec.label, "replicas": len(good),
                   "failed": failed, "rigid_body": spec.is_rigid, "evals_per_ps": spec.evals_per_ps(constraints=True),
                   "s_per_ps": timings.get((model, spec.label))}
            if good and min(len(a["t"]) for a, _ in good) >= 3:
                stats = _row_stats(good, cfg["n_waters"], cfg["temperature"])
                row.update({k: v.as_dict() if isinstance(v, Estimate) else v for k, v in stats.items()})
            table.append(row)
        ref = next((r for r in table if r["label"] == ref_label), None)
        for r in table:
            r["vs_ref"] = {}
            if ref is not None and "per_replica" in ref and "per_replica" in r:
                for k in PAIRED:
                    e = paired(r["per_replica"][k], ref["per_replica"][k])
                    if e is not None:
                        r["vs_ref"][k] = e.as_dict()
        for r in table:
            r.pop("per_replica", None)
        v2 = next((r for r in table if r["label"] == "verlet 2 fs"), None)
        for r in table:
            r["evals_vs_ref"] = r["evals_per_ps"] / ref["evals_per_ps"] if ref else None
            r["wall_vs_ref"] = (r["s_per_ps"] / ref["s_per_ps"]) if ref and r["s_per_ps"] and ref["s_per_ps"] else None
            r["wall_vs_verlet2"] = (r["s_per_ps"] / v2["s_per_ps"]) if v2 and r["s_per_ps"] and v2["s_per_ps"] else None
            r["matches_ref"] = bool(ref and all(k in r["vs_ref"] and agrees(Estimate(**r["vs_ref"][k]), ZERO)
                                                for k in PAIRED))
        models[model] = {"rows": table, "reference": ref["label"] if ref else None,
                         "verlet_trend": _verlet_trend(table, ref), "cheapest_match": _cheapest(table, ref)}
    return {"config": cfg, "models": models}


def _verlet_trend(table, ref) -> dict:
    """Whether Verlet's T_rot - T_trans falls below the 0.5 fs value as the step grows (the published trend:
    rotation cooler than translation at 1-3 fs)."""
    rows = sorted((r for r in table if r["method"] == "verlet" and "dT" in r), key=lambda r: r["step_fs"])
    if not ref or "dT" not in ref or len(rows) < 2:
        return {"reproduced": None, "text": "not enough Verlet rows to test the published trend"}
    pts = []
    for r in rows:
        if r is ref or "dT" not in r["vs_ref"]:
            continue
        pts.append((r["step_fs"], r["vs_ref"]["dT"]["mean"], r["vs_ref"]["dT"]["se"]))
    large = [p for p in pts if p[0] >= 2.0]
    significant = [h for h, d, s in large if d < -2 * s]
    direction = bool(large) and all(d < 0 for _, d, _ in large)
    reproduced = bool(large) and len(significant) == len(large)
    text = "; ".join(f"{h:g} fs: {d:+.2f} ± {s:.2f} K ({d / s:+.1f} SE)" for h, d, s in pts)
    if reproduced:
        verdict = "reproduced"
    elif direction and significant:
        verdict = (f"partly reproduced: rotation cooler at every step >= 2 fs, beyond 2 standard errors at "
                   f"{', '.join(f'{h:g}' for h in significant)} fs only")
    else:
        verdict = "NOT reproduced"
    return {"reproduced": reproduced, "direction": direction, "significant_fs": significant, "points": pts,
            "text": (f"Verlet T_rot - T_trans relative to {ref['label']} (paired by replica): {text}. Published "
                     f"trend (rotation cooler at >= 2 fs, beyond 2 standard errors) {verdict}.")}


def _cheapest(table, ref):
    cands = [r for r in table if r is not ref and r["matches_ref"] and not r["failed"]]
    if not cands:
        return None
    best = min(cands, key=lambda r: (r["evals_per_ps"], r["s_per_ps"] or float("inf")))
    return {"label": best["label"], "evals_vs_ref": best["evals_vs_ref"], "wall_vs_ref": best["wall_vs_ref"],
            "wall_vs_verlet2": best["wall_vs_verlet2"]}


def _pm(d, spec=".2f"):
    if not d:
        return "-"
    return f"{format(d['mean'], spec)} ± {format(d['se'], spec)}"


def format_summary(summary: dict) -> str:
    cfg = summary["config"]
    lines = [f"Equipartition of rigid water: {cfg['n_waters']} waters, PME {cfg['cutoff_nm']} nm, "
             f"{cfg['temperature']:g} K, NVE runs of {cfg['length_ps']:g} ps (after {cfg['settle_ps']:g} ps settling) "
             f"from n replica states; mean ± standard error over replicas; 'minus ref': the difference from the "
             f"reference, replica by replica"]
    for model, res in summary["models"].items():
        lines.append("")
        lines.append(f"{model}:")
        lines.append(f"{'method':22s} {'T_rot-T_trans K':>15s} {'  minus ref K':>14s} {'PE/mol kJ/mol':>17s} "
                     f"{'minus ref':>16s} {'T_trans K':>13s} {'drift kT/ns/dof':>16s} {'tau ps':>6s} {'n':>3s} "
                     f"{'evals/ps':>8s} {'wall/ref':>8s} {'wall/v2':>7s} match")
        for r in res["rows"]:
            if "dT" not in r:
                lines.append(f"{r['label']:24s} {'no finished runs' if not r['failed'] else r['failed'][0]}")
                continue
            wr = f"{r['wall_vs_ref']:.2f}" if r["wall_vs_ref"] else "-"
            w2 = f"{r['wall_vs_verlet2']:.2f}" if r["wall_vs_verlet2"] else "-"
            mark = "ref" if r["label"] == res["reference"] else ("yes" if r["matches_ref"] else "no")
            fail = f"  ({len(r['failed'])} failed: {r['failed'][0]})" if r["failed"] else ""
            vs = r.get("vs_ref", {})
            is_ref = r["label"] == res["reference"]
            lines.append(f"{r['label']:22s} {_pm(r['dT']):>15s} {'' if is_ref else _pm(vs.get('dT')):>14s} "
                         f"{_pm(r['pe'], '.3f'):>17s} {'' if is_ref else _pm(vs.get('pe'), '.3f'):>16s} "
                         f"{_pm(r['T_trans'], '.1f'):>13s} {_pm(r['drift'], '.3f'):>16s} {r['tau_ps']:6.3f} "
                         f"{r['replicas']:3d} {r['evals_per_ps']:8.0f} {wr:>8s} {w2:>7s} {mark}{fail}")
        lines.append(res["verlet_trend"]["text"])
        c = res["cheapest_match"]
        if c:
            cost = f"{c['evals_vs_ref']:.2f}x the force evaluations of {res['reference']}"
            if c["wall_vs_ref"]:
                cost += f", {c['wall_vs_ref']:.2f}x its wall time"
            if c["wall_vs_verlet2"]:
                cost += f", {c['wall_vs_verlet2']:.2f}x the wall time of verlet 2 fs"
            lines.append(f"cheapest configuration matching {res['reference']}: {c['label']} ({cost})")
        else:
            lines.append(f"no configuration other than {res['reference']} matches it within 2 standard errors")
    return "\n".join(lines)
