"""Charts of a sweep (matplotlib, Agg backend, PNG).

* ``bench_work_precision_<scene>.png``: log-log error against cost, one line per method over its step
  sizes: RMS trajectory error at the final time (top) and max |E - E0| per degree of freedom (bottom),
  against force evaluations per ps (left, hardware-independent) and wall seconds per ps (right).  Failed
  runs are marked with a cross: at their error if they finished, on the top edge if they blew up.
* ``bench_stability.png``: largest stable step per method and scene, and the same per force evaluation.
* ``bench_energy_<scene>.png``: E(t) - E0 per degree of freedom at one step size.
* ``bench_speed.png``: wall time per step relative to OpenMM's VerletIntegrator against force
  evaluations per step (the diagonal is "cost = force evaluations").
"""
from __future__ import annotations

import math
import os

import numpy as np

from ...support import require
from ..core.charts import pyplot, save
from .aggregate import usable
from .runs import label

plt = pyplot("openmm_symprk.studies.bench.charts")


def _log_axes(ax):
    ticker = require("matplotlib.ticker", "studies", "openmm_symprk.studies.bench.charts")
    FuncFormatter, LogLocator, NullFormatter = ticker.FuncFormatter, ticker.LogLocator, ticker.NullFormatter

    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):
        lo, hi = (ax.get_xlim() if axis is ax.xaxis else ax.get_ylim())
        if lo > 0 and hi / lo < 30:  # less than ~1.5 decades: label 1, 2, 5 x 10^k
            axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
        axis.set_minor_formatter(NullFormatter())


#: tab10 without its grey (kept for the Langevin row) and olive/cyan moved last
_PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22",
            "#393b79", "#637939", "#ad494a"]


def _styles(methods):
    styles = {}
    i = 0
    for m in methods:
        if m == "openmm-verlet":
            styles[m] = {"color": "black", "ls": "--", "marker": "s"}
        elif m == "openmm-langevin":
            styles[m] = {"color": "0.6", "ls": ":", "marker": "v"}
        else:
            styles[m] = {"color": _PALETTE[i % len(_PALETTE)], "ls": "-", "marker": "o"}
            i += 1
    return styles


