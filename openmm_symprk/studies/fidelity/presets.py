"""Settings and rows of the fidelity study (data only; :mod:`.simulation` runs them).

A row is one label of the studies' row type (:class:`openmm_symprk.studies.core.rows.Row`; the grammar is in
that module's docstring), e.g. ``"verlet 2 fs"``, ``"omelyan-2 4 fs SVR 0.1 ps"`` (the package's stochastic velocity
rescaling, collision time 0.1 ps, at the ends of the step), ``"verlet 2 fs SVR 0.1 ps middle"`` (in the middle of
the step), ``"langevin 2 fs friction 0.1/ps"`` (OpenMM's LangevinMiddleIntegrator), ``"openmm-verlet 2 fs"``,
``"mts-langevin 3/2 fs friction 1/ps"`` (BAOAB-RESPA: reciprocal-space PME once per 3-fs step, the rest twice),
``"verlet 4/2 fs"`` (the package's MTS, the same split), ``"... HMR 3 Da"`` (hydrogen masses repartitioned).

The references (:data:`REFERENCES`) are rows too, always run: Verlet at 0.5 fs NVE for the NVE rows, and Verlet at
0.5 fs with the thermostat in the middle of the step at :data:`NVT_TAU_PS` for the NVT rows.
"""
from __future__ import annotations

__all__ = ["ROWS", "QUICK_ROWS", "REFERENCES", "NVT_TAU_PS", "DECIDING", "TOLERANCES", "EVENT_FS", "FRONTIER_ROWS",
           "FRONTIER_DECIDING", "FRONTIER_NVT_DECIDING", "FRONTIER_NVT_REPLICAS", "FRONTIER_HALF_FS_REPLICAS",
           "FRONTIER_TARGETS", "SIDE_ROWS", "MEAN_SQUARE_FREQUENCY_FS2", "LOWERED_ROWS", "PRESETS", "full", "quick",
           "frontier"]

#: Collision time of the package's thermostat in the NVT reference and the new NVT rows (issue 26).
NVT_TAU_PS = 0.1
#: The reference of each ensemble (rows of :data:`ROWS`).
REFERENCES = {"NVE": "verlet 0.5 fs", "NVT": "verlet 0.5 fs SVR 0.1 ps middle"}

#: The rows of issue 21 and issue 26, references first.
ROWS = [
    "verlet 0.5 fs",
    "verlet 0.5 fs SVR 0.1 ps middle",
    # NVE: the package
    "verlet 1 fs", "verlet 2 fs", "verlet 3 fs",
    "omelyan-2 4 fs", "omelyan-2 5 fs", "omelyan-2 6 fs", "omelyan-2 7 fs", "pefrl 4 fs",
    "verlet 4 fs HMR 3 Da", "omelyan-2 4 fs HMR 3 Da",
    "verlet 4/2 fs", "omelyan-2 6/2 fs",  # the package's MTS: reciprocal-space PME once per outer step
    # NVE: OpenMM
    "openmm-verlet 1 fs", "openmm-verlet 2 fs",
    # NVT: the package's thermostat, at the ends (issue 21) and in the middle of the step (issue 26)
    "verlet 2 fs SVR 0.1 ps", "verlet 2 fs SVR 1 ps", "omelyan-2 4 fs SVR 0.1 ps", "omelyan-2 4 fs SVR 1 ps",
    "verlet 2 fs SVR 0.1 ps middle", "verlet 3 fs SVR 0.1 ps middle", "verlet 4 fs SVR 0.1 ps middle",
    # omelyan-2 at its best placement (methods.placement.best_position: "ends")
    "omelyan-2 5 fs SVR 0.1 ps", "omelyan-2 6 fs SVR 0.1 ps", "omelyan-2 7 fs SVR 0.1 ps",
    "verlet 4/2 fs SVR 0.1 ps middle", "omelyan-2 6/2 fs SVR 0.1 ps",
    # NVT: OpenMM
    "langevin 1 fs friction 0.1/ps", "langevin 2 fs friction 0.1/ps", "langevin 3 fs friction 0.1/ps",
    "langevin 4 fs friction 0.1/ps", "langevin 2 fs friction 1/ps", "langevin 4 fs friction 1/ps HMR 3 Da",
    "mts-langevin 3/2 fs friction 1/ps", "nose-hoover 2 fs 1/ps", "dpd 2 fs friction 1/ps",
]

