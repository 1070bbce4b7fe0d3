"""``symprk bench``: speed against accuracy, and where each method stops being stable.

Its scenes are the named scenes of :mod:`openmm_symprk.studies.core.scenes` (analytic toys with exact solutions,
water, villin, PME boxes, user systems).  Modules: :mod:`.runs` (one run), :mod:`.stability` (largest
stable step by bisection), :mod:`.records` and :mod:`.store` (typed records of finished runs on disk),
:mod:`.presets` (quick and full sweeps), :mod:`.sweep` (scenes x methods x steps in parallel, resumable),
:mod:`.aggregate` (results and tables), :mod:`.charts` (figures) and :mod:`.cli` (the command line).  The
rows, the engine that runs them, the folder lock, atomic files, run keys, executors and job loop are the studies' shared skeleton
(:mod:`openmm_symprk.studies.core`); drifts and their errors come from :mod:`openmm_symprk.stats`.  Python
use::

    from openmm_symprk.studies.bench import run_sweep, presets
    results = run_sweep(presets.quick(), out="bench-results/quick", workers=2)
"""
from __future__ import annotations


def __getattr__(name):  # keep ``import openmm_symprk.studies.bench`` light: load on first use
    import importlib

    if name == "run_sweep":
        return importlib.import_module(".sweep", __name__).run_sweep
    if name == "presets":
        return importlib.import_module(".presets", __name__)
    raise AttributeError(name)
