"""``symprk demo``'s rows show what they claim: on the platform users run (CPU), exact momentum keeps |dL|/|L| to
round-off where OpenMM's Verlet does not, and the package's thermostat keeps P and L where OpenMM's
LangevinMiddleIntegrator loses them, with a conserved effective energy."""
import pytest

from openmm_symprk.studies.demo import ROWS, default_platform, run_demo


@pytest.fixture(scope="module")
def demo():
    lines = []
    rows = run_demo(n_waters=8, steps=200, chunk=50, out=lines.append)
    return {r.name: r for r in rows}, "\n".join(lines)


def test_every_row_runs_in_table_order(demo):
    rows, text = demo
    assert list(rows) == [name for name, _ in ROWS]
    platform, _ = default_platform()
    assert f"on {platform}." in text
    assert rows["OpenMM VerletIntegrator"].seconds_per_step > 0 and rows["symprk yoshida-4"].evals_per_step == 3


def test_exact_momentum_keeps_momenta_to_round_off(demo):
    rows, _ = demo
    exact = rows["symprk verlet exact_momentum"]
    # |L| of the spinning cluster is ~1e2 Da nm^2/ps: a few hundred steps of double-precision round-off
    assert exact.dL_rel < 1e-13 and exact.dP < 1e-10, (exact.dL_rel, exact.dP)
    if default_platform()[0] == "CPU":
        # the point of the demo: OpenMM's Verlet on CPU (single-precision forces) loses L by orders of magnitude more
        assert rows["OpenMM VerletIntegrator"].dL_rel > 100 * exact.dL_rel


def test_our_thermostat_keeps_momenta_and_langevin_does_not(demo):
    rows, text = demo
    ours = rows["symprk verlet 300 K exact_momentum"]
    langevin = rows["OpenMM LangevinMiddle 300 K"]
    assert ours.nvt and langevin.nvt
    assert ours.dL_rel < 1e-13 and ours.dP < 1e-10, (ours.dL_rel, ours.dP)
    # random forces on 24 atoms for 0.4 ps at 1/ps: |dP| of order 10 Da nm/ps, and L changes by a sizeable fraction
    assert langevin.dP > 0.5 and langevin.dL_rel > 1e-3, (langevin.dP, langevin.dL_rel)
    # the effective energy (E + heat-bath energy) is conserved to the integrator's error, like the NVE rows';
    # Langevin has none and shows a dash
    nve = rows["symprk verlet"].energy_error
    assert ours.energy_error is not None and ours.energy_error < 20 * nve, (ours.energy_error, nve)
    assert langevin.energy_error is None
    line = next(l for l in text.splitlines() if l.startswith("OpenMM LangevinMiddle"))
    assert line.split()[5] == "-"


def test_reference_is_the_fallback_and_says_so():
    assert default_platform(["Reference", "CPU", "OpenCL"]) == ("CPU", "")
    platform, note = default_platform(["Reference", "OpenCL"])
    assert platform == "Reference" and "CPU platform is not available" in note and "fallback" in note


def test_named_methods_run_beside_openmm_verlet():
    rows = run_demo(methods=["velocity-verlet"], n_waters=4, steps=20, out=lambda line: None)
    assert [r.name for r in rows] == ["OpenMM VerletIntegrator", "symprk verlet"]
    assert not any(r.nvt for r in rows) and all(r.energy_error is not None for r in rows)
