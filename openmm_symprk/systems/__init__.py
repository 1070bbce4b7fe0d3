"""OpenMM Systems: their facts (:mod:`.properties`), what they let a simulation conserve (:mod:`.checks`),
initial states (:mod:`.prepare`) and the minimal scenes used by the tests, the demo and the studies
(:mod:`.scenes`)."""
from .checks import ConservationWarning, conservation_issues, validate_system, warn_once
from .properties import (constraint_violation, degrees_of_freedom, has_constraints, masses, molecules,
                         signature)

__all__ = ["ConservationWarning", "conservation_issues", "validate_system", "warn_once", "constraint_violation",
           "degrees_of_freedom", "has_constraints", "masses", "molecules", "signature"]
