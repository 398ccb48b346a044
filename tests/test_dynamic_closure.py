"""The compliant dynamic closure (closure.model: dynamic): settings, outcomes, the
soft-synergy balance at rest, the net wrench on a held box (palm grasp and pinch),
determinism."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest

from bullet_reference import contact_force_vectors
from conftest import study_closure_params, study_dynamic_params, study_placement
from synergrasp.config import ConfigError, defaults, validate_config
from synergrasp.hand.synergies import Synergies, SynergyPath
from synergrasp.simulation.capsules import HandCapsules
from synergrasp.simulation.closure import SimulateParams, closure_model, simulate_object
from synergrasp.simulation.closure_params import ClosureMechanics, DynamicParams
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.placement import ObjectPose, object_pose
from synergrasp.simulation.shapes import Box

MECHANICS = ClosureMechanics(k_ss_Nmm_per_rad=200.0, mu=1.5, gravity_direction=(1.0, 0.0, 0.0))
PARAMS = study_closure_params(model="dynamic", dynamic=study_dynamic_params(time_limit_s=3.0))
CUBE60 = Box((60.0, 60.0, 60.0))
#: A 60 mm cube against the palm: the palm's surface is at x = 9.5 mm (hand.yaml), the
#: cube's palm-side face 0.3 mm in front of it, centred on the palm's width.
AGAINST_PALM = study_placement(center_mm=(9.5 + 30.0 + 0.3, -9.0, 75.0))


@pytest.fixture(scope="module")
def model(hand, synergies):
    m = closure_model(hand, synergies, PARAMS, MECHANICS, 9.81)
    yield m
    m.close()


def _with_dynamic(**values):
    closure = defaults()["closure"]
    return {**defaults(), "closure": {**closure, "model": "dynamic", "dynamic": {**closure["dynamic"], **values}}}


def test_settings_name_the_key_and_allowed_values():
    """The dynamic settings are checked once, by the schema and the relations of the config."""
    with pytest.raises(ConfigError, match=r"'closure.model': 'soft' is not allowed; allowed values: \['kinematic', 'dynamic'\]"):
        validate_config({**defaults(), "closure": {**defaults()["closure"], "model": "soft"}})
    with pytest.raises(
        ConfigError, match=r"'closure.dynamic.unloaded_contacts': 'ignore' is not allowed; allowed values: \['drop', 'keep'\]"
    ):
        validate_config(_with_dynamic(unloaded_contacts="ignore"))
    with pytest.raises(ConfigError, match=r"'closure.dynamic'.*'timestep'"):
        validate_config(_with_dynamic(timestep=0.01))
    with pytest.raises(
        ConfigError,
        match=r"'closure.dynamic.time_limit_s': 0.2 must be at least "
        r"closure.dynamic.ramp_time_s \(0.3\)",
    ):
        validate_config(_with_dynamic(time_limit_s=0.2))
    # the workflow's one path from the config to the parameters
    config = validate_config(_with_dynamic(settle_window_s=0.1))
    params = SimulateParams.from_config(config, "obj1").closure.dynamic
    assert isinstance(params, DynamicParams) and params.settle_window_s == 0.1 and params.window_ticks == 24
    with pytest.raises(ValueError, match="needs the mechanics block"):
        closure_model(None, None, PARAMS)  # type: ignore[arg-type]


def test_no_object_every_finger_closes_to_its_limits_or_to_the_hand(model, hand):
    far = object_pose(study_placement(center_mm=(600.0, 0.0, 100.0)), CUBE60, 0.0, 0.0, hand.palm_normal)
    result = model.grasp(far)
    assert result.status == "no_contact" and result.settled
    assert np.allclose(result.settled_pose.center_mm, far.center_mm)
    reference = model.path.reference(model.sigma_closed)
    for f, joints in enumerate(hand.finger_joints):
        state = result.finger_state[f]
        assert state in ("limit", "self")
        if state == "limit":  # nothing stops it: at the end of the path (the reference), within 0.02 rad
            assert np.max(np.abs(result.q[list(joints)] - reference[list(joints)])) < 0.02


def test_box_against_the_palm_ends_with_a_palm_contact(model, hand):
    placed = object_pose(AGAINST_PALM, CUBE60, 0.0, 0.0, hand.palm_normal)
    result = model.grasp(placed)
    assert result.status == "grasp" and result.settled
    assert 0 in result.links.tolist()
    # every touching link is listed with its load (which count is decided downstream); the palm carries load
    assert np.all(result.normal_force_N >= 0.0) and result.normal_force_N[result.links.tolist().index(0)] > 0.01
    # contact points on the exact box surface at its settled pose, inward normals
    pose = result.settled_pose
    for point, normal in zip(result.points, result.normals):
        on_box, inward = pose.surface_point(point)
        assert np.allclose(on_box, point, atol=1e-9) and np.allclose(inward, normal, atol=1e-9)


def _generalised_contact_forces(model) -> np.ndarray:
    """Per elementary axis, Jᵢᵀ f summed over every contact of the last step: f the force the
    hand applies to the box at the box contacts, and both sides of every hand–hand contact;
    Jacobians from pybullet at the engine's own joint angles (an independent model)."""
    b, body, client = model.bullet, model.body, model.client
    theta, _ = b.axis_states(client, body)
    n = pb.getNumJoints(body.body, physicsClientId=client)
    positions = [0.0] * n
    for j, v in zip(body.joint_indices, theta):
        positions[int(j)] = float(v)
    total = np.zeros(len(theta))

    def add(link: int, point: np.ndarray, force: np.ndarray) -> None:
        if link <= 0:
            return
        state = pb.getLinkState(body.body, int(body.link_index[link]), computeForwardKinematics=1, physicsClientId=client)
        rotation = np.array(pb.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        local = rotation.T @ (point * 1e-3 - np.array(state[4]))
        lin, _ = pb.calculateJacobian(
            body.body, int(body.link_index[link]), local.tolist(), positions, [0.0] * n, [0.0] * n, physicsClientId=client
        )
        total[:] += (np.array(lin)[:, body.joint_indices] * 1e3).T @ force  # mm/rad · N = N·mm

    links, points, forces = contact_force_vectors(client, model.box, body)
    for (_, lb), p, f in zip(links, points, forces):
        add(int(lb), p, f)
    links, points, forces = contact_force_vectors(client, body, body)
    for (la, lb), p, f in zip(links, points, forces):
        add(int(lb), p, f)
        add(int(la), p, -f)
    return total


def test_at_rest_the_springs_balance_the_contact_forces(hand, synergies):
    """k_ss (q_r − q) = Jᵀ f per joint, checked on every elementary axis off its limits:
    (k_ss/s_i)(s_i q_r − θ_i) = J_iᵀ f within 10 % of the spring torque + 1 N·mm. The
    equilibrium is the model's; to check it rather than the solver's convergence the rest is
    reached with 50 solver iterations and a stricter settle criterion (with the defaults the
    residual is reported in docs/dynamic_closure.md)."""
    tight = study_dynamic_params(time_limit_s=6.0, settle_joint_change_rad=0.0015, settle_object_change_mm=0.1)
    params = study_closure_params(model="dynamic", dynamic=tight)
    model = closure_model(hand, synergies, params, MECHANICS, 9.81)
    placed = object_pose(AGAINST_PALM, CUBE60, 0.0, 0.0, hand.palm_normal)
    try:
        _check_balance(model, hand, params, model.grasp(placed))
    finally:
        model.close()


def _check_balance(model, hand, params, result):
    assert result.settled and result.status == "grasp"
    theta, _ = model.bullet.axis_states(model.client, model.body)
    scale, axis = model.axis_scale, model.axis_joint
    reference = scale * model.path.reference(model.sigma_closed)[axis]
    spring = model.k_ss / scale * (reference - theta)
    contact = _generalised_contact_forces(model)
    # fingers pressed against the hand itself are left out: on them the residual reached
    # ~8 N·mm of 18 (docs/dynamic_closure.md); every finger touching only the box is checked
    links, _, _ = contact_force_vectors(model.client, model.body, model.body)
    against_hand = {hand.link_finger[int(k)] for k in links.ravel()}
    checked = np.array([hand.joint_names[j].split("_")[0] not in against_hand for j in axis])
    off_limits = checked & (theta > scale * hand.lower[axis] + 0.01) & (theta < scale * hand.upper[axis] - 0.01)
    assert off_limits.sum() >= 6 and np.abs(spring[off_limits]).max() > 20.0  # loaded joints are checked
    bad = off_limits & (np.abs(spring - contact) > 0.1 * np.abs(spring) + 1.0)
    assert not bad.any(), [(hand.joint_names[axis[i]], round(spring[i], 2), round(contact[i], 2)) for i in np.flatnonzero(bad)]


def test_deterministic_on_rerun_and_whatever_ran_before(hand, synergies):
    params = study_closure_params(model="dynamic", dynamic=study_dynamic_params(time_limit_s=0.4))
    box, placement = GraspedObject("obj1", Box((30.0, 30.0, 30.0)), 1.0, 9.81), study_placement()
    alone = simulate_object(hand, synergies, box, placement, params, poses=[300], mechanics=MECHANICS)
    after = simulate_object(hand, synergies, box, placement, params, poses=[0, 150, 300], mechanics=MECHANICS)
    for column in ("status", "q", "contact_link", "contact_point", "contact_normal_force_N", "object_center"):
        assert np.array_equal(np.asarray(alone.iloc[0][column]), np.asarray(after.iloc[2][column])), column
    assert after.iloc[2]["closure_model"] == "dynamic"


def test_twins_are_closed_each_on_their_own(hand, synergies, monkeypatch):
    """A free box ends differently at poses that fill one region (docs/closure.md): unlike the
    kinematic model's, the dynamic model's closures are never shared."""
    from synergrasp.simulation import dynamic_closure
    from synergrasp.simulation.placement import pose_grid

    params = study_closure_params(model="dynamic", dynamic=study_dynamic_params(time_limit_s=0.2))
    box, placement = GraspedObject("obj1", Box((30.0, 30.0, 30.0)), 1.0, 9.81), study_placement()
    grid = pose_grid(placement)
    calls = []
    real = dynamic_closure.DynamicClosure.grasp
    monkeypatch.setattr(dynamic_closure.DynamicClosure, "grasp", lambda self, placed: calls.append(1) or real(self, placed))
    table = simulate_object(
        hand, synergies, box, placement, params, poses=[grid.index(-30.0, 0.0), grid.index(60.0, 0.0)], mechanics=MECHANICS
    )
    assert len(calls) == 2 and list(table["closure_model"]) == ["dynamic", "dynamic"]


def test_settled_box_carries_a_near_zero_net_contact_wrench(model, hand):
    """Gravity off: the box at rest between palm, thumb and fingers feels no net wrench from
    its contacts (force within 5 % of the summed contact-force magnitudes; moment about its
    centre within 5 % of that sum times the half edge)."""
    placed = object_pose(AGAINST_PALM, CUBE60, 0.0, 0.0, hand.palm_normal)
    result = model.grasp(placed)
    assert result.settled and {0, 3, 7}.issubset(result.links.tolist())  # palm, thumb and index tips
    _, points, forces = contact_force_vectors(model.client, model.box, model.body)
    scale = np.linalg.norm(forces, axis=1).sum()
    assert scale > 1.0
    assert np.linalg.norm(forces.sum(axis=0)) <= 0.05 * scale
    moment = np.cross(points - result.settled_pose.center_mm, forces).sum(axis=0)
    assert np.linalg.norm(moment) <= 0.05 * scale * 30.0


def test_a_box_pushed_out_of_the_hand_is_lost(hand, synergies):
    """obj4 placed 50 mm in front of the palm (fixed placement, centre (90, 5, 112) mm): at α = −180°,
    β = −40° the closing fingers push it away and nothing holds it (no gravity)."""
    box = GraspedObject("obj4", Box((100.0, 60.0, 100.0)), 1.0, 9.81)
    placement = study_placement(mode="fixed", center_mm=(90.0, 5.0, 112.0), box_axes=(1, 0, 2))
    row = simulate_object(
        hand, synergies, box, placement, study_closure_params(model="dynamic"), poses=[4], mechanics=MECHANICS
    ).iloc[0]
    assert (row["alpha_deg"], row["beta_deg"]) == (-180.0, -40.0)
    assert row["status"] == "lost" and row["n_contacts"] == 0
    assert np.linalg.norm(row["object_translation_mm"]) > 10.0
    assert not HandCapsules.of(hand).encloses(np.asarray(row["q"]), np.asarray(row["object_center"]))
    assert np.allclose(row["object_center"], np.asarray(placement.center_mm) + row["object_translation_mm"])


def test_a_box_moved_but_left_inside_the_closed_hand_is_caged(hand, synergies):
    """obj1 (30 mm cube, approach placement) at α = −180°, β = −60°: the closing fingers push it
    toward the wrist and close past it; nothing touches it at the end, and its centre is inside
    the closed hand's hull, so it is caged, not lost."""
    config = {
        **defaults(),
        "closure": {**defaults()["closure"], "model": "dynamic"},
        "placement": {**defaults()["placement"], "mode": "approach"},
    }
    sim = SimulateParams.from_config(config, "obj1")
    row = simulate_object(hand, synergies, sim.object, sim.placement, sim.closure, poses=[0], mechanics=sim.mechanics).iloc[0]
    assert row["status"] == "caged" and row["n_contacts"] == 0
    assert np.linalg.norm(row["object_translation_mm"]) > sim.closure.dynamic.lost_distance_mm
    assert HandCapsules.of(hand).encloses(np.asarray(row["q"]), np.asarray(row["object_center"]))


def test_thumb_index_pinch_of_a_small_box_settles_with_a_near_zero_net_wrench(hand, synergies):
    """Gravity off: a 20 mm cube on the thumb's pad, pressed by the closing index, ends held
    by the two fingertips alone, with a near-zero net contact wrench (force within 5 % of the
    summed contact-force magnitudes, moment about its centre within 5 % of that sum times the
    half edge). The set-up is the pinch's: the thumb (compliant, k_ss) is held at q_r(σ = 1)
    of S1, the other fingers extended, and only the index closes, along its S1 entries. (Closing
    both along S1 makes the tips cross past each other and roll the box out between them.)"""
    thumb, index = list(hand.finger_joints[0]), list(hand.finger_joints[1])
    mean = np.where(hand.flexion_joints, hand.lower, synergies.mean)
    mean[thumb] = SynergyPath.along(synergies, hand.lower, hand.upper).reference(1.0)[thumb]
    mean[index] = synergies.mean[index]
    closing = np.zeros(hand.n_joints)
    closing[index] = synergies.matrix[index, 0]
    pinch = Synergies(synergies.joint_names, mean, closing[:, None], ("S1",))
    model = closure_model(hand, pinch, PARAMS, MECHANICS, 9.81)
    try:
        # the box's face on the thumb's pad, toward the index tip where the tips are 25 mm apart
        b, edge = model.bullet, 20.0
        tip_t, tip_i = hand.finger_links[0][-1], hand.finger_links[1][-1]
        for sigma in np.linspace(model.sigma_open, model.sigma_closed, 400):
            b.reset_hand(model.client, model.body, model.path.reference(sigma))
            near = b.self_closest_points(model.client, model.body, 500.0, ((tip_t, tip_i),))
            if near.distance.min() <= edge + 5.0:
                break
        k = int(np.argmin(near.distance))
        x = near.point_b[k] - near.point_a[k]
        x /= np.linalg.norm(x)
        y = np.cross(x, [0.0, 0.0, 1.0])
        y /= np.linalg.norm(y)
        placed = ObjectPose(
            near.point_a[k] + (edge / 2 + 0.3) * x, np.stack([x, y, np.cross(x, y)], axis=1), Box((edge, edge, edge))
        )
        result = model.grasp(placed)
        assert result.status == "grasp" and result.settled
        fingertips = set(hand.finger_links[0]) | set(hand.finger_links[1])
        links, points, forces = contact_force_vectors(model.client, model.box, model.body)
        assert set(links[:, 1].tolist()) <= fingertips and set(result.links.tolist()) <= fingertips
        assert {hand.link_finger[link] for link in result.links} == {"thumb", "index"}
        scale = np.linalg.norm(forces, axis=1).sum()
        assert scale > 1.0
        assert np.linalg.norm(forces.sum(axis=0)) <= 0.05 * scale
        moment = np.cross(points - result.settled_pose.center_mm, forces).sum(axis=0)
        assert np.linalg.norm(moment) <= 0.05 * scale * edge / 2
    finally:
        model.close()


def test_a_held_box_stays_put_and_the_fingers_settle_on_it_in_equilibrium(hand, synergies):
    """The pose of test_a_box_pushed_out_of_the_hand_is_lost with ``object: held``: the box
    cannot move, so the same closing fingers end on it, at rest, carrying load; its pose is
    unchanged to the last digit. The end state is an equilibrium of the soft-synergy hand: the
    torque residual of the recorded contacts (synergrasp.optimisation.equilibrium, an
    independent model of the balance) is below 10 % (measured: 2.3 %)."""
    from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium

    box = GraspedObject("obj4", Box((100.0, 60.0, 100.0)), 1.0, 9.81)
    placement = study_placement(mode="fixed", center_mm=(90.0, 5.0, 112.0), box_axes=(1, 0, 2))
    params = study_closure_params(model="dynamic", dynamic=study_dynamic_params(object="held"))
    rows = simulate_object(hand, synergies, box, placement, params, poses=[4], mechanics=MECHANICS)
    row = rows.iloc[0]
    assert row["status"] == "grasp" and row["settled"] and row["n_contacts"] >= 1
    assert row["closure_model"] == "dynamic_held"
    assert np.all(np.asarray(row["contact_normal_force_N"]) > 0.01)
    assert np.array_equal(row["object_center"], placement.center_mm) and row["object_rotation_deg"] == 0.0
    assert np.array_equal(row["object_translation_mm"], np.zeros(3))
    checks = grasp_equilibrium(
        rows, EquilibriumParams.of(hand, synergies, MECHANICS.k_ss_Nmm_per_rad, MECHANICS.mu), synergies.columns([1])[:, 0]
    )
    assert checks["torque_residual"].iloc[0] < 0.1


def test_the_held_setting_is_a_checked_key():
    with pytest.raises(
        ConfigError, match=r"'closure.dynamic.object': 'fixed' is not allowed; allowed values: \['free', 'held'\]"
    ):
        validate_config(_with_dynamic(object="fixed"))
    assert SimulateParams.from_config(validate_config(_with_dynamic(object="held")), "obj1").closure.dynamic.held
    assert not SimulateParams.from_config(defaults(), "obj1").closure.dynamic.held
