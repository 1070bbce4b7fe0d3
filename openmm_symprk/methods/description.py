"""A method as plain JSON data, and back: what a compiled program stores of a method that is not in the catalogue,
so that the program read back from XML resolves the same method again (:mod:`openmm_symprk.integrators.restore`).

    describe(Splitting([("kick", "1/2"), ("drift", 1), ("kick", "1/2")]))
    # {"splitting": [["kick", "1/2"], ["drift", "1"], ["kick", "1/2"]]}
    from_description({"catalogue": "pefrl"})                   # the catalogue's Method

A catalogue method is described by its name, a :class:`~.splitting.Splitting` by its exact coefficients (fractions
as strings), a :class:`~.tableau.PRKTableau` by its arrays (the shortest decimal strings that give back the same
values in its precision), that precision and its name.
"""
from __future__ import annotations

import numpy as np

from .catalogue import get_method
from .resolved import ResolvedMethod
from .splitting import Splitting
from .tableau import PRKTableau
from ..support.errors import InputError

__all__ = ["describe", "from_description"]


def _number(x) -> str:
    return np.format_float_scientific(x, unique=True, trim="-")


def describe(method) -> dict:
    """The description of a catalogue name or Method, a Splitting, a PRKTableau or a ResolvedMethod (its catalogue
    entry, or the tableau or sequence it was resolved from)."""
    if isinstance(method, ResolvedMethod):
        method = method.entry or (method.tableau if method.tableau is not None else method.splitting)
    if isinstance(method, Splitting):
        return {"splitting": [[label, str(c)] for label, c in method.steps]}
    if isinstance(method, PRKTableau):
        arrays = {k: np.vectorize(_number, otypes=[object])(getattr(method, k)).tolist()
                  for k in ("A", "b", "A_hat", "b_hat")}
        return {"tableau": arrays, "dtype": method.dtype.name, "name": method.name}
    return {"catalogue": get_method(method).name}


def from_description(description: dict):
    """The catalogue Method, Splitting or PRKTableau of a :func:`describe` result (ValueError for anything else)."""
    if "catalogue" in description:
        return get_method(description["catalogue"])
    if "splitting" in description:
        return Splitting((label, c) for label, c in description["splitting"])
    if "tableau" in description:
        t = description["tableau"]
        return PRKTableau(t["A"], t["b"], t["A_hat"], t["b_hat"], name=description.get("name"),
                          dtype=np.dtype(description.get("dtype", "float64")))
    raise InputError(f"not the description of a method (keys catalogue, splitting or tableau): {description!r}")