def _smoothed_wall(rows):
    """Wall seconds per ps of each run from the method's median wall time per step over its runs (the
    cost of a step does not depend on the step size, so the median over the sweep is the better estimate
    of it than a single short timing)."""
    per_step = sorted(r["wall_per_step"] for r in rows if r.get("wall_per_step"))
    if not per_step:
        return
    med = per_step[len(per_step) // 2]
    for r in rows:
        r["wall_per_ps_chart"] = med / (r["step_fs"] * 1e-3) if r.get("force_evals_per_ps") else None


def _series(rows, xkey, ykey):
    pts = sorted((r for r in rows if r.get(xkey)), key=lambda r: -r["step_fs"])
    good = [(r[xkey], r[ykey]) for r in pts if usable(r) and r.get(ykey) is not None and r[ykey] > 0]
    bad_at = [(r[xkey], r[ykey]) for r in pts if not usable(r) and r.get(ykey) is not None and r[ykey] > 0]
    blown = [r[xkey] for r in pts if not usable(r) and (r.get(ykey) is None or not r[ykey] > 0)]
    return good, bad_at, blown


def work_precision(results, scene, path) -> str | None:
    rows = [r for r in results["runs"] if r["scene"] == scene and r["status"] in ("ok", "failed")]
    if not rows or not any(r.get("traj_error") for r in rows):
        return None
    methods = results["config"]["methods"]
    sty = _styles(methods)
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), sharey="row")
    panels = [(0, "traj_error", "RMS trajectory error at T (nm)"), (1, "energy_error_per_dof", "max |E - E0| per DOF (kJ/mol)")]
    costs = [(0, "force_evals_per_ps", "force evaluations per ps"),
             (1, "wall_per_ps_chart", "wall time per ps (s): median time per step / step")]
    rows = [dict(r) for r in rows]
    for m in methods:
        _smoothed_wall([r for r in rows if r["method"] == m])
    for i, ykey, ylabel in panels:
        for j, xkey, xlabel in costs:
            ax = axes[i, j]
            tops = []
            for m in methods:
                mr = [r for r in rows if r["method"] == m]
                good, bad_at, blown = _series(mr, xkey, ykey)
                s = sty[m]
                if good:
                    ax.plot(*zip(*good), color=s["color"], ls=s["ls"], marker=s["marker"], ms=4, lw=1.3,
                            label=label(m))
                if bad_at:
                    ax.plot(*zip(*bad_at), ls="none", marker="x", ms=8, mew=2, color=s["color"])
                tops += [(x, s["color"]) for x in blown]
            _log_axes(ax)
            ax.grid(True, which="major", alpha=0.3)
            ax.set_xlabel(xlabel)
            if j == 0:
                ax.set_ylabel(ylabel)
            if tops:
                ax.figure.canvas.draw()
                y_top = ax.get_ylim()[1]
                for x, c in tops:
                    ax.plot([x], [y_top], ls="none", marker="x", ms=8, mew=2, color=c, clip_on=False)
                ax.set_ylim(top=y_top)
    info = results["scenes"][scene]
    ref = next((r for r in results["references"] if r["scene"] == scene), None)
    src = "exact solution" if info["exact"] else (f"reference: {ref['method']} at {ref['step_fs']:.3g} fs" if ref else "")
    fig.suptitle(f"{scene}: {info['description']}\nerrors vs {src}; x = failed run (on the top edge: blew up); "
                 f"wall times on {info['platform']}", fontsize=10)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(5, len(labels)), fontsize=9, frameon=False)
    return save(fig, path, rect=(0, 0.06, 1, 0.95))


def stability_chart(results, path) -> str | None:
    rows = [s for s in results["stability"] if s.get("status") == "ok"]
    if not rows:
        return None
    scenes = list(dict.fromkeys(s["scene"] for s in rows))
    methods = [m for m in results["config"]["methods"] if any(s["method"] == m for s in rows)]
    sty = _styles(results["config"]["methods"])
    fig, axes = plt.subplots(len(scenes), 2, figsize=(12, 0.9 + len(scenes) * (0.75 + 0.24 * len(methods))),
                             squeeze=False)
    for si, sc in enumerate(scenes):
        srows = {r["method"]: r for r in rows if r["scene"] == sc}
        for k, (key, xlabel) in enumerate([("h_stable_fs", "largest stable step (fs)"),
                                           ("stable_fs_per_eval", "largest stable step per force evaluation (fs)")]):
            ax = axes[si, k]
            for mi, m in enumerate(methods):
                s = srows.get(m)
                if s is None or not s.get(key):
                    continue
                ax.barh(mi, s[key], height=0.75, color=sty[m]["color"], alpha=0.85)
                text = f" {s[key]:.3g}" + (" (no failure up to the cap)" if s["h_fail_fs"] is None else "")
                ax.text(s[key], mi, text, va="center", fontsize=7)
                cat = s.get("catalogue")
                w = results["scenes"][sc].get("omega_max")
                if cat and w and math.isfinite(cat):
                    ref = cat / w * 1e3 / (1 if key == "h_stable_fs" else s["force_evals_per_step"])
                    ax.plot([ref, ref], [mi - 0.42, mi + 0.42], color="red", lw=1.5)
            ax.set_yticks(range(len(methods)))
            ax.set_yticklabels([label(m) for m in methods], fontsize=8)
            ax.set_ylim(len(methods) - 0.5, -0.5)
            ax.grid(True, axis="x", alpha=0.3)
            ax.margins(x=0.18)
            if si == len(scenes) - 1:
                ax.set_xlabel(xlabel)
            if k == 0:
                crit = next(r["criterion"] for r in rows if r["scene"] == sc)
                ax.set_title(f"{sc} ({crit})", fontsize=9, loc="left")
    fig.suptitle("Largest stable step by bisection.  Failure: blow-up, |E - E0| > 0.1 kT per DOF, or a constraint "
                 "error > 1e-3.\nRed ticks: catalogue stability interval h*omega / omega_max (harmonic toy).",
                 fontsize=9)
    return save(fig, path, rect=(0, 0, 1, 0.97))


