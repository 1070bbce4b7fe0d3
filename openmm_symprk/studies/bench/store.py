"""Finished runs on disk: one JSON file per run (plus an .npz for arrays), written atomically.

A run's key is a hash of its :class:`~.runs.RunSpec` and the fingerprint of its scene's initial state,
so a resumed sweep finds exactly the runs it already did and a changed scene never reuses stale ones.
Files are written to a temporary name and renamed, so an interrupted sweep leaves either a complete
record or none.
"""
from __future__ import annotations

import hashlib
import json
import os

import numpy as np

from ..folders import write_json
from .records import RunRecord


def run_key(spec_dict: dict, fingerprint: str) -> str:
    text = json.dumps({"spec": spec_dict, "scene": fingerprint}, sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:20]


class Store:
    """``<out>/runs/<key>.json`` (+ ``<key>.npz``)."""

    def __init__(self, out: str):
        self.out = out
        self.folder = os.path.join(out, "runs")
        os.makedirs(self.folder, exist_ok=True)

    def _path(self, key, ext):
        return os.path.join(self.folder, f"{key}.{ext}")

    def get(self, key: str) -> RunRecord | None:
        """The stored record, or None; SchemaError for a record of another schema version."""
        try:
            with open(self._path(key, "json")) as fh:
                data = json.load(fh)
        except (FileNotFoundError, json.JSONDecodeError):
            return None
        return RunRecord.from_json(data)

    def put(self, key: str, record: RunRecord, arrays: dict | None = None):
        if arrays:
            tmp = self._path(key, f"tmp{os.getpid()}.npz")
            np.savez(tmp, **arrays)
            os.replace(tmp, self._path(key, "npz"))
        record.update(key=key, has_arrays=bool(arrays))
        write_json(self._path(key, "json"), record.to_json())

    def arrays(self, key: str) -> dict | None:
        try:
            with np.load(self._path(key, "npz")) as data:
                return {k: data[k] for k in data.files}
        except FileNotFoundError:
            return None

    def keys(self) -> set:
        return {f[:-5] for f in os.listdir(self.folder) if f.endswith(".json")}

    def __len__(self):
        return len(self.keys())
