"""One parser for the positive physical quantities integrators take (step size, temperature, collision time):
a Quantity in compatible units, or a plain number taken in the stated unit; bools, other units, non-numbers,
zero, negative and non-finite values are refused with an error that names the value and shows what is
accepted."""
from __future__ import annotations

import math

import numpy as np
import openmm.unit as unit

from ..support.errors import InputError

__all__ = ["positive_quantity"]


def positive_quantity(value, name: str, in_unit, kind: str, example: str) -> float:
    """``value`` as a float in ``in_unit``, positive and finite.

    ``name`` is how the message calls it ("step size"), ``kind`` what it must be ("time"), ``example`` an
    accepted value ("2*unit.femtoseconds")."""
    hint = f"give e.g. {example} (a plain number is taken as {in_unit.get_name()})"
    raw = value._value if unit.is_quantity(value) else value
    if isinstance(raw, (bool, np.bool_)):
        raise TypeError(f"{name} {value!r} is a truth value, not a {kind}: {hint}")
    if unit.is_quantity(value):
        if not value.unit.is_compatible(in_unit):
            raise TypeError(f"{name} {value} is not a {kind}: {hint}")
        number = value.value_in_unit(in_unit)
    else:
        number = value
    try:
        number = float(number)
    except (TypeError, ValueError):
        raise TypeError(f"{name} {value!r} is not a {kind}: {hint}") from None
    if not math.isfinite(number) or number <= 0:
        raise InputError(f"{name} must be positive and finite, got {value} ({hint})")
    return number
