"""What users compute from a trajectory, per method and step (issue 21): the observables of the fidelity study,
as pure-numpy functions of arrays (nm, ps, Da), each with known-answer tests in tests/studies/fidelity/.

- :mod:`.diffusion` - unwrapping, MSD by FFT, the self-diffusion coefficient with its error (1e-5 cm^2/s),
  the Yeh-Hummer finite-size correction;
- :mod:`.reorientation` - Legendre correlation functions C_1, C_2 of the dipole / bisector / H-H vectors and
  the correlation times tau_1, tau_2;
- :mod:`.angular` - the molecules' angular velocity (space or body frame) and its autocorrelation;
- :mod:`.structure` - the radial distribution function g(r) under periodic boundaries and its first peak;
- :mod:`.extrapolation` - an observable extrapolated to step size h -> 0 (fit a + b h^2);
- :mod:`.molecules`, :mod:`.correlation` - the molecules' centre-of-mass frames along a trajectory, and
  time correlation functions averaged over origins with their jackknife over molecules, shared by the above;
- :mod:`.literature` - constants and published model data (viscosities) with their sources.

The study (``symprk fidelity``, docs/fidelity.md) is built on them and on the study skeleton: :mod:`.presets`
(its settings and rows, data), :mod:`.simulation.engines` (a row made into a running OpenMM integrator),
:mod:`.simulation.runs` (one run: frames at the cadence each observable needs), :mod:`.observe` (every observable
of one run), :mod:`.simulation.study` (:class:`~.simulation.study.FidelityStudy`, replica states shared with the
equipartition study), :mod:`.report` (tables, pairing, the extrapolated reference, verdicts, chart) and
:mod:`.cli`.  Only the pure modules are imported here.
"""
from . import angular, correlation, diffusion, extrapolation, literature, molecules, presets, reorientation, structure

__all__ = ["angular", "correlation", "diffusion", "extrapolation", "literature", "molecules", "presets",
           "reorientation", "structure"]
