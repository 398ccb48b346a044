"""Every claim's verdict on hand-made tables where it holds, where it does not, and on a tie."""
import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.claims import FAILS, HOLDS, UNDEFINED, claims_table, combine, compare, compare_lower_force

SINGLES = {1: 50.0, 2: 10.0, 3: 12.0, 4: 20.0, 5: 25.0, 6: 5.0, 7: 5.0}
PAIRS = {(1, 5): 80.0, (1, 4): 70.0, (1, 2): 60.0, (1, 3): 60.0}
RATIOS = {1: 1.2, 2: 2.0, 3: 2.0, 4: 1.3, 5: 1.1, 6: 2.5, 7: 3.0}


def inputs(singles=None, pairs=None, ratios=None, k7=(100.0, 99.6), lost=0, kept=95.0, null_high=40.0):
    """Tables on which every claim holds (with the defaults)."""
    singles, pairs, ratios = {**SINGLES, **(singles or {})}, {**PAIRS, **(pairs or {})}, {**RATIOS, **(ratios or {})}
    rates = [(str(i), r) for i, r in singles.items()]
    for i in range(1, 8):
        for j in range(i + 1, 8):
            rates.append((f"{i}-{j}", pairs.get((i, j), 30.0)))
    mean_rates = pd.DataFrame(rates, columns=["set_id", "success_rate"])
    table2 = pd.DataFrame({"object": ["a", "b"], 7: list(k7)})
    preservation = pd.DataFrame([{"object": "all", "pairs": "all", "preserved_percent": kept,
                                  "null_mean_percent": 30.0, "null_low_percent": 20.0, "null_high_percent": null_high}])
    per_object = pd.DataFrame([(o, str(i), r * f) for o, f in (("a", 1.0), ("b", 1.1)) for i, r in ratios.items()],
                              columns=["object", "set_id", "force_ratio_median"])
    return table2, lost, preservation, mean_rates, per_object


def verdicts(**changes) -> list[str]:
    return claims_table(*inputs(**changes)).set_index("claim")["verdict"].tolist()


def test_every_claim_holds_on_the_reference_tables():
    table = claims_table(*inputs())
    assert table["verdict"].tolist() == [HOLDS] * 7
    assert list(table.columns) == ["claim", "statement", "tested_by", "measured", "verdict"]
    assert table["tested_by"].str.len().min() > 0


@pytest.mark.parametrize("changes, claim, verdict", [
    (dict(k7=(100.0, 99.0)), 1, FAILS),
    (dict(k7=(100.0, np.nan)), 1, UNDEFINED),
    (dict(lost=3), 2, FAILS),
    (dict(lost=None), 2, UNDEFINED),
    (dict(kept=85.0), 3, FAILS),            # below 90 %
    (dict(kept=95.0, null_high=96.5), 3, FAILS),   # not above chance
    (dict(kept=90.5), 3, UNDEFINED),        # a tie with 90 %
    (dict(singles={5: 60.0}), 4, FAILS),
    (dict(singles={4: 50.5}), 4, UNDEFINED),
    (dict(singles={3: 30.0}), 5, FAILS),    # S3 above S4
    (dict(pairs={(1, 2): 75.0}), 5, FAILS),  # {S1,S2} above {S1,S4}
    (dict(singles={3: 19.5}), 5, UNDEFINED),
    (dict(pairs={(2, 3): 90.0}), 6, FAILS),
    (dict(pairs={(1, 4): 79.5}), 6, UNDEFINED),
    (dict(ratios={3: 1.0}), 7, FAILS),
    (dict(ratios={3: 1.33}), 7, UNDEFINED),  # within 5 % of S4's 1.3
    (dict(ratios={4: np.nan}), 7, UNDEFINED),  # S4 never succeeds alone
])
def test_each_claim_fails_or_is_undefined(changes, claim, verdict):
    got = verdicts(**changes)
    assert got[claim - 1] == verdict
    assert all(v == HOLDS for i, v in enumerate(got, 1) if i != claim)  # the others are untouched


def test_comparison_rules():
    assert compare(52.0, 50.0) == HOLDS and compare(50.5, 50.0) == UNDEFINED and compare(48.0, 50.0) == FAILS
    assert compare(np.nan, 1.0) == UNDEFINED
    assert compare_lower_force(1.0, 1.1) == HOLDS and compare_lower_force(1.0, 1.04) == UNDEFINED
    assert compare_lower_force(1.2, 1.0) == FAILS
    assert combine([HOLDS, HOLDS]) == HOLDS and combine([HOLDS, UNDEFINED]) == UNDEFINED
    assert combine([UNDEFINED, FAILS]) == FAILS
