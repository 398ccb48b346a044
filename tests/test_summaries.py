import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.summaries import (
    full_but_not_first7,
    hierarchy_matrices,
    incrementality_table,
    mean_over_objects,
    minimum_preservation,
    success_rates,
    study_tables,
    verdict_disagreements,
)

FULL = "1-2-3"


def gfo_rows(obj: str, set_id: str, forces: list[float | None], strict: list[bool] | None = None) -> list[dict]:
    """One row per pose; None = not force closure."""
    strict = strict if strict is not None else [f is not None for f in forces]
    return [dict(object=obj, pose=p, alpha_deg=5.0 * p, beta_deg=0.0, set_id=set_id,
                 n_synergies=len(set_id.split("-")), status="force_closure" if f is not None else "infeasible",
                 force_closure=f is not None, strict_internal=s, force_norm=np.nan if f is None else f)
            for p, (f, s) in enumerate(zip(forces, strict))]


@pytest.fixture
def gfo() -> pd.DataFrame:
    rows = (gfo_rows("a", "1", [1.0, None, None, None])
            + gfo_rows("a", "1-2", [2.0, 4.0, None, None])
            + gfo_rows("a", FULL, [1.0, 2.0, 3.0, 10.0])
            + gfo_rows("b", "1", [None, None, None, None])
            + gfo_rows("b", "1-2", [5.0, None, None, None])
            + gfo_rows("b", FULL, [None, None, None, None]))
    return pd.DataFrame(rows)


def test_success_rates_by_hand(gfo):
    r = success_rates(gfo, FULL).set_index(["object", "set_id"])
    assert r.loc[("a", "1-2"), "n_force_closure"] == 2
    assert r.loc[("a", "1-2"), "success_rate"] == pytest.approx(50.0)  # 2 of the full set's 4
    assert r.loc[("a", "1"), "success_rate"] == pytest.approx(25.0)
    assert r.loc[("a", FULL), "success_rate"] == pytest.approx(100.0)
    assert r.loc[("a", "1-2"), "absolute_share"] == pytest.approx(50.0)
    assert r.loc[("a", FULL), "mean_force"] == pytest.approx(4.0)
    assert r.loc[("a", FULL), "median_force"] == pytest.approx(2.5)
    # b: the full set never succeeds -> undefined rate, flagged; absolute share still defined
    assert np.isnan(r.loc[("b", "1-2"), "success_rate"]) and r.loc[("b", "1-2"), "full_set_empty"]
    assert r.loc[("b", "1-2"), "absolute_share"] == pytest.approx(25.0)
    assert not r.loc[("a", "1"), "full_set_empty"]
    assert np.isnan(r.loc[("b", "1"), "mean_force"])
    assert list(r.reset_index()["set_id"][:3]) == ["1", "1-2", FULL]


def test_success_rates_unknown_full_set(gfo):
    with pytest.raises(ValueError, match="full_set_id '9' .*allowed values"):
        success_rates(gfo, "9")


def test_incrementality_table(gfo):
    t = incrementality_table(success_rates(gfo, FULL), 4)
    assert list(t.columns) == ["object", 1, 2, 3, 4]
    assert t.set_index("object").loc["a", [1, 2, 3]].tolist() == [25.0, 50.0, 100.0]
    assert np.isnan(t.set_index("object").loc["a", 4])  # set 1-2-3-4 not computed


def test_mean_over_objects_skips_undefined(gfo):
    m = mean_over_objects(success_rates(gfo, FULL)).set_index("set_id")
    assert m.loc["1-2", "success_rate"] == pytest.approx(50.0)  # b is undefined, not 0
    assert m.loc["1-2", "n_objects"] == 1
    assert m.loc["1-2", "mean_force"] == pytest.approx((3.0 + 5.0) / 2)
    assert m.loc["1-2", "absolute_share"] == pytest.approx((50.0 + 25.0) / 2)


def test_hierarchy_matrices_collapse_duplicates():
    sets = ["1", "2", "3", "1-2", "1-3", "2-3", "1-2-3"]
    rates = pd.DataFrame({"set_id": sets, "success_rate": np.arange(7.0), "mean_force": 10 + np.arange(7.0)})
    h = hierarchy_matrices(rates, first=3)
    assert len(h) == 27
    cell = h.set_index(["k", "i", "j"])
    assert cell.loc[(2, 2, 2), "set_id"] == "2"
    assert cell.loc[(2, 2, 3), "set_id"] == "2-3" == cell.loc[(2, 3, 3), "set_id"] == cell.loc[(3, 2, 2), "set_id"]
    assert cell.loc[(3, 1, 2), "set_id"] == "1-2-3"
    assert cell.loc[(3, 1, 2), "success_rate"] == 6.0 and cell.loc[(1, 1, 3), "mean_force"] == 14.0
    # every matrix is symmetric in (i, j)
    for k in (1, 2, 3):
        m = h[h["k"] == k].pivot(index="i", columns="j", values="success_rate").to_numpy()
        np.testing.assert_array_equal(m, m.T)


