"""The claims over the placement search's targets (synergrasp.analysis.target_claims)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from synergrasp.analysis.minima import minima_table
from synergrasp.analysis.periods import alpha_period_deg
from synergrasp.analysis.study_tables import frames_by_object, study_tables
from synergrasp.analysis.summaries import TablesParams
from synergrasp.analysis.target_claims import ClaimsAtTargets, TargetClaimsParams, claims_at_targets, claims_summary
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.config import ConfigError, validate_config
from synergrasp.hand.synergies import load_synergies
from synergrasp.ids import synergy_sets
from synergrasp.optimisation.problem import SynergySets
from synergrasp.optimisation.optimise import gfo_table
from synergrasp.simulation.closure import SimulateParams, simulate_object
from synergrasp.steps import step_config

SMALL = yaml.safe_load((Path(__file__).parent / "config" / "small.yaml").read_text())
TARGET = (9.5, -20.0, 100.0)


def _config(**analyses):
    config = dict(
        SMALL,
        placement={**SMALL["placement"], "mode": "searched"},
        objects={"obj1": SMALL["objects"]["obj1"]},
        synergy_sets={"incremental_max": 6, "hierarchy_first": 4, "hierarchy_max_size": 2},
    )
    # fewer resamples and null draws than the study: the same code, a fast test
    config["analyses"] = {
        **SMALL["analyses"],
        "table2_k_max": 6,
        "min_distinct_poses": 3,
        "bootstrap": {"resamples": 100},
        "null_model": {"draws": 50, "seed": 2018},
        "fig4": {"panel_k": [1, 6]},
        "target_claims": {"alpha_every": 1, "beta_every": 1, **analyses},
    }
    return validate_config(config)


def _placement_table(targets):
    return pd.DataFrame(
        [
            {"object": "obj1", "rank": k + 1, "x_mm": x, "y_mm": y, "z_mm": z, "force_closure_percent": 100.0 - k}
            for k, (x, y, z) in enumerate(targets)
        ]
    )


@pytest.fixture(scope="module")
def small_claims(hand):
    config = _config()
    params = TargetClaimsParams.from_config(config, "obj1")
    synergies = load_synergies(None, joint_names=hand.joint_names)
    period = alpha_period_deg(params.search.placement, params.search.object.shape, hand.palm_normal)
    return config, params, synergies, period


def _study_claims(hand, synergies, config, target):
    """The study's own claims of obj1 with the box brought toward ``target`` (the fixed
    preset of the same placement rule) on the whole grid, by the study's steps."""
    fixed = dict(config, placement={**config["placement"], "mode": "fixed", "center_mm": list(target)})
    sim = SimulateParams.from_config(fixed, "obj1")
    contacts = simulate_object(hand, sim.synergies(hand.joint_names), sim.object, sim.placement, sim.closure)
    sets = SynergySets(synergies.matrix, tuple(synergy_sets(config["synergy_sets"]).values()))
    params = TargetClaimsParams.from_config(config, "obj1")
    gfo = gfo_table(contacts, sets, params.search.gfo)
    minima = minima_table(with_verdicts(gfo, "force_closure"), params.minima.radius_deg)
    tables = TablesParams.from_config(fixed)
    claims = study_tables(frames_by_object(gfo, minima), tables.synergy_sets, tables.table2_k_max, tables.settings)["claims"][1]
    return claims[claims["headline"]].reset_index(drop=True)


def test_claims_at_a_target_equal_the_studys_claims_there(hand, small_claims):
    """On a lattice equal to the grid's first α-period, the claims at a target are the
    study's own claims with the box brought to that target (same rule, same verdict rules):
    the period fold of the bootstrap and of the minima makes one period carry them all."""
    config, params, synergies, period = small_claims
    computer = ClaimsAtTargets(hand, synergies, params, period)
    try:
        at_target = computer(TARGET)
    finally:
        computer.close()
    study = _study_claims(hand, synergies, config, TARGET)
    assert len(computer.poses) == int(period // 30) * 7
    assert list(at_target["claim"]) == list(study["claim"])
    assert list(at_target["verdict"]) == list(study["verdict"])
    assert list(at_target["n_distinct_poses"]) == list(study["n_distinct_poses"])
    # claim 3's null model draws shifts over the grid it is given: its numbers may differ
    same = at_target["claim"] != 3
    np.testing.assert_allclose(
        at_target.loc[same, "difference"].astype(float), study.loc[same, "difference"].astype(float), rtol=1e-9, equal_nan=True
    )


def test_claims_at_targets_in_rank_order_and_bounded_by_max_targets(hand, small_claims):
    config, params, synergies, period = small_claims
    placement = _placement_table([(49.5, 30.0, 180.0), TARGET, (29.5, -10.0, 110.0)]).iloc[::-1]
    few = TargetClaimsParams.from_config(_config(max_targets=2), "obj1")
    table = claims_at_targets(hand, synergies, few, period, placement)
    assert list(dict.fromkeys(table["rank"])) == [1, 2]
    assert set(table.groupby("rank")["claim"].apply(tuple)) == {tuple(range(1, 8))}
    far = table[table["rank"] == 1]
    # (49.5, 30, 180) mm lies past the fingertips: the box is never touched, nothing holds
    assert (far["n_distinct_poses"] == 0).all() and (far["verdict"] == "undefined").all()


def test_summary_shares_by_hand():
    rows = []
    for rank, verdicts in enumerate(
        [("holds", "undefined"), ("holds", "does not hold"), ("does not hold", "does not hold"), ("holds", "undefined")], start=1
    ):
        for claim, verdict in zip((4, 6), verdicts):
            rows.append({"object": "obj9", "rank": rank, "claim": claim, "verdict": verdict})
    summary = claims_summary(pd.DataFrame(rows)).set_index("claim")
    assert summary.loc[4, ["holds_percent", "does_not_hold_percent", "undefined_percent"]].tolist() == [75, 25, 0]
    assert summary.loc[6, ["holds_percent", "does_not_hold_percent", "undefined_percent"]].tolist() == [0, 50, 50]
    assert summary.loc[4, "at_chosen_target"] == "holds" and summary.loc[6, "at_chosen_target"] == "undefined"
    assert (summary["n_targets"] == 4).all()


def test_bad_lattice_is_one_error_naming_the_key():
    for key, value in (("alpha_every", 0), ("max_targets", -1)):
        with pytest.raises(ConfigError, match=f"analyses.target_claims.{key}"):
            _config(**{key: value})


def test_step_reads_what_its_params_need():
    """Its parameters built from its own part of the configuration equal those from the whole."""
    config = _config()
    assert TargetClaimsParams.from_config(step_config(config, "target_claims", "obj1"), "obj1") == TargetClaimsParams.from_config(
        config, "obj1"
    )
