"""The modified-energy model of the study's biases (:mod:`openmm_symprk.methods.shadow`), beside what was measured.

For each row of this package (or OpenMM's VerletIntegrator, whose on-step positions and velocities are velocity
Verlet's) the model predicts, to first order in h^2, the bias of the translational kinetic temperature, of T_rot -
T_trans and of the potential energy per molecule against the row's reference, from two properties of the box: the
mean square frequencies of translation and rotation, <w^2> = <F.M^-1.F>/(N kT) at the replica states
(:func:`openmm_symprk.systems.frequencies.mean_square_frequency`), and the configurational heat capacity per molecule,
C_conf = Var(PE)/(k T^2) of the NVT reference's potential energy.

* NVT with velocity rescaling at event point s: every mode's temperature is scaled by 1 + g, g = c_T(s) <(hw)^2>;
* NVE from canonical states: by 1 + g, g = (c_T + c_V)/2 <(hw)^2> (the modified energy's mean over the states);

then, read at the step's ends, a class of modes (translation, rotation) has the kinetic temperature T (1 + g - c_T
(hw)^2) and the potential energy per molecule moves by T C_conf g - (kT/2) c_V (3 (hw_trans)^2 + 3 (hw_rot)^2).
Methods whose h^2 error vanishes (order 4 and more) and OpenMM's Langevin integrators (friction per particle, not a
pinned total kinetic energy) are not modelled.
"""
from __future__ import annotations

import numpy as np

from ...methods.shadow import event_coefficients
from ...physics.temperature import R_KJ as KB
from .rowspec import to_row

__all__ = ["predict", "bias_predictions", "box_properties"]


def predict(label: str, props: dict, temperature: float) -> dict | None:
    """{"T_trans": K, "dT": K (T_rot - T_trans), "pe": kJ/mol per molecule} of the row ``label`` against exact
    dynamics; None where the model does not apply.  ``props``: {"omega2_ps2": {"trans", "rot"}, "c_conf": kJ/mol/K
    per molecule}."""
    from ...methods.catalogue import get_method

    row = to_row(label)
    if row.who == "openmm-verlet":
        method, position, ensemble = "verlet", "ends", "NVE"
    elif row.is_ours and not row.is_rigid and not row.mts and row.hmr_da is None:
        method, ensemble = row.method, row.ensemble
        position = "ends" if ensemble == "NVE" else _position(row)
    else:
        return None
    m = get_method(method)
    if m.order != 2 or getattr(m, "splitting", None) is None:
        return None
    c = event_coefficients(m.splitting.steps, position)
    c_t, c_v = c["ends"]
    h2 = row.step_fs ** 2 * 1e-6  # ps^2
    x_t, x_r = h2 * props["omega2_ps2"]["trans"], h2 * props["omega2_ps2"]["rot"]
    mean = 0.5 * (x_t + x_r)
    g = (c["event"] if ensemble == "NVT" else 0.5 * (c_t + c_v)) * mean
    t = float(temperature)
    if row.ensemble == "NVT" and row.temperature != t:  # a lowered target: every temperature scales with it
        g += row.temperature / t - 1.0
    return {"T_trans": t * (g - c_t * x_t), "dT": -t * c_t * (x_r - x_t),
            "pe": t * props["c_conf"] * g - 0.5 * KB * t * c_v * 3.0 * (x_t + x_r)}


def _position(row) -> str:
    """The placement a row's thermostat runs at ("auto" resolved as the integrator resolves it)."""
    from ...methods.resolved import resolve, thermostat_position_for

    return thermostat_position_for(resolve(row.method, True), row.position)


def bias_predictions(labels, references: dict, props: dict, temperature: float) -> dict:
    """{label: predicted bias against its ensemble's reference (the row's prediction less the reference's)} for the
    rows the model covers."""
    out = {}
    for lab in labels:
        row = to_row(lab)
        ref = references.get(row.ensemble)
        mine = predict(lab, props, temperature)
        base = predict(ref, props, temperature) if ref else None
        if mine is None or base is None or lab == ref:
            continue
        out[lab] = {k: float(mine[k] - base[k]) for k in mine}
    return out


def box_properties(system, states, molecules, temperature: float, pe_series=None) -> dict:
    """The model's inputs (see the module docstring): <w^2> of translation and rotation over the replica states,
    and C_conf from the NVT reference's potential-energy series ``pe_series`` (kJ/mol of the box, one array per
    run; the mean of their variances) -- None where no series is at hand."""
    from ...systems.frequencies import mean_square_frequency

    w2 = mean_square_frequency(system, states, temperature, molecules, platform="CPU")
    out = {"omega2_ps2": {"trans": w2["trans"], "rot": w2["rot"]}, "states": w2["configurations"]}
    if pe_series:  # the variance about the mean of every run: the runs' own means scatter canonically too
        pooled = np.concatenate([np.asarray(s, dtype=float) for s in pe_series])
        var = float(np.var(pooled[np.isfinite(pooled)], ddof=1))
        out["c_conf"] = var / (KB * float(temperature) ** 2) / len(molecules)
        out["pe_runs"] = len(pe_series)
    return out
