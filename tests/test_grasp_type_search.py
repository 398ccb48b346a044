"""Version 3 of the placement search (docs/placement_search.md, pre-registered): the grasp type
searched only where the hand can make it, the fallback chain power -> precision -> any, no
target chosen among all-zero scores, and the region grown where the chosen target lies on it."""

from __future__ import annotations

from dataclasses import replace

import pandas as pd
import pytest

from synergrasp.config import defaults, overlay
from synergrasp.optimisation import placement_search
from synergrasp.optimisation.grasp_type_search import KEPT, FallbackParams, fallback_line, search_with_fallback, type_label
from synergrasp.optimisation.placement_search import SearchResult, SearchStepParams, TargetScore, grown_region, search_object
from synergrasp.simulation.reach import HandReach
from synergrasp.simulation.shapes.box import Box

CUBE60 = Box((60.0, 60.0, 60.0))
BAR = Box((100.0, 60.0, 100.0))
ON = FallbackParams(True, 0.0, 1.5)


def _reach(d_max=27.0, aperture=156.5):
    return HandReach(pd.DataFrame({"press_mm": [5.0, d_max], "aperture_mm": [float("nan"), aperture]}), 9.5)


def _result(grasp_type, typed):
    """A search result whose targets score ``typed`` (%), best first."""
    scores = tuple(TargetScore((9.5 + 10 * k, 0.0, 60.0), 27, float(t), 90.0, 1.0, 4.0) for k, t in enumerate(typed))
    return SearchResult("obj3", scores, {s.target_mm: 0 for s in scores}, grasp_type, ((9.5, 49.5),) * 3)


class _Searches:
    """run_search stand-in: the typed shares each grasp type's search gives; records the calls."""

    def __init__(self, **typed):
        self.typed, self.calls = typed, []

    def __call__(self, grasp_type):
        self.calls.append(grasp_type)
        return _result(grasp_type, self.typed[grasp_type])


def _palm_centre():
    return _result("any", [0.0])


def test_an_infeasible_stated_type_is_not_searched_and_falls_back_to_precision_of_the_same_class():
    runs = _Searches(precision=[64.0, 60.0])
    result = search_with_fallback("power", CUBE60, _reach(), ON, runs, _palm_centre)
    assert runs.calls == ["precision"]
    assert (result.stated_type, result.effective_type) == ("power-circular", "precision-circular")
    assert "power-circular infeasible for this hand: thickness 60 mm > d_max 27 mm" in result.type_reason
    assert result.chosen.typed_percent == 64.0
    assert fallback_line(result).startswith("obj3: stated grasp type power-circular, effective precision-circular")
    bar = search_with_fallback("power", BAR, _reach(), ON, _Searches(precision=[30.0]), _palm_centre)
    assert (bar.stated_type, bar.effective_type) == ("power-prismatic", "precision-prismatic")


def test_a_feasible_stated_type_with_a_score_is_kept():
    runs = _Searches(power=[40.0, 0.0])
    result = search_with_fallback("power", CUBE60, _reach(d_max=79.0), ON, runs, _palm_centre)
    assert runs.calls == ["power"] and result.effective_type == "power-circular" and result.type_reason == KEPT
    assert fallback_line(result) is None


def test_targets_that_all_score_zero_are_never_chosen_the_search_falls_back_instead():
    runs = _Searches(power=[0.0, 0.0, 0.0], precision=[0.0, 0.0], any=[12.0, 5.0])
    result = search_with_fallback("power", CUBE60, _reach(d_max=79.0), ON, runs, _palm_centre)
    assert runs.calls == ["power", "precision", "any"]
    assert result.effective_type == "any" and result.chosen.typed_percent == 12.0
    assert "power-circular: the best of 3 targets scores T = 0 %" in result.type_reason
    assert "precision-circular: the best of 2 targets scores T = 0 %" in result.type_reason


def test_when_every_type_scores_zero_the_box_goes_to_the_palm_centre_chosen_by_no_score():
    runs = _Searches(precision=[0.0], any=[0.0, 0.0])
    result = search_with_fallback("precision", CUBE60, _reach(), ON, runs, _palm_centre)
    assert runs.calls == ["precision", "any"]
    assert len(result.ranked) == 1 and "chosen by no score" in result.type_reason


def test_a_minimum_share_stated_in_advance_is_a_further_trigger():
    runs = _Searches(precision=[40.0], any=[90.0])
    strict = search_with_fallback("precision", CUBE60, _reach(), replace(ON, min_typed_percent=50.0), runs, _palm_centre)
    assert strict.effective_type == "any" and "(<= min_typed_percent 50)" in strict.type_reason
    assert search_with_fallback("precision", CUBE60, _reach(), ON, runs, _palm_centre).effective_type == "precision-circular"


