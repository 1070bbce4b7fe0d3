"""Study output folders: atomic JSON, text and array files, and an exclusive lock for the life of a run."""
from __future__ import annotations

import json
import os

import numpy as np

__all__ = ["FolderLock", "FolderLockedError", "write_text", "write_json", "write_npz", "jsonable"]


class FolderLockedError(RuntimeError):
    """Another process holds the folder's lock."""


class FolderLock:
    """An exclusive lock on ``<out>/.lock`` (released by :meth:`release` or when the process ends).
    ``command`` names the holder in the error another process gets."""

    def __init__(self, out: str, command: str = "symprk", error: type = FolderLockedError):
        import fcntl

        self.fh = open(os.path.join(out, ".lock"), "w")
        try:
            fcntl.flock(self.fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.fh.close()
            raise error(f"another {command} is running on {out}: wait for it, or use another --out") from None

    def release(self):
        import fcntl

        fcntl.flock(self.fh, fcntl.LOCK_UN)
        self.fh.close()


def jsonable(obj):
    """``obj`` with numpy arrays and scalars as lists and numbers, NaN as None, dataclasses as dicts."""
    import dataclasses

    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return jsonable(dataclasses.asdict(obj))
    if isinstance(obj, dict):
        return {str(k) if not isinstance(k, str) else k: jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return jsonable(obj.item())
    if isinstance(obj, float) and obj != obj:
        return None
    return obj


def write_text(path: str, text: str):
    """Write ``text`` to a temporary name, then rename (a reader sees the old file or the new one, never a part)."""
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def write_json(path: str, data):
    """Write ``data`` (made :func:`jsonable`) as JSON, atomically: the one JSON writer of the studies."""
    write_text(path, json.dumps(jsonable(data), indent=1, allow_nan=True))


def write_npz(path: str, arrays: dict):
    """Write ``arrays`` to ``path`` (an .npz file), atomically."""
    tmp = f"{path[:-4] if path.endswith('.npz') else path}.tmp{os.getpid()}.npz"
    np.savez(tmp, **arrays)
    os.replace(tmp, path)
