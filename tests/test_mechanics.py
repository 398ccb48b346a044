"""Grasp mechanics: grasp matrix, stiffness, particular solution, internal-force basis."""

import numpy as np
import pytest

from synergrasp.optimisation.cones import CircularCone
from synergrasp.optimisation.mechanics import (
    Grasp,
    contact_frames,
    contact_stiffness,
    grasp_matrix,
    grasp_mechanics,
    internal_force_basis,
    weight_wrench,
)
from grasp_problems import LINK_CHAINS, random_grasp, random_synergies

W = 9.81  # N, weight of the 1 kg object


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@pytest.fixture
def grasp():
    return random_grasp(np.random.default_rng(7), 8, palm_contacts=2)


def test_grasp_matrix_columns_are_force_and_moment_about_centre():
    """Column 3i+k of G is the wrench of a unit force along axis k at p_i: [e_k; (p_i - o) x e_k]."""
    rng = np.random.default_rng(0)
    p, o = rng.normal(size=(5, 3)) * 40, np.array([3.0, -2.0, 100.0])
    G = grasp_matrix(p, o)
    assert G.shape == (6, 15)
    for i in range(5):
        for k in range(3):
            e = np.eye(3)[k]
            np.testing.assert_allclose(G[:, 3 * i + k], np.r_[e, np.cross(p[i] - o, e)], atol=1e-12)
    f = rng.normal(size=15)
    F = f.reshape(5, 3)
    np.testing.assert_allclose(G @ f, np.r_[F.sum(0), np.cross(p - o, F).sum(0)], atol=1e-10)


def test_weight_wrench_opposes_weight():
    np.testing.assert_allclose(weight_wrench(W, [0, 0, -1]), [0, 0, W, 0, 0, 0])
    np.testing.assert_allclose(weight_wrench(2 * W, [3.0, 0, 0]), [-2 * W, 0, 0, 0, 0, 0])  # normalised


def test_contact_stiffness_is_spd_inverse_compliance(grasp):
    J = grasp.jacobian
    K = contact_stiffness(J, 1.0, 200.0)
    np.testing.assert_allclose(K, K.T, atol=0)
    assert np.linalg.eigvalsh(K).min() > 0
    C = np.eye(J.shape[0]) / 1.0 + J @ J.T / 200.0
    np.testing.assert_allclose(K @ C, np.eye(J.shape[0]), atol=1e-10)
    # Palm contacts: no joint moves them, so their stiffness is the structural one, k_stru I.
    np.testing.assert_allclose(K[:6, :6], np.eye(6), atol=1e-12)
    np.testing.assert_allclose(K[:6, 6:], 0, atol=1e-12)
    # A single joint driving one contact along d: C = I + L^2 d d^T / k_ss, so K d = d / (1 + L^2/k_ss).
    d, L = _unit([1.0, 2.0, 2.0]), 50.0
    Kd = contact_stiffness((L * d)[:, None], 1.0, 200.0) @ d
    np.testing.assert_allclose(Kd, d / (1 + L**2 / 200.0), rtol=1e-12)
    with pytest.raises(ValueError, match="k_ss"):
        contact_stiffness(J, 1.0, 0.0)


def test_particular_solution_and_projector(grasp):
    w = weight_wrench(W, _unit([0.3, -1.0, -0.2]))
    mech = grasp_mechanics(grasp, w, 1.0, 200.0)
    assert mech.rank_G == 6
    np.testing.assert_allclose(mech.G @ mech.f_p, w, atol=1e-9)
    # The K-weighted least-norm solution: K^-1 f_p lies in range(G^T) (Lagrange condition).
    lam, *_ = np.linalg.lstsq(mech.G.T, np.linalg.solve(mech.K, mech.f_p), rcond=None)
    np.testing.assert_allclose(mech.G.T @ lam, np.linalg.solve(mech.K, mech.f_p), atol=1e-9)
    # Internal forces: G (I - G_K^R G) K J = 0, relative to the size of K J.
    assert np.abs(mech.G @ mech.projector).max() <= 1e-10 * np.abs(mech.KJ).max() * 100
    np.testing.assert_allclose(mech.G @ mech.GKR, np.eye(6), atol=1e-9)


def test_internal_force_basis_orthonormal_and_spans_fs(grasp):
    mech = grasp_mechanics(grasp, weight_wrench(W, [0, 0, -1]), 1.0, 200.0)
    S = random_synergies(np.random.default_rng(3))[:, :5]
    E = internal_force_basis(mech.projector, S, mech.response_norm)
    F = mech.projector @ S
    assert E.shape == (24, 5)
    np.testing.assert_allclose(E.T @ E, np.eye(5), atol=1e-12)
    # Same range: projecting F on range(E) leaves it unchanged, and dimensions agree.
    np.testing.assert_allclose(E @ (E.T @ F), F, atol=1e-10 * np.abs(F).max())
    # A repeated synergy column adds no direction.
    assert internal_force_basis(mech.projector, np.c_[S, S[:, :2] @ [1.0, -2.0]], mech.response_norm).shape[1] == 5


