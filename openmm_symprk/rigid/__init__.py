"""Rigid bodies.

* :mod:`.lie_poisson` -- the Lie-Poisson integrators of Euler's equations (pure numpy, with the exact
  Jacobi-elliptic solution), their methods taken from the catalogue;
* :mod:`.groups` -- rigid molecules in an OpenMM System: distance constraints that make atom groups rigid, so every
  catalogue method runs them through RATTLE (:func:`make_rigid`);
* :mod:`.free_body` -- a free rigid molecule in OpenMM, the scene that cross-validates the two;
* :mod:`.bodies` -- molecules moved as rigid bodies with forces from OpenMM.
"""
from .groups import RigidGroup, RigidGroupError, RigidGroupWarning, make_rigid

__all__ = ["RigidGroup", "RigidGroupError", "RigidGroupWarning", "make_rigid"]
