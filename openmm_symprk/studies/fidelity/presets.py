"""Settings and rows of the fidelity study (data only; :mod:`.simulation.engines` builds them).

A row is a dict: ``kind`` (who integrates), ``step_fs`` and the kind's options:

* ``"symprk"`` -- :class:`~openmm_symprk.SymplecticIntegrator` with catalogue ``method``; NVE, or thermostatted
  by stochastic velocity rescaling with ``collision_time_ps`` (the package's thermostat; a row whose integrator
  does not accept ``temperature=`` yet is reported "unavailable: needs the thermostat");
* ``"langevin"`` -- OpenMM's LangevinMiddleIntegrator, ``friction_per_ps``;
* ``"mts-langevin"`` -- OpenMM's MTSLangevinIntegrator (BAOAB-RESPA), ``friction_per_ps``, reciprocal-space PME
  once per outer step, the rest ``inner_steps`` times;
* ``"nose-hoover"`` -- OpenMM's NoseHooverIntegrator (one chain), ``collision_frequency_per_ps``;
* ``"dpd"`` -- OpenMM's DPDIntegrator (pairwise friction, keeps the momentum), ``friction_per_ps`` and
  ``cutoff_nm`` (default: the box's nonbonded cutoff);

and for any kind ``hmr_da``: the hydrogen masses repartitioned to that many daltons (rigid water's too).
The reference row is the first: Verlet at 0.5 fs, NVE.
"""
from __future__ import annotations

import copy

__all__ = ["ROWS", "full", "quick"]

#: The rows of issue 21, reference first.
ROWS = [
    {"kind": "symprk", "method": "verlet", "step_fs": 0.5},
    {"kind": "symprk", "method": "verlet", "step_fs": 1.0},
    {"kind": "symprk", "method": "verlet", "step_fs": 2.0},
    {"kind": "symprk", "method": "verlet", "step_fs": 3.0},
    {"kind": "symprk", "method": "omelyan-2", "step_fs": 4.0},
    {"kind": "symprk", "method": "pefrl", "step_fs": 4.0},
    {"kind": "symprk", "method": "verlet", "step_fs": 4.0, "hmr_da": 3.0},
    {"kind": "symprk", "method": "omelyan-2", "step_fs": 4.0, "hmr_da": 3.0},
    {"kind": "symprk", "method": "verlet", "step_fs": 2.0, "collision_time_ps": 0.1},
    {"kind": "symprk", "method": "verlet", "step_fs": 2.0, "collision_time_ps": 1.0},
    {"kind": "symprk", "method": "omelyan-2", "step_fs": 4.0, "collision_time_ps": 0.1},
    {"kind": "symprk", "method": "omelyan-2", "step_fs": 4.0, "collision_time_ps": 1.0},
    {"kind": "langevin", "step_fs": 2.0, "friction_per_ps": 1.0},
    {"kind": "langevin", "step_fs": 2.0, "friction_per_ps": 0.1},
    {"kind": "langevin", "step_fs": 4.0, "friction_per_ps": 1.0, "hmr_da": 3.0},
    {"kind": "mts-langevin", "step_fs": 3.0, "friction_per_ps": 1.0, "inner_steps": 2},
    {"kind": "nose-hoover", "step_fs": 2.0, "collision_frequency_per_ps": 1.0},
    {"kind": "dpd", "step_fs": 2.0, "friction_per_ps": 1.0},
]


def full() -> dict:
    """The study of docs/fidelity.md: rigid SPC/E, 216 waters at 0.997 g/cm^3 (the equipartition study's box and
    replica states), 16 replicas; per run 2 ps to settle, 2 ps with frames every 4 fs (the angular-velocity
    correlation), then 20 ps with a frame every 24 fs (temperatures, energies, diffusion, reorientation; g(r)
    from every 5th frame); wall time per simulated ps timed in turns, 3 blocks of 200 fs per row.  About 3 hours on 2
    cores (18 rows x 16 replicas; more cores with --scheduler)."""
    return {
        "model": "spce", "n_waters": 216, "cutoff_nm": 0.9, "density_g_cm3": 0.997, "temperature": 300.0,
        "seed": 2024, "equilibrate_ps": 20.0, "spacing_ps": 5.0, "threads": 1, "replicas": 16,
        "settle_ps": 2.0, "omega_ps": 2.0, "omega_fs": 4.0, "omega_max_lag_ps": 0.5,
        "length_ps": 20.0, "sample_fs": 24.0, "rdf_every": 5,
        "msd_window_ps": [2.0, 8.0], "tau_fit": [0.1, 0.5], "rdf_r_min_nm": 0.2, "timing_fs": 200.0,
        "rows": copy.deepcopy(ROWS),
    }


def quick() -> dict:
    """The pipeline in seconds: 64 waters with a 0.55-nm cutoff, 2 replicas, 0.6-ps runs (error bars are large;
    tau from the C_l range 0.1-0.95, since C_l does not fall to 0.5 within 0.3 ps)."""
    cfg = full()
    cfg.update(n_waters=64, cutoff_nm=0.55, equilibrate_ps=1.0, spacing_ps=0.2, replicas=2, settle_ps=0.05,
               omega_ps=0.12, omega_max_lag_ps=0.06, length_ps=0.6, sample_fs=12.0, rdf_every=1,
               msd_window_ps=[0.1, 0.3], tau_fit=[0.1, 0.95], timing_fs=50.0)
    return cfg
