"""What users compute from a trajectory of water or a solvated system: the observables of the fidelity study,
as kernels on plain arrays (nm, ps, Da, e) and as MDAnalysis analyses of any Universe.

Kernels (numpy; g(r) through MDAnalysis' InterRDF), each with known-answer tests in tests/analysis/:

- :mod:`.molecules` - molecules made whole across the box, their centres of mass and centre-of-mass frames;
- :mod:`.correlation` - time correlation functions averaged over every time origin, by FFT;
- :mod:`.diffusion` - unwrapping, MSD by FFT, the self-diffusion coefficient with its error (1e-5 cm^2/s),
  the Yeh-Hummer finite-size correction;
- :mod:`.reorientation` - Legendre correlation functions C_1, C_2 of the dipole / bisector / H-H / O-H vectors
  and the correlation times tau_1, tau_2;
- :mod:`.angular` - the molecules' angular velocity (space or body frame) and its autocorrelation;
- :mod:`.structure` - the radial distribution function g(r) and its first peak;
- :mod:`.literature` - constants and published model data (viscosities) with their sources.

Errors come from the package's statistics (:mod:`openmm_symprk.stats`: the jackknife over molecules, block
and correlated-series errors).  :mod:`openmm_symprk.analysis.universe` runs the same kernels on any
MDAnalysis Universe (imported on first use: it needs MDAnalysis); ``symprk observe`` (:mod:`.cli`) prints them
for a trajectory file.
"""
from . import angular, correlation, diffusion, literature, molecules, reorientation, structure

__all__ = ["angular", "correlation", "diffusion", "literature", "molecules", "reorientation", "structure"]
