import math
from pathlib import Path

import numpy as np
import pytest

from synergrasp.hand.kinematics import JOINT_NAMES
from synergrasp.hand.synergies import (
    HUMAN_JOINT_NAMES,
    Synergies,
    SynergyFileError,
    load_human_synergies,
    load_synergies,
    load_synergy_mapping,
    map_human_synergies,
    SynergyPath,
    shipped_path,
    SHIPPED_TABLES,
    write_synergies,
)

LOWER = np.radians([0, 0, 0] + [-30, 0, 0, 0] * 4)
UPPER = np.radians([90, 90, 90] + [30, 90, 90, 90] * 4)
LONG_FLEXIONS = [f"{f}_{j}" for f in ("index", "middle", "ring", "little") for j in ("mcp", "pip", "dip")]


@pytest.mark.parametrize("table", SHIPPED_TABLES)
def test_shipped_file_equals_fresh_mapping(table):
    shipped = load_synergies(table)
    fresh = map_human_synergies(load_human_synergies(), load_synergy_mapping(table))
    assert shipped.joint_names == JOINT_NAMES == fresh.joint_names
    assert shipped.names == tuple(f"S{i}" for i in range(1, 16))
    np.testing.assert_array_equal(shipped.mean, fresh.mean)
    np.testing.assert_array_equal(shipped.matrix, fresh.matrix)


def test_human_copy_matches_known_facts():
    human = load_human_synergies()
    assert human.matrix.shape == (20, 15)
    row = dict(zip(HUMAN_JOINT_NAMES, range(20)))
    # every DIP row is 2/3 of its PIP row; the middle abduction row is zero
    for f in ("index", "middle", "ring", "little"):
        np.testing.assert_allclose(human.matrix[row[f"{f}_dip"]], 2 / 3 * human.matrix[row[f"{f}_pip"]], atol=1e-12)
    assert not human.matrix[row["middle_abd"]].any()


def test_long_fingers_map_one_to_one_and_s1_closes():
    human = load_human_synergies()
    hand = load_synergies()
    for name in LONG_FLEXIONS + ["index_abd", "ring_abd", "little_abd"]:
        h, j = HUMAN_JOINT_NAMES.index(name), JOINT_NAMES.index(name)
        np.testing.assert_array_equal(hand.matrix[j, 0], -human.matrix[h, 0])  # S1 negated
        np.testing.assert_array_equal(hand.matrix[j, 1:], human.matrix[h, 1:])
    s1 = dict(zip(JOINT_NAMES, hand.matrix[:, 0]))
    assert all(s1[n] > 0 for n in LONG_FLEXIONS + ["thumb_flex1", "thumb_flex2"])
    # closing adducts: index toward the middle (-y), ring and little toward it (+y)
    assert s1["index_abd"] < 0 < s1["ring_abd"] < s1["little_abd"]


def test_default_is_softhand_opposed_and_names_resolve(tmp_path):
    default = load_synergies()
    np.testing.assert_array_equal(default.matrix, load_synergies("softhand_opposed").matrix)
    assert not np.array_equal(default.matrix, load_synergies("legacy_thumb").matrix)
    with pytest.raises(SynergyFileError, match="softhand_opposed"):
        load_synergies("softhand")


def test_softhand_thumb_follows_the_average_finger_flexion():
    """Thumb rows = (1.3, 1.3, 1.0) x the mean of the 12 long-finger flexion rows, in the mean
    posture and in every column (hand_model.md: the SoftHand's own synergy)."""
    s = load_synergies("softhand_opposed")
    flex = [JOINT_NAMES.index(n) for n in LONG_FLEXIONS]
    human = load_human_synergies()
    human_mean = np.mean([human.mean[HUMAN_JOINT_NAMES.index(n)] for n in LONG_FLEXIONS])
    for name, ratio in (("thumb_abd", 1.3), ("thumb_flex1", 1.3), ("thumb_flex2", 1.0)):
        j = JOINT_NAMES.index(name)
        np.testing.assert_allclose(s.matrix[j], ratio * s.matrix[flex].mean(axis=0), atol=1e-12)
        assert s.mean[j] == pytest.approx(ratio * human_mean)
    assert s.matrix[JOINT_NAMES.index("thumb_abd"), 0] > 0  # S1 opposes the thumb


def test_mean_posture_is_reachable_and_clipped_where_needed():
    assert np.all(load_synergies().mean >= LOWER) and np.all(load_synergies().mean <= UPPER)
    s = load_synergies("legacy_thumb")
    assert np.all(s.mean >= LOWER) and np.all(s.mean <= UPPER)
    mean = dict(zip(JOINT_NAMES, s.mean))
    assert mean["little_abd"] == pytest.approx(-math.pi / 6)  # human -30.3 deg, clipped
    assert mean["thumb_flex1"] == 0.0  # pi/2 - 101 deg < 0, clipped
    assert mean["thumb_abd"] == pytest.approx(0.9825865684823639)  # -thumb_j1