#: The rows that decide issue 26's answer (NVT), run first and on the second water model.
DECIDING = ["verlet 2 fs SVR 0.1 ps middle", "omelyan-2 4 fs SVR 0.1 ps", "langevin 2 fs friction 0.1/ps",
            "omelyan-2 4 fs", "openmm-verlet 2 fs"]


def full() -> dict:
    """The study of docs/fidelity.md: rigid SPC/E, 216 waters at 0.997 g/cm^3 (the equipartition study's box and
    replica states), 16 replicas; per run 2 ps to settle, 2 ps with frames every 4 fs (the angular-velocity
    correlation), then 20 ps with a frame every 24 fs (temperatures, energies, diffusion, reorientation; g(r)
    from every 5th frame); wall time per simulated ps timed in turns, 3 blocks of 1 ps per row (200 fs gave ratios off by 3x on a loaded machine).  About 3 hours on 2
    cores (18 rows x 16 replicas; more cores with --scheduler)."""
    return {
        "model": "spce", "n_waters": 216, "cutoff_nm": 0.9, "density_g_cm3": 0.997, "temperature": 300.0,
        "seed": 2024, "equilibrate_ps": 20.0, "spacing_ps": 5.0, "threads": 1, "replicas": 16,
        "settle_ps": 2.0, "omega_ps": 2.0, "omega_fs": 4.0, "omega_max_lag_ps": 0.5,
        "length_ps": 20.0, "sample_fs": 24.0, "rdf_every": 5,
        "msd_window_ps": [2.0, 8.0], "tau_fit": [0.1, 0.5], "rdf_r_min_nm": 0.2, "timing_fs": 1000.0,
        "rows": list(ROWS), "references": dict(REFERENCES),
        # issue 26's study is kept as it ran (runs of version 2): its report is remade from the stored runs only
        "run_version": 2, "frozen": "match-3se",
    }


#: The rows of :func:`quick`: both references, each ensemble's Verlet trend (the h -> 0 fits), and one row of every
#: kind of integrator the full study runs (the package's NVE, HMR, MTS and both thermostat placements; OpenMM's
#: Verlet, LangevinMiddle, MTSLangevin, Nose-Hoover and DPD), so the pipeline is checked for each in a third of
#: the full row list's time.
QUICK_ROWS = [
    "verlet 0.5 fs", "verlet 0.5 fs SVR 0.1 ps middle", "verlet 1 fs", "verlet 2 fs", "verlet 3 fs",
    "omelyan-2 4 fs", "verlet 4 fs HMR 3 Da", "verlet 4/2 fs", "openmm-verlet 2 fs",
    "omelyan-2 4 fs SVR 0.1 ps", "verlet 2 fs SVR 0.1 ps middle", "verlet 3 fs SVR 0.1 ps middle",
    "langevin 2 fs friction 0.1/ps", "mts-langevin 3/2 fs friction 1/ps", "nose-hoover 2 fs 1/ps",
    "dpd 2 fs friction 1/ps",
]


def quick() -> dict:
    """The pipeline in seconds: 64 waters with a 0.55-nm cutoff, 2 replicas, 0.6-ps runs (error bars are large;
    tau from the C_l range 0.1-0.95, since C_l does not fall to 0.5 within 0.3 ps), on :data:`QUICK_ROWS`."""
    cfg = full()
    del cfg["frozen"]
    cfg.update(run_version=3, rows=list(QUICK_ROWS), n_waters=64, cutoff_nm=0.55, equilibrate_ps=1.0, spacing_ps=0.2, replicas=2, settle_ps=0.05,
               omega_ps=0.12, omega_max_lag_ps=0.06, length_ps=0.6, sample_fs=12.0, rdf_every=1,
               msd_window_ps=[0.1, 0.3], tau_fit=[0.1, 0.95], timing_fs=50.0, tolerances=TOLERANCES)
    return cfg


