"""tools/closure_agreement.py: the agreement in distribution (per object counts against the
band the reference's copies span), on hand-made tables."""

import importlib.util
from pathlib import Path

import pandas as pd
import pytest

SPEC = importlib.util.spec_from_file_location("closure_agreement", Path(__file__).parents[1] / "tools" / "closure_agreement.py")
closure_agreement = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(closure_agreement)


def table(grasps: int, verdicts: int, n: int = 60) -> pd.DataFrame:
    """One object, n poses: the first ``grasps`` are grasps, the first ``verdicts`` of them force closure."""
    return pd.DataFrame(
        {
            "object": "obj",
            "pose": range(n),
            "status": ["grasp"] * grasps + ["lost"] * (n - grasps),
            "force_closure": [True] * verdicts + [False] * (n - verdicts),
        }
    )


def band(table: pd.DataFrame, count: str) -> pd.Series:
    return table.set_index("count").loc[count]


def test_band_is_the_copies_range_widened_by_one_binomial_standard_error():
    # copies: 10 and 14 grasps of 60. se(10) = √(60·p(1−p)), p = 10.5/61 -> 2.924; se(14), p = 14.5/61 -> 3.297
    copies = [table(10, 0), table(14, 0)]
    result = band(closure_agreement.distribution_agreement(table(12, 0), copies), "grasps")
    assert (result["copies_min"], result["copies_max"]) == (10, 14)
    assert result["band_low"] == pytest.approx(10 - 2.9241, abs=1e-3)
    assert result["band_high"] == pytest.approx(14 + 3.2973, abs=1e-3)
    inside = {
        k: bool(band(closure_agreement.distribution_agreement(table(k, 0), copies), "grasps")["agrees"])
        for k in (6, 7, 8, 17, 18)
    }
    assert inside == {6: False, 7: False, 8: True, 17: True, 18: False}


def test_a_count_of_zero_in_every_copy_still_has_a_band_below_one():
    # copies without any verdict: p = 0.5/61, se = 0.699: 0 agrees, 1 does not
    copies = [table(10, 0), table(12, 0)]
    agree = closure_agreement.distribution_agreement(table(11, 0), copies)
    disagree = closure_agreement.distribution_agreement(table(11, 1), copies)
    assert band(agree, "force_closure")["band_high"] == pytest.approx(0.699, abs=1e-3)
    assert agree["agrees"].all() and not band(disagree, "force_closure")["agrees"]
    assert band(disagree, "grasps")["agrees"]  # each count judged on its own


def test_every_object_is_judged():
    two = pd.concat([table(10, 5), table(40, 30).assign(object="obj2")], ignore_index=True)
    moved = pd.concat([table(10, 5), table(20, 30).assign(object="obj2")], ignore_index=True)
    result = closure_agreement.distribution_agreement(moved, [two])
    assert result[["object", "count", "agrees"]].values.tolist() == [
        ["obj", "grasps", True],
        ["obj", "force_closure", True],
        ["obj2", "grasps", False],
        ["obj2", "force_closure", True],
    ]
    with pytest.raises(ValueError, match="at least one copy"):
        closure_agreement.distribution_agreement(two, [])
