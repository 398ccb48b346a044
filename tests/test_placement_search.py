"""The placement search's objective, tie rules, region, pose subset and what it passes to the
solver (docs/placement_search.md, pre-registered)."""

from __future__ import annotations

import math
import random
from dataclasses import replace

import numpy as np
import pytest

from synergrasp.config import defaults, overlay
from synergrasp.optimisation import placement_search
from synergrasp.simulation.opposition import GRASP_TYPES
from synergrasp.optimisation.placement_search import (
    SearchStepParams,
    SearchParams,
    TargetScore,
    distinct_ranks,
    pose_subset,
    rank_targets,
    region_lattice,
    score_target,
    search_object,
)

REFERENCE = (9.5, -9.0, 52.0)


def _score(target, fc, force, contacts):
    return TargetScore(tuple(float(v) for v in target), 27, float(fc), float(fc), float(force), float(contacts))


def test_score_is_the_force_closure_share_the_median_force_over_weight_and_contacts():
    fc = np.array([True, True, False, True, False])
    force = np.array([20.0, 40.0, np.nan, 100.0, 5.0])  # the 5 N of a pose not in force closure is not read
    contacts = np.array([3, 5, 0, 6, 2])
    s = score_target((1, 2, 3), fc, force, contacts, weight_N=10.0)
    assert s.force_closure_percent == pytest.approx(60.0)
    assert s.median_force_per_weight == pytest.approx(4.0)  # median of 20, 40, 100 N over 10 N
    assert s.median_contacts == 3.0
    assert s.n_poses == 5 and s.target_mm == (1.0, 2.0, 3.0)


def test_score_counts_the_poses_of_the_grasp_type_in_force_closure_and_their_forces_only():
    fc = np.array([True, True, False, True, False])
    force = np.array([20.0, 40.0, np.nan, 100.0, 5.0])
    typed = np.array([True, False, True, True, False])  # pose 2 is of the type but not in force closure
    s = score_target((0, 0, 0), fc, force, np.array([3, 5, 0, 6, 2]), 10.0, of_type=typed)
    assert s.typed_percent == pytest.approx(40.0)  # poses 0 and 3
    assert s.force_closure_percent == pytest.approx(60.0)  # reported, not scored
    assert s.median_force_per_weight == pytest.approx(6.0)  # median of 20 and 100 N over 10 N
    none = score_target((0, 0, 0), fc, force, np.array([3, 5, 0, 6, 2]), 10.0, of_type=np.zeros(5, bool))
    assert none.typed_percent == 0.0 and math.isinf(none.median_force_per_weight)
    # the tie rules rank by the typed share: 100 % force closure of the wrong type loses
    ranked = rank_targets([s, replace(none, target_mm=(5.0, 5.0, 5.0))], REFERENCE, 2.0, 0.05)
    assert ranked[0].target_mm == (0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="equal-length"):
        score_target((0, 0, 0), fc, force, np.zeros(5), 1.0, of_type=np.ones(4, bool))


def test_score_without_force_closure_has_infinite_force_and_bad_input_is_refused():
    s = score_target((0, 0, 0), np.zeros(3, bool), np.full(3, np.nan), np.array([0, 1, 2]), 9.81)
    assert s.force_closure_percent == 0.0 and math.isinf(s.median_force_per_weight)
    # a force-closure pose without a force (the solvers disagree) is left out of the median
    s = score_target((0, 0, 0), np.array([True, True]), np.array([np.nan, 30.0]), np.array([4, 4]), 10.0)
    assert s.median_force_per_weight == pytest.approx(3.0)
    with pytest.raises(ValueError, match="equal-length"):
        score_target((0, 0, 0), np.zeros(3, bool), np.zeros(2), np.zeros(3), 1.0)
    with pytest.raises(ValueError, match="weight_N"):
        score_target((0, 0, 0), np.zeros(3, bool), np.zeros(3), np.zeros(3), 0.0)


def _ranked(scores, band=2.0, rel=0.05):
    return [s.target_mm for s in rank_targets(scores, REFERENCE, band, rel)]


