"""Studies that measure the package against OpenMM, each a sub-command of ``symprk`` (:mod:`openmm_symprk.cli`):
the demo (:mod:`.demo`), the work-precision and stability bench (:mod:`.bench`), the native backend per platform
(:mod:`.platforms`: speed, conservation, the GPU check), the replica studies (:mod:`.equipartition`,
:mod:`.fidelity`, :mod:`.drift`) and the thermostat's measurements (:mod:`.nvt`).  What they share is
:mod:`.core` (rows, the engine that runs them, timing in turns, scenes, replica states, stored runs); no study
imports another."""
