"""The equipartition study's chart (matplotlib); its table is :mod:`openmm_symprk.studies.core.temperatures`,
which the fidelity study's temperature view shares."""
from __future__ import annotations

from ..core.charts import pyplot, save
from ..core.rows import Row
from ..core.temperatures import format_summary, summarise

__all__ = ["summarise", "format_summary", "chart"]


def chart(summary: dict, path: str):
    """Three panels, error bars ± 2 SE: T_rot - T_trans against step size with the reference row as a band;
    T_rot - T_trans minus the reference's (replica by replica) against force evaluations per ps; the potential
    energy per molecule minus the reference's against step size."""
    plt = pyplot("openmm_symprk.studies.equipartition.report.chart")

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
    save(fig, path)
