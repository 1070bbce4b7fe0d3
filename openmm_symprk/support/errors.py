"""The errors the package raises on purpose, told apart from the errors of a bug.

Every error class of the package derives from :class:`SymprkError` besides its usual base (``ValueError``,
``ImportError``, ``RuntimeError`` ...), so ``except ValueError`` in a user's code catches it as before, and the
``symprk`` command (:mod:`openmm_symprk.cli`) prints it as one line: an exception that is not a
:class:`SymprkError` (a tuple that does not unpack, an ImportError of a typo) is a bug and keeps its traceback.

An input check raises :class:`InputError`, a ValueError::

    from ..support.errors import InputError

    if not n >= 1:
        raise InputError(f"n_waters must be at least 1, got {n}")

A new error class of the package mixes :class:`SymprkError` in: ``class TableauError(SymprkError, ValueError)``.
"""
from __future__ import annotations

__all__ = ["SymprkError", "InputError"]


class SymprkError(Exception):
    """An error the package raises on purpose: the input (a value, a name, a file, a platform, a missing extra) is
    wrong or cannot be run, and the message says what and how to fix it."""


class InputError(SymprkError, ValueError):
    """A value the package's input checks refuse (an unknown name, a number out of range, settings that do not go
    together): a ValueError that is a user's error, not a bug."""
