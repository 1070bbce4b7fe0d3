import locale

import openmm as mm
import pytest

#: The character type the interpreter took from the environment (C.UTF-8 here).
CTYPE = locale.setlocale(locale.LC_CTYPE)


def platform_available(name: str) -> bool:
    try:
        mm.Platform.getPlatformByName(name)
        return True
    except Exception:
        return False


def pytest_runtest_setup(item):
    """A C library a test loads may set the C locale's character type to "C" (seen on this machine in long runs of
    the suite, not in a shorter one): Python's text files and pipes then read as ASCII. Every test starts with the
    character type the interpreter started with."""
    if locale.setlocale(locale.LC_CTYPE) != CTYPE:
        locale.setlocale(locale.LC_CTYPE, CTYPE)


@pytest.fixture(autouse=True)
def fresh_warnings():
    """Every test sees the package's one-time warnings as a fresh process would."""
    from openmm_symprk.systems.checks import warn_once

    warn_once.reset()
    yield
    warn_once.reset()


@pytest.fixture(scope="session")
def water27():
    from openmm_symprk.systems.scenes import water_cluster

    return water_cluster(27)


@pytest.fixture(scope="session")
def water8():
    from openmm_symprk.systems.scenes import water_cluster

    return water_cluster(8)


@pytest.fixture(scope="session")
def morse():
    from openmm_symprk.systems.scenes import morse_molecule

    return morse_molecule()


@pytest.fixture(scope="session")
def constrained():
    from openmm_symprk.systems.scenes import constrained_molecule

    return constrained_molecule()
