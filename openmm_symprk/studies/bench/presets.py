"""Sweep configurations: ``quick()`` for CI (seconds) and ``full()`` for the figures in docs/benchmarks.md.

A configuration is plain JSON-ready data (it is saved in results.json)::

    {"mode": ..., "methods": [...], "reference": {"method": "kahan-li-8", "factor": 4},
     "timing_s": 0.5, "threads": 1,
     "scenes": {name: {"params": {...}, "steps_fs": [...], "length_ps": T, "samples": n,
                       "stability": {...} | None, "eval_s": cost hint, "platform": optional,
                       "rows": [[row, step_fs], ...] (optional: instead of methods x steps_fs),
                       "baseline": [row, step_fs] (production scenes: what the others are compared to)}}}

Every step size must divide the run length (trajectory errors are compared at the same final time).
:func:`production` is the sweep of the production-shaped scenes (``symprk bench --production``).
``stability`` holds the search settings of :func:`~.stability.driver` (``linear`` for the harmonic toy).
"""
from __future__ import annotations

import copy

from ...support.errors import InputError


#: The rows of the default sweep: OpenMM's integrators, then one method per cost/order class.
DEFAULT_METHODS = ["openmm-verlet", "openmm-langevin", "verlet", "omelyan-2", "yoshida-4", "pefrl",
                   "blanes-moan-srkn6b-4", "yoshida-6", "blanes-moan-srkn11b-6", "kahan-li-8"]
QUICK_METHODS = ["openmm-verlet", "openmm-langevin", "verlet", "yoshida-4"]
REFERENCE = {"method": "kahan-li-8", "factor": 4}


def _linear(rel_tol):
    from .stability import linear_settings

    return linear_settings(700.0, rel_tol)  # the harmonic scene's top frequency (toys.OMEGA_OH)


def _md_stability(probe_steps, rel_tol=0.02, h0=1.0, grow=1.4, cap=12.0, samples=20):
    return {"h0_fs": h0, "cap_fs": cap, "grow": grow, "rel_tol": rel_tol, "probe_steps": probe_steps,
            "samples": samples}