def test_mapping_weights_and_offsets_by_hand():
    human = Synergies(HUMAN_JOINT_NAMES, np.linspace(0.2, 0.4, 20), np.arange(40.0).reshape(20, 2) / 100, ("S1", "S2"))
    mapping = load_synergy_mapping()
    mapping["column_sign"] = {"syn2": -1}
    mapping["joints"]["thumb_flex1"] = {
        "terms": [{"human": "thumb_j2", "weight": 0.5}, {"human": "thumb_j3", "weight": 0.5}],
        "offset_rad": 0.1,
        "limits_deg": [0, 90],
    }
    out = map_human_synergies(human, mapping)
    j = JOINT_NAMES.index("thumb_flex1")
    assert out.mean[j] == pytest.approx(0.1 + 0.5 * (human.mean[1] + human.mean[2]))
    assert out.matrix[j, 0] == pytest.approx(0.5 * (0.02 + 0.04))
    assert out.matrix[j, 1] == pytest.approx(-0.5 * (0.03 + 0.05))


def test_mapping_rejects_missing_joint():
    mapping = load_synergy_mapping()
    del mapping["joints"]["ring_pip"]
    with pytest.raises(SynergyFileError, match="ring_pip"):
        map_human_synergies(load_human_synergies(), mapping)


def test_reference_posture_clips_and_broadcasts():
    s = load_synergies()
    path = SynergyPath.along(s, LOWER, UPPER)
    q0 = path.reference(0.0)
    np.testing.assert_array_equal(q0, s.mean)
    q = path.reference([-10.0, 1.0, 10.0])
    assert q.shape == (3, 19)
    np.testing.assert_allclose(q[1], np.clip(s.mean + s.matrix[:, 0], LOWER, UPPER))
    # far along +S1 every long-finger flexion is at its upper limit
    idx = [JOINT_NAMES.index(n) for n in LONG_FLEXIONS]
    np.testing.assert_allclose(q[2, idx], math.pi / 2)
    np.testing.assert_allclose(q[0, idx], 0.0)
    with pytest.raises(ValueError, match="lower and upper"):
        SynergyPath.along(s, LOWER[:3], UPPER)


def test_columns_selects_one_based():
    s = load_synergies()
    np.testing.assert_array_equal(s.columns([3, 1]), s.matrix[:, [2, 0]])
    with pytest.raises(ValueError, match="1..15"):
        s.columns([0])


def test_user_file_round_trip_any_row_order(tmp_path):
    s = load_synergies()
    path = tmp_path / "mine.csv"
    write_synergies(s, path)
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0], *reversed(lines[1:])]) + "\n")
    back = load_synergies(path)
    np.testing.assert_array_equal(back.matrix, s.matrix)
    np.testing.assert_array_equal(back.mean, s.mean)


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.csv"
    path.write_text(text)
    return path


def _good_lines(k: int = 2) -> list[str]:
    head = "joint,mean_rad," + ",".join(f"syn{i}" for i in range(1, k + 1))
    return [head] + [f"{n},0.1," + ",".join(["0.5"] * k) for n in JOINT_NAMES]


@pytest.mark.parametrize(
    "mutate, match",
    [
        (lambda L: [L[0].replace("joint,", "name,")] + L[1:], "missing column 'joint'"),
        (lambda L: [L[0].replace("mean_rad", "mean")] + L[1:], "missing column 'mean_rad'"),
        (lambda L: L[:-1], r"missing \['little_dip'\]"),
        (lambda L: L + [L[1]], r"duplicated \['thumb_abd'\]"),
        (lambda L: L[:1] + [L[1].replace("thumb_abd", "thumb_rot")] + L[2:], r"unknown \['thumb_rot'\]"),
        (lambda L: L[:1] + [L[1].replace("0.5", "abc", 1)] + L[2:], "field 'syn1' of joint 'thumb_abd'"),
        (lambda L: L[:1] + [L[1].replace("0.1", "nan", 1)] + L[2:], "field 'mean_rad'"),
        (lambda L: L[:1] + [L[1].replace("0.5", "", 1)] + L[2:], "field 'syn1'"),
        (lambda L: [L[0].replace("syn1,syn2", "syn2,syn1")] + L[1:], "syn1..syn2 in this order"),
        (lambda L: [L[0].replace("syn2", "extra")] + L[1:], "syn1..syn2"),
    ],
)
def test_bad_files_raise_one_clear_error(tmp_path, mutate, match):
    path = _write(tmp_path, "\n".join(mutate(_good_lines())) + "\n")
    with pytest.raises(SynergyFileError, match=match) as info:
        load_synergies(path)
    assert str(path) in str(info.value)


