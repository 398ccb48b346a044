"""Study summaries on hand-made gfo tables: success rates under both verdicts, distinct
poses, paired forces, Table II, hierarchy matrices, minimum preservation, cross-checks."""

import numpy as np
import pandas as pd
import pytest

from conftest import study_analysis_settings
from synergrasp.analysis.invariants import InvariantError
from synergrasp.analysis.study_tables import frames_by_object, study_tables
from synergrasp.analysis.summaries import (
    full_but_not_first_n,
    hierarchy_matrices,
    incrementality_table,
    mean_over_objects,
    minimum_preservation,
    success_rates,
    verdict_disagreements,
)
from synergrasp.analysis.verdicts import with_verdicts

FULL = "1-2-3"


def gfo_rows(
    obj: str, set_id: str, forces: list[float | None], strict: list[bool] | None = None, step_deg: float = 5.0
) -> list[dict]:
    """One row per pose (α = step·pose, β = 0); None = the optimisation is infeasible.
    ``strict`` (default: wherever feasible) is the strict internal-force test."""
    strict = strict if strict is not None else [f is not None for f in forces]
    return [
        dict(
            object=obj,
            pose=p,
            alpha_deg=step_deg * p,
            beta_deg=0.0,
            set_id=set_id,
            n_synergies=len(set_id.split("-")),
            status="feasible" if f is not None else "infeasible",
            load_feasible=f is not None,
            force_closure_def1=s,
            rank_G=6,
            force_norm=np.nan if f is None else f,
        )
        for p, (f, s) in enumerate(zip(forces, strict))
    ]


@pytest.fixture
def gfo() -> pd.DataFrame:
    rows = (
        gfo_rows("a", "1", [1.0, None, None, None])
        + gfo_rows("a", "1-2", [2.0, 4.0, None, None])
        + gfo_rows("a", FULL, [1.0, 2.0, 3.0, 10.0])
        + gfo_rows("b", "1", [None, None, None, None])
        + gfo_rows("b", "1-2", [5.0, None, None, None])
        + gfo_rows("b", FULL, [None, None, None, None])
    )
    return pd.DataFrame(rows)


def test_success_rates_by_hand(gfo):
    r = success_rates(with_verdicts(gfo, "force_closure"), FULL).set_index(["object", "set_id"])
    assert r.loc[("a", "1-2"), "n_success"] == 2
    assert r.loc[("a", "1-2"), "success_rate"] == pytest.approx(50.0)  # 2 of the full set's 4
    assert r.loc[("a", "1"), "success_rate"] == pytest.approx(25.0)
    assert r.loc[("a", FULL), "success_rate"] == pytest.approx(100.0)
    assert r.loc[("a", "1-2"), "absolute_share"] == pytest.approx(50.0)
    assert r.loc[("a", FULL), "plain_mean_force_N"] == pytest.approx(4.0)
    assert r.loc[("a", FULL), "plain_median_force_N"] == pytest.approx(2.5)
    # paired: set 1-2 at poses 0, 1: 2/1 and 4/2 -> median 2; the full set against itself: 1
    assert r.loc[("a", "1-2"), "force_ratio_median"] == pytest.approx(2.0)
    assert r.loc[("a", FULL), "force_ratio_median"] == pytest.approx(1.0)
    # b: the full set never succeeds -> undefined rate, flagged; absolute share still defined
    assert np.isnan(r.loc[("b", "1-2"), "success_rate"]) and r.loc[("b", "1-2"), "full_set_empty"]
    assert r.loc[("b", "1-2"), "absolute_share"] == pytest.approx(25.0)
    assert r.loc[("b", "1-2"), "n_ratio_undefined"] == 1  # a success where the full set has no force
    assert not r.loc[("a", "1"), "full_set_empty"]
    assert np.isnan(r.loc[("b", "1"), "plain_mean_force_N"])
    assert list(r.reset_index()["set_id"][:3]) == ["1", "1-2", FULL]


