"""The fidelity study's frontier: the cost of every integrator family at equal accuracy, with intervals.

A family is the rows of one integrator and thermostat that differ only in the step (and, on the common event grid,
in the thermostat interval that keeps the events at the same simulated times).  Per ensemble, observable and family
the paired biases against the ensemble's reference (replica by replica) are fitted as c h^p (p: :func:`bias_order`,
:mod:`openmm_symprk.stats.frontier`: weights 1/SE^2, replicas resampled jointly across families), and at each
tolerance level (:data:`.presets.TOLERANCES`, declared before the runs) each family gets its equal-accuracy step
(the smallest over the observables, at most the largest step it ran), its cost per simulated ps (force evaluations,
and wall seconds from the rows' timings), the step at which every observable stays inside its tolerance with 95 %
confidence, and the package's cheapest family is compared with OpenMM's cheapest: a ratio of costs with a 95 %
bootstrap interval.  Relative tolerances (D, tau2, the g(r) peak height) are taken of the reference's mean.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ...stats.frontier import Family, bootstrap, compare, fits, frontier, replicas_for_interval
from ..core.charts import pyplot, save
from ..core.rows import OPENMM_KINDS
from .rowspec import to_row

__all__ = ["family_of", "bias_order", "free_observables", "families", "frontier_summary", "format_frontier",
           "frontier_chart", "N_BOOT", "DYNAMICAL"]

#: A ratio's interval is decisive within this fraction of its value (the NVT answer's target).
WITHIN = 0.25

#: Bootstrap resamples of the replicas.
N_BOOT = 2000


def family_of(label: str, temperature: float = 300.0) -> str:
    """The family of a row: its label with the step (and the thermostat interval that follows it) left out; a row
    whose thermostat's target is not the study's ``temperature`` (lowered by the modified energy, a different
    target at each step) is of the family "... T lowered"."""
    row = to_row(label)
    lowered = row.ensemble == "NVT" and row.temperature != temperature
    name = dataclasses.replace(row, step_fs=1.0, every=1, temperature=temperature if lowered else row.temperature)
    return name.label.replace(" 1 fs", "", 1) + (" T lowered" if lowered else "")


def bias_order(label: str) -> int:
    """The power p of the family's bias c h^p: the method's order under constraints (RATTLE keeps a composition's
    fourth order, not a fourth-order splitting's: the resolved method's ``constrained_order``) for
    the package's NVE rows; 2 for OpenMM's integrators and for every thermostat row (the thermostat's splitting is
    second order whatever the method)."""
    row = to_row(label)
    if not row.is_ours or row.ensemble != "NVE":
        return 2
    return int(row.resolved(constraints=True).constrained_order or 2)


#: The observables of the dynamics (diffusion, reorientation, the angular-velocity correlation): a thermostat that
#: acts on each particle (OpenMM's Langevin integrators) changes them at any step, which the paired bias against a
#: velocity-rescaling reference keeps as an h-independent part.
DYNAMICAL = ("D", "tau2_dip", "w_zero", "w_min")


def shared_part(label: str) -> tuple | None:
    """(group, strength) of a family's h-independent part shared with others of one cause: OpenMM's Langevin
    integrators at their friction (per ps; linear response: the friction's effect on the dynamics is proportional to
    it, so the 1/ps family's well-resolved effect fixes the 0.1/ps family's); None otherwise."""
    row = to_row(label)
    if row.thermostat == "langevin" and row.friction_per_ps:
        return row.who, float(row.friction_per_ps)
    return None


def free_observables(label: str, reference: str) -> tuple:
    """The observables whose bias against ``reference`` has an h-independent part (fitted as a + c h^p): the
    dynamical ones (:data:`DYNAMICAL`) of a row whose thermostat is not the reference's kind (OpenMM's Langevin, Nose-
    Hoover or DPD against the package's velocity rescaling); none for rows of the reference's own kind, whose bias
    vanishes with h (their thermostat and collision time are the reference's)."""
    row, ref = to_row(label), to_row(reference)
    if row.ensemble == "NVE" or (row.is_ours and row.tau_ps == ref.tau_ps):
        return ()
    return DYNAMICAL


def _absolute(tolerances: dict, ref_means: dict) -> dict:
    """Tolerances in the observables' own units: a key ending in ``_rel`` is a fraction of the reference's mean."""
    out = {}
    for key, eps in tolerances.items():
        if key.endswith("_rel"):
            obs = key[:-len("_rel")]
            if ref_means.get(obs) is None:
                continue
            out[obs] = float(eps) * abs(ref_means[obs])
        else:
            out[key] = float(eps)
    return out


def families(rows, per: dict, reference: str, ensemble: str, observables) -> list:
    """The families of ``ensemble`` among ``rows`` (labels) with their paired biases against ``reference``
    (``per``: {label: {observable: {replica: (value, se)}}}), each row's replicas as columns (NaN where missing)."""
    ref = per.get(reference)
    if ref is None:
        return []
    groups: dict = {}
    for lab in rows:
        r = to_row(lab)
        if lab == reference or r.ensemble != ensemble or lab not in per:
            continue
        groups.setdefault(family_of(lab), []).append(lab)
    # the replicas of this ensemble's rows (another ensemble's rows run at more replicas leave its resampling as is)
    n = 1 + max((rep for lab in [lab for labels in groups.values() for lab in labels] + [reference] if lab in per
                 for k in observables for rep in per[lab].get(k, {})), default=0)
    out = []
    for name, labels in groups.items():
        labels = sorted(labels, key=lambda lab: to_row(lab).step_fs)
        bias = {}
        for k in observables:
            b = np.full((len(labels), n), np.nan)
            for i, lab in enumerate(labels):
                for rep, (value, _) in per[lab].get(k, {}).items():
                    if rep in ref.get(k, {}):
                        b[i, rep] = value - ref[k][rep][0]
            bias[k] = b
        rows_ = [to_row(lab) for lab in labels]
        out.append((Family(name, tuple(r.step_fs for r in rows_), bias, order=bias_order(labels[0]),
                           cost_per_step=float(np.mean([r.evals_per_step() for r in rows_])),
                           free=tuple(k for k in free_observables(labels[0], reference) if k in observables),
                           shared=shared_part(labels[0])),
                    labels))
    return out


def frontier_summary(rows, per: dict, references: dict, tolerances: dict, timings: dict | None = None,
                     n_boot: int = N_BOOT, run_seconds: dict | None = None) -> dict:
    """{ensemble: {"families": [...], "levels": {level: {...}}}} (see the module docstring).  ``run_seconds``:
    {label: mean wall seconds of one of its runs}, for what a ratio's interval of :data:`WITHIN` would cost."""
    timings, run_seconds = timings or {}, run_seconds or {}
    out = {}
    for ensemble, reference in references.items():
        keys = sorted({k[:-len("_rel")] if k.endswith("_rel") else k for t in tolerances.values() for k in t})
        # a family on the frontier has two steps or more (one step fixes c but not that the bias goes as h^2), each
        # with two replicas or more of every observable
        found = families(rows, per, reference, ensemble, keys)
        fams = [(f, labs) for f, labs in found if len(set(f.steps)) >= (3 if f.free else 2)
                and all(np.isfinite(f.bias[k]).sum(axis=1).min() >= 2 for k in keys)]
        if not fams:
            continue
        ref_means = {k: float(np.mean([v for v, _ in per[reference][k].values()])) if per[reference].get(k) else None
                     for k in keys}
        boot = bootstrap([f for f, _ in fams], keys, n_boot=n_boot)
        counts = {lab: c for f, labs in fams for lab, c in zip(labs, _replicas(f))}
        counts[reference] = max(counts.values())
        wall = {f.name: _wall_per_step(labs, timings) for f, labs in fams}
        entry = {"reference": reference, "families": [], "levels": {},
                 "left_out": sorted(f.name for f, _ in found if all(f.name != g.name for g, _ in fams))}
        point = {k: fits([f for f, _ in fams], k) for k in keys}  # {observable: {family: (a, c)}}
        for f, labs in fams:
            fitted = {k: point[k][f.name] for k in keys}
            entry["families"].append({
                "family": f.name, "rows": labs, "steps_fs": list(f.steps), "evals_per_step": f.cost_per_step,
                "s_per_step": wall[f.name], "openmm": to_row(labs[0]).who in OPENMM_KINDS,
                "c": {k: fitted[k][1] for k in keys},
                "c_interval": {k: [float(np.nanquantile(boot[f.name][k][:, 1], q)) for q in (0.025, 0.975)]
                               for k in keys}})
            if f.free:  # the h-independent part of the bias, where the family has one
                entry["families"][-1]["a"] = {k: fitted[k][0] for k in f.free}
                if f.shared is not None:
                    entry["families"][-1]["shared"] = list(f.shared)
                entry["families"][-1]["a_interval"] = {
                    k: [float(np.nanquantile(boot[f.name][k][:, 0], q)) for q in (0.025, 0.975)] for k in f.free}
        for level, tol in tolerances.items():
            eps = _absolute(tol, ref_means)
            points = {f.name: frontier(f, eps, boot[f.name], point={k: point[k][f.name] for k in eps})
                      for f, _ in fams}
            level_entry = {"tolerances": eps, "families": {}}
            for f, _ in fams:
                p = points[f.name]
                level_entry["families"][f.name] = {
                    "step_fs": p.step, "evals_per_ps": 1000.0 * p.cost, "safe_step_fs": p.safe_step,
                    "limited_by": p.limited_by,
                    "s_per_ps": 1000.0 * _per_step(wall[f.name], p.step) if wall[f.name] else None}
            for unit, cost_of in (("evals", lambda name: next(f.cost_per_step for f, _ in fams if f.name == name)),
                                  ("wall", lambda name: wall[name])):
                ours = [f.name for f, labs in fams if to_row(labs[0]).who not in OPENMM_KINDS and cost_of(f.name)]
                theirs = [f.name for f, labs in fams if to_row(labs[0]).who in OPENMM_KINDS and cost_of(f.name)]
                if not ours or not theirs:
                    continue
                best_ours = min(ours, key=lambda n: _per_step(cost_of(n), points[n].step))
                best_theirs = min(theirs, key=lambda n: _per_step(cost_of(n), points[n].step))
                a = dataclasses.replace(points[best_ours], cost=_per_step(cost_of(best_ours), points[best_ours].step))
                b = dataclasses.replace(points[best_theirs],
                                        cost=_per_step(cost_of(best_theirs), points[best_theirs].step))
                ratio, low, high = compare(a, b, cost_of(best_ours), cost_of(best_theirs))
                # the replicas the two families' rows have (the median: rows may have run at different counts)
                n = int(np.median([counts[lab] for f, labs in fams if f.name in (best_ours, best_theirs)
                                   for lab in labs]))
                need = replicas_for_interval(n, ratio, low, high, WITHIN)
                # the reference, the two families and those sharing a fitted part with them (a shared group's rows
                # all fix its kappa), each brought from its own count to the replicas needed
                groups = {f.shared[0] for f, _ in fams if f.name in (best_ours, best_theirs) and f.shared}
                labels = [reference] + [lab for f, labs in fams if f.name in (best_ours, best_theirs)
                                        or (f.shared and f.shared[0] in groups) for lab in labs]
                more = sum(max(0.0, need - counts[lab]) * run_seconds.get(lab, np.nan) for lab in labels) / 3600.0
                level_entry[f"ratio_{unit}"] = {"ours": best_ours, "theirs": best_theirs, "ratio": ratio,
                                                "low": low, "high": high, "replicas": n, "replicas_needed": need,
                                                "core_hours_more": more if np.isfinite(more) else None}
            entry["levels"][level] = level_entry
        out[ensemble] = entry
    return out


def _replicas(family: Family) -> list:
    """The replicas each row of ``family`` has (of the observable it has fewest of)."""
    return [int(n) for n in np.min([np.isfinite(np.asarray(b, dtype=float)).sum(axis=1)
                                    for b in family.bias.values()], axis=0)]


def _per_step(cost: float, step: float) -> float:
    """A cost per step over the step: the cost per unit of simulated time, infinite at a step of 0 (a family that
    meets the tolerance at no step)."""
    return cost / step if step > 0 else float("inf")


def _wall_per_step(labels, timings: dict, temperature: float = 300.0) -> float | None:
    """Wall seconds per step of a family: its rows' seconds per simulated ps times their steps, averaged.  A row whose
    thermostat's target is lowered runs the same step as its twin at the study's ``temperature`` (the target is one
    number of the event) and takes the twin's timing where it has none of its own."""
    def timed(lab):
        twin = dataclasses.replace(to_row(lab), temperature=temperature).label
        return timings.get(lab) or timings.get(twin)

    per_step = [timed(lab) * to_row(lab).step_fs / 1000.0 for lab in labels if timed(lab)]
    return float(np.mean(per_step)) if per_step else None


def format_frontier(summary: dict) -> str:
    """The frontier as text: per ensemble, the fitted c of each family, then per tolerance level each family's
    equal-accuracy step, what limits it, its cost, its 95 %-safe step, and the package's cheapest family against
    OpenMM's with the 95 % interval."""
    lines = []
    for ensemble, entry in summary.items():
        lines.append(f"{ensemble}: biases against {entry['reference']} fitted as c h^p (h in fs; p the order kept, "
                     f"2 with a thermostat), 95 % intervals from {N_BOOT} resamples of the replicas")
        keys = sorted(entry["families"][0]["c"]) if entry["families"] else []
        lines.append("  " + "family".ljust(34) + "steps fs".ljust(16) + "".join(f"c[{k}]".rjust(24) for k in keys))
        for fam in entry["families"]:
            cs = "".join(f"{fam['c'][k]:+.2e} [{fam['c_interval'][k][0]:+.1e},{fam['c_interval'][k][1]:+.1e}]"
                         .rjust(24) for k in keys)
            lines.append("  " + fam["family"][:33].ljust(34) + ",".join(f"{h:g}" for h in fam["steps_fs"]).ljust(16)
                         + cs)
            if fam.get("a"):
                why = (f"a = kappa x {fam['shared'][1]:g}, kappa fitted over the {fam['shared'][0]} families"
                       if fam.get("shared") else "fitted")
                lines.append(f"    and an h-independent part a (its thermostat is not the reference's; {why}): " + ", ".join(
                    f"a[{k}] {fam['a'][k]:+.3g} [{fam['a_interval'][k][0]:+.2g},{fam['a_interval'][k][1]:+.2g}]"
                    for k in fam["a"]))
        if entry.get("left_out"):
            lines.append(f"  not on the frontier (fewer than two steps, or fewer than two replicas of an observable): "
                         f"{'; '.join(entry['left_out'])}")
        for level, le in entry["levels"].items():
            tol = ", ".join(f"{k} {v:.3g}" for k, v in le["tolerances"].items())
            lines.append(f"  tolerance '{level}': {tol}")
            lines.append("    " + "family".ljust(34) + "h_eps fs".rjust(9) + "limited by".rjust(14) + "f/ps".rjust(8)
                         + "s/ps".rjust(8) + "95%-safe h".rjust(12))
            for name, fe in le["families"].items():
                wall = f"{fe['s_per_ps']:.2f}" if fe["s_per_ps"] else "-"
                lines.append("    " + name[:33].ljust(34) + f"{fe['step_fs']:9.2f}" + fe["limited_by"].rjust(14)
                             + f"{fe['evals_per_ps']:8.0f}" + wall.rjust(8) + f"{fe['safe_step_fs']:12.2f}")
            for unit in ("evals", "wall"):
                r = le.get(f"ratio_{unit}")
                if r:
                    what = "force evaluations" if unit == "evals" else "wall time"
                    lines.append(f"    {r['ours']} against {r['theirs']}: {r['ratio']:.2f}x less {what} per "
                                 f"simulated ps (95 % interval {r['low']:.2f}-{r['high']:.2f})")
                    if unit == "evals" and r.get("replicas_needed") is not None:
                        lines.append("      " + _interval_need(r))
        lines.append("")
    return "\n".join(lines).rstrip()


def _interval_need(r: dict) -> str:
    """What an interval within :data:`WITHIN` of the ratio would take, in words."""
    goal = f"an interval within +-{100 * WITHIN:g} % of the ratio"
    if r["replicas_needed"] <= r["replicas"]:
        return f"{goal}: reached at {r['replicas']} replicas"
    if not np.isfinite(r["replicas_needed"]):
        return f"{goal}: no replica count gives it (an end of the interval is infinite)"
    cost = (f", about {r['core_hours_more']:.1f} more core-hours at the measured wall time per run"
            if r.get("core_hours_more") is not None else "")
    return (f"{goal}: about {r['replicas_needed']:.0f} replicas of the two families' rows, the reference and the "
            f"families that share a fitted part with them "
            f"(now {r['replicas']}; half-widths shrink as 1/sqrt(n)){cost}")


def frontier_chart(summary: dict, path: str):
    """The frontier as a work-precision chart: per ensemble (a row of panels) and observable, each row's paired bias
    (± 2 SE) against its force evaluations per simulated ps, coloured by family, with the family's fit c h^2 drawn
    as the bias it predicts at each cost (h = evaluations per step / cost), and the standard tolerance as a band;
    a last panel per ensemble: the ratio of the package's cheapest family to OpenMM's per tolerance level, with its
    95 % interval (1: equal cost)."""
    plt = pyplot("the frontier chart")
    fr = summary.get("frontier") or {}
    ensembles = list(fr)
    if not ensembles:
        return
    keys = sorted(fr[ensembles[0]]["families"][0]["c"])
    fig, axes = plt.subplots(len(ensembles), len(keys) + 1, figsize=(3.2 * (len(keys) + 1), 3.3 * len(ensembles)),
                             squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for row_axes, ens in zip(axes, ensembles):
        entry = fr[ens]
        fams = entry["families"]
        colour = {f["family"]: colours[i % len(colours)] for i, f in enumerate(fams)}
        standard = entry["levels"].get("standard", next(iter(entry["levels"].values())))["tolerances"]
        for ax, k in zip(row_axes, keys):
            for f in fams:
                for lab in f["rows"]:
                    e = next((r for r in summary["rows"] if r["label"] == lab), None)
                    d = (e or {}).get("vs_ref", {}).get(k)
                    if d:
                        ax.errorbar([e["evals_per_ps"]], [d["mean"]], [2 * d["se"]], marker="o", ms=4, capsize=2,
                                    color=colour[f["family"]], linestyle="none")
                cost = np.geomspace(min(f["steps_fs"]) * 0.8, max(f["steps_fs"]) * 1.2, 30)  # steps (fs)
                ax.plot(1000.0 * f["evals_per_step"] / cost, f["c"][k] * cost ** 2, color=colour[f["family"]],
                        lw=1, label=f["family"])
            if k in standard:
                ax.axhspan(-standard[k], standard[k], color="grey", alpha=0.15, lw=0)
            ax.axhline(0.0, color="grey", lw=0.6)
            ax.set_xscale("log")
            ax.set_title(f"{ens}: {k}", fontsize=9)
            ax.set_xlabel("force evaluations per ps", fontsize=8)
            ax.tick_params(labelsize=7)
        ax = row_axes[-1]
        levels = list(entry["levels"])
        for i, level in enumerate(levels):
            r = entry["levels"][level].get("ratio_evals")
            if r:
                ax.errorbar([i], [r["ratio"]], [[r["ratio"] - r["low"]], [r["high"] - r["ratio"]]], marker="s",
                            capsize=4, color="black")
        ax.axhline(1.0, color="grey", lw=0.6)
        ax.set_xticks(range(len(levels)), levels, fontsize=8)
        ax.set_title(f"{ens}: OpenMM's cost / the package's (95 %)", fontsize=9)
        row_axes[0].legend(fontsize=6)
    fig.suptitle("Frontier: paired bias against cost, fits c h^2 (lines), the standard tolerance (band)", fontsize=10)
    save(fig, path, dpi=80)
