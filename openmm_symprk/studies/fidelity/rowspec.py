"""What a row of the fidelity study is: its stored form (a dict, whose fields the runs' keys hash) read as the studies'
one row type, :class:`~..core.rows.Row` (the rows are data in :mod:`.presets`; :mod:`.simulation.engines` runs them).

:func:`check_row` validates a row and names what is wrong; :func:`label` names it; :func:`describe` gives its
label, ensemble, force evaluations per step, whether it keeps the total momentum and whether it has a conserved
effective energy.
"""
from __future__ import annotations

from ..core.rows import Row

__all__ = ["KINDS", "UNAVAILABLE_THERMOSTAT", "check_row", "describe", "label", "to_row"]

#: Options each kind of row takes (besides kind, step_fs and hmr_da).
KINDS = {"symprk": {"method", "collision_time_ps"}, "langevin": {"friction_per_ps"},
         "mts-langevin": {"friction_per_ps", "inner_steps"}, "nose-hoover": {"collision_frequency_per_ps"},
         "dpd": {"friction_per_ps", "cutoff_nm"}}
_REQUIRED = {"symprk": {"method"}, "langevin": {"friction_per_ps"}, "mts-langevin": {"friction_per_ps", "inner_steps"},
             "nose-hoover": {"collision_frequency_per_ps"}, "dpd": {"friction_per_ps"}}

#: What the output says for a thermostat row this installation cannot run.
UNAVAILABLE_THERMOSTAT = "unavailable: needs the thermostat"


def check_row(row: dict) -> dict:
    """``row`` with step_fs as a float; ValueError naming the row and the bad field otherwise."""
    if not isinstance(row, dict) or row.get("kind") not in KINDS:
        raise ValueError(f"row {row!r}: kind must be one of {', '.join(KINDS)}")
    kind = row["kind"]
    extra = set(row) - KINDS[kind] - {"kind", "step_fs", "hmr_da"}
    missing = _REQUIRED[kind] - set(row)
    if extra or missing:
        raise ValueError(f"row {row!r}: a {kind} row takes {', '.join(sorted(KINDS[kind] | {'step_fs', 'hmr_da'}))}"
                         + (f"; unknown: {', '.join(sorted(extra))}" if extra else "")
                         + (f"; missing: {', '.join(sorted(missing))}" if missing else ""))
    for k, v in row.items():
        if k not in ("kind", "method") and (isinstance(v, bool) or not float(v) > 0):
            raise ValueError(f"row {row!r}: {k} must be a positive number, got {v!r}")
    if "inner_steps" in row and int(row["inner_steps"]) != row["inner_steps"]:
        raise ValueError(f"row {row!r}: inner_steps must be a whole number")
    to_row(row).require_kick_drift("rigid water")  # and what the row type refuses
    return dict(row, step_fs=float(row["step_fs"]))


def to_row(row: dict, temperature: float = 300.0) -> Row:
    """The :class:`~..core.rows.Row` of a fidelity row (a dict of :data:`KINDS`; the study's ``temperature``)."""
    kind = row["kind"]
    return Row(row["method"] if kind == "symprk" else kind, float(row["step_fs"]), mts=int(row.get("inner_steps", 0)),
               tau_ps=row.get("collision_time_ps"), friction_per_ps=row.get("friction_per_ps"),
               collision_per_ps=row.get("collision_frequency_per_ps"), cutoff_nm=row.get("cutoff_nm"),
               hmr_da=row.get("hmr_da"), temperature=float(temperature))


def label(row: dict) -> str:
    """e.g. 'verlet 0.5 fs', 'omelyan-2 4 fs SVR 1 ps', 'langevin 4 fs friction 1/ps HMR 3 Da' (:attr:`Row.label`)."""
    return to_row(row).label


def describe(row: dict) -> dict:
    """label; ensemble ("NVE" or "NVT"); evals_per_step (force evaluations of the resolved method under constraints;
    MTS: force-group evaluations, one reciprocal-space and inner_steps direct-space); keeps_momentum; heat_bath (a
    conserved effective energy: NVE's total energy, or total + heat-bath energy); family ("symprk" or "openmm")."""
    r = to_row(row)
    return {"label": r.label, "ensemble": r.ensemble, "evals_per_step": r.evals_per_step(constraints=True),
            "keeps_momentum": r.keeps_momentum, "effective_energy": r.has_heat_bath,
            "family": "symprk" if r.is_ours else "openmm", "hmr": r.hmr_da is not None}
