"""Which contacts count: the load-carrying selection of a contacts table (hand-built rows)."""

import numpy as np
import pandas as pd
import pytest

from synergrasp import table_contracts
from synergrasp.optimisation.mechanics import read_grasps
from synergrasp.simulation.contacts import load_carrying_contacts


def _row(pose: int, links: list[int], loads: list[float], status: str = "grasp") -> dict:
    m = len(links)
    return {
        "object": "a",
        "pose": pose,
        "alpha_deg": 0.0,
        "beta_deg": 0.0,
        "status": status,
        "q": [0.0] * 19,
        "finger_state": ["contact"] * 5,
        "n_contacts": m,
        "contact_link": links,
        "contact_point": [float(10 * k + c) for k in range(m) for c in range(3)],
        "contact_normal": [1.0, 0.0, 0.0] * m,
        "jacobian": [float(100 * r + c) for r in range(3 * m) for c in range(19)],
        "object_center": [0.0] * 3,
        "object_rotation": list(np.eye(3).ravel()),
        "max_penetration_mm": 0.1,
        "closure_model": "dynamic",
        "contact_normal_force_N": loads,
        "object_translation_mm": [0.0] * 3,
        "object_rotation_deg": 0.0,
        "settled": True,
    }


def _table(rows: list[dict]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=list(table_contracts.CONTACTS.names))


def test_only_contacts_at_or_above_the_threshold_are_kept_with_their_rows():
    table = _table([_row(0, [0, 3, 7], [2.0, 0.005, 0.01]), _row(1, [5], [1.0])])
    out = load_carrying_contacts(table, 0.01)
    first = out.iloc[0]
    assert first["n_contacts"] == 2 and list(first["contact_link"]) == [0, 7]
    assert list(first["contact_point"]) == [0.0, 1.0, 2.0, 20.0, 21.0, 22.0]
    assert list(first["contact_normal_force_N"]) == [2.0, 0.01]
    jac = np.asarray(first["jacobian"]).reshape(6, 19)
    assert list(jac[:, 0]) == [0.0, 100.0, 200.0, 600.0, 700.0, 800.0]  # rows of contacts 0 and 2
    grasp = read_grasps(out)[0]
    assert grasp.n_contacts == 2 and grasp.jacobian.shape == (6, 19)
    pd.testing.assert_series_equal(out.iloc[1], table.iloc[1], check_names=False)  # nothing to drop


def test_a_grasp_without_a_loaded_contact_has_no_contact_and_other_statuses_stay():
    table = _table([_row(0, [3, 7], [0.0, 0.001]), _row(1, [], [], status="lost")])
    out = load_carrying_contacts(table, 0.01)
    assert list(out["status"]) == ["no_contact", "lost"]
    assert list(out["n_contacts"]) == [0, 0] and read_grasps(out) == [None, None]


def test_a_table_without_loads_cannot_be_selected_by_load():
    table = _table([_row(0, [3], [np.nan])])
    with pytest.raises(ValueError, match="pose 0: the closure model .* recorded no contact loads"):
        load_carrying_contacts(table, 0.01)
