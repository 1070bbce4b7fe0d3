"""Finished runs on disk: ``<out>/runs/<key>.json`` (what the run measured, plain data) and, when it has arrays,
``<key>.npz``; both written atomically, the arrays first, so a JSON file on disk means a complete run.

Every study keys its runs one way, :func:`run_key`, the one function that computes a run's key
(:attr:`.study.Run.key` calls it): the row's label (:attr:`~.rows.Row.label`, however the row was written), the
replica and everything else the run depends on (its settings, the key of its starting states, the version of what
it stores), so a study called again finds exactly the runs it already did, and a changed setting never reuses a
stale run.
"""
from __future__ import annotations

import json
import os

import numpy as np

from ...support.files import content_key, write_json, write_npz
from .rows import Row

__all__ = ["run_key", "RunStore"]


def run_key(row, replica: int | None, settings: dict, length: int = 16, **context) -> str:
    """The key of a run of ``row`` (a Row or a label, hashed as its canonical label) from ``replica``: the SHA-1 of
    ``{"cfg": settings, "row": label, "replica": replica, **context}`` as sorted JSON, cut to ``length`` hex
    digits."""
    label = (row if isinstance(row, Row) else Row.parse(row)).label
    return content_key({"cfg": settings, "row": label, "replica": None if replica is None else int(replica),
                        **context}, length)


class RunStore:
    """``<out>/<folder>/<key>.json`` (+ ``<key>.npz``)."""

    def __init__(self, out: str, folder: str = "runs", create: bool = True):
        self.out = out
        self.folder = os.path.join(out, folder)
        if create:
            os.makedirs(self.folder, exist_ok=True)

    def path(self, key: str, ext: str) -> str:
        """Where the run of ``key`` is stored."""
        return os.path.join(self.folder, f"{key}.{ext}")

    def info(self, key: str) -> dict | None:
        """The stored JSON of a run, or None (missing or unreadable)."""
        try:
            with open(self.path(key, "json")) as fh:
                return json.load(fh)
        except (FileNotFoundError, json.JSONDecodeError):
            return None

    def arrays(self, key: str) -> dict | None:
        try:
            with np.load(self.path(key, "npz")) as data:
                return {k: data[k] for k in data.files}
        except FileNotFoundError:
            return None

    def put(self, key: str, info: dict, arrays: dict | None = None):
        if arrays:
            write_npz(self.path(key, "npz"), arrays)
        write_json(self.path(key, "json"), info)

    def __contains__(self, key: str) -> bool:
        return os.path.exists(self.path(key, "json"))

    def keys(self) -> set:
        if not os.path.isdir(self.folder):
            return set()
        return {f[:-5] for f in os.listdir(self.folder) if f.endswith(".json")}

    def __len__(self):
        return len(self.keys())
