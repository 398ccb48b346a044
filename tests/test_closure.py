"""Placement, pose grid and the quasi-static closure along S1 (pybullet)."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from synergrasp.simulation.closure import ClosureParams, simulate_object
from synergrasp.simulation.contacts import read_grasps, write_contacts
from synergrasp.simulation.placement import Placement, object_pose, pose_grid
from synergrasp.hand.kinematics import forward_kinematics
from synergrasp.simulation.objects import Box

PARAMS = ClosureParams()
PLACEMENT = Placement()
CUBE = Box("obj1", (30.0, 30.0, 30.0), 1.0)
PLATE = Box("obj2", (30.0, 60.0, 60.0), 1.0)


@pytest.fixture(scope="module")
def grid():
    return pose_grid(PLACEMENT)


@pytest.fixture(scope="module")
def sample(hand, synergies, grid):
    """A spread of poses of two boxes, plus the same poses turned by α + 180°."""
    base = [grid.index(a, b) for a, b in [(-180, 0), (-90, 30), (-30, -60), (5, 10), (45, 20), (10, -25)]]
    mirrored = [(p + 36 * grid.n_beta) % grid.n_poses for p in base]
    tables = {box.name: simulate_object(hand, synergies, box, PLACEMENT, PARAMS, poses=base + mirrored)
              for box in (CUBE, PLATE)}
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


@pytest.mark.parametrize("kwargs, field", [
    ({"box_axes": (0, 0, 2)}, "box_axes"),
    ({"rotation_order": "xyz"}, "rotation_order"),
    ({"center_mm": (1.0, 2.0)}, "center_mm"),
    ({"alpha_deg": (-180.0, 180.0, 5.0)}, "alpha_deg"),
    ({"beta_deg": (-60.0, 61.0, 5.0)}, "beta_deg"),
])
def test_bad_placement_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        Placement(**kwargs)


def test_bad_closure_params_name_the_field():
    with pytest.raises(ValueError, match="sigma_closed"):
        ClosureParams(sigma_open=1.0, sigma_closed=0.0)
    with pytest.raises(ValueError, match="tolerance_mm"):
        ClosureParams(tolerance_mm=0.0)


def test_zero_pose_maps_box_edges_to_palm_axes():
    placed = object_pose(Placement(box_axes=(2, 0, 1)), (10.0, 20.0, 30.0), 0.0, 0.0)
    extent = np.abs(placed.rotation) @ placed.half_extents_mm  # half extent along palm x, y, z
    np.testing.assert_allclose(extent, [15.0, 5.0, 10.0])


def test_alpha_turns_about_palm_normal_then_beta_about_fingers():
    placed = object_pose(PLACEMENT, (10.0, 20.0, 30.0), 90.0, 90.0)
    # α = 90° about x takes box y (20) onto palm z; β = 90° about z takes box x (10) onto palm y
    extent = np.abs(placed.rotation) @ placed.half_extents_mm
    np.testing.assert_allclose(extent, [15.0, 5.0, 10.0], atol=1e-12)


def _corners(placed):
    signs = np.array(list(itertools.product((-1, 1), repeat=3)), dtype=float)
    pts = (signs * placed.half_extents_mm) @ placed.rotation.T + placed.center_mm
    return pts[np.lexsort(np.round(pts, 9).T)]


@pytest.mark.parametrize("alpha, beta", [(-30.0, 0.0), (45.0, 20.0), (-165.0, -60.0)])
def test_alpha_and_alpha_plus_180_place_the_same_box(alpha, beta):
    a = object_pose(PLACEMENT, (100.0, 60.0, 30.0), alpha, beta)
    b = object_pose(PLACEMENT, (100.0, 60.0, 30.0), alpha + 180.0, beta)
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
        half = 0.5 * np.asarray(CUBE.size_mm if row.object == "obj1" else PLATE.size_mm)
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
            np.testing.assert_allclose(jac[3 * i:3 * i + 3], fd, atol=1e-5)
            checked += 1
        if checked >= 12:
            break
    assert checked > 0


def test_closing_on_nothing_ends_at_limits_or_blocked_by_the_hand(hand, synergies):
    far = Placement(center_mm=(600.0, 0.0, 0.0))
    table = simulate_object(hand, synergies, CUBE, far, PARAMS, poses=[0, 900])
    for _, row in table.iterrows():
        assert row.status == "no_contact"
        assert row.n_contacts == 0
        assert set(row.finger_state) <= {"limit", "self"}
        q = np.asarray(row.q)
        reference = np.clip(synergies.mean + PARAMS.sigma_closed * synergies.matrix[:, 0], hand.lower, hand.upper)
        for f, (state, joints) in enumerate(zip(row.finger_state, hand.finger_joints)):
            if state == "limit":  # a free finger followed the reference to the end
                np.testing.assert_allclose(q[list(joints)], reference[list(joints)], atol=1e-12)


def test_box_through_the_palm_is_flagged(hand, synergies):
    inside = Placement(center_mm=(0.0, 0.0, 50.0))
    table = simulate_object(hand, synergies, CUBE, inside, PARAMS, poses=[0])
    assert table.status.iloc[0] == "intersects_open_hand"
    assert table.n_contacts.iloc[0] == 0
    assert read_grasps(table) == [None]


def test_table_round_trips_through_parquet_into_grasps(sample, tmp_path):
    _, _, tables = sample
    table = tables["obj2"]
    path = tmp_path / "contacts.parquet"
    write_contacts(table, str(path))
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
