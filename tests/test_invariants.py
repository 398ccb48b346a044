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