def test_shares_within_the_tie_band_are_decided_by_the_lower_force():
    a = _score((10, 0, 60), 80.0, 3.0, 5)
    b = _score((20, 0, 60), 78.5, 1.0, 5)  # 1.5 points lower: tied, lower force wins
    c = _score((30, 0, 60), 77.0, 0.5, 9)  # 3 points below the best: not tied
    assert _ranked([a, b, c]) == [b.target_mm, a.target_mm, c.target_mm]
    # without a band the share alone decides
    assert _ranked([a, b, c], band=0.0) == [a.target_mm, b.target_mm, c.target_mm]


def test_forces_within_five_percent_are_decided_by_more_contacts_then_the_palm_centre_then_xyz():
    a = _score((10, 0, 60), 50.0, 2.00, 4)
    b = _score((20, 0, 60), 50.0, 2.09, 6)  # force 4.5 % higher: tied, more contacts wins
    c = _score((30, 0, 60), 50.0, 2.20, 9)  # 10 % higher: not tied
    assert _ranked([a, b, c])[0] == b.target_mm
    near = _score((9.5, -9, 62), 50.0, 2.0, 4)  # 10 mm from the palm centre
    far = _score((9.5, -9, 92), 50.0, 2.0, 4)
    assert _ranked([far, near])[0] == near.target_mm
    left = _score((9.5, -19, 52), 50.0, 2.0, 4)  # same distance as `right`: smaller (x, y, z) first
    right = _score((9.5, 1, 52), 50.0, 2.0, 4)
    assert _ranked([right, left]) == [left.target_mm, right.target_mm]


def test_targets_without_force_closure_stay_tied_on_force():
    a = _score((10, 0, 60), 0.0, math.inf, 2)
    b = _score((20, 0, 60), 0.0, math.inf, 3)
    assert _ranked([a, b])[0] == b.target_mm


def test_ranking_does_not_depend_on_the_order_of_the_targets():
    rng = np.random.default_rng(3)
    scores = [
        _score(
            (x, y, z), rng.choice([0.0, 48.0, 50.0, 51.0, 70.0, 71.5]), rng.choice([1.0, 1.04, 2.0, math.inf]), rng.integers(2, 7)
        )
        for x in (9.5, 19.5)
        for y in (-10, 0, 10)
        for z in (40, 50, 60)
    ]
    first = _ranked(scores)
    for seed in range(5):
        shuffled = list(scores)
        random.Random(seed).shuffle(shuffled)
        assert _ranked(shuffled) == first
    assert sorted(first) == sorted(s.target_mm for s in scores)


def test_distinct_ranks_skip_targets_too_close_to_a_better_one():
    ranked = [_score(t, 50, 1, 4) for t in [(0, 0, 0), (5, 0, 0), (10, 0, 0), (0, 0, 20)]]
    assert distinct_ranks(ranked, 10.0) == [1, 0, 2, 3]
    assert distinct_ranks(ranked, 0.0) == [1, 2, 3, 4]


def _params(**changes):
    return replace(SearchStepParams.from_config(defaults(), "obj1").search, **changes)


def test_each_grasp_types_default_region_is_a_20_mm_lattice_refined_at_10_mm():
    cfg = defaults()
    lattices = {}
    for kind in GRASP_TYPES:
        cfg["objects"]["obj1"]["grasp_type"] = kind
        params = SearchStepParams.from_config(cfg, "obj1").search
        assert params.spacing_mm <= 10.0 and params.grasp_type == kind
        lattices[kind] = region_lattice(params, params.coarse_spacing_mm)
        np.testing.assert_array_equal(np.unique(lattices[kind][:, 1]), [-50, -30, -10, 10, 30])
    # any: the palm face and the fingers, out to the curling fingers' reach (the first version's region)
    assert lattices["any"].shape == (135, 3)
    np.testing.assert_array_equal(np.unique(lattices["any"][:, 0]), [9.5, 29.5, 49.5])
    # power: the box brought onto the palm face (x = 9.5), centred over the palm
    assert lattices["power"].shape == (25, 3)
    np.testing.assert_array_equal(np.unique(lattices["power"][:, 0]), [9.5])
    np.testing.assert_array_equal(np.unique(lattices["power"][:, 2]), [20, 40, 60, 80, 100])
    # precision: in front of the fingers, where the thumb's and the fingers' tips meet
    assert lattices["precision"].shape == (50, 3)
    np.testing.assert_array_equal(np.unique(lattices["precision"][:, 0]), [19.5, 39.5])
    np.testing.assert_array_equal(np.unique(lattices["precision"][:, 2]), [60, 80, 100, 120, 140])
    params = _params()
    with pytest.raises(ValueError, match="whole multiple"):
        SearchParams(params.region_mm, 15.0, 10.0, 3, 4, 30.0, 15.0, 2.0, 0.05)