def test_success_rates_under_both_verdicts():
    """Set 1 is feasible under the weight at poses 0-3 but strictly prehensile only at 0."""
    rows = gfo_rows("a", "1", [1.0, 2.0, 3.0, 4.0], strict=[True, False, False, False]) + gfo_rows(
        "a", "1-2", [1.0, 1.0, 1.0, 1.0]
    )
    table = pd.DataFrame(rows)
    fc = success_rates(with_verdicts(table, "force_closure"), "1-2").set_index("set_id")
    lf = success_rates(with_verdicts(table, "load_feasible"), "1-2").set_index("set_id")
    assert fc.loc["1", "success_rate"] == pytest.approx(25.0) and lf.loc["1", "success_rate"] == pytest.approx(100.0)
    for r in (fc, lf):
        assert r.loc["1", "success_rate_force_closure"] == pytest.approx(25.0)
        assert r.loc["1", "success_rate_load_feasible"] == pytest.approx(100.0)


def test_distinct_poses_count_one_period():
    """Eight poses 0..315 deg step 45 with period 90: two distinct poses (0 and 45)."""
    table = pd.DataFrame(gfo_rows("a", "1", [1.0, None] * 4, step_deg=45.0) + gfo_rows("a", "1-2", [1.0, 1.0] * 4, step_deg=45.0))
    r = success_rates(with_verdicts(table, "force_closure"), "1-2", {"a": 90.0}).set_index("set_id")
    assert r.loc["1", "n_success"] == 1 and r.loc["1", "n_success_grid"] == 4  # the headline: distinct poses
    assert r.loc["1", "n_poses"] == 2
    assert r.loc["1", "success_rate_grid"] == pytest.approx(50.0) == r.loc["1", "success_rate"]


def test_marginal_grasps_flagged_and_excluded():
    """Weight 1 N, multiple 10: forces 5, 20 and 50 N -> two marginal successes."""
    table = pd.DataFrame(gfo_rows("a", "1", [5.0, 20.0, 50.0]) + gfo_rows("a", "1-2", [5.0, 10.0, 10.0]))
    judged = with_verdicts(table, "force_closure", weights_N={"a": 1.0}, marginal_multiple=10.0)
    r = success_rates(judged, "1-2").set_index("set_id")
    assert r.loc["1", "n_marginal"] == 2 and r.loc["1", "marginal_percent"] == pytest.approx(200 / 3)
    assert r.loc["1", "plain_mean_force_N"] == pytest.approx(25.0)
    assert r.loc["1", "plain_mean_force_non_marginal_N"] == pytest.approx(5.0)
    assert r.loc["1", "force_ratio_median"] == pytest.approx(2.0)  # 1, 2, 5
    assert r.loc["1", "force_ratio_median_non_marginal"] == pytest.approx(1.0)


def test_success_rates_unknown_full_set(gfo):
    with pytest.raises(ValueError, match="full_set_id '9' .*allowed values"):
        success_rates(with_verdicts(gfo, "force_closure"), "9")


def test_incrementality_table(gfo):
    t = incrementality_table(success_rates(with_verdicts(gfo, "force_closure"), FULL), 4)
    assert list(t.columns) == ["object", 1, 2, 3, 4]
    assert t.set_index("object").loc["a", [1, 2, 3]].tolist() == [25.0, 50.0, 100.0]
    assert np.isnan(t.set_index("object").loc["a", 4])  # set 1-2-3-4 not computed


def test_mean_over_objects_skips_undefined(gfo):
    m = mean_over_objects(success_rates(with_verdicts(gfo, "force_closure"), FULL)).set_index("set_id")
    assert m.loc["1-2", "success_rate"] == pytest.approx(50.0)  # b is undefined, not 0
    assert m.loc["1-2", "n_objects"] == 1
    assert m.loc["1-2", "plain_mean_force_N"] == pytest.approx((3.0 + 5.0) / 2)
    assert m.loc["1-2", "absolute_share"] == pytest.approx((50.0 + 25.0) / 2)
    assert m.loc["1-2", "force_ratio_median"] == pytest.approx(2.0)  # b has no paired ratio


