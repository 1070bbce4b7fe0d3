"""The configurations whose compiled programs and native Reference trajectories must not change by accident.

``python tests/golden.py`` rewrites ``tests/integrators/data/golden_programs.json`` (only when a change of the
programs is intended: say so in the commit); :mod:`test_golden_programs` checks the current code against it.
Each entry is the SHA-256 of ``XmlSerializer.serialize(integrator)`` (both backends), or of the positions and
velocities (float64 bytes) after 40 native steps on Reference, or the heat-bath energy after them (``repr``).
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit

DATA = os.path.join(os.path.dirname(__file__), "integrators", "data", "golden_programs.json")


def _scenes():
    from openmm_symprk.systems.forcegroups import split_forces
    from openmm_symprk.systems.prepare import maxwell_boltzmann, minimise
    from openmm_symprk.systems.scenes import water_box, water_cluster

    cl = water_cluster(8)
    flex = water_cluster(4, rigid=False)
    box, _, bx = water_box("spce", n_waters=32, cutoff_nm=0.45)
    bx = minimise(box, bx, "Reference", tolerance=10.0, max_iterations=200)
    bv = maxwell_boltzmann(box, bx, 300.0, seed=4)
    mts = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(box))
    split_forces(mts)
    return {"cluster": (cl.system, cl.positions, cl.velocities), "flexible": (flex.system, flex.positions, flex.velocities),
            "box": (box, bx, bv), "mts": (mts, bx, bv)}


#: name -> (scene, step fs, method, options); backend="custom" only where the native backend cannot run it
CONFIGS = {
    "nve-verlet": ("cluster", 1.0, "verlet", {}),
    "nve-yoshida4": ("cluster", 1.0, "yoshida-4", {}),
    "nve-pefrl": ("cluster", 1.0, "pefrl", {}),
    "nve-omelyan2-flex": ("flexible", 1.0, "omelyan-2", {}),
    "exact-verlet": ("cluster", 1.0, "verlet", {"exact_momentum": True}),
    "exact-yoshida4": ("cluster", 1.0, "yoshida-4", {"exact_momentum": True}),
    "nvt-verlet-cluster": ("cluster", 1.0, "verlet", {"temperature": 300, "random_seed": 5, "thermostat_position": "ends"}),
    "nvt-omelyan2-box": ("box", 1.0, "omelyan-2", {"temperature": 300, "random_seed": 7, "thermostat_position": "ends"}),
    "nvt-verlet-box-int5": ("box", 1.0, "verlet", {"temperature": 300, "thermostat_position": "ends", "collision_time": 0.5, "thermostat_interval": 5,
                                                   "random_seed": 9}),
    "nvt-verlet-middle": ("cluster", 1.0, "verlet", {"temperature": 300, "random_seed": 5, "thermostat_interval": 3,
                                                    "thermostat_position": "middle"}),
    "mts-verlet": ("mts", 2.0, "verlet", {"groups": [(1, 1), (0, 2)]}),
    "mts-omelyan2-nvt": ("mts", 2.0, "omelyan-2", {"groups": [(1, 1), (0, 2)], "inner_method": "verlet",
                                                   "temperature": 300, "random_seed": 3, "thermostat_position": "ends"}),
    "custom-gauss2": ("flexible", 1.0, "gauss-2", {"backends": ("custom",)}),
    # the thermostat in the middle of the step (native: once the plugin runs the THERMOSTAT sub-step)
    "nvt-verlet-cluster-middle": ("cluster", 1.0, "verlet", {"temperature": 300, "random_seed": 5,
                                                             "thermostat_position": "middle", "backends": ("custom",)}),
    "nvt-omelyan2-box-middle-int3": ("box", 1.0, "omelyan-2", {"temperature": 300, "random_seed": 7,
                                                               "thermostat_position": "middle", "thermostat_interval": 3,
                                                               "backends": ("custom",)}),
}


def compute(names=None) -> dict:
    from openmm_symprk import SymplecticIntegrator

    warnings.simplefilter("ignore")
    scenes = _scenes()
    out = {}
    for name, (scene, fs, method, options) in CONFIGS.items():
        if names is not None and name not in names:
            continue
        options = dict(options)
        backends = options.pop("backends", ("custom", "native"))
        system, x, v = scenes[scene]
        for backend in backends:
            ig = SymplecticIntegrator(fs * unit.femtoseconds, method, system=system, backend=backend, **options)
            out[f"xml/{backend}/{name}"] = hashlib.sha256(mm.XmlSerializer.serialize(ig).encode()).hexdigest()
            if backend != "native":
                continue
            ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
            ctx.setPositions(x)
            ctx.setVelocities(v)
            ig.step(40)
            st = ctx.getState(getPositions=True, getVelocities=True)
            xs = np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer), dtype=np.float64)
            vs = np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond),
                            dtype=np.float64)
            out[f"traj/native/{name}"] = hashlib.sha256(xs.tobytes() + vs.tobytes()).hexdigest()
            if "temperature" in options:
                out[f"bath/native/{name}"] = repr(float(ig.getHeatBathEnergy()))
            del ctx
    return out


if __name__ == "__main__":
    # python tests/golden.py            rewrites every entry
    # python tests/golden.py NAME ...   rewrites the entries of those configurations only
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), ".."))
    names = sys.argv[1:]
    unknown = [n for n in names if n not in CONFIGS]
    if unknown:
        sys.exit(f"unknown configuration(s) {', '.join(unknown)}; known: {', '.join(CONFIGS)}")
    result = compute(names or None)
    if names:
        with open(DATA) as fh:
            result = {**json.load(fh), **result}
    with open(DATA, "w") as fh:
        json.dump(result, fh, indent=1, sort_keys=True)
        fh.write("\n")
    print(f"wrote {len(result)} entries to {DATA}")
