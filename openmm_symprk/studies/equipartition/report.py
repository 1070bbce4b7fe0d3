"""Summary, verdicts and chart of the equipartition study (numpy; matplotlib for the chart only).

Per model and row (method, step): T_rot - T_trans, T_trans, potential energy per molecule and the NVE energy
drift (kT/ns per degree of freedom), each the mean over replicas with the larger of the within- and
between-replica standard errors (:mod:`openmm_symprk.stats`); the cost in force evaluations per ps and in wall seconds per
simulated ps (measured in turns, relative to the reference row).  A row *matches* the reference (Verlet at
0.5 fs) when its T_rot - T_trans and potential energy per molecule both lie within 2 combined standard errors
of the reference's, compared replica by replica: every row runs from the same replica states, so each replica's
total energy (and with it much of the scatter of T and the potential energy between replicas) is shared, and
the mean of the per-replica differences (``vs_ref``) is far more precise than the difference of the means.
"""
from __future__ import annotations

import numpy as np

from ..core.units import kt_per_ns_per_dof
from ...support import require
from ..core.rows import Row
from .runs import force_evals_per_step
from ...stats import Estimate, agrees, combine, drift, paired, series_stats

ZERO = Estimate(0.0, 0.0, 0, 0.0, 0.0)

__all__ = ["summarise", "format_summary", "chart", "label"]


def label(method: str, step_fs: float) -> str:
    """The row's label (:attr:`~..core.rows.Row.label`), e.g. 'rigid:verlet 2 fs'."""
    return Row(method, step_fs).label


def _estimate_dict(e: Estimate) -> dict:
    return e.as_dict()


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
    """The study's results from its finished runs ({(model, method, step): [(arrays, info)]}) and the optional
    timings ({(model, method, step): wall seconds per simulated ps})."""
    timings = timings or {}
    ref_method, ref_h = cfg["reference"][0], float(cfg["reference"][1])
    models = {}
    for model, rows in cfg["models"].items():
        table = []
        for method, h in rows:
            h = float(h)
            reps = runs.get((model, method, h), [])
            good = [(a, i) for a, i in reps if i.get("status") == "ok"]
            failed = [i["status"] for a, i in reps if i.get("status") != "ok"]
            row = {"method": method, "step_fs": h, "label": label(method, h), "replicas": len(good),
                   "failed": failed, "rigid_body": Row(method, h).is_rigid,
                   "evals_per_ps": force_evals_per_step(method) / (h * 1e-3),
                   "s_per_ps": timings.get((model, method, h))}
            if good and min(len(a["t"]) for a, _ in good) >= 3:
                stats = _row_stats(good, cfg["n_waters"], cfg["temperature"])
                row.update({k: _estimate_dict(v) if isinstance(v, Estimate) else v for k, v in stats.items()})
            table.append(row)
        ref = next((r for r in table if r["method"] == ref_method and r["step_fs"] == ref_h), None)
        for r in table:
            r["vs_ref"] = {}
            if ref is not None and "per_replica" in ref and "per_replica" in r:
                for k in PAIRED:
                    e = paired(r["per_replica"][k], ref["per_replica"][k])
                    if e is not None:
                        r["vs_ref"][k] = _estimate_dict(e)
        for r in table:
            r.pop("per_replica", None)
        v2 = next((r for r in table if r["method"] == "verlet" and r["step_fs"] == 2.0), None)
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


def chart(summary: dict, path: str):
    """Three panels, error bars ± 2 SE: T_rot - T_trans against step size with the reference row as a band;
    T_rot - T_trans minus the reference's (replica by replica) against force evaluations per ps; the potential
    energy per molecule minus the reference's against step size."""
    require("matplotlib", "studies", "openmm_symprk.studies.equipartition.report.chart").use("Agg")
    plt = require("matplotlib.pyplot", "studies", "openmm_symprk.studies.equipartition.report.chart")

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    markers = {"verlet": "o", "omelyan-2": "s", "pefrl": "D"}
    colours = {"spce": "tab:blue", "tip3p": "tab:orange"}
    for model, res in summary["models"].items():
        rows = [r for r in res["rows"] if "dT" in r]
        ref = next((r for r in rows if r["label"] == res["reference"]), None)
        col = colours.get(model, None)
        if ref:
            m, s = ref["dT"]["mean"], ref["dT"]["se"]
            axes[0].axhspan(m - 2 * s, m + 2 * s, color=col, alpha=0.15)
        for method in sorted({r["method"] for r in rows}):
            rs = sorted((r for r in rows if r["method"] == method), key=lambda r: r["step_fs"])
            base = Row(method, 1.0).method
            style = dict(marker=markers.get(base, "^"), color=col, linestyle="--" if method != base else "-",
                         mfc="none" if method != base else col, capsize=3, label=f"{model} {method}")
            axes[0].errorbar([r["step_fs"] for r in rs], [r["dT"]["mean"] for r in rs],
                             [2 * r["dT"]["se"] for r in rs], **style)
            paired = [r for r in rs if r is not ref and "dT" in r.get("vs_ref", {})]
            if paired:
                axes[1].errorbar([r["evals_per_ps"] for r in paired], [r["vs_ref"]["dT"]["mean"] for r in paired],
                                 [2 * r["vs_ref"]["dT"]["se"] for r in paired], **style)
                axes[2].errorbar([r["step_fs"] for r in paired], [r["vs_ref"]["pe"]["mean"] for r in paired],
                                 [2 * r["vs_ref"]["pe"]["se"] for r in paired], **style)
    axes[0].set_xlabel("step (fs)")
    axes[0].set_ylabel("T_rot - T_trans (K)")
    axes[0].set_title("band: the reference ± 2 SE", fontsize=9)
    axes[1].set_xscale("log")
    axes[1].set_xlabel("force evaluations per ps")
    axes[1].set_ylabel("T_rot - T_trans minus the reference's (K)")
    axes[1].set_title("paired by replica", fontsize=9)
    axes[2].set_xlabel("step (fs)")
    axes[2].set_ylabel("PE per molecule minus the reference's (kJ/mol)")
    axes[2].set_title("paired by replica", fontsize=9)
    for ax in axes:
        ax.axhline(0.0, color="grey", lw=0.7)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    ref_label = next((res["reference"] for res in summary["models"].values() if res["reference"]), "the reference")
    fig.suptitle(f"Rigid water: equipartition between rotation and translation, against {ref_label} "
                 f"(error bars ± 2 SE)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