# -- issue 35: the frontier ----------------------------------------------------------------------------------------
#: The tolerances on the observables' biases at which the frontier answers (issue 35), declared before its runs.  A
#: key ending in ``_rel`` is a fraction of the reference's mean.  Why these sizes:
#:
#: * pe (kJ/mol per molecule): 0.01, 0.03, 0.1. The heat capacity of water (~75 J/mol/K) makes 0.1 kJ/mol the
#:   potential energy of ~1.5 K; 0.01 is below what a force field's parameters fix (a tenth of that);
#: * D_rel, tau2_dip_rel: 2 %, 5 %, 10 %. Diffusion and reorientation are reported to a few per cent (the box's own
#:   Yeh-Hummer correction is 18 % of D here), 10 % is what a screening run accepts;
#: * w_zero (fs): 0.05, 0.1, 0.2 of its 14.4 fs (0.3-1.4 %), w_min: 0.003, 0.006, 0.012 of its -0.53 (0.6-2.3 %): the
#:   librations' phase and depth, the first things a large step distorts (THEORY: a relative frequency error of
#:   0.5 % at the middle level);
#: * dT (K): 0.5, 1, 2 of T_rot - T_trans (0 in the exact dynamics): equipartition, which a thermostat hides;
#: * g_h_rel: 0.5 %, 1 %, 2 % of the O-O first peak's height (structure).
TOLERANCES = {
    "tight": {"pe": 0.01, "D_rel": 0.02, "tau2_dip_rel": 0.02, "w_zero": 0.05, "w_min": 0.003, "dT": 0.5,
              "g_h_rel": 0.005},
    "standard": {"pe": 0.03, "D_rel": 0.05, "tau2_dip_rel": 0.05, "w_zero": 0.1, "w_min": 0.006, "dT": 1.0,
                 "g_h_rel": 0.01},
    "loose": {"pe": 0.1, "D_rel": 0.10, "tau2_dip_rel": 0.10, "w_zero": 0.2, "w_min": 0.012, "dT": 2.0,
              "g_h_rel": 0.02},
}
#: The one event grid of the NVT rows: every row thermostats at the same simulated times (every EVENT_FS fs, half an
#: event at each end of an interval), with the same seed, so its draws are the NVT reference's event for event and a
#: row pairs with the reference replica by replica as NVE rows do (common random numbers).
EVENT_FS = 12.0
#: <w^2> = <F.M^-1.F>/(N_f kT) per degree of freedom (fs^-2) of each water model's frontier box, over its replica
#: states (SPC/E's first 12, TIP3P's 8; :func:`openmm_symprk.systems.frequencies.mean_square_frequency`): what
#: lowers each model's thermostat target, T (1 - c_T h^2 <w^2>) (:func:`openmm_symprk.integrators.shadow.lowered_target`).
MEAN_SQUARE_FREQUENCY_FS2 = {"spce": 6.818e-3, "tip3p": 5.610e-3}
#: The rows whose thermostat target is lowered for one water model's <w^2>: they hold for that model only.  A study
#: of another model swaps each for its own row of the same method, step and thermostat (:func:`.rowspec.for_model`), or
#: leaves it out where the model has none (SPC/E's side rows).  The first five of each model are the omelyan-2
#: family on the event grid (the package's cheapest accurate NVT configuration); SPC/E's are the frontier's rows.
LOWERED_ROWS = {
    "spce": ["omelyan-2 3 fs SVR 0.1 ps every 4 T 299.76 K", "omelyan-2 4 fs SVR 0.1 ps every 3 T 299.57 K",
             "omelyan-2 5 fs SVR 0.1 ps T 299.32 K", "omelyan-2 6 fs SVR 0.1 ps every 2 T 299.02 K",
             "omelyan-2 7 fs SVR 0.1 ps T 298.67 K", "predescu-3 12 fs SVR 0.1 ps T 298.38 K",
             "bcss-2 6 fs SVR 0.1 ps every 2 T 298.34 K", "verlet 3 fs SVR 0.1 ps every 4 T 296.93 K"],
    "tip3p": ["omelyan-2 3 fs SVR 0.1 ps every 4 T 299.8 K", "omelyan-2 4 fs SVR 0.1 ps every 3 T 299.64 K",
              "omelyan-2 5 fs SVR 0.1 ps T 299.44 K", "omelyan-2 6 fs SVR 0.1 ps every 2 T 299.2 K",
              "omelyan-2 7 fs SVR 0.1 ps T 298.91 K"],
}
#: SPC/E's lowered-target omelyan-2 family and its lowered side rows (other methods, one step each).
_LOWERED_FAMILY, _LOWERED_SIDE = LOWERED_ROWS["spce"][:5], LOWERED_ROWS["spce"][5:]

