"""The incremental planner: a hand-made force map whose minima and best pose are known, the
greedy enrollment order on hand-made success sets, and the study's solver on random grasps
against the exhaustive gfo table."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import study_gfo_params
from grasp_problems import random_grasp, random_synergies
from synergrasp.analysis.minima import MinimaParams
from synergrasp.analysis.plan_study import PlanParams, StudySolver, plan_object
from synergrasp.analysis.planner import greedy_order, plan_against_exhaustive, plan_incremental
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.ids import incremental_set_id
from synergrasp.optimisation.optimise import gfo_table
from synergrasp.optimisation.problem import SynergySets

# a 12 x 5 grid, 30 deg steps: alpha -180..150 (wraps), beta -60..60
ALPHA, BETA = (a.ravel() for a in np.meshgrid(np.arange(-180.0, 180.0, 30.0), np.arange(-60.0, 61.0, 30.0), indexing="ij"))
#: level k: two cones, A at (0, 0) of apex 1 and B_k of apex 0.5, 0.4, 0.3 drifting one cell a level
WELLS = {1: (90.0, 30.0, 0.5), 2: (120.0, 30.0, 0.4), 3: (150.0, 60.0, 0.3)}


def _cells(a0: float, b0: float) -> np.ndarray:
    """L1 distance in grid cells to (a0, b0), alpha wrapping."""
    da = np.abs(ALPHA - a0) % 360.0
    return np.minimum(da, 360.0 - da) / 30.0 + np.abs(BETA - b0) / 30.0


def _force(k: int) -> np.ndarray:
    a, b, apex = WELLS[k]
    return np.minimum(1.0 + _cells(0.0, 0.0), apex + _cells(a, b))


class MapSolver:
    """The hand-made map as the planner's solve, remembering what it was asked."""

    def __init__(self, success=None):
        self.asked: list[np.ndarray] = []
        self.success = success

    def __call__(self, k, poses):
        self.asked.append(np.asarray(poses))
        ok = np.ones(poses.size, bool) if self.success is None else self.success(k)[poses]
        return ok, np.where(ok, _force(k)[poses], np.nan)


def _pose(alpha: float, beta: float) -> int:
    return int(np.flatnonzero((ALPHA == alpha) & (BETA == beta))[0])


def test_planner_follows_the_drifting_minimum_to_the_global_one():
    solve = MapSolver()
    plan = plan_incremental(ALPHA, BETA, solve, 3, radius_deg=30, minima_radius_deg=30)
    # level 1: the whole grid; its minima are the two apexes; each seeds a 3 x 3 square
    assert [s.size for s in plan.solved] == [60, 18, 18] and plan.n_solves == 96
    assert sorted(plan.seeds[0].tolist()) == sorted([_pose(0, 0), _pose(90, 30)])
    assert sorted(plan.seeds[1].tolist()) == sorted([_pose(0, 0), _pose(120, 30)])
    assert plan.from_minima == (True, True, True)
    assert plan.best_pose == _pose(150, 60) and plan.best_force_N == pytest.approx(0.3)
    versus = plan_against_exhaustive(plan, np.ones(60, bool), _force(3))
    assert versus["is_global_min"] and versus["rank"] == 1 and versus["regret"] == pytest.approx(1.0)
    assert versus["exhaustive_best_pose"] == _pose(150, 60)


def test_a_radius_too_small_loses_the_minimum_and_the_regret_says_so():
    plan = plan_incremental(ALPHA, BETA, MapSolver(), 3, radius_deg=0, minima_radius_deg=30)
    # seeds only: level 2 solves the two apexes; of the two, only A (1.0) is below their median
    assert [s.size for s in plan.solved] == [60, 2, 1]
    assert plan.best_pose == _pose(0, 0) and plan.best_force_N == pytest.approx(1.0)
    f3 = _force(3)
    versus = plan_against_exhaustive(plan, np.ones(60, bool), f3)
    assert not versus["is_global_min"]
    assert versus["rank"] == 1 + int(np.sum(f3 < 1.0 - 1e-9)) and versus["regret"] == pytest.approx(1.0 / 0.3)


