"""Replica states: independent starting states of one System, built once, kept in a study's folder and extended
when more are asked for.  Replica r is the same state whatever their number, so a study asked for more replicas
later reuses every finished run; a key hashes what the states depend on, so a changed setting never reuses stale
states.  Two recipes, the studies' only ones:

* :func:`scene_replicas` -- a named scene (:mod:`.scenes`; ``<folder>/<scene>-<key>.xml`` and ``.npz``): replica r
  from the scene's positions with fresh Maxwell-Boltzmann velocities (seed ``seed + r``) and ``decorrelate_ps`` of
  Langevin dynamics at ``temperature`` (the drift study);
* :func:`water_box_replicas` -- the rigid-water box of a model (:func:`water_box_scene`;
  ``<out>/states/<model>-<key>.npz``): minimised, ``equilibrate_ps`` of Langevin dynamics, then one state every
  ``spacing_ps`` along one chain (replica r continues with seed ``seed + r``), each state's total momentum set to
  zero (Langevin dynamics without a CMMotionRemover leaves the box drifting as a whole, ~0.04 nm/ps for 216
  waters, which NVE keeps and which biases a diffusion coefficient).  The equipartition and fidelity studies start
  from the same states (same settings, same file).
"""
from __future__ import annotations

import os
import time

import numpy as np
import openmm as mm

from ...support.files import content_key, write_npz
from ...systems.prepare import equilibrate, minimise, without_net_momentum
from ...systems.scenes import WATER_DENSITY_G_CM3, Scene, load_states, save_states, water_box
from ...support.errors import InputError

__all__ = ["scene_replicas", "scene_state_key", "water_box_scene", "water_box_replicas", "box_state_key",
           "BOX_STATE_KEYS", "BOX_STATE_VERSION", "EQUILIBRATORS"]

#: Version of a named scene's stored replica states (a change never reuses stale ones).
SCENE_STATE_VERSION = 1
#: What a water box's replica states depend on (not their number).
BOX_STATE_KEYS = ("n_waters", "cutoff_nm", "density_g_cm3", "temperature", "seed", "equilibrate_ps", "spacing_ps",
                  "threads")
#: Version of a water box's replica states (2: the box at a stated density, 0.997 g/cm^3, instead of Modeller's
#: 0.864, and each state's total momentum zero).
BOX_STATE_VERSION = 2


def scene_state_key(name: str, temperature: float, seed: int, decorrelate_ps: float) -> str:
    return content_key({"scene": name, "temperature": float(temperature), "seed": int(seed),
                        "decorrelate_ps": float(decorrelate_ps), "version": SCENE_STATE_VERSION})


def scene_replicas(name: str, folder: str, replicas: int, temperature: float, seed: int, decorrelate_ps: float,
                   threads: int = 1, log=print) -> dict:
    """{"xml", "x" (R, N, 3), "v" (R, N, 3)} for at least ``replicas`` replica states of the named scene ``name``,
    built or extended and kept in ``folder``."""
    from .scenes import build

    base = os.path.join(folder, f"{name}-{scene_state_key(name, temperature, seed, decorrelate_ps)}")
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


#: The boxes built in this process, keyed by everything :func:`water_box_scene` reads from a study's settings.
_boxes: dict = {}


def water_box_scene(cfg: dict, model: str) -> Scene:
    """The rigid-water box of ``model`` (:func:`openmm_symprk.systems.scenes.water_box`: ``n_waters``,
    ``cutoff_nm``, ``density_g_cm3`` of ``cfg``) as a Scene whose ``meta["model"]`` names the model and whose
    temperature is ``cfg["temperature"]``; its state is Modeller's (the replica states are :func:`water_box_replicas`).
    Built once per process for each (model, n_waters, cutoff_nm, density_g_cm3, temperature), so a worker running
    many rows reuses it, and a study with other settings in the same process never gets a stale box; treat it as
    read-only."""
    density = float(cfg.get("density_g_cm3", WATER_DENSITY_G_CM3))
    key = (model, int(cfg["n_waters"]), float(cfg["cutoff_nm"]), density, float(cfg["temperature"]))
    if key not in _boxes:
        system, topology, x = water_box(model, cfg["n_waters"], cfg["cutoff_nm"], density_g_cm3=density)
        _boxes[key] = Scene(f"water-box-{model}", system, x, np.zeros_like(x),
                            f"{cfg['n_waters']} rigid {model} waters, PME", topology, purpose="production",
                            platform="CPU", invariants=("energy", "momentum"), temperature=float(cfg["temperature"]),
                            meta={"model": model})
    return _boxes[key]


