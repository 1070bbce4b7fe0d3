"""The measurements of the NVT thermostat (docs/thermostat.md, "Measurements"): ``symprk nvt cost`` and
``symprk nvt drift``.

* :mod:`.rows` -- the integrators compared, one Row label a line: the package's methods with the thermostat and
  OpenMM 8.6's thermostatted integrators (LangevinMiddle, NoseHoover, DPD, MTSLangevin);
* :mod:`.cost` -- time per step against LangevinMiddleIntegrator in the same run (CPU platform);
* ``symprk nvt drift`` is the energy-drift study's ``nvt`` preset (:mod:`openmm_symprk.studies.drift`): the
  effective-energy drift (total + heat-bath energy) next to the NVE drift of the same method and step.
"""
