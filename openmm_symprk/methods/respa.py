"""Multiple time stepping (r-RESPA) as one more splitting (pure Python, exact arithmetic).

Split the potential into force groups, V = V_slow + V_fast (or more levels).  Each level runs a kick/drift
method whose kicks use that level's forces and whose drifts are replaced by the next level's integration over
the drift's time; the innermost level drifts.  With Verlet at every level this is the r-RESPA of Tuckerman,
Berne and Martyna (J. Chem. Phys. 97, 1990 (1992)) that OpenMM's ``MTSIntegrator`` runs.  The result is one
kick/drift sequence whose kicks are labelled with their force groups (``"kick:1"``, ``"kick:0,2"``): it is a
composition of symplectic maps, so it is symplectic, and every group that is translation and rotation
invariant keeps linear and angular momentum exactly (docs/theory.md, section 5).

Levels come in the form OpenMM's ``MTSIntegrator`` takes: ``[(force group, substeps), ...]``, ``substeps``
being how many times the group is evaluated per step when every level runs Verlet (one kick per step).  In
general a level with ``n`` substeps runs ``n / n_parent`` steps of its method inside every drift of the level
above it (``n_parent`` = 1 for the outermost level).  Groups with the same substeps form one level.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from .splitting import DRIFT, KICK, Splitting
from ..support.errors import InputError

__all__ = ["Level", "MTSError", "kick_label", "label_groups", "mts_groups", "levels", "respa", "evaluations_per_step"]

KICK_PREFIX = KICK + ":"


class MTSError(InputError):
    """A malformed multiple-time-step specification (the message names the bad entry)."""


def kick_label(groups) -> str:
    """The label of a kick with the forces of ``groups`` (sorted force-group indices)."""
    return KICK_PREFIX + ",".join(str(g) for g in sorted(groups))


def label_groups(label: str):
    """The force groups of a kick label (a tuple), None for a plain kick (all forces), or ValueError."""
    if label == KICK:
        return None
    if not label.startswith(KICK_PREFIX):
        raise ValueError(f"{label!r} is not a kick label")
    return tuple(int(g) for g in label[len(KICK_PREFIX):].split(","))


@dataclass(frozen=True)
class Level:
    groups: tuple  # force groups kicked at this level
    substeps: int  # evaluations per step of this level's forces when every level runs Verlet
    splitting: Splitting  # this level's kick/drift method


def mts_groups(groups) -> tuple:
    """``[(force group, substeps), ...]`` checked and made a tuple of int pairs (MTSError naming the bad entry)."""
    try:
        entries = [(g, n) for g, n in groups]
    except (TypeError, ValueError):
        raise MTSError(f"groups must be a list of (force group, substeps) pairs, e.g. [(0, 1), (1, 2)]; "
                       f"got {groups!r}") from None
    if not entries:
        raise MTSError("groups is empty: give at least one (force group, substeps) pair, e.g. [(0, 1), (1, 2)]")
    seen = set()
    for g, n in entries:
        if isinstance(g, bool) or not isinstance(g, int) or not 0 <= g <= 31:
            raise MTSError(f"force group {g!r} in {(g, n)}: a force group is an integer from 0 to 31")
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise MTSError(f"substeps {n!r} in {(g, n)}: substeps is a whole number >= 1 (evaluations per step)")
        if g in seen:
            raise MTSError(f"force group {g} appears twice in {entries}")
        seen.add(g)
    return tuple((int(g), int(n)) for g, n in entries)


def levels(groups, outer: Splitting, inner: Splitting) -> list:
    """Validated levels from ``[(force group, substeps), ...]`` (:func:`mts_groups`), slowest first; the outermost
    level runs ``outer``, every other level ``inner``."""
    by_n: dict = {}
    for g, n in mts_groups(groups):
        by_n.setdefault(n, []).append(g)
    out, parent = [], 1
    for i, n in enumerate(sorted(by_n)):
        if n % parent:
            raise MTSError(f"substeps {n} is not a multiple of the next slower level's {parent}: each level must "
                           f"run a whole number of steps inside every step of the level above it")
        out.append(Level(tuple(sorted(by_n[n])), n, outer if i == 0 else inner))
        parent = n
    return out


def respa(levels_) -> Splitting:
    """The kick/drift sequence of one step of the multiple-time-step method (see the module docstring)."""
    if not levels_:
        raise MTSError("no levels")
    for lv in levels_:
        bad = sorted(set(lv.splitting.labels) - {KICK, DRIFT})
        if bad:
            raise MTSError(f"the method of a level must be a kick/drift splitting; it has {bad}")

    def expand(i: int, parent_substeps: int, scale: Fraction) -> list:
        lv = levels_[i]
        n = lv.substeps // parent_substeps
        label = kick_label(lv.groups)
        seq = []
        for _ in range(n):
            for kind, c in lv.splitting.steps:
                tau = c * scale / n
                if kind == KICK:
                    seq.append((label, tau))
                elif i + 1 < len(levels_):
                    seq.extend(expand(i + 1, lv.substeps, tau))
                else:
                    seq.append((DRIFT, tau))
        return seq

    return Splitting(expand(0, 1, Fraction(1)))


def evaluations_per_step(splitting: Splitting) -> dict:
    """{force groups (tuple, or None for all forces): evaluations per step in a long run}."""
    return {label_groups(label): splitting.force_evaluations(label)
            for label in dict.fromkeys(lab for lab in splitting.labels if lab != DRIFT)}
