"""Configurations of the drift studies (plain JSON-ready data, saved in results.json).

    {"study": name, "replicas": R, "length_ps": T, "sample_ps": dt, "decorrelate_ps": t, "temperature": K,
     "seed": s, "threads": n, "constraint_tolerance": tol,
     "rows": [{"name", "scene", "row", "platform"}, ...],
     "comparisons": [{"row": name, "ref": name, "kind": "claim" | "cost", "factor": f | None}, ...]}

``row`` is a :class:`~..core.rows.Row` label (one line a row: who, step, thermostat, options); ``scene`` a named
scene (:mod:`..core.scenes`; the HMR rows run on ``villin-pme-hmr``, whose System OpenMM's ForceField built with
heavier hydrogens, and whose replica states were equilibrated with them); ``platform`` NAME or NAME:PRECISION.  A "claim" comparison asks whether ``row`` drifts less than
``ref`` (about ``factor`` times less);  a "cost" comparison whether ``row`` (an option switched on: exact momentum,
the thermostat) drifts more than ``ref`` (switched off).  Both are paired by replica (:mod:`.verdict`).
"""
from __future__ import annotations

from ..core.platforms import split
from ..core.rows import Row
from ...support.errors import InputError

__all__ = ["hmr", "exact_momentum", "nvt", "nvt_pairs", "PRECISION_PLATFORMS", "OPENMM_PUBLISHED", "STUDIES"]

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


def _row(name, scene, label, platform="CPU"):
    split(platform)  # ValueError for an unknown precision
    return {"name": name, "scene": scene, "row": Row.parse(label).label, "platform": platform}


def hmr(quick: bool = False, control: bool = True) -> dict:
    """Our ``verlet`` (velocity Verlet, RATTLE) against OpenMM's VerletIntegrator at 4 fs with HMR on solvated villin
    (the production study's finding: about 10x less drift at equal speed), and the same pair at 2 fs without HMR
    as a control.  OpenMM's default constraint tolerance (1e-5), as the production study ran.  ``quick``: villin in
    vacuum (with and without HMR) instead of the solvated box, 0.2 ps per run: seconds, the pipeline only."""
    hmr_scene, plain = ("villin-vacuum-hmr", "villin-vacuum") if quick else ("villin-pme-hmr", "villin-pme")
    rows = [_row("verlet 4 fs HMR", hmr_scene, "verlet 4 fs"),
            _row("OpenMM Verlet 4 fs HMR", hmr_scene, "openmm-verlet 4 fs")]
    comparisons = [{"row": "verlet 4 fs HMR", "ref": "OpenMM Verlet 4 fs HMR", "kind": "claim", "factor": 10.0}]
    if control:
        rows += [_row("verlet 2 fs", plain, "verlet 2 fs"), _row("OpenMM Verlet 2 fs", plain, "openmm-verlet 2 fs")]
        comparisons.append({"row": "verlet 2 fs", "ref": "OpenMM Verlet 2 fs", "kind": "claim", "factor": None})
    return dict(_common(quick), study="hmr", mode="quick" if quick else "full", rows=rows, comparisons=comparisons)


def exact_momentum(quick: bool = False, platforms=PRECISION_PLATFORMS) -> dict:
    """Villin in vacuum (amber14, HBonds, no cutoff), ``verlet`` at 2 fs with and without ``exact_momentum`` on each
    platform and precision, paired by replica.  ``quick``: 0.2 ps per run."""
    rows, comparisons = [], []
    for plat in platforms:
        off, on = f"{plat} off", f"{plat} on"
        rows += [_row(off, "villin-vacuum", "verlet 2 fs", plat),
                 _row(on, "villin-vacuum", "verlet 2 fs exact-momentum", plat)]
        comparisons.append({"row": on, "ref": off, "kind": "cost", "factor": None})
    return dict(_common(quick), study="exact-momentum", mode="quick" if quick else "full", rows=rows,
                comparisons=comparisons)


#: The NVT study's pairs: (NVT row, the NVE row of the same method and step).  Ours thermostatted by velocity
#: rescaling (the package's default collision time 0.1 ps, every step) next to the same method without it;
#: OpenMM's NoseHooverIntegrator (its own heat-bath energy) next to OpenMM's VerletIntegrator.
NVT_PAIRS = ["verlet@1", "verlet@2", "verlet@3", "omelyan-2@4", "pefrl@4", "nosehoover@2"]
NVT_QUICK = ["verlet@2", "omelyan-2@4"]


def nvt_pairs(items) -> list:
    """[(NVT name, NVT label, NVE name, NVE label)] from "method@step_fs" items (``nosehoover@2``: OpenMM's
    NoseHooverIntegrator next to its VerletIntegrator); ValueError naming a bad item."""
    out = []
    for item in items:
        if "@" not in item:
            raise InputError(f"row {item!r}: write method@step_fs, e.g. omelyan-2@4 or nosehoover@2")
        row = Row.parse(item)
        h = f"{row.step_fs:g} fs"
        if row.who == "nose-hoover":
            out.append((f"NoseHoover {h}", row.label, f"OpenMM Verlet {h}", f"openmm-verlet {h}"))
        elif row.is_ours and not row.is_rigid:
            out.append((f"{row.method} {h}", f"{row.method} {h} SVR 0.1 ps", f"{row.method} {h} NVE", f"{row.method} {h}"))
        else:
            raise InputError(f"row {item!r}: the NVT study pairs catalogue methods and nosehoover")
    if not out:
        raise InputError("no rows: write method@step_fs,..., e.g. verlet@2,omelyan-2@4")
    return out


def nvt(quick: bool = False, items=None) -> dict:
    """The NVT study (docs/thermostat.md, "Measurements"): with the thermostat on, total + heat-bath energy is
    conserved but for the integrator's error, so its drift should be the NVE drift of the same method and step;
    each NVT row is compared with its NVE row replica by replica.  216 rigid TIP3P waters, PME 0.9 nm (the named
    scene ``water-box-216``), CPU platform.  ``items``: "method@step_fs" pairs instead of the full set.  ``quick``:
    two pairs, one replica of 0.2 ps (seconds, the pipeline only)."""
    rows, comparisons = [], []
    for nvt_name, nvt_label, nve_name, nve_label in nvt_pairs(items or (NVT_QUICK if quick else NVT_PAIRS)):
        rows += [_row(nvt_name, "water-box-216", nvt_label), _row(nve_name, "water-box-216", nve_label)]
        comparisons.append({"row": nvt_name, "ref": nve_name, "kind": "cost", "factor": None})
    common = dict(_common(quick), replicas=1 if quick else 3, length_ps=0.2 if quick else 20.0,
                  sample_ps=0.008 if quick else 0.02, decorrelate_ps=0.1 if quick else 2.0, threads=2)
    return dict(common, study="nvt", mode="quick" if quick else "full", rows=rows, comparisons=comparisons)


#: The studies by name (``symprk drift NAME``).
STUDIES = ("hmr", "exact-momentum", "nvt")
