"""Rigid bodies: the Lie-Poisson integrators of Euler's equations (:mod:`.lie_poisson`, pure numpy, with the
exact Jacobi-elliptic solution) and rigid molecules in an OpenMM System (:mod:`.molecules`: distance
constraints that make atom groups rigid, so every catalogue method runs them through RATTLE)."""
from .molecules import RigidGroup, RigidGroupError, RigidGroupWarning, make_rigid

__all__ = ["RigidGroup", "RigidGroupError", "RigidGroupWarning", "make_rigid"]
