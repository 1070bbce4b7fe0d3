"""Support for every layer (imports nothing else of the package, and no OpenMM): optional dependencies
imported on first use with an error that names the extra installing them (:mod:`.optional`)."""
from .optional import EXTRAS, MissingDependencyError, require

__all__ = ["EXTRAS", "MissingDependencyError", "require"]
