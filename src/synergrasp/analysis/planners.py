"""Planners compared at equal cost (docs/planner.md, "The comparison of planners").

Does solving the cheap low-dimensional sets help find the full set's best pose? The
incremental planner (:mod:`synergrasp.analysis.planner`) and its variants are run beside
planners that solve only the full set {S1..Sn}: every pose, random sampling, multi-start
steepest descent on the pose grid, and a coarse grid (its offset drawn at random) refined by
descent. The candidates, their seeds and the rule that selects the recommended planner were
written down before any run (:data:`CANDIDATES`, :func:`recommended`).

A planner asks an *oracle* ``oracle(k, poses) -> (success, force_N)`` for {S1..Sk} at pose
indices (:data:`synergrasp.analysis.planner.LevelSolve`); the oracle keeps the cost:

- **closures**: the distinct poses asked anything (for a new object each needs the hand
  closed there);
- **problems** per set size k: the (grasp, set) problems handed to the solver, one per
  distinct grasp (twin poses share, as in the study).

:class:`ReplayOracle` answers from a study's judged gfo table (a lookup; the replay);
:class:`synergrasp.analysis.plan_study.StudySolver` and the on-demand oracle of
:mod:`synergrasp.analysis.plan_new` solve. The planners cannot tell them apart, which a test
checks (0 rows differ).

The solve time of a set of size k relative to the full set's, :data:`SOLVE_COST_BY_SET_SIZE`,
is measured by ``benchmarks/bench_set_size.py`` (``benchmarks/results/set_size.csv``).
"""

from __future__ import annotations

import functools

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.planner import plan_incremental, pose_against_exhaustive

__all__ = [
    "PoseGrid",
    "PlannerSpec",
    "CANDIDATES",
    "SEEDS",
    "REGRET_AIM_PERCENT",
    "PROBABILITY_AIM",
    "OBJECTS_AIM",
    "CLOSURE_TIE",
    "SOLVE_COST_BY_SET_SIZE",
    "Oracle",
    "ReplayOracle",
    "run_planner",
    "compare_planners",
    "across_objects",
    "recommended",
    "recommendation_line",
    "Conjecture",
    "conjecture",
]

#: The aims of the rule (docs/planner.md): a regret of at most this (%), with at least this
#: probability over the seeds, on at least this share of the objects (%); closures within this
#: relative difference are a tie.
REGRET_AIM_PERCENT, PROBABILITY_AIM, OBJECTS_AIM, CLOSURE_TIE = 5.0, 0.95, 95.0, 0.01
#: Seeds of a randomised planner (numpy.random.default_rng(seed)).
SEEDS: tuple[int, ...] = tuple(range(200))
#: Solve time of one (grasp, {S1..Sk}) problem over the full set's, k = 1 … 15 (index k − 1),
#: the grasp's mechanics included as a planner's level pays them: benchmarks/bench_set_size.py,
#: recorded in benchmarks/results/set_size.csv (a test checks they agree).
SOLVE_COST_BY_SET_SIZE: tuple[float, ...] = (
    0.432,
    0.474,
    0.457,
    0.461,
    0.477,
    0.525,
    0.562,
    0.556,
    0.656,
    0.692,
    0.735,
    0.773,
    0.877,
    0.838,
    1.000,
)