def test_version_2_searches_the_stated_type_only_even_when_infeasible_and_all_zero():
    runs = _Searches(power=[0.0, 0.0])
    result = search_with_fallback("power", CUBE60, _reach(), replace(ON, enabled=False), runs, _palm_centre)
    assert runs.calls == ["power"] and result.effective_type == result.stated_type == "power-circular"


def test_labels_carry_the_shape_class_except_any():
    assert type_label("power", "prismatic") == "power-prismatic" and type_label("any", "circular") == "any"


def test_the_region_grows_one_step_where_the_target_lies_on_it_within_the_hands_reach():
    region = ((19.5, 49.5), (-50.0, 30.0), (60.0, 140.0))
    reach = ((9.0, 55.0), (-48.0, 30.0), (14.0, 190.0))
    # on the upper z bound: grows to 150; on the outer x bound: 59.5 would pass the reach (55)
    assert grown_region(region, (49.5, 0.0, 140.0), 10.0, reach) == ((19.5, 49.5), (-50.0, 30.0), (60.0, 150.0))
    # on the lower z bound and y's upper bound (at the reach): z to 50, y stays
    assert grown_region(region, (29.5, 30.0, 60.0), 10.0, reach) == ((19.5, 49.5), (-50.0, 30.0), (50.0, 140.0))
    assert grown_region(region, (29.5, 0.0, 100.0), 10.0, reach) == region  # inside: nothing grows
    pinned = ((9.5, 9.5), (-50.0, 30.0), (20.0, 100.0))  # the power region's x: the palm face
    assert grown_region(pinned, (9.5, 0.0, 60.0), 10.0, reach) == pinned


class _FakeScorer:
    """TargetScorer stand-in: T rises with z (30 % at z = 60, +5 points per 10 mm); every pose in force
    closure."""

    def __init__(self, *args, **kwargs):
        pass

    def __call__(self, target):
        t = tuple(float(v) for v in target)
        return TargetScore(t, 27, 30.0 + 0.5 * (t[2] - 60.0) - 0.1 * abs(t[1]), 100.0, 1.0, 4.0)

    def close(self):
        pass


def _sim(**search):
    cfg = overlay(
        defaults(),
        {
            "placement": {"search": {"region_mm": {"precision": {"z": [60.0, 100.0]}}, "grow_region": True, **search}},
            "objects": {"obj1": {"grasp_type": "precision"}},
        },
    )
    return SearchStepParams.from_config(cfg, "obj1")


def test_the_search_grows_its_region_until_the_chosen_target_is_inside_or_the_reach_stops_it(hand, synergies, monkeypatch):
    monkeypatch.setattr(placement_search, "TargetScorer", _FakeScorer)
    sim = _sim()
    bound = ((9.0, 55.0), (-48.0, 30.0), (14.0, 130.0))

    def run(params, bound_mm):
        return search_object(
            hand, synergies, sim.object, sim.placement, sim.closure, sim.gfo, None, params, 90.0, bound_mm=bound_mm
        )

    grown = run(sim.search, bound)
    assert grown.chosen.target_mm[2] == 130.0  # the best z the reach allows (bound 130)
    assert grown.region_mm[2] == (60.0, 130.0)
    # T does not depend on x: the tie rules take the x nearest the palm centre, on the lower
    # bound 19.5, so x grows one step to 9.5 (the reach's bound 9 stops the next)
    assert grown.region_mm[0] == (9.5, 49.5) and grown.chosen.target_mm[0] == 9.5
    fixed = run(replace(sim.search, grow_region=False), bound)
    assert fixed.chosen.target_mm[2] == 100.0 and fixed.region_mm[2] == (60.0, 100.0)
    # the non-growing search is unchanged by the new code path: same targets, same rounds
    assert run(sim.search, None).table(10.0).equals(fixed.table(10.0))


def test_bad_fallback_settings_are_refused_naming_the_key():
    from synergrasp.config import ConfigError, validate_config

    bad = overlay(defaults(), {"placement": {"search": {"fallback": {"min_typed_percent": 100.0}}}})
    with pytest.raises(ConfigError) as err:
        validate_config(bad)
    assert "'placement.search.fallback.min_typed_percent'" in str(err.value)


def test_the_graspable_table_reads_each_searched_objects_stated_and_effective_type():
    from synergrasp.analysis.graspability import fallback_lines, grasp_types_of

    searched = search_with_fallback("power", CUBE60, _reach(), ON, _Searches(precision=[64.0]), _palm_centre)
    types = grasp_types_of({"obj1": "precision", "obj3": "power"}, [searched.table(10.0)])
    assert types["obj1"] == ("precision", "precision", "")  # not searched: the configured type
    stated, effective, reason = types["obj3"]
    assert (stated, effective) == ("power-circular", "precision-circular") and "infeasible" in reason
    table = pd.DataFrame(
        [{"object": o, "stated_type": t[0], "effective_type": t[1], "type_reason": t[2]} for o, t in types.items()]
    )
    assert fallback_lines(table) == [f"obj3: stated grasp type power-circular, effective precision-circular ({reason})"]
