"""The log of one workflow job: everything the job prints to stderr, its warnings and, when
it fails, the traceback of the failure, in the log file its rule declares."""

from __future__ import annotations

import sys
import traceback
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stderr
from pathlib import Path
from typing import TextIO

__all__ = ["job_log"]


@contextmanager
def job_log(path: str | Path) -> Iterator[TextIO]:
    """Write stderr (and so warnings) to ``path`` for the duration of the block; an exception
    raised inside it is written to the log with its traceback before it propagates, so a
    failed job's log says why it failed. The file is created even if nothing is printed."""
    with open(path, "w") as log, redirect_stderr(log):
        try:
            yield log
        except BaseException:
            traceback.print_exc(file=log)
            log.flush()
            raise
        finally:
            sys.stderr.flush()
