"""What one grasp in full costs: `synergrasp grasp obj4 --alpha -30 --beta 0` (every default
set: the 15 single synergies and {S1..Sk} for k = 2..15), warm (the solver kernel compiled and
cached, one run before the measured ones), alone and with `--png` and `--html`; then the
3-D pages of Fig. 2's grasps (the `fig2` step's second half) in this process.

    .venv/bin/python benchmarks/bench_inspector.py [--results results] [--runs 3]

Each command variant runs in a fresh process `--runs` times: the median wall time and the
median CPU time (user + system of the process). Needs a finished default study under
`--results` (obj4's searched target, every object's contacts). The machine-read lines
(`key: number  (what it is)`) are what `make bench` records (tools/measurements.py).
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMAND = ["grasp", "obj4", "--alpha", "-30", "--beta", "0"]


def _cpu_children() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(args: list[str], results: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one run of the command in its own process."""
    cpu, start = _cpu_children(), time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "synergrasp.cli", *COMMAND, "--results", str(results), *args],
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    return time.perf_counter() - start, _cpu_children() - cpu


def pages_cost(results: Path, folder: Path) -> tuple[float, float]:
    """Wall and CPU seconds of the 3-D pages' work on the study under ``results``
    (imports and the solver kernel's load from its cache included)."""
    cpu, start = time.process_time(), time.perf_counter()
    from synergrasp import table_contracts
    from synergrasp.config import validate_config
    from synergrasp.figures.grasp_3d import Grasps3dParams, fig2_scenes, write_grasp_pages
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies

    params = Grasps3dParams.from_config(validate_config({}))
    hand = load_hand(params.hand)
    matrix = load_synergies(params.synergies, joint_names=hand.joint_names).matrix
    contacts = [
        table_contracts.read(table_contracts.CONTACTS, results / "objects" / o.name / "contacts.parquet") for o in params.objects
    ]
    write_grasp_pages(folder, fig2_scenes(hand, matrix, params, contacts), "pages")
    return time.perf_counter() - start, time.process_time() - cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--results", type=Path, default=Path("results"))
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    if not (args.results / "objects" / "obj4" / "placement.csv").is_file():
        raise SystemExit(f"no finished default study under {args.results} (obj4's placement.csv): run `make study`")
    what = f"synergrasp grasp obj4 --alpha -30 --beta 0, 29 sets, warm, median of {args.runs} runs"
    with tempfile.TemporaryDirectory() as tmp:
        variants = {
            "": [],
            "_png": ["--png", f"{tmp}/g.png"],
            "_html": ["--html", f"{tmp}/g.html"],
            "_png_html": ["--png", f"{tmp}/g.png", "--html", f"{tmp}/g.html"],
        }
        run_once([], args.results)  # warm: the kernel's cache and the files in the page cache
        for name, extra in variants.items():
            times = [run_once(extra, args.results) for _ in range(args.runs)]
            flags = " ".join(a for a in extra if a.startswith("--")) or "alone"
            print(f"inspector{name}_wall_s: {statistics.median(t[0] for t in times):.2f}  ({what}; {flags}: wall s)")
            print(f"inspector{name}_cpu_s: {statistics.median(t[1] for t in times):.2f}  ({what}; {flags}: CPU s)")
        wall, cpu = pages_cost(args.results, Path(tmp) / "pages")
    print(
        f"grasps_3d_pages_wall_s: {wall:.2f}  (the 3-D pages of Fig. 2's 12 grasps with the full set's forces, "
        "imports included: wall s)"
    )
    print(f"grasps_3d_pages_cpu_s: {cpu:.2f}  (the same: CPU s)")


if __name__ == "__main__":
    main()