def box_state_key(cfg: dict) -> str:
    """The key of a water box's replica states: what they depend on (not their number; the equilibrator only where a
    study names one, so the states made before it was a setting keep their key)."""
    keys = BOX_STATE_KEYS + (("equilibrator",) if "equilibrator" in cfg else ())
    return content_key({"cfg": {k: cfg[k] for k in keys}, "version": BOX_STATE_VERSION})


#: The equilibrators of a water box's replica states: OpenMM's LangevinMiddleIntegrator at 2 fs (the default, and what
#: issue 26's states were made with: its State velocities are the mid-step ones) or, "svr", the package's velocity
#: Verlet at 1 fs with stochastic velocity rescaling at the ends of the step (collision time 0.1 ps), whose on-step
#: velocities and positions are both canonical.
EQUILIBRATORS = ("langevin", "svr")


def _equilibrate(cfg, system, x, picoseconds, seed, props):
    how = cfg.get("equilibrator", "langevin")
    if how not in EQUILIBRATORS:
        raise InputError(f"equilibrator {how!r}; known: {', '.join(EQUILIBRATORS)}")
    if how == "langevin":
        return equilibrate(system, x, cfg["temperature"], picoseconds, seed, platform="CPU", properties=props)
    from ...integrators import SymplecticIntegrator
    from ...systems.prepare import maxwell_boltzmann

    ig = SymplecticIntegrator(0.001, "verlet", system=system, temperature=float(cfg["temperature"]),
                              collision_time=0.1, random_seed=int(seed), thermostat_position="ends")
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("CPU"), props)
    try:
        ctx.setPositions(x)
        ctx.setVelocities(maxwell_boltzmann(system, x, cfg["temperature"], seed))
        ig.step(int(round(picoseconds * 1000.0)))
        st = ctx.getState(getPositions=True, getVelocities=True)
        return (np.array(st.getPositions(asNumpy=True)._value), np.array(st.getVelocities(asNumpy=True)._value))
    finally:
        del ctx


def water_box_replicas(cfg: dict, model: str, out: str, log=print):
    """(x, v) arrays of shape (replicas, N, 3): at least ``cfg["replicas"]`` states of the model's box (the module's
    docstring), built or extended and kept in ``<out>/states/<model>-<key>.npz``."""
    path = os.path.join(out, "states", f"{model}-{box_state_key(cfg)}.npz")
    xs, vs = [], []
    if os.path.exists(path):
        with np.load(path) as d:
            xs, vs = list(d["x"]), list(d["v"])
        if len(xs) >= int(cfg["replicas"]):
            return np.array(xs), np.array(vs)
    box = water_box_scene(cfg, model)
    props, seed, n_old, t0 = {"Threads": str(cfg.get("threads", 1))}, int(cfg["seed"]), len(xs), time.perf_counter()
    if not xs:
        x = minimise(box.system, box.positions, platform="CPU", properties=props, max_iterations=500)
        x, v = _equilibrate(cfg, box.system, x, cfg["equilibrate_ps"], seed, props)
        xs, vs = [x], [without_net_momentum(v, box.masses())]
    for r in range(len(xs), int(cfg["replicas"])):
        x, v = _equilibrate(cfg, box.system, xs[-1], cfg["spacing_ps"], seed + r, props)
        xs.append(x)
        vs.append(without_net_momentum(v, box.masses()))
    how = "Langevin" if cfg.get("equilibrator", "langevin") == "langevin" else "velocity-rescaling"
    log(f"{model}: {len(box.molecules)} waters, {len(xs)} replica states ({cfg['equilibrate_ps']} + "
        f"{cfg['spacing_ps']} ps apart of {how} dynamics; {len(xs) - n_old} new, "
        f"{time.perf_counter() - t0:.0f} s)")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    write_npz(path, {"x": np.array(xs), "v": np.array(vs)})
    return np.array(xs), np.array(vs)
