"""Throughput of grasp-force optimisation: the compiled interior-point back end vs
per-problem Clarabel vs cvxpy, all through the front door `solve_gfo`.

Realistic study mix: random grasps with 4-12 contacts (some on the palm) x the 75 synergy
sets of the study (15 incremental + subsets of 1-3 of S1..S7). The "ipm" figure is the
study's loop (`optimise.optimise_grasps`, GFO only): mechanics, bases, rows and solves,
measured after one warm-up call that loads the compiled kernel (its one-time cost per
process is printed separately), median of 5 runs (`--repeats`); also, not machine-read, the
same loop with every set solved and every basis from scratch (`IPMSettings(nested=False)`). Run on one core with
OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1. The last six lines are machine-read (`key: N  (what)`,
tools/measurements.py).
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the generators the tests use
from grasp_problems import random_grasp, random_synergies  # noqa: E402

from synergrasp.config import defaults  # noqa: E402
from synergrasp.optimisation.gfo import solve_gfo  # noqa: E402
from synergrasp.optimisation.ipm.solver import IPMSettings  # noqa: E402
from synergrasp.optimisation.problem import GraspSets, SynergySets  # noqa: E402
from synergrasp.optimisation.optimise import OptimiseParams, mechanics_for, optimise_grasps  # noqa: E402


def study_sets() -> list[tuple[int, ...]]:
    sets = [tuple(range(1, k + 1)) for k in range(1, 16)]
    for r in (1, 2, 3):
        sets += [c for c in itertools.combinations(range(1, 8), r) if c not in sets]
    return sets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problems", type=int, default=15000, help="number of (pose, set) GFO problems")
    ap.add_argument("--exact", type=int, default=1500, help="problems for the per-problem exact solver")
    ap.add_argument("--cvxpy", type=int, default=60, help="problems for the cvxpy loop")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=5, help="runs of the study loop; the median is reported")
    args = ap.parse_args()

    rng = np.random.default_rng(args.seed)
    sets = study_sets()
    n_poses = max(1, args.problems // len(sets))
    grasps = [random_grasp(rng, int(rng.integers(4, 13)), palm_contacts=int(rng.integers(0, 2))) for _ in range(n_poses)]
    # the study's mechanics (configuration defaults), gravity along the benchmark grasps' -z
    params = replace(OptimiseParams.from_config(defaults(), "obj1").gfo, gravity_direction=(0.0, 0.0, -1.0))
    synergies = SynergySets(random_synergies(rng), tuple(sets))
    n = n_poses * len(sets)

    t0 = time.perf_counter()
    optimise_grasps(grasps[:1], SynergySets(synergies.matrix, tuple(sets[:1])), params, strict=False)  # loads the kernel
    t_load = time.perf_counter() - t0
    walls, cpus = [], []
    for _ in range(args.repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = optimise_grasps(grasps, synergies, params, strict=False)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    t_ipm, c_ipm = float(np.median(walls)), float(np.median(cpus))
    every = []  # the kernel against itself: every set solved, every basis from scratch
    for _ in range(args.repeats):
        c0 = time.process_time()
        optimise_grasps(grasps, synergies, params, strict=False, ipm=IPMSettings(nested=False))
        every.append(time.process_time() - c0)
    ipm_rate = n / t_ipm
    fallback = float(np.mean(out["solver"] == "clarabel_fallback"))

    # The same problems, per problem (subset): mechanics once per pose, then E and the solve.
    problems = []
    for grasp in grasps:
        mech = mechanics_for(grasp, params)
        if mech.rank_G == 6:
            g = GraspSets(
                mech.f_p,
                mech.normals,
                mech.projector,
                mech.response_norm,
                synergies,
                params.f_min_N,
                params.cone,
                params.basis_rtol,
            )
            problems += [(g, j) for j in range(len(g))]
    pick = rng.permutation(len(problems))

    def per_problem_rate(method: str, count: int) -> float:
        sub = [problems[k] for k in pick[:count]]
        t0 = time.perf_counter()
        for g, j in sub:
            solve_gfo([g.problem(j)], method)
        return len(sub) / (time.perf_counter() - t0)

    exact_rate = per_problem_rate("clarabel", args.exact)
    cvxpy_rate = per_problem_rate("cvxpy", args.cvxpy)

    statuses = {s: int(np.sum(out["status"] == s)) for s in sorted(set(out["status"]))}
    print(f"problems: {n} ({n_poses} grasps x {len(sets)} sets), statuses {statuses}")
    print(f"mean interior-point iterations: {out['iterations'][out['solver'] == 'ipm'].mean():.2f}")
    print(f"compiled kernel load (once per process): {t_load:.2f} s")
    print(
        f"every set solved (IPMSettings(nested=False)), solves per CPU second: {n / float(np.median(every)):.0f}; "
        f"implied by nested sets: {np.mean(out['solver'] == 'implied'):.3f} of the problems"
    )
    print(
        f"gfo_solves_per_s: {ipm_rate:.0f}  (the study's loop, solves per second, wall; mechanics, bases and "
        f"building included; median of {args.repeats} runs of {n:,} problems, {min(walls):.2f}-{max(walls):.2f} s)"
    )
    print(f"gfo_solves_per_cpu_s: {n / c_ipm:.0f}  (the same loop, solves per CPU second: steadier on a loaded machine)")
    print(f"clarabel_solves_per_s: {exact_rate:.0f}  (per-problem Clarabel, solves per second, {min(args.exact, n)} problems)")
    print(f"cvxpy_solves_per_s: {cvxpy_rate:.1f}  (per-problem cvxpy, solves per second, {min(args.cvxpy, n)} problems)")
    print(f"gfo_speedup_vs_cvxpy: {ipm_rate / cvxpy_rate:.0f}  (the study's loop over per-problem cvxpy)")
    print(f"gfo_fallback_share: {fallback:.4f}  (share of the problems the Clarabel fallback decided)")


if __name__ == "__main__":
    main()
