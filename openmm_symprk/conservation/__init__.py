"""Conservation diagnostics: float64 figures from a live Context (:mod:`.diagnostics`), reporters for
``app.Simulation`` (:mod:`.reporters`) and MDAnalysis analysis of stored trajectories (:mod:`.analysis`,
imported on first use: it needs MDAnalysis)."""
from .diagnostics import (Diagnostics, angular_momentum, constraint_violation, degrees_of_freedom, diagnostics,
                          energies, kinetic_energy, kinetic_temperatures, linear_momentum, masses_of,
                          molecule_angular_momentum, molecules)
from .reporters import ConservationReporter, VelocityTRRReporter, write_topology

__all__ = ["Diagnostics", "angular_momentum", "constraint_violation", "degrees_of_freedom", "diagnostics", "energies",
           "kinetic_energy", "kinetic_temperatures", "linear_momentum", "masses_of", "molecule_angular_momentum", "molecules",
           "ConservationReporter", "VelocityTRRReporter", "write_topology"]
