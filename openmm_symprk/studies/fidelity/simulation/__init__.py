"""The OpenMM side of the fidelity study: one run (:mod:`.runs`) and the study on the skeleton of
:mod:`openmm_symprk.studies.core` (:mod:`.study`).  The
observables, the rows' description and the report, in the folder above, are pure numerics."""
from .study import FidelityStudy, run_of, run_study

__all__ = ["FidelityStudy", "run_of", "run_study"]
