"""The incremental grasp planner: the study's minimum preservation put to work.

The study finds that the local minima of the optimal force over the (α, β) poses "remain
roughly the same as more synergies are considered" and proposes to leverage the solution
of lower-dimensional problems as synergies are added. The planner (docs/planner.md):

1. solve {S1} at every pose of the grid;
2. find that level's local minima by the study's policy (:func:`synergrasp.analysis.minima.local_minima`,
   its radius, over the poses solved at that level);
3. for k = 2 … n solve {S1..Sk} only at the poses within ±radius in α (wrapped) and in β
   of the previous level's minima (seeds);
4. return the pose of least optimal force with the full set {S1..Sn} among those it solved.

A level without a minimum among its solved poses seeds the next with its best success (the
policy needs poses below the median, which a handful of successes may not give); a level
without any success seeds nothing, and the next level is solved over the whole grid.

What a solve is, is the caller's: ``solve(k, poses) -> (success, force_N)`` for {S1..Sk}
at the given pose indices (the study's solver front door in
:mod:`synergrasp.analysis.plan_study`; a hand-made force map in the tests). Also here:
how a plan compares with the exhaustive search, and the greedy enrollment order.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from synergrasp.analysis.minima import FORCE_TIE_RTOL, local_minima, preserved

__all__ = ["LevelSolve", "Plan", "plan_incremental", "plan_against_exhaustive", "pose_against_exhaustive", "greedy_order"]

#: (k, pose indices) -> (success (p,) bool, optimal force (p,) N, NaN where no success).
LevelSolve = Callable[[int, NDArray[np.int64]], tuple[NDArray[np.bool_], NDArray[np.float64]]]


@dataclass(frozen=True)
class Plan:
    """One run of the planner.

    radius_deg: the neighbourhood half-width around each level's seeds, deg.
    solved: per level solved (k = 1 … n unless the caller skips levels), the pose indices
        solved with that level's set {S1..Sk}.
    seeds: per level, the pose indices seeding the next level (its minima, else its best
        success; empty: none, the next level covers the grid).
    from_minima: per level, whether the seeds are local minima.
    best_pose: pose index of least optimal force with the full set among those solved
        (-1: none succeeds); best_force_N its optimal force, N (NaN: none).
    """

    radius_deg: float
    solved: tuple[NDArray[np.int64], ...]
    seeds: tuple[NDArray[np.int64], ...]
    from_minima: tuple[bool, ...]
    best_pose: int
    best_force_N: float

    @property
    def n_solves(self) -> int:
        """(pose, set) problems solved over every level."""
        return int(sum(s.size for s in self.solved))


def _neighbourhood(
    alpha: NDArray, beta: NDArray, seeds: NDArray[np.int64], radius_deg: float, alpha_period_deg: float
) -> NDArray[np.int64]:
    """Pose indices within ±radius (α wrapping) of any seed: the minima module's own square
    test (`preserved` asks, per pose, whether a seed lies in its square)."""
    near = preserved(alpha, beta, alpha[seeds], beta[seeds], radius_deg, alpha_period_deg)
    return np.flatnonzero(near).astype(np.int64)


def plan_incremental(
    alpha_deg: ArrayLike,
    beta_deg: ArrayLike,
    solve: LevelSolve,
    n_levels: int,
    radius_deg: float,
    minima_radius_deg: float = 10.0,
    alpha_period_deg: float = 360.0,
    levels: Sequence[int] | None = None,
    max_seeds: int | None = None,
) -> Plan:
    """Run the planner over a pose grid (module docstring).

    alpha_deg, beta_deg: (p,) the grid's poses, deg; solve: :data:`LevelSolve`;
    n_levels: n, the full set is {S1..Sn}; radius_deg: the seeds' neighbourhood, deg;
    minima_radius_deg: the study's radius of a local minimum, deg; levels: the set sizes k
    solved, increasing, ending at n (None: every k = 1 … n; the variants of docs/planner.md skip
    levels); max_seeds: only the minima of least force, at most this many, seed the next level
    (None: every minimum). ``Plan.solved`` holds one entry per level solved.
    """
    alpha = np.asarray(alpha_deg, dtype=float)
    beta = np.asarray(beta_deg, dtype=float)
    if n_levels < 1:
        raise ValueError(f"n_levels must be >= 1; got {n_levels}")
    ks = list(range(1, n_levels + 1)) if levels is None else [int(k) for k in levels]
    if not ks or ks[-1] != n_levels or any(b <= a for a, b in zip(ks, ks[1:])) or ks[0] < 1:
        raise ValueError(f"levels must increase from >= 1 to n_levels = {n_levels}; got {ks}")
    if max_seeds is not None and max_seeds < 1:
        raise ValueError(f"max_seeds must be >= 1 or None; got {max_seeds}")
    every = np.arange(alpha.size, dtype=np.int64)
    seeds = np.zeros(0, dtype=np.int64)
    solved, seeded, from_minima = [], [], []
    success = force = np.zeros(0)
    todo = every
    for i, k in enumerate(ks):
        if i > 0:
            todo = _neighbourhood(alpha, beta, seeds, radius_deg, alpha_period_deg) if seeds.size else every
        success, force = solve(k, todo)
        success = np.asarray(success, dtype=bool) & np.isfinite(force)
        minima = local_minima(alpha[todo], beta[todo], force, success, minima_radius_deg, alpha_period_deg)
        if minima.any():
            found = np.flatnonzero(minima)
            if max_seeds is not None:  # the least forces; a stable sort keeps the lower pose on a tie
                found = found[np.argsort(force[found], kind="stable")[:max_seeds]]
            seeds = todo[np.sort(found)]
        elif success.any():
            seeds = todo[[int(np.nanargmin(np.where(success, force, np.nan)))]]
        else:
            seeds = np.zeros(0, dtype=np.int64)
        solved.append(todo)
        seeded.append(seeds)
        from_minima.append(bool(minima.any()))
    if success.any():
        best = int(np.nanargmin(np.where(success, force, np.nan)))
        best_pose, best_force = int(todo[best]), float(force[best])
    else:
        best_pose, best_force = -1, float("nan")
    return Plan(float(radius_deg), tuple(solved), tuple(seeded), tuple(from_minima), best_pose, best_force)


def plan_against_exhaustive(plan: Plan, full_success: ArrayLike, full_force: ArrayLike) -> dict[str, float | int | bool]:
    """How a plan compares with the exhaustive search of the full set over every pose.

    full_success, full_force: (p,) the full set's verdict and optimal force (N) at every
    pose. Returns: exhaustive_min_force_N, exhaustive_best_pose, is_global_min (the plan's
    force equal to the minimum within the tie tolerance of the minima), rank (1 + the poses
    whose exhaustive force is lower beyond that tolerance; twins share a rank; 0: no pose),
    n_ranked (force-closure poses), regret (plan's force / the minimum; exactly 1 for the minimum
    within the tie tolerance, never below 1; NaN without either).
    """
    return pose_against_exhaustive(plan.best_pose, plan.best_force_N, full_success, full_force)


def pose_against_exhaustive(
    best_pose: int, best_force_N: float, full_success: ArrayLike, full_force: ArrayLike
) -> dict[str, float | int | bool]:
    """How a planner's pose (index, -1: none) and its full-set force (N) compare with the
    exhaustive search: :func:`plan_against_exhaustive`'s columns."""
    fc = np.asarray(full_success, dtype=bool) & np.isfinite(full_force)
    f = np.where(fc, np.asarray(full_force, dtype=float), np.inf)
    if not fc.any():
        return {
            "exhaustive_min_force_N": float("nan"),
            "exhaustive_best_pose": -1,
            "is_global_min": False,
            "rank": 0,
            "n_ranked": 0,
            "regret": float("nan"),
        }
    best = int(np.argmin(f))
    mine = best_force_N
    found = best_pose >= 0
    rank = int(np.sum(f < mine * (1.0 - FORCE_TIE_RTOL))) + 1 if found else 0
    is_global = bool(found and mine <= f[best] * (1.0 + FORCE_TIE_RTOL))
    # the minimum itself (or a twin within the tie tolerance): no regret, not rounding's 1 + 1e-16
    regret = 1.0 if is_global else (max(float(mine / f[best]), 1.0) if found else float("nan"))
    return {
        "exhaustive_min_force_N": float(f[best]),
        "exhaustive_best_pose": best,
        "is_global_min": is_global,
        "rank": rank,
        "n_ranked": int(fc.sum()),
        "regret": regret,
    }


def greedy_order(
    count: Callable[[Sequence[tuple[int, ...]]], NDArray[np.int64]], n_synergies: int, target: int
) -> tuple[tuple[int, ...], NDArray[np.int64]]:
    """The enrollment order the data prefers: start from no synergy; add, each time, the
    synergy whose set has the most successes (``count(sets) -> successes per set``; ties:
    the lower index), until the set reaches ``target`` successes (the full set's); the
    remaining synergies follow in PCA order (every superset of a set at the target stays
    at it: the sets are nested).

    Returns the order (1-based synergies, length ``n_synergies``) and the successes of the
    greedy set {g1..gk} for k = 1 … n_synergies."""
    order: list[int] = []
    counts: list[int] = []
    left = list(range(1, n_synergies + 1))
    while left and (not counts or counts[-1] < target):
        sets = [tuple(sorted(order + [s])) for s in left]
        got = np.asarray(count(sets), dtype=np.int64)
        pick = int(np.argmax(got))  # first maximum: the lower synergy index
        order.append(left.pop(pick))
        counts.append(int(got[pick]))
    counts += [counts[-1] if counts else 0] * len(left)
    return tuple(order + left), np.asarray(counts, dtype=np.int64)