def test_a_level_without_success_hands_the_whole_grid_to_the_next():
    # {S1} succeeds nowhere, {S1,S2} everywhere
    solve = MapSolver(success=lambda k: np.full(60, k > 1))
    plan = plan_incremental(ALPHA, BETA, solve, 3, radius_deg=30, minima_radius_deg=30)
    assert [s.size for s in plan.solved] == [60, 60, 18]
    assert plan.seeds[0].size == 0 and plan.from_minima == (False, True, True)
    assert plan.best_pose == _pose(150, 60)


def test_no_success_with_the_full_set_gives_no_pose():
    plan = plan_incremental(ALPHA, BETA, MapSolver(success=lambda k: np.zeros(60, bool)), 2, radius_deg=30)
    assert plan.best_pose == -1 and np.isnan(plan.best_force_N) and plan.n_solves == 120
    versus = plan_against_exhaustive(plan, np.zeros(60, bool), np.full(60, np.nan))
    assert versus["rank"] == 0 and not versus["is_global_min"]


def test_greedy_order_adds_the_synergy_that_adds_most_successes():
    # each synergy makes a fixed set of poses succeed; a set succeeds on the union
    covers = {1: {0, 1, 2}, 2: {0, 1}, 3: {3, 4, 5, 6}, 4: {7}, 5: {2, 7, 8}}
    target = len(set().union(*covers.values()))  # 9

    def count(sets):
        return np.array([len(set().union(*(covers[s] for s in st))) for st in sets])

    order, counts = greedy_order(count, 5, target)
    # S3 (4 poses); then S1 and S5 add 3 each (tie: S1); then S5 adds 7, 8; done at 9
    assert order[:3] == (3, 1, 5) and counts[:3].tolist() == [4, 7, 9]
    assert order[3:] == (2, 4) and counts[3:].tolist() == [9, 9]


def _random_study(seed: int = 38):
    """Twelve random grasps (one pose empty) on a 4 x 3 grid, its gfo table of the incremental
    sets {S1..Sk}, k = 1 … 4, and the plan step's parameters."""
    rng = np.random.default_rng(seed)
    grasps = [random_grasp(rng, int(rng.integers(4, 10))) for _ in range(12)]
    grasps[5] = None
    from test_optimise import _contacts_of

    contacts = _contacts_of(grasps)
    contacts["alpha_deg"] = np.repeat(np.arange(-180.0, 180.0, 90.0), 3)  # 4 x 3 grid
    contacts["beta_deg"] = np.tile([-10.0, 0.0, 10.0], 4)
    matrix = random_synergies(rng)
    n = 4
    gfo_params = study_gfo_params(gravity_direction=(0.0, 0.0, -1.0))
    sets = tuple(tuple(range(1, k + 1)) for k in range(1, n + 1))
    gfo = gfo_table(contacts, SynergySets(matrix, sets), gfo_params)
    params = PlanParams((10.0, 200.0), n, None, gfo_params, MinimaParams(10.0, "load_feasible"))
    return contacts, gfo, matrix, params


def test_the_planner_on_the_study_solver_reproduces_the_gfo_table():
    contacts, gfo, matrix, params = _random_study()
    n = params.n_levels
    result = plan_object(contacts, gfo, matrix, params)
    plan, enrollment = result.table, result.enrollment
    assert (plan["study_rows_differing"] == 0).all()
    # a radius spanning the grid solves every pose at every level: the exhaustive search
    wide = plan.set_index("radius_deg").loc[200.0]
    assert wide["n_solves"] == 12 * n and wide["solve_share_percent"] == 100.0
    full = gfo[gfo["set_id"] == incremental_set_id(n)]
    ok = full["load_feasible"].to_numpy()
    assert ok.any(), "the random grasps should give some load-feasible pose"
    assert wide["is_global_min"] and wide["best_force_N"] == pytest.approx(full["force_norm"][ok].min(), rel=1e-5)
    assert enrollment["k"].tolist() == list(range(1, n + 1))
    assert enrollment["pca_n_success"].tolist() == [
        int(gfo[gfo["set_id"] == incremental_set_id(k)]["load_feasible"].sum()) for k in range(1, n + 1)
    ]
    assert enrollment["greedy_n_success"].iloc[-1] == enrollment["full_n_success"].iloc[0] == ok.sum()
    assert enrollment["greedy_n_success"].iloc[0] >= enrollment["pca_n_success"].iloc[0]
    assert sorted(enrollment["greedy_added"]) == list(range(1, n + 1))


