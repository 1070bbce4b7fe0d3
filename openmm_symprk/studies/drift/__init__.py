"""``symprk drift``: NVE energy drift of paired rows over independent replicas, with a verdict at 3 standard errors.

Two questions use it (presets in :mod:`.presets`):

* ``symprk drift hmr`` -- does this package's velocity Verlet with RATTLE drift less than OpenMM's
  VerletIntegrator at 4 fs with hydrogen mass repartitioning (docs/production.md)?
* ``symprk drift exact-momentum`` -- does ``exact_momentum=True`` cost energy conservation, per platform
  precision (docs/conservation.md)?

Modules: :mod:`.verdict` (pure statistics: drifts per row, paired comparisons, the verdict), :mod:`.presets`
(configurations), :mod:`openmm_symprk.systems.scenes.replicas` (the named scenes' independent replica states), :mod:`.runs` (one NVE run),
:mod:`.study` (the study on :mod:`openmm_symprk.studies.core`: resumable, one stored run per key), :mod:`.report`
(tables) and :mod:`.cli`.
"""
