"""Analytic toy systems (the bench's ``harmonic`` and ``anharmonic`` scenes): independent oscillators whose exact solution is known.

Both toys are sets of unit-mass particles in an external potential, one independent 1-D oscillator per
Cartesian axis, so that the exact state at any time is a closed formula and every error the bench reports
on them is an error of the integrator alone (no reference run, no chaos):

* harmonic: V = k_i |r_i|^2 / 2 with frequencies spread evenly over (0, omega_max].  Exact solution
  q(t) = q0 cos(wt) + v0/w sin(wt).  A spread of frequencies reaching down to zero is what makes the
  largest stable step of a simulation equal to the linear stability interval of the catalogue (stable for
  every h*omega in (0, x]), resonance bands included.
* anharmonic (hardening Duffing): V = a_i |r_i|^2 / 2 + b_i (x^4 + y^4 + z^4) / 4.  Exact solution
  x(t) = A cn(Omega t + u0 | m) with Omega^2 = a + b A^2 and m = b A^2 / (2 (a + b A^2))
  (Jacobi elliptic functions, scipy.special.ellipj).

Units are OpenMM's (nm, ps, Da, kJ/mol); omega_max = 700 / ps is an O-H stretch (3700 cm^-1), so the
step sizes that matter are the femtoseconds of molecular dynamics.
"""
from __future__ import annotations

import numpy as np
import openmm as mm

from ...physics.temperature import R_KJ
from ...support import require

special = require("scipy.special", "studies", "openmm_symprk.studies.core.toys")
ellipj, ellipkinc = special.ellipj, special.ellipkinc

#: kT at 300 K in kJ/mol: the toys hold about this much energy per degree of freedom.
KT300 = R_KJ * 300.0
#: O-H stretch angular frequency (1/ps), the top of the harmonic toy's spectrum.
OMEGA_OH = 700.0


def harmonic_frequencies(n: int, omega_max: float = OMEGA_OH) -> np.ndarray:
    """omega_i = omega_max * i / n, i = 1..n (1/ps)."""
    return omega_max * np.arange(1, n + 1) / n


def harmonic_system(omega: np.ndarray) -> mm.System:
    """Unit-mass particles in isotropic harmonic wells k_i = omega_i^2 (no interactions)."""
    system = mm.System()
    force = mm.CustomExternalForce("0.5*k*(x^2 + y^2 + z^2)")
    force.addPerParticleParameter("k")
    for i, w in enumerate(np.asarray(omega, float)):
        system.addParticle(1.0)
        force.addParticle(i, [float(w * w)])
    system.addForce(force)
    return system


def harmonic_initial_state(omega: np.ndarray, seed: int = 11, energy: float = KT300):
    """Random phases, ``energy`` kJ/mol in every axis of every oscillator."""
    rng = np.random.default_rng(seed)
    w = np.asarray(omega, float)[:, None]
    phase = rng.uniform(0, 2 * np.pi, size=(len(w), 3))
    amp = np.sqrt(2 * energy) / w
    return amp * np.cos(phase), -amp * w * np.sin(phase)


def harmonic_exact(omega, x0, v0, t: float):
    """Exact positions and velocities at time t (ps)."""
    w = np.asarray(omega, float)[:, None]
    c, s = np.cos(w * t), np.sin(w * t)
    return x0 * c + v0 / w * s, -x0 * w * s + v0 * c


def duffing_parameters(n: int, omega_lo: float = 100.0, omega_hi: float = 495.0, anharmonicity: float = 1.0,
                       energy: float = KT300):
    """(a, b, A) per particle: linear frequencies sqrt(a) spread over [omega_lo, omega_hi], quartic b
    chosen so that b A^2 / a = ``anharmonicity`` at the amplitude A that holds ``energy`` per axis.
    With anharmonicity 1 the oscillation frequency is sqrt(2) times the linear one (up to 700/ps)."""
    w0 = np.linspace(omega_lo, omega_hi, n)
    a = w0 ** 2
    amp = np.sqrt(energy / (a * (0.5 + anharmonicity / 4)))
    b = anharmonicity * a / amp ** 2
    return a, b, amp


def duffing_system(a, b) -> mm.System:
    system = mm.System()
    force = mm.CustomExternalForce("0.5*a*(x^2 + y^2 + z^2) + 0.25*b*(x^4 + y^4 + z^4)")
    force.addPerParticleParameter("a")
    force.addPerParticleParameter("b")
    for i, (ai, bi) in enumerate(zip(a, b)):
        system.addParticle(1.0)
        force.addParticle(i, [float(ai), float(bi)])
    system.addForce(force)
    return system


def _duffing_constants(a, b, amp):
    a = np.asarray(a, float)[:, None]
    b = np.asarray(b, float)[:, None]
    amp = np.broadcast_to(np.asarray(amp, float)[:, None] if np.ndim(amp) == 1 else amp, (a.shape[0], 3))
    big_omega = np.sqrt(a + b * amp ** 2)
    m = b * amp ** 2 / (2 * big_omega ** 2)
    return a, b, amp, big_omega, m


def duffing_initial_state(a, b, amp, seed: int = 13):
    """Random phases u0 on the orbit of amplitude A (per particle, the same A on its three axes).

    Returns (x0, v0, u0); u0 is the elliptic phase the exact solution needs."""
    a2, b2, amp2, big_omega, m = _duffing_constants(a, b, amp)
    rng = np.random.default_rng(seed)
    period = 4 * ellipkinc(np.pi / 2, m)
    u0 = rng.uniform(0, 1, size=amp2.shape) * period
    sn, cn, dn, _ = ellipj(u0, m)
    return amp2 * cn, -amp2 * big_omega * sn * dn, u0


def duffing_exact(a, b, amp, u0, t: float):
    """Exact positions and velocities at time t: x = A cn(Omega t + u0 | m), v = -A Omega sn dn."""
    _, _, amp2, big_omega, m = _duffing_constants(a, b, amp)
    sn, cn, dn, _ = ellipj(big_omega * t + u0, m)
    return amp2 * cn, -amp2 * big_omega * sn * dn


def exact_state(meta: dict, t: float):
    """Exact (x, v) of a toy scene at time t from its metadata (see :mod:`openmm_symprk.studies.core.scenes`)."""
    if meta["toy"] == "harmonic":
        return harmonic_exact(np.array(meta["omega"]), np.array(meta["x0"]), np.array(meta["v0"]), t)
    if meta["toy"] == "duffing":
        return duffing_exact(np.array(meta["a"]), np.array(meta["b"]), np.array(meta["amp"]),
                             np.array(meta["u0"]), t)
    raise ValueError(f"unknown toy {meta['toy']!r}")
