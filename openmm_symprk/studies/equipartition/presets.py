"""Settings of the equipartition study (data only).

Rows are labels of the studies' row type (:class:`~..core.rows.Row`), e.g. ``"verlet 2 fs"``; ``rigid:<method>`` runs
the molecules as rigid bodies (:class:`openmm_symprk.rigid.bodies.RigidBodies`, ``rigid:verlet`` = NO_SQUISH); any
other catalogue method runs in :class:`~openmm_symprk.SymplecticIntegrator` with RATTLE/SETTLE.
"""
from __future__ import annotations

import copy

__all__ = ["full", "quick"]


def full() -> dict:
    """The study as reported in docs/equipartition.md: 216 waters at 0.997 g/cm^3 (a 1.864-nm box, the smallest
    cubic box that fits a 0.9 nm PME cutoff), 4 replicas 5 ps apart after 20 ps of Langevin equilibration, 2 ps of NVE to settle, then
    20 ps of NVE measured every 24 fs.  About an hour on 2 cores."""
    return {
        "n_waters": 216, "cutoff_nm": 0.9, "density_g_cm3": 0.997, "temperature": 300.0, "seed": 2024,
        "equilibrate_ps": 20.0, "spacing_ps": 5.0, "replicas": 4,
        "settle_ps": 2.0, "length_ps": 20.0, "sample_fs": 24.0, "threads": 1,
        "reference": "verlet 0.5 fs",
        "models": {
            "spce": ["verlet 0.5 fs", "verlet 1 fs", "verlet 2 fs", "verlet 3 fs", "omelyan-2 4 fs", "pefrl 4 fs",
                     "rigid:verlet 2 fs", "rigid:verlet 3 fs", "rigid:omelyan-2 4 fs"],
            "tip3p": ["verlet 0.5 fs", "verlet 2 fs", "omelyan-2 4 fs"],
        },
    }


def quick() -> dict:
    """A seconds-long version for tests and a first look: 64 waters, short runs (error bars are large)."""
    cfg = copy.deepcopy(full())
    cfg.update(n_waters=64, cutoff_nm=0.55, equilibrate_ps=1.0, spacing_ps=0.2, replicas=2, settle_ps=0.05,
               length_ps=0.3, sample_fs=12.0)
    cfg["models"] = {"spce": ["verlet 0.5 fs", "verlet 2 fs", "omelyan-2 4 fs", "rigid:verlet 2 fs"]}
    return cfg
