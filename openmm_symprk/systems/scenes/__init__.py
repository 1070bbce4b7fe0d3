"""Scenes: an OpenMM System with one shared initial state and what may be measured on it.

* :mod:`.scene` -- the one scene type, :class:`Scene`, and how scenes and sets of states are stored
  (:func:`save_scene`, :func:`save_states`);
* :mod:`.builders` -- minimal scenes, each modelling no more than the effect it is there to show: rigid or flexible
  water clusters, a Morse molecule, villin in vacuum, periodic water boxes, harmonic oscillators.

The studies' named scenes, their analytic toys and replica states are :mod:`openmm_symprk.studies.core.scenes`,
:mod:`openmm_symprk.studies.core.toys` and :mod:`openmm_symprk.studies.core.replicas`.
"""
from .builders import (WATER_DENSITY_G_CM3, WATER_MODELS, constrained_molecule, harmonic_oscillators, morse_molecule,
                       openmm_data, protein_vacuum, water_box, water_cluster)
from .scene import ALL_INVARIANTS, Scene, load_scene, load_states, save_scene, save_states

__all__ = ["Scene", "ALL_INVARIANTS", "save_scene", "load_scene", "save_states", "load_states", "water_cluster",
           "morse_molecule", "constrained_molecule", "harmonic_oscillators", "protein_vacuum", "water_box", "openmm_data", "WATER_MODELS",
           "WATER_DENSITY_G_CM3"]
