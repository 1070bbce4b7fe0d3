"""Configurations of the drift studies (plain JSON-ready data, saved in results.json).

    {"study": name, "replicas": R, "length_ps": T, "sample_ps": dt, "decorrelate_ps": t, "temperature": K,
     "seed": s, "threads": n, "constraint_tolerance": tol,
     "rows": [{"name", "scene", "integrator", "step_fs", "platform", "precision", "exact_momentum"}, ...],
     "comparisons": [{"row": name, "ref": name, "kind": "claim" | "cost", "factor": f | None}, ...]}

A "claim" comparison asks whether ``row`` drifts less than ``ref`` (about ``factor`` times less);  a "cost"
comparison whether ``row`` (an option switched on) drifts more than ``ref`` (switched off).  Both are paired by
replica (:mod:`.verdict`).
"""
from __future__ import annotations

__all__ = ["hmr", "exact_momentum", "PRECISION_PLATFORMS", "OPENMM_PUBLISHED"]

#: The platforms of the exact-momentum study: CPU (single-precision forces, double integration) and OpenCL in
#: each precision (PoCL runs it on the CPU here).
PRECISION_PLATFORMS = ("CPU", "OpenCL:single", "OpenCL:mixed", "OpenCL:double")
#: OpenMM's published drift per precision mode, kT/ns/DOF: its user guide, "Testing and Validation of OpenMM",
#: section "Energy Conservation" (ubiquitin in OBC implicit solvent, CUDA, Verlet at 0.5 fs, no constraints, no
#: cutoff; 3.98, 0.217 and 0.00100 kJ/mol/ns).
OPENMM_PUBLISHED = {"single": 4.3e-4, "mixed": 2.3e-5, "double": 1.1e-7}


def _common(quick: bool) -> dict:
    if quick:
        return {"replicas": 3, "length_ps": 0.2, "sample_ps": 0.004, "decorrelate_ps": 0.02, "temperature": 300.0,
                "seed": 101, "threads": 1, "constraint_tolerance": 1e-5}
    return {"replicas": 3, "length_ps": 100.0, "sample_ps": 0.1, "decorrelate_ps": 2.0, "temperature": 300.0,
            "seed": 101, "threads": 2, "constraint_tolerance": 1e-5}


def _row(name, scene, integrator, step_fs, platform="CPU", exact_momentum=False):
    plat, _, precision = platform.partition(":")
    return {"name": name, "scene": scene, "integrator": integrator, "step_fs": float(step_fs), "platform": plat,
            "precision": precision or None, "exact_momentum": bool(exact_momentum)}


def hmr(quick: bool = False, control: bool = True) -> dict:
    """Our ``verlet`` (velocity Verlet, RATTLE) against OpenMM's VerletIntegrator at 4 fs with HMR on solvated villin
    (the production study's finding: about 10x less drift at equal speed), and the same pair at 2 fs without HMR
    as a control.  OpenMM's default constraint tolerance (1e-5), as the production study ran.  ``quick``: villin in
    vacuum (with and without HMR) instead of the solvated box, 0.2 ps per run: seconds, the pipeline only."""
    hmr_scene, plain = ("villin-vacuum-hmr", "villin-vacuum") if quick else ("villin-pme-hmr", "villin-pme")
    rows = [_row("verlet 4 fs HMR", hmr_scene, "verlet", 4.0), _row("OpenMM Verlet 4 fs HMR", hmr_scene,
                                                                     "openmm-verlet", 4.0)]
    comparisons = [{"row": "verlet 4 fs HMR", "ref": "OpenMM Verlet 4 fs HMR", "kind": "claim", "factor": 10.0}]
    if control:
        rows += [_row("verlet 2 fs", plain, "verlet", 2.0), _row("OpenMM Verlet 2 fs", plain, "openmm-verlet", 2.0)]
        comparisons.append({"row": "verlet 2 fs", "ref": "OpenMM Verlet 2 fs", "kind": "claim", "factor": None})
    return dict(_common(quick), study="hmr", mode="quick" if quick else "full", rows=rows, comparisons=comparisons)


def exact_momentum(quick: bool = False, platforms=PRECISION_PLATFORMS) -> dict:
    """Villin in vacuum (amber14, HBonds, no cutoff), ``verlet`` at 2 fs with and without ``exact_momentum`` on each
    platform and precision, paired by replica.  ``quick``: 0.2 ps per run."""
    rows, comparisons = [], []
    for plat in platforms:
        off, on = f"{plat} off", f"{plat} on"
        rows += [_row(off, "villin-vacuum", "verlet", 2.0, plat, False),
                 _row(on, "villin-vacuum", "verlet", 2.0, plat, True)]
        comparisons.append({"row": on, "ref": off, "kind": "cost", "factor": None})
    return dict(_common(quick), study="exact-momentum", mode="quick" if quick else "full", rows=rows,
                comparisons=comparisons)
