"""OpenMM platforms as the studies name them: ``NAME`` or ``NAME:PRECISION`` (e.g. ``CPU``, ``OpenCL:mixed``), whether
this installation has one, and the Context properties a run sets (the CPU platform's threads, a GPU platform's
precision)."""
from __future__ import annotations

from ...support.errors import InputError

__all__ = ["PRECISIONS", "split", "names", "available", "check", "properties"]

#: The precision modes of OpenMM's OpenCL, CUDA and HIP platforms.
PRECISIONS = ("single", "mixed", "double")


def split(spec: str) -> tuple:
    """``"OpenCL:mixed"`` -> ("OpenCL", "mixed"); ``"CPU"`` -> ("CPU", None); ValueError for an unknown precision."""
    name, _, precision = str(spec).partition(":")
    if precision and precision not in PRECISIONS:
        raise InputError(f"platform {spec!r}: precision {precision!r} not known; give NAME or NAME:PRECISION with "
                         f"PRECISION one of {', '.join(PRECISIONS)}, e.g. CPU,OpenCL:single,OpenCL:mixed,OpenCL:double")
    return name, precision or None


def names() -> list:
    """The names of this installation's OpenMM platforms."""
    import openmm as mm

    return [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]


def available(name: str) -> bool:
    """Whether this installation of OpenMM has the platform ``name`` (a spec's precision is ignored)."""
    return split(name)[0] in names()


def check(name: str) -> str:
    """``name`` if this installation has that platform (a name, no precision); ValueError naming those it has."""
    if name not in names():
        raise InputError(f"unknown OpenMM platform {name!r}; this installation has {', '.join(names())}")
    return name


def properties(name: str, threads: int | None = None, precision: str | None = None) -> dict:
    """The Context properties of a run: ``Threads`` on the CPU platform, ``Precision`` elsewhere when given."""
    if name == "CPU":
        return {"Threads": str(int(threads))} if threads else {}
    return {"Precision": precision} if precision else {}
