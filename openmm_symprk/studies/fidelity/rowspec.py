"""What a row of the fidelity study is (pure; the rows are data in :mod:`.presets`, and
:mod:`.simulation.engines` makes them into running OpenMM integrators).

:func:`check_row` validates a row and names what is wrong; :func:`label` names it; :func:`describe` gives its
label, ensemble, force evaluations per step, whether it keeps the total momentum and whether it has a conserved
effective energy.
"""
from __future__ import annotations

from ...methods.catalogue import get_method

__all__ = ["KINDS", "UNAVAILABLE_THERMOSTAT", "check_row", "describe", "label"]

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
    if kind == "symprk":
        m = get_method(row["method"])
        if not m.is_splitting:
            raise ValueError(f"row {row!r}: {m.name} is a {m.family} method; rigid water runs kick/drift splittings "
                             f"and compositions only (e.g. verlet, omelyan-2, pefrl)")
    if "inner_steps" in row and int(row["inner_steps"]) != row["inner_steps"]:
        raise ValueError(f"row {row!r}: inner_steps must be a whole number")
    return dict(row, step_fs=float(row["step_fs"]))


def _g(x) -> str:
    return f"{float(x):g}"


def label(row: dict) -> str:
    """e.g. 'verlet 0.5 fs', 'omelyan-2 4 fs SVR 1 ps', 'langevin 4 fs friction 1/ps HMR 3 Da'."""
    kind, h = row["kind"], _g(row["step_fs"])
    if kind == "symprk":
        text = f"{row['method']} {h} fs" + (f" SVR {_g(row['collision_time_ps'])} ps" if "collision_time_ps" in row
                                            else "")
    elif kind == "mts-langevin":
        text = f"mts-langevin {h}/{int(row['inner_steps'])} fs friction {_g(row['friction_per_ps'])}/ps"
    elif kind == "nose-hoover":
        text = f"nose-hoover {h} fs {_g(row['collision_frequency_per_ps'])}/ps"
    else:
        text = f"{kind} {h} fs friction {_g(row['friction_per_ps'])}/ps"
    return text + (f" HMR {_g(row['hmr_da'])} Da" if "hmr_da" in row else "")


def describe(row: dict) -> dict:
    """label; ensemble ("NVE" or "NVT"); evals_per_step (force evaluations; MTS: force-group evaluations, one
    reciprocal-space and inner_steps direct-space); keeps_momentum; heat_bath (a conserved effective energy:
    NVE's total energy, or total + heat-bath energy); family ("symprk" or "openmm")."""
    kind = row["kind"]
    nvt = kind != "symprk" or "collision_time_ps" in row
    evals = {"symprk": lambda: get_method(row["method"]).force_evals,
             "mts-langevin": lambda: 1 + int(row["inner_steps"])}.get(kind, lambda: 1)()
    return {"label": label(row), "ensemble": "NVT" if nvt else "NVE", "evals_per_step": evals,
            "keeps_momentum": kind not in ("langevin", "mts-langevin"),
            "effective_energy": kind in ("symprk", "nose-hoover"), "family": "symprk" if kind == "symprk" else "openmm",
            "hmr": "hmr_da" in row}