#: The frontier's rows: the references, then per family its steps up to where it stops paying.  NVE: OpenMM's
#: VerletIntegrator (1-3 fs), omelyan-2, BCSS-2 and the three-stage Predescu scheme; NVT on the event grid:
#: the package's thermostat on omelyan-2, BCSS-2 and Verlet (at the ends and in the middle), and OpenMM's
#: LangevinMiddleIntegrator (1-3 fs; it cannot share the draws: its family is resolved by the pooled fit over its
#: steps).
FRONTIER_ROWS = [
    "verlet 0.5 fs", "verlet 0.5 fs SVR 0.1 ps every 24",
    "openmm-verlet 1 fs", "openmm-verlet 2 fs", "openmm-verlet 3 fs",
    "omelyan-2 4 fs", "omelyan-2 6 fs", "omelyan-2 7 fs", "bcss-2 4 fs", "bcss-2 6 fs", "bcss-2 7 fs",
    "predescu-3 6 fs", "predescu-3 9 fs", "predescu-3 12 fs",
    "omelyan-2 4 fs SVR 0.1 ps every 3", "omelyan-2 6 fs SVR 0.1 ps every 2", "bcss-2 4 fs SVR 0.1 ps every 3",
    "bcss-2 6 fs SVR 0.1 ps every 2",
    "verlet 2 fs SVR 0.1 ps every 6", "verlet 3 fs SVR 0.1 ps every 4",
    # the placement question (issue 35): Verlet with the event in the middle of the interval's centre step (the same
    # draws as the reference, 5-4.5 fs off its event times), against the ends rows above
    "verlet 2 fs SVR 0.1 ps every 6 middle", "verlet 3 fs SVR 0.1 ps every 4 middle",
    "langevin 1 fs friction 0.1/ps", "langevin 2 fs friction 0.1/ps", "langevin 3 fs friction 0.1/ps",
    # fourth order where it might survive constraints (issue 35): the compositions over RATTLE keep it (fitted as
    # c h^4), PEFRL falls to second order; each up to about its stability limit in water (the catalogue's interval
    # over Verlet's, times Verlet's 4-5 fs), then one step beyond, to find where each fails
    "yoshida-4 3 fs", "yoshida-4 4 fs", "suzuki-4 6 fs", "suzuki-4 8 fs", "pefrl 6 fs", "pefrl 8 fs",
    "yoshida-4 5 fs", "suzuki-4 10 fs", "pefrl 10 fs",
    # NVT at equal accuracy: every NVT family on three steps or more, where "auto" puts its thermostat (the ends for
    # the multi-stage splittings, the middle for Verlet), and OpenMM's LangevinMiddleIntegrator at the friction users
    # run (1/ps) beside 0.1/ps.  Common random numbers bought nothing measurable (docs/fidelity.md), so a step that
    # does not divide the 12-fs grid thermostats every step (its events 5-9 fs apart, the same collision time).
    "omelyan-2 2 fs SVR 0.1 ps every 6", "omelyan-2 3 fs SVR 0.1 ps every 4", "omelyan-2 5 fs SVR 0.1 ps",
    "omelyan-2 7 fs SVR 0.1 ps", "bcss-2 2 fs SVR 0.1 ps every 6", "bcss-2 3 fs SVR 0.1 ps every 4",
    "predescu-3 6 fs SVR 0.1 ps every 2", "predescu-3 9 fs SVR 0.1 ps", "predescu-3 12 fs SVR 0.1 ps",
    "verlet 1 fs SVR 0.1 ps every 12 middle",
    "langevin 1 fs friction 1/ps", "langevin 2 fs friction 1/ps", "langevin 3 fs friction 1/ps",
    # LangevinMiddle at the references' step: its dynamical bias at h -> 0 (friction slows diffusion at any step),
    # fitted with the rest of its family as a + c h^2 (studies.fidelity.frontier.free_observables)
    "langevin 0.5 fs friction 0.1/ps", "langevin 0.5 fs friction 1/ps",
    # the thermostat's target lowered by the modified energy (below: T (1 - c_T h^2 <w^2>)), a family of its own on
    # the omelyan-2 family's steps and event grid (studies.fidelity.frontier.family_of: "T lowered"); the targets
    # are SPC/E's (:data:`LOWERED_ROWS`: another model's run has its own, :func:`.rowspec.for_model`)
    *_LOWERED_FAMILY,
] + [
    # tests of where the NVT rows' potential-energy bias comes from (:data:`SIDE_ROWS`: run and tabulated, not fitted)
    "omelyan-2 6 fs SVR 0.1 ps", "omelyan-2 6 fs SVR 1 ps every 2", "omelyan-2 6 fs SVR 0.1 ps every 2 middle",
    "predescu-3 12 fs SVR 0.1 ps middle",
    # the thermostat's target lowered to the modified energy's kinetic temperature, T (1 - c_T h^2 <w^2>), with
    # c_T of the method at the event point and <w^2> = <F.M^-1.F>/(N_f kT) of this box's replica states
    # (:data:`MEAN_SQUARE_FREQUENCY_FS2`): the configurational temperature of the slow modes then sits at 300 K
    # (integrators.shadow.lowered_target; tests/studies/test_fidelity.py checks these labels against it)
    *_LOWERED_SIDE,
]
#: Rows that test a hypothesis about the others (the thermostat's interval, collision time or placement at one
#: step): run and tabulated like every row, left out of the frontier's families (each would sit beside a row of
#: the same family and step, or form a family of one step).
SIDE_ROWS = ["omelyan-2 6 fs SVR 0.1 ps", "omelyan-2 6 fs SVR 1 ps every 2", "omelyan-2 6 fs SVR 0.1 ps every 2 middle",
             "predescu-3 12 fs SVR 0.1 ps middle", *_LOWERED_SIDE]