def test_scored_poses_are_the_first_alpha_period_on_the_search_steps():
    sim = SearchStepParams.from_config(defaults(), "obj1")
    poses = pose_subset(sim.placement, 90.0, sim.search)
    from synergrasp.simulation.placement import pose_grid

    grid = pose_grid(sim.placement)
    angles = [grid.angles_deg(p) for p in poses]
    assert len(poses) == 27 == len(set(poses))
    assert sorted({a for a, _ in angles}) == [-180.0, -150.0, -120.0]
    assert sorted({b for _, b in angles}) == list(np.arange(-60.0, 61.0, 15.0))
    assert len(pose_subset(sim.placement, 180.0, sim.search)) == 54


def _tiny(obj="obj1", **search):
    """The study's search of ``obj`` on a toy region (2 coarse targets, 4 poses, 1 round)."""
    cfg = overlay(
        defaults(),
        {
            "placement": {
                "search": {
                    "region_mm": {kind: {"x": [9.5, 9.5], "y": [-10.0, -10.0], "z": [60.0, 80.0]} for kind in GRASP_TYPES},
                    "pose_alpha_step_deg": 60.0,
                    "pose_beta_step_deg": 60.0,
                    "refine_top": 1,
                    "max_rounds": 1,
                    **search,
                }
            }
        },
    )
    return SearchStepParams.from_config(cfg, obj)


def _run(sim, hand, synergies, processes=1):
    full = placement_search.full_synergy_set(synergies.matrix, sim.full_set_size)
    return search_object(
        hand,
        synergies,
        sim.object,
        sim.placement,
        sim.closure,
        sim.gfo,
        full,
        sim.search,
        period_deg=90.0,
        processes=processes,
        opposition=sim.opposition,
    )


def test_the_search_passes_the_solver_the_full_synergy_set_and_nothing_else(hand, synergies, monkeypatch):
    seen = []
    real = placement_search.optimise_grasps

    def spy(grasps, sets, params, **kwargs):
        seen.append((sets, params, kwargs))
        return real(grasps, sets, params, **kwargs)

    monkeypatch.setattr(placement_search, "optimise_grasps", spy)
    sim = _tiny(max_rounds=0)
    result = _run(sim, hand, synergies)
    assert len(seen) == len(result.ranked) == 2  # one solver call per target
    for sets, params, kwargs in seen:
        assert sets.sets == (tuple(range(1, 16)),)  # {S1..S15}, one set, no subset
        np.testing.assert_array_equal(sets.matrix, synergies.matrix)
        assert params == sim.gfo and kwargs == {}


def test_the_search_is_deterministic_for_any_number_of_processes(hand, synergies):
    sim = _tiny()
    one = _run(sim, hand, synergies).table(sim.distinct_mm)
    again = _run(sim, hand, synergies).table(sim.distinct_mm)
    two = _run(sim, hand, synergies, processes=2).table(sim.distinct_mm)
    assert one.equals(again) and one.equals(two)
    assert one["chosen"].sum() == 1 and one["rank"].tolist() == list(range(1, len(one) + 1))
    assert (one["round"] == 1).any()  # the refinement scored 10 mm neighbours of the best target
    assert set(np.diff(np.sort(one["z_mm"].unique()))) == {10.0}


def test_bad_search_settings_are_refused_before_any_job_naming_the_key():
    from synergrasp.config import ConfigError, validate_config

    bad = overlay(
        defaults(),
        {
            "placement": {"search": {"region_mm": {"any": {"x": [9.5, 0.0]}}}},
            "objects": {"obj1": {"placement": {"search": {"coarse_spacing_mm": 25.0}}}},
        },
    )
    with pytest.raises(ConfigError) as err:
        validate_config(bad)
    assert "'placement.search.region_mm.any.x'" in str(err.value)
    assert "'objects.obj1.placement.search.coarse_spacing_mm'" in str(err.value)
