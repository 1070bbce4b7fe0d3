"""openmm_symprk: symplectic partitioned Runge-Kutta integrators for OpenMM."""
from .catalogue import UnknownMethodError, get_method, methods
from .integrators import PRKIntegrator, SimulationBlowUpError, SymplecticIntegrator, step_size_in_ps
from .splitting import Splitting, compose
from .tableau import PRKTableau, TableauError

__version__ = "0.1.0"
