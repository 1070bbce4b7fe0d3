"""Multiple time stepping for both backends: the kick/drift sequence of ``groups=`` and ``inner_method=``.

The sequence comes from :func:`openmm_symprk.methods.respa.respa`; this module picks each level's method
(under constraints a composition is taken over the RATTLE base, as for a single level), checks the groups
against the System when there is one, and gives the force-group mask of every kick for the native plugin.
"""
from __future__ import annotations

from ..methods.catalogue import Method, get_method
from ..methods.respa import MTSError, label_groups, levels, respa
from ..methods.splitting import DRIFT, Splitting
from ..systems.forcegroups import check_groups

__all__ = ["mts_splitting", "kick_masks", "describe_levels", "MTSError"]


def _splitting_of(method, constraints: bool) -> Splitting:
    if isinstance(method, Splitting):
        return method
    m = method if isinstance(method, Method) else get_method(method)
    if not m.is_splitting:
        raise MTSError(f"multiple time stepping needs kick/drift methods at every level; {m.name!r} is a general "
                       f"({m.family}) PRK tableau")
    return m.constrained_splitting if constraints else m.splitting


def mts_splitting(method, groups, inner_method=None, constraints: bool = True, system=None):
    """(splitting, levels) of one step; ``inner_method`` defaults to ``method``."""
    outer = _splitting_of(method, constraints)
    inner = _splitting_of(method if inner_method is None else inner_method, constraints)
    lv = levels(groups, outer, inner)
    if system is not None:
        check_groups(system, [(g, level.substeps) for level in lv for g in level.groups])
    return respa(lv), lv


def kick_masks(splitting: Splitting) -> list:
    """The plugin's force-group mask of every sub-step (-1 for drifts and for kicks of all forces)."""
    out = []
    for label, _ in splitting.steps:
        groups = None if label == DRIFT else label_groups(label)
        out.append(-1 if groups is None else sum(1 << g for g in groups))
    return out


def describe_levels(levels_, evals_per_group=None) -> str:
    """One line: each level's groups, substeps and evaluations per step."""
    evals = evals_per_group or {}
    parts = [f"groups {','.join(map(str, lv.groups))} x{lv.substeps}"
             + (f" ({evals[tuple(lv.groups)]} evaluations per step)" if tuple(lv.groups) in evals else "")
             for lv in levels_]
    return "multiple time stepping, slowest first: " + "; ".join(parts)
