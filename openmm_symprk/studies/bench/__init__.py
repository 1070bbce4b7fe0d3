"""``symprk bench``: speed against accuracy, and where each method stops being stable.

Modules: :mod:`.toys` (analytic oscillators with exact solutions), :mod:`.scenes` (the scene registry
and user systems), :mod:`.measure` (observables), :mod:`.runs` (one run), :mod:`.stability` (largest
stable step by bisection), :mod:`.store` (finished runs on disk), :mod:`.presets` (quick and full
sweeps), :mod:`.sweep` (scenes x methods x steps in parallel, resumable), :mod:`.charts` (figures) and
:mod:`.cli` (the command line).  Python use::

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
