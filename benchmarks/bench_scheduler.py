"""Benchmark of Snakemake's own cost per job: the small sweep (tests/config/small.yaml with
tests/config/small_sweep.yaml in place of the workflow's configuration, target `sensitivity`) from an empty working directory, -j2,
once with Snakemake's default job-rate limiter (100 jobs per 1 s) and once with the
workflow profile's (profiles/default/config.yaml). Prints the CPU seconds of Snakemake's
own process (its children, the jobs, excluded), per job; the lines
`snakemake_cpu_s_per_job[_<setting>]: N` are machine-read.

Why the limiter matters: while jobs wait for a free core, Snakemake's scheduler re-runs
itself once per limiter timespan, and every finished job starts one more such timer chain;
each pass re-reads the sizes of every ready job's inputs (each job lists the package's
source files among them), so the scheduler's own CPU grows with the number of jobs done.

    .venv/bin/python benchmarks/bench_scheduler.py
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
SETTINGS = {"snakemake_default": ["--max-jobs-per-timespan", "100/1s"], "profile": []}


def _own_cpu_s(pid: int) -> float | None:
    """utime + stime of one process (children excluded), s; None once it has exited."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def run_sweep(extra: list[str]) -> tuple[float, int, float]:
    """Snakemake's own CPU s, the number of jobs and the wall s of one small sweep."""
    with tempfile.TemporaryDirectory() as work:
        config = yaml.safe_load((ROOT / "tests/config/small.yaml").read_text())
        config.update(yaml.safe_load((ROOT / "tests/config/small_sweep.yaml").read_text()))
        (Path(work) / "sweep.yaml").write_text(yaml.safe_dump(config))
        cmd = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "--directory", work,
               "--configfile", str(Path(work) / "sweep.yaml"), "--replace-workflow-config", "-j2", "sensitivity",
               *extra]
        start, cpu = time.perf_counter(), 0.0
        with subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True) as proc:
            while proc.poll() is None:
                cpu = _own_cpu_s(proc.pid) or cpu
                time.sleep(0.2)
            log = proc.stderr.read() if proc.stderr else ""
        if proc.returncode:
            raise SystemExit(f"the sweep failed:\n{log[-3000:]}")
        done = re.findall(r"(\d+) of (\d+) steps", log)
        return cpu, int(done[-1][1]) if done else 0, time.perf_counter() - start


def main() -> None:
    for name, extra in SETTINGS.items():
        cpu, jobs, wall = run_sweep(extra)
        print(f"{name}: {jobs} jobs, wall {wall:.1f} s, Snakemake's own CPU {cpu:.1f} s, "
              f"load average {os.getloadavg()[0]:.1f}", flush=True)
        suffix = "" if name == "profile" else f"_{name}"
        print(f"snakemake_cpu_s_per_job{suffix}: {cpu / max(jobs, 1):.3f}  (Snakemake's own CPU s per job, "
              f"small sweep, -j2, limiter: {' '.join(extra) or 'the profile'})", flush=True)


if __name__ == "__main__":
    main()