@dataclass(frozen=True)
class PoseGrid:
    """The study's (α, β) grid as cells: ``alpha_deg``, ``beta_deg`` (p,) per pose (deg);
    ``cell`` (p, 2) its α and β cell; ``index`` (n_α, n_β) the pose at a cell (−1: none).
    α wraps (the grid covers a full turn), β does not."""

    alpha_deg: NDArray[np.float64]
    beta_deg: NDArray[np.float64]
    cell: NDArray[np.int64]
    index: NDArray[np.int64]

    @classmethod
    def from_angles(cls, alpha_deg: Sequence[float] | NDArray, beta_deg: Sequence[float] | NDArray) -> PoseGrid:
        a, b = np.asarray(alpha_deg, dtype=float), np.asarray(beta_deg, dtype=float)
        ua, ia = np.unique(np.round(a, 6), return_inverse=True)
        ub, ib = np.unique(np.round(b, 6), return_inverse=True)
        index = np.full((ua.size, ub.size), -1, dtype=np.int64)
        index[ia, ib] = np.arange(a.size)
        return cls(a, b, np.stack([ia, ib], axis=1).astype(np.int64), index)

    @property
    def n_poses(self) -> int:
        return int(self.alpha_deg.size)

    def neighbours(self, pose: int) -> NDArray[np.int64]:
        """The up to 8 grid neighbours of a pose (α wrapping, β bounded), increasing; read-only
        (every pose's are listed once per grid: the planners ask them many thousand times)."""
        return self._neighbour_lists[pose]

    @functools.cached_property
    def _neighbour_lists(self) -> tuple[NDArray[np.int64], ...]:
        na, nb = self.index.shape
        lists = []
        for pose, (ia, ib) in enumerate(self.cell.tolist()):
            out = [
                self.index[(ia + da) % na, ib + db] for da in (-1, 0, 1) for db in (-1, 0, 1) if (da or db) and 0 <= ib + db < nb
            ]
            near = np.array(sorted({int(v) for v in out if v >= 0 and v != pose}), dtype=np.int64)
            near.flags.writeable = False
            lists.append(near)
        return tuple(lists)

    def coarse(self, step: int, offset: tuple[int, int]) -> NDArray[np.int64]:
        """Every ``step``-th pose in α and in β from the cell ``offset``."""
        keep = (self.cell[:, 0] % step == offset[0]) & (self.cell[:, 1] % step == offset[1])
        return np.flatnonzero(keep).astype(np.int64)


@dataclass(frozen=True)
class PlannerSpec:
    """One candidate planner (docs/planner.md). ``kind``: exhaustive | random | descent |
    coarse | incremental; ``size``: N poses (random), S starts (descent), the coarse step s
    (cells); ``radius_deg``, ``max_seeds`` (None: every minimum) and ``levels``: every |
    doubling | straight, for the incremental kind."""

    name: str
    kind: str
    size: int = 0
    radius_deg: float = 0.0
    max_seeds: int | None = None
    levels: str = "every"

    @property
    def family(self) -> str:
        """``incremental`` (solves reduced sets) or ``full_set`` (solves only the full set)."""
        return "incremental" if self.kind == "incremental" else "full_set"

    @property
    def randomised(self) -> bool:
        return self.kind in ("random", "descent", "coarse")

    def set_sizes(self, n: int) -> list[int]:
        """The set sizes k an incremental planner solves, ending at n."""
        if self.levels == "straight":
            return [1, n] if n > 1 else [1]
        if self.levels == "doubling":
            return sorted({min(2**i, n) for i in range(n.bit_length() + 1)} | {n})
        return list(range(1, n + 1))


def _candidates() -> tuple[PlannerSpec, ...]:
    out = [PlannerSpec("exhaustive", "exhaustive")]
    out += [PlannerSpec(f"random_{n}", "random", n) for n in (100, 200, 400, 800, 1200)]
    out += [PlannerSpec(f"descent_{s}", "descent", s) for s in (5, 10, 20, 40)]
    out += [PlannerSpec(f"coarse_{s}", "coarse", s) for s in (2, 3, 4)]
    out += [PlannerSpec(f"incremental_r{r}", "incremental", radius_deg=r) for r in (10, 20, 30)]
    out += [PlannerSpec(f"incremental_m{m}_r{r}", "incremental", radius_deg=r, max_seeds=m) for m in (1, 3) for r in (20, 45)]
    out += [PlannerSpec(f"skip_r{r}", "incremental", radius_deg=r, levels="doubling") for r in (20, 45)]
    out += [
        PlannerSpec(f"straight_m{m or 'all'}_r{r}", "incremental", radius_deg=r, max_seeds=m, levels="straight")
        for m in (1, 3, None)
        for r in (20, 45)
    ]
    return tuple(out)


#: The pre-registered candidates (docs/planner.md).
CANDIDATES: tuple[PlannerSpec, ...] = _candidates()


