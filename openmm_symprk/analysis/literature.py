"""Constants and published model data the fidelity observables use, each with its source."""

__all__ = ["NM2_PER_PS_IN_1E5_CM2_PER_S", "K_BOLTZMANN", "XI_CUBIC", "VISCOSITY_MPAS"]

#: 1 nm^2/ps expressed in the literature's unit for diffusion coefficients, 1e-5 cm^2/s.
NM2_PER_PS_IN_1E5_CM2_PER_S = 1000.0
#: Boltzmann's constant, J/K (exact, SI 2019).
K_BOLTZMANN = 1.380649e-23
#: xi of a cubic periodic lattice in the Yeh-Hummer correction (Yeh & Hummer, J. Phys. Chem. B 108, 15873, 2004).
XI_CUBIC = 2.837297
#: Shear viscosity of the rigid water models, mPa s, at 298 K and 1 bar, from equilibrium MD (Green-Kubo):
#: M. A. González and J. L. F. Abascal, J. Chem. Phys. 132, 096101 (2010), "The shear viscosity of rigid water
#: models" (experiment: 0.896 mPa s).  The models' viscosity, not water's, is what the correction needs.
VISCOSITY_MPAS = {"spce": 0.729, "tip3p": 0.321}
