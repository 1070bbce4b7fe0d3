"""What a row of the fidelity study is: a label of the studies' one row type, :class:`~..core.rows.Row` (the rows
are one line each in :mod:`.presets`; :mod:`.simulation` runs them).  A row is stored, and hashed into its
runs' keys, as its canonical label (what :attr:`Row.label` writes back).

:func:`check_row` validates a row and names what is wrong; :func:`label` names it; :func:`to_row` reads it;
:func:`describe` gives its label, ensemble, force evaluations per step, whether it keeps the total momentum and
whether it has a conserved effective energy; :func:`for_model` swaps the rows that hold for one water model only
(a thermostat target lowered for its box) for another model's (:func:`counterparts`); :func:`foreign_rows` finds
those left behind.
"""
from __future__ import annotations

import dataclasses

from ..core.rows import Row
from ...support.errors import InputError

__all__ = ["check_row", "describe", "label", "to_row", "is_verlet_limit", "for_model", "foreign_rows", "counterparts"]


def to_row(row, temperature: float = 300.0) -> Row:
    """The :class:`~..core.rows.Row` of a fidelity row (a label, or a Row) at the study's ``temperature``."""
    if isinstance(row, Row):
        return row
    if not isinstance(row, str):
        raise InputError(f"row {row!r}: a row is a label such as 'verlet 2 fs' or 'omelyan-2 4 fs SVR 0.1 ps' "
                         f"(the grammar of openmm_symprk.studies.core.rows)")
    return Row.parse(row, temperature=float(temperature))


def check_row(row) -> str:
    """The canonical label of ``row``; ValueError naming the row and what is wrong otherwise."""
    r = to_row(row)
    if r.is_rigid:
        raise InputError(f"row {row!r}: the fidelity study runs OpenMM integrators on a constrained System, not "
                         f"rigid-body engines")
    r.require_kick_drift("rigid water")
    return r.label


def label(row) -> str:
    """e.g. 'verlet 0.5 fs', 'omelyan-2 4 fs SVR 1 ps', 'langevin 4 fs friction 1/ps HMR 3 Da' (:attr:`Row.label`)."""
    return to_row(row).label


def is_verlet_limit(row, ensemble: str, tau_ps: float | None = None) -> bool:
    """Whether ``row`` is one of the Verlet rows extrapolated to h -> 0 for ``ensemble``: the package's Verlet
    without HMR or MTS, NVE; or (NVT) with the thermostat in the middle of the step at collision time ``tau_ps``."""
    r = to_row(row)
    if r.who != "verlet" or r.hmr_da is not None or r.mts or r.ensemble != ensemble:
        return False
    return ensemble == "NVE" or (r.position == "middle" and r.every == 1 and r.tau_ps == tau_ps)


def describe(row) -> dict:
    """label; ensemble ("NVE" or "NVT"); evals_per_step (force evaluations of the resolved method under constraints;
    MTS: force-group evaluations); keeps_momentum; effective_energy (a conserved effective energy: NVE's total
    energy, or total + heat-bath energy); family ("symprk" or "openmm"); hmr; step_fs."""
    r = to_row(row)
    return {"label": r.label, "ensemble": r.ensemble, "evals_per_step": r.evals_per_step(constraints=True),
            "keeps_momentum": r.keeps_momentum, "effective_energy": r.conserves_effective_energy,
            "family": "symprk" if r.is_ours else "openmm", "hmr": r.hmr_da is not None, "step_fs": r.step_fs}


def _bare(lab: str, temperature: float) -> str:
    """A lowered-target row's label at the study's ``temperature``: the method, step and thermostat it shares with the
    same row lowered for another water model."""
    row = to_row(lab, temperature)
    return dataclasses.replace(row, temperature=float(temperature)).label


def counterparts(cfg: dict, model: str) -> dict:
    """{label: the same row lowered for ``model``, or None where ``model`` has none} of every row of
    ``cfg["lowered_rows"]`` ({model: labels}) that belongs to another model."""
    temperature = float(cfg.get("temperature", 300.0))
    lowered = cfg.get("lowered_rows") or {}
    own = {_bare(lab, temperature): label(lab) for lab in lowered.get(model, ())}
    return {label(lab): own.get(_bare(lab, temperature)) for m, labs in lowered.items() if m != model for lab in labs}


def foreign_rows(cfg: dict, rows: list) -> dict:
    """{label: the model's own row or None} of the ``rows`` whose target is lowered for another water model than
    ``cfg["model"]`` (:func:`counterparts`)."""
    swap = counterparts(cfg, cfg.get("model", "spce"))
    return {lab: swap[lab] for lab in map(label, rows) if lab in swap}


def for_model(cfg: dict, model: str) -> dict:
    """``cfg`` for water ``model``: ``cfg["model"]`` set, and each row of ``cfg["lowered_rows"]`` that belongs to
    another model (its target lowered for that model's box) replaced, in the rows, the deciding and side rows and the
    per-row replica counts, by the model's own row of the same method, step and thermostat, or left out where the model
    has none (a preset's side rows measured in one model only).  A config without ``lowered_rows`` only gets the
    model; the rows are otherwise kept as written (duplicates included, for :func:`..simulation.study.check` to
    name)."""
    cfg["model"] = model
    swap = counterparts(cfg, model)

    def new(lab):
        return swap.get(label(lab), lab)

    for key in ("rows", "deciding", "side"):
        if key in cfg:
            cfg[key] = [new(lab) for lab in cfg[key] if new(lab) is not None]
    if cfg.get("row_replicas"):
        cfg["row_replicas"] = {new(lab): n for lab, n in cfg["row_replicas"].items() if new(lab) is not None}
    return cfg
