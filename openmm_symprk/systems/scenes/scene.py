"""The one scene type: an OpenMM System with one shared initial state, and what may be measured on it.

Tests, the demo, the bench and the studies all take a :class:`Scene`.  A scene, or a set of states of one System
(the replica states of a study), is stored one way: ``<base>.xml`` (the System), ``<base>.npz`` (the arrays) and,
for a scene, ``<base>.json`` (its info and fingerprint), each written atomically (:func:`save_states`).  A scene travels to worker processes as
its :meth:`Scene.payload` (plain, picklable data: the System as XML), whose fingerprint hashes everything a run
on it depends on, so every run of a study (and of a resumed study) starts from bit-identical coordinates and a
changed scene never reuses stale runs.
"""
from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field

import numpy as np
import openmm as mm
import openmm.app as app

from ...support.files import write_json, write_npz, write_text
from ..properties import constraint_arrays, degrees_of_freedom, masses
from ...support.errors import InputError

__all__ = ["Scene", "ALL_INVARIANTS", "save_scene", "load_scene", "save_states", "load_states"]

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
            raise InputError(f"scene {self.name!r} has no topology, so no molecules")
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


def save_states(base: str, xml: str, arrays: dict, info: dict | None = None):
    """Store a System (its XML) with arrays of states: ``<base>.xml``, ``<base>.npz`` and, given ``info``,
    ``<base>.json``; each file atomically, the ``.npz`` last, so that one on disk means a complete set."""
    os.makedirs(os.path.dirname(os.path.abspath(base)), exist_ok=True)
    write_text(base + ".xml", xml)
    if info is not None:
        write_json(base + ".json", info)
    write_npz(base + ".npz", arrays)


def load_states(base: str, with_info: bool = False):
    """(xml, arrays[, info]) stored by :func:`save_states`, or None when the set is not there (or incomplete)."""
    paths = [base + ".xml", base + ".npz"] + ([base + ".json"] if with_info else [])
    if not all(os.path.exists(p) for p in paths):
        return None
    with open(base + ".xml") as fh:
        xml = fh.read()
    with np.load(base + ".npz") as data:
        arrays = {k: data[k] for k in data.files}
    if not with_info:
        return xml, arrays
    with open(base + ".json") as fh:
        return xml, arrays, json.load(fh)


def save_scene(scene: Scene, folder: str) -> str:
    """Store the scene's payload as <folder>/<name>.xml + .npz + .json (:func:`save_states`); returns the JSON
    path."""
    p = scene.payload()
    base = os.path.join(folder, scene.name)
    save_states(base, p["xml"], {"positions": p["positions"], "velocities": p["velocities"]},
                {"info": p["info"], "fingerprint": p["fingerprint"]})
    return base + ".json"


def load_scene(folder: str, name: str) -> Scene:
    """The scene :func:`save_scene` stored in ``folder``."""
    found = load_states(os.path.join(folder, name), with_info=True)
    if found is None:
        raise FileNotFoundError(f"no stored scene {name!r} in {folder}")
    xml, arrays, meta = found
    return Scene.from_payload({"xml": xml, "positions": arrays["positions"], "velocities": arrays["velocities"],
                               "info": meta["info"]})
