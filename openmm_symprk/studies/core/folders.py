"""Study output folders: an exclusive lock for the life of a run (the files in them are written atomically by
:mod:`openmm_symprk.support.files`)."""
from __future__ import annotations

import os

from ...support.errors import SymprkError
from ...support.files import jsonable, write_json, write_npz, write_text

__all__ = ["FolderLock", "FolderLockedError", "write_text", "write_json", "write_npz", "jsonable"]


class FolderLockedError(SymprkError, BlockingIOError):
    """Another process holds the folder's lock (an OSError: the command says so in one line)."""


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
