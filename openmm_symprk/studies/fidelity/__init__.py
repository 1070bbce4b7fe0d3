"""What users compute from a trajectory, per method and step (issue 21): the fidelity study.

The observables it measures (diffusion, reorientation, the angular-velocity autocorrelation, g(r), the kinetic
temperatures) are the package's analysis kernels, :mod:`openmm_symprk.analysis`, called on the frames each run
keeps in memory; the same kernels run on any trajectory through :mod:`openmm_symprk.analysis.universe`.

The study (``symprk fidelity``, docs/fidelity.md) is built on them and on the study skeleton: :mod:`.presets`
(its settings and rows, data), :mod:`.rowspec` (a row's description), :mod:`.observables` (every observable of one
run from its frames), :mod:`.extrapolation` (an observable extrapolated to step size h -> 0, fit a + b h^2),
:mod:`.simulation` (one run's frames from a replica state, the study), :mod:`.report` (tables, pairing, the
extrapolated reference, verdicts, chart) and :mod:`.cli`.  Only the pure modules are imported here.
"""
from . import extrapolation, presets

__all__ = ["extrapolation", "presets"]
