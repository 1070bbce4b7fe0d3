"""``symprk drift``: the energy-drift study -- the drift of paired rows over independent replicas, with a verdict at
3 standard errors.

Three questions use it (presets in :mod:`.presets`):

* ``symprk drift hmr`` -- does this package's velocity Verlet with RATTLE drift less than OpenMM's
  VerletIntegrator at 4 fs with hydrogen mass repartitioning (docs/production.md)?
* ``symprk drift exact-momentum`` -- does ``exact_momentum=True`` cost energy conservation, per platform
  precision (docs/conservation.md)?
* ``symprk drift nvt`` (also ``symprk nvt drift``) -- does the thermostat keep total + heat-bath energy as well
  as NVE keeps the energy, method by method (docs/thermostat.md)?  Its work-precision chart is :mod:`.chart`.

Modules: :mod:`.verdict` (pure statistics: drifts per row, paired comparisons, the verdict), :mod:`.presets`
(configurations), :mod:`openmm_symprk.studies.core.replicas` (the named scenes' independent replica states), :mod:`.runs` (one NVE run),
:mod:`.study` (the study on :mod:`openmm_symprk.studies.core`: resumable, one stored run per key), :mod:`.report`
(tables) and :mod:`.cli`.
"""