def _trace_step(results, scene):
    cfg = results["config"]["scenes"][scene]
    if cfg.get("trace_fs"):
        return cfg["trace_fs"]
    rows = [r for r in results["runs"] if r["scene"] == scene]
    steps = sorted({r["step_fs"] for r in rows}, reverse=True)
    for h in steps:
        at = [r for r in rows if r["step_fs"] == h]
        if sum(usable(r) for r in at) >= 0.75 * len(at):
            return h
    return steps[-1] if steps else None


def energy_chart(results, scene, path) -> str | None:
    h = _trace_step(results, scene)
    rows = [r for r in results["runs"] if r["scene"] == scene and r["step_fs"] == h and r.get("trace_t")]
    if not rows:
        return None
    sty = _styles(results["config"]["methods"])
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    for ax, scale in zip(axes, ("linear", "symlog")):
        for r in sorted(rows, key=lambda r: results["config"]["methods"].index(r["method"])):
            s = sty[r["method"]]
            ax.plot(r["trace_t"], r["trace_de_per_dof"], color=s["color"], ls=s["ls"], lw=1.2,
                    label=f"{label(r['method'])}" + ("" if usable(r) else " (failed)"))
        ax.set_xlabel("time (ps)")
        ax.set_ylabel("(E - E0) per DOF (kJ/mol)")
        ax.grid(True, alpha=0.3)
        if scale == "symlog":
            vals = np.concatenate([np.abs(r["trace_de_per_dof"][1:]) for r in rows if len(r["trace_de_per_dof"]) > 1])
            vals = vals[vals > 0]
            ax.set_yscale("symlog", linthresh=float(np.percentile(vals, 10)) if vals.size else 1e-8)
            ax.set_title("symmetric log scale", fontsize=9)
        else:
            usable_rows = [r for r in rows if usable(r) and r["method"] != "openmm-langevin"]
            if usable_rows:
                lim = max(max(abs(v) for v in r["trace_de_per_dof"]) for r in usable_rows) * 1.1
                if lim > 0:
                    ax.set_ylim(-lim, lim)
            ax.set_title("linear scale (Langevin and failed runs may leave the frame)", fontsize=9)
    axes[1].legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    fig.suptitle(f"{scene}: energy error at {h:g} fs ({results['scenes'][scene]['description']})", fontsize=10)
    return save(fig, path)


