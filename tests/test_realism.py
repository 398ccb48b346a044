"""The grasp-realism table on hand-made contacts and gfo tables (counts checked by hand),
and its figure."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from synergrasp import table_contracts
from synergrasp.analysis.realism import NORMAL_FORCE_COLUMN, grasp_labels, grasp_realism, link_categories
from synergrasp.simulation.opposition import HandAxes, OppositionRule
from synergrasp.simulation.shapes import shape_from_config

_RULE = OppositionRule(45.0, 1.0)
_BOX = shape_from_config({"box": {"size_mm": [10.0, 20.0, 30.0]}})

# Links of the shipped hand: 0 palm, 3 thumb_distal, 5 index_proximal, 6 index_middle,
# 7 index_distal, 11 middle_distal, 15 ring_distal, 19 little_distal.
_POSES = [  # (status, contact links, normal forces N)
    ("grasp", [3, 7], [0.5, 0.0]),
    ("grasp", [0, 3, 6, 11], [1.0, 2.0, 0.0, 3.0]),
    ("intersects_open_hand", [], []),
    ("grasp", [5, 7, 11, 15, 19, 3, 0], [0.0] * 7),
]


def _contacts(obj: str = "a", poses=_POSES, normals=None, points=None) -> pd.DataFrame:
    rows = []
    for pose, (status, links, forces) in enumerate(poses):
        m = len(links)
        rows.append(
            {
                "object": obj,
                "pose": pose,
                "alpha_deg": 5.0 * pose,
                "beta_deg": 0.0,
                "status": status,
                "q": [0.0] * 19,
                "finger_state": [],
                "n_contacts": m,
                "contact_link": links,
                "contact_point": [0.0] * 3 * m if points is None else points[pose],
                "contact_normal": [1.0, 0.0, 0.0] * m if normals is None else normals[pose],
                "jacobian": [0.0] * 57 * m,
                "object_center": [0.0] * 3,
                "object_rotation": list(np.eye(3).ravel()),
                "max_penetration_mm": 0.0,
                NORMAL_FORCE_COLUMN: forces,
                "closure_model": "kinematic",
                "object_translation_mm": [0.0] * 3,
                "object_rotation_deg": 0.0,
                "settled": True,
            }
        )
    return pd.DataFrame(rows)


def _gfo(obj: str = "a") -> pd.DataFrame:
    full = [(3, False, np.nan), (6, True, 10.0), (0, False, np.nan), (6, True, 30.0)]  # rank_G, fc, |f| N
    rows = []
    for pose, (rank, fc, force) in enumerate(full):
        for set_id, values in (("1-2", (rank, fc, force)), ("1", (6, True, 1000.0))):  # "1" must not be read
            rows.append(
                {
                    "object": obj,
                    "pose": pose,
                    "alpha_deg": 5.0 * pose,
                    "beta_deg": 0.0,
                    "set_id": set_id,
                    "n_synergies": len(set_id.split("-")),
                    "status": "feasible" if values[1] else "infeasible",
                    "load_feasible": values[1],
                    "force_closure_def1": values[1],
                    "force_norm": values[2],
                    "e_s": 1,
                    "rank_G": values[0],
                    "n_contacts": 0,
                    "iterations": 1,
                    "solver": "ipm",
                }
            )
    return pd.DataFrame(rows)


def _checks(contacts: pd.DataFrame) -> pd.DataFrame:
    """Per-grasp equilibrium checks, made up: residual 0.1 × pose, pose p has p contacts pushed
    outside their cone (the real ones are tested in tests/test_equilibrium.py)."""
    grasps = contacts[contacts["status"] == "grasp"]
    return pd.DataFrame(
        {
            "object": grasps["object"],
            "closure_model": grasps["closure_model"],
            "pose": grasps["pose"],
            "torque_residual": 0.1 * grasps["pose"],
            "s1_outside_cone": grasps["pose"],
        }
    )


def _table(hand, contacts=None, gfo=None, load_threshold_N=0.01, grasp_type="power"):
    contacts = _contacts() if contacts is None else contacts
    labels = grasp_labels(contacts, HandAxes.from_hand(hand), _RULE, {"a": _BOX})
    return grasp_realism(
        contacts,
        _gfo() if gfo is None else gfo,
        _checks(contacts),
        hand.link_names,
        hand.link_finger,
        "1-2",
        {"a": 10.0},
        load_threshold_N,
        labels,
        {"a": grasp_type},
    )


def test_counts_and_shares_by_hand(hand):
    table = _table(hand)
    assert list(table.columns) == list(table_contracts.GRASP_REALISM.names)
    row = table.iloc[0]
    assert (row["object"], row["closure_model"]) == ("a", "kinematic")
    assert (row["poses"], row["simulated"], row["dropped"]) == (4, 3, 1)
    assert row["dropped_by"] == "intersects_open_hand: 1"
    assert row["contacts_median"] == 4.0  # m = 2, 4, 7
    third = 100.0 / 3.0
    expected_bins = {"pct_m0": 0, "pct_m1": 0, "pct_m2": third, "pct_m3": 0, "pct_m4": third, "pct_m5": 0, "pct_m6plus": third}
    for column, value in expected_bins.items():
        assert row[column] == pytest.approx(value), column
    assert row["pct_thumb"] == pytest.approx(100.0)  # link 3 in every grasp
    assert row["pct_palm"] == pytest.approx(2 * third)  # poses 1 and 3
    assert row["pct_proximal_or_middle"] == pytest.approx(2 * third)  # pose 1 (index_middle), 3 (index_proximal)
    assert row["pct_rank6"] == pytest.approx(2 * third)  # full set: ranks 3, 6, 6 over the grasps
    assert row["pct_force_closure"] == pytest.approx(2 * third)
    assert row["median_force_per_weight"] == pytest.approx(2.0)  # 10/10 and 30/10
    assert row["loaded_contacts_median"] == 1.0  # 1, 3, 0 contacts with a normal force > 0
    # index links 5, 6, 7 in poses 0, 1, 3; middle (11) in 1, 3; ring (15) and little (19) in 3
    assert (row["pct_index"], row["pct_middle"]) == (pytest.approx(100.0), pytest.approx(2 * third))
    assert (row["pct_ring"], row["pct_little"]) == (pytest.approx(third), pytest.approx(third))
    assert row["median_torque_residual"] == pytest.approx(0.1)  # 0, 0.1, 0.3
    assert row["pct_s1_outside_cone"] == pytest.approx(2 * third)  # poses 1 and 3


def test_opposition_shares_grasp_type_and_edge_contacts_by_hand(hand):
    """Pose 0: thumb pad against index pad (pad); pose 1: palm pushing out, the middle
    fingertip pushing back (palm); pose 3: everything pushing off the palm (none)."""
    x, y = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    minus = lambda v: [-c for c in v]  # noqa: E731
    normals = [minus(y) + y, x + x + x + minus(x), [], x * 7]
    # pose 0 touches the box (centred at the origin, 10 x 20 x 30 mm) at a corner and a face
    points = [[5.0, 10.0, 15.0, 5.0, 0.0, 0.0], [0.0] * 12, [], [0.0] * 21]
    contacts = _contacts(normals=normals, points=points)
    row = _table(hand, contacts).iloc[0]
    third = 100.0 / 3.0
    assert (row["pct_palm_opposition"], row["pct_pad_opposition"]) == (pytest.approx(third), pytest.approx(third))
    assert (row["pct_side_opposition"], row["pct_no_opposition"]) == (0.0, pytest.approx(third))
    assert row["grasp_type"] == "power" and row["pct_of_grasp_type"] == pytest.approx(third)
    assert row["pct_of_grasp_type_force_closure"] == pytest.approx(third)  # pose 1 is in force closure
    assert row["pct_contacts_on_edges"] == pytest.approx(100.0 / 13.0)  # 1 of the 2 + 4 + 7 contacts
    precise = _table(hand, contacts, grasp_type="precision").iloc[0]
    assert precise["pct_of_grasp_type"] == pytest.approx(third)
    assert precise["pct_of_grasp_type_force_closure"] == 0.0  # pose 0's grasp has rank 3


def test_the_index_column_and_the_link_shares_on_a_hand_made_table(hand):
    """Index touching in 1 of 3 grasps (its distal link only), a no_contact grasp counts as a
    grasp without it, a dropped pose not at all."""
    from synergrasp.analysis.realism import link_shares

    poses = [("grasp", [0, 3], []), ("grasp", [3, 7], []), ("no_contact", [], []), ("intersects_open_hand", [], [])]
    contacts = _contacts(poses=poses)
    gfo = _gfo()
    row = _table(hand, contacts, gfo).iloc[0]
    assert row["pct_index"] == pytest.approx(100.0 / 3.0)
    shares = link_shares(contacts, hand.link_names, hand.link_finger).set_index("link")["pct_grasps"]
    assert shares["index_distal"] == pytest.approx(100.0 / 3.0)
    assert shares["thumb_distal"] == pytest.approx(200.0 / 3.0)
    assert shares["palm"] == pytest.approx(100.0 / 3.0)
    assert shares["index_proximal"] == 0.0
    assert len(shares) == len(hand.link_names)


def test_force_closure_is_the_studys_definition_not_load_feasibility(hand):
    """Pose 1 holds its load only with the weight's help (feasible, strict test fails): it is
    load-feasible, not in force closure, and its force does not enter the force median."""
    gfo = _gfo()
    gfo.loc[(gfo["pose"] == 1) & (gfo["set_id"] == "1-2"), "force_closure_def1"] = False
    row = _table(hand, gfo=gfo).iloc[0]
    assert row["pct_force_closure"] == pytest.approx(100.0 / 3.0)
    assert row["pct_load_feasible"] == pytest.approx(200.0 / 3.0)
    assert row["median_force_per_weight"] == pytest.approx(3.0)  # pose 3 only: 30 N / 10 N


def test_without_normal_forces_the_loaded_count_is_nan_and_models_group(hand):
    contacts = _contacts()  # the kinematic closure records no forces: NaN per contact
    contacts[NORMAL_FORCE_COLUMN] = [[np.nan] * len(links) for links in contacts["contact_link"]]
    assert np.isnan(_table(hand, contacts)["loaded_contacts_median"].iloc[0])
    two = pd.concat([contacts.assign(closure_model="kinematic"), contacts.assign(closure_model="dynamic")])
    gfo = pd.concat([_gfo().assign(closure_model="kinematic"), _gfo().assign(closure_model="dynamic")])
    table = _table(hand, two, gfo)
    assert list(table["closure_model"]) == ["dynamic", "kinematic"]
    assert list(table["simulated"]) == [3, 3]


def test_link_categories_of_the_shipped_hand(hand):
    cats = link_categories(hand.link_names, hand.link_finger)
    assert cats["palm"] == {0}
    assert cats["thumb"] == {1, 2, 3}
    assert {hand.link_names[i] for i in cats["index"]} == {f"index_{s}" for s in ("knuckle", "proximal", "middle", "distal")}
    assert {hand.link_names[i] for i in cats["proximal_or_middle"]} == {
        "thumb_proximal",
        *(f"{f}_{s}" for f in ("index", "middle", "ring", "little") for s in ("proximal", "middle")),
    }


def test_missing_weight_or_full_set_is_one_clear_error(hand):
    labels = grasp_labels(_contacts(), HandAxes.from_hand(hand), _RULE, {"a": _BOX})
    with pytest.raises(ValueError, match=r"no weight for object\(s\) \['a'\]"):
        grasp_realism(
            _contacts(),
            _gfo(),
            _checks(_contacts()),
            hand.link_names,
            hand.link_finger,
            "1-2",
            {"b": 1.0},
            0.01,
            labels,
            {"a": "any"},
        )
    with pytest.raises(ValueError, match="full_set_id '1-2-3'"):
        grasp_realism(
            _contacts(),
            _gfo(),
            _checks(_contacts()),
            hand.link_names,
            hand.link_finger,
            "1-2-3",
            {"a": 1.0},
            0.01,
            labels,
            {"a": "any"},
        )


def test_figure_is_written_and_the_same_on_rerun(hand, tmp_path):
    from synergrasp.figures.grasp_realism import figure_grasp_realism

    table = pd.concat([_table(hand), _table(hand).assign(object="b", median_force_per_weight=np.nan)])
    for run in ("1", "2"):
        figure_grasp_realism(table, tmp_path / f"r{run}.png", tmp_path / f"r{run}.pdf")
    for ext in ("png", "pdf"):
        first = (tmp_path / f"r1.{ext}").read_bytes()
        assert len(first) > 5000
        assert first == (tmp_path / f"r2.{ext}").read_bytes()


def test_representative_grasps_follow_the_stated_rule(hand):
    from synergrasp.analysis.realism import representative_grasps

    # Patterns: {3, 7} x 3 grasps, {3, 7, 11} x 2, {7, 11, 15} x 1, {3, 7, 11, 15} x 1, one dropped pose.
    # Contacts 2, 2, 3 (two on link 7), 3, 3, 3, 4: median 3, the typical count.
    poses = [
        ("grasp", [3, 7], []),
        ("grasp", [7, 3], []),
        ("grasp", [3, 7, 7], []),
        ("grasp", [3, 7, 11], []),
        ("grasp", [3, 7, 11], []),
        ("grasp", [7, 11, 15], []),
        ("grasp", [3, 7, 11, 15], []),
        ("intersects_open_hand", [], []),
    ]
    contacts = _contacts(poses=poses)
    contacts["alpha_deg"] = [40.0, -10.0, 5.0, 0.0, 180.0, 0.0, 0.0, 0.0]
    contacts["beta_deg"] = [0.0, 0.0, 0.0, 20.0, 0.0, 0.0, 0.0, 0.0]
    chosen = representative_grasps(contacts, n=3)
    assert [tuple(p) for p in chosen["pattern"]] == [(3, 7), (3, 7, 11), (7, 11, 15)]
    assert list(chosen["reason"]) == ["most common contacts", "typical count (m = 3)", "next most common"]
    # (3, 7): poses 0, 1, 2 at |(α, β)| = 40, 10, 5 -> pose 2; (3, 7, 11): 20 vs 180 -> pose 3.
    assert list(chosen["pose"]) == [2, 3, 5]
    np.testing.assert_allclose(chosen["share_pct"], [100 * 3 / 7, 100 * 2 / 7, 100 / 7])
    assert representative_grasps(contacts[contacts["status"] != "grasp"]).empty


def test_a_closure_without_contact_is_simulated_not_dropped(hand):
    poses = _POSES + [("no_contact", [], [])]
    unsolved = _gfo().iloc[:2].assign(pose=4, rank_G=0, load_feasible=False, force_closure_def1=False, force_norm=np.nan)
    gfo = pd.concat([_gfo(), unsolved])
    row = _table(hand, _contacts(poses=poses), gfo).iloc[0]
    assert (row["poses"], row["simulated"], row["dropped"]) == (5, 4, 1)
    assert row["pct_m0"] == pytest.approx(25.0)
    assert row["pct_thumb"] == pytest.approx(75.0)
    assert row["median_force_per_weight"] == pytest.approx(2.0)


def test_a_contact_carries_load_from_the_configured_threshold_on(hand):
    """Loads 0.5 / 0 N, 1 / 2 / 0 / 3 N and 7 × 0 N: at 1 N the counts are 0, 3 and 0 (a load equal
    to the threshold counts); without a threshold nothing is known."""
    assert _table(hand, load_threshold_N=1.0)["loaded_contacts_median"].iloc[0] == 0.0
    assert _table(hand, load_threshold_N=0.6)["loaded_contacts_median"].iloc[0] == 0.0
    assert _table(hand, load_threshold_N=0.5)["loaded_contacts_median"].iloc[0] == 1.0
    assert np.isnan(_table(hand, load_threshold_N=None)["loaded_contacts_median"].iloc[0])


def test_one_object_at_a_time_gives_the_tables_of_every_objects_rows(hand, tmp_path):
    """``realism_by_object`` (one object's files at a time, the objects handed in unsorted)
    against the three tables made from both objects' rows at once."""
    from dataclasses import replace

    from conftest import defaults
    from synergrasp.analysis.graspability import graspable_objects
    from synergrasp.analysis.realism import RealismParams, link_shares, realism_by_object
    from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium

    params = replace(
        RealismParams.from_config(defaults()),
        full_set_id="1-2",
        weights_N={"a": 10.0, "b": 4.0},
        grasp_types={"a": "power", "b": "precision"},
        shapes={"a": _BOX, "b": _BOX},
        opposition=_RULE,
    )
    types = {"a": ("power", "power", ""), "b": ("precision", "precision", "")}
    frames = {"b": (_contacts("b", _POSES[::-1]), _gfo("b")), "a": (_contacts("a"), _gfo("a"))}
    files = []
    for obj, (contacts, gfo) in frames.items():
        (tmp_path / obj).mkdir()
        table_contracts.write(table_contracts.CONTACTS, contacts, tmp_path / obj / "contacts.parquet")
        table_contracts.write(table_contracts.GFO, gfo, tmp_path / obj / "gfo.parquet")
        files.append((tmp_path / obj / "contacts.parquet", tmp_path / obj / "gfo.parquet"))
    table, links, graspable = realism_by_object(files, hand, params, types)

    contacts = pd.concat([frames[o][0] for o in ("b", "a")], ignore_index=True)
    gfo = pd.concat([frames[o][1] for o in ("b", "a")], ignore_index=True)
    synergies = params.synergies(hand.joint_names)
    checks = grasp_equilibrium(
        contacts, EquilibriumParams.of(hand, synergies, params.k_ss_Nmm_per_rad, params.mu), synergies.columns([1])[:, 0]
    )
    labels = grasp_labels(contacts, HandAxes.from_hand(hand), _RULE, params.shapes)
    expected = grasp_realism(
        contacts,
        gfo,
        checks,
        hand.link_names,
        hand.link_finger,
        "1-2",
        params.weights_N,
        params.load_threshold_N,
        labels,
        {"a": "power", "b": "precision"},
    )
    pd.testing.assert_frame_equal(table, expected, check_exact=True)
    pd.testing.assert_frame_equal(links, link_shares(contacts, hand.link_names, hand.link_finger), check_exact=True)
    pd.testing.assert_frame_equal(graspable, graspable_objects(contacts, gfo, "1-2", types), check_exact=True)
    assert table["object"].tolist() == ["a", "b"] and table["poses"].tolist() == [4, 4]
    assert table["grasp_type"].tolist() == ["power", "precision"]
    assert graspable["force_closure_full_set"].tolist() == [2, 2]  # poses 1 and 3 of each, by hand


def test_figure_canvas_does_not_grow_past_its_rows(hand, tmp_path, monkeypatch):
    """Past TALL_ROWS rows the figure is no taller (the realism job's memory is its canvas), and
    past LISTED_OBJECTS rows the title gives the dropped poses' totals, not a name per row
    (a title as wide as every object's name made the 97 random objects' figure 184 M pixels)."""
    from PIL import Image

    from synergrasp.figures import grasp_realism

    monkeypatch.setattr(grasp_realism, "TALL_ROWS", 3)
    monkeypatch.setattr(grasp_realism, "LISTED_OBJECTS", 3)
    one = _table(hand)
    sizes = {}
    for n in (3, 8):
        table = pd.concat([one.assign(object=f"object_with_a_long_name_{k}") for k in range(n)], ignore_index=True)
        grasp_realism.figure_grasp_realism(table, tmp_path / f"{n}.png", tmp_path / f"{n}.pdf")
        with Image.open(tmp_path / f"{n}.png") as png:
            sizes[n] = png.size
    assert sizes[8] == sizes[3]
