"""The incremental planner on one object of the study (the ``plan`` step, docs/planner.md).

The planner (:mod:`synergrasp.analysis.planner`) runs once per radius on the object's study:
a (set, grasp) the gfo table already holds is read from it (the study's own solve, judged by
`with_verdicts`, ``analyses.success``), and every other set (the greedy enrollment's) is solved
through the study's front door, `optimise_grasps` (one model: the gfo step's), on the
object's contacts table. The exhaustive gfo table is the yardstick; the solver the planner
runs on demand (``synergrasp plan --on-demand``) is audited against it at the poses that
steered the plans (``study_rows_differing``: same verdict, force within 1e-5 relative, else
counted).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.minima import FORCE_TIE_RTOL, MinimaParams
from synergrasp.analysis.planner import Plan, greedy_order, plan_against_exhaustive, plan_incremental
from synergrasp.analysis.planners import CANDIDATES, Oracle, PlannerSpec, PoseGrid, ReplayOracle, compare_planners
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.ids import incremental_set_id, set_id
from synergrasp.optimisation.mechanics import GraspMechanics, first_same_grasp, read_grasps
from synergrasp.optimisation.optimise import GFOParams, mechanics_for, optimise_grasps
from synergrasp.optimisation.problem import SynergySets

__all__ = ["PlanParams", "ObjectPlan", "StudySolver", "plan_object", "PlannersParams", "replay_oracle", "compare_on_study"]


@dataclass(frozen=True)
class PlanParams:
    """The ``plan`` step of one object: the planner's radii (deg), the full set's size n,
    the synergy file (None: the shipped table), the GFO parameters and the minima's policy
    (radius, verdict, force bound)."""

    radii_deg: tuple[float, ...]
    n_levels: int
    synergies: str | None
    gfo: GFOParams
    minima: MinimaParams

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> PlanParams:
        """From a configuration or the step's own part of it, for the object ``obj``."""
        return cls(
            tuple(float(r) for r in config["analyses"]["planner_radii_deg"]),
            int(config["synergy_sets"]["incremental_max"]),
            config["synergies"],
            GFOParams.from_config(config, obj),
            MinimaParams.from_config(config, obj),
        )


@dataclass(frozen=True)
class ObjectPlan:
    """The planner on one object: ``table`` (table_contracts.PLAN, one row per radius), ``enrollment``
    (table_contracts.ENROLLMENT, one row per k), the plans by radius (deg), and ``full``: the full
    set's rows of the judged gfo table, one per pose in the contacts' order (``success``,
    ``success_force`` in N)."""

    table: pd.DataFrame
    enrollment: pd.DataFrame
    plans: dict[float, Plan]
    full: pd.DataFrame


