"""`synergrasp plan --on-demand` on every object of the configuration (the four boxes of the
default study, or those of ``--configfile`` overlays, e.g. pybullet's random objects): the
hand closed only where the planner asks, against the study's exhaustive
minimum (docs/planner.md). Needs a study's results (``--results``: the searched placement's
target and the gfo tables the regret is read from). Per object the machine-read lines
(`key: N  (what)`, tools/measurements.py): closures run, their share of the grid, the wall
time of the plan (closures and solves) and the regret.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from synergrasp import tables
from synergrasp.analysis.plan_new import DEFAULT_PLANNER
from synergrasp.study_checks import checked_configuration
from synergrasp.cli import main as synergrasp


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--results", default="results", help="the study's results")
    ap.add_argument("--planner", default=DEFAULT_PLANNER)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--configfile", nargs="+", default=[], help="overlays on the study's configuration")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for obj in checked_configuration(args.configfile)["objects"]:
            out = Path(folder) / f"{obj}.csv"
            code = synergrasp(
                [
                    "plan",
                    obj,
                    "--on-demand",
                    "--planner",
                    args.planner,
                    "--seed",
                    str(args.seed),
                    "--results",
                    args.results,
                    "--csv",
                    str(out),
                ]
                + (["--configfile", *args.configfile] if args.configfile else [])
            )
            if code:
                raise SystemExit(code)
            rows.append(tables.read_csv(tables.PLAN_ON_DEMAND, out).iloc[0])
    for r in rows:
        print(
            f"closures_{r['object']}: {r['closures']}  ({r['planner']}, seed {r['seed']}: closures run of {r['n_poses']} poses)"
        )
        print(f"closure_share_{r['object']}: {100.0 * r['closures'] / r['n_poses']:.1f}  (% of the exhaustive closures)")
        print(f"wall_s_{r['object']}: {r['wall_s']:.1f}  (the plan's wall time, closures and solves, s)")
        print(f"regret_percent_{r['object']}: {r['regret_percent']:.2f}  (its force over the study's exhaustive minimum, -1, %)")


if __name__ == "__main__":
    main()
