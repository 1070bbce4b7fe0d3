"""The one timing harness of the studies: integrators take turns, so machine load hits them alike.

Wall-time ratios between integrators are only meaningful when they are measured in the same run under the
same load.  :func:`interleaved` runs every stepper for a block of steps in turn, round after round, and
keeps each one's fastest block (load from other processes only ever slows a block down), its total and every
block's time (so that a ratio can be taken round by round, between blocks run moments apart).
:func:`time_rows` times running rows (:class:`~.engine.RowEngine`) so: the studies' cost and speed tables, the
bench (each run against OpenMM's VerletIntegrator), the replica studies' wall time per simulated ps.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from ...support.errors import InputError

__all__ = ["Timing", "interleaved", "time_rows", "seconds_per_ps"]


@dataclass
class Timing:
    best: float  # seconds per step of the fastest block
    total: float  # seconds over all blocks
    steps: int  # steps timed in all
    blocks: list = field(default_factory=list)  # seconds per step of each block, in round order

    @property
    def mean(self) -> float:
        return self.total / self.steps if self.steps else float("nan")


def interleaved(steppers: dict, steps, rounds: int = 3, after=None) -> dict:
    """Time ``steppers`` ({name: callable(n) that advances n steps}) in turns: ``rounds`` rounds of
    ``steps`` steps each (an int, or {name: steps} when their costs differ).  ``after(name)`` runs after each
    block, outside the timing (e.g. a measurement).  Returns {name: Timing}."""
    if rounds < 1:
        raise InputError(f"rounds must be >= 1, got {rounds}")
    counts = steps if isinstance(steps, dict) else {name: steps for name in steppers}
    out = {name: Timing(float("inf"), 0.0, 0) for name in steppers}
    for _ in range(rounds):
        for name, advance in steppers.items():
            n = int(counts[name])
            if n < 1:
                raise InputError(f"{name}: steps per block must be >= 1, got {n}")
            t0 = time.perf_counter()
            advance(n)
            dt = time.perf_counter() - t0
            rec = out[name]
            rec.best = min(rec.best, dt / n)
            rec.blocks.append(dt / n)
            rec.total += dt
            rec.steps += n
            if after is not None:
                after(name)
    return out


def time_rows(engines: dict, steps, rounds: int = 3, warmup: int = 0) -> dict:
    """{name: Timing} of ``engines`` ({name: RowEngine}) taking turns, each block's work finished before its clock
    stops (:meth:`~.engine.RowEngine.advance`).  ``steps``: steps per block, an int or {name: int}, or a float
    number of seconds: each row's block sized, from one block of 2 steps, to last about that long (2 to 400 steps),
    so that a 17x slower row does not take 17x the time and every row gets as many short blocks.  ``warmup``: steps
    each row takes first, untimed (kernels compiled, neighbour lists and caches built)."""
    for engine in engines.values():
        if warmup:
            engine.step(warmup)
    steppers = {name: engine.advance for name, engine in engines.items()}
    if isinstance(steps, float):
        first = interleaved(steppers, 2, rounds=1)
        steps = {name: int(min(400, max(2, round(steps / t.best)))) for name, t in first.items()}
    return interleaved(steppers, steps, rounds)


def seconds_per_ps(rows: dict, scene, x, v, block_fs: float, threads: int = 1, seed: int | None = None,
                   rounds: int = 3) -> dict:
    """{label: wall seconds per simulated ps} of ``rows`` ({label: Row}) running from the state (x, v) of
    ``scene``, timed in turns (:func:`time_rows`) in blocks of about ``block_fs`` femtoseconds each, so that the ratios
    between rows hold under the machine's load."""
    from .engine import RowEngine

    engines = {lab: RowEngine(row, scene, x, v, threads=threads, seed=seed) for lab, row in rows.items()}
    res = time_rows(engines, {lab: row.steps_for(block_fs) for lab, row in rows.items()}, rounds)
    return {lab: t.best / rows[lab].h_ps for lab, t in res.items()}

