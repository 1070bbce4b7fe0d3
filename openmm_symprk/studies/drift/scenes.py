"""The systems of the drift studies and their independent replica states.

A scene is built once per study folder and kept there (``<out>/states/<scene>-<key>.xml`` and ``.npz``).  Replica r
starts from the scene's state with fresh Maxwell-Boltzmann velocities (seed ``seed + r``) and ``decorrelate_ps`` of
Langevin dynamics at the study's temperature (:func:`openmm_symprk.systems.prepare.equilibrate`): different
velocities and positions per replica, and replica r is the same state whatever the number of replicas, so asking
for more replicas later reuses every finished run.

Scenes: ``villin-pme`` and ``villin-pme-hmr`` are the bench's production scenes (:mod:`..bench.registry`: solvated
villin, PME, HBonds, rigid water, HMR 1.5 Da); ``villin-vacuum`` is the conservation table's protein
(:func:`openmm_symprk.systems.scenes.protein_vacuum`: amber14, HBonds, no cutoff); ``villin-vacuum-hmr`` is the
same with HMR 1.5 Da, the seconds-long stand-in of the solvated HMR scene in ``--quick`` runs.
"""
from __future__ import annotations

import functools
import os

import numpy as np
import openmm as mm

from ..core import run_key, write_npz, write_text

__all__ = ["SCENES", "build", "replica_states", "state_key", "STATE_VERSION"]

#: Version of the stored scenes and replica states (a change never reuses stale ones).
STATE_VERSION = 1
#: The scenes: name -> what it is.
SCENES = {
    "villin-pme": "solvated villin (8,867 atoms), PME, HBonds, rigid water (the bench's production scene)",
    "villin-pme-hmr": "the same with HMR 1.5 Da (the bench's production scene)",
    "villin-vacuum": "villin in vacuum (582 atoms), amber14, HBonds, no cutoff, no CMMotionRemover",
    "villin-vacuum-hmr": "villin in vacuum with HMR 1.5 Da (the --quick stand-in of villin-pme-hmr)",
}


def build(name: str):
    """(System, positions in nm) of a scene, the platform to prepare it on."""
    if name in ("villin-pme", "villin-pme-hmr"):
        from ..bench.registry import build as bench_build

        scene = bench_build(name)
        return scene.system, np.asarray(scene.positions), "CPU"
    if name in ("villin-vacuum", "villin-vacuum-hmr"):
        from ...systems.repartition import repartition_hydrogen_mass
        scene = _villin_vacuum()
        system = mm.XmlSerializer.clone(scene.system)
        if name.endswith("-hmr"):
            system = repartition_hydrogen_mass(system, scene.topology, 1.5)
        return system, np.asarray(scene.positions), "CPU"
    raise ValueError(f"unknown drift scene {name!r}; known: {', '.join(SCENES)}")


@functools.lru_cache(maxsize=1)
def _villin_vacuum():
    """The vacuum villin, built once per process (minimised: a few seconds)."""
    from ...systems.scenes import protein_vacuum

    return protein_vacuum()


def state_key(cfg: dict, name: str) -> str:
    return run_key({"scene": name, "temperature": float(cfg["temperature"]), "seed": int(cfg["seed"]),
                    "decorrelate_ps": float(cfg["decorrelate_ps"]), "version": STATE_VERSION})


def replica_states(cfg: dict, name: str, out: str, log=print) -> dict:
    """{"xml", "x" (R, N, 3), "v" (R, N, 3)} for at least ``cfg["replicas"]`` replicas of scene ``name``, built or
    extended and kept in ``<out>/states``."""
    from ...systems.prepare import equilibrate

    base = os.path.join(out, "states", f"{name}-{state_key(cfg, name)}")
    os.makedirs(os.path.dirname(base), exist_ok=True)
    want = int(cfg["replicas"])
    xs, vs, xml, x0 = [], [], None, None
    if os.path.exists(base + ".npz") and os.path.exists(base + ".xml"):
        with open(base + ".xml") as fh:
            xml = fh.read()
        with np.load(base + ".npz") as d:
            xs, vs, x0 = list(d["x"]), list(d["v"]), d["x0"]
        if len(xs) >= want:
            return {"xml": xml, "x": np.asarray(xs), "v": np.asarray(vs)}
    if xml is None:
        log(f"building scene {name} ...")
        system, x0, _ = build(name)
        xml = mm.XmlSerializer.serialize(system)
        write_text(base + ".xml", xml)
    system = mm.XmlSerializer.deserialize(xml)
    for r in range(len(xs), want):
        log(f"{name}: replica {r}: {cfg['decorrelate_ps']:g} ps Langevin at {cfg['temperature']:g} K, seed "
            f"{int(cfg['seed']) + r}")
        x, v = equilibrate(system, x0, float(cfg["temperature"]), float(cfg["decorrelate_ps"]), int(cfg["seed"]) + r,
                           platform="CPU", properties={"Threads": str(cfg.get("threads", 1))})
        xs.append(x)
        vs.append(v)
        write_npz(base + ".npz", {"x0": np.asarray(x0), "x": np.asarray(xs), "v": np.asarray(vs)})
    return {"xml": xml, "x": np.asarray(xs), "v": np.asarray(vs)}
