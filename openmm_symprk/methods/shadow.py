"""The modified (shadow) energy of a kick/drift splitting to second order, and what a thermostat that pins the
kinetic energy makes of it (pure numerics).

A symmetric splitting of H = T(p) + V(q) with step h conserves, to O(h^4), the modified energy

    H~ = H + (h^2 / 2) (c_T p.M^-1 Hess(V) M^-1.p + c_V F.M^-1.F),        F = -grad V,

where (c_T, c_V) depend on the method and on where in the step the state is read (the step's ends, or a point
inside it such as the thermostat's event in the middle placement).  On one harmonic mode of angular frequency w
the two terms are c_T (hw)^2 T and c_V (hw)^2 V, so the step's linear map fixes both numbers: its rotation angle per
step, hw (1 + c (hw)^2), gives c_T + c_V = 2c, and the ratio of the kinetic to the potential coefficient of the
quadratic form it conserves, 1 + d (hw)^2, gives c_T - c_V = d (:func:`coefficients`).  Velocity Verlet read at its
ends: c_T = 1/6, c_V = -1/12; read between its half drifts (the middle placement's event): c_T = -1/12, c_V = 1/6.
``tests/methods/test_shadow.py`` checks the pair on an anharmonic oscillator, where H~ is conserved to O(h^4).

**What a thermostat samples.**  Velocity rescaling pins the kinetic energy at its event point s to N_f kT/2.  Where
the dynamics between events mix the modes (a liquid), the stationary state is close to exp(-H~/kT'') with T'' such
that <T> = N_f kT/2 at s: T'' = T (1 + c_T(s) <(hw)^2>), <(hw)^2> the mean over the degrees of freedom, h^2
<F.M^-1.F>/(N_f kT).  Every mode is then hotter (or colder) by that factor, and mode i, read at the step's ends, has
the kinetic temperature T'' (1 - c_T (hw_i)^2) and the configurational temperature T'' (1 - c_V (hw_i)^2).  So the
configurations of the slow modes (diffusion, structure) sit at T'' instead of T, which raises the potential energy
by about T C_conf c_T(s) <(hw)^2> (C_conf the configurational heat capacity), and the fast modes (water's
librations) carry the per-mode error -c_V (hw_i)^2 (:func:`nvt_temperatures`).  A thermostat whose target is
lowered to T (1 - c_T(s) <(hw)^2>) removes the first part: T'' = T (:func:`shadow_target`).
"""
from __future__ import annotations

import numpy as np

from ..support.errors import InputError
from .placement import THERMOSTAT, with_thermostat

__all__ = ["coefficients", "event_coefficients", "nvt_temperatures", "shadow_target"]

#: h*omega at which the coefficients are read off the harmonic map (and at twice it, for the O(h^2) part alone).
_X = 1e-2


def _map(steps, x: float) -> np.ndarray:
    """The linear map of one step on q'' = -q at h*omega = x, in (q, p); thermostat entries are skipped."""
    a = np.eye(2)
    for label, c in steps:
        if label == THERMOSTAT:
            continue
        c = float(c)
        m = np.array([[1.0, c * x], [0.0, 1.0]]) if label == "drift" else np.array([[1.0, 0.0], [-c * x, 1.0]])
        a = m @ a
    return a


def coefficients(steps) -> tuple:
    """(c_T, c_V) of the modified energy of the kick/drift sequence ``steps`` ((label, coefficient) pairs, the state
    read where the sequence starts), from its harmonic map (see the module docstring).  ValueError where the sequence
    is not time-symmetric about its start (its map conserves a form with a p q term: no such pair)."""
    def read(x):
        a = _map(steps, x)
        if not abs(a[0, 0] - a[1, 1]) < 1e-9:
            raise InputError("the sequence is not symmetric about its start (its map's diagonal differs: "
                             f"{a[0, 0]!r}, {a[1, 1]!r}); read it at a point of symmetry")
        c = (np.arccos(np.clip(0.5 * np.trace(a), -1.0, 1.0)) / x - 1.0) / x ** 2
        d = (-a[0, 1] / a[1, 0] - 1.0) / x ** 2
        return np.array([c + d / 2, c - d / 2])

    # the O(h^2) part, the O(h^4) remainder removed by Richardson's extrapolation from x and 2x
    c_t, c_v = (4.0 * read(_X) - read(2 * _X)) / 3.0
    return float(c_t), float(c_v)


def event_coefficients(steps, position: str) -> dict:
    """{"event": c_T at the thermostat's event, "ends": (c_T, c_V) at the step's ends} of the splitting ``steps``
    with the thermostat at ``position`` ("ends" or "middle"; :func:`.placement.with_thermostat`)."""
    ends = coefficients(steps)
    if position == "ends":
        return {"event": ends[0], "ends": ends}
    seq = with_thermostat(steps, position)
    i = max(k for k, (label, _) in enumerate(seq) if label == THERMOSTAT)
    return {"event": coefficients(seq[i + 1:] + seq[:i])[0], "ends": ends}


def nvt_temperatures(steps, position: str, h_omega2) -> dict:
    """Relative shifts predicted at the step's ends for modes of mean-square h*omega ``h_omega2`` (a mapping
    {name: <(hw)^2> of that class of modes}, e.g. {"trans": ..., "rot": ...}; their mean, weighting the classes
    equally, is the system's <(hw)^2>): {"global": T''/T - 1, "kinetic": {name: ...}, "configurational": {name: ...}}
    (see the module docstring; first order in h^2)."""
    c = event_coefficients(steps, position)
    c_t, c_v = c["ends"]
    mean = float(np.mean(list(h_omega2.values())))
    shift = c["event"] * mean
    return {"global": shift, "kinetic": {k: shift - c_t * x for k, x in h_omega2.items()},
            "configurational": {k: shift - c_v * x for k, x in h_omega2.items()}}


def shadow_target(steps, position: str, h_omega2_mean: float) -> float:
    """The factor by which a thermostat's target temperature is lowered so that the modified energy's temperature
    is the one asked for: 1 - c_T(event) <(hw)^2> (module docstring)."""
    return 1.0 - event_coefficients(steps, position)["event"] * float(h_omega2_mean)