def full() -> dict:
    """The README/docs sweep: about 10 minutes with 2 workers on the 2-core development machine."""
    return {
        "mode": "full",
        "methods": list(DEFAULT_METHODS),
        "reference": dict(REFERENCE),
        "timing_s": 0.6,
        "threads": 1,
        "scenes": {
            "harmonic": {"params": {"n": 256}, "steps_fs": [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
                         "length_ps": 0.3, "samples": 60, "stability": _linear(1e-4), "eval_s": 1e-4},
            "anharmonic": {"params": {"n": 64}, "steps_fs": [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
                           "length_ps": 0.3, "samples": 60, "stability": _md_stability(2000, 0.01, 0.5, 1.25),
                           "eval_s": 3e-5},
            "water-rigid": {"params": {"n_waters": 64}, "steps_fs": [0.5, 1.0, 2.0, 3.0, 4.0, 5.0],
                            "length_ps": 1.2, "samples": 60, "stability": _md_stability(500), "eval_s": 4e-4},
            "water-flexible": {"params": {"n_waters": 64}, "steps_fs": [0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5],
                               "length_ps": 0.6, "samples": 60, "stability": _md_stability(500, h0=0.5),
                               "eval_s": 4e-4},
            "villin": {"params": {}, "steps_fs": [1.0, 2.0, 3.0, 4.0], "length_ps": 0.24, "samples": 40,
                       "stability": _md_stability(100), "eval_s": 5e-3},
            "water-box-pme": {"params": {}, "steps_fs": [1.0], "length_ps": 0.02, "samples": 4, "stability": None,
                              "eval_s": 3.5e-2},
        },
    }


def quick() -> dict:
    """CI: tiny scenes, two step sizes, four rows; runs in seconds and still exercises every stage
    (reference run, exact toys, linear and run-based stability, timing, charts)."""
    return {
        "mode": "quick",
        "methods": list(QUICK_METHODS),
        "reference": {"method": "kahan-li-8", "factor": 2},
        "timing_s": 0.02,
        "threads": 1,
        "scenes": {
            "harmonic": {"params": {"n": 32}, "steps_fs": [1.0, 2.0, 3.0], "length_ps": 0.06, "samples": 6,
                         "stability": _linear(1e-3), "eval_s": 1e-5},
            "anharmonic": {"params": {"n": 8}, "steps_fs": [1.0, 2.0], "length_ps": 0.06, "samples": 6,
                           "stability": None, "eval_s": 1e-5},
            "water-rigid": {"params": {"n_waters": 8}, "steps_fs": [1.0, 2.0], "length_ps": 0.04, "samples": 4,
                            "stability": _md_stability(40, rel_tol=0.3, h0=2.0, grow=2.0, cap=16.0, samples=4),
                            "eval_s": 1e-4},
        },
    }


def production() -> dict:
    """Production-shaped runs (``symprk bench --production``): the solvated villin box as OpenMM users run it,
    with and without hydrogen mass repartitioning, and a box whose slow force is the expensive part; NVE, energy
    drift and fluctuation, ns/day.  About two hours on 2 cores (a benchmark, not a test)."""
    return {
        "mode": "production",
        "methods": ["openmm-verlet", "verlet"],
        "timing_s": 4.0,
        "threads": 2,
        "scenes": {
            "villin-pme": {
                "params": {}, "length_ps": 24.0, "samples": 240, "stability": None, "eval_s": 1.2e-2,
                "steps_fs": [2.0], "baseline": ["openmm-verlet", 2.0],
                "rows": [["openmm-verlet", 2.0], ["verlet", 2.0], ["omelyan-2", 4.0], ["omelyan-2", 4.8],
                         ["pefrl", 6.0], ["verlet@mts2", 4.0], ["openmm-mts2", 4.0], ["omelyan-2/verlet@mts2", 6.0],
                         ["omelyan-2/verlet@mts1", 4.8]]},
            "villin-pme-hmr": {
                "params": {}, "length_ps": 24.0, "samples": 240, "stability": None, "eval_s": 1.2e-2,
                "steps_fs": [4.0], "baseline": "largest-good openmm-verlet",
                "rows": [["openmm-verlet", 2.0], ["openmm-verlet", 3.0], ["openmm-verlet", 4.0],
                         ["openmm-verlet", 4.8], ["verlet", 4.0], ["omelyan-2", 6.0], ["omelyan-2", 8.0],
                         ["pefrl", 8.0], ["verlet@mts2", 6.0], ["openmm-mts2", 6.0], ["omelyan-2/verlet@mts1", 8.0]]},
            "water-pme-accurate": {
                "params": {}, "length_ps": 12.0, "samples": 120, "stability": None, "eval_s": 4e-2,
                "steps_fs": [2.0], "baseline": ["openmm-verlet", 2.0],
                "rows": [["openmm-verlet", 2.0], ["verlet", 2.0], ["verlet@mts2", 4.0], ["openmm-mts2", 4.0],
                         ["verlet@mts4", 6.0], ["openmm-mts4", 6.0], ["omelyan-2/verlet@mts1", 4.0],
                         ["omelyan-2/verlet@mts2", 6.0]]},
        },
    }


def rows_of(config: dict, scene: str) -> list:
    """[(row, step_fs)] of a scene: its explicit rows, or the sweep's methods x the scene's step sizes."""
    sc = config["scenes"][scene]
    if sc.get("rows"):
        return [(m, float(h)) for m, h in sc["rows"]]
    if sc.get("production") and sc.get("production_rows"):
        return [(m, float(h)) for m, h in sc["production_rows"]]
    return [(m, float(h)) for h in sc["steps_fs"] for m in sc.get("methods", config["methods"])]


def user_defaults() -> dict:
    """Settings for a user-supplied system: molecular-dynamics step sizes and short runs against a reference run;
    a periodic one is measured like a production run instead (``production_rows``, ``production_length_ps``):
    NVE drift, fluctuation and ns/day against OpenMM's VerletIntegrator at 2 fs."""
    return {"params": {}, "steps_fs": [0.5, 1.0, 2.0, 3.0, 4.0], "length_ps": 0.24, "samples": 40,
            "stability": _md_stability(200), "eval_s": 1e-2, "baseline": ["openmm-verlet", 2.0],
            "production_rows": [["openmm-verlet", 2.0], ["verlet", 2.0], ["omelyan-2", 4.0], ["pefrl", 6.0],
                                ["verlet@mts2", 4.0], ["openmm-mts2", 4.0], ["omelyan-2/verlet@mts2", 6.0]],
            "production_length_ps": 12.0, "production_samples": 120}


def select(config: dict, scenes=None, methods=None, steps_fs=None, length_ps=None, stability=True) -> dict:
    """A copy of ``config`` restricted to ``scenes`` / with other ``methods``, step sizes or length."""
    cfg = copy.deepcopy(config)
    if scenes:
        unknown = [s for s in scenes if s not in cfg["scenes"]]
        if unknown:
            from ..core.scenes import SCENES

            known = dict(full()["scenes"], **production()["scenes"])
            extra = {s: known[s] for s in unknown if s in SCENES}
            bad = [s for s in unknown if s not in extra]
            if bad:
                raise InputError(f"unknown scene(s) {', '.join(bad)}; known: {', '.join(SCENES)}")
            cfg["scenes"].update(extra)
        cfg["scenes"] = {k: v for k, v in cfg["scenes"].items() if k in scenes}
    if methods:
        from .runs import canonical_row

        cfg["methods"] = [canonical_row(m) for m in methods]
    for sc in cfg["scenes"].values():
        if methods or steps_fs:
            sc.pop("rows", None)  # an explicit grid replaces a scene's own rows
            sc.pop("production_rows", None)
        if steps_fs:
            sc["steps_fs"] = [float(h) for h in steps_fs]
        if length_ps:
            sc["length_ps"] = float(length_ps)
        if not stability:
            sc["stability"] = None
    return cfg


def check(config: dict):
    """Raise ValueError if a step size does not divide its scene's run length."""
    for name, sc in config["scenes"].items():
        for h in sorted({h for _, h in rows_of(config, name)}):
            n = sc["length_ps"] * 1e3 / h
            if abs(n - round(n)) > 1e-6 * n or round(n) < 1:
                raise InputError(f"scene {name}: step {h} fs does not divide the run length "
                                 f"{sc['length_ps']} ps ({n:.3f} steps); choose steps that divide it")