def test_hierarchy_matrices_collapse_duplicates():
    sets = ["1", "2", "3", "1-2", "1-3", "2-3", "1-2-3"]
    rates = pd.DataFrame(
        {
            "set_id": sets,
            "success_rate": np.arange(7.0),
            "force_ratio_median": 1 + np.arange(7.0),
            "plain_mean_force_N": 10 + np.arange(7.0),
        }
    )
    h = hierarchy_matrices(rates, first=3)
    assert len(h) == 27
    cell = h.set_index(["k", "i", "j"])
    assert cell.loc[(2, 2, 2), "set_id"] == "2"
    assert cell.loc[(2, 2, 3), "set_id"] == "2-3" == cell.loc[(2, 3, 3), "set_id"] == cell.loc[(3, 2, 2), "set_id"]
    assert cell.loc[(3, 1, 2), "set_id"] == "1-2-3"
    assert cell.loc[(3, 1, 2), "success_rate"] == 6.0 and cell.loc[(1, 1, 3), "plain_mean_force_N"] == 14.0
    for k in (1, 2, 3):  # every matrix is symmetric in (i, j)
        m = h[h["k"] == k].pivot(index="i", columns="j", values="success_rate").to_numpy()
        np.testing.assert_array_equal(m, m.T)


def test_hierarchy_missing_set_is_nan_and_duplicates_rejected():
    h = hierarchy_matrices(pd.DataFrame({"set_id": ["1"], "success_rate": [1.0]}), first=2, values=["success_rate"])
    assert h.set_index(["k", "i", "j"]).loc[(1, 1, 1), "success_rate"] == 1.0
    assert h["success_rate"].isna().sum() == 7
    with pytest.raises(ValueError, match="one row per set_id"):
        hierarchy_matrices(pd.DataFrame({"set_id": ["1", "1"], "success_rate": [1, 2]}), values=["success_rate"])


def test_minimum_preservation_by_hand(gfo):
    minima = pd.DataFrame(
        [
            dict(object="a", set_id="1", alpha_deg=-180.0, beta_deg=0.0),  # kept: 1-2 has one at 175 (wrap)
            dict(object="a", set_id="1", alpha_deg=0.0, beta_deg=-60.0),  # lost
            dict(object="a", set_id="1-2", alpha_deg=175.0, beta_deg=5.0),  # kept: 1-2-3 has one at 170
            dict(object="a", set_id="1-2-3", alpha_deg=170.0, beta_deg=10.0),
            dict(object="b", set_id="1-2", alpha_deg=0.0, beta_deg=0.0),  # lost: b's 1-2-3 has none
        ]
    )
    p = minimum_preservation(gfo, minima, k_max=3)
    rows = {(o, None if pd.isna(k) else k): r for o, k, r in zip(p["object"], p["k"], p.to_dict("records"))}
    assert (rows[("a", 1)]["n_minima"], rows[("a", 1)]["n_preserved"]) == (2, 1)
    assert rows[("a", 1)]["preserved_percent"] == pytest.approx(50.0)
    assert (rows[("a", 2)]["n_minima"], rows[("a", 2)]["n_preserved"]) == (1, 1)
    assert (rows[("a", None)]["n_minima"], rows[("a", None)]["n_preserved"]) == (3, 2)
    assert rows[("b", 1)]["n_minima"] == 0 and np.isnan(rows[("b", 1)]["preserved_percent"])
    assert (rows[("all", 2)]["n_minima"], rows[("all", 2)]["n_preserved"]) == (2, 1)
    assert (rows[("all", None)]["n_minima"], rows[("all", None)]["n_preserved"]) == (4, 2)
    assert list(p.columns) == [
        "object",
        "k",
        "n_minima",
        "n_preserved",
        "preserved_percent",
        "n_minima_distinct",
        "n_preserved_distinct",
    ]
    # with a 180 deg period, a's grid starts at alpha 0: the minimum at -180 is outside [0, 180)
    q = minimum_preservation(gfo, minima, k_max=3, periods_deg={"a": 180.0}).set_index(["object", "k"])
    assert q.loc[("a", 1), ["n_minima_distinct", "n_preserved_distinct"]].tolist() == [1, 0]


def test_full_but_not_first_n(gfo):
    out = full_but_not_first_n(with_verdicts(gfo, "force_closure"), FULL, "1-2")
    assert out[["object", "pose"]].values.tolist() == [["a", 2], ["a", 3]]
    assert out["full_force_norm"].tolist() == [3.0, 10.0]
    assert set(out["first7_status"]) == {"infeasible"}
    partial = gfo[~((gfo["set_id"] == "1-2") & (gfo["pose"] == 3))]
    assert full_but_not_first_n(with_verdicts(partial, "force_closure"), FULL, "1-2")["first7_status"].tolist() == [
        "infeasible",
        "missing",
    ]
    with pytest.raises(ValueError, match="first_n_set_id"):
        full_but_not_first_n(with_verdicts(gfo, "force_closure"), FULL, "1-2-3-4-5-6-7")


