"""Energy drift over replicas, and whether one row drifts less than another (paired by replica, at k SE).

Every run gives a drift (the least-squares slope of E(t) per degree of freedom, :func:`openmm_symprk.stats.drift`)
with its standard error.  A row's drift over its replicas is :func:`openmm_symprk.stats.combine` (the larger of the
within- and between-replica errors).  Two rows run from the same replica states are compared replica by replica.

Whether |a| < |b| (the magnitudes of two drifts) is an intersection-union test: with s the sign of b, it holds at
k SE when both s(b - a) > k SE and s(b + a) > k SE (each a paired difference over the replicas); no multiplicity
correction is needed, since both must pass.  |a| > |b| is the same test with the roles swapped; neither is "not
resolved".  Pure numerics: no OpenMM.
"""
from __future__ import annotations

import numpy as np

from ...stats import Estimate, combine, drift, paired
from ..core.units import kt_per_ns_per_dof
from ...support.errors import InputError

__all__ = ["run_drift", "row_estimate", "magnitude", "ratio", "claim_verdict", "cost_verdict", "K_SE", "NOT_HALVED"]

#: Standard errors for a verdict.
K_SE = 3.0
#: A claim "a drifts about f times less than b" (f >= 2) is refuted when a/b is resolved above this.
NOT_HALVED = 0.5


def run_drift(t_ps, e_kj, n_dof: int, temperature: float) -> tuple[float, float]:
    """(drift, standard error) in kT per ns per degree of freedom of the energy series e(t) (kJ/mol, ps)."""
    if n_dof < 1:
        raise InputError(f"n_dof must be >= 1, got {n_dof}")
    fit = drift(np.asarray(t_ps, dtype=np.float64), np.asarray(e_kj, dtype=np.float64) / n_dof)
    return kt_per_ns_per_dof(fit.slope, temperature), kt_per_ns_per_dof(fit.se, temperature)


def row_estimate(reps: dict) -> Estimate | None:
    """{replica: (drift, se)} -> the combined drift of the row (None without replicas)."""
    if not reps:
        return None
    keys = sorted(reps)
    return combine([reps[r][0] for r in keys], [reps[r][1] for r in keys])


def magnitude(row: dict, ref: dict, k: float = K_SE) -> str:
    """"smaller" if |row| < |ref| at ``k`` SE, "larger" if |row| > |ref|, else "not resolved" (paired over the
    replicas both have; ``{replica: (drift, se)}`` each)."""
    def below(a, b):  # |a| < |b| at k SE
        est = row_estimate(b)
        if est is None:
            return False
        s = 1.0 if est.mean >= 0 else -1.0
        minus = paired({r: (s * v[0], v[1]) for r, v in b.items()}, {r: (s * v[0], v[1]) for r, v in a.items()})
        plus = paired({r: (s * v[0], v[1]) for r, v in b.items()}, {r: (-s * v[0], v[1]) for r, v in a.items()})
        if minus is None or plus is None:
            return False
        return minus.mean > k * minus.se and plus.mean > k * plus.se

    if below(row, ref):
        return "smaller"
    if below(ref, row):
        return "larger"
    return "not resolved"


def ratio(row: Estimate, ref: Estimate, k: float = K_SE) -> Estimate | None:
    """|row| / |ref| with a first-order error, or None when |ref| is not resolved from zero at ``k`` SE."""
    if row is None or ref is None or not abs(ref.mean) > k * ref.se:
        return None
    b = abs(ref.mean)
    r = abs(row.mean) / b
    return Estimate(r, float(np.hypot(row.se / b, r * ref.se / b)), min(row.replicas, ref.replicas))


def claim_verdict(row: dict, ref: dict, factor: float | None = None, k: float = K_SE) -> dict:
    """The verdict on the claim "``row`` drifts less than ``ref``" (about ``factor`` times less, if given):

    * "refuted" when |row| > |ref| at k SE, or (with ``factor`` >= 2) when |row|/|ref| is resolved above
      :data:`NOT_HALVED` (the drift is not even halved, so "about ``factor`` times less" cannot hold);
    * "confirmed" when |row| < |ref| at k SE;
    * "not resolved at k SE" otherwise.
    """
    mag = magnitude(row, ref, k)
    est_row, est_ref = row_estimate(row), row_estimate(ref)
    q = ratio(est_row, est_ref, k)
    if mag == "larger":
        verdict, why = "refuted", f"|drift| is larger than the reference's at {k:g} SE"
    elif factor and factor >= 2 and q is not None and q.mean - k * q.se > NOT_HALVED:
        verdict, why = "refuted", (f"the ratio of |drifts| is {q:.2f}, above {NOT_HALVED:g} at {k:g} SE: not about "
                                   f"{factor:g}x less")
    elif mag == "smaller":
        verdict, why = "confirmed", f"|drift| is smaller than the reference's at {k:g} SE"
    else:
        verdict, why = f"not resolved at {k:g} SE", "neither |drift| is resolved larger than the other"
    return {"verdict": verdict, "why": why, "magnitude": mag, "ratio": q, "row": est_row, "ref": est_ref,
            "difference": paired(row, ref)}


def cost_verdict(on: dict, off: dict, k: float = K_SE) -> str:
    """Whether an option (``on``) costs energy conservation against ``off``, paired, at ``k`` SE."""
    mag = magnitude(on, off, k)
    return {"larger": f"costs: |drift| larger at {k:g} SE", "smaller": f"improves: |drift| smaller at {k:g} SE"}.get(
        mag, f"no difference resolved at {k:g} SE")
