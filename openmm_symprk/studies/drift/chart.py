"""The NVT study's work-precision chart: the effective-energy drift (kT/ns/DOF, signed, one standard error) against force
evaluations per ps, NVT rows filled, the NVE drift of the same method and step hollow beside it (matplotlib, Agg
backend, PNG).  The y axis is symmetric-logarithmic: linear within +-0.01 kT/ns/DOF, so a drift consistent with
zero shows as such and the sign is kept."""
from __future__ import annotations

from ...support import require
from ..core.charts import pyplot, save


def work_precision(summary: dict, path: str) -> str:
    """Draw the chart of a summary of the NVT study (:func:`.report.summarise`) into ``path``; returns ``path``."""
    plt = pyplot("openmm_symprk.studies.drift.chart")
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    by = {r["name"]: r for r in summary["rows"]}
    pairs = [{"nvt_row": c["row"], "evals_per_ps": by[c["row"]]["evals_per_ps"], "nvt": by[c["row"]]["drift"],
              "nve": by[c["ref"]]["drift"]} for c in summary["comparisons"]]
    xs = [r["evals_per_ps"] for r in pairs]
    for i, r in enumerate(pairs):
        c = colours[i % len(colours)]
        x = xs[i]
        same = [j for j, y in enumerate(xs) if y == x]  # rows of one cost side by side
        x *= 1.1 ** (same.index(i) - (len(same) - 1) / 2)
        for key, fill, dx in (("nvt", c, 0.98), ("nve", "white", 1.02)):
            d = r[key]
            if d:
                ax.errorbar([x * dx], [d["mean"]], yerr=[d["se"]], fmt="o", mfc=fill, mec=c, ecolor=c, capsize=3,
                            label=r["nvt_row"] if key == "nvt" else None)
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=0.01)
    ticker = require("matplotlib.ticker", "studies", "openmm_symprk.studies.drift.chart")
    ax.xaxis.set_major_formatter(ticker.ScalarFormatter())
    ax.xaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_xticks(sorted(set(xs)))
    ax.set_xlim(min(xs) / 1.4, max(xs) * 1.4)
    ax.set_xlabel("force evaluations per ps (cost)")
    ax.set_ylabel("drift of the (effective) energy, kT/ns/DOF")
    cfg = summary["config"]
    ax.set_title(f"NVT (filled: total + heat-bath energy) and NVE (hollow), {cfg['replicas']} x "
                 f"{cfg['length_ps']:g} ps\n{cfg['rows'][0]['scene']}, {cfg['rows'][0]['platform']}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save(fig, path)