def test_verdict_disagreements():
    rows = gfo_rows("a", "1", [1.0, 2.0, None, None], strict=[True, False, True, False]) + gfo_rows(
        "a", "1-2", [1.0, None], strict=[True, False]
    )
    out = verdict_disagreements(with_verdicts(pd.DataFrame(rows), "force_closure"))
    assert len(out) == 1  # 1-2 agrees everywhere
    row = out.iloc[0]
    assert (row["set_id"], row["n_poses"], row["n_disagree"], row["n_load_feasible_only"], row["n_force_closure_only"]) == (
        "1",
        4,
        2,
        1,
        1,
    )
    assert row["disagree_percent"] == pytest.approx(50.0)


def test_study_tables_names_and_csv_round_trip(gfo, tmp_path):
    minima = pd.DataFrame([dict(object="a", set_id="1", pose=0, alpha_deg=0.0, beta_deg=0.0)])
    settings = study_analysis_settings(null_draws=20)
    with pytest.warns(UserWarning):  # b's set 1-2 succeeds where its full set does not
        tables = study_tables(
            frames_by_object(gfo, minima), {"incremental_max": 3, "hierarchy_first": 2, "hierarchy_max_size": 2}, 3, settings
        )
    assert set(tables) == {
        "success_rates",
        "table2_success_rates",
        "hierarchy",
        "minimum_preservation",
        "preservation_vs_chance",
        "full_not_first7",
        "verdict_disagreements",
        "invariant_checks",
        "claims",
    }
    from synergrasp.steps import STEPS
    from synergrasp.table_contracts import STUDY_TABLES

    assert list(tables) == list(STUDY_TABLES) and set(STEPS["tables"].outputs) == {
        f"{t}_{e}" for t in STUDY_TABLES for e in ("csv", "md")
    }
    assert tables["full_not_first7"][1]["pose"].tolist() == [2, 3]
    rates = tables["success_rates"][1]
    views = rates[rates["object"] == "all"].set_index(["set_id", "view"])
    assert views.loc[("1-2", "per_object"), "success_rate"] == pytest.approx(50.0)  # b's full set never succeeds
    assert views.loc[("1-2", "pooled"), "success_rate"] == pytest.approx(50.0)
    assert views.loc[("1-2", "pooled"), "n_force_poses"] == 2  # a's poses 0, 1 (b's pose 0 has no full-set force)
    assert views.loc[("1-2", "pooled"), "force_ratio_median"] == pytest.approx(2.0)
    checks = tables["invariant_checks"][1].set_index(["check", "object"])
    assert checks.loc[("nested_sets", "b"), "count"] == 1 and checks.loc[("nested_sets", "a"), "count"] == 0
    path = tmp_path / "rates.csv"  # a CSV round trip reads set "1" back as an integer
    tables["success_rates"][1].to_csv(path, index=False)
    h = hierarchy_matrices(mean_over_objects(pd.read_csv(path)), 2).set_index(["k", "i", "j"])
    assert h.loc[(1, 1, 2), "success_rate"] == pytest.approx(50.0)


def test_study_tables_stop_on_a_rate_far_above_100(gfo):
    """A subset succeeding on twice the full set's poses (e.g. a synergy entry of 1e300)."""
    broken = pd.DataFrame(gfo_rows("a", "1", [1.0, 1.0, 1.0, 1.0]) + gfo_rows("a", "1-2", [1.0, 1.0, None, None]))
    with pytest.raises(InvariantError, match=r"success_rate_tolerance_percent \(1.0\).*a \{1\}: 200 %"):
        study_tables(
            frames_by_object(broken, broken.iloc[:0].assign(pose=[], alpha_deg=[], beta_deg=[])),
            {"incremental_max": 2, "hierarchy_first": 2, "hierarchy_max_size": 1},
            2,
            study_analysis_settings(null_draws=5),
        )
