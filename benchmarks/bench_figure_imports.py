"""What each figure job pays in imports against the rest of its work, from the last study.

For every figure rule, the CPU time of its script's imports (the `import` and `from` lines of
`workflow/scripts/<rule>.py`, run in a fresh interpreter, the interpreter's own start-up
subtracted; median of 3) and the job's CPU time from its Snakemake benchmark files under
`--root` (median over the rule's jobs; start-up, imports, reading and drawing). The rest, job
minus imports, is what the job does besides importing. Nothing of the study is rerun: run
`make study` first. The last line is machine-read: the largest share of a job's CPU spent in
imports, and its rule.

    .venv/bin/python benchmarks/bench_figure_imports.py [--root results]
"""

from __future__ import annotations

import argparse
import re
import resource
import statistics
import subprocess
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
#: The rules that draw figures (their benchmark files: <root>/benchmarks/<rule>[/<object>].tsv).
FIGURE_RULES = ("fig1", "fig2", "fig3", "fig4", "fig5", "placement_map", "realism", "quality")
_IMPORT = re.compile(r"^(?:import|from)\s.*?(?=^\S|\Z)", re.MULTILINE | re.DOTALL)


def _child_cpu_s(code: str) -> float:
    """CPU s of one fresh interpreter running ``code``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def import_cpu_s(script: Path) -> float:
    """Median CPU s (of 3) of the script's top-level imports, the bare interpreter's subtracted."""
    code = "".join(_IMPORT.findall(script.read_text()))
    start = statistics.median(_child_cpu_s("pass") for _ in range(3))
    return max(statistics.median(_child_cpu_s(code) for _ in range(3)) - start, 0.0)


def job_cpu_s(results: Path, rule: str) -> float | None:
    """Median CPU s of the rule's jobs in the study's benchmark files; None if it has none."""
    files = [*results.glob(f"benchmarks/{rule}.tsv"), *results.glob(f"benchmarks/{rule}/*.tsv")]
    if not files:
        return None
    return statistics.median(float(pd.read_csv(f, sep="\t")["cpu_time"].iloc[-1]) for f in files)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=ROOT / "results", help="results of a finished study")
    args = ap.parse_args()
    worst, worst_rule = 0.0, ""
    for rule in FIGURE_RULES:
        job = job_cpu_s(args.root, rule)
        if job is None:
            print(f"{rule}: no benchmark file under {args.root}: run `make study` first")
            continue
        imports = import_cpu_s(ROOT / "workflow" / "scripts" / f"{rule}.py")
        share = imports / job if job > 0 else 0.0
        print(
            f"{rule}: job {job:.2f} CPU s, imports {imports:.2f} s ({100 * share:.0f} %), the rest {job - imports:.2f} s",
            flush=True,
        )
        if share > worst:
            worst, worst_rule = share, rule
    print(f"figure_imports_share_max: {worst:.2f}  (largest share of a figure job's CPU spent importing: {worst_rule})")


if __name__ == "__main__":
    main()