def test_synergrasp_plan_reads_the_study_s_tables_and_prints_one_line_per_radius(tmp_path, capsys):
    import yaml

    from synergrasp import table_contracts
    from synergrasp.cli import main
    from synergrasp.hand.synergies import load_synergies
    from test_optimise import _contacts_of

    rng = np.random.default_rng(7)
    contacts = _contacts_of([random_grasp(rng, int(rng.integers(4, 10))) for _ in range(6)])
    contacts["alpha_deg"], contacts["beta_deg"] = np.repeat([-180.0, 0.0], 3), np.tile([-10.0, 0.0, 10.0], 2)
    gfo = gfo_table(
        contacts,
        SynergySets(load_synergies(None).matrix, tuple(tuple(range(1, k + 1)) for k in range(1, 16))),
        study_gfo_params(),
    )
    folder = tmp_path / "objects" / "box"
    folder.mkdir(parents=True)
    filler = {"string": "kinematic", "int32": 0, "float64": 0.0, "bool": True}
    for column in table_contracts.CONTACTS.columns:  # what the closure writes and the planner does not read
        if column.name not in contacts:
            contacts[column.name] = (
                [[] for _ in range(len(contacts))] if column.dtype.startswith("list") else filler[column.dtype]
            )
    table_contracts.write(table_contracts.CONTACTS, contacts, folder / "contacts.parquet")
    table_contracts.write(table_contracts.GFO, gfo, folder / "gfo.parquet")
    overlay = tmp_path / "box.yaml"
    overlay.write_text(
        yaml.safe_dump(
            {
                "objects": {"box": {"shape": {"box": {"size_mm": [30, 30, 30]}}, "mass_kg": 1.0}},
                "analyses": {"success": "load_feasible"},
            }
        )
    )
    assert (
        main(
            [
                "plan",
                "box",
                "--radius",
                "10",
                "400",
                "--configfile",
                str(overlay),
                "--results",
                str(tmp_path),
                "--csv",
                str(tmp_path / "plan.csv"),
            ]
        )
        == 0
    )
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and lines[1].startswith("box radius 400 deg: 90 of 90 solves (100.0 %)")
    plan = table_contracts.read_csv(table_contracts.PLAN, tmp_path / "plan.csv")
    assert plan["study_rows_differing"].tolist() == [0, 0] and bool(plan["is_global_min"].iloc[1])
    assert main(["plan", "nothing", "--results", str(tmp_path)]) == 2
    assert "synergrasp plan: object: 'nothing' is not an object of the configuration" in capsys.readouterr().err


def test_the_study_s_remembered_rows_steer_the_planner_as_solving_them_anew_does():
    contacts, gfo, matrix, params = _random_study()
    judged = with_verdicts(gfo, params.minima.success)
    alpha, beta = contacts["alpha_deg"].to_numpy(float), contacts["beta_deg"].to_numpy(float)
    solvers = StudySolver(contacts, matrix, params), StudySolver(contacts, matrix, params, study=judged)
    assert len(solvers[1].memo) == 11 * params.n_levels  # every non-empty pose, every set of the table
    live, remembered = (plan_incremental(alpha, beta, s.level, params.n_levels, 10.0) for s in solvers)
    assert solvers[0].n_problems > 0 and solvers[1].n_problems == 0  # nothing handed to the solver again
    assert [s.tolist() for s in live.solved] == [s.tolist() for s in remembered.solved]
    assert [s.tolist() for s in live.seeds] == [s.tolist() for s in remembered.seeds]
    assert live.best_pose == remembered.best_pose >= 0
    assert remembered.best_force_N == pytest.approx(live.best_force_N, rel=1e-12)


def test_the_audit_counts_rows_where_the_study_s_table_disagrees_with_the_solver():
    contacts, gfo, matrix, params = _random_study()
    plan = plan_object(contacts, gfo, matrix, params).table
    best = int(plan["best_pose"].iloc[0])
    assert best >= 0 and (plan["study_rows_differing"] == 0).all()
    # the study's table made wrong at the plans' best pose, full set: the audit solves that row anew
    wrong = gfo.copy()
    at = (wrong["pose"] == contacts["pose"].iat[best]) & (wrong["set_id"] == incremental_set_id(params.n_levels))
    wrong.loc[at, "force_norm"] *= 1.01
    assert (plan_object(contacts, wrong, matrix, params).table["study_rows_differing"] >= 1).all()
