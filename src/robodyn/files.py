"""Writing output files atomically: a file is either written whole or not at all.

Every writer of robodyn (trajectory and log CSVs, URDF, C code, LaTeX, plots, GIFs, reports)
writes into a temporary file next to the target and renames it into place when the writing
succeeded (``os.replace``, atomic on POSIX and Windows). A failure halfway (a full disk, an
exception while plotting, Ctrl-C) leaves the previous file, if any, untouched and no partial
file behind.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path):
    """Yield a temporary path next to ``path`` (same directory, same suffix, so that writers
    that pick a format from the suffix still do); on success it replaces ``path``, on failure
    it is removed."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text(path, text: str) -> None:
    """``Path(path).write_text(text)``, atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
