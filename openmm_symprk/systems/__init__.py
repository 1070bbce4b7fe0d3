"""OpenMM Systems: their facts (:mod:`.properties`, their hydrogens: :mod:`.hydrogens`), what they let a simulation
conserve (:mod:`.checks`), the steps measured on Systems of their kind (:mod:`.step_limits`), initial states (:mod:`.prepare`) and the minimal scenes used by the tests, the demo and the studies
(:mod:`.scenes`)."""
from .checks import ConservationWarning, conservation_issues, validate_system, warn_once
from .properties import (constraint_violation, degrees_of_freedom, has_constraints, masses, molecules,
                         signature)
from .step_limits import StepLimitWarning

__all__ = ["ConservationWarning", "conservation_issues", "validate_system", "warn_once", "constraint_violation",
           "degrees_of_freedom", "has_constraints", "masses", "molecules", "signature", "StepLimitWarning"]
