"""The modified energy's second-order coefficients (openmm_symprk.methods.shadow): exact values for velocity Verlet,
conservation to O(h^4) on an anharmonic oscillator for every symmetric splitting of the catalogue, and agreement
with the placement module's exact harmonic moments."""
from fractions import Fraction

import numpy as np
import pytest

from openmm_symprk.methods.catalogue import get_method, methods
from openmm_symprk.methods.placement import harmonic_sampling, with_thermostat
from openmm_symprk.methods.shadow import coefficients, event_coefficients, nvt_temperatures, shadow_target


def _symmetric_splittings():
    out = []
    for name, method in sorted(methods.items()):
        split = getattr(method, "splitting", None)
        if split is None or name != method.name:
            continue
        steps = [(label, Fraction(c)) for label, c in split.steps]
        if steps == steps[::-1] and all(label in ("kick", "drift") for label, _ in steps):
            out.append((name, method.order))
    return out


SYMMETRIC = _symmetric_splittings()


def test_velocity_verlet_read_at_its_ends_and_between_its_half_drifts():
    c_t, c_v = coefficients(get_method("verlet").splitting.steps)
    assert c_t == pytest.approx(1 / 6, abs=1e-6) and c_v == pytest.approx(-1 / 12, abs=1e-6)
    middle = event_coefficients(get_method("verlet").splitting.steps, "middle")
    assert middle["event"] == pytest.approx(-1 / 12, abs=1e-6)
    assert middle["ends"] == pytest.approx((1 / 6, -1 / 12), abs=1e-6)


def _spread(steps, h, c_t=0.0, c_v=0.0, n=4000):
    """Peak-to-peak of H + h^2/2 (c_T p^2 V'' + c_V V'^2) along a trajectory of V = q^2/2 + q^4/4 (m = 1)."""
    dv = lambda q: q + q ** 3  # noqa: E731
    q, p, out = 1.0, 0.5, []
    for _ in range(n):
        for label, c in steps:
            if label == "drift":
                q += float(c) * h * p
            else:
                p -= float(c) * h * dv(q)
        out.append(p * p / 2 + q * q / 2 + q ** 4 / 4 + h * h / 2 * (c_t * p * p * (1 + 3 * q * q) + c_v * dv(q) ** 2))
    return float(np.ptp(out))


@pytest.mark.parametrize("name,order", SYMMETRIC)
def test_the_modified_energy_is_conserved_to_fourth_order_on_an_anharmonic_oscillator(name, order):
    """H itself wanders as h^2 (halving h divides its spread by 4); H~ with the two coefficients as h^4 (by about 16):
    each coefficient is right, not only their harmonic combinations.  A method of order 4 or more has no h^2 term."""
    steps = get_method(name).splitting.steps
    c_t, c_v = coefficients(steps)
    if order > 2:
        assert abs(c_t) < 1e-6 and abs(c_v) < 1e-6, (name, c_t, c_v)
        return
    h = 0.4 / max(1, len(steps) // 2)
    plain = _spread(steps, h) / _spread(steps, h / 2)
    shadow = _spread(steps, h, c_t, c_v) / _spread(steps, h / 2, c_t, c_v)
    assert plain == pytest.approx(4.0, rel=0.1)
    assert shadow > 11.0, (name, c_t, c_v, shadow)


@pytest.mark.parametrize("name", ["verlet", "omelyan-2", "bcss-2", "predescu-3"])
def test_the_difference_of_the_coefficients_is_the_ends_placements_configurational_error(name):
    """Kinetic energy pinned at the ends of the step, one harmonic mode samples w^2<q^2>/kT = 1 + (c_T - c_V)(hw)^2."""
    steps = get_method(name).splitting.steps
    c_t, c_v = coefficients(steps)
    x = 0.05
    q2, _ = harmonic_sampling(with_thermostat(steps, "ends"), x)
    assert (q2 - 1.0) / x ** 2 == pytest.approx(c_t - c_v, abs=2e-3)


def test_a_sequence_that_is_not_symmetric_about_its_start_is_refused():
    steps = get_method("verlet").splitting.steps
    with pytest.raises(ValueError, match="not symmetric"):
        coefficients(list(steps)[1:] + list(steps)[:1])


def test_the_predicted_shifts_and_the_target_that_removes_the_global_one():
    steps = get_method("verlet").splitting.steps
    got = nvt_temperatures(steps, "ends", {"trans": 0.01, "rot": 0.05})
    assert got["global"] == pytest.approx(0.03 / 6, rel=1e-4)
    assert got["kinetic"]["rot"] == pytest.approx(0.03 / 6 - 0.05 / 6, rel=1e-4)
    assert got["configurational"]["trans"] == pytest.approx(0.03 / 6 + 0.01 / 12, rel=1e-4)
    assert shadow_target(steps, "ends", 0.03) == pytest.approx(1 - 0.03 / 6, rel=1e-6)
    assert shadow_target(steps, "middle", 0.03) == pytest.approx(1 + 0.03 / 12, rel=1e-6)
