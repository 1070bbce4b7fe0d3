"""Multiple time stepping as a splitting (openmm_symprk.methods.respa): exact sequences, evaluation counts,
errors, and the order of RESPA compositions on a two-scale oscillator (pure numpy)."""
from fractions import Fraction

import numpy as np
import pytest

from openmm_symprk.methods import methods
from openmm_symprk.methods.respa import MTSError, evaluations_per_step, kick_label, label_groups, levels, respa

V = methods["verlet"].splitting


def test_verlet_respa_is_tuckermans_sequence():
    seq = respa(levels([(0, 1), (1, 2)], V, V))
    half, quarter = Fraction(1, 2), Fraction(1, 4)
    assert seq.steps == (("kick:0", half), ("kick:1", quarter), ("drift", half), ("kick:1", half),
                         ("drift", half), ("kick:1", quarter), ("kick:0", half))
    assert evaluations_per_step(seq) == {(0,): 1, (1,): 2}
    # a third level, 8 per step: group 2 every eighth of the step
    three = respa(levels([(0, 1), (1, 2), (2, 8)], V, V))
    assert evaluations_per_step(three) == {(0,): 1, (1,): 2, (2,): 8}
    assert three.total("drift") == 1 and all(three.total(kick_label((g,))) == 1 for g in range(3))


def test_groups_with_equal_substeps_share_a_level_and_labels_round_trip():
    lv = levels([(3, 2), (0, 1), (5, 2)], V, V)
    assert [(x.groups, x.substeps) for x in lv] == [((0,), 1), ((3, 5), 2)]
    assert label_groups(kick_label((5, 3))) == (3, 5) and label_groups("kick") is None


@pytest.mark.parametrize("groups,message", [
    ([], "empty"), ([(0, 1), (0, 2)], "appears twice"), ([(0, 0)], "substeps 0"), ([(40, 1)], "from 0 to 31"),
    ([(0, 2), (1, 3)], "not a multiple"), (7, "pairs"), ([(0, 1.5)], "whole number"),
])
def test_bad_specifications_are_refused(groups, message):
    with pytest.raises(MTSError, match=message):
        levels(groups, V, V)


def _two_scale(outer, inner, h, n_steps, k_fast=400.0, k_slow=1.0, substeps=4):
    """q'' = -(k_fast + k_slow) q as a stiff plus a soft spring, by RESPA (fast inner), unit mass; also a cubic
    slow force so that the order conditions are nonlinear.  Returns (q, p) at the end."""
    seq = respa(levels([(0, 1), (1, substeps)], methods[outer].splitting, methods[inner].splitting))
    forces = {"kick:0": lambda q: -k_slow * q - q ** 3, "kick:1": lambda q: -k_fast * q}
    q, p = np.longdouble(0.3), np.longdouble(0.1)
    coeffs = seq.coefficients(np.longdouble)
    hh = np.longdouble(h)
    for _ in range(n_steps):
        for lab, c in coeffs:
            if lab == "drift":
                q = q + c * hh * p
            else:
                p = p + c * hh * forces[lab](q)
    return q, p


@pytest.mark.parametrize("outer,inner,order", [("verlet", "verlet", 2), ("yoshida-4", "yoshida-4", 4),
                                               ("omelyan-2", "verlet", 2), ("yoshida-6", "yoshida-6", 6)])
def test_respa_order_on_a_two_scale_oscillator(outer, inner, order):
    T = 2.0
    ys = [np.array(_two_scale(outer, inner, T / n, n)) for n in (20, 40, 80, 160)]
    d = [np.abs(a - b).max() for a, b in zip(ys, ys[1:])]
    measured = np.log2(float(d[-2] / d[-1]))
    assert abs(measured - order) < 0.3, (outer, inner, [float(x) for x in d], measured)
