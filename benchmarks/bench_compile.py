"""First compile of the GFO kernel, and loading it from a new checkout path.

Two child processes run `gfo.warm_up()`: the first with an empty cache directory
(`NUMBA_CACHE_DIR` set to a new temporary directory: the kernel's first compile, as on a
fresh clone), the second from a copy of the package in another directory with the same
cache (a new clone path: it must load, not compile). CPU seconds of each child (user +
system, `resource.getrusage(RUSAGE_CHILDREN)`), median of `--repeats` for the load. Run on
one core with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1. The last two lines are machine-read.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import synergrasp

WARM_UP = "from synergrasp.optimisation.gfo import warm_up; warm_up()"


def child_cpu(env: dict[str, str]) -> float:
    """CPU seconds of one child running the warm-up."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", WARM_UP], env=env, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=5, help="loads from the new path; the median is reported")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        first = child_cpu(env)
        clone = Path(tmp) / "clone"
        shutil.copytree(Path(synergrasp.__file__).parent, clone / "synergrasp",
                        ignore=shutil.ignore_patterns("__pycache__"))
        env["PYTHONPATH"] = str(clone)
        loads = [child_cpu(env) for _ in range(args.repeats)]
        cached = sorted(p.name for p in (Path(tmp) / "cache").rglob("*.nbi"))
    print(f"first compile (empty cache, one process): {first:.1f} CPU s; {len(cached)} compiled functions cached")
    print(f"warm-up from a copy in a new path, same cache (median of {args.repeats}): {statistics.median(loads):.2f} CPU s"
          f" (runs {min(loads):.2f}-{max(loads):.2f})")
    print(f"first_compile_s: {first:.1f}  (the compiled kernel's first compile with an empty cache, CPU s of one process)")
    print(f"new_path_load_s: {statistics.median(loads):.2f}  (the warm-up from a new checkout path with the same "
          f"cache, CPU s, median of {args.repeats})")


if __name__ == "__main__":
    main()
