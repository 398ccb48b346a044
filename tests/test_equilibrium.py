"""The equilibrium checks of a closure's end state (synergrasp.optimisation.equilibrium) on
hand-made grasps whose answers are derived by hand, and on the shipped hand's Jacobian."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from synergrasp.hand.kinematics import contact_jacobian
from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium, push_angles_deg, torque_residual
from synergrasp.optimisation.mechanics import contact_frames


def _one_contact(normal=(1.0, 0.0, 0.0)):
    """One contact moved by three joints as J = I (mm/rad): Jᵀ f = f."""
    return np.eye(3), np.array([normal], dtype=float)


def test_a_torque_inside_the_cone_is_balanced_exactly():
    J, n = _one_contact()
    assert torque_residual(np.array([2.0, 1.0, -0.5]), J, n, mu=1.5) < 1e-6


def test_a_torque_outside_the_cone_leaves_its_distance_to_the_cone():
    """τ = (1, 2, 0) at 63.43° from the normal of a μ = 1 cone (45°): the nearest cone force is
    τ's projection on the cone's edge, so r = sin(63.43° − 45°) = 0.3162."""
    J, n = _one_contact()
    expected = np.sin(np.arctan2(2.0, 1.0) - np.pi / 4)
    assert torque_residual(np.array([1.0, 2.0, 0.0]), J, n, mu=1.0) == pytest.approx(expected, abs=1e-7)


def test_a_torque_that_needs_a_pull_is_not_balanced_at_all():
    J, n = _one_contact()
    assert torque_residual(np.array([-3.0, 0.5, 0.0]), J, n, mu=0.5) == pytest.approx(1.0, abs=1e-7)


def test_no_box_joint_and_no_torque():
    J = np.zeros((3, 4))  # a palm contact: no joint moves it
    assert np.isnan(torque_residual(np.ones(4), J, np.array([[0.0, 0.0, 1.0]]), mu=1.0))
    J, n = _one_contact()
    assert torque_residual(np.zeros(3), J, n, mu=1.0) == 0.0


def _hand_grasp(hand, rng):
    """Five contacts on the shipped hand at a half-closed posture: tips and middle phalanges
    and the palm, points at the link frames' origins, random inward normals."""
    q = 0.5 * (hand.lower + hand.upper)
    names = ["palm", "thumb_distal", "index_distal", "middle_middle", "ring_distal"]
    links = np.array([hand.link_names.index(n) for n in names])
    points = rng.uniform(-20, 20, size=(len(links), 3)) + np.array([30.0, 0.0, 100.0])
    normals = rng.normal(size=(len(links), 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return q, links, points, normals, contact_jacobian(hand, q, links, points)


def test_an_exact_equilibrium_of_the_hand_has_zero_residual_and_a_perturbed_one_does_not(hand):
    """q = q_r − Jᵀ f / k_ss with f strictly inside the cones: τ = Jᵀ f, r = 0 to 1e-6. The
    same grasp with the finger torques reversed needs pulling forces: r is large."""
    rng = np.random.default_rng(7)
    q, links, points, normals, J = _hand_grasp(hand, rng)
    frames = contact_frames(normals)
    f = np.concatenate([fr.T @ np.array([2.0, 0.5, -0.3]) for fr in frames])  # 0.58 N tangential, μ = 1
    q_r = np.clip(q + 0.3, hand.lower, hand.upper)
    params = EquilibriumParams(200.0, 1.0, q_r)
    q_end = q_r - J.T @ f / 200.0
    assert torque_residual(params.torques(q_end), J, normals, 1.0) < 1e-6
    q_reversed = q_r + J.T @ f / 200.0
    assert torque_residual(params.torques(q_reversed), J, normals, 1.0) > 0.9


def test_s1_push_angles_and_the_outside_count_on_a_hand_made_contact():
    """Contact 0 moves at 30° from its normal, contact 1 at 70°, contact 2 backwards (180°),
    contact 3 is not moved by S1: with μ = 1.5 (cone 56.3°) two contacts are outside."""
    synergy = np.array([1.0, 0.0])
    directions = [
        (np.cos(np.radians(30)), np.sin(np.radians(30)), 0.0),
        (np.cos(np.radians(70)), 0.0, np.sin(np.radians(70))),
        (-1.0, 0.0, 0.0),
        (0.0, 0.0, 0.0),
    ]
    J = np.zeros((12, 2))
    J[:, 0] = 5.0 * np.concatenate(directions)  # 5 mm per unit σ along each direction
    J[:, 1] = 1.0  # a second joint S1 does not move
    normals = np.tile([1.0, 0.0, 0.0], (4, 1))
    angles = push_angles_deg(J, normals, synergy)
    np.testing.assert_allclose(angles[:3], [30.0, 70.0, 180.0], atol=1e-9)
    assert np.isnan(angles[3])
    contacts = pd.DataFrame(
        [
            {
                "object": "a",
                "closure_model": "kinematic",
                "pose": 3,
                "status": "grasp",
                "n_contacts": 4,
                "q": [0.0, 0.0],
                "jacobian": J.ravel().tolist(),
                "contact_normal": normals.ravel().tolist(),
                "contact_link": [1, 2, 3, 4],
                "contact_point": [0.0] * 12,
                "object_center": [0.0] * 3,
            }
        ]
    )
    row = grasp_equilibrium(contacts, EquilibriumParams(200.0, 1.5, np.array([0.1, 0.0])), synergy).iloc[0]
    assert (row["s1_outside_cone"], row["s1_pushed_contacts"]) == (2, 3)
    # τ = k_ss (q_r − q) = (20, 0) N·mm on the two joints, both moving a contact
    assert row["torque_box_Nmm"] == pytest.approx(20.0)
    assert row["torque_other_Nmm"] == 0.0


def test_one_grasp_in_one_posture_is_checked_once(monkeypatch):
    """Rows with one grasp and one posture (a box's α-period twins) share the first row's
    checks; the same grasp in another posture is checked on its own."""
    from synergrasp.optimisation import equilibrium

    rng = np.random.default_rng(7)
    J, normals = rng.normal(size=(9, 2)), np.tile([1.0, 0.0, 0.0], (3, 1))
    row = {
        "object": "a",
        "closure_model": "kinematic",
        "status": "grasp",
        "n_contacts": 3,
        "jacobian": J.ravel().tolist(),
        "contact_normal": normals.ravel().tolist(),
        "contact_link": [1, 2, 3],
        "contact_point": rng.normal(size=9).tolist(),
        "object_center": [0.0] * 3,
    }
    contacts = pd.DataFrame(
        [{**row, "pose": 0, "q": [0.0, 0.0]}, {**row, "pose": 1, "q": [0.0, 1e-13]}, {**row, "pose": 2, "q": [0.0, 0.2]}]
    )
    calls = []
    real = equilibrium._one
    monkeypatch.setattr(equilibrium, "_one", lambda r, *a: calls.append(r.pose) or real(r, *a))
    out = grasp_equilibrium(contacts, EquilibriumParams(200.0, 1.0, np.array([0.1, 0.3])), np.array([1.0, 0.0]))
    assert calls == [0, 2]
    assert out.iloc[0].drop("pose").equals(out.iloc[1].drop("pose"))
    assert out["torque_box_Nmm"].iloc[2] != out["torque_box_Nmm"].iloc[0]


def test_the_residual_agrees_with_an_independent_cvxpy_model():
    """Random grasps (2-5 contacts, 6 joints, μ = 0.3-1.5): the same minimum from cvxpy's own
    canonicalisation of min ‖τ − Jᵀ f‖ with cp.SOC on each contact's tangential part."""
    cp = pytest.importorskip("cvxpy")
    rng = np.random.default_rng(2018)
    for _ in range(12):
        m, mu = int(rng.integers(2, 6)), float(rng.uniform(0.3, 1.5))
        J = rng.normal(size=(3 * m, 6)) * 20.0
        normals = rng.normal(size=(m, 3))
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        tau = rng.normal(size=6) * 50.0
        f = cp.Variable(3 * m)
        cones = [
            cp.SOC(
                mu * (normals[i] @ f[3 * i : 3 * i + 3]), f[3 * i : 3 * i + 3] - normals[i] * (normals[i] @ f[3 * i : 3 * i + 3])
            )
            for i in range(m)
        ]
        cp.Problem(cp.Minimize(cp.norm(tau - J.T @ f)), cones).solve(solver="CLARABEL")
        expected = np.linalg.norm(tau - J.T @ f.value) / np.linalg.norm(tau)
        assert torque_residual(tau, J, normals, mu) == pytest.approx(expected, abs=1e-6)
