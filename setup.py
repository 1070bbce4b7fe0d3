"""Packaging for openmm_symprk: `pip install .` (add `[test]` for the test-suite).

The build also compiles the native OpenMM plugin (platforms/, driven by platforms/build_native.py) against
the installed openmm wheel.  If that fails for any reason the package still installs and works through
the CustomIntegrator backend: the build prints a warning, and openmm_symprk.native.unavailable_reason()
reports the error (SYMPRK_NATIVE=0 skips the native build).
"""
import os
import sys
import traceback

from setuptools import Distribution, find_packages, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


class BuildNative(build_ext):
    """Build the native plugin into the package (in place for editable installs); never fail the install."""

    def run(self):
        inplace = bool(self.inplace or getattr(self, "editable_mode", False))
        target = os.path.join(HERE if inplace else self.build_lib, "openmm_symprk", "plugin")
        os.makedirs(target, exist_ok=True)
        error_file = os.path.join(target, "_build_error.txt")
        if os.path.exists(error_file):
            os.remove(error_file)
        try:
            sys.path.insert(0, os.path.join(HERE, "platforms"))
            import build_native

            build_native.build(target, os.path.join(self.build_temp, "symprk-native"), log=self._log)
        except Exception as exc:  # noqa: BLE001 - any failure must leave the pure-Python install working
            reason = str(exc) if exc.__class__.__name__ == "NativeBuildError" else traceback.format_exc()
            with open(error_file, "w") as fh:
                fh.write(reason)
            bar = "=" * 78
            sys.stderr.write(f"\n{bar}\nWARNING: openmm_symprk's native plugin was not built; the package installs "
                             f"and works\nthrough the CustomIntegrator backend only.\nReason: {reason.strip()}\n{bar}\n\n")
        finally:
            if sys.path and sys.path[0] == os.path.join(HERE, "platforms"):
                sys.path.pop(0)

    def _log(self, msg):
        sys.stderr.write(msg + "\n")

    def get_outputs(self):
        return []


class BinaryDistribution(Distribution):
    """The wheel carries compiled libraries: platform-specific, and build_ext always runs."""

    def has_ext_modules(self):
        return True

setup(
    name="openmm_symprk",
    version="0.1.0",
    description="Symplectic partitioned Runge-Kutta and RATTLE integrators for OpenMM, "
                "with exact momentum conservation and conservation diagnostics",
    long_description=open("README.md", encoding="utf-8").read() if __import__("os").path.exists("README.md") else "",
    long_description_content_type="text/markdown",
    python_requires=">=3.10",
    packages=find_packages(include=["openmm_symprk", "openmm_symprk.*"]),
    package_data={"openmm_symprk.methods": ["data/*.toml"]},
    install_requires=[
        "openmm>=8.6,<8.7",
        "numpy>=1.24",
        "scipy>=1.10",
        "MDAnalysis>=2.7",
        "matplotlib>=3.7",
        "tqdm>=4.60",
    ],
    extras_require={
        "test": ["pytest>=7", "pyelftools>=0.29"],
        "cluster": ["dask[distributed]>=2023.1"],
        "cuda12": ["openmm-cuda-12>=8.6,<8.7"],
    },
    entry_points={"console_scripts": ["symprk=openmm_symprk.cli:main"]},
    cmdclass={"build_ext": BuildNative},
    distclass=BinaryDistribution,
    classifiers=[
        "Programming Language :: Python :: 3",
        "Topic :: Scientific/Engineering :: Chemistry",
        "Topic :: Scientific/Engineering :: Physics",
    ],
)
