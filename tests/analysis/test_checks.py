"""The checks applied to frames before an analysis (openmm_symprk.analysis.universe.checks), on made-up frames:
what they accept (float32 times, a cluster losing a molecule) as well as what they refuse."""
import numpy as np
import pytest

pytest.importorskip("MDAnalysis")
from openmm_symprk.analysis.universe.checks import (describe_steps, geometry_problem, time_steps,  # noqa: E402
                                                    wrapped_problem)


def test_float32_times_far_from_zero_are_evenly_spaced_and_a_gap_is_not():
    """XTC stores times as float32: at 100 ns, 0.1-ps steps come out 0.0938 to 0.1016 ps (float32's spacing there
    is 0.0078 ps) and are one interval; a step of 0.2 ps among them is not."""
    t = (1e5 + 0.1 * np.arange(50)).astype(np.float32).astype(np.float64)
    assert np.ptp(np.diff(t)) > 0.005  # the rounding is there
    dt, irregular = time_steps(t)
    assert dt == pytest.approx(0.1, rel=1e-3) and len(irregular) == 0
    t[30:] += 0.1
    dt, irregular = time_steps(t)
    assert irregular.tolist() == [29]
    assert ("between frame 29 (t = 100002.898 ps) and frame 30 (t = 100003.1 ps) 0.202 ps pass where the other "
            "frames are 0.1 ps apart") in describe_steps(t, irregular)


def _water(n, spacing=3.1, rng=None):
    """n SPC/E-shaped waters (O, H, H; Angstrom) on a cubic lattice, randomly oriented: positions (3n, 3),
    masses, molecules."""
    rng = rng or np.random.default_rng(0)
    side = int(np.ceil(n ** (1 / 3)))
    o = spacing * np.array([(i, j, k) for i in range(side) for j in range(side) for k in range(side)][:n], float)
    shape = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [np.cos(np.radians(109.47)), np.sin(np.radians(109.47)), 0]])
    x = []
    for centre in o:
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        x.extend(centre + shape @ q.T)
    return np.array(x), np.tile([15.999, 1.008, 1.008], n), np.arange(3 * n).reshape(n, 3)


def test_water_geometry_is_accepted_and_a_swapped_atom_order_is_not():
    x, _, mols = _water(8)
    assert geometry_problem(x, mols) is None
    swapped = mols[:, [1, 2, 0]]  # the "O" is an H
    assert "molecule 0 is not water in the first frame: O-H 1.63 and 1.00 Angstrom, H-H 1.00 Angstrom" in \
        geometry_problem(x, swapped)


def test_a_cluster_losing_a_molecule_is_continuous_and_the_same_frames_wrapped_are_not():
    """Without a box: 27 waters diffusing by 0.3 Angstrom per frame while one flies off at 4 Angstrom per frame
    (evaporation) are continuous; wrapped into a 12 Angstrom box, their centres jump by about its width."""
    rng = np.random.default_rng(5)
    x0, m, mols = _water(27, rng=rng)
    steps = np.repeat(rng.normal(scale=0.3, size=(40, 27, 1, 3)), 3, axis=2).reshape(40, 81, 3)
    steps[:, 0:3] += np.array([4.0, 0.0, 0.0])  # molecule 0 leaves
    x = x0 + np.cumsum(steps, axis=0)
    assert wrapped_problem(x, m, mols) is None
    box = 12.0
    com = x[:, mols].mean(axis=2)  # wrap whole molecules by their centres, as OpenMM's DCDReporter does
    wrapped = (x.reshape(40, 27, 3, 3) - (box * np.floor(com / box))[:, :, None]).reshape(40, 81, 3)
    problem = wrapped_problem(wrapped, m, mols)
    assert problem is not None and "jumps" in problem and "about the width of the system" in problem
    assert wrapped_problem(wrapped, m, mols, jumps=False) is None  # the molecules themselves are whole
