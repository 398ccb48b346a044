"""Placement, pose grid and the quasi-static closure along S1 (pybullet)."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

import bullet_reference
from conftest import study_closure_params, study_placement
from synergrasp.config import ConfigError, defaults, validate_config
from synergrasp.hand.kinematics import forward_kinematics
from synergrasp.hand.synergies import SynergyPath, load_synergies
from synergrasp.optimisation.mechanics import read_grasps
from synergrasp.simulation.closure import simulate_object
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.placement import approach_line, object_pose, palm_centre, pose_grid
from synergrasp.simulation.shapes import Box
from synergrasp.table_contracts import CONTACTS
from synergrasp.table_contracts import write as write_table

PARAMS = study_closure_params()
PLACEMENT = study_placement()
CUBE = GraspedObject("obj1", Box((30.0, 30.0, 30.0)), 1.0)
PLATE = GraspedObject("obj2", Box((30.0, 60.0, 60.0)), 1.0)


@pytest.fixture(scope="module")
def grid():
    return pose_grid(PLACEMENT)


@pytest.fixture(scope="module")
def sample(hand, synergies, grid):
    """A spread of poses of two boxes, plus the same poses turned by α + 180°."""
    base = [grid.index(a, b) for a, b in [(-180, 0), (-90, 30), (-30, -60), (5, 10), (45, 20), (10, -25)]]
    mirrored = [(p + 36 * grid.n_beta) % grid.n_poses for p in base]
    # two runs: within one, a mirrored pose would share its base pose's closure (same region)
    tables = {
        box.name: pd.concat(
            [simulate_object(hand, synergies, box, PLACEMENT, PARAMS, poses=poses) for poses in (base, mirrored)],
            ignore_index=True,
        )
        for box in (CUBE, PLATE)
    }
    return base, mirrored, tables


def _grasp_rows(tables):
    for name, table in tables.items():
        for _, row in table[table.status == "grasp"].iterrows():
            yield name, row


# ------------------------------------------------------------------ placement and grid


def test_grid_has_72_by_25_poses_and_index_round_trips(grid):
    assert (grid.n_alpha, grid.n_beta, grid.n_poses) == (72, 25, 1800)
    assert grid.angles_deg(0) == (-180.0, -60.0)
    assert grid.angles_deg(3 * 25 + 4) == (-165.0, -40.0)
    for pose in (0, 77, 1799):
        assert grid.index(*grid.angles_deg(pose)) == pose
    assert grid.index(180.0, 0.0) == grid.index(-180.0, 0.0)  # α is periodic


@pytest.mark.parametrize(
    "block, key, value, message",
    [
        ("placement", "box_axes", [0, 0, 2], "'placement.box_axes'"),
        ("placement", "mode", "drop", "'placement.mode'"),
        ("placement", "clearance_mm", -1.0, "'placement.clearance_mm'"),
        ("placement", "approach_point_mm", [1.0, 2.0], "'placement.approach_point_mm'"),
        ("placement", "rotation_order", "xyz", "'placement.rotation_order'"),
        ("placement", "center_mm", [1.0, 2.0], "'placement.center_mm'"),
        ("grid", "alpha_deg", {"start": -180, "stop": 180, "step": 5}, "'grid.alpha_deg'"),
        ("grid", "beta_deg", {"start": -60, "stop": 61, "step": 5}, "'grid.beta_deg.step'"),
        ("closure", "step_mm", 0.1, "'closure.step_mm'"),
        ("closure", "tolerance_mm", 0.0, "'closure.tolerance_mm'"),
    ],
)
def test_bad_placement_and_closure_values_name_the_key(block, key, value, message):
    """Placement and closure values are checked once, before any job (the schema and the
    relations of the configuration); the typed classes only carry them."""
    config = defaults()
    config[block] = {**config[block], key: value}
    with pytest.raises(ConfigError, match=message):
        validate_config(config)


def test_zero_pose_maps_box_edges_to_palm_axes():
    placed = object_pose(study_placement(box_axes=(2, 0, 1)), Box((10.0, 20.0, 30.0)), 0.0, 0.0)
    extent = np.abs(placed.rotation) @ placed.shape.half_extents_mm  # half extent along palm x, y, z
    np.testing.assert_allclose(extent, [15.0, 5.0, 10.0])


def test_alpha_turns_about_palm_normal_then_beta_about_fingers():
    placed = object_pose(PLACEMENT, Box((10.0, 20.0, 30.0)), 90.0, 90.0)
    # α = 90° about x takes box y (20) onto palm z; β = 90° about z takes box x (10) onto palm y
    extent = np.abs(placed.rotation) @ placed.shape.half_extents_mm
    np.testing.assert_allclose(extent, [15.0, 5.0, 10.0], atol=1e-12)


def _corners(placed):
    signs = np.array(list(itertools.product((-1, 1), repeat=3)), dtype=float)
    pts = (signs * placed.shape.half_extents_mm) @ placed.rotation.T + placed.center_mm
    return pts[np.lexsort(np.round(pts, 9).T)]


@pytest.mark.parametrize("alpha, beta", [(-30.0, 0.0), (45.0, 20.0), (-165.0, -60.0)])
def test_alpha_and_alpha_plus_180_place_the_same_box(alpha, beta):
    a = object_pose(PLACEMENT, Box((100.0, 60.0, 30.0)), alpha, beta)
    b = object_pose(PLACEMENT, Box((100.0, 60.0, 30.0)), alpha + 180.0, beta)
    np.testing.assert_allclose(_corners(a), _corners(b), atol=1e-9)


# ------------------------------------------------------------------ closure


def test_sample_has_grasps(sample):
    _, _, tables = sample
    for table in tables.values():
        assert (table.status == "grasp").sum() >= 6
        assert set(table.status) <= {"grasp", "intersects_open_hand", "no_contact"}


def test_contacts_lie_on_the_box_and_do_not_penetrate(sample):
    _, _, tables = sample
    for _, row in _grasp_rows(tables):
        m = int(row.n_contacts)
        R = np.asarray(row.object_rotation).reshape(3, 3)
        c = np.asarray(row.object_center)
        half = (CUBE if row.object == "obj1" else PLATE).shape.half_extents_mm
        local = (np.asarray(row.contact_point).reshape(m, 3) - c) @ R
        np.testing.assert_allclose(np.max(np.abs(local) / half, axis=1), 1.0, atol=1e-9)
        assert row.max_penetration_mm <= PARAMS.penetration_tolerance_mm


def test_normals_are_unit_and_point_into_the_box(sample):
    _, _, tables = sample
    for _, row in _grasp_rows(tables):
        m = int(row.n_contacts)
        n = np.asarray(row.contact_normal).reshape(m, 3)
        p = np.asarray(row.contact_point).reshape(m, 3)
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
        assert np.all(np.sum(n * (np.asarray(row.object_center) - p), axis=1) > 0)


def test_links_touch_the_box_within_contact_distance(hand, sample):
    """Cross-check of pybullet's contact detection with the hand's own capsule geometry."""
    _, _, tables = sample
    for _, row in _grasp_rows(tables):
        frames = forward_kinematics(hand, np.asarray(row.q))
        m = int(row.n_contacts)
        for link, point in zip(row.contact_link, np.asarray(row.contact_point).reshape(m, 3)):
            gaps = []
            for shape in hand.link_shapes[link]:
                if shape.kind != "capsule":
                    continue
                pose = frames[link] @ shape.pose
                axis = pose[:3, 2]
                t = np.clip((point - pose[:3, 3]) @ axis, -shape.length / 2, shape.length / 2)
                gaps.append(np.linalg.norm(point - pose[:3, 3] - t * axis) - shape.radius)
            if gaps:
                assert -PARAMS.penetration_tolerance_mm - 1e-6 <= min(gaps) <= PARAMS.contact_distance_mm + 0.05


def test_same_pose_twice_gives_identical_rows(hand, synergies, sample):
    base, _, tables = sample
    again = simulate_object(hand, synergies, PLATE, PLACEMENT, PARAMS, poses=base[:3])
    pd.testing.assert_frame_equal(again, tables["obj2"].iloc[:3].reset_index(drop=True))


def test_alpha_plus_180_gives_the_same_grasp(sample):
    """Same box in space: same final posture and contact set (up to float noise of the
    box orientation, 1e-6 rad in q and 1e-4 mm in the points)."""
    base, mirrored, tables = sample
    for table in tables.values():
        a = table.set_index("pose")
        for p, r in zip(base, mirrored):
            assert a.loc[p, "status"] == a.loc[r, "status"]
            np.testing.assert_allclose(a.loc[p, "q"], a.loc[r, "q"], atol=1e-6)
            assert list(a.loc[p, "contact_link"]) == list(a.loc[r, "contact_link"])
            np.testing.assert_allclose(a.loc[p, "contact_point"], a.loc[r, "contact_point"], atol=1e-4)


def test_one_region_one_closure_within_a_run(hand, synergies, sample, monkeypatch):
    """Poses that fill one region share the first one's closure (every contact column equal),
    each keeping its own pose columns; a region seen once is closed once."""
    from synergrasp.simulation import kinematic_closure

    base, mirrored, tables = sample
    calls = []
    real = kinematic_closure.KinematicClosure.grasp
    monkeypatch.setattr(kinematic_closure.KinematicClosure, "grasp", lambda self, placed: calls.append(1) or real(self, placed))
    both = simulate_object(hand, synergies, PLATE, PLACEMENT, PARAMS, poses=base + mirrored)
    assert len(calls) == len(base)
    n = len(base)
    for col in ("status", "q", "contact_link", "contact_point", "contact_normal", "jacobian", "max_penetration_mm"):
        assert both[col].iloc[:n].tolist() == both[col].iloc[n:].tolist(), col
    assert both["pose"].tolist() == base + mirrored
    assert not np.allclose(np.stack(both["object_rotation"].iloc[:n]), np.stack(both["object_rotation"].iloc[n:]))
    # the shared rows are the separate closures' to round-off
    apart = tables["obj2"]
    np.testing.assert_allclose(
        np.concatenate(both["contact_point"].tolist()), np.concatenate(apart["contact_point"].tolist()), atol=1e-9
    )


def test_a_pose_alone_as_in_the_grid_is_the_grid_runs_row(hand, synergies, sample):
    """``as_in_grid``: one pose closed alone gives the row a run over the grid gives it, bit
    for bit (closed at the grid's first pose of its region, here α = −180°)."""
    base, mirrored, _ = sample
    grid_run = simulate_object(hand, synergies, PLATE, PLACEMENT, PARAMS, poses=[base[0], mirrored[0]]).iloc[1]
    alone = simulate_object(hand, synergies, PLATE, PLACEMENT, PARAMS, poses=[mirrored[0]], as_in_grid=True).iloc[0]
    plain = simulate_object(hand, synergies, PLATE, PLACEMENT, PARAMS, poses=[mirrored[0]]).iloc[0]
    for col in ("q", "contact_point", "contact_normal", "jacobian", "object_rotation"):
        assert list(alone[col]) == list(grid_run[col]), col
    assert list(plain["contact_point"]) != list(grid_run["contact_point"])  # closed on its own: round-off apart


def test_jacobian_rows_match_finite_differences_of_fk(hand, sample):
    _, _, tables = sample
    checked = 0
    for _, row in _grasp_rows(tables):
        q = np.asarray(row.q)
        m = int(row.n_contacts)
        jac = np.asarray(row.jacobian).reshape(3 * m, hand.n_joints)
        frames = forward_kinematics(hand, q)
        for i, (link, point) in enumerate(zip(row.contact_link, np.asarray(row.contact_point).reshape(m, 3))):
            local = frames[link, :3, :3].T @ (point - frames[link, :3, 3])  # point fixed to the link
            fd = np.zeros((3, hand.n_joints))
            for j in range(hand.n_joints):
                h = 1e-6
                fp = forward_kinematics(hand, q + h * np.eye(hand.n_joints)[j])[link]
                fm = forward_kinematics(hand, q - h * np.eye(hand.n_joints)[j])[link]
                fd[:, j] = ((fp[:3, :3] @ local + fp[:3, 3]) - (fm[:3, :3] @ local + fm[:3, 3])) / (2 * h)
            np.testing.assert_allclose(jac[3 * i : 3 * i + 3], fd, atol=1e-5)
            checked += 1
        if checked >= 12:
            break
    assert checked > 0


@pytest.fixture(scope="module")
def empty_hand(hand, synergies):
    """Closures with nothing to grasp (the box 600 mm away)."""
    far = study_placement(mode="fixed", center_mm=(600.0, 0.0, 0.0))
    return pd.concat([simulate_object(hand, synergies, CUBE, far, PARAMS, poses=[p]) for p in (0, 900)], ignore_index=True)


def test_closing_on_nothing_ends_at_limits_or_blocked_by_the_hand(hand, synergies, empty_hand):
    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    reference = path.reference(path.closure_range(hand.flexion_joints)[1])
    for _, row in empty_hand.iterrows():
        assert row.status == "no_contact"
        assert row.n_contacts == 0
        assert set(row.finger_state) <= {"limit", "self"}
        q = np.asarray(row.q)
        for f, (state, joints) in enumerate(zip(row.finger_state, hand.finger_joints)):
            if state == "limit":  # a free finger followed the reference to the end: every joint at a limit
                np.testing.assert_allclose(q[list(joints)], reference[list(joints)], atol=1e-12)


def _link_gap(hand, q, a, b):
    """Distance (mm) between the capsules of links a and b at q, from the hand's own geometry."""
    frames = forward_kinematics(hand, q)

    def segment(link):
        (shape,) = [s for s in hand.link_shapes[link] if s.kind == "capsule"]
        pose = frames[link] @ shape.pose
        half = 0.5 * shape.length * pose[:3, 2]
        return pose[:3, 3] - half, pose[:3, 3] + half, shape.radius

    (p0, p1, ra), (q0, q1, rb) = segment(a), segment(b)
    t = np.linspace(0.0, 1.0, 401)
    pa = p0 + t[:, None] * (p1 - p0)
    pb = q0 + t[:, None] * (q1 - q0)
    return float(np.min(np.linalg.norm(pa[:, None] - pb[None], axis=2))) - ra - rb


def test_closing_on_nothing_pinches_thumb_and_index(hand, empty_hand):
    """The opposing thumb: with no object the thumb's and the index's distal links end
    within the contact distance of each other (independent capsule geometry, 401 samples
    per axis: up to 0.05 mm above the exact distance)."""
    thumb, index = hand.link_index("thumb_distal"), hand.link_index("index_distal")
    for _, row in empty_hand.iterrows():
        gap = _link_gap(hand, np.asarray(row.q), thumb, index)
        assert -PARAMS.penetration_tolerance_mm <= gap <= PARAMS.contact_distance_mm + 0.05


@pytest.mark.parametrize("table", ["softhand_opposed", "softhand_human_higher"])
def test_open_path_pinches_thumb_with_index_and_middle(hand, table):
    """Along q_r(σ) itself the thumb's distal link meets the index's and the middle's while
    the index is still bending (a pinch, not a fist on the curled index: docs/synergies.md)."""
    path = SynergyPath.along(load_synergies(table, joint_names=hand.joint_names), hand.lower, hand.upper)
    lo, hi = path.closure_range(hand.flexion_joints)
    thumb = hand.link_index("thumb_distal")
    index = [hand.joint_names.index(f"index_{j}") for j in ("mcp", "pip", "dip")]
    for other in ("index_distal", "middle_distal"):
        sigmas = np.linspace(lo, hi, 121)
        gaps = np.array([_link_gap(hand, path.reference(s), thumb, hand.link_index(other)) for s in sigmas])
        assert gaps.min() <= PARAMS.contact_distance_mm, other
        first = sigmas[np.argmax(gaps <= PARAMS.contact_distance_mm)]
        assert np.all(path.reference(first)[index] < hand.upper[index] - 0.05), (other, first)


def test_a_target_behind_the_palm_ends_touching_and_not_intersecting_the_open_hand(hand, synergies):
    """The box turned by (α, β) stops at first touch of the open hand when its target lies
    behind the palm face (the earlier fixed placement dropped such a pose)."""
    from synergrasp.simulation.closure import closure_model, place_object

    behind = study_placement(mode="fixed", center_mm=(0.0, 0.0, 50.0))
    model = closure_model(hand, synergies, PARAMS)
    try:
        for alpha, beta in [(0.0, 0.0), (-30.0, 20.0), (45.0, -60.0)]:
            placed = place_object(model.scene, model.q_open, behind, CUBE.shape, alpha, beta)
            model.scene.set_posture(model.q_open)
            gap = float(np.min(model.scene.object_distance()))
            assert -1e-9 <= gap <= 0.011, (alpha, beta, gap)  # touching (to round-off), not intersecting
            assert placed.center_mm[0] > 0.0  # stopped in front of the target, on the palm normal
            np.testing.assert_allclose(placed.center_mm[1:], [0.0, 50.0], atol=1e-12)
    finally:
        model.close()
    table = simulate_object(hand, synergies, CUBE, behind, PARAMS, poses=[0])
    assert table.status.iloc[0] == "grasp" and table.n_contacts.iloc[0] > 0


@pytest.mark.parametrize("mode", ["fixed", "approach"])
def test_a_reachable_target_puts_the_box_centre_on_it(hand, synergies, mode):
    """A target the box reaches without touching the open hand: the centre is the target."""
    from synergrasp.simulation.closure import closure_model, place_object

    target = (90.0, -9.0, 100.0)
    placement = study_placement(mode=mode, center_mm=target, approach_point_mm=target)
    model = closure_model(hand, synergies, PARAMS)
    try:
        for alpha, beta in [(0.0, 0.0), (35.0, -45.0)]:
            placed = place_object(model.scene, model.q_open, placement, PLATE.shape, alpha, beta)
            np.testing.assert_array_equal(placed.center_mm, target)
            model.scene.set_posture(model.q_open)
            assert float(np.min(model.scene.object_distance())) > 0.0
    finally:
        model.close()


def test_the_approach_preset_is_the_earlier_approach_bit_for_bit(hand, synergies, grid):
    """With its target on the palm face the box always touches before reaching it, so the
    rule takes exactly the earlier approach's steps (bring_object without the stop at the point)."""
    from synergrasp.simulation.closure import closure_model, place_object

    model = closure_model(hand, synergies, PARAMS)
    point, normal = approach_line(PLACEMENT, hand)
    try:
        for shape in (CUBE.shape, PLATE.shape, Box((100.0, 60.0, 100.0))):
            for pose in range(0, grid.n_poses, 97):
                a, b = grid.angles_deg(pose)
                placed = place_object(model.scene, model.q_open, PLACEMENT, shape, a, b)
                turned = object_pose(PLACEMENT, shape, a, b, hand.palm_normal)
                earlier = model.scene.bring_object(shape, turned.rotation, point, normal, model.q_open, PLACEMENT.clearance_mm)
                np.testing.assert_array_equal(placed.center_mm, earlier.center_mm)
                np.testing.assert_array_equal(placed.rotation, earlier.rotation)
    finally:
        model.close()


@pytest.mark.parametrize(
    "target",
    [(-20.0, -9.0, 52.0), (9.5, -50.0, 20.0), (29.5, 30.0, 180.0), (49.5, -10.0, 100.0), (9.5, 10.0, 120.0), (38.0, 5.0, 112.0)],
)
def test_no_pose_is_dropped_at_any_target(hand, synergies, target):
    obj4 = GraspedObject("obj4", Box((100.0, 60.0, 100.0)), 1.0)
    placement = study_placement("obj4", mode="searched", target_mm=target)
    table = simulate_object(hand, synergies, obj4, placement, PARAMS, poses=range(0, 1800, 131))
    assert "intersects_open_hand" not in set(table.status)


def test_table_round_trips_through_parquet_into_grasps(sample, tmp_path):
    _, _, tables = sample
    table = tables["obj2"]
    path = tmp_path / "contacts.parquet"
    write_table(CONTACTS, table, str(path))
    back = pd.read_parquet(path)
    assert back["pose"].dtype == np.int32
    grasps = read_grasps(back)
    assert len(grasps) == len(table)
    for g, (_, row) in zip(grasps, table.iterrows()):
        if row.status != "grasp":
            assert g is None
            continue
        assert g.points.shape == (row.n_contacts, 3)
        assert g.jacobian.shape == (3 * row.n_contacts, 19)
        np.testing.assert_array_equal(g.links, row.contact_link)
        np.testing.assert_allclose(g.center, row.object_center)


def test_simulate_object_rejects_poses_off_the_grid(hand, synergies):
    with pytest.raises(ValueError, match="poses"):
        simulate_object(hand, synergies, CUBE, PLACEMENT, PARAMS, poses=[1800])


def _final_rows(sample, empty_hand):
    _, _, tables = sample
    return [
        row for table in [*tables.values(), empty_hand] for _, row in table.iterrows() if row.status != "intersects_open_hand"
    ]


def test_every_finger_ends_in_contact_blocked_by_the_hand_or_at_its_limits(hand, synergies, sample, empty_hand):
    from synergrasp.simulation.closure import closure_model

    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    closed = path.reference(path.closure_range(hand.flexion_joints)[1])
    model = closure_model(hand, synergies, PARAMS)
    try:
        for row in _final_rows(sample, empty_hand):
            q = np.asarray(row.q)
            model.scene.set_posture(q)
            gaps = model.scene.pair_distances(model.self_pairs)
            near = [pair for pair, gap in zip(model.self_pairs, gaps) if gap <= PARAMS.contact_distance_mm]
            for f, (state, joints, links) in enumerate(zip(row.finger_state, hand.finger_joints, hand.finger_links)):
                if state == "contact":
                    assert set(links) & set(int(v) for v in row.contact_link)
                elif state == "self":
                    assert any(a in links or b in links for a, b in near), (row.pose, f)
                else:
                    assert state == "limit"
                    np.testing.assert_allclose(q[list(joints)], closed[list(joints)], atol=1e-12)
    finally:
        model.close()


def test_no_two_hand_links_overlap_at_the_end(hand, synergies, sample, empty_hand):
    """Independent check with pybullet's collision pipeline: no monitored pair of hand links
    overlaps by more than the tolerance at the end of a closure."""
    from synergrasp.simulation import bullet
    from synergrasp.simulation.closure import closure_model

    model = closure_model(hand, synergies, PARAMS)
    client = bullet.connect()
    body = bullet_reference.load_hand_body(client, hand)
    try:
        for row in _final_rows(sample, empty_hand):
            bullet.set_posture(client, body, np.asarray(row.q))
            pts = bullet.self_closest_points(client, body, 0.0, model.self_pairs)
            assert np.all(pts.distance >= -PARAMS.tolerance_mm - 0.05), (row.object, row.pose, pts.distance.min())
    finally:
        model.close()
        bullet.disconnect(client)


# ------------------------------------------------------------------ approach placement


def test_palm_centre_is_the_middle_of_the_palm_face(hand):
    """The shipped palm is one box: centre (-2.5, -9, 52), 24 mm thick along the palm normal x."""
    np.testing.assert_allclose(palm_centre(hand), [9.5, -9.0, 52.0], atol=1e-9)


@pytest.mark.parametrize("clearance", [0.0, 3.0])
def test_approach_brings_the_box_to_the_open_hand(hand, synergies, clearance):
    """At every pose the box ends on the approach line, ``clearance`` from the open hand
    (independent check: pybullet distance at the open posture), never intersecting it."""
    from synergrasp.simulation.closure import closure_model, place_object

    placement = study_placement(clearance_mm=clearance)
    point, normal = approach_line(placement, hand)
    model = closure_model(hand, synergies, PARAMS)
    try:
        for alpha, beta in [(0.0, 0.0), (-30.0, 0.0), (45.0, 20.0), (90.0, -60.0)]:
            placed = place_object(model.scene, model.q_open, placement, PLATE.shape, alpha, beta)
            offset = placed.center_mm - point
            np.testing.assert_allclose(offset - (offset @ normal) * normal, 0.0, atol=1e-9)
            model.scene.set_posture(model.q_open)
            gap = float(np.min(model.scene.object_distance(100.0)))
            assert clearance - 1e-6 <= gap <= clearance + 0.02
    finally:
        model.close()


def test_large_box_brought_to_the_palm_ends_with_a_palm_contact(hand, synergies):
    cube = GraspedObject("obj3", Box((60.0, 60.0, 60.0)), 1.0)
    table = simulate_object(hand, synergies, cube, PLACEMENT, PARAMS, poses=[pose_grid(PLACEMENT).index(0.0, 0.0)])
    row = table.iloc[0]
    assert row.status == "grasp"
    assert 0 in list(row.contact_link)  # link 0 is the palm


def test_approach_never_drops_a_pose(sample):
    _, _, tables = sample
    for table in tables.values():
        assert "intersects_open_hand" not in set(table.status)
