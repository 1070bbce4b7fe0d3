"""The one scene type: an OpenMM System with one shared initial state, and what may be measured on it.

Tests, the demo, the bench and the studies all take a :class:`Scene`.  A scene travels to worker processes as
its :meth:`Scene.payload` (plain, picklable data: the System as XML), whose fingerprint hashes everything a run
on it depends on, so every run of a study (and of a resumed study) starts from bit-identical coordinates and a
changed scene never reuses stale runs.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field

import numpy as np
import openmm as mm
import openmm.app as app

from .properties import constraint_arrays, degrees_of_freedom, masses

__all__ = ["Scene", "ALL_INVARIANTS"]

#: Every invariant an isolated system has.
ALL_INVARIANTS = ("energy", "momentum", "angular_momentum")

#: The fields of a scene that its payload carries (besides the System and the state) and its fingerprint hashes.
_INFO = ("name", "description", "purpose", "platform", "temperature", "exact", "linear", "why", "meta")


@dataclass
class Scene:
    name: str
    system: mm.System
    positions: np.ndarray  # nm, (N, 3)
    velocities: np.ndarray  # nm/ps, (N, 3)
    description: str = ""
    topology: app.Topology | None = None
    purpose: str = "accuracy"  # "accuracy": errors and stability; "speed": wall time only; "production": NVE drift,
    #                            fluctuation and ns/day of a periodic system (no trajectory reference)
    platform: str = "Reference"
    invariants: tuple = ALL_INVARIANTS
    temperature: float = 300.0  # K (e.g. for a Langevin comparison row)
    exact: dict | None = None  # toy metadata: errors are taken against an exact solution
    linear: dict | None = None  # {"omega_max": w}: the harmonic toy, stability decided exactly
    why: str = ""
    meta: dict = field(default_factory=dict)

    # -- derived ---------------------------------------------------------------------------------------------
    @property
    def n_atoms(self) -> int:
        return self.system.getNumParticles()

    @property
    def n_dof(self) -> int:
        return degrees_of_freedom(self.system)

    def masses(self) -> np.ndarray:
        if "_masses" not in self.__dict__:
            self.__dict__["_masses"] = masses(self.system)
        return self.__dict__["_masses"]

    def constraints(self):
        """(i, j, d) arrays of the distance constraints."""
        return constraint_arrays(self.system)

    @property
    def molecules(self) -> list:
        """Atom indices of each residue of the topology (e.g. each water)."""
        if self.topology is None:
            raise ValueError(f"scene {self.name!r} has no topology, so no molecules")
        return [[a.index for a in r.atoms()] for r in self.topology.residues()]

    def context(self, integrator, platform=None, properties=None):
        """A Context at the scene's initial state on the named platform (default: the scene's)."""
        platform = platform or self.platform
        plat = mm.Platform.getPlatformByName(platform) if isinstance(platform, str) else platform
        ctx = mm.Context(self.system, integrator, plat, properties or {})
        ctx.setPositions(self.positions)
        ctx.setVelocities(self.velocities)
        return ctx

    # -- transport -------------------------------------------------------------------------------------------
    def payload(self) -> dict:
        """Everything a worker needs, as picklable plain data (the System as XML; not the topology)."""
        xml = mm.XmlSerializer.serialize(self.system)
        info = {k: getattr(self, k) for k in _INFO}
        info["invariants"] = list(self.invariants)
        pos = np.ascontiguousarray(self.positions, dtype=np.float64)
        vel = np.ascontiguousarray(self.velocities, dtype=np.float64)
        h = hashlib.sha1(xml.encode())
        h.update(pos.tobytes())
        h.update(vel.tobytes())
        h.update(json.dumps(_plain(info), sort_keys=True).encode())
        return {"xml": xml, "positions": pos, "velocities": vel, "info": info, "fingerprint": h.hexdigest()[:16]}

    @classmethod
    def from_payload(cls, payload: dict) -> "Scene":
        info = dict(payload["info"])
        info["invariants"] = tuple(info["invariants"])
        system = mm.XmlSerializer.deserialize(payload["xml"])
        return cls(system=system, positions=np.asarray(payload["positions"]),
                   velocities=np.asarray(payload["velocities"]), **info)


def _plain(obj):
    """A JSON-ready copy (numpy arrays and scalars to lists and numbers) for the fingerprint."""
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj
