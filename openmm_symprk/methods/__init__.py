"""The methods themselves, as data and pure numerics: no OpenMM here (a test checks it).

* :mod:`.splitting` -- kick/drift sequences with exact rational coefficients, merging, composition;
* :mod:`.tableau` -- PRK tableau pairs, validation, Reich's conditions (6)-(7), splitting <-> PRK;
* :mod:`.catalogue` and ``data/*.toml`` -- the named methods (coefficients live in the data files);
  ``methods`` is the catalogue mapping (name or alias -> :class:`~.catalogue.Method`);
* :mod:`.resolved` -- :func:`resolve`: what the user passed, made once into the description of the step that
  will run (its form, sub-steps with their flags, force evaluations, orders), taken by everything that runs a
  method.  A catalogue entry (:class:`~.catalogue.Method`) says what a method is; a
  :class:`~.resolved.ResolvedMethod` how it runs;
* :mod:`.description` -- a method as JSON data and back (what a compiled program stores of a user method);
* :mod:`.respa` -- multiple time stepping as one more kick/drift sequence;
* :mod:`.placement` -- where a velocity thermostat sits in a kick/drift step, and what that does to sampling;
* :mod:`.reference` -- pure-numpy integrators on model problems (float64 or long double);
* :mod:`.stability` -- linear stability intervals; :mod:`.orders` -- the observed-order fit.
"""
from .catalogue import Method, UnknownMethodError, format_table, get_method, methods
from .resolved import ResolvedMethod, Substep, SubstepFlag, SubstepKind, resolve
from .splitting import DRIFT, KICK, Splitting, compose
from .tableau import PRKTableau, TableauError

__all__ = ["Method", "UnknownMethodError", "format_table", "get_method", "methods", "DRIFT", "KICK", "Splitting",
           "compose", "PRKTableau", "TableauError", "resolve", "ResolvedMethod", "Substep", "SubstepKind",
           "SubstepFlag"]
