"""The one timing harness of the studies: integrators take turns, so machine load hits them alike.

Wall-time ratios between integrators are only meaningful when they are measured in the same run under the
same load.  :func:`interleaved` runs every stepper for a block of steps in turn, round after round, and
keeps each one's fastest block (load from other processes only ever slows a block down), its total and every
block's time (so that a ratio can be taken round by round, between blocks run moments apart).
Used by ``symprk demo``, the bench (each run against OpenMM's VerletIntegrator), the conservation table
(projection on/off) and the native speed study.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

__all__ = ["Timing", "interleaved"]


@dataclass
class Timing:
    best: float  # seconds per step of the fastest block
    total: float  # seconds over all blocks
    steps: int  # steps timed in all
    blocks: list = field(default_factory=list)  # seconds per step of each block, in round order

    @property
    def mean(self) -> float:
        return self.total / self.steps if self.steps else float("nan")


def interleaved(steppers: dict, steps: int, rounds: int = 3, after=None) -> dict:
    """Time ``steppers`` ({name: callable(n) that advances n steps}) in turns: ``rounds`` rounds of
    ``steps`` steps each (an int, or {name: steps} when their costs differ).  ``after(name)`` runs after each
    block, outside the timing (e.g. a measurement).  Returns {name: Timing}."""
    if rounds < 1:
        raise ValueError(f"rounds must be >= 1, got {rounds}")
    counts = steps if isinstance(steps, dict) else {name: steps for name in steppers}
    out = {name: Timing(float("inf"), 0.0, 0) for name in steppers}
    for _ in range(rounds):
        for name, advance in steppers.items():
            n = int(counts[name])
            if n < 1:
                raise ValueError(f"{name}: steps per block must be >= 1, got {n}")
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
