"""openmm_symprk: symplectic partitioned Runge-Kutta integrators for OpenMM.

    from openmm_symprk import SymplecticIntegrator, catalogue
    integrator = SymplecticIntegrator(2*unit.femtoseconds, "yoshida-4", system=system)
    catalogue["yoshida-4"].order                    # the catalogue: name or alias -> Method

The package by layer (each imports only from the ones above it):

* :mod:`.support` -- optional dependencies imported on first use (an error names the extra installing them);
* :mod:`.methods` -- tableaux, splittings, the catalogue (``catalogue`` here), :func:`resolve`, pure-numpy
  reference integrators (no OpenMM);
* :mod:`.physics` -- momenta, inertia and rigid motion on arrays, about a stated point (no OpenMM);
* :mod:`.systems` -- facts of an OpenMM System, conservation checks, initial states, minimal scenes;
* :mod:`.plugin` -- the compiled OpenMM plugin and its loader;
* :mod:`.integrators` -- the integrators on two backends, one base: CustomIntegrator programs
  (:mod:`.integrators.custom_backend`) and the native plugin's integrator (:mod:`.integrators.native_backend`);
* :mod:`.conservation`, :mod:`.rigid` -- diagnostics, reporters, MDAnalysis analysis; rigid bodies (Euler's
  equations, rigid groups in a System);
* :mod:`.studies` -- demo, bench, conservation table, speed; :mod:`.cli` -- the ``symprk`` command.

Heavier parts (rigid bodies, diagnostics, reporters, MDAnalysis analysis, studies) load on first use.
"""
from importlib import import_module

from .integrators import (CheckpointMismatchError, CustomSymplecticIntegrator, NativeSymplecticIntegrator,
                          PRKIntegrator, SimulationBlowUpError, SymplecticIntegrator, SystemMismatchError, deserialize,
                          restore, step_size_in_ps)
from .methods import PRKTableau, ResolvedMethod, Splitting, TableauError, UnknownMethodError, compose, get_method, resolve
from .methods.catalogue import methods as catalogue

__version__ = "0.3.0"

# name -> module that defines it, imported lazily (keeps `import openmm_symprk` light)
_LAZY = {
    "make_rigid": ".rigid.groups",
    "RigidGroup": ".rigid.groups",
    "RigidGroupError": ".rigid.groups",
    "RigidGroupWarning": ".rigid.groups",
    "linear_momentum": ".conservation.diagnostics",
    "angular_momentum": ".conservation.diagnostics",
    "diagnostics": ".conservation.diagnostics",
    "ConservationReporter": ".conservation.reporters",
    "VelocityTRRReporter": ".conservation.reporters",
    "split_forces": ".systems.forcegroups",
    "lowered_target": ".integrators.shadow",
}


def __getattr__(name):
    if name in _LAZY:
        return getattr(import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module 'openmm_symprk' has no attribute {name!r}")


__all__ = ["SymplecticIntegrator", "PRKIntegrator", "CustomSymplecticIntegrator", "NativeSymplecticIntegrator",
           "PRKTableau", "Splitting", "compose", "catalogue", "get_method", "resolve", "ResolvedMethod", "UnknownMethodError", "TableauError",
           "SimulationBlowUpError", "SystemMismatchError", "CheckpointMismatchError", "restore", "deserialize",
           "step_size_in_ps", *_LAZY]