def test_no_synergy_columns_and_too_many(tmp_path):
    path = _write(tmp_path, "\n".join(["joint,mean_rad"] + [f"{n},0.1" for n in JOINT_NAMES]) + "\n")
    with pytest.raises(SynergyFileError, match="no synergy columns"):
        load_synergies(path)
    path = _write(tmp_path, "\n".join(_good_lines(20)) + "\n")
    with pytest.raises(SynergyFileError, match="at most 19"):
        load_synergies(path)


@pytest.mark.parametrize(
    "name, content", [("nope.csv", None), ("folder", "dir"), ("empty.csv", b""), ("binary.csv", bytes(range(256)))]
)
def test_unreadable_file_gives_one_message_naming_it(tmp_path, name, content):
    path = tmp_path / name
    if content == "dir":
        path.mkdir()
    elif content is not None:
        path.write_bytes(content)
    with pytest.raises(SynergyFileError, match=f"synergy file '{path}'"):
        load_synergies(path)


def test_shipped_path_exists():
    for table in SHIPPED_TABLES:
        assert shipped_path(table).is_file()


def test_mapping_limits_agree_with_hand_model():
    from synergrasp.hand.kinematics import load_hand

    hand = load_hand(None)
    joints = load_synergy_mapping()["joints"]
    np.testing.assert_allclose(np.radians([joints[j]["limits_deg"][0] for j in hand.joint_names]), hand.lower)
    np.testing.assert_allclose(np.radians([joints[j]["limits_deg"][1] for j in hand.joint_names]), hand.upper)
    s = load_synergies(joint_names=hand.joint_names)
    assert np.all((s.mean >= hand.lower) & (s.mean <= hand.upper))


def test_softhand_human_higher_couples_s1_and_follows_the_human_thumb_above():
    """Mean posture and S1 as softhand_opposed (the same closure); the thumb rows of S2..S15
    are the human thumb joints' (j1, j2, j3) with weight -1, read from the human table."""
    s, opposed = load_synergies("softhand_human_higher"), load_synergies("softhand_opposed")
    human = load_human_synergies()
    np.testing.assert_array_equal(s.mean, opposed.mean)
    np.testing.assert_array_equal(s.matrix[:, 0], opposed.matrix[:, 0])
    thumb = [JOINT_NAMES.index(n) for n in ("thumb_abd", "thumb_flex1", "thumb_flex2")]
    others = [j for j in range(len(JOINT_NAMES)) if j not in thumb]
    np.testing.assert_array_equal(s.matrix[others], opposed.matrix[others])
    for j, source in zip(thumb, ("thumb_j1", "thumb_j2", "thumb_j3")):
        np.testing.assert_allclose(s.matrix[j, 1:], -human.matrix[HUMAN_JOINT_NAMES.index(source), 1:], atol=1e-15)


def test_column_terms_replace_the_terms_in_their_columns_only():
    human = Synergies(HUMAN_JOINT_NAMES, np.linspace(0.2, 0.4, 20), np.arange(60.0).reshape(20, 3) / 100, ("S1", "S2", "S3"))
    mapping = load_synergy_mapping("legacy_thumb")
    mapping["column_sign"] = {"syn3": -1}
    mapping["joints"]["thumb_flex2"]["column_terms"] = [{"columns": [2, 3], "terms": [{"human": "thumb_j4", "weight": 2.0}]}]
    out = map_human_synergies(human, mapping)
    j = JOINT_NAMES.index("thumb_flex2")
    assert out.mean[j] == pytest.approx(-human.mean[2] if -human.mean[2] > 0 else 0.0)  # mean from `terms`
    assert out.matrix[j, 0] == pytest.approx(-0.06)  # S1 from `terms`: -thumb_j3
    assert out.matrix[j, 1] == pytest.approx(2 * 0.10)  # S2: 2 * thumb_j4
    assert out.matrix[j, 2] == pytest.approx(-2 * 0.11)  # S3: 2 * thumb_j4, column sign -1


@pytest.mark.parametrize("columns", [[0, 3], [2, 4], [3, 2], [2], "2-3", [1.5, 3]])
def test_column_terms_reject_a_bad_range(columns):
    human = Synergies(HUMAN_JOINT_NAMES, np.zeros(20), np.ones((20, 3)), ("S1", "S2", "S3"))
    mapping = load_synergy_mapping("legacy_thumb")
    mapping["joints"]["thumb_abd"]["column_terms"] = [{"columns": columns, "terms": []}]
    with pytest.raises(SynergyFileError, match=r"thumb_abd.*column_terms\.columns.*1 <= first <= last <= 3"):
        map_human_synergies(human, mapping)