def speed_chart(results, path) -> str | None:
    rows = [r for r in results["runs"] if r.get("wall_vs_verlet")]
    if not rows:
        return None
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = results["config"]["methods"]
    sty = _styles(methods)
    fig, ax = plt.subplots(figsize=(10.5, 6))
    markers = ["o", "s", "^", "D", "v", "P", "X"]
    fmax = 1
    for si, sc in enumerate(scenes):
        for m in methods:
            vals = [r["wall_vs_verlet"] for r in rows if r["scene"] == sc and r["method"] == m]
            f = next((r["force_evals_per_step"] for r in rows if r["scene"] == sc and r["method"] == m), None)
            if not vals or not f:
                continue
            fmax = max(fmax, f)
            ax.plot([f * (1 + 0.03 * (si - len(scenes) / 2))], [float(np.median(vals))], ls="none",
                    marker=markers[si % len(markers)], color=sty[m]["color"], ms=7, alpha=0.85)
    xs = np.array([0.8, fmax * 1.3])
    ax.plot(xs, xs, color="0.5", lw=1, ls="--")
    _log_axes(ax)
    ax.set_xlabel("force evaluations per step")
    ax.set_ylabel("wall time per step / OpenMM VerletIntegrator's")
    ax.grid(True, which="both", alpha=0.25)
    Line2D = require("matplotlib.lines", "studies", "openmm_symprk.studies.bench.charts").Line2D

    h1 = [Line2D([], [], ls="none", marker=markers[i % len(markers)], color="0.3", label=sc) for i, sc in enumerate(scenes)]
    h2 = [Line2D([], [], ls="none", marker="o", color=sty[m]["color"], label=label(m)) for m in methods
          if any(r["method"] == m for r in rows)]
    ax.legend(handles=h1 + h2, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title("Cost per step relative to OpenMM's VerletIntegrator (timed in alternation in the same run, median "
                 "over step sizes);\ndashed: cost = force evaluations.  The toys (a few hundred independent particles) "
                 "show CustomIntegrator overhead, not force cost", fontsize=9)
    return save(fig, path)


def production_chart(results, scene, path) -> str | None:
    """Speed against accuracy of a production scene: speed-up over the baseline (same run, machine-load free)
    against the energy drift (kT/ns/DOF, with its standard error) and against the energy fluctuation per DOF."""
    summary = results.get("production", {}).get(scene)
    rows = [r for r in (summary or {}).get("rows", []) if r["speedup"] and r["fluctuation"] is not None]
    if not rows:
        return None
    base = summary["baseline"]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    for ax, key, ylabel in ((axes[0], "drift", "|energy drift| (kT / ns / DOF)"),
                            (axes[1], "fluctuation", "std(E) per DOF (kJ/mol)")):
        for r in rows:
            is_base = base and r["method"] == base["method"] and r["step_fs"] == base["step_fs"]
            colour = "black" if r["method"].startswith("openmm") else ("C2" if r["matches"] else "C3")
            y = abs(r[key])
            err = r["drift_err"] if key == "drift" else None
            ax.errorbar(r["speedup"], max(y, 1e-12), yerr=err, fmt="s" if is_base else "o", color=colour, ms=7 if is_base
                        else 5, capsize=3)
            ax.annotate(f"{label(r['method'])} {r['step_fs']:g} fs", (r["speedup"], max(y, 1e-12)), fontsize=7,
                        xytext=(4, 3), textcoords="offset points")
        if base:
            b = next(r for r in rows if r["method"] == base["method"] and r["step_fs"] == base["step_fs"])
            ax.axhline(abs(b[key]), color="0.6", ls=":", lw=1)
        ax.axvline(1.0, color="0.6", ls=":", lw=1)
        ax.set_yscale("log")
        ax.set_xlabel("speed-up over the baseline (wall time per simulated ps, same run)")
        ax.set_ylabel(ylabel)
    info = results["scenes"][scene]
    fig.suptitle(f"{scene}: {info['description']}\nbaseline (square): {label(base['method'])} at {base['step_fs']:g} fs; "
                 "green: drift and fluctuation no larger than the baseline's; red: larger; black: OpenMM's integrators",
                 fontsize=9)
    return save(fig, path, dpi=120)


def make_charts(results, folder) -> list:
    """Write every chart of ``results`` into ``folder``; returns the paths written."""
    os.makedirs(folder, exist_ok=True)
    paths = []
    for scene, info in results["scenes"].items():
        if info["purpose"] == "production":
            paths.append(production_chart(results, scene, os.path.join(folder, f"bench_production_{scene}.png")))
        if info["purpose"] == "accuracy":
            paths.append(work_precision(results, scene, os.path.join(folder, f"bench_work_precision_{scene}.png")))
            paths.append(energy_chart(results, scene, os.path.join(folder, f"bench_energy_{scene}.png")))
    paths.append(stability_chart(results, os.path.join(folder, "bench_stability.png")))
    paths.append(speed_chart(results, os.path.join(folder, "bench_speed.png")))
    return [p for p in paths if p]
