"""The sweep's summary on hand-made study tables: one row per scenario, each claim's verdict
and figure carried over, Table II rows, single-synergy rates averaged over objects, and the
share of minima preserved."""

import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.sensitivity import ScenarioTables, sensitivity_table, table2_long


def tables(verdict1: str, rate_s1_obj1: float, preserved: float) -> ScenarioTables:
    claims = pd.DataFrame(
        {
            "claim": [1, 2],
            "statement": ["a", "b"],
            "tested_by": ["T2", "T2"],
            "measured": [f"fig {verdict1}", "0 pairs"],
            "verdict": [verdict1, "holds"],
        }
    )
    table2 = pd.DataFrame(
        {"object": ["obj1", "obj2"], "1": [rate_s1_obj1, 20.0], "2": [80.0, 60.0], "3": [100.0, 90.0], "4": [100.0, 100.0]}
    )
    rates = pd.DataFrame(
        {
            "object": ["obj1", "obj2", "obj1", "obj1"],
            "set_id": ["1", "1", "2", "1-2"],
            "n_synergies": [1, 1, 1, 2],
            "success_rate": [rate_s1_obj1, 20.0, 30.0, 80.0],
        }
    )
    preservation = pd.DataFrame({"object": ["obj1", "all"], "pairs": ["all", "all"], "preserved_percent": [50.0, preserved]})
    return ScenarioTables(claims, table2, rates, preservation)


def test_one_row_per_scenario_with_each_figure():
    summary = sensitivity_table({"default": tables("holds", 40.0, 95.0), "mu_1_0": tables("does not hold", 10.0, 70.0)})
    assert list(summary["scenario"]) == ["default", "mu_1_0"]
    assert list(summary["claim1_verdict"]) == ["holds", "does not hold"]
    assert list(summary["claim1_measured"]) == ["fig holds", "fig does not hold"]
    assert list(summary["claim2_verdict"]) == ["holds", "holds"]
    assert list(summary["table2_k1_obj1"]) == [40.0, 10.0]
    assert list(summary["table2_k3_obj2"]) == [90.0, 90.0]
    assert "table2_k4_obj1" not in summary.columns
    # {S1} alone: mean over objects (40 + 20) / 2; {S2} only for obj1; S3..S7 absent
    assert list(summary["S1_success_percent"]) == [30.0, 15.0]
    assert list(summary["S2_success_percent"]) == [30.0, 30.0]
    assert np.isnan(summary["S7_success_percent"]).all()
    assert list(summary["minima_preserved_percent"]) == [95.0, 70.0]


def test_preservation_share_from_counts_when_no_overall_row():
    t = tables("holds", 40.0, 95.0)
    counts = pd.DataFrame(
        {
            "object": ["obj1", "obj2"],
            "k": [1, 1],
            "n_minima": [3, 1],
            "n_preserved": [2, 1],
            "preserved_percent": [200 / 3, 100.0],
        }
    )
    summary = sensitivity_table({"default": ScenarioTables(t.claims, t.table2, t.success_rates, counts)})
    assert summary["minima_preserved_percent"].iloc[0] == pytest.approx(75.0)


def test_table2_long_and_empty_sweep():
    long = table2_long({"default": tables("holds", 40.0, 95.0)})
    assert len(long) == 8 and long["k"].dtype.kind == "i"
    assert long.query("object == 'obj1' and k == 1")["success_rate"].item() == 40.0
    with pytest.raises(ValueError, match="no scenarios"):
        sensitivity_table({})


def test_figures_are_written(tmp_path):
    from synergrasp.figures.sensitivity import figure_claims_grid, figure_table2_curves

    scenarios = {"default": tables("holds", 40.0, 95.0), "mu_1_0": tables("undefined", 10.0, 70.0)}
    figure_claims_grid(sensitivity_table(scenarios), tmp_path / "g.png", tmp_path / "g.pdf")
    figure_table2_curves(table2_long(scenarios), tmp_path / "c.png", tmp_path / "c.pdf", k_max=4)
    assert all((tmp_path / n).stat().st_size > 0 for n in ("g.png", "g.pdf", "c.png", "c.pdf"))


def test_the_shipped_sweep_is_valid_and_changes_one_factor_per_scenario():
    """config/sensitivity.yaml over config/config.yaml: every scenario passes the checks and
    differs from the default in exactly one top-level section of the configuration."""
    from pathlib import Path

    import yaml

    from conftest import scenario_configs

    root = Path(__file__).resolve().parents[1]
    raw = yaml.safe_load((root / "config" / "config.yaml").read_text())
    raw["scenarios"] = yaml.safe_load((root / "config" / "sensitivity.yaml").read_text())["scenarios"]
    configs = scenario_configs(raw)
    assert len(configs) == 1 + len(raw["scenarios"]) >= 14
    default = configs["default"]
    for name, cfg in configs.items():
        changed = [k for k in default if k != "scenarios" and cfg[k] != default[k]]
        assert len(changed) == (0 if name == "default" else 1), (name, changed)


def test_realism_per_object_in_scenario_order():
    """Each grasp-realism figure is every object's value, in the table's order, joined by "/";
    a missing value is a dash, and a scenario without the table has no such column."""
    t = tables("holds", 40.0, 95.0)
    realism = pd.DataFrame(
        {
            "object": ["obj1", "obj2"],
            "contacts_median": [5.0, 6.0],
            "pct_palm": [89.6, 18.9],
            "pct_thumb": [72.7, 100.0],
            "pct_index": [0.0, 69.3],
            "pct_force_closure": [100.0, 92.7],
            "median_force_per_weight": [0.541, np.nan],
        }
    )
    with_realism = ScenarioTables(t.claims, t.table2, t.success_rates, t.preservation, realism)
    summary = sensitivity_table({"default": with_realism, "other": t})
    row = summary.iloc[0]
    assert row["grasp_contacts_median"] == "5/6"
    assert row["grasp_palm_percent"] == "90/19"
    assert row["grasp_index_percent"] == "0/69"
    assert row["grasp_force_closure_percent"] == "100/93"
    assert row["grasp_force_per_weight_median"] == "0.54/—"
    assert pd.isna(summary.iloc[1]["grasp_palm_percent"])
