"""The thermostat's target lowered by the modified energy (integrators.shadow.lowered_target)."""
import numpy as np
import openmm.unit as unit
import pytest

from openmm_symprk import lowered_target
from openmm_symprk.methods.catalogue import get_method
from openmm_symprk.methods.shadow import shadow_target
from openmm_symprk.systems.frequencies import mean_square_frequency
from openmm_symprk.systems.scenes import water_cluster


@pytest.fixture(scope="module")
def cluster():
    return water_cluster(8)


def test_the_target_is_lowered_by_c_t_h2_omega2(cluster):
    """T (1 - c_T h^2 <w^2>) with <w^2> of the configurations given, c_T of omelyan-2 at the ends ("auto"), and a
    Quantity in, a Quantity out; a larger step lowers it more, and the middle of Verlet (its "auto") differs from
    the ends."""
    x = np.asarray(cluster.positions)  # nm
    omega2 = mean_square_frequency(cluster.system, [x], 300.0)["all"]
    got = lowered_target("omelyan-2", 4 * unit.femtoseconds, cluster.system, x * unit.nanometer, 300 * unit.kelvin)
    want = 300.0 * shadow_target(get_method("omelyan-2").splitting.steps, "ends", 0.004 ** 2 * omega2)
    assert got.value_in_unit(unit.kelvin) == pytest.approx(want, rel=1e-12) and want < 300.0
    assert lowered_target("omelyan-2", 0.006, cluster.system, [x, x], 300.0) < want
    verlet = get_method("verlet").splitting.steps
    assert lowered_target("verlet", 0.002, cluster.system, x, 300.0) == pytest.approx(
        300.0 * shadow_target(verlet, "middle", 0.002 ** 2 * omega2), rel=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    ({"step_size": -1.0}, "step size"),
    ({"temperature": 0.0}, "temperature 0.0"),
    ({"method": "gauss-2"}, "kick/drift method"),
])
def test_bad_input_is_named(cluster, kwargs, message):
    args = {"method": "omelyan-2", "step_size": 0.004, "temperature": 300.0, **kwargs}
    with pytest.raises(ValueError, match=message):
        lowered_target(args["method"], args["step_size"], cluster.system, cluster.positions, args["temperature"])


def test_unequilibrated_configurations_are_refused_and_a_large_lowering_warns(cluster):
    """Positions straight from a builder carry large forces: <w^2> then lowers the target by far more than the
    first-order correction can mean (refused, naming the per cent and what to pass); between 2 and 5 % it warns."""
    from openmm_symprk.integrators.shadow import LoweredTargetWarning, REFUSE_ABOVE, WARN_ABOVE
    from openmm_symprk.systems.scenes import water_box

    system, _, raw = water_box("spce", n_waters=64, cutoff_nm=0.6)  # Modeller's positions: not minimised
    with pytest.raises(ValueError, match=r"lowers 300 K by 1\d\.\d\d %.*equilibrated run"):
        lowered_target("omelyan-2", 0.005, system, raw, 300.0)
    x = np.asarray(cluster.positions)
    omega2 = mean_square_frequency(cluster.system, [x], 300.0)["all"]
    steps = get_method("verlet").splitting.steps
    # a step whose lowering (Verlet's middle: c_T = -1/12 raises it; the ends: 1/6) lies between the two bounds
    h = (0.5 * (WARN_ABOVE + REFUSE_ABOVE) / (omega2 / 6.0)) ** 0.5
    assert WARN_ABOVE < 1 - shadow_target(steps, "ends", h * h * omega2) < REFUSE_ABOVE
    with pytest.warns(LoweredTargetWarning, match="doubtful"):
        lowered_target("verlet", h, cluster.system, x, 300.0, thermostat_position="ends")
    with pytest.raises(ValueError, match="no configuration given"):
        lowered_target("omelyan-2", 0.004, cluster.system, [], 300.0)
