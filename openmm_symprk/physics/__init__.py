"""Shared physics on plain arrays (nm, ps, Da; pure numpy, no OpenMM): one definition of each quantity.

:mod:`.momenta` -- centre of mass, linear momentum, angular momentum and inertia tensor *about a stated
point* (there is no default: "com" and "origin" give different numbers, and both are conserved in an
isolated system).  Massless particles (virtual sites) carry no momentum and drop out of every sum.
:mod:`.rigid_motion` -- a rigid group's principal axes, rigid-motion velocities, body frame and body-frame angular
momentum.
:mod:`.temperature` -- translational and rotational kinetic energy and temperature of molecules.
:mod:`.velocity_rescaling` -- the numerics of the stochastic velocity-rescaling thermostat.
"""
from .momenta import angular_momentum, centre_of_mass, inertia_tensor, kinetic_energy, linear_momentum
from .temperature import KineticTemperatures, kinetic_temperatures, molecule_kinetics

__all__ = ["angular_momentum", "centre_of_mass", "inertia_tensor", "kinetic_energy", "linear_momentum",
           "KineticTemperatures", "kinetic_temperatures", "molecule_kinetics"]
