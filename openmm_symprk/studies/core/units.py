"""The studies' one conversion of energy drift: kJ/mol per ps to kT per ns per degree of freedom, OpenMM's unit for
energy drift (its user guide, "Testing and Validation of OpenMM"), with the package's one gas constant
(:data:`openmm_symprk.physics.temperature.R_KJ`)."""
from __future__ import annotations

from ...physics.temperature import R_KJ
from ...support.errors import InputError

__all__ = ["R_KJ", "kT", "kt_per_ns_per_dof"]


def kT(temperature: float) -> float:
    """kT in kJ/mol at ``temperature`` K."""
    return R_KJ * float(temperature)


def kt_per_ns_per_dof(rate_kj_per_ps: float, temperature: float, dof: int = 1) -> float:
    """A rate of energy change (kJ/mol per ps; per degree of freedom with ``dof`` = 1) in kT per ns per degree of
    freedom."""
    if dof < 1:
        raise InputError(f"dof must be >= 1, got {dof}")
    return float(rate_kj_per_ps) * 1e3 / (kT(temperature) * dof)
