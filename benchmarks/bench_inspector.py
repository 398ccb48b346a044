"""What one grasp in full costs: `synergrasp grasp obj4 --alpha -30 --beta 0` (every default
set: 15 single synergies and {S1..Sk} for k = 2..15), warm (the solver kernel compiled and
cached, one run before the measured ones), alone and with `--png` and `--html`.

    .venv/bin/python benchmarks/bench_inspector.py [--results results] [--runs 3]

Each variant runs the command in a fresh process `--runs` times; printed: the median wall
time and the median CPU time (user + system of the process), seconds, and the machine's load
average when it started. Needs the searched target of obj4 (`--results`, the default study's
`results/objects/obj4/placement.csv`). Writes `<results>/benchmarks/bench_inspector.tsv`,
which `tools/measurements.py` puts on docs/measurements.md.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMAND = ["grasp", "obj4", "--alpha", "-30", "--beta", "0"]


def run_once(args: list[str], results: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one run of the command in its own process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "synergrasp.cli", *COMMAND, "--results", str(results), *args],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", type=Path, default=Path("results"))
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    if not (args.results / "objects" / "obj4" / "placement.csv").is_file():
        raise SystemExit(f"no searched target of obj4 under {args.results}: run `make study` first")
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        variants = {"text": [], "png": ["--png", f"{tmp}/g.png"], "html": ["--html", f"{tmp}/g.html"],
                    "png_html": ["--png", f"{tmp}/g.png", "--html", f"{tmp}/g.html"]}
        run_once([], args.results)  # warm: the kernel's cache and the files in the page cache
        rows = []
        for name, extra in variants.items():
            times = [run_once(extra, args.results) for _ in range(args.runs)]
            rows.append((name, statistics.median(t[0] for t in times), statistics.median(t[1] for t in times)))
    print(f"load average at the start: {load:.2f}; median of {args.runs} runs")
    lines = ["variant\twall_s\tcpu_s\tload"]
    for name, wall, cpu in rows:
        print(f"inspector_{name}: wall {wall:.2f} s, CPU {cpu:.2f} s")
        lines.append(f"{name}\t{wall:.3f}\t{cpu:.3f}\t{load:.2f}")
    out = args.results / "benchmarks" / "bench_inspector.tsv"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
