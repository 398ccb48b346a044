"""synergies map: a synergy table carried over to another hand in the object's terms
(docs/synergies.md, "Mapping a synergy table onto another hand")."""

from dataclasses import replace

import numpy as np
import pytest

from synergrasp.cli import main
from synergrasp.hand.kinematics import fingertip_positions, forward_kinematics, load_hand
from synergrasp.hand.synergies import load_synergies, shadow_hand_files
from synergrasp.hand.synergy_fit import fit_synergies, read_postures
from synergrasp.hand.synergy_map import MapParams, _Retarget, grasp_features, hand_size, map_postures, map_synergies

# a coarse sampling keeps the tests short; the shipped table uses the defaults
COARSE = MapParams(s1_samples=9, other_samples=3)


@pytest.fixture(scope="module")
def soft():
    return load_hand(None), load_synergies(None)


@pytest.fixture(scope="module")
def shadow():
    return load_hand("shadow_hand")


def test_hand_size_by_hand(soft):
    """The SoftHand's long fingers are 89.3 mm from the abduction axis to the tip (docs/hand.md);
    the knuckle centre is the mean of the four abduction axes' origins."""
    hand, _ = soft
    centre, size = hand_size(hand)
    assert size == pytest.approx(89.3, abs=1e-9)
    frames = forward_kinematics(hand, np.zeros(hand.n_joints))
    knuckles = [frames[hand.link_index(f"{f}_knuckle"), :3, 3] for f in ("index", "middle", "ring", "little")]
    np.testing.assert_allclose(centre, np.mean(knuckles, axis=0), atol=1e-12)


def test_features_are_tips_and_thumb_vectors(soft):
    hand, table = soft
    tips = fingertip_positions(hand, table.mean)
    centre, size = hand_size(hand)
    features = grasp_features(hand, table.mean, centre, size) * size
    np.testing.assert_allclose(features[:5], tips - centre, atol=1e-12)
    np.testing.assert_allclose(features[5 + 1], tips[2] - tips[0], atol=1e-12)  # thumb tip to middle tip


def test_residual_jacobian_equals_central_differences(shadow):
    """The retargeting's analytic Jacobian (fingertip Jacobians through the feature map)
    against central differences of its residual, on the Shadow hand (coupled, reversed joints)."""
    problem = _Retarget(shadow, MapParams())
    rng = np.random.default_rng(3)
    q = shadow.lower + rng.uniform(0.2, 0.8, shadow.n_joints) * (shadow.upper - shadow.lower)
    goal, previous = rng.normal(size=27) * 30.0, q + 0.1
    jac = problem.jacobian(q, goal, previous)
    h = 1e-6
    numeric = np.column_stack(
        [
            (problem.residual(q + h * e, goal, previous) - problem.residual(q - h * e, goal, previous)) / (2 * h)
            for e in np.eye(shadow.n_joints)
        ]
    )
    np.testing.assert_allclose(jac, numeric, atol=1e-5)


def test_a_hand_mapped_onto_itself_matches_every_posture(soft):
    """Source = target, without the pull toward the previous posture: every sampled posture is
    reachable, so the features match to the solver's tolerance (the joints may differ only
    where the fingertips do not fix them). With the pull (2 mm/rad) they match within 0.1 mm."""
    hand, table = soft
    mapped = map_postures(hand, table, hand, replace(COARSE, smoothing_mm_per_rad=1e-6))
    assert len(mapped.sigma) == 1 + COARSE.s1_samples + 14 * 2  # the mean (σ = 0) once; 9 along S1; ±1 along the others
    assert np.max(mapped.residual_mm) < 1e-4
    assert np.max(map_postures(hand, table, hand, COARSE).residual_mm) < 0.1
    for q_source, q_target in zip(mapped.source[::7], mapped.target[::7]):
        np.testing.assert_allclose(fingertip_positions(hand, q_target), fingertip_positions(hand, q_source), atol=1e-3)


def test_mapping_is_deterministic_and_the_fit_is_synergies_fit(soft, shadow):
    hand, table = soft
    first, mapped = map_synergies(hand, table, shadow, params=COARSE)
    second, _ = map_synergies(hand, table, shadow, params=COARSE)
    np.testing.assert_array_equal(first.synergies.matrix, second.synergies.matrix)
    np.testing.assert_array_equal(first.synergies.mean, second.synergies.mean)
    direct = fit_synergies(shadow.joint_names, mapped.target, table.n_synergies)
    np.testing.assert_array_equal(first.synergies.matrix, direct.synergies.matrix)
    assert np.all(first.synergies.mean >= shadow.lower) and np.all(first.synergies.mean <= shadow.upper)