#: The frontier's deciding rows (``--rows deciding``; what TIP3P runs, ``--model tip3p``): those that decide the
#: answer in SPC/E (the references, OpenMM's families, omelyan-2 in both ensembles) and the placement question's rows.
FRONTIER_DECIDING = [
    "verlet 0.5 fs", "verlet 0.5 fs SVR 0.1 ps every 24",
    "openmm-verlet 1 fs", "openmm-verlet 2 fs", "openmm-verlet 3 fs", "omelyan-2 4 fs", "omelyan-2 6 fs",
    "omelyan-2 7 fs", "omelyan-2 4 fs SVR 0.1 ps every 3", "omelyan-2 6 fs SVR 0.1 ps every 2",
    "verlet 2 fs SVR 0.1 ps every 6", "verlet 3 fs SVR 0.1 ps every 4",
    "verlet 2 fs SVR 0.1 ps every 6 middle", "verlet 3 fs SVR 0.1 ps every 4 middle",
    "langevin 1 fs friction 0.1/ps", "langevin 2 fs friction 0.1/ps", "langevin 3 fs friction 0.1/ps",
    # the NVT answer: the omelyan-2 family on four steps, LangevinMiddle at both frictions down to the references' step
    "omelyan-2 3 fs SVR 0.1 ps every 4", "omelyan-2 5 fs SVR 0.1 ps", "langevin 0.5 fs friction 0.1/ps",
    "langevin 0.5 fs friction 1/ps", "langevin 1 fs friction 1/ps", "langevin 2 fs friction 1/ps",
    "langevin 3 fs friction 1/ps",
    # the package's cheapest accurate NVT configuration: omelyan-2 with the lowered target (SPC/E's targets; the
    # model's own under --model, :func:`.rowspec.for_model`)
    *_LOWERED_FAMILY,
]

