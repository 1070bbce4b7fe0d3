"""Summaries of a drift study: per row the drift over replicas (kT/ns/DOF, with its error), per comparison the
paired difference, the ratio of |drifts| and the verdict at 3 SE (:mod:`.verdict`)."""
from __future__ import annotations

import numpy as np

from .presets import OPENMM_PUBLISHED
from .runs import row_of
from .verdict import K_SE, claim_verdict, cost_verdict, row_estimate, run_drift

__all__ = ["summarise", "format_summary"]


def _est(e):
    return None if e is None else e.as_dict()


def summarise(cfg: dict, found: dict, skipped=()) -> dict:
    """``found``: {row name: [(arrays, info) per stored replica]} -> the summary (plain data)."""
    rows, per_row = [], {}
    for row in cfg["rows"]:
        reps = found.get(row["name"], [])
        drifts, failed, walls = {}, [], []
        for arrays, info in reps:
            if info.get("status") != "ok" or len(arrays.get("t", ())) < 3:
                failed.append({"replica": info["replica"], "status": info.get("status"), "why": info.get("failure")})
                continue
            drifts[int(info["replica"])] = run_drift(arrays["t"], arrays["e"], info["n_dof"], cfg["temperature"])
            walls.append(info["wall_per_ps"])
        per_row[row["name"]] = drifts
        est = row_estimate(drifts)
        spec = row_of(row)
        rows.append(dict(row, step_fs=spec.step_fs, replicas_done=len(drifts), failed=failed, drift=_est(est),
                         ensemble=spec.ensemble,
                         exact_momentum=spec.exact_momentum,
                         evals_per_ps=spec.evals_per_ps(),
                         per_replica={str(r): list(v) for r, v in sorted(drifts.items())},
                         wall_s_per_ps=float(np.mean(walls)) if walls else None,
                         skipped=row["name"] in skipped))
    comparisons = []
    for c in cfg["comparisons"]:
        a, b = per_row.get(c["row"], {}), per_row.get(c["ref"], {})
        entry = dict(c)
        if not a or not b:
            entry.update(verdict="not measured", why="a row has no finished replica")
        elif c["kind"] == "claim":
            v = claim_verdict(a, b, c.get("factor"), K_SE)
            entry.update(verdict=v["verdict"], why=v["why"], magnitude=v["magnitude"], ratio=_est(v["ratio"]),
                         difference=_est(v["difference"]))
        else:
            v = claim_verdict(a, b, None, K_SE)
            entry.update(verdict=cost_verdict(a, b, K_SE), magnitude=v["magnitude"], ratio=_est(v["ratio"]),
                         difference=_est(v["difference"]))
        wa = next((r["wall_s_per_ps"] for r in rows if r["name"] == c["row"]), None)
        wb = next((r["wall_s_per_ps"] for r in rows if r["name"] == c["ref"]), None)
        entry["speed_ratio"] = wb / wa if wa and wb else None  # > 1: the row is faster than its reference
        comparisons.append(entry)
    return {"config": cfg, "rows": rows, "comparisons": comparisons, "k_se": K_SE,
            "openmm_published": OPENMM_PUBLISHED if cfg.get("study") == "exact-momentum" else None}


def _pm(d):
    return f"{d['mean']:+.2e} ± {d['se']:.2e}" if d else "-"


def format_summary(s: dict) -> str:
    cfg = s["config"]
    out = [f"symprk drift {cfg['study']} ({cfg['mode']}): {cfg['replicas']} replicas x {cfg['length_ps']:g} ps per row, "
           f"energy every {cfg['sample_ps']:g} ps, constraint tolerance {cfg['constraint_tolerance']:g}, "
           f"{cfg['temperature']:g} K, replicas {cfg['decorrelate_ps']:g} ps of Langevin apart (seeds from "
           f"{cfg['seed']})", "",
           "| row | scene | h (fs) | platform | replicas | drift (kT/ns/DOF) | per replica | s per ps |",
           "|---|---|---|---|---|---|---|---|"]
    for r in s["rows"]:
        plat = r["platform"]
        if r["skipped"]:
            out.append(f"| {r['name']} | {r['scene']} | {r['step_fs']:g} | {plat} | - | platform not available | - | - |")
            continue
        reps = ", ".join(f"{v[0]:+.1e}" for v in r["per_replica"].values()) or "-"
        fails = f" ({len(r['failed'])} failed)" if r["failed"] else ""
        wall = f"{r['wall_s_per_ps']:.3g}" if r["wall_s_per_ps"] else "-"
        out.append(f"| {r['name']} | {r['scene']} | {r['step_fs']:g} | {plat} | {r['replicas_done']}{fails} | "
                   f"{_pm(r['drift'])} | {reps} | {wall} |")
    out += ["", "| row | against | paired difference | abs ratio | speed ratio | verdict |", "|---|---|---|---|---|---|"]
    for c in s["comparisons"]:
        ratio = f"{c['ratio']['mean']:.2f} ± {c['ratio']['se']:.2f}" if c.get("ratio") else "-"
        speed = f"{c['speed_ratio']:.2f}" if c.get("speed_ratio") else "-"
        claim = " (claim: less" + (f", about {c['factor']:g}x" if c.get("factor") else "") + ")" \
            if c["kind"] == "claim" else " (does it cost?)"
        out.append(f"| {c['row']} | {c['ref']} | {_pm(c.get('difference'))} | {ratio} | {speed} | "
                   f"**{c['verdict']}**{claim} |")
    if cfg.get("study") == "nvt":
        out += ["", format_nvt(s)]
    if s.get("openmm_published"):
        pub = ", ".join(f"{k} {v:.1e}" for k, v in s["openmm_published"].items())
        out += ["", f"OpenMM's published drift (kT/ns/DOF; user guide, Testing and Validation, Energy Conservation: "
                    f"ubiquitin, OBC, Verlet 0.5 fs, no constraints): {pub}"]
    out += ["", f"abs ratio: |drift of row| / |drift of reference| (first-order error; '-' where the reference's "
                f"drift is not resolved from zero at {s['k_se']:g} SE); speed ratio: reference's wall time per ps / "
                f"the row's (> 1: the row is faster; same process, in sequence)."]
    return "\n".join(out)


def format_nvt(s: dict) -> str:
    """The NVT study's table: per pair the NVT drift (total + heat-bath energy), the NVE drift of the same method and
    step, and their difference paired by replica."""
    rows = {r["name"]: r for r in s["rows"]}
    lines = [f"{'NVT row':18s} {'f/ps':>6s} {'NVT drift':>20s} {'NVE drift (same step)':>22s} {'NVT - NVE (paired)':>20s}"]
    for c in s["comparisons"]:
        nvt, nve = rows[c["row"]], rows[c["ref"]]
        lines.append(f"{c['row']:18s} {nvt['evals_per_ps']:6.0f} {_pm(nvt['drift']):>20s} {_pm(nve['drift']):>22s} "
                     f"{_pm(c.get('difference')):>20s}")
    lines.append("kT/ns/DOF; NVT: total + heat-bath energy; the NVE row of NoseHoover is OpenMM's VerletIntegrator")
    return "\n".join(lines)
