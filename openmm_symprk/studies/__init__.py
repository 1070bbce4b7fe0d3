"""Studies that measure the package against OpenMM: the demo (:mod:`.demo`), the work-precision and stability
bench (:mod:`.bench`), the conservation table (:mod:`.conservation_table`), the native backend's speed
(:mod:`.native_speed`), the GPU check (:mod:`.gpucheck`); all time integrators with :mod:`.timing`."""
