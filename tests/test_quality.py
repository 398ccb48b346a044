"""Grasp quality indices against closed forms and independent computations: the Ferrari–Canny
ε against a brute-force facet enumeration and HiGHS linear programmes (no Qhull), σ_min against
scipy's SVD and a closed form."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import linprog

from synergrasp.optimisation.mechanics import Grasp
from synergrasp.optimisation.quality import (
    ferrari_canny_l1,
    grasp_quality,
    primitive_wrenches,
    scaled_grasp_matrix,
    synergy_manipulability,
)


def _grasp(points, normals, n_joints=2, jacobian=None):
    points = np.asarray(points, dtype=float)
    m = len(points)
    jac = np.zeros((3 * m, n_joints)) if jacobian is None else jacobian
    return Grasp(points=points, normals=np.asarray(normals, dtype=float), links=np.arange(m), jacobian=jac, center=np.zeros(3))


def _cube_face_grasp(a):
    """One contact at the centre of each face of a cube of half edge a, normals inward."""
    axes = np.vstack([np.eye(3), -np.eye(3)])
    return _grasp(a * axes, -axes)


def test_sigma_min_and_isotropy_of_the_face_centre_grasp_in_closed_form():
    # G_L G_Lᵀ = diag(6 I, 4 a² / L² I): singular values √6 (forces) and 2a/L (torques)
    a, L = 15.0, 15.0 * math.sqrt(3.0)
    q = grasp_quality(_cube_face_grasp(a), mu=0.5, length_mm=L)
    assert q.rank_G == 6
    assert q.sigma_min == pytest.approx(2.0 * a / L, rel=1e-12)
    assert q.isotropy == pytest.approx((2.0 * a / L) / math.sqrt(6.0), rel=1e-12)


def _random_grasp(rng, m):
    """m contacts on a sphere of radius 20 mm, normals inward, tilted at random."""
    p = rng.normal(size=(m, 3))
    p = 20.0 * p / np.linalg.norm(p, axis=1, keepdims=True)
    n = -p / 20.0 + 0.3 * rng.normal(size=(m, 3))
    return _grasp(p, n / np.linalg.norm(n, axis=1, keepdims=True))


@pytest.mark.parametrize("seed", range(5))
def test_sigma_min_against_scipy_svd(seed):
    rng = np.random.default_rng(seed)
    g = _random_grasp(rng, 4)
    q = grasp_quality(g, mu=0.8, length_mm=20.0)
    sv = sla.svdvals(scaled_grasp_matrix(g.points, g.center, 20.0))
    assert q.sigma_min == pytest.approx(sv[-1], rel=1e-10)
    assert q.isotropy == pytest.approx(sv[-1] / sv[0], rel=1e-10)


def _epsilon_by_facets(W):
    """ε by brute force: every 6-subset of the wrenches spans a hyperplane a·x = 1; it is a
    facet if no wrench lies beyond it; ε = the least 1/|a| over facets (0 unless the origin is
    strictly inside, i.e. every direction is bounded by some facet: checked by an LP)."""
    best = math.inf
    for idx in itertools.combinations(range(len(W)), 6):
        A = W[list(idx)]
        if abs(np.linalg.det(A)) < 1e-12:
            continue
        a = np.linalg.solve(A, np.ones(6))
        if np.all(W @ a <= 1.0 + 1e-9):
            best = min(best, 1.0 / np.linalg.norm(a))
    return best


def _radial(W, u):
    """Largest t with t u in conv(W) (HiGHS): the hull's radial function along u (-inf: the
    line through the origin along u misses the hull)."""
    k = len(W)
    c = np.zeros(k + 1)
    c[-1] = -1.0
    A_eq = np.zeros((7, k + 1))
    A_eq[:6, :k], A_eq[:6, -1] = W.T, -u
    A_eq[6, :k] = 1.0
    res = linprog(c, A_eq=A_eq, b_eq=np.r_[np.zeros(6), 1.0], bounds=[(0, None)] * k + [(None, None)], method="highs")
    if res.status == 2:  # the line through the origin along u misses the hull
        return -math.inf
    assert res.status == 0
    return -res.fun


@pytest.mark.parametrize("seed", range(8))
def test_epsilon_against_facet_enumeration_and_linear_programmes(seed):
    rng = np.random.default_rng(100 + seed)
    g = _random_grasp(rng, 4)
    W = primitive_wrenches(g, mu=1.0, length_mm=20.0, edges=4)  # 16 wrenches: 8,008 subsets
    eps = ferrari_canny_l1(W)
    # the origin is strictly inside iff the radial function is positive in ± every axis and
    # in random directions; then ε is the nearest facet's distance
    dirs = rng.normal(size=(60, 6))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    radial = np.array([_radial(W, u) for u in np.vstack([np.eye(6), -np.eye(6), dirs])])
    if radial.min() <= 1e-9:
        assert eps == 0.0
        return
    assert eps == pytest.approx(_epsilon_by_facets(W), rel=1e-8)
    assert np.all(radial >= eps * (1 - 1e-9))  # the ball of radius ε lies inside the hull


def test_epsilon_is_positive_for_a_force_closure_grasp_and_bounded_by_the_radial_function():
    g = _cube_face_grasp(15.0)
    W = primitive_wrenches(g, mu=0.8, length_mm=15.0 * math.sqrt(3.0), edges=8)
    eps = ferrari_canny_l1(W)
    assert eps > 0.05
    for u in np.vstack([np.eye(6), -np.eye(6)]):
        assert _radial(W, u) >= eps * (1 - 1e-9)


def test_epsilon_is_zero_for_rank_deficient_and_non_closure_grasps():
    # two opposing contacts: the wrenches span < 6 dimensions (no torque about their line)
    two = _grasp([[0, 0, 10.0], [0, 0, -10.0]], [[0, 0, -1.0], [0, 0, 1.0]])
    assert grasp_quality(two, mu=1.0, length_mm=10.0).epsilon == 0.0
    assert grasp_quality(two, mu=1.0, length_mm=10.0).rank_G < 6
    # four contacts on one face: every force pushes along -z, the origin is outside the hull
    face = [[x, y, 10.0] for x in (-5.0, 5.0) for y in (-5.0, 5.0)]
    one_side = _grasp(face, [[0, 0, -1.0]] * 4)
    q = grasp_quality(one_side, mu=0.5, length_mm=10.0)
    assert q.rank_G == 6 and q.epsilon == 0.0


def test_manipulability_of_a_rigid_translation_and_of_a_squeeze():
    points = [[10.0, 0, 0], [-10.0, 0, 0], [0, 10.0, 0]]
    normals = [[-1.0, 0, 0], [1.0, 0, 0], [0, -1.0, 0]]
    v = np.array([0.0, 0.0, 3.0])
    # synergy 1 moves every contact by v (a rigid translation), synergy 2 squeezes the x pair
    jac = np.zeros((9, 2))
    jac[:, 0] = np.tile(v, 3)
    jac[0, 1], jac[3, 1] = -1.0, 1.0
    g = _grasp(points, normals, jacobian=jac)
    both = synergy_manipulability(g, np.eye(2), length_mm=10.0)
    assert both[0] == pytest.approx(3.0, rel=1e-12)
    assert np.allclose(both[1:], 0.0, atol=1e-12)
    squeeze = synergy_manipulability(g, np.eye(2)[:, 1:], length_mm=10.0)
    assert np.allclose(squeeze, 0.0)


def test_quality_table_rows_for_a_grasp_and_a_pose_without_one(tmp_path):
    import pandas as pd

    from synergrasp import table_contracts
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.optimisation.quality import QualityParams, quality_table
    from synergrasp.simulation.opposition import HandAxes, OppositionRule

    g = _cube_face_grasp(15.0)
    # the palm (link 0) pushes the cube off the palm, the middle fingertip (link 11) back: palm opposition
    contacts = pd.DataFrame(
        {
            "object": ["cube", "cube"],
            "pose": [0, 1],
            "alpha_deg": [0.0, 5.0],
            "beta_deg": [0.0, 0.0],
            "n_contacts": [6, 0],
            "status": ["grasp", "no_contact"],
            "contact_link": [[0, 11, 1, 2, 4, 5], []],
            "contact_normal": [np.r_[1.0, 0, 0, -1.0, 0, 0, np.zeros(12)], np.zeros(0)],
        }
    )
    gfo = pd.DataFrame(
        {
            "object": "cube",
            "pose": [0, 1],
            "set_id": "1-2",
            "force_closure_def1": [True, False],
            "rank_G": [6, 0],
            "force_norm": [19.62, np.nan],
        }
    )
    params = QualityParams(
        hand=None,
        synergies=None,
        mu=0.8,
        full_set_id="1-2",
        weight_N=9.81,
        torque_length_mm=15.0 * math.sqrt(3.0),
        opposition=OppositionRule(45.0, 1.0),
    )
    table = quality_table(contacts, gfo, [g, None], np.zeros((2, 2)), params, HandAxes.from_hand(load_hand()))
    assert table["opposition"].tolist() == ["palm", "none"]
    table_contracts.write(table_contracts.QUALITY, table, tmp_path / "quality.parquet")  # the contract's columns and types
    table = table_contracts.read(table_contracts.QUALITY, tmp_path / "quality.parquet")
    expected = grasp_quality(g, 0.8, params.torque_length_mm)
    first, second = table.iloc[0], table.iloc[1]
    assert first["epsilon"] == pytest.approx(expected.epsilon) and first["rank_G"] == 6
    assert bool(first["force_closure"]) and first["force_per_weight"] == pytest.approx(2.0)
    assert second["rank_G"] == 0 and np.isnan(second["epsilon"]) and not second["force_closure"]
    assert np.isnan(second["force_per_weight"])


def _moved(grasp, delta_mm, links=None):
    return Grasp(
        points=grasp.points + delta_mm,
        normals=grasp.normals,
        links=grasp.links if links is None else links,
        jacobian=grasp.jacobian,
        center=grasp.center,
    )


def test_same_grasp_within_round_off_only():
    from synergrasp.optimisation.mechanics import same_grasp

    g = _random_grasp(np.random.default_rng(3), 5)
    assert same_grasp(g, _moved(g, 1e-12))  # a box's α-period twins differ by about this
    assert not same_grasp(g, _moved(g, 1e-6))
    assert not same_grasp(g, _moved(g, 0.0, links=g.links[::-1].copy()))


def test_quality_table_computes_one_grasp_once_and_shares_it(monkeypatch):
    import pandas as pd

    from synergrasp.hand.kinematics import load_hand
    from synergrasp.optimisation import quality
    from synergrasp.simulation.opposition import HandAxes, OppositionRule

    rng = np.random.default_rng(4)
    a, b = _random_grasp(rng, 5), _random_grasp(rng, 6)
    grasps = [a, b, _moved(a, 1e-12), _moved(b, 1e-6)]  # the third is the first; the fourth is not the second
    calls = []
    real = quality.grasp_quality
    monkeypatch.setattr(quality, "grasp_quality", lambda g, *args, **kw: calls.append(g) or real(g, *args, **kw))
    contacts = pd.DataFrame(
        {
            "object": "box",
            "pose": range(4),
            "alpha_deg": [0.0, 5.0, 90.0, 95.0],
            "beta_deg": 0.0,
            "n_contacts": [5, 6, 5, 6],
            "status": "grasp",
            "contact_link": [g.links for g in grasps],
            "contact_normal": [g.normals for g in grasps],
        }
    )
    gfo = pd.DataFrame(
        {"object": "box", "pose": range(4), "set_id": "1-2", "force_closure_def1": True, "rank_G": 6, "force_norm": 9.81}
    )
    params = quality.QualityParams(
        hand=None,
        synergies=None,
        mu=0.8,
        full_set_id="1-2",
        weight_N=9.81,
        torque_length_mm=20.0,
        opposition=OppositionRule(45.0, 1.0),
    )
    table = quality.quality_table(contacts, gfo, grasps, np.zeros((2, 1)), params, HandAxes.from_hand(load_hand()))
    assert [id(g) for g in calls] == [id(grasps[0]), id(grasps[1]), id(grasps[3])]
    assert table["epsilon"].iloc[2] == table["epsilon"].iloc[0] > 0
    assert table["epsilon"].iloc[3] == pytest.approx(table["epsilon"].iloc[1], rel=1e-3)
