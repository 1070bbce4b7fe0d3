"""The bench's finished runs: :class:`~..core.store.RunStore` holding typed :class:`~.records.RunRecord` s, under
the keys of their runs (:func:`.sweep.run_of`)."""
from __future__ import annotations

from ..core.store import RunStore
from .records import RunRecord

__all__ = ["Store"]


class Store(RunStore):
    """``<out>/runs/<key>.json`` (+ ``<key>.npz``) as :class:`RunRecord` s."""

    def get(self, key: str) -> RunRecord | None:
        """The stored record, or None; SchemaError for a record of another schema version."""
        data = self.info(key)
        return None if data is None else RunRecord.from_json(data)

    def put(self, key: str, record: RunRecord, arrays: dict | None = None):
        record.update(key=key, has_arrays=bool(arrays))
        super().put(key, record.to_json(), arrays)
