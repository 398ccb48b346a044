"""Where a run's time went: jobs, wall seconds and CPU seconds per rule, summed over every
Snakemake benchmark file under a results folder (the default study's and every scenario's).

    .venv/bin/python tools/job_times.py [results]

A rule's benchmark files are `<root>/benchmarks/<rule>/<...>.tsv` or
`<root>/benchmarks/<rule>.tsv` (workflow/rules/*.smk); `s` is the job's wall time, in seconds.
A job's CPU seconds are the last line of its log, `<root>/logs/<rule>/<...>.log`
(`synergrasp.job_log.CPU_LINE`), where it has one; else the benchmark's `cpu_time`, which
misses what the job spent after the benchmark's last sample (every 0.5 s for 15 s, then
every 30 s). Prints one row per rule, largest CPU share first; `logged` counts the jobs whose
CPU seconds come from their log.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from synergrasp.job_log import job_cpu_s


def job_times(results: Path) -> pd.DataFrame:
    """One row per rule: jobs, wall s, CPU s, the CPU share (percent), the largest peak
    resident memory of any of its jobs (MB) and how many jobs' CPU s come from their logs."""
    rows = []
    for path in sorted(results.rglob("benchmarks/**/*.tsv")):
        parts = path.relative_to(results).parts
        at = parts.index("benchmarks")
        rule = parts[at + 1] if len(parts) > at + 2 else path.stem
        bench = pd.read_csv(path, sep="\t")
        log = results.joinpath(*parts[:at], "logs", *parts[at + 1 :]).with_suffix(".log")
        logged = job_cpu_s(log) if log.exists() else None
        rows.append(
            {
                "rule": rule,
                "wall_s": float(bench["s"].iloc[-1]),
                "cpu_s": float(bench["cpu_time"].iloc[-1]) if logged is None else logged,
                "mb": float(bench["max_rss"].iloc[-1]),
                "logged": logged is not None,
            }
        )
    table = pd.DataFrame(rows, columns=["rule", "wall_s", "cpu_s", "mb", "logged"])
    out = table.groupby("rule").agg(
        jobs=("wall_s", "size"),
        wall_s=("wall_s", "sum"),
        cpu_s=("cpu_s", "sum"),
        peak_mb=("mb", "max"),
        logged=("logged", "sum"),
    )
    out["cpu_percent"] = 100.0 * out["cpu_s"] / out["cpu_s"].sum()
    return out.sort_values("cpu_s", ascending=False)


if __name__ == "__main__":
    table = job_times(Path(sys.argv[1] if len(sys.argv) > 1 else "results"))
    print(table.round(1).to_string())
    print(
        f"total: {int(table['jobs'].sum())} jobs, {table['wall_s'].sum():.0f} job-seconds, {table['cpu_s'].sum():.0f} CPU seconds"
    )
