"""MDAnalysis analyses of water on any trajectory MDAnalysis reads (GROMACS, AMBER, CHARMM/NAMD, LAMMPS,
OpenMM ...), built on the package's analysis kernels (:mod:`openmm_symprk.analysis`, which work in nm), each with
its error.  They speak MDAnalysis' units, Angstrom and ps, in their inputs and results (K for temperatures; D
in 1e-5 cm^2/s, water's literature unit), use the names of MDAnalysis' own classes where they compute the same
(``SelfDiffusion``: EinsteinMSD's ``timeseries``, ``msds_by_particle``; ``RadialDistribution``: InterRDF's
``bins``, ``edges``, ``rdf``, ``nbins``, ``range``), and name each result's unit in ``results.units``::

    import MDAnalysis as mda
    from openmm_symprk.analysis.universe import Reorientation, SelfDiffusion
    u = mda.Universe("water.tpr", "water.trr")
    d = SelfDiffusion(u, window_ps=(2, 20)).run()
    d.results.D, d.results.se                       # 1e-5 cm^2/s (d.results.units["D"])
    d.results.timeseries                            # the MSD, Angstrom^2, at lags d.results.lag_ps (ps)
    r = Reorientation(u).run()
    r.results.tau["dipole"]["tau2"]                 # ps, with its jackknife error

:class:`SelfDiffusion`, :class:`Reorientation`, :class:`AngularVelocityCorrelation` (velocities needed),
:class:`KineticTemperatures` (velocities needed), :class:`RadialDistribution`; :func:`find_waters` finds the
waters they work on.  As in MDAnalysis, the frames to analyse are chosen in ``.run(start, stop, step)``; a
constructor refuses keywords it does not take.  Importing this module needs MDAnalysis
(``pip install 'openmm_symprk[analysis]'``).
"""
from .angular import AngularVelocityCorrelation
from .base import Waters, WaterFrames, find_waters
from .diffusion import SelfDiffusion
from .reorientation import VECTORS, Reorientation
from .structure import RadialDistribution
from .temperatures import KineticTemperatures

__all__ = ["AngularVelocityCorrelation", "KineticTemperatures", "RadialDistribution", "Reorientation",
           "SelfDiffusion", "VECTORS", "WaterFrames", "Waters", "find_waters"]
