"""Benchmark of Snakemake's own cost per job: the small sweep (tests/config/small.yaml with
tests/config/small_sweep.yaml in place of the workflow's configuration, target `sensitivity`)
from an empty working directory, -j2, with the workflow profile. Prints the CPU seconds of
Snakemake's own process (its children, the jobs, excluded), per job; the line
`snakemake_cpu_s_per_job: N` is machine-read.

What it grows with: while jobs wait for a free core, Snakemake's scheduler re-runs itself
once per job-rate-limiter timespan, and every finished job starts one more such timer chain;
each pass re-reads the sizes of every ready job's inputs. With Snakemake's default timespan
(1 s) its own CPU per job grew with the length of a run: ~0.1 s per job on this 68-job sweep,
~2 s on the 706-job sensitivity sweep. The profile's timespan is 1000 s, and the workflow
cancels the timers left at its end (they are not daemon threads); the line
`exit_after_last_job_s: N` says how long Snakemake stayed alive after its last job finished.

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
SETTINGS = {"profile": []}


def _own_cpu_s(pid: int) -> float | None:
    """utime + stime of one process (children excluded), s; None once it has exited."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def run_sweep(extra: list[str]) -> tuple[float, int, float, float]:
    """Snakemake's own CPU s, the number of jobs, the wall s of one small sweep and the wall s
    from its last job's end (the log's "100%" line, sampled every 0.2 s) to its exit."""
    with tempfile.TemporaryDirectory() as work:
        config = yaml.safe_load((ROOT / "tests/config/small.yaml").read_text())
        config.update(yaml.safe_load((ROOT / "tests/config/small_sweep.yaml").read_text()))
        (Path(work) / "sweep.yaml").write_text(yaml.safe_dump(config))
        cmd = [
            sys.executable,
            "-m",
            "snakemake",
            "-s",
            str(ROOT / "Snakefile"),
            "--directory",
            work,
            "--configfile",
            str(Path(work) / "sweep.yaml"),
            "--replace-workflow-config",
            "-j2",
            "sensitivity",
            *extra,
        ]
        start, cpu, log_path = time.perf_counter(), 0.0, Path(work) / "snakemake.log"
        with open(log_path, "w") as log_file, subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=log_file) as proc:
            all_done = None
            while proc.poll() is None:  # sampled until exit: /proc forgets a process once reaped
                cpu = _own_cpu_s(proc.pid) or cpu
                if all_done is None and "(100%) done" in log_path.read_text():
                    all_done = time.perf_counter()
                time.sleep(0.2)
            end = time.perf_counter()
        log = log_path.read_text()
        if proc.returncode:
            raise SystemExit(f"the sweep failed:\n{log[-3000:]}")
        done = re.findall(r"(\d+) of (\d+) steps", log)
        return cpu, int(done[-1][1]) if done else 0, end - start, end - (all_done or end)


def main() -> None:
    for name, extra in SETTINGS.items():
        cpu, jobs, wall, linger = run_sweep(extra)
        print(
            f"{name}: {jobs} jobs, wall {wall:.1f} s, Snakemake's own CPU {cpu:.1f} s, load average {os.getloadavg()[0]:.1f}",
            flush=True,
        )
        suffix = "" if name == "profile" else f"_{name}"
        print(
            f"snakemake_cpu_s_per_job{suffix}: {cpu / max(jobs, 1):.3f}  (Snakemake's own CPU s per job, "
            f"small sweep, -j2, limiter: {' '.join(extra) or 'the profile'})",
            flush=True,
        )
        print(
            f"exit_after_last_job_s{suffix}: {linger:.1f}  (wall s from the last job's end to Snakemake's exit, "
            f"sampled every 0.2 s)",
            flush=True,
        )


if __name__ == "__main__":
    main()
