"""A fresh clone's set-up side by side: `make venv` and the first compile (`make warm-up` where
the Makefile has it; before it, the Makefile's two warm-ups side by side, after the package's
bytecode where its Makefile compiles it) of
two commits, one after the other, each in a new clone with empty caches (XDG_CACHE_HOME and
NUMBA_CACHE_DIR new temporary folders, PIP_NO_CACHE_DIR=1), each from the same state: the files
the one before wrote on disk (sync: no set-up pays for the other's writes) and, where the bench
may (root), the page cache emptied as on a freshly started machine (no set-up pays for reclaiming
the other's pages; the line `page_cache_dropped` says whether it was). Where `make venv` compiles while
it installs, its time includes the first compile, and `make warm-up`'s is the cache check that
`make study` and `make test` run after it.

    .venv/bin/python benchmarks/bench_fresh_venv.py [BASE [NEW [PAIRS]]]

BASE (default cec0629, pip) and NEW (default HEAD, uv) are commits of this repository; PAIRS
(default 1) runs BASE then NEW that many times. Prints, per commit and pair, the wall and CPU
seconds (the command's children) of each part as machine-read lines (tools/measurements.py).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The warm-ups of a Makefile without `make warm-up` (cec0629 and the commits up to 5f77418).
WARM_UP = (
    "from synergrasp.simulation.closure import warm_up; warm_up()",
    "from synergrasp.optimisation.gfo import warm_up; warm_up()",
)


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timed(run) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), _cpu()
    run()
    return time.perf_counter() - wall, _cpu() - cpu


def _settle() -> bool:
    """The files written so far on disk, and the page cache emptied where allowed: whether it was."""
    os.sync()
    try:
        Path("/proc/sys/vm/drop_caches").write_text("3\n")
    except OSError:
        return False
    return True


def set_up(commit: str) -> tuple[bool, float, float, float, float]:
    """(page cache dropped, venv wall s, venv CPU s, compile wall s, compile CPU s) of a new
    clone at ``commit``."""
    with tempfile.TemporaryDirectory(prefix="synergrasp-fresh-") as work:
        clone = Path(work) / "repo"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        subprocess.run(["git", "-C", str(clone), "checkout", "-q", commit], check=True)
        dropped = _settle()
        env = {**os.environ, "XDG_CACHE_HOME": f"{work}/cache", "NUMBA_CACHE_DIR": f"{work}/cache/numba", "PIP_NO_CACHE_DIR": "1"}
        venv = _timed(lambda: subprocess.run(["make", "venv"], cwd=clone, env=env, check=True, stdout=subprocess.DEVNULL))
        python = str(clone / ".venv" / "bin" / "python")

        def compile_() -> None:
            makefile = (clone / "Makefile").read_text()
            if "\nwarm-up:" in makefile:  # the Makefile's own set-up step
                subprocess.run(["make", "warm-up"], cwd=clone, env=env, check=True, stdout=subprocess.DEVNULL)
                return
            if "compileall" in makefile:  # the package's bytecode first, as its Makefile does
                subprocess.run([python, "-m", "compileall", "-q", "src/synergrasp"], cwd=clone, env=env, check=True)
            runs = [subprocess.Popen([python, "-c", code], cwd=clone, env=env) for code in WARM_UP]
            if any(run.wait() for run in runs):
                raise SystemExit(f"the warm-up failed at {commit}")

        return (dropped, *venv, *_timed(compile_))


def main(argv: list[str]) -> None:
    base, new = (argv + ["cec0629", "HEAD"][len(argv) :])[:2]
    pairs = int(argv[2]) if len(argv) > 2 else 1
    for pair in range(1, pairs + 1):
        for label, commit in (("base", base), ("new", new)):
            dropped, venv_wall, venv_cpu, compile_wall, compile_cpu = set_up(commit)
            print(f"{label}_page_cache_dropped_{pair}: {int(dropped)}  (1: the page cache emptied before the set-up)")
            print(f"{label}_venv_wall_s_{pair}: {venv_wall:.1f}  (make venv at {commit}, wall s)")
            print(f"{label}_venv_cpu_s_{pair}: {venv_cpu:.1f}  (make venv at {commit}, CPU s of its processes)")
            print(f"{label}_compile_wall_s_{pair}: {compile_wall:.1f}  (the first compile at {commit}, wall s)")
            print(f"{label}_compile_cpu_s_{pair}: {compile_cpu:.1f}  (the first compile at {commit}, CPU s)")
            sys.stdout.flush()


if __name__ == "__main__":
    main(sys.argv[1:])
