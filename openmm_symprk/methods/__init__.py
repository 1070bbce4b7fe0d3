"""The methods themselves, as data and pure numerics: no OpenMM here (a test checks it).

* :mod:`.splitting` -- kick/drift sequences with exact rational coefficients, merging, composition;
* :mod:`.tableau` -- PRK tableau pairs, validation, Reich's conditions (6)-(7), splitting <-> PRK;
* :mod:`.catalogue` and ``data/*.toml`` -- the named methods (coefficients live in the data files);
* :mod:`.reference` -- pure-numpy integrators on model problems (float64 or long double);
* :mod:`.stability` -- linear stability intervals; :mod:`.orders` -- the observed-order fit.
"""
from .catalogue import Method, UnknownMethodError, format_table, get_method, methods
from .splitting import DRIFT, KICK, Splitting, compose
from .tableau import PRKTableau, TableauError

__all__ = ["Method", "UnknownMethodError", "format_table", "get_method", "methods", "DRIFT", "KICK", "Splitting",
           "compose", "PRKTableau", "TableauError"]
