"""Solve time of one grasp-force problem per size k of the synergy set {S1..Sk}, as the
planners hand them to the solver (docs/planner.md): one call of the study's front door
`optimise_grasps` per set, on random grasps of 3-8 contacts (the generator the tests use),
the grasp's mechanics included (each level of a planner is such a call). CPU time (steadier
than wall time on a shared machine), median of ``--repeats`` runs, after one warm-up call that
loads the compiled kernel. Run on one core
with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1. The last lines are machine-read
(`key: N  (what)`, tools/measurements.py): ``solve_us_k<k>`` the microseconds per
(grasp, set) problem, and ``solve_cost_k<k>`` the same over the full set's (n = 15).
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the generators the tests use
from grasp_problems import random_grasp, random_synergies  # noqa: E402

from synergrasp.config import defaults  # noqa: E402
from synergrasp.optimisation.optimise import OptimiseParams, optimise_grasps  # noqa: E402
from synergrasp.optimisation.problem import SynergySets  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--grasps", type=int, default=2000, help="grasps solved per set size")
    ap.add_argument("--repeats", type=int, default=7, help="runs per set size; the median is reported")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    rng = np.random.default_rng(args.seed)
    grasps = [random_grasp(rng, int(rng.integers(3, 9))) for _ in range(args.grasps)]
    params = replace(OptimiseParams.from_config(defaults(), "obj1").gfo, gravity_direction=(0.0, 0.0, -1.0))
    matrix = random_synergies(rng)
    n = matrix.shape[1]
    optimise_grasps(grasps[:1], SynergySets(matrix, ((1,),)), params)  # loads the compiled kernel
    per_k = []
    for k in range(1, n + 1):
        sets = SynergySets(matrix, (tuple(range(1, k + 1)),))
        cpus = []
        for _ in range(args.repeats):
            c0 = time.process_time()
            optimise_grasps(grasps, sets, params)
            cpus.append(time.process_time() - c0)
        per_k.append(1e6 * float(np.median(cpus)) / len(grasps))
    print(f"{len(grasps)} random grasps (3-8 contacts) per set size, median of {args.repeats} runs")
    for k, us in enumerate(per_k, start=1):
        print(f"solve_us_k{k}: {us:.1f}  (one (grasp, set) problem of {{S1..S{k}}}, mechanics included, CPU us)")
    for k, us in enumerate(per_k, start=1):
        print(f"solve_cost_k{k}: {us / per_k[-1]:.3f}  (its solve time over the full set's, {{S1..S{n}}})")


if __name__ == "__main__":
    main()
