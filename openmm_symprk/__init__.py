"""openmm_symprk: symplectic partitioned Runge-Kutta integrators for OpenMM.

    from openmm_symprk import SymplecticIntegrator, methods
    integrator = SymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)

Heavier parts (rigid bodies, diagnostics, reporters, MDAnalysis analysis, benchmarks) load on first use.
"""
from importlib import import_module

from .catalogue import UnknownMethodError, get_method, methods
from .integrators import PRKIntegrator, SimulationBlowUpError, SymplecticIntegrator, step_size_in_ps
from .splitting import Splitting, compose
from .tableau import PRKTableau, TableauError

__version__ = "0.1.0"

# name -> module that defines it, imported lazily (keeps `import openmm_symprk` light)
_LAZY = {
    "rigidbody": ".rigidbody",
    "native": ".native",
    "make_rigid": ".rigid_molecules",
    "RigidGroup": ".rigid_molecules",
    "RigidGroupError": ".rigid_molecules",
    "RigidGroupWarning": ".rigid_molecules",
    "linear_momentum": ".conservation",
    "angular_momentum": ".conservation",
    "diagnostics": ".conservation",
    "ConservationReporter": ".reporters",
    "VelocityTRRReporter": ".reporters",
}


def __getattr__(name):
    if name in _LAZY:
        module = import_module(_LAZY[name], __name__)
        return module if module.__name__.endswith("." + name) else getattr(module, name)
    raise AttributeError(f"module 'openmm_symprk' has no attribute {name!r}")


__all__ = ["SymplecticIntegrator", "PRKIntegrator", "PRKTableau", "Splitting", "compose", "methods",
           "get_method", "UnknownMethodError", "TableauError", "SimulationBlowUpError", "step_size_in_ps",
           *_LAZY]
