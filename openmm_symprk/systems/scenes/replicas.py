"""Independent replica states of a named scene, built once and kept in a study's folder.

A scene (:mod:`.named`) is built once per folder and stored with its replica states (``<folder>/<scene>-<key>.xml``
and ``.npz``, :func:`.scene.save_states`).  Replica r starts from the scene's positions with fresh
Maxwell-Boltzmann velocities (seed ``seed + r``) and ``decorrelate_ps`` of Langevin dynamics at ``temperature``
(:func:`openmm_symprk.systems.prepare.equilibrate`): different velocities and positions per replica, and replica r
is the same state whatever the number of replicas, so asking for more replicas later reuses every finished run.
The key hashes what the states depend on, so a changed setting never reuses stale states.
"""
from __future__ import annotations

import os

import numpy as np
import openmm as mm

from ...support.files import content_key
from .scene import load_states, save_states

__all__ = ["replica_states", "state_key", "STATE_VERSION"]

#: Version of the stored replica states (a change never reuses stale ones).
STATE_VERSION = 1


def state_key(name: str, temperature: float, seed: int, decorrelate_ps: float) -> str:
    return content_key({"scene": name, "temperature": float(temperature), "seed": int(seed),
                        "decorrelate_ps": float(decorrelate_ps), "version": STATE_VERSION})


def replica_states(name: str, folder: str, replicas: int, temperature: float, seed: int, decorrelate_ps: float,
                   threads: int = 1, log=print) -> dict:
    """{"xml", "x" (R, N, 3), "v" (R, N, 3)} for at least ``replicas`` replica states of the named scene ``name``,
    built or extended and kept in ``folder``."""
    from ..prepare import equilibrate
    from .named import build

    base = os.path.join(folder, f"{name}-{state_key(name, temperature, seed, decorrelate_ps)}")
    found = load_states(base)
    xs, vs = [], []
    if found is not None:
        xml, arrays = found
        xs, vs, x0 = list(arrays["x"]), list(arrays["v"]), arrays["x0"]
        if len(xs) >= replicas:
            return {"xml": xml, "x": np.asarray(xs), "v": np.asarray(vs)}
    else:
        log(f"building scene {name} ...")
        scene = build(name)
        xml, x0 = mm.XmlSerializer.serialize(scene.system), np.asarray(scene.positions)
    system = mm.XmlSerializer.deserialize(xml)
    for r in range(len(xs), int(replicas)):
        log(f"{name}: replica {r}: {decorrelate_ps:g} ps Langevin at {temperature:g} K, seed {int(seed) + r}")
        x, v = equilibrate(system, x0, float(temperature), float(decorrelate_ps), int(seed) + r, platform="CPU",
                           properties={"Threads": str(threads)})
        xs.append(x)
        vs.append(v)
        save_states(base, xml, {"x0": np.asarray(x0), "x": np.asarray(xs), "v": np.asarray(vs)})
    return {"xml": xml, "x": np.asarray(xs), "v": np.asarray(vs)}
