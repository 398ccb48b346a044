"""The study's tables made one object at a time (``synergrasp.analysis.study_tables``) against
the same tables made from every object's rows at once (the all-rows composition the tables
job ran before, written out here), on a made-up study of three objects: every table equal,
numbers and order; and the reduction never holds two objects' gfo rows at once."""

import gc
import weakref
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

from conftest import study_analysis_settings
from synergrasp.analysis.bootstrap import PoseResampler
from synergrasp.analysis.chance import preservation_vs_chance, resampled_preservation
from synergrasp.analysis.claims import claims_table
from synergrasp.analysis.intervals import StudyCounts
from synergrasp.analysis.invariants import invariant_checks
from synergrasp.analysis.study_tables import frames_by_object, study_tables
from synergrasp.analysis.summaries import (
    full_but_not_first_n,
    incrementality_table,
    minimum_preservation,
    success_rates,
    verdict_disagreements,
    with_intervals,
)
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.ids import incremental_set_id

SETS = ("1", "2", "3", "1-2", "1-3", "2-3", "1-2-3")
SETS_CONFIG = {"incremental_max": 3, "hierarchy_first": 2, "hierarchy_max_size": 3}
ALPHAS, BETAS = np.arange(0.0, 180.0, 15.0), np.arange(-30.0, 31.0, 15.0)


def made_up_study(seed: int = 3, objects=("c", "a", "b")) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A gfo table of ``objects`` (in that order: not sorted) on a 12 x 5 grid, every set,
    successes nested in the sets but for a few poses (the nested check has something to
    count), and minima of the incremental sets at random poses."""
    rng = np.random.default_rng(seed)
    rows, minima = [], []
    grid = [(a, b) for a in ALPHAS for b in BETAS]
    for obj in objects:
        strength = rng.uniform(0.2, 1.0, size=len(grid))
        for sid in SETS:
            n = len(sid.split("-"))
            for pose, (alpha, beta) in enumerate(grid):
                ok = strength[pose] * n / 3 + rng.normal(0, 0.05) > 0.45
                force = float(rng.uniform(1.0, 20.0) / n) if ok or rng.random() < 0.2 else np.nan
                rows.append(
                    dict(
                        object=obj,
                        pose=pose,
                        alpha_deg=alpha,
                        beta_deg=beta,
                        set_id=sid,
                        n_synergies=n,
                        status="feasible" if np.isfinite(force) else "infeasible",
                        load_feasible=bool(np.isfinite(force)),
                        force_closure_def1=bool(ok),
                        rank_G=6,
                        force_norm=force,
                    )
                )
        for k in (1, 2, 3):
            for pose in rng.choice(len(grid), size=6, replace=False):
                alpha, beta = grid[pose]
                minima.append(dict(object=obj, set_id=incremental_set_id(k), pose=int(pose), alpha_deg=alpha, beta_deg=beta))
    return pd.DataFrame(rows), pd.DataFrame(minima)


def all_rows_tables(gfo: pd.DataFrame, minima: pd.DataFrame, settings) -> dict[str, pd.DataFrame]:
    """The tables from every object's rows at once, as the tables job made them before."""
    full, first_n = incremental_set_id(3), incremental_set_id(2)
    periods = dict(settings.periods_deg)
    table = with_verdicts(gfo, settings.success, settings.weights_N, settings.marginal_weight_multiple)
    resampler = PoseResampler(table[table["set_id"] == full], periods, settings.bootstrap)
    counts = StudyCounts(table, full, resampler)
    chance, pairs = preservation_vs_chance(
        table, minima, 3, settings.radius_deg, periods, settings.null_draws, settings.null_seed
    )
    kept = resampled_preservation(minima, 3, settings.radius_deg, resampler)
    rates = success_rates(table, full, periods)
    preservation = minimum_preservation(table, minima, 3, settings.radius_deg, periods)
    return {
        "claims": claims_table(counts, kept, chance, settings.rules, 2),
        "success_rates": with_intervals(rates, counts),
        "table2_success_rates": incrementality_table(rates, 3),
        "invariant_checks": invariant_checks(table, rates, periods, settings.success_rate_tolerance_percent),
        "full_not_first7": full_but_not_first_n(table, full, first_n),
        "minimum_preservation": preservation.merge(pairs.astype({"k": "Int64"}), on=["object", "k"], how="left"),
        "preservation_vs_chance": chance,
        "verdict_disagreements": verdict_disagreements(table),
    }


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("periods", [{}, {"a": 90.0, "b": 180.0}])
def test_one_object_at_a_time_gives_the_all_rows_tables(periods):
    gfo, minima = made_up_study()
    settings = study_analysis_settings(null_draws=40)
    settings = replace(
        settings, periods_deg=periods, bootstrap=replace(settings.bootstrap, resamples=200, seed=11, block_deg=30.0)
    )
    reference = all_rows_tables(gfo, minima, settings)
    made = study_tables(frames_by_object(gfo, minima), SETS_CONFIG, 3, settings)
    for name, expected in reference.items():
        got = made[name][1]
        assert len(got) == len(expected) > 0, name
        assert_frame_equal(got.reset_index(drop=True), expected.reset_index(drop=True), check_exact=True, obj=name)
    rates = made["success_rates"][1]
    per_object = rates[rates["view"] == "per_object"]
    assert per_object["success_rate_low"].notna().any()  # the bootstrap ran: intervals, not NaN


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_an_object_without_a_set_counts_no_success_of_it():
    """``StudyCounts.finish`` aligns an object computed without set 2-3 on the study's sets."""
    gfo, minima = made_up_study()
    gfo = gfo[~((gfo["object"] == "b") & (gfo["set_id"] == "2-3"))]
    settings = study_analysis_settings(null_draws=20)
    settings = replace(settings, bootstrap=replace(settings.bootstrap, resamples=50, seed=5, block_deg=30.0))
    reference = all_rows_tables(gfo, minima, settings)
    made = study_tables(frames_by_object(gfo, minima), SETS_CONFIG, 3, settings)
    for name in ("claims", "success_rates"):
        assert_frame_equal(made[name][1], reference[name], check_exact=True, obj=name)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_the_reduction_holds_one_objects_rows_at_a_time():
    """Each loader's frames are gone (garbage-collected) before the next object is read, and
    the objects are read in sorted order whatever order they are handed in."""
    gfo, minima = made_up_study()
    alive: list[weakref.ref] = []
    read: list[str] = []

    def loader(obj):
        def load():
            gc.collect()
            assert all(ref() is None for ref in alive), f"an earlier object's rows are still held when {obj} is read"
            own = gfo[gfo["object"] == obj].copy(), minima[minima["object"] == obj].copy()
            alive.append(weakref.ref(own[0]))
            read.append(obj)
            return own

        return load

    settings = study_analysis_settings(null_draws=10)
    study_tables([(obj, loader(obj)) for obj in ("c", "a", "b")], SETS_CONFIG, 3, settings)
    assert read == ["a", "b", "c"]
