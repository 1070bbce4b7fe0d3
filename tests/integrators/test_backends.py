"""SymplecticIntegrator's backend choice: native plugin when it can run, CustomIntegrator otherwise."""
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators import (NativeMethodError, NativeSymplecticIntegrator, NativeUnavailableError,
                                       choose_backend)

needs_native = pytest.mark.skipif(not plugin.available(), reason=f"native backend: {plugin.unavailable_reason()}")


def test_custom_is_always_possible(water8):
    ig = SymplecticIntegrator(2 * unit.femtoseconds, "yoshida-4", system=water8.system, backend="custom")
    assert isinstance(ig, mm.CustomIntegrator) and ig.backend == "custom"


def test_general_tableaux_fall_back_to_custom(morse):
    assert choose_backend("gauss-2") == "custom"
    assert choose_backend("verlet", options={"tolerance": 1e-3}) == "custom"
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "rk4", system=morse.system, allow_nonsymplectic=True)
    assert isinstance(ig, mm.CustomIntegrator)


def test_bad_backend_name():
    with pytest.raises(ValueError, match="backend must be one of 'auto', 'native', 'custom', got 'gpu'"):
        SymplecticIntegrator(0.001, "verlet", backend="gpu")


@needs_native
def test_auto_picks_native_with_the_same_interface(water8):
    ig = SymplecticIntegrator(2 * unit.femtoseconds, "kahan-li-6", system=water8.system)
    assert isinstance(ig, NativeSymplecticIntegrator) and ig.backend == "native"
    custom = SymplecticIntegrator(2 * unit.femtoseconds, "kahan-li-6", system=water8.system, backend="custom")
    assert ig.force_evals == custom.program_info.force_evals == 9  # the plugin's count, and the method's
    assert ig.program_info.rattle and custom.program_info.rattle


@needs_native
def test_native_refuses_what_it_cannot_do(morse):
    with pytest.raises(NativeMethodError, match="'gauss-2'"):
        SymplecticIntegrator(0.001, "gauss-2", backend="native")
    with pytest.raises(ValueError, match="does not take the option.*tolerance"):
        SymplecticIntegrator(0.001, "verlet", backend="native", tolerance=1e-3)


@pytest.mark.skipif(plugin.available(), reason="the native backend is built here")
def test_native_unavailable_is_a_clear_error():
    with pytest.raises(NativeUnavailableError, match="unavailable"):
        SymplecticIntegrator(0.001, "verlet", backend="native")
