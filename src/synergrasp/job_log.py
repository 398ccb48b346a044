"""The log of one workflow job: everything the job prints to stderr, its warnings and, when
it fails, the traceback of the failure, in the log file its rule declares; its last line is
the job's CPU time."""

from __future__ import annotations

import resource
import sys
import traceback
from collections.abc import Iterator
from contextlib import contextmanager, redirect_stderr
from pathlib import Path
from typing import TextIO

__all__ = ["job_log", "job_cpu_s", "CPU_LINE"]

#: The start of a job log's last line, followed by the job's CPU seconds: user and system time
#: of its process and of every process it waited for (a pool's workers), from its start.
#: Snakemake's benchmark file samples a job's processes (every 0.5 s for 15 s, then every
#: 30 s) and so misses what a job spends after its last sample; this line misses nothing.
CPU_LINE = "job CPU s: "


def _cpu_s() -> float:
    own, waited = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + waited.ru_utime + waited.ru_stime


@contextmanager
def job_log(path: str | Path) -> Iterator[TextIO]:
    """Write stderr (and so warnings) to ``path`` for the duration of the block; an exception
    raised inside it is written to the log with its traceback before it propagates, so a
    failed job's log says why it failed. The file is created even if nothing is printed; its
    last line is the job's CPU seconds so far (:data:`CPU_LINE`)."""
    with open(path, "w") as log, redirect_stderr(log):
        try:
            yield log
        except BaseException:
            traceback.print_exc(file=log)
            raise
        finally:
            sys.stderr.flush()
            print(f"{CPU_LINE}{_cpu_s():.3f}", file=log, flush=True)


def job_cpu_s(path: str | Path) -> float | None:
    """The CPU seconds a job's log records (:data:`CPU_LINE`), None where it records none (a
    log written before the line existed, or a job killed before its end)."""
    lines = Path(path).read_text().splitlines()
    if lines and lines[-1].startswith(CPU_LINE):
        return float(lines[-1][len(CPU_LINE) :])
    return None
