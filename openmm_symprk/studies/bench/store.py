"""The bench's finished runs: :class:`~..core.store.RunStore` holding typed :class:`~.records.RunRecord` s.

A run's key is a hash of its :class:`~.runs.RunSpec` and the fingerprint of its scene's initial state,
so a resumed sweep finds exactly the runs it already did and a changed scene never reuses stale ones.
"""
from __future__ import annotations

from ..core.store import RunStore
from ..core.store import run_key as hash_key
from .records import RunRecord

__all__ = ["run_key", "Store"]


def run_key(spec_dict: dict, fingerprint: str) -> str:
    return hash_key({"spec": spec_dict, "scene": fingerprint}, length=20)


class Store(RunStore):
    """``<out>/runs/<key>.json`` (+ ``<key>.npz``) as :class:`RunRecord` s."""

    def get(self, key: str) -> RunRecord | None:
        """The stored record, or None; SchemaError for a record of another schema version."""
        data = self.info(key)
        return None if data is None else RunRecord.from_json(data)

    def put(self, key: str, record: RunRecord, arrays: dict | None = None):
        record.update(key=key, has_arrays=bool(arrays))
        super().put(key, record.to_json(), arrays)
