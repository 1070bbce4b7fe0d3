"""Typed records of the bench, and the version of their JSON schema.

:class:`RunRecord` is what one run (or stability probe) produces: the :class:`~.runs.RunSpec` that named
it (its row as the bench's name and its step), then what was measured (units nm, ps, Da, kJ/mol; see :mod:`.runs` for the meaning of each figure).
:class:`StabilityRecord` is what a stability search concludes.  Both are written to disk as JSON objects
carrying ``"schema": SCHEMA_VERSION``; reading a record of another schema raises :class:`SchemaError`
(rerun that sweep, or use the package version that wrote it), so stale results are never mixed in.
Unknown fields are refused both ways: a typo is an error, not a silent new key.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

from ...support.errors import InputError

#: Version of the JSON schema of run records, stability records and results.json.
SCHEMA_VERSION = 3

__all__ = ["SCHEMA_VERSION", "SchemaError", "RunRecord", "StabilityRecord"]


class SchemaError(InputError):
    """A stored record of another schema version (or not a record of this bench at all)."""


class _Record:
    def update(self, **values):
        """Set several fields at once (unknown names are an error)."""
        names = {f.name for f in fields(self)}
        unknown = sorted(set(values) - names)
        if unknown:
            raise AttributeError(f"{type(self).__name__} has no field(s) {', '.join(unknown)}")
        for k, v in values.items():
            setattr(self, k, v)
        return self

    def to_json(self) -> dict:
        return dict(asdict(self), schema=SCHEMA_VERSION)

    @classmethod
    def from_json(cls, data: dict):
        data = dict(data)
        version = data.pop("schema", None)
        if version != SCHEMA_VERSION:
            raise SchemaError(f"a {cls.__name__} of schema {version!r} (this bench reads schema {SCHEMA_VERSION}): "
                              f"rerun the sweep into a new --out folder")
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise SchemaError(f"{cls.__name__} with unknown field(s) {', '.join(unknown)}")
        return cls(**data)


@dataclass
class RunRecord(_Record):
    # -- the spec (RunSpec's fields; ``platform`` is the platform actually used) --------------------------------
    scene: str
    method: str
    step_fs: float
    n_steps: int
    n_samples: int = 50
    role: str = "run"
    platform: str | None = None
    timing_s: float = 0.0
    threads: int = 1
    seed: int = 1
    # -- the scene ---------------------------------------------------------------------------------------------
    label: str = ""
    length_ps: float = 0.0
    n_atoms: int = 0
    n_dof: int = 0
    # -- outcome -----------------------------------------------------------------------------------------------
    status: str = "ok"  # "ok", "failed", "unsupported", "error"
    failed: bool = False
    failure: str | None = None
    fail_time_ps: float | None = None
    blew_up: bool = False
    steps_done: int = 0
    traceback: str | None = None
    # -- cost --------------------------------------------------------------------------------------------------
    force_evals_per_step: int | None = None
    force_evals_per_ps: float | None = None
    setup_s: float | None = None
    wall_per_step: float | None = None
    wall_per_ps: float | None = None
    timing_steps: int = 0
    verlet_wall_per_step: float | None = None
    wall_vs_verlet_paired: float | None = None
    retimed: bool = False  # the timing was measured again (``symprk bench --retime``), apart from the run
    # -- accuracy ----------------------------------------------------------------------------------------------
    E0: float | None = None
    energy_error: float | None = None
    energy_error_per_dof: float | None = None
    drift_per_ns_per_dof: float | None = None
    dP: float | None = None
    dL_rel: float | None = None
    constraint_error: float | None = None
    traj_error: float | None = None
    energy_std_per_dof: float | None = None  # production scenes: std of E per DOF (kJ/mol)
    drift_kT_per_ns_per_dof: float | None = None  # production scenes: energy drift, kT per ns per DOF ...
    drift_kT_stderr: float | None = None  # ... and its standard error (correlated samples)
    trace_t: list = field(default_factory=list)
    trace_de_per_dof: list = field(default_factory=list)
    # -- linear stability probes ---------------------------------------------------------------------------------
    n_oscillators: int | None = None
    spectral_radius: float | None = None
    x_first_unstable: float | None = None
    # -- storage ---------------------------------------------------------------------------------------------------
    key: str | None = None
    has_arrays: bool = False


@dataclass
class StabilityRecord(_Record):
    scene: str
    method: str
    label: str
    status: str  # "ok", "unsupported", "error"
    h_stable_fs: float | None
    h_fail_fs: float | None
    failure: str | None
    force_evals_per_step: int | None
    stable_fs_per_eval: float | None
    probes: list
    criterion: str
    rel_tol: float
    x_stable: float | None = None
    catalogue: float | None = None