def test_shipped_shadow_table_equals_a_fresh_mapping(soft):
    """data/hands/shadow/synergies.csv is the mapping of the study's table (tools/synergy_tables.py),
    no hand-written row; S1 closes (every flexion entry >= 0)."""
    hand, table = soft
    hand_path, _, table_path = shadow_hand_files()
    target = load_hand(hand_path)
    fit, _ = map_synergies(hand, table, target)
    shipped = load_synergies(table_path, joint_names=target.joint_names)
    np.testing.assert_allclose(shipped.matrix, fit.synergies.matrix, atol=1e-9)
    np.testing.assert_allclose(shipped.mean, fit.synergies.mean, atol=1e-9)
    assert np.all(shipped.matrix[target.flexion_joints, 0] >= 0)


def test_command_writes_the_table_and_postures_that_synergies_fit_reproduces(tmp_path, capsys):
    out, postures = tmp_path / "shadow.csv", tmp_path / "postures.csv"
    assert main(["synergies", "map", "shadow_hand", "--out", str(out), "--postures", str(postures)]) == 0
    text = capsys.readouterr().out
    assert "S15" in text and "thumb opposition: hand 'shadow_hand'" in text
    names, x = read_postures(postures)
    refit = fit_synergies(names, x, 15).synergies
    table = load_synergies(out, joint_names=names)
    np.testing.assert_array_equal(table.matrix, refit.matrix)
    np.testing.assert_array_equal(table.mean, refit.mean)


def test_command_checks_its_arguments_before_any_work_and_never_writes_over_its_input(tmp_path, capsys):
    table = tmp_path / "table.csv"
    table.write_bytes(load_synergies.__globals__["shipped_path"]().read_bytes())
    before = table.read_bytes()
    assert (
        main(
            [
                "synergies",
                "map",
                "shadow_hand",
                "--table",
                str(table),
                "--out",
                str(table),
                "--png",
                str(tmp_path / "v.txt"),
                "--synergies",
                "40",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"synergrasp synergies map: --out {table}: is the file the command reads (--table {table}); write to another file",
        f"synergrasp synergies map: --png {tmp_path / 'v.txt'}: the file name must end in .png",
    ]
    # the outputs mended, the count is checked before any mapping
    assert (
        main(["synergies", "map", "shadow_hand", "--table", str(table), "--out", str(tmp_path / "o.csv"), "--synergies", "40"])
        == 2
    )
    assert capsys.readouterr().err.strip().splitlines() == [
        "synergrasp synergies map: --synergies 40: must be 1 … 15 (the table's columns, at most the target's joints)"
    ]
    assert table.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]
    assert main(["synergies", "map", str(tmp_path / "none.yaml"), "--out", str(tmp_path / "o.csv")]) == 2
    assert "none.yaml" in capsys.readouterr().err and not (tmp_path / "o.csv").exists()


def test_joint_by_joint_option_writes_the_mapping_files_table_and_warns(tmp_path, capsys):
    """--joint-mapping: the human table mapped joint by joint (map_human_synergies); on the
    Shadow hand's mapping file, the thumb-opposition check's warning (its thumb on the palm)."""
    from synergrasp.hand.synergies import load_human_synergies, load_synergy_mapping, map_human_synergies

    hand = load_hand("shadow_hand")
    _, mapping, _ = shadow_hand_files()
    out = tmp_path / "joint.csv"
    assert main(["synergies", "map", "shadow_hand", "--joint-mapping", str(mapping), "--out", str(out)]) == 0
    assert "WARNING: thumb opposition: hand 'shadow_hand'" in capsys.readouterr().out
    expected = map_human_synergies(load_human_synergies(), load_synergy_mapping(mapping), hand.joint_names)
    table = load_synergies(out, joint_names=hand.joint_names)
    np.testing.assert_array_equal(table.matrix, expected.matrix)
    assert (
        main(
            [
                "synergies",
                "map",
                "shadow_hand",
                "--joint-mapping",
                str(mapping),
                "--out",
                str(tmp_path / "o.csv"),
                "--synergies",
                "3",
            ]
        )
        == 2
    )
    assert capsys.readouterr().err.strip() == (
        "synergrasp synergies map: --synergies: not used with --joint-mapping (it maps the human table joint by joint)"
    )
    assert not (tmp_path / "o.csv").exists()
