"""Write docs/measurements.md: what a run of the study cost, from its Snakemake benchmark
files (`<root>/benchmarks/**/*.tsv`) and its per-object tables (how many poses and
(pose, set) problems each job did).

    .venv/bin/python tools/measurements.py [results] [docs/measurements.md] ["how loaded the machine was"]

Every cost the documentation quotes is on that page, in one place; rerun this after a run
on a quiet machine to update it. The per-unit figures are CPU time over the work of every
job of a rule: the closure per pose, the optimisation per (pose, set).
"""

from __future__ import annotations

import platform
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from job_times import job_times  # noqa: E402

#: What one unit of a rule's work is, and the per-object table that counts it.
UNITS = {
    "simulate_contacts": ("pose", "contacts.parquet"),
    "optimise": ("(pose, set)", "gfo.parquet"),
    "aggregate_gfo": ("(pose, set)", "gfo.parquet"),
    "local_minima": ("(pose, set)", "gfo.parquet"),
    "fig4": ("(pose, set)", "gfo.parquet"),
}


def units_done(results: Path, table: str) -> int:
    """Rows of every object's ``table`` under ``results`` (the default study's only)."""
    return sum(len(pd.read_parquet(p, columns=["pose"])) for p in sorted((results / "objects").glob(f"*/{table}")))


def page(results: Path, note: str = "") -> str:
    """The measurements page of the run under ``results``; ``note``: how loaded the machine was."""
    times = job_times(results)
    lines = [
        "# Measurements",
        "",
        f"Written by `.venv/bin/python tools/measurements.py {results}` from the benchmark files of one",
        "run of the default study (Snakemake's `benchmark:` files, `results/benchmarks/`); do not",
        "edit by hand. Machine: "
        f"{platform.machine()}, {platform.python_implementation()} {platform.python_version()}.",
        "CPU seconds are the jobs' own; wall seconds depend on how loaded the machine was"
        + (f" ({note})." if note else "."),
        "",
        "| rule | jobs | wall s | CPU s | CPU % | peak MB | CPU per unit |",
        "|---|---|---|---|---|---|---|",
    ]
    for rule, row in times.iterrows():
        per = ""
        if rule in UNITS:
            unit, table = UNITS[rule]
            n = units_done(results, table)
            if n:
                per = f"{1e3 * row['cpu_s'] / n:.3g} ms per {unit} ({n:,} {unit}s)"
        lines.append(f"| `{rule}` | {int(row['jobs'])} | {row['wall_s']:.1f} | {row['cpu_s']:.1f} | "
                     f"{row['cpu_percent']:.0f} | {row['peak_mb']:.0f} | {per} |")
    lines += ["", f"Total: {int(times['jobs'].sum())} jobs, {times['wall_s'].sum():.0f} job-seconds, "
              f"{times['cpu_s'].sum():.0f} CPU seconds.", ""]
    return "\n".join(lines + inspector_lines(results))


#: The inspector's variants as benchmarks/bench_inspector.py names them, in words.
INSPECTOR_VARIANTS = {"text": "the text (every default set)", "png": "and `--png`", "html": "and `--html`",
                      "png_html": "and `--png` and `--html`"}


def inspector_lines(results: Path) -> list[str]:
    """The one-grasp command's cost (benchmarks/bench_inspector.py's file), if it was measured."""
    path = results / "benchmarks" / "bench_inspector.tsv"
    if not path.is_file():
        return []
    bench = pd.read_csv(path, sep="\t")
    lines = ["## One grasp in full", "",
             "`synergrasp grasp obj4 --alpha -30 --beta 0` (29 sets), warm, each in a fresh process, median of its",
             f"runs (`.venv/bin/python benchmarks/bench_inspector.py`; load average {bench['load'].iloc[0]:.2f} when it "
             "started):", "", "| command | wall s | CPU s |", "|---|---|---|"]
    for row in bench.itertuples():
        lines.append(f"| {INSPECTOR_VARIANTS.get(row.variant, row.variant)} | {row.wall_s:.2f} | {row.cpu_s:.2f} |")
    return lines + [""]


if __name__ == "__main__":
    results = Path(sys.argv[1] if len(sys.argv) > 1 else "results")
    out = Path(sys.argv[2] if len(sys.argv) > 2 else Path(__file__).resolve().parents[1] / "docs" / "measurements.md")
    out.write_text(page(results, sys.argv[3] if len(sys.argv) > 3 else ""))
    print(f"wrote {out}")
