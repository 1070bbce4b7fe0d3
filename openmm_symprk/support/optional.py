"""Optional dependencies, imported where a feature needs them.

The integrators need only OpenMM and numpy.  Analysis, charts, progress bars, statistics and cluster runs
need more; each is installed by an extra of the package (pyproject.toml's ``optional-dependencies`` holds the
same table as :data:`EXTRAS`)::

    pip install 'openmm_symprk[analysis]'   # MDAnalysis, scipy, tqdm
    pip install 'openmm_symprk[studies]'    # matplotlib, tqdm, pymbar, scipy, MDAnalysis
    pip install 'openmm_symprk[cluster]'    # dask[distributed]
    pip install 'openmm_symprk[all]'        # analysis + studies

A module that needs one imports it through :func:`require`, which returns the module or raises
:class:`MissingDependencyError` (an ImportError, and a :class:`~.errors.SymprkError`: the command prints it as
one line) saying which feature needs which package and which extra installs it::

    mda = require("MDAnalysis", "analysis", "openmm_symprk.analysis.universe")
"""
from __future__ import annotations

import importlib

from .errors import SymprkError

#: The pip requirement of each optional top-level module.
PACKAGES = {"MDAnalysis": "MDAnalysis", "scipy": "scipy", "matplotlib": "matplotlib", "tqdm": "tqdm",
            "pymbar": "pymbar", "dask": "dask[distributed]", "distributed": "dask[distributed]"}

#: The package's extras and the packages each installs (pyproject.toml's ``optional-dependencies`` names the same).
EXTRAS = {
    "analysis": ("MDAnalysis", "scipy", "tqdm"),
    "studies": ("matplotlib", "tqdm", "pymbar", "scipy", "MDAnalysis"),
    "cluster": ("dask[distributed]",),
}
EXTRAS["all"] = tuple(dict.fromkeys(EXTRAS["analysis"] + EXTRAS["studies"]))


class MissingDependencyError(SymprkError, ImportError):
    """An optional package a feature needs is missing (or fails to import).  ``package`` is its pip
    requirement, ``extra`` the extra of openmm_symprk that installs it, ``feature`` what needed it."""

    def __init__(self, message, *, package, extra, feature, name=None):
        super().__init__(message, name=name)
        self.package, self.extra, self.feature = package, extra, feature


def require(module: str, extra: str, feature: str):
    """Import and return ``module`` (e.g. ``"MDAnalysis"``, ``"scipy.special"``, ``"dask.distributed"``),
    which ``feature`` (the public name of what needs it) uses and the extra ``extra`` installs.

    Raises :class:`MissingDependencyError` if it cannot be imported: "<feature> needs <package>: pip
    install 'openmm_symprk[<extra>]'", with the import's own reason when the package is installed but
    broken.  Raises ValueError if ``extra`` is not an extra of the package or does not install ``module``
    (a mistake in the caller, not in the user's installation)."""
    top = module.split(".")[0]
    package = PACKAGES.get(top)
    if package is None:
        raise ValueError(f"require: {top!r} is not an optional dependency of openmm_symprk; "
                         f"known: {', '.join(sorted(PACKAGES))}")
    if package not in EXTRAS.get(extra, ()):
        wanted = [e for e, pkgs in EXTRAS.items() if package in pkgs]
        raise ValueError(f"require: the extra {extra!r} does not install {package} "
                         f"(it is in {', '.join(repr(e) for e in wanted)})")
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        missing = exc.name or ""
        if missing and (module == missing or module.startswith(missing + ".")
                        or (top == "dask" and missing == "distributed")):
            why = "which is not installed"  # the module itself or a parent package of it is absent
        else:  # installed, but it (or one of its own dependencies) does not import
            why = f"which does not import here ({type(exc).__name__}: {exc})"
        raise MissingDependencyError(
            f"{feature} needs {package}, {why}: pip install 'openmm_symprk[{extra}]' (or pip install '{package}')",
            package=package, extra=extra, feature=feature, name=module) from exc
