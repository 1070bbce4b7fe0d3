"""Support for every layer (imports nothing else of the package, and no OpenMM): the errors the package raises on
purpose (:mod:`.errors`: one line from the command, where a bug keeps its traceback), optional dependencies
imported on first use with an error that names the extra installing them (:mod:`.optional`), and files written
atomically, the package's one writer of JSON, text and array files (:mod:`.files`)."""
from .errors import InputError, SymprkError
from .optional import EXTRAS, MissingDependencyError, require

__all__ = ["SymprkError", "InputError", "EXTRAS", "MissingDependencyError", "require"]