#: The rows that decide the NVT answer at the standard level (the NVT reference, the lowered-target omelyan-2 family
#: and LangevinMiddle at both frictions, which share the fitted friction part): run at more replicas than the others
#: (:data:`FRONTIER_NVT_REPLICAS`), replica by replica, so that a run stopped part way leaves them balanced.
FRONTIER_NVT_DECIDING = [
    "verlet 0.5 fs SVR 0.1 ps every 24",
    *_LOWERED_FAMILY,
    "langevin 0.5 fs friction 0.1/ps", "langevin 1 fs friction 0.1/ps", "langevin 2 fs friction 0.1/ps",
    "langevin 3 fs friction 0.1/ps",
    "langevin 0.5 fs friction 1/ps", "langevin 1 fs friction 1/ps", "langevin 2 fs friction 1/ps",
    "langevin 3 fs friction 1/ps",
]
#: The replicas of :data:`FRONTIER_NVT_DECIDING` committed (the other rows have 12); a later measurement raises it and
#: runs ``symprk fidelity --preset frontier --out docs/data/fidelity/frontier-spce --no-timing``, which runs only the
#: missing replicas.
FRONTIER_NVT_REPLICAS = 40
#: LangevinMiddle at 0.5 fs is a third of the cost of a replica of those rows and carries little of the fitted c
#: (h^2 = 0.25 fs^2 against 1-9 at 1-3 fs): its replicas stop here.
FRONTIER_HALF_FS_REPLICAS = 14


def frontier_row_replicas() -> dict:
    """{label: replicas} of the frontier's rows run at more replicas than the others (the preset's ``row_replicas``)."""
    return {lab: FRONTIER_HALF_FS_REPLICAS if lab.startswith("langevin 0.5 fs") else FRONTIER_NVT_REPLICAS
            for lab in FRONTIER_NVT_DECIDING}


#: The resolution the frontier's rows aim at: a paired SE of PE of 0.015 kJ/mol per molecule (half the standard
#: tolerance's 0.03, so that a bias at the tolerance is 2 SE out) and of D of 5 % (the standard tolerance).
FRONTIER_TARGETS = {"D_rel": 0.05, "pe": 0.015}


def frontier() -> dict:
    """Issue 35's study: the box, lengths and observables of :func:`full`, 12 replicas (:data:`FRONTIER_NVT_REPLICAS` of
    the NVT answer's rows; --replicas N: N of every row), replica
    states from the package's thermostat (velocity Verlet at 1 fs with stochastic velocity rescaling at the ends of
    the step: on-step velocities and positions both canonical at 300 K; ``equilibrator``), runs of version 3
    (leapfrog rows' velocities brought to the positions' time, the omega ACF's features read between its samples and
    its curve kept), the references Verlet at 0.5 fs NVE and on the event grid NVT, :data:`TOLERANCES` and
    :data:`FRONTIER_TARGETS`."""
    cfg = full()
    del cfg["frozen"]
    cfg.update(rows=list(FRONTIER_ROWS), replicas=12, run_version=3, equilibrator="svr",
               references={"NVE": "verlet 0.5 fs", "NVT": "verlet 0.5 fs SVR 0.1 ps every 24"},
               tolerances=TOLERANCES, deciding=list(FRONTIER_DECIDING), side=list(SIDE_ROWS),
               targets=dict(FRONTIER_TARGETS), row_replicas=frontier_row_replicas(),
               lowered_rows={m: list(labs) for m, labs in LOWERED_ROWS.items()})
    return cfg


#: The studies ``symprk fidelity --preset`` runs.
PRESETS = {"match-3se": full, "frontier": frontier}
