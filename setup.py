"""Packaging for openmm_symprk: `pip install .` (add `[test]` for the test-suite)."""
from setuptools import find_packages, setup

setup(
    name="openmm_symprk",
    version="0.1.0",
    description="Symplectic partitioned Runge-Kutta and RATTLE integrators for OpenMM, "
                "with exact momentum conservation and conservation diagnostics",
    long_description=open("README.md", encoding="utf-8").read() if __import__("os").path.exists("README.md") else "",
    long_description_content_type="text/markdown",
    python_requires=">=3.10",
    packages=find_packages(include=["openmm_symprk", "openmm_symprk.*"]),
    package_data={"openmm_symprk": ["data/*.toml"]},
    install_requires=[
        "openmm>=8.6,<8.7",
        "numpy>=1.24",
        "scipy>=1.10",
        "MDAnalysis>=2.7",
        "matplotlib>=3.7",
        "tqdm>=4.60",
    ],
    extras_require={
        "test": ["pytest>=7"],
        "cluster": ["dask[distributed]>=2023.1"],
    },
    entry_points={"console_scripts": ["symprk=openmm_symprk.cli:main"]},
    classifiers=[
        "Programming Language :: Python :: 3",
        "Topic :: Scientific/Engineering :: Chemistry",
        "Topic :: Scientific/Engineering :: Physics",
    ],
)
