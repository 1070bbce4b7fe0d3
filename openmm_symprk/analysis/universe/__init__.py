"""MDAnalysis analyses of water on any trajectory MDAnalysis reads (GROMACS, AMBER, CHARMM/NAMD, LAMMPS,
OpenMM ...), built on the package's analysis kernels (:mod:`openmm_symprk.analysis`), in the package's units (nm,
ps, K; D in 1e-5 cm^2/s), each with its error::

    import MDAnalysis as mda
    from openmm_symprk.analysis.universe import Reorientation, SelfDiffusion
    u = mda.Universe("water.tpr", "water.trr")
    d = SelfDiffusion(u, window_ps=(2, 20)).run()
    d.results.D, d.results.se                       # 1e-5 cm^2/s
    r = Reorientation(u).run()
    r.results.tau["dipole"]["tau2"]                 # ps, with its jackknife error

:class:`SelfDiffusion`, :class:`Reorientation`, :class:`AngularVelocityCorrelation` (velocities needed),
:class:`KineticTemperatures` (velocities needed), :class:`RadialDistribution`; :func:`find_waters` finds the
waters they work on.  Importing this module needs MDAnalysis (``pip install 'openmm_symprk[analysis]'``).
"""
from .angular import AngularVelocityCorrelation
from .base import Waters, WaterFrames, find_waters
from .diffusion import SelfDiffusion
from .reorientation import VECTORS, Reorientation
from .structure import RadialDistribution
from .temperatures import KineticTemperatures

__all__ = ["AngularVelocityCorrelation", "KineticTemperatures", "RadialDistribution", "Reorientation",
           "SelfDiffusion", "VECTORS", "WaterFrames", "Waters", "find_waters"]
