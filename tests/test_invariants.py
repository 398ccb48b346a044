"""The pipeline's invariant checks on hand-made results."""

import pandas as pd
import pytest

from synergrasp.analysis.invariants import InvariantError, check_success_rates, superset_inconsistencies


def test_superset_inconsistencies_name_object_and_sets():
    rows = []
    for pose, ok in enumerate([(True, True, True), (True, False, True), (False, False, True), (True, True, False)]):
        for sid, success in zip(("1", "1-2", "1-2-3"), ok):
            rows.append({"object": "box", "pose": pose, "set_id": sid, "success": success})
    bad = superset_inconsistencies(pd.DataFrame(rows))
    got = {(r.set_id, r.superset_id): r.n_poses for r in bad.itertuples()}
    # pose 1: {1} yes, {1,2} no; pose 3: {1} and {1,2} yes, {1,2,3} no
    assert got == {("1", "1-2"): 1, ("1", "1-2-3"): 1, ("1-2", "1-2-3"): 1}
    assert set(bad["object"]) == {"box"}


def test_success_rates_above_100_warn_within_and_stop_beyond_the_tolerance():
    rates = pd.DataFrame({"object": ["a", "a", "b"], "set_id": ["1", "2", "1"], "success_rate": [100.0, 100.4, 50.0]})
    messages = check_success_rates(rates, 1.0)
    assert len(messages) == 1 and "a {2}" in messages[0]
    with pytest.raises(InvariantError, match=r"a \{2\}: 100.4 %"):
        check_success_rates(rates, 0.1)


def test_force_beyond_the_solver_is_explained_not_warned():
    """Pose 0: force closure of {1} without a force, its superset needing 500 N (> 10 x 9.81 N):
    explained. Pose 1: the superset needs 50 N, so the missing force is unexplained: a warning."""
    import numpy as np

    from synergrasp.analysis.invariants import InvariantWarning, invariant_checks
    from synergrasp.analysis.summaries import success_rates
    from synergrasp.analysis.verdicts import with_verdicts

    gfo = pd.DataFrame(
        {
            "object": ["a"] * 4,
            "pose": [0, 0, 1, 1],
            "alpha_deg": [0.0, 0.0, 5.0, 5.0],
            "beta_deg": [0.0] * 4,
            "set_id": ["1", "1-2", "1", "1-2"],
            "n_synergies": [1, 2, 1, 2],
            "status": ["infeasible", "feasible"] * 2,
            "load_feasible": [False, True] * 2,
            "force_closure_def1": [True] * 4,
            "rank_G": [6] * 4,
            "force_norm": [np.nan, 500.0, np.nan, 50.0],
        }
    )
    table = with_verdicts(gfo, "force_closure", {"a": 9.81}, 10.0)
    with pytest.warns(InvariantWarning) as caught:
        checks = invariant_checks(table, success_rates(table, "1-2"), {}, 1.0).set_index("check")
    assert checks.loc["force_beyond_solver", "count"] == 1 and "500 N" in checks.loc["force_beyond_solver", "detail"]
    assert checks.loc["force_closure_has_optimal_force", "count"] == 1
    assert [str(w.message) for w in caught if "force_beyond_solver" in str(w.message)] == []