def test_no_internal_force_when_every_hand_motion_moves_the_object_rigidly():
    """Every joint moves all five contacts as one rigid body (J's columns are Gᵀ·twist), so
    the hand can only carry the object along: F_s = 0 exactly, and P = (I − G_K^R G) K J is
    round-off. A rank cut-off relative to ||P|| would take that round-off for five internal
    forces; relative to ||K J|| (the forces the joints produce at all) e_s = 0."""
    rng = np.random.default_rng(1)
    points = np.array([[15.0, 0, 0], [-15.0, 0, 0], [0, 15.0, 0], [0, -15.0, 5.0], [0, 0, 15.0]])
    center = np.zeros(3)
    twists = rng.normal(size=(6, 19)) * np.r_[np.ones(3), np.full(3, 0.02)][:, None]  # mm/rad, rad/rad
    rigid = Grasp(points, -_unit(points), np.arange(5), grasp_matrix(points, center).T @ twists, center)
    mech = grasp_mechanics(rigid, weight_wrench(W, [0, 0, -1]), 1.0, 200.0)
    S = random_synergies(rng)[:, :5]
    assert mech.rank_G == 6
    noise = np.linalg.svd(mech.projector @ S, compute_uv=False)
    assert noise.max() < 1e-12 * mech.response_norm * np.linalg.norm(S, 2)  # round-off of K J S ...
    assert np.sum(noise > 1e-9 * np.linalg.norm(mech.projector, 2) * np.linalg.norm(S, 2)) == 5  # ... yet large vs ||P||
    assert internal_force_basis(mech.projector, S, mech.response_norm).shape[1] == 0


def test_internal_force_basis_rank_decision_on_null_synergies(grasp):
    """Synergies that the projector annihilates (and their round-off) give e_s = 0."""
    mech = grasp_mechanics(grasp, weight_wrench(W, [0, 0, -1]), 1.0, 200.0)
    _, sv, Vt = np.linalg.svd(mech.projector)
    null = Vt[np.sum(sv > 1e-12 * sv[0]) :].T  # joint motions with no internal force
    if null.shape[1] == 0:  # with 6 finger contacts the projector is full column rank
        null = np.zeros((19, 1))
    assert internal_force_basis(mech.projector, null[:, :1], mech.response_norm).shape[1] == 0
    # Mixed: one null direction with one genuine direction gives exactly one.
    S = np.c_[null[:, 0], Vt[0]]
    assert internal_force_basis(mech.projector, S, mech.response_norm).shape[1] == 1
    with pytest.raises(ValueError, match="agree in n"):
        internal_force_basis(mech.projector, np.ones((18, 2)), mech.response_norm)


def test_random_grasp_jacobian_structure():
    g = random_grasp(np.random.default_rng(11), 12, palm_contacts=3)
    assert np.all(g.links[:3] == 0)
    np.testing.assert_array_equal(g.jacobian[:9], 0)
    for i, link in enumerate(g.links):
        rows = g.jacobian[3 * i : 3 * i + 3]
        moving = set(np.flatnonzero(np.abs(rows).sum(0) > 0))
        assert moving == set(LINK_CHAINS[link])
        col_norms = np.linalg.norm(rows[:, list(LINK_CHAINS[link])], axis=0)
        assert np.all(col_norms <= 90.0 + 1e-9)
    # Points on the box surface, normals inward (toward the centre side).
    assert np.all(np.einsum("ij,ij->i", g.normals, g.center - g.points) > 0)


@pytest.mark.parametrize(
    "points, rank",
    [
        ([[-20.0, 0, 0], [20.0, 0, 0]], 5),  # two contacts: rotation about their line is free
        ([[-20.0, 0, 0], [0.0, 0, 0], [35.0, 0, 0]], 5),  # collinear contacts
        ([[-20.0, 0, 0]], 3),  # a single contact resists no torque
        ([[20.0, 0, 0], [-10.0, 17.32, 0], [-10.0, -17.32, 0]], 6),  # three non-collinear
    ],
)
def test_rank_of_known_grasps(points, rank):
    p = np.asarray(points)
    m = len(p)
    normals = np.tile([0.0, 0.0, 1.0], (m, 1))
    g = Grasp(p, normals, np.arange(1, m + 1), np.zeros((3 * m, 19)), np.zeros(3))
    mech = grasp_mechanics(g, weight_wrench(W, [1.0, 0, 0]), 1.0, 200.0)
    assert mech.rank_G == rank
    if rank < 6:
        assert mech.GKR is None and mech.f_p is None and mech.projector is None


def test_contact_frames_and_circular_cone_rows():
    n = _unit(np.random.default_rng(5).normal(size=(50, 3)))
    n[0] = [0, 0, 1.0]
    frames = contact_frames(n)
    np.testing.assert_array_equal(frames[:, 0], n)
    np.testing.assert_allclose(frames @ frames.transpose(0, 2, 1), np.broadcast_to(np.eye(3), (50, 3, 3)), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(frames), 1.0)
    np.testing.assert_array_equal(frames, contact_frames(n))  # deterministic
    R = CircularCone(1.5).soc_rows(frames)
    np.testing.assert_allclose(R[:, 0], 1.5 * n)
    np.testing.assert_array_equal(R[:, 1:], frames[:, 1:])
    # a force at the cone's edge (tangential part mu times the normal part) is on the SOC boundary
    f = frames[:, 0] + 1.5 * frames[:, 1]
    Rf = np.einsum("iab,ib->ia", R, f)
    np.testing.assert_allclose(Rf[:, 0], np.linalg.norm(Rf[:, 1:], axis=1))
    assert CircularCone(1.5).violation(f.ravel(), n, 1.0) == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="unit vectors"):
        contact_frames(n * 2)
    with pytest.raises(ValueError, match="cone.mu"):
        CircularCone(0.0)


def test_grasp_rejects_bad_shapes():
    with pytest.raises(ValueError, match="Grasp.jacobian"):
        Grasp(np.zeros((2, 3)), [[1.0, 0, 0]] * 2, np.array([1, 2]), np.zeros((5, 19)), np.zeros(3))
    with pytest.raises(ValueError, match="Grasp.links"):
        Grasp(np.zeros((2, 3)), [[1.0, 0, 0]] * 2, np.array([1.0, 2.0]), np.zeros((6, 19)), np.zeros(3))
