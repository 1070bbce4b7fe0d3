"""Where the thermostat sits: exact stationary moments on harmonic oscillators (methods.placement)."""
from fractions import Fraction

import numpy as np
import pytest

from openmm_symprk import resolve
from openmm_symprk.methods.placement import (THERMOSTAT, best_position, centre, harmonic_sampling, placement_errors,
                                             with_thermostat)

VERLET = [("kick", Fraction(1, 2)), ("drift", Fraction(1)), ("kick", Fraction(1, 2))]


@pytest.mark.parametrize("x", [0.26, 0.5, 1.0, 1.5])
@pytest.mark.parametrize("decay", [0.05, 0.5, 0.95])
def test_verlet_known_answers(x, decay):
    """Velocity Verlet: ends <q^2>w^2/kT = 1/(1 - x^2/4), on-step <v^2> = 1; middle (BAOAB) 1 and 1 - x^2/4; any c."""
    q2, v2 = harmonic_sampling(with_thermostat(VERLET, "ends"), x, decay)
    assert q2 == pytest.approx(1 / (1 - x * x / 4), rel=1e-12)
    assert v2 == pytest.approx(1.0, rel=1e-12)
    q2, v2 = harmonic_sampling(with_thermostat(VERLET, "middle"), x, decay)
    assert q2 == pytest.approx(1.0, rel=1e-12)
    assert v2 == pytest.approx(1 - x * x / 4, rel=1e-12)


def _monte_carlo(steps, x, decay, n=20000, burn=400, samples=300, seed=1):
    """<q^2>, <v^2> (kT = 1) of n oscillators run with numpy, and the standard errors of the two means."""
    rng = np.random.default_rng(seed)
    q, v = rng.standard_normal(n), rng.standard_normal(n)
    seq = [(label, float(c)) for label, c in steps]
    q2, v2 = [], []
    for k in range(burn + samples):
        for label, c in seq:
            if label == THERMOSTAT:
                a = decay ** c
                v = a * v + np.sqrt(1 - a * a) * rng.standard_normal(n)
            elif label == "drift":
                q = q + c * x * v
            else:
                v = v - c * x * q
        if k >= burn:
            q2.append(np.mean(q * q))
            v2.append(np.mean(v * v))
    # the per-sample means are correlated in time: blocks of 30 samples
    def mean_se(s):
        b = np.asarray(s).reshape(10, -1).mean(axis=1)
        return b.mean(), b.std(ddof=1) / np.sqrt(len(b))
    return mean_se(q2), mean_se(v2)


@pytest.mark.parametrize("position", ["ends", "middle"])
def test_omelyan_exact_moments_against_sampling(position):
    """omelyan-2 (a BABAB scheme, whose centre is a kick): the exact moments agree with a simulation within 4 SE,
    and they are THEORY's: ends 0.997, middle 1.063 at h w = 1 (c = 0.5)."""
    steps = with_thermostat(resolve("omelyan-2").splitting.steps, position)
    q2, v2 = harmonic_sampling(steps, 1.0, 0.5)
    assert q2 == pytest.approx({"ends": 0.9962, "middle": 1.0630}[position], abs=5e-4)
    (mq, sq), (mv, sv) = _monte_carlo(steps, 1.0, 0.5)
    assert abs(mq - q2) < 4 * sq and abs(mv - v2) < 4 * sv


def test_middle_splits_the_central_substep():
    steps = list(resolve("omelyan-2").splitting.steps)
    out = with_thermostat(steps, "middle")
    assert len(out) == len(steps) + 2
    i = centre(steps)
    assert out[i] == (steps[i][0], steps[i][1] / 2) == out[i + 2]
    assert out[i + 1] == (THERMOSTAT, 1)
    assert sum(c for label, c in out if label == "drift") == 1
    ends = with_thermostat(steps, "ends")
    assert ends[0] == ends[-1] == (THERMOSTAT, Fraction(1, 2))


def test_asymmetric_step_has_no_middle():
    with pytest.raises(ValueError, match="symmetric"):
        with_thermostat([("drift", 1), ("kick", 1)], "middle")
    with pytest.raises(ValueError, match="'ends' or 'middle'"):
        with_thermostat(VERLET, "centre")


