"""The rows the NVT measurements compare (data: one line a row, a :class:`~..core.rows.Row` label each).

The package's integrators (``SVR 0.1 ps``: ``temperature=`` with the package's default ``collision_time``, as
GROMACS users set v-rescale's tau; or NVE), OpenMM 8.6's thermostatted integrators with friction (collision
frequency) 1/ps, OpenMM's usual choice, and its VerletIntegrator.  Velocity rescaling acts on one collective
variable, the kinetic energy, so its tau is no per-particle friction; and an event is the same work whatever tau.
The rows with ``4/2 fs`` step the slow group 1 (PME reciprocal space) once per outer step, group 0 twice.
"""
from __future__ import annotations

from ..core.rows import Row

#: The thermostats' target temperature (K).
TEMPERATURE = 300.0

#: The cost table: (name printed, row, the OpenMM row it replaces -- its ratio is printed too); data, one line a
#: row, so its lines are alike on purpose.
COST_ROWS = [
    ("LangevinMiddle", "langevin 2 fs friction 1/ps", ""),
    ("NoseHoover (chain 3)", "nose-hoover 2 fs 1/ps", ""),
    ("DPD", "dpd 2 fs friction 1/ps cutoff 0.9 nm", ""),
    ("OpenMM Verlet (NVE)", "openmm-verlet 2 fs", ""),
    ("verlet (NVE)", "verlet 2 fs native", "OpenMM Verlet (NVE)"),
    ("verlet + thermostat", "verlet 2 fs SVR 0.1 ps native", ""),
    ("verlet + thermostat middle", "verlet 2 fs SVR 0.1 ps middle native", ""),
    ("verlet + thermostat /10", "verlet 2 fs SVR 0.1 ps every 10 native", ""),
    ("omelyan-2 + thermostat", "omelyan-2 4 fs SVR 0.1 ps native", ""),
    ("omelyan-2 + thermostat middle", "omelyan-2 4 fs SVR 0.1 ps middle native", ""),
    ("MTSLangevin 1x1+0x2", "mts-langevin 4/2 fs friction 1/ps", ""),
    ("verlet MTS 1x1+0x2 + thermostat", "verlet 4/2 fs SVR 0.1 ps native", "MTSLangevin 1x1+0x2"),
]


def cost_rows() -> list:
    """[(name, Row, peer name)] of :data:`COST_ROWS`."""
    return [(name, Row.parse(label), peer) for name, label, peer in COST_ROWS]
