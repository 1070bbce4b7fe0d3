"""Splitting methods as labelled coefficient sequences (pure Python, exact arithmetic).

A splitting step is a sequence of sub-flows applied left to right, each a label and a coefficient:
``("kick", b)`` means v += b*h*F/m, ``("drift", a)`` means x += a*h*v.  The same machinery serves
any number of parts (the rigid-body Lie-Poisson splitting uses labels "X1", "X2", "X3").

Coefficients are kept as :class:`fractions.Fraction` built from the decimal strings of the
catalogue, so compositions and merges are exact; conversion to float64 or long double happens once,
at the end (:meth:`Splitting.coefficients`).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from fractions import Fraction
from typing import Iterable, Sequence

import numpy as np

from ..support.errors import InputError

KICK = "kick"
DRIFT = "drift"


def exact(value) -> Fraction:
    """Exact rational value of a coefficient given as str, int, Fraction or float."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, (int, np.integer)):
        return Fraction(int(value))
    if isinstance(value, str):
        try:
            return Fraction(value.strip())
        except ValueError:
            raise InputError(f"coefficient {value!r} is not a number") from None
    value = float(value)
    if not np.isfinite(value):
        raise InputError(f"coefficient {value!r} is not finite")
    return Fraction(value)


def to_dtype(value: Fraction, dtype=np.float64):
    """Convert an exact coefficient to ``dtype`` with correct rounding (also for long double)."""
    if np.dtype(dtype) == np.dtype(np.longdouble):
        # numpy parses long double from a decimal string at full precision; 30 digits is plenty.
        return np.longdouble(_decimal_string(value, 30))
    return np.dtype(dtype).type(float(value))


def _decimal_string(value: Fraction, digits: int) -> str:
    from decimal import Decimal, getcontext

    getcontext().prec = digits + 5
    return str(Decimal(value.numerator) / Decimal(value.denominator))


@dataclass(frozen=True)
class Splitting:
    """An ordered, merged sequence of (label, exact coefficient) sub-flows."""

    steps: tuple

    def __init__(self, steps: Iterable):
        merged = merge((label, exact(c)) for label, c in steps)
        if not merged:
            raise InputError("a splitting needs at least one sub-flow with a non-zero coefficient")
        object.__setattr__(self, "steps", tuple(merged))

    # -- views --------------------------------------------------------------------------
    @property
    def labels(self) -> tuple:
        return tuple(label for label, _ in self.steps)

    def coefficients(self, dtype=np.float64) -> list:
        """[(label, coefficient as dtype)] in order."""
        return [(label, to_dtype(c, dtype)) for label, c in self.steps]

    def total(self, label: str) -> Fraction:
        """Sum of the coefficients of one part (1 for a consistent method)."""
        return sum((c for lab, c in self.steps if lab == label), Fraction(0))

    def count(self, label: str) -> int:
        return sum(1 for lab, _ in self.steps if lab == label)

    def is_symmetric(self, tol: float = 0.0) -> bool:
        """True if the sequence reads the same backwards (a self-adjoint step)."""
        rev = self.steps[::-1]
        return all(a[0] == b[0] and abs(float(a[1] - b[1])) <= tol for a, b in zip(self.steps, rev))

    def adjoint(self) -> "Splitting":
        return Splitting(self.steps[::-1])

    @cached_property
    def evaluating_kicks(self) -> frozenset:
        """Indices (into ``steps``) of the sub-flows that need a fresh evaluation of their forces in a long run
        (:func:`evaluating_kicks`)."""
        return evaluating_kicks(self.labels)

    def force_evaluations(self, label: str = KICK) -> int:
        """Evaluations of the ``label`` part per step in a long run (see :attr:`evaluating_kicks`)."""
        return sum(1 for i in self.evaluating_kicks if self.steps[i][0] == label)

    def __len__(self):
        return len(self.steps)

    def __iter__(self):
        return iter(self.steps)

    def __str__(self):
        return "\n".join(f"{label:6s} {float(c): .22f}" for label, c in self.steps)


def evaluating_kicks(labels: Sequence, others: Sequence = ()) -> frozenset:
    """Indices (into ``labels``, a step's sequence of sub-flow labels) of the kicks that need a fresh evaluation of
    their forces in a long run; every label but a drift and ``others`` (entries that move nothing, such as a
    thermostat event) is a kick.

    The one rule of the package for cached forces: a sub-flow of a kick label needs an evaluation when the
    positions changed (a drift) since the previous sub-flow of the same label, counted cyclically: the
    closing evaluation of a step is reused by the next step's opening one when no drift separates them
    (first same as last).  Kicks of other labels (force groups of a multiple-time-step sequence) do not
    move the positions, and neither do ``others``.  Every other kick runs on cached forces."""
    labels = list(labels)
    out = set()
    n = len(labels)
    for label in dict.fromkeys(lab for lab in labels if lab != DRIFT and lab not in others):
        kicks = [i for i, lab in enumerate(labels) if lab == label]
        for k, i in enumerate(kicks):
            previous = kicks[k - 1]  # cyclically: the last one of the previous step for the first
            between = range(previous + 1, i) if previous < i else list(range(previous + 1, n)) + list(range(i))
            if len(kicks) == 1 or any(labels[j] == DRIFT for j in between):
                out.add(i)
    return frozenset(out)


def merge(steps: Iterable) -> list:
    """Merge adjacent sub-flows with the same label and drop zero coefficients (exact)."""
    out: list = []
    for label, c in steps:
        if c == 0:
            continue
        if out and out[-1][0] == label:
            total = out[-1][1] + c
            out.pop()
            if total != 0:
                out.append((label, total))
        else:
            out.append((label, c))
    # Dropping a zero can make two equal labels adjacent: merge again until stable.
    if any(a[0] == b[0] for a, b in zip(out, out[1:])):
        return merge(out)
    return out


def compose(base: Splitting, weights: Sequence) -> Splitting:
    """The composition base(w_1 h) o base(w_2 h) o ... (applied left to right), merged.

    For a symmetric base step of order 2 and symmetric weights of a Yoshida/Suzuki/Kahan-Li kind this
    raises the order; it is the single code path for every composition in the package (MD kick/drift
    sequences and rigid-body sub-flows alike)."""
    ws = [exact(w) for w in weights]
    if not ws:
        raise InputError("composition weights must not be empty")
    total = sum(ws, Fraction(0))
    if total != 1 and abs(float(total) - 1.0) > 1e-15:
        raise InputError(f"composition weights must sum to 1, got {float(total)!r}")
    seq = []
    for w in ws:
        seq.extend((label, w * c) for label, c in base.steps)
    return Splitting(seq)