def test_hierarchy_missing_set_is_nan_and_duplicates_rejected():
    h = hierarchy_matrices(pd.DataFrame({"set_id": ["1"], "success_rate": [1.0], "mean_force": [2.0]}), first=2)
    assert h.set_index(["k", "i", "j"]).loc[(1, 1, 1), "success_rate"] == 1.0
    assert h["success_rate"].isna().sum() == 7
    with pytest.raises(ValueError, match="one row per set_id"):
        hierarchy_matrices(pd.DataFrame({"set_id": ["1", "1"], "success_rate": [1, 2], "mean_force": [1, 2]}))


def test_minimum_preservation_by_hand(gfo):
    minima = pd.DataFrame([
        dict(object="a", set_id="1", alpha_deg=-180.0, beta_deg=0.0),   # kept: 1-2 has one at 175 (wrap)
        dict(object="a", set_id="1", alpha_deg=0.0, beta_deg=-60.0),    # lost
        dict(object="a", set_id="1-2", alpha_deg=175.0, beta_deg=5.0),  # kept: 1-2-3 has one at 170
        dict(object="a", set_id="1-2-3", alpha_deg=170.0, beta_deg=10.0),
        dict(object="b", set_id="1-2", alpha_deg=0.0, beta_deg=0.0),    # lost: b's 1-2-3 has none
    ])
    p = minimum_preservation(gfo, minima, k_max=3)
    rows = {(o, None if pd.isna(k) else k): r for o, k, r in zip(p["object"], p["k"], p.to_dict("records"))}
    assert (rows[("a", 1)]["n_minima"], rows[("a", 1)]["n_preserved"]) == (2, 1)
    assert rows[("a", 1)]["preserved_percent"] == pytest.approx(50.0)
    assert (rows[("a", 2)]["n_minima"], rows[("a", 2)]["n_preserved"]) == (1, 1)
    assert (rows[("a", None)]["n_minima"], rows[("a", None)]["n_preserved"]) == (3, 2)
    assert rows[("b", 1)]["n_minima"] == 0 and np.isnan(rows[("b", 1)]["preserved_percent"])
    assert (rows[("all", 2)]["n_minima"], rows[("all", 2)]["n_preserved"]) == (2, 1)
    assert (rows[("all", None)]["n_minima"], rows[("all", None)]["n_preserved"]) == (4, 2)
    assert list(p.columns) == ["object", "k", "n_minima", "n_preserved", "preserved_percent"]


def test_full_but_not_first7(gfo):
    out = full_but_not_first7(gfo, FULL, "1-2")
    assert out[["object", "pose"]].values.tolist() == [["a", 2], ["a", 3]]
    assert out["full_force_norm"].tolist() == [3.0, 10.0]
    assert set(out["first7_status"]) == {"infeasible"}
    partial = gfo[~((gfo["set_id"] == "1-2") & (gfo["pose"] == 3))]
    assert full_but_not_first7(partial, FULL, "1-2")["first7_status"].tolist() == ["infeasible", "missing"]
    with pytest.raises(ValueError, match="first7_set_id"):
        full_but_not_first7(gfo, FULL, "1-2-3-4-5-6-7")


def test_verdict_disagreements():
    rows = (gfo_rows("a", "1", [1.0, 2.0, None, None], strict=[True, False, True, False])
            + gfo_rows("a", "1-2", [1.0, None], strict=[True, False]))
    out = verdict_disagreements(pd.DataFrame(rows))
    assert len(out) == 1  # 1-2 agrees everywhere
    row = out.iloc[0]
    assert (row["set_id"], row["n_poses"], row["n_disagree"], row["n_fc_not_strict"], row["n_strict_not_fc"]) == \
        ("1", 4, 2, 1, 1)
    assert row["disagree_percent"] == pytest.approx(50.0)


def test_study_tables_names_and_csv_round_trip(gfo, tmp_path):
    minima = pd.DataFrame([dict(object="a", set_id="1", alpha_deg=0.0, beta_deg=0.0)])
    tables = study_tables(gfo, minima, {"incremental_max": 3, "hierarchy_first": 2, "hierarchy_max_size": 2}, 3)
    assert set(tables) == {"success_rates", "table2_success_rates", "hierarchy", "minimum_preservation",
                           "full_not_first7", "verdict_disagreements"}
    assert tables["full_not_first7"][1]["pose"].tolist() == [2, 3]
    # the figure step reads the rates back from CSV
    path = tmp_path / "rates.csv"
    tables["success_rates"][1].to_csv(path, index=False)
    h = hierarchy_matrices(mean_over_objects(pd.read_csv(path)), 2).set_index(["k", "i", "j"])
    assert h.loc[(1, 1, 2), "success_rate"] == pytest.approx(50.0)
