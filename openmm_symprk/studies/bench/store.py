"""The bench's finished runs: :class:`~..core.store.RunStore` holding typed :class:`~.records.RunRecord` s.

A run's key (:func:`~..core.store.run_key`) hashes its row's label, the rest of its :class:`~.runs.RunSpec` and
the fingerprint of its scene's initial state, so a resumed sweep finds exactly the runs it already did and a changed
scene never reuses stale ones; a run stored under the key of the bench's earlier form (:func:`legacy_key`) is
found too.
"""
from __future__ import annotations

from ...support.files import content_key
from ..core.store import RunStore
from ..core.store import run_key as row_run_key
from .records import RunRecord

__all__ = ["run_key", "legacy_key", "Store"]


def run_key(spec, fingerprint: str) -> str:
    settings = {k: v for k, v in spec.to_dict().items() if k != "row"}
    return row_run_key(spec.row, None, settings, length=20, scene=fingerprint)


def legacy_key(spec, fingerprint: str) -> str:
    """The key before runs were keyed by their rows' labels: the spec with the bench's name of the row and its step."""
    return content_key({"spec": spec.record_fields(), "scene": fingerprint}, length=20)


class Store(RunStore):
    """``<out>/runs/<key>.json`` (+ ``<key>.npz``) as :class:`RunRecord` s."""

    def get(self, key: str) -> RunRecord | None:
        """The stored record, or None; SchemaError for a record of another schema version."""
        data = self.info(key)
        return None if data is None else RunRecord.from_json(data)

    def put(self, key: str, record: RunRecord, arrays: dict | None = None):
        record.update(key=key, has_arrays=bool(arrays))
        super().put(key, record.to_json(), arrays)