class StudySolver(Oracle):
    """Solves synergy sets at poses of one object through `optimise_grasps`, one solve per
    distinct grasp (the study's sharing of twins), and remembers them: a (grasp, set) is
    solved once however many radii ask, and a grasp's mechanics (what does not depend on
    the set) are computed once however many sets it is solved for. ``n_problems`` counts the
    problems handed to the solver; as an :class:`~synergrasp.analysis.planners.Oracle`
    (``solver(k, poses)``: a planner's solve of {S1..Sk}) it also keeps the planners' cost ledger."""

    def __init__(self, contacts: pd.DataFrame, matrix: NDArray, params: PlanParams, study: pd.DataFrame | None = None):
        super().__init__(len(contacts), params.n_levels)
        self.contacts = contacts.reset_index(drop=True)
        self.object_name = str(self.contacts["object"].iat[0]) if len(self.contacts) else ""
        self.pose_ids = self.contacts["pose"].to_numpy(np.int64)
        self.grasps = read_grasps(self.contacts)
        self.first = first_same_grasp(self.grasps)
        self.matrix, self.params = matrix, params
        self.memo: dict[tuple[str, int], tuple[bool, float]] = {}
        self.mechanics: dict[int, GraspMechanics] = {}
        self.n_problems = 0
        if study is not None:
            self._remember(study)

    def _remember(self, study: pd.DataFrame) -> None:
        """Take the (set, grasp) verdicts the study already holds (its judged gfo table, one row
        per pose and set) instead of solving them again: the rows at each grasp's first pose."""
        reps = np.unique(self.first[self.first >= 0])
        row_of = dict(zip(self.pose_ids[reps].tolist(), reps.tolist()))
        rows = study[study["pose"].isin(list(row_of))]
        for pose, sid, ok, force in zip(
            rows["pose"].tolist(), rows["set_id"].astype(str).tolist(), rows["success"].tolist(), rows["success_force"].tolist()
        ):
            self.memo[sid, row_of[pose]] = (bool(ok), float(force))

    def verdicts(self, sets: Sequence[tuple[int, ...]], poses: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """(len(sets), len(poses)) success (the study's verdict) and its optimal force (N, NaN
        elsewhere) of every set at every pose."""
        ids = [set_id(s) for s in sets]
        reps = np.unique(self.first[poses][self.first[poses] >= 0])
        missing = [i for i, sid in enumerate(ids) if any((sid, int(g)) not in self.memo for g in reps)]
        new = [int(g) for g in reps if any((ids[i], int(g)) not in self.memo for i in missing)]
        if new:
            self._solve([sets[i] for i in missing], [ids[i] for i in missing], new)
        success = np.zeros((len(sets), len(poses)), dtype=bool)
        force = np.full((len(sets), len(poses)), np.nan)
        for j, pose in enumerate(poses):
            g = int(self.first[pose])
            if g < 0:
                continue
            for i, sid in enumerate(ids):
                success[i, j], force[i, j] = self.memo[sid, g]
        return success, force

    def _solve(self, sets: Sequence[tuple[int, ...]], ids: list[str], grasps: list[int]) -> None:
        for g in grasps:
            if g not in self.mechanics:
                self.mechanics[g] = mechanics_for(self.grasps[g], self.params.gfo)
        out = optimise_grasps(
            [self.grasps[g] for g in grasps],
            SynergySets(self.matrix, tuple(sets)),
            self.params.gfo,
            mechanics=[self.mechanics[g] for g in grasps],
        )
        self.n_problems += len(grasps) * len(sets)
        frame = pd.DataFrame({"object": self.object_name, "pose": self.pose_ids[np.repeat(grasps, len(sets))]} | out)
        minima = self.params.minima
        weights = {self.object_name: minima.weight_N} if minima.weight_N is not None and len(frame) else None
        judged = with_verdicts(frame, minima.success, weights, minima.bound_multiple)
        success, force = judged["success"].to_numpy(bool), judged["success_force"].to_numpy(float)
        for row, g in enumerate(np.repeat(grasps, len(sets))):
            self.memo[ids[row % len(sets)], int(g)] = (bool(success[row]), float(force[row]))

    def level(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """The planner's solve: {S1..Sk} at ``poses``."""
        success, force = self.verdicts([tuple(range(1, k + 1))], poses)
        return success[0], force[0]

    def ask(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """:meth:`level`, counting the problems it hands the solver under set size k."""
        before = self.n_problems
        out = self.level(k, poses)
        self.problems[k] += self.n_problems - before
        return out


def _study_differences(live: StudySolver, gfo: pd.DataFrame, plans: Sequence[Plan]) -> int:
    """The audit of the solver the planner runs on demand: at the poses that steered the plans
    (every level's seeds, and each plan's best pose at the full set), the rows ``live`` solves
    anew (no row of the study remembered) whose verdict differs from the study's, or whose force
    differs by more than the minima's tie tolerance (relative)."""
    bad = 0
    n = live.params.n_levels
    for k in range(1, n + 1):
        steering = [p.seeds[k - 1] for p in plans] + [np.array([p.best_pose]) for p in plans if k == n and p.best_pose >= 0]
        poses = np.unique(np.concatenate(steering)).astype(np.int64)
        if not poses.size:
            continue
        mine, force = live.level(k, poses)
        rows = gfo[gfo["set_id"] == incremental_set_id(k)].set_index("pose")
        theirs = rows.loc[live.contacts["pose"].to_numpy()[poses]]
        same = mine == theirs["success"].to_numpy(bool)
        ft = theirs["success_force"].to_numpy(float)
        close = np.where(mine & same, np.abs(force - ft) <= FORCE_TIE_RTOL * np.abs(ft), True)
        bad += int(np.sum(~(same & close)))
    return bad


def plan_object(contacts: pd.DataFrame, gfo: pd.DataFrame, matrix: NDArray, params: PlanParams) -> ObjectPlan:
    """The planner at every radius of ``params`` on one object, against the exhaustive search.

    ``gfo``: the object's gfo table (the exhaustive search); ``contacts``: its contacts table,
    one row per pose in the same pose order; ``matrix``: the synergy matrix (n_joints, K)."""
    minima = params.minima
    weights = {str(gfo["object"].iat[0]): minima.weight_N} if minima.weight_N is not None else None
    judged = with_verdicts(gfo, minima.success, weights, minima.bound_multiple)
    n = params.n_levels
    full = judged[judged["set_id"] == incremental_set_id(n)].set_index("pose").loc[contacts["pose"].to_numpy()]
    solver = StudySolver(contacts, matrix, params, study=judged)
    alpha, beta = contacts["alpha_deg"].to_numpy(float), contacts["beta_deg"].to_numpy(float)
    plans = {r: plan_incremental(alpha, beta, solver.level, n, r, minima.radius_deg, 360.0) for r in params.radii_deg}
    differing = _study_differences(StudySolver(contacts, matrix, params), judged, list(plans.values()))
    rows = []
    for r, plan in plans.items():
        versus = plan_against_exhaustive(plan, full["success"].to_numpy(bool), full["success_force"].to_numpy(float))
        best = plan.best_pose
        rows.append(
            {
                "object": str(contacts["object"].iat[0]),
                "radius_deg": r,
                "n_levels": n,
                "n_solves": plan.n_solves,
                "n_exhaustive_solves": len(contacts) * n,
                "solve_share_percent": 100.0 * plan.n_solves / (len(contacts) * n),
                "levels_from_minima": int(sum(plan.from_minima)),
                "best_pose": best,
                "best_alpha_deg": alpha[best] if best >= 0 else np.nan,
                "best_beta_deg": beta[best] if best >= 0 else np.nan,
                "best_force_N": plan.best_force_N,
                **versus,
                "regret_percent": 100.0 * (versus["regret"] - 1.0),
                "study_rows_differing": differing,
            }
        )
    enrollment = _enrollment(solver, full["success"].to_numpy(bool), judged, contacts, n)
    return ObjectPlan(pd.DataFrame(rows), enrollment, plans, full.reset_index())


def _enrollment(solver: StudySolver, full_success: NDArray, judged: pd.DataFrame, contacts: pd.DataFrame, n: int) -> pd.DataFrame:
    """Greedy order against the PCA order: successes (grid poses) of each order's first k."""
    # The sets are nested, so success only grows with a set: a set succeeds only where the full
    # set does, and every set of a greedy round (the last pick plus one synergy) succeeds
    # wherever the last pick did. Each round solves only where the last pick failed.
    where = np.flatnonzero(full_success).astype(np.int64)
    picked = np.zeros(where.size, dtype=bool)  # the last pick's successes on `where`

    def count(sets: Sequence[tuple[int, ...]]) -> NDArray[np.int64]:
        nonlocal picked
        success = np.tile(picked, (len(sets), 1))
        if (~picked).any():
            success[:, ~picked] = solver.verdicts(sets, where[~picked])[0]
        got = success.sum(axis=1)
        picked = success[int(np.argmax(got))] if len(sets) else picked  # greedy_order picks the first maximum
        return got

    target = int(where.size)
    order, greedy = greedy_order(count, n, target)
    pca = [int(judged.loc[judged["set_id"] == incremental_set_id(k), "success"].sum()) for k in range(1, n + 1)]
    pct = (lambda c: 100.0 * c / target) if target else (lambda c: np.nan)
    return pd.DataFrame(
        {
            "object": str(contacts["object"].iat[0]),
            "k": np.arange(1, n + 1),
            "greedy_added": order,
            "greedy_set": [set_id(order[:k]) for k in range(1, n + 1)],
            "greedy_n_success": greedy,
            "greedy_success_rate": [pct(c) for c in greedy],
            "pca_n_success": pca,
            "pca_success_rate": [pct(c) for c in pca],
            "full_n_success": target,
        }
    )


@dataclass(frozen=True)
class PlannersParams:
    """The ``planners`` step (docs/planner.md): the full set's size n and, per object, the
    minima's policy (radius, verdict, force bound)."""

    n_levels: int
    minima: Mapping[str, MinimaParams]

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> PlannersParams:
        """From a configuration or the step's own part of it; ``objects``: the objects whose
        minima need a force bound (``analyses.success: force_closure_bounded``), others read
        none (:func:`minima_for`)."""
        bounded = config["analyses"]["success"] == "force_closure_bounded"
        names = list(config["objects"]) if bounded else [""]
        return cls(
            int(config["synergy_sets"]["incremental_max"]), {name: MinimaParams.from_config(config, name) for name in names}
        )

    def minima_for(self, obj: str) -> MinimaParams:
        """The object's minima policy (the one shared one where no force bound is read)."""
        return self.minima[obj] if obj in self.minima else self.minima[""]


def _judged_levels(contacts: pd.DataFrame, gfo: pd.DataFrame, n: int, minima: MinimaParams) -> tuple[NDArray, NDArray]:
    """(n, p) the study's verdict and its force (N, NaN elsewhere) of {S1..Sk} (row k − 1) at
    every pose of ``contacts``, in its order."""
    weights = {str(gfo["object"].iat[0]): minima.weight_N} if minima.weight_N is not None else None
    judged = with_verdicts(gfo, minima.success, weights, minima.bound_multiple)
    order = contacts["pose"].to_numpy()
    success, force = np.zeros((n, len(order)), dtype=bool), np.full((n, len(order)), np.nan)
    for k in range(1, n + 1):
        rows = judged[judged["set_id"] == incremental_set_id(k)].set_index("pose").loc[order]
        success[k - 1] = rows["success"].to_numpy(bool)
        force[k - 1] = np.where(success[k - 1], rows["success_force"].to_numpy(float), np.nan)
    return success, force


def replay_oracle(contacts: pd.DataFrame, gfo: pd.DataFrame, n: int, minima: MinimaParams):
    """A factory of fresh :class:`ReplayOracle` on one object's study tables (the judged
    verdicts of {S1..Sk}, k = 1 … n, and the distinct grasps of its contacts)."""
    success, force = _judged_levels(contacts, gfo, n, minima)
    first = np.asarray(first_same_grasp(read_grasps(contacts.reset_index(drop=True))), dtype=np.int64)
    return lambda: ReplayOracle(success, force, first)


def compare_on_study(
    contacts: pd.DataFrame,
    gfo: pd.DataFrame,
    n: int,
    minima: MinimaParams,
    specs: Sequence[PlannerSpec] = CANDIDATES,
    **kwargs: Any,
) -> pd.DataFrame:
    """Every candidate planner replayed on one object of a study (``planners.compare_planners``'s
    rows): its contacts table (poses in order) and gfo table."""
    contacts = contacts.reset_index(drop=True)
    grid = PoseGrid.from_angles(contacts["alpha_deg"].to_numpy(float), contacts["beta_deg"].to_numpy(float))
    new = replay_oracle(contacts, gfo, n, minima)
    full = new()
    return compare_planners(
        str(contacts["object"].iat[0]), grid, new, full.success[n - 1], full.force[n - 1], n, minima.radius_deg, specs, **kwargs
    )
