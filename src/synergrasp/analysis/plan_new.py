"""A planner for a new object (``synergrasp plan --on-demand``, docs/planner.md): the hand is
closed only at the poses the planner asks, pose by pose on demand, through the study's
closure front door (``simulation.closure.simulate_object``, with the ``contacts`` step's
choice of contacts: ``inspector.object_closure`` makes the ``close`` this module is handed),
and every set is solved through the optimisation front door (``optimise_grasps``, via
:class:`synergrasp.analysis.plan_study.StudySolver`); so a plan costs the planner's
closures, not the grid's.

The default planner, :data:`DEFAULT_PLANNER`, is the one the pre-registered rule selects
(``analysis.planners.recommended``) on the study's comparison (table ``planners_across``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.plan_study import PlanParams, StudySolver
from synergrasp.analysis.planners import CANDIDATES, Oracle, PlannerSpec, PoseGrid, run_planner
from synergrasp.optimisation.mechanics import GraspMechanics, first_same_grasp, read_grasps

__all__ = ["DEFAULT_PLANNER", "planner_spec", "OnDemandSolver", "OnDemandPlan", "plan_on_demand"]

#: The rule's choice on the hundred random objects (97 studied; tables/planners_across.csv of
#: config/examples/random_objects.yaml): only the exhaustive search meets the aim there, so a
#: new object is planned by closing every pose unless ``--planner`` asks for a cheaper one (on
#: the four boxes the rule chose random_1200; docs/planner.md gives both comparisons).
DEFAULT_PLANNER = "exhaustive"


def planner_spec(name: str) -> PlannerSpec:
    """The candidate planner of that name; ValueError naming the candidates otherwise."""
    found = {s.name: s for s in CANDIDATES}
    if name not in found:
        raise ValueError(f"--planner {name!r} is not a candidate planner; candidates: {', '.join(found)}")
    return found[name]


class OnDemandSolver(StudySolver):
    """A :class:`StudySolver` of an object nobody closed: ``close(poses) -> contacts table``
    (one row per pose, in that order) closes the hand at the grid poses a planner asks that
    are not closed yet; twins are found among the poses closed so far (a pose's grasp counts
    once however often it is asked)."""

    def __init__(
        self, obj: str, n_poses: int, close: Callable[[Sequence[int]], pd.DataFrame], matrix: NDArray, params: PlanParams
    ) -> None:
        Oracle.__init__(self, n_poses, params.n_levels)  # nothing closed yet: no contacts to read
        self.object_name, self.pose_ids = obj, np.arange(n_poses, dtype=np.int64)
        self.grasps: list = [None] * n_poses
        self.first = np.full(n_poses, -1, dtype=np.int64)
        self.matrix, self.params = matrix, params
        self.memo: dict[tuple[str, int], tuple[bool, float]] = {}
        self.mechanics: dict[int, GraspMechanics] = {}
        self.n_problems = 0
        self.close = close
        self.is_closed = np.zeros(n_poses, dtype=bool)

    def ask(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        new = poses[~self.is_closed[poses]]
        if new.size:
            table = self.close([int(v) for v in new])
            for pose, grasp in zip(new, read_grasps(table.reset_index(drop=True))):
                self.grasps[int(pose)] = grasp
            self.is_closed[new] = True
            # the first closed pose of a grasp stays its representative: twins only point to it
            first = np.asarray(first_same_grasp(self.grasps), dtype=np.int64)
            self.first = np.where(self.first >= 0, self.first, first)
        return super().ask(k, poses)


@dataclass(frozen=True)
class OnDemandPlan:
    """A plan on a new object: the planner and seed, its pose (−1: none succeeds), (α, β)
    deg, its full-set force (N), the closures it ran of the grid's poses, the (grasp, set)
    problems it solved, and its wall time (s)."""

    object: str
    planner: str
    seed: int
    pose: int
    alpha_deg: float
    beta_deg: float
    force_N: float
    closures: int
    n_poses: int
    problems: int
    wall_s: float


def plan_on_demand(
    obj: str,
    grid: PoseGrid,
    close: Callable[[Sequence[int]], pd.DataFrame],
    matrix: NDArray,
    params: PlanParams,
    spec: PlannerSpec,
    seed: int = 0,
) -> tuple[OnDemandPlan, OnDemandSolver]:
    """Run ``spec`` on object ``obj`` closing the hand only where it asks (module docstring)."""
    t0 = time.perf_counter()
    solver = OnDemandSolver(obj, grid.n_poses, close, matrix, params)
    rng = np.random.default_rng(seed) if spec.randomised else None
    pose, force = run_planner(spec, grid, solver, params.n_levels, params.minima.radius_deg, rng)
    wall = time.perf_counter() - t0
    a, b = (float(grid.alpha_deg[pose]), float(grid.beta_deg[pose])) if pose >= 0 else (np.nan, np.nan)
    return OnDemandPlan(
        obj, spec.name, seed, pose, a, b, force, int(solver.is_closed.sum()), grid.n_poses, int(solver.problems.sum()), wall
    ), solver
