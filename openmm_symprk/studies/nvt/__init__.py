"""The measurements of the NVT thermostat (docs/thermostat.md, "Measurements"): ``symprk nvt cost`` and
``symprk nvt drift``.

* :mod:`.rows` -- the integrators compared: the package's methods with ``temperature=`` and OpenMM 8.6's
  thermostatted integrators (LangevinMiddle, NoseHoover, DPD, MTSLangevin), built from one row name;
* :mod:`.cost` -- time per step against LangevinMiddleIntegrator in the same run (CPU platform);
* :mod:`.drift` -- effective-energy drift (total + heat-bath energy) in kT/ns per degree of freedom, next to the
  NVE drift of the same method and step, with standard errors over replicas; :mod:`.chart` draws it.
"""
