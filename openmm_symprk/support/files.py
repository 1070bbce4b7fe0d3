"""Files written atomically (a reader sees the old file or the new one, never a part), the package's one writer
of JSON, text and array files, and the key of a JSON-ready object."""
from __future__ import annotations

import hashlib
import json
import os

import numpy as np

__all__ = ["write_text", "write_json", "write_npz", "jsonable", "content_key"]


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
    """Write ``text`` to a temporary name, then rename."""
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.replace(tmp, path)


def write_json(path: str, data):
    """Write ``data`` (made :func:`jsonable`) as JSON, atomically."""
    write_text(path, json.dumps(jsonable(data), indent=1, allow_nan=True))


def write_npz(path: str, arrays: dict):
    """Write ``arrays`` to ``path`` (an .npz file), atomically."""
    tmp = f"{path[:-4] if path.endswith('.npz') else path}.tmp{os.getpid()}.npz"
    np.savez(tmp, **arrays)
    os.replace(tmp, path)


def content_key(obj, length: int = 16) -> str:
    """The SHA-1 of ``obj`` as sorted JSON, cut to ``length`` hex digits: the key of what ``obj`` describes."""
    return hashlib.sha1(json.dumps(obj, sort_keys=True).encode()).hexdigest()[:length]
