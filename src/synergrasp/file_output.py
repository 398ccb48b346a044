"""Writing an output file or folder so that it is never half-written: the new content goes to
a temporary name beside it and replaces the old one by a rename only once complete. A
failure (an unreadable input, a full disk, a kill) leaves the previous content, or nothing,
never a torn file that a later run would read. With the workflow's outputs kept during a
job (``synergrasp.snakemake_adapter.keep_outputs_until_replaced``) a failed rerun keeps the finished
result. This module imports nothing of the project (lowest layer).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["replacing", "replacing_folder"]


def _beside(path: Path, tag: str) -> Path:
    # the same folder (one file system, so the rename is atomic) and the same suffix (writers
    # such as matplotlib choose the format by it); hidden, named by the process
    return path.with_name(f".{path.stem}.{tag}{os.getpid()}{path.suffix}")


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """A temporary path to write ``path``'s new content to; it replaces ``path`` when the
    block ends without error and is removed otherwise (``path`` then keeps its content)."""
    path = Path(path)
    partial = _beside(path, "partial")
    try:
        yield partial
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)


@contextmanager
def replacing_folder(path: str | Path) -> Iterator[Path]:
    """A new empty folder to write ``path``'s new content to; it replaces the folder ``path``
    (every file of the old one gone) when the block ends without error, and is removed
    otherwise."""
    path = Path(path)
    partial, old = _beside(path, "partial"), _beside(path, "old")
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    try:
        yield partial
        if path.exists():
            os.replace(path, old)
        os.replace(partial, path)
    finally:
        shutil.rmtree(partial, ignore_errors=True)
        shutil.rmtree(old, ignore_errors=True)