class Oracle:
    """The cost ledger every oracle keeps: ``closed`` (p,) poses asked anything; ``problems``
    per set size k, the distinct grasps solved with {S1..Sk}. A subclass answers ``ask``."""

    def __init__(self, n_poses: int, n_levels: int) -> None:
        self.closed = np.zeros(n_poses, dtype=bool)
        self.problems = np.zeros(n_levels + 1, dtype=np.int64)

    def __call__(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
        poses = np.asarray(poses, dtype=np.int64)
        self.closed[poses] = True
        return self.ask(k, poses)

    def ask(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
        raise NotImplementedError

    @property
    def closures(self) -> int:
        return int(self.closed.sum())

    def solve_cost(self, costs: Sequence[float] = SOLVE_COST_BY_SET_SIZE) -> float:
        """Problems weighted by their set size's solve time, in full-set solves."""
        n = self.problems.size - 1
        scale = costs[n - 1] if n <= len(costs) else 1.0
        return float(sum(self.problems[k] * (costs[k - 1] if k <= len(costs) else 1.0) for k in range(1, n + 1)) / scale)


class ReplayOracle(Oracle):
    """Answers from a study's tables: ``success``, ``force_N`` (n, p) the judged verdict and its
    force of {S1..Sk} (row k − 1) at every pose; ``grasp`` (p,) the first pose of the same
    grasp (−1: no grasp, nothing to solve), as ``mechanics.first_same_grasp`` gives it."""

    def __init__(self, success: NDArray[np.bool_], force_N: NDArray[np.float64], grasp: NDArray[np.int64]) -> None:
        super().__init__(success.shape[1], success.shape[0])
        self.success, self.force, self.grasp = success, force_N, np.asarray(grasp, dtype=np.int64)
        self.solved = np.zeros(success.shape, dtype=bool)  # per k, the grasps solved (by first pose)

    def ask(self, k: int, poses: NDArray[np.int64]) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
        reps = self.grasp[poses]
        reps = np.unique(reps[reps >= 0])
        fresh = reps[~self.solved[k - 1, reps]]
        self.solved[k - 1, fresh] = True
        self.problems[k] += fresh.size
        ok = self.success[k - 1, poses]
        return ok, np.where(ok, self.force[k - 1, poses], np.nan)


def _descent(
    grid: PoseGrid, known: dict[int, float], ask: Callable[[NDArray[np.int64]], None], starts: NDArray[np.int64]
) -> None:
    """Steepest descent over the 8 neighbours from every start, walkers in lockstep; a pose
    without success is +inf; a walker stops where no neighbour is lower."""
    ask(starts)
    walkers = np.unique(starts)
    while walkers.size:
        near = {int(w): grid.neighbours(int(w)) for w in walkers}
        ask(np.unique(np.concatenate(list(near.values()))) if near else np.zeros(0, dtype=np.int64))
        moved = []
        for w, nb in near.items():
            if nb.size:
                forces = np.array([known[int(v)] for v in nb])
                j = int(np.argmin(forces))  # the first least: the lower pose index on a tie
                if forces[j] < known[w]:
                    moved.append(int(nb[j]))
        walkers = np.unique(np.array(moved, dtype=np.int64))


def run_planner(
    spec: PlannerSpec,
    grid: PoseGrid,
    oracle: Oracle,
    n_levels: int,
    minima_radius_deg: float,
    rng: np.random.Generator | None = None,
) -> tuple[int, float]:
    """Run one planner; returns its pose (−1: none succeeds) and that pose's full-set force (N):
    the least among the poses where it solved the full set. ``rng`` for a randomised planner."""
    p = grid.n_poses
    if spec.kind == "incremental":
        plan = plan_incremental(
            grid.alpha_deg,
            grid.beta_deg,
            oracle,
            n_levels,
            spec.radius_deg,
            minima_radius_deg,
            360.0,
            levels=spec.set_sizes(n_levels),
            max_seeds=spec.max_seeds,
        )
        return plan.best_pose, plan.best_force_N
    known: dict[int, float] = {}

    def ask(poses: NDArray[np.int64]) -> None:
        new = np.array(sorted({int(v) for v in poses} - known.keys()), dtype=np.int64)
        if new.size:
            ok, force = oracle(n_levels, new)
            known.update(zip(new.tolist(), np.where(ok, force, np.inf).tolist()))

    if spec.kind == "exhaustive":
        ask(np.arange(p, dtype=np.int64))
    elif rng is None:
        raise ValueError(f"planner {spec.name}: a randomised planner needs a random generator")
    elif spec.kind == "random":
        ask(np.sort(rng.choice(p, size=min(spec.size, p), replace=False)).astype(np.int64))
    elif spec.kind == "descent":
        _descent(grid, known, ask, np.sort(rng.choice(p, size=min(spec.size, p), replace=False)).astype(np.int64))
    elif spec.kind == "coarse":
        offset = (int(rng.integers(0, spec.size)), int(rng.integers(0, spec.size)))
        coarse = grid.coarse(spec.size, offset)
        ask(coarse)
        forces = np.array([known[int(v)] for v in coarse])
        best = coarse[np.argsort(forces, kind="stable")[:3]]
        _descent(grid, known, ask, best[np.isfinite(np.sort(forces)[:3])])
    else:
        raise ValueError(f"planner {spec.name}: unknown kind {spec.kind!r}")
    poses = np.array(sorted(known), dtype=np.int64)
    forces = np.array([known[int(v)] for v in poses])
    if not np.isfinite(forces).any():
        return -1, float("nan")
    j = int(np.argmin(forces))
    return int(poses[j]), float(forces[j])


def compare_planners(
    obj: str,
    grid: PoseGrid,
    new_oracle: Callable[[], Oracle],
    full_success: NDArray[np.bool_],
    full_force_N: NDArray[np.float64],
    n_levels: int,
    minima_radius_deg: float,
    specs: Sequence[PlannerSpec] = CANDIDATES,
    seeds: Sequence[int] = SEEDS,
    costs: Sequence[float] = SOLVE_COST_BY_SET_SIZE,
) -> pd.DataFrame:
    """Every planner on one object against the exhaustive search (one row per planner;
    columns of ``table_contracts.PLANNERS`` but the across-objects ones). ``new_oracle()`` gives a
    fresh oracle (empty ledger) per run; a randomised planner runs once per seed."""
    rows = []
    for spec in specs:
        runs = []
        for seed in seeds if spec.randomised else (None,):
            oracle = new_oracle()
            rng = np.random.default_rng(seed) if seed is not None else None
            pose, force = run_planner(spec, grid, oracle, n_levels, minima_radius_deg, rng)
            versus = pose_against_exhaustive(pose, force, full_success, full_force_N)
            runs.append(
                (
                    oracle.closures,
                    oracle.solve_cost(costs),
                    int(oracle.problems.sum()),
                    100.0 * (versus["regret"] - 1.0),
                    bool(versus["is_global_min"]),
                )
            )
        closures, cost, problems, regret, exact = (np.array(v, dtype=float) for v in zip(*runs))
        within = np.where(np.isfinite(regret), regret <= REGRET_AIM_PERCENT, False)
        rows.append(
            {
                "object": obj,
                "planner": spec.name,
                "family": spec.family,
                "randomised": spec.randomised,
                "runs": len(runs),
                "closures": float(closures.mean()),
                "closure_share_percent": 100.0 * float(closures.mean()) / grid.n_poses,
                "solve_cost": float(cost.mean()),
                "problems": float(problems.mean()),
                "regret_percent_mean": float(np.nanmean(regret)) if np.isfinite(regret).any() else np.nan,
                "regret_percent_max": float(np.nanmax(regret)) if np.isfinite(regret).any() else np.nan,
                "global_min_probability": float(exact.mean()),
                "within_aim_probability": float(within.mean()),
                "meets_aim": bool(within.mean() >= PROBABILITY_AIM),
            }
        )
    return pd.DataFrame(rows)


#: The columns :func:`across_objects` computes (``table_contracts.PLANNERS_ACROSS`` adds ``recommended``).
ACROSS_COLUMNS = (
    "planner",
    "family",
    "randomised",
    "objects",
    "objects_meeting_aim",
    "meeting_aim_percent",
    "closures",
    "closure_share_percent",
    "solve_cost",
    "regret_percent_mean",
    "regret_percent_max",
    "within_aim_probability",
)


def across_objects(per_object: pd.DataFrame) -> pd.DataFrame:
    """Per planner over the objects (rows of objects whose full set succeeds somewhere:
    ``regret_percent_mean`` defined): objects, those where it meets the aim and their share (%),
    mean closures and solve time; ``recommended``: the one :func:`recommended` selects."""
    judged = per_object[per_object["regret_percent_mean"].notna()]
    rows = []
    for name, part in judged.groupby("planner", sort=False):
        rows.append(
            {
                "planner": name,
                "family": part["family"].iat[0],
                "randomised": bool(part["randomised"].iat[0]),
                "objects": len(part),
                "objects_meeting_aim": int(part["meets_aim"].sum()),
                "meeting_aim_percent": 100.0 * float(part["meets_aim"].mean()),
                "closures": float(part["closures"].mean()),
                "closure_share_percent": float(part["closure_share_percent"].mean()),
                "solve_cost": float(part["solve_cost"].mean()),
                "regret_percent_mean": float(part["regret_percent_mean"].mean()),
                "regret_percent_max": float(part["regret_percent_max"].max()),
                "within_aim_probability": float(part["within_aim_probability"].min()),
            }
        )
    table = pd.DataFrame(rows, columns=ACROSS_COLUMNS)
    # no object whose full set succeeds anywhere: an empty table of the same columns
    table["recommended"] = (table["planner"] == recommended(table)) if len(table) else pd.Series(dtype=bool)
    return table


def recommended(table: pd.DataFrame, family: str | None = None, cost: str = "closures") -> str:
    """The rule written before the comparison ran (docs/planner.md): among the planners (of
    ``family``, None: all) meeting the aim on at least ``OBJECTS_AIM`` % of the objects, the
    one of least ``cost`` (mean over objects; ``closures``: within ``CLOSURE_TIE`` relative a
    tie, broken by the solve time; ``solve_cost``: the solve time alone), then by name.
    Returns "" when none meets the aim."""
    pool = table[(table["meeting_aim_percent"] >= OBJECTS_AIM) & (table["family"] == family if family else True)]
    if not len(pool):
        return ""
    if cost == "closures":
        least = float(pool["closures"].min())
        pool = pool[pool["closures"] <= least * (1.0 + CLOSURE_TIE)]
        cost = "solve_cost"
    return str(pool.sort_values([cost, "planner"], kind="stable")["planner"].iat[0])


@dataclass(frozen=True)
class Conjecture:
    """Claim 8 measured: the incremental and the full-set planners chosen by their solve time
    (``""``: none meets the aim), per object the difference 100 (C_full − C_inc) / C_full (%),
    its mean and 95 % percentile interval over objects, and the closures of both (mean)."""

    incremental: str
    full_set: str
    differences: NDArray[np.float64]
    mean: float
    low: float
    high: float
    closures_incremental: float
    closures_full_set: float


def conjecture(per_object: pd.DataFrame, resamples: int = 1000, seed: int = 2018) -> Conjecture:
    """Claim 8 from the per-object comparison (docs/planner.md): in each family the planner that
    meets the aim on ≥ ``OBJECTS_AIM`` % of the objects with the least solve time; per object
    the relative difference of their solve times; a percentile bootstrap over objects."""
    table = across_objects(per_object)
    if not len(table):
        return Conjecture("", "", np.zeros(0), np.nan, np.nan, np.nan, np.nan, np.nan)
    inc, full = recommended(table, "incremental", "solve_cost"), recommended(table, "full_set", "solve_cost")
    closures = table.set_index("planner")["closures"]
    if not inc or not full:
        return Conjecture(
            inc, full, np.zeros(0), np.nan, np.nan, np.nan, float(closures.get(inc, np.nan)), float(closures.get(full, np.nan))
        )
    judged = per_object[per_object["regret_percent_mean"].notna()]
    cost = judged.pivot(index="object", columns="planner", values="solve_cost")
    d = (100.0 * (cost[full] - cost[inc]) / cost[full]).to_numpy(float)
    rng = np.random.default_rng(seed)
    means = d[rng.integers(0, d.size, size=(resamples, d.size))].mean(axis=1)
    low, high = np.percentile(means, [2.5, 97.5])
    return Conjecture(inc, full, d, float(d.mean()), float(low), float(high), float(closures[inc]), float(closures[full]))


def recommendation_line(across: pd.DataFrame) -> str:
    """The rule's choice in one line; a WARNING when only the exhaustive search meets the aim."""
    chosen = across.loc[across["recommended"], "planner"] if "recommended" in across else pd.Series(dtype=str)
    if not len(chosen):
        return "WARNING: planners: no object has a force-closure pose of the full set; no planner recommended"
    row = across.set_index("planner").loc[chosen.iat[0]]
    line = (
        f"planners: recommended {chosen.iat[0]} ({row['closures']:.0f} closures, {row['solve_cost']:.0f} full-set "
        f"solves on average; meets the aim on {row['objects_meeting_aim']} of {row['objects']} objects)"
    )
    return ("WARNING: only the exhaustive search meets the aim; " + line) if chosen.iat[0] == "exhaustive" else line
