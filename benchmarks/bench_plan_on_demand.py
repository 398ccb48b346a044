"""`synergrasp plan --on-demand` on every object of the configuration (the four boxes of the
default study, or those of ``--configfile`` overlays, e.g. pybullet's random objects): the
hand closed only where the planner asks, against the study's exhaustive
minimum (docs/planner.md). Needs a study's results (``--results``: the searched placement's
target and the gfo tables the regret is read from). Per object the machine-read lines
(`key: N  (what)`, tools/measurements.py): closures run, their share of the grid, the wall
time of the plan (closures and solves) and the regret; then the figures across the objects
(the share planned within 5 % of the exhaustive minimum, with at most half its closures).

Many objects: ``--shard K/N`` plans every N-th object from the K-th (two shards side by side
on two cores), ``--table`` keeps the rows (table ``plan_on_demand``), and ``--summarise
A.csv B.csv`` prints the figures across the shards' tables without planning. An object the
command cannot plan (exit status != 0) is a row-less failure counted in the summary.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.plan_new import DEFAULT_PLANNER
from synergrasp.cli import main as synergrasp
from synergrasp.input_checks import checked_configuration

#: The issue's aim: a pose within this regret (%), with at most this share of the closures.
AIM_REGRET_PERCENT, AIM_CLOSURE_SHARE = 5.0, 0.5


def _shard(text: str) -> tuple[int, int]:
    k, _, n = text.partition("/")
    if not (k.isdigit() and n.isdigit() and 0 <= int(k) < int(n)):
        raise argparse.ArgumentTypeError(f"--shard {text!r}: K/N with 0 <= K < N")
    return int(k), int(n)


def plan_objects(objects: list[str], args: argparse.Namespace) -> tuple[pd.DataFrame, list[str]]:
    """Each object planned in this process; the rows and the objects that could not be planned."""
    rows, failed = [], []
    overlays = ["--configfile", *args.configfile] if args.configfile else []
    with tempfile.TemporaryDirectory() as folder:
        for obj in objects:
            out = Path(folder) / f"{obj}.csv"
            argv = ["plan", obj, "--on-demand", "--planner", args.planner, "--seed", str(args.seed)]
            code = synergrasp(argv + ["--results", args.results, "--csv", str(out)] + overlays)
            if code:
                failed.append(obj)
                continue
            rows.append(table_contracts.read_csv(table_contracts.PLAN_ON_DEMAND, out))
    return (pd.concat(rows, ignore_index=True) if rows else table_contracts.empty(table_contracts.PLAN_ON_DEMAND)), failed


def print_rows(table: pd.DataFrame) -> None:
    """Per object, the machine-read lines of its plan."""
    for r in table.itertuples():
        print(f"closures_{r.object}: {r.closures}  ({r.planner}, seed {r.seed}: closures run of {r.n_poses} poses)")
        print(f"closure_share_{r.object}: {100.0 * r.closures / r.n_poses:.1f}  (% of the exhaustive closures)")
        print(f"wall_s_{r.object}: {r.wall_s:.1f}  (the plan's wall time, closures and solves, s)")
        print(f"regret_percent_{r.object}: {r.regret_percent:.2f}  (its force over the study's exhaustive minimum, -1, %)")


def summarise(table: pd.DataFrame, n_failed: int) -> None:
    """The figures across the objects (machine-read lines)."""
    share = table["closures"] / table["n_poses"]
    within = table["regret_percent"] <= AIM_REGRET_PERCENT
    n = len(table) + n_failed
    print(f"objects: {n}  (asked; {n_failed} could not be planned)")
    print(f"within_5_percent: {100.0 * within.sum() / n:.1f}  (% of the objects planned within 5 % of the exhaustive minimum)")
    both = within & (share <= AIM_CLOSURE_SHARE)
    print(f"aim_met: {100.0 * both.sum() / n:.1f}  (% of the objects within 5 % with at most half the closures)")
    print(f"closure_share_median: {100.0 * float(np.median(share)):.1f}  (% of the exhaustive closures, median over objects)")
    print(f"wall_s_median: {float(np.median(table['wall_s'])):.1f}  (the plan's wall time per object, median, s)")
    print(f"wall_s_total: {float(table['wall_s'].sum()):.0f}  (summed over objects, s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--results", default="results", help="the study's results")
    ap.add_argument("--planner", default=DEFAULT_PLANNER)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    ap.add_argument("--shard", type=_shard, default=(0, 1), help="K/N: every N-th object from the K-th")
    ap.add_argument("--table", type=Path, help="write the rows here (CSV, table plan_on_demand)")
    ap.add_argument("--summarise", type=Path, nargs="+", help="only summarise these tables")
    args = ap.parse_args()
    if args.summarise:
        frames = [table_contracts.read_csv(table_contracts.PLAN_ON_DEMAND, p) for p in args.summarise]
        table = pd.concat(frames, ignore_index=True)
        print_rows(table)
        summarise(table, 0)
        return
    k, n = args.shard
    objects = sorted(checked_configuration(args.configfile)["objects"])[k::n]
    table, failed = plan_objects(objects, args)
    if args.table:
        table_contracts.write_csv(table_contracts.PLAN_ON_DEMAND, table, args.table)
    print_rows(table)
    summarise(table, len(failed))


if __name__ == "__main__":
    main()
