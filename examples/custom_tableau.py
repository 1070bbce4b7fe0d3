"""Your own method: a PRK tableau pair or a kick/drift sequence, checked before use.

    python examples/custom_tableau.py          (--quick: the same, it takes a second anyway)

1. A user splitting (here McLachlan's 2-stage 'optimal' second-order method, written as a sequence).
2. The same method as a PRK tableau pair: Reich's residuals are reported and the integrator accepts it.
3. A non-symplectic pair (Lobatto IIIA with itself) is refused with its residual, unless opted in.
"""
import argparse

import openmm.unit as unit

from openmm_symprk import PRKIntegrator, PRKTableau, Splitting, TableauError
from openmm_symprk.methods.reference import measure_order
from openmm_symprk.methods.stability import stability_interval
from openmm_symprk.systems.scenes import morse_molecule

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("--quick", action="store_true", help="accepted for uniformity: this example takes a second")
parser.parse_args()

# 1. a splitting, coefficients as exact strings
b = "0.1931833275037835739600"
mine = Splitting([("kick", b), ("drift", "1/2"), ("kick", f"{1 - 2 * float(b)!r}"), ("drift", "1/2"), ("kick", b)])
orders, _ = measure_order(mine)
print(f"my splitting: measured order {orders[-1]:.2f}, largest stable h*omega {stability_interval(mine):.4f}, "
      f"{mine.force_evaluations()} force evaluations per step")

# 2. the same as a tableau pair
tab = PRKTableau.from_splitting(mine, name="my-omelyan")
print(tab.summary())
scene = morse_molecule()
integrator = PRKIntegrator(1 * unit.femtoseconds, tab, system=scene.system)
print(integrator.describe())
context = scene.context(integrator)
integrator.step(100)

# 3. a non-symplectic pair is refused with the residual of condition (6)
A = [["0", "0", "0"], ["5/24", "1/3", "-1/24"], ["1/6", "2/3", "1/6"]]
bb = ["1/6", "2/3", "1/6"]
try:
    PRKIntegrator(1 * unit.femtoseconds, PRKTableau(A, bb, A, bb, name="lobatto-iiia-iiia"))
except TableauError as err:
    print("refused:", err)
