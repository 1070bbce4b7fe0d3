"""Support for every layer (imports nothing else of the package, and no OpenMM): optional dependencies
imported on first use with an error that names the extra installing them (:mod:`.optional`), and files written
atomically, the package's one writer of JSON, text and array files (:mod:`.files`)."""
from .optional import EXTRAS, MissingDependencyError, require

__all__ = ["EXTRAS", "MissingDependencyError", "require"]
