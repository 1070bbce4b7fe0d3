"""Summary, verdicts and chart of the equipartition study (numpy; matplotlib for the chart only).

Per model and row (method, step): T_rot - T_trans, T_trans, potential energy per molecule and the NVE energy
drift (kT/ns per degree of freedom), each the mean over replicas with the larger of the within- and
between-replica standard errors (:mod:`.stats`); the cost in force evaluations per ps and in wall seconds per
simulated ps (measured in turns, relative to the reference row).  A row *matches* the reference (Verlet at
0.5 fs) when its T_rot - T_trans and potential energy per molecule both lie within 2 combined standard errors
of the reference's.
"""
from __future__ import annotations

import numpy as np

from ...physics.temperature import R_KJ
from .presets import RIGID_PREFIX
from .runs import force_evals_per_step
from .stats import Estimate, agrees, combine, drift, series_stats

__all__ = ["summarise", "format_summary", "chart", "label"]


def label(method: str, step_fs: float) -> str:
    return f"{method} {step_fs:g} fs"


def _estimate_dict(e: Estimate) -> dict:
    return {"mean": e.mean, "se": e.se, "replicas": e.replicas, "se_within": e.se_within, "se_between": e.se_between}


def _row_stats(reps, n_waters, temperature):
    per = {"dT": [], "T_trans": [], "T_rot": [], "pe": [], "drift": []}
    taus = []
    dof = 6 * n_waters - 3
    kT = R_KJ * temperature
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
        per["drift"].append((slope * 1000.0 / (kT * dof), se * 1000.0 / (kT * dof)))
    out = {}
    for k, vals in per.items():
        if k == "drift":
            out[k] = combine([a for a, _ in vals], [b for _, b in vals])
        else:
            out[k] = combine([s.mean for s in vals], [s.se for s in vals])
    out["tau_ps"] = float(np.mean(taus))
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
                   "failed": failed, "rigid_body": method.startswith(RIGID_PREFIX),
                   "evals_per_ps": force_evals_per_step(method) / (h * 1e-3),
                   "s_per_ps": timings.get((model, method, h))}
            if good and min(len(a["t"]) for a, _ in good) >= 3:
                stats = _row_stats(good, cfg["n_waters"], cfg["temperature"])
                row.update({k: _estimate_dict(v) if isinstance(v, Estimate) else v for k, v in stats.items()})
            table.append(row)
        ref = next((r for r in table if r["method"] == ref_method and r["step_fs"] == ref_h), None)
        v2 = next((r for r in table if r["method"] == "verlet" and r["step_fs"] == 2.0), None)
        for r in table:
            r["evals_vs_ref"] = r["evals_per_ps"] / ref["evals_per_ps"] if ref else None
            r["wall_vs_ref"] = (r["s_per_ps"] / ref["s_per_ps"]) if ref and r["s_per_ps"] and ref["s_per_ps"] else None
            r["wall_vs_verlet2"] = (r["s_per_ps"] / v2["s_per_ps"]) if v2 and r["s_per_ps"] and v2["s_per_ps"] else None
            r["matches_ref"] = bool(ref and "dT" in ref and "dT" in r and
                                    agrees(Estimate(**r["dT"]), Estimate(**ref["dT"])) and
                                    agrees(Estimate(**r["pe"]), Estimate(**ref["pe"])))
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
        if r is ref:
            continue
        diff = r["dT"]["mean"] - ref["dT"]["mean"]
        se = float(np.hypot(r["dT"]["se"], ref["dT"]["se"]))
        pts.append((r["step_fs"], diff, se))
    significant = [(h, d, s) for h, d, s in pts if h >= 2.0 and d < -2 * s]
    large = [p for p in pts if p[0] >= 2.0]
    reproduced = bool(large) and len(significant) == len(large)
    text = "; ".join(f"{h:g} fs: {d:+.2f} ± {s:.2f} K" for h, d, s in pts)
    return {"reproduced": reproduced, "points": pts,
            "text": (f"Verlet T_rot - T_trans relative to {ref['label']}: {text}. Published trend (rotation cooler "
                     f"at >= 2 fs, beyond 2 standard errors) {'reproduced' if reproduced else 'NOT reproduced'}.")}


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
             f"from n replica states; mean ± standard error over replicas"]
    for model, res in summary["models"].items():
        lines.append("")
        lines.append(f"{model}:")
        lines.append(f"{'method':24s} {'T_rot-T_trans K':>16s} {'T_trans K':>15s} {'PE/mol kJ/mol':>17s} "
                     f"{'drift kT/ns/dof':>17s} {'tau ps':>7s} {'n':>3s} {'evals/ps':>9s} {'wall/ref':>8s} "
                     f"{'wall/v2':>8s} match")
        for r in res["rows"]:
            if "dT" not in r:
                lines.append(f"{r['label']:24s} {'no finished runs' if not r['failed'] else r['failed'][0]}")
                continue
            wr = f"{r['wall_vs_ref']:.2f}" if r["wall_vs_ref"] else "-"
            w2 = f"{r['wall_vs_verlet2']:.2f}" if r["wall_vs_verlet2"] else "-"
            mark = "ref" if r["label"] == res["reference"] else ("yes" if r["matches_ref"] else "no")
            fail = f"  ({len(r['failed'])} failed: {r['failed'][0]})" if r["failed"] else ""
            lines.append(f"{r['label']:24s} {_pm(r['dT']):>16s} {_pm(r['T_trans'], '.1f'):>15s} "
                         f"{_pm(r['pe'], '.3f'):>17s} {_pm(r['drift'], '.3f'):>17s} {r['tau_ps']:7.3f} "
                         f"{r['replicas']:3d} {r['evals_per_ps']:9.0f} {wr:>8s} {w2:>8s} {mark}{fail}")
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
    """Three panels: T_rot - T_trans against step size and against force evaluations per ps, and the potential
    energy per molecule against step size, with the reference row as a band (mean ± 2 SE)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    markers = {"verlet": "o", "omelyan-2": "s", "pefrl": "D"}
    colours = {"spce": "tab:blue", "tip3p": "tab:orange"}
    for model, res in summary["models"].items():
        rows = [r for r in res["rows"] if "dT" in r]
        ref = next((r for r in rows if r["label"] == res["reference"]), None)
        col = colours.get(model, None)
        if ref:
            for ax, key in ((axes[0], "dT"), (axes[1], "dT"), (axes[2], "pe")):
                m, s = ref[key]["mean"], ref[key]["se"]
                ax.axhspan(m - 2 * s, m + 2 * s, color=col, alpha=0.15)
        methods = sorted({r["method"] for r in rows})
        for method in methods:
            rs = sorted((r for r in rows if r["method"] == method), key=lambda r: r["step_fs"])
            base = method[len(RIGID_PREFIX):] if method.startswith(RIGID_PREFIX) else method
            style = dict(marker=markers.get(base, "^"), color=col, linestyle="--" if method != base else "-",
                         mfc="none" if method != base else col, capsize=3, label=f"{model} {method}")
            h = [r["step_fs"] for r in rs]
            axes[0].errorbar(h, [r["dT"]["mean"] for r in rs], [2 * r["dT"]["se"] for r in rs], **style)
            axes[1].errorbar([r["evals_per_ps"] for r in rs], [r["dT"]["mean"] for r in rs],
                             [2 * r["dT"]["se"] for r in rs], **style)
            axes[2].errorbar(h, [r["pe"]["mean"] for r in rs], [2 * r["pe"]["se"] for r in rs], **style)
    axes[0].set_xlabel("step (fs)")
    axes[0].set_ylabel("T_rot - T_trans (K), ± 2 SE")
    axes[1].set_xscale("log")
    axes[1].set_xlabel("force evaluations per ps")
    axes[1].set_ylabel("T_rot - T_trans (K)")
    axes[2].set_xlabel("step (fs)")
    axes[2].set_ylabel("potential energy per molecule (kJ/mol)")
    for ax in axes:
        ax.axhline(0.0, color="grey", lw=0.5) if ax is not axes[2] else None
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Rigid water: equipartition between rotation and translation (band: Verlet 0.5 fs ± 2 SE)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