def test_unstable_step_and_bad_decay():
    with pytest.raises(ValueError, match="not stable"):
        harmonic_sampling(with_thermostat(VERLET, "ends"), 2.5)
    with pytest.raises(ValueError, match="between 0 and 1"):
        harmonic_sampling(with_thermostat(VERLET, "ends"), 1.0, decay=1.0)
    assert placement_errors(VERLET, (2.5,))["ends"] == float("inf")


@pytest.mark.parametrize("name,expected", [("verlet", "middle"), ("omelyan-2", "ends"), ("pefrl", "ends"),
                                           ("yoshida-4", "ends"), ("blanes-moan-srkn6b-4", "ends")])
def test_best_position(name, expected):
    r = resolve(name)
    assert best_position(r.splitting.steps, r.stability) == expected


def test_multiple_time_stepping_centre_is_a_fast_kick():
    """Verlet outside, two inner Verlet steps: the outer step's centre falls inside the fast group's middle kick,
    which samples like the ends placement of the inner steps (1/(1 - (x/2)^2/4))."""
    steps = resolve("verlet", groups=[(1, 1), (0, 2)]).splitting.steps
    fast = {"kick:0"}
    for position in ("ends", "middle"):
        q2, _ = harmonic_sampling(with_thermostat(steps, position), 1.0, 0.5, forced=fast)
        assert q2 == pytest.approx(1 / (1 - 0.25 / 4), rel=1e-12)
    assert best_position(steps, forced=fast) == "ends"


def test_an_event_every_n_steps_keeps_each_placements_known_answer():
    """One event every n steps (thermostat_interval n, what the frontier study's common event grid uses): Verlet with
    the event in the middle of the interval's centre step still samples the oscillator's configurations exactly, at
    every step boundary of the interval, and the ends placement's half events around the interval still give
    1/(1 - h^2 w^2/4): the interval moves neither known answer (h w = 0.5; n = 1, 2, 3, 6)."""
    from openmm_symprk.methods.placement import THERMOSTAT, harmonic_sampling

    verlet = [("kick", 0.5), ("drift", 1.0), ("kick", 0.5)]
    for n in (1, 2, 3, 6):
        for where, exact in (("middle", 1.0), ("ends", 1 / (1 - 0.25 / 4))):
            steps = []
            for i in range(n):
                step = list(verlet)
                if where == "middle" and i == (n - 1) // 2:
                    step = [("kick", 0.5), ("drift", 0.5), (THERMOSTAT, float(n)), ("drift", 0.5), ("kick", 0.5)]
                if where == "ends":
                    step = ([(THERMOSTAT, n / 2)] if i == 0 else []) + step + ([(THERMOSTAT, n / 2)] if i == n - 1 else [])
                steps.append(step)
            for r in range(n):  # read at each step boundary of the interval
                q2, _ = harmonic_sampling(sum(steps[r + 1:] + steps[:r + 1], []), 0.5, decay=0.5)
                assert q2 == pytest.approx(exact, rel=1e-9), (where, n, r)


def test_the_middle_placement_advice_names_where_it_falls_and_what_it_costs():
    """The middle is the worse placement for every splitting but Verlet: the advice says where the middle falls (a
    kick for BABAB schemes), quotes the harmonic oscillator's configurational temperature in both placements, and
    the measurement in water where there is one; for Verlet, whose best placement is the middle, there is none."""
    from openmm_symprk.methods.catalogue import get_method
    from openmm_symprk.methods.placement import middle_placement_advice

    assert middle_placement_advice("verlet", get_method("verlet").splitting.steps) is None
    text = middle_placement_advice("omelyan-2", get_method("omelyan-2").splitting.steps)
    assert "inside its central kick" in text and "1.0150" in text and "1.0003" in text and "SPC/E" in text
    assert "'auto'" in text
    pefrl = middle_placement_advice("pefrl", get_method("pefrl").splitting.steps)
    assert pefrl is not None and "SPC/E" not in pefrl  # not measured in water: the harmonic numbers only
