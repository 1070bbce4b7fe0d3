import openmm as mm
import pytest


def platform_available(name: str) -> bool:
    try:
        mm.Platform.getPlatformByName(name)
        return True
    except Exception:
        return False


@pytest.fixture(scope="session")
def water27():
    from openmm_symprk.scenes import water_cluster

    return water_cluster(27)


@pytest.fixture(scope="session")
def water8():
    from openmm_symprk.scenes import water_cluster

    return water_cluster(8)


@pytest.fixture(scope="session")
def morse():
    from openmm_symprk.scenes import morse_molecule

    return morse_molecule()


@pytest.fixture(scope="session")
def constrained():
    from openmm_symprk.scenes import constrained_molecule

    return constrained_molecule()
