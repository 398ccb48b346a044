"""What blocks a synergy set (docs/blockers.md), on hand-made grasps whose answer is known,
and the max-margin problem against independent solvers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.blockers import blocker_sets, blockers_summary, contact_labels, set_blockers
from synergrasp.config import defaults
from synergrasp.optimisation.blocking import ACTIVE_TOL, blocking_contacts, contact_margins
from synergrasp.optimisation.cones import CircularCone, PyramidCone
from synergrasp.optimisation.gfo import solve_gfo
from synergrasp.optimisation.mechanics import Grasp, internal_force_basis
from synergrasp.optimisation.optimise import GFOParams, mechanics_for
from synergrasp.optimisation.problem import GFOProblem
from synergrasp.simulation.opposition import HandAxes, OppositionRule, classify_grasp
from synergrasp.simulation.shapes import shape_from_config

X, Y, Z = np.eye(3)
PARAMS = GFOParams.from_config(defaults(), "obj1")  # mu 1.5, f_min 0.1 N, k_stru 1 N/mm, k_ss 200 N mm/rad
RULE = OppositionRule(45.0, 1.0)


@pytest.fixture(scope="module")
def axes(hand):
    return HandAxes.from_hand(hand)


def hand_made(hand, contacts, motions, center):
    """A grasp of contacts (link name, point mm, inward normal) whose joints each move one
    contact point along a direction (contact, direction): the Jacobian column is that
    direction at the contact's rows (mm/rad), zero elsewhere."""
    links = np.array([hand.link_index(name) for name, _, _ in contacts])
    J = np.zeros((3 * len(contacts), len(motions)))
    for j, (i, direction) in enumerate(motions):
        J[3 * i : 3 * i + 3, j] = direction
    return Grasp(
        np.array([p for _, p, _ in contacts], dtype=float),
        np.array([n for _, _, n in contacts], dtype=float),
        links,
        20.0 * J,
        np.asarray(center, dtype=float),
    )


def strict(grasp, S):
    """The study's strict internal-force verdict of one set (Definition 1 at rank 6)."""
    mech = mechanics_for(grasp, PARAMS)
    E = internal_force_basis(mech.projector, S, mech.response_norm)
    problem = GFOProblem(mech.f_p, E, mech.normals, PARAMS.f_min_N, PARAMS.cone)
    return bool(solve_gfo([problem], "clarabel", strict_shrink=1e-5).strict_internal[0])


def test_a_box_squeezed_between_palm_and_fingers_has_no_blocker(hand, axes):
    # the palm pushes the box off the palm (+x); two fingertips close on it (-x)
    contacts = [
        ("palm", (20, 10, -10), X),
        ("palm", (20, -10, -10), X),
        ("middle_distal", (60, 5, 10), -X),
        ("ring_distal", (60, -5, 10), -X),
    ]
    grasp = hand_made(hand, contacts, [(2, -X), (3, -X)], (40, 0, 0))
    S = np.array([[1.0, 1.0], [1.0, -1.0]]) / math.sqrt(2)  # S1 closes both, S2 one against the other
    full, s1 = set_blockers(grasp, S, [(1, 2), (1,)], PARAMS)
    for found in (full, s1):
        assert found.rank_G == 6 and found.reason == "contacts"
        assert found.blocking.margin > 0.05  # strictly inside every cone: nothing blocks
    assert s1.e_s == 1 and full.e_s == 2
    assert strict(grasp, S) and strict(grasp, S[:, :1])
    assert classify_grasp(grasp.links, grasp.normals, axes, RULE) == "palm"


def test_a_pinch_squeezes_and_a_rigid_motion_reaches_no_internal_force(hand, axes):
    contacts = [("thumb_distal", (40, -20, 0), Y), ("index_distal", (40, 20, 8), -Y), ("middle_distal", (40, 20, -8), -Y)]
    grasp = hand_made(hand, contacts, [(0, Y), (1, -Y), (2, -Y)], (40, 0, 0))
    S = np.array([[1.0, -1.0], [1.0, 1.0], [1.0, 1.0]]) / math.sqrt(3)
    pinch, rigid = set_blockers(grasp, S, [(1,), (2,)], PARAMS)
    assert pinch.reason == "contacts" and pinch.blocking.margin > 0.05
    # S2 moves every contact the same way: a rigid motion of the box, no internal force
    assert rigid.e_s == 0 and rigid.reason == "no_internal_force" and not rigid.blocking.blockers.any()
    assert not strict(grasp, S[:, 1:])
    assert classify_grasp(grasp.links, grasp.normals, axes, RULE) == "pad"


def one_sided_push(hand):
    """obj4's grasp before the grasp type, by hand: the palm and the index and middle tips on
    the box face toward the palm (all pushing the box away from the palm, +x), the thumb and
    little tips on its sides. S1 curls the index and middle tips toward the palm (-x, off the
    box) and closes thumb and little on the sides; each tip has three joints (x, y, z)."""
    contacts = [
        ("palm", (20, 0, -15), X),
        ("index_distal", (20, 25, 25), X),
        ("middle_distal", (20, -25, 25), X),
        ("thumb_distal", (50, -30, 0), Y),
        ("little_distal", (50, 30, 0), -Y),
    ]
    motions = [(i, d) for i in range(1, 5) for d in (X, Y, Z)]
    grasp = hand_made(hand, contacts, motions, (50, 0, 0))
    s1 = np.zeros(len(motions))
    s1[[0, 3]] = -1.0  # index, middle tips: -x
    s1[7], s1[10] = 1.0, -1.0  # thumb +y, little -y
    S = np.column_stack([s1 / np.linalg.norm(s1), np.eye(len(motions))])
    return grasp, S


def test_a_one_sided_fingertip_push_blocks_s1_at_the_fingertips(hand, axes):
    grasp, S = one_sided_push(hand)
    assert classify_grasp(grasp.links, grasp.normals, axes, RULE) == "none"
    full, s1 = set_blockers(grasp, S, [tuple(range(2, S.shape[1] + 1)), (1,)], PARAMS)
    assert full.reason == "contacts" and full.blocking.margin > 0 and strict(grasp, S[:, 1:])
    assert s1.e_s == 1 and s1.reason == "contacts" and s1.blocking.margin < 0 and not strict(grasp, S[:, :1])
    names = {hand.link_names[grasp.links[k]] for k in np.flatnonzero(s1.blocking.blockers)}
    assert names == {"index_distal", "middle_distal"}  # mirror twins: both, to round-off
    assert (s1.blocking.normal_force[s1.blocking.blockers] < 0).all()  # they pull: S1 curls them off the box
    box = shape_from_config({"box": {"size_mm": [60, 60, 60]}}, "test")
    labels = contact_labels(grasp, np.eye(3), box, hand.link_names, axes, RULE)
    at = np.flatnonzero(s1.blocking.blockers)
    assert {labels.kinds[k] for k in at} == {"finger_pad"}
    assert {labels.faces[k] for k in at} == {"palm_face"} and {labels.features[k] for k in at} == {"face"}


def test_with_one_internal_force_the_blockers_are_worked_out_by_hand(hand):
    """e_s = 1: f = y e; the normalisation sum_i n_i.f_i = 1 fixes y = 1 / sum_i n_i.e_i (the
    sign that squeezes), t* is the least contact margin of that force and the blockers are
    the contacts at it: contacts outside their cone or with non-positive normal force along
    the one internal force, the worst of them. The reverse sign pulls somewhere (its total
    normal force is negative), so the set is blocked iff a contact of this force is."""
    grasp, S = one_sided_push(hand)
    mech = mechanics_for(grasp, PARAMS)
    e = internal_force_basis(mech.projector, S[:, :1], mech.response_norm)[:, 0]
    n = mech.normals
    E3 = e.reshape(-1, 3)
    f = e / float(np.einsum("ij,ij->", n, E3))
    F = f.reshape(-1, 3)
    fn = np.einsum("ij,ij->i", F, n)
    margin = 1.5 * fn - np.linalg.norm(F - fn[:, None] * n, axis=1)
    found = blocking_contacts(GFOProblem(mech.f_p, e[:, None], n, 0.1, CircularCone(1.5)))
    assert found.margin == pytest.approx(margin.min(), abs=1e-7)
    np.testing.assert_allclose(found.contact_margin, margin, atol=1e-7)
    np.testing.assert_array_equal(found.blockers, margin <= margin.min() + ACTIVE_TOL)
    assert ((margin <= 0) | (fn <= 0))[found.blockers].all()


def random_problem(rng, m, e, cone):
    normals = rng.normal(size=(m, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    E = np.linalg.qr(rng.normal(size=(3 * m, e)))[0]
    return GFOProblem(np.zeros(3 * m), E, normals, 0.1, cone)


def test_t_star_agrees_with_cvxpy_and_with_a_search_along_the_line():
    cp = pytest.importorskip("cvxpy")
    rng = np.random.default_rng(36)
    for _ in range(12):
        m, e = int(rng.integers(3, 8)), int(rng.integers(1, 5))
        problem = random_problem(rng, m, e, CircularCone(float(rng.uniform(0.3, 1.5))))
        found = blocking_contacts(problem)
        # cvxpy: the tangential part without contact frames, its own canonicalisation
        y, t = cp.Variable(e), cp.Variable()
        F = [problem.E[3 * i : 3 * i + 3] @ y for i in range(m)]
        fn = [problem.normals[i] @ F[i] for i in range(m)]
        cons = [sum(fn) == 1] + [cp.norm(F[i] - fn[i] * problem.normals[i]) <= problem.cone.mu * fn[i] - t for i in range(m)]
        cp.Problem(cp.Maximize(t), cons).solve(solver="CLARABEL")
        assert found.margin == pytest.approx(float(t.value), abs=1e-6 * max(1.0, abs(float(t.value))))
    # e_s = 2: the feasible y lie on a line; t(y) is concave on it, so a ternary search finds t*
    for _ in range(6):
        problem = random_problem(rng, 5, 2, CircularCone(1.0))
        c = np.einsum("ij,ijk->k", problem.normals, problem.E.reshape(5, 3, 2))
        y0, d = c / (c @ c), np.array([-c[1], c[0]])

        def t_at(s):
            return contact_margins(problem.E @ (y0 + s * d), problem).min()

        lo, hi = -1e4, 1e4
        for _ in range(300):
            a, b = lo + (hi - lo) / 3, hi - (hi - lo) / 3
            lo, hi = (a, hi) if t_at(a) < t_at(b) else (lo, b)
        assert blocking_contacts(problem).margin == pytest.approx(t_at(0.5 * (lo + hi)), abs=1e-6)


def test_pyramid_t_star_agrees_with_a_linear_programme():
    from scipy.optimize import linprog

    rng = np.random.default_rng(7)
    for _ in range(8):
        m, e = int(rng.integers(3, 7)), int(rng.integers(1, 4))
        problem = random_problem(rng, m, e, PyramidCone(1.0, 8, True))
        from synergrasp.optimisation.mechanics import contact_frames

        faces = problem.cone.face_rows(contact_frames(problem.normals))  # a_k: a_k.f <= 0 inside
        A = np.einsum("isj,ijk->isk", faces, problem.E.reshape(m, 3, e)).reshape(-1, e)
        c = np.einsum("ij,ijk->k", problem.normals, problem.E.reshape(m, 3, e))
        # max t: a_k.E y + t <= 0, c.y = 1
        res = linprog(
            np.r_[np.zeros(e), -1.0],
            A_ub=np.hstack([A, np.ones((A.shape[0], 1))]),
            b_ub=np.zeros(A.shape[0]),
            A_eq=np.r_[c, 0.0][None, :],
            b_eq=[1.0],
            bounds=[(None, None)] * (e + 1),
            method="highs",
        )
        assert res.status == 0
        assert blocking_contacts(problem).margin == pytest.approx(-res.fun, abs=1e-6)


def test_sets_examined_and_the_summary_counts_poses():
    sets = blocker_sets({"hierarchy_first": 3, "incremental_max": 15})
    assert list(sets) == ["1", "1-2", "1-2-3", "2", "3"]
    assert list(blocker_sets({"hierarchy_first": 3, "incremental_max": 2})) == ["1", "1-2", "2", "3"]
    rows = pd.DataFrame(
        {
            "object": ["a", "a", "a"],
            "set_id": ["1", "1", "2"],
            "reason": ["contacts", "contacts", "no_internal_force"],
            "margin": [-1.0, -0.5, np.nan],
            "blocker_link_kind": [["finger_pad", "palm"], ["finger_pad"], []],
            "blocker_face": [["palm_face", "palm_face"], ["side_face"], []],
            "blocker_feature": [["edge", "face"], ["corner"], []],
        }
    )
    table = blockers_summary(rows, sets).set_index(["object", "set_id"])
    assert table.loc[("a", "1"), "n_failing"] == 2
    assert table.loc[("a", "1"), "pct_kind_finger_pad"] == 100.0 and table.loc[("a", "1"), "pct_kind_palm"] == 50.0
    assert table.loc[("a", "1"), "pct_face_palm_face"] == 50.0 and table.loc[("a", "1"), "pct_feature_corner"] == 50.0
    assert table.loc[("a", "2"), "pct_no_internal_force"] == 100.0 and table.loc[("a", "2"), "pct_kind_palm"] == 0.0
    assert table.loc[("all", "1"), "n_failing"] == 2 and table.loc[("a", "3"), "n_failing"] == 0


def test_the_table_solves_twin_poses_once_and_keeps_its_contract(hand, axes, tmp_path, monkeypatch):
    from synergrasp import table_contracts
    from synergrasp.analysis import blockers as module

    grasp, S = one_sided_push(hand)
    m = grasp.n_contacts
    row = {
        "object": "box",
        "alpha_deg": 0.0,
        "beta_deg": 0.0,
        "status": "grasp",
        "n_contacts": m,
        "contact_link": grasp.links.tolist(),
        "contact_point": grasp.points.ravel().tolist(),
        "contact_normal": grasp.normals.ravel().tolist(),
        "jacobian": grasp.jacobian.ravel().tolist(),
        "object_center": grasp.center.tolist(),
        "object_rotation": np.eye(3).ravel().tolist(),
    }
    contacts = pd.DataFrame([{**row, "pose": 0}, {**row, "pose": 1, "alpha_deg": 90.0}])
    full_id = "-".join(str(k) for k in range(2, S.shape[1] + 1))
    gfo = pd.DataFrame(
        [
            {
                "object": "box",
                "pose": p,
                "alpha_deg": 90.0 * p,
                "beta_deg": 0.0,
                "set_id": sid,
                "n_synergies": n,
                "status": "feasible",
                "load_feasible": True,
                "force_closure_def1": ok,
                "rank_G": 6,
                "force_norm": 1.0,
            }
            for p in (0, 1)
            for sid, n, ok in ((full_id, S.shape[1] - 1, True), ("1", 1, False))
        ]
    )
    box = shape_from_config({"box": {"size_mm": [60, 60, 60]}}, "test")
    params = module.BlockersParams(None, None, PARAMS, {"1": (1,)}, full_id, RULE, box)
    calls = []
    solve = module.set_blockers
    monkeypatch.setattr(module, "set_blockers", lambda *a: calls.append(a) or solve(*a))
    table = module.blockers_table(contacts, gfo, hand.link_names, axes, S, params)
    assert len(calls) == 1 and list(table["pose"]) == [0, 1] and list(table["alpha_deg"]) == [0.0, 90.0]
    assert table["blocker_link_name"].tolist() == [["index_distal", "middle_distal"]] * 2
    table_contracts.write(table_contracts.BLOCKERS, table, tmp_path / "blockers.parquet")
    back = table_contracts.read(table_contracts.BLOCKERS, tmp_path / "blockers.parquet")
    assert back["margin"].tolist() == table["margin"].tolist() and back["reason"].tolist() == ["contacts"] * 2


def test_the_summary_one_object_at_a_time_is_the_summary_of_every_objects_rows(monkeypatch):
    """Two objects' files read one at a time (handed in unsorted): the same table, to the
    last digit, as from both objects' rows at once; the pooled median margin by hand."""
    from synergrasp.analysis import blockers as module

    def rows(obj, margins, kinds):
        return pd.DataFrame(
            {
                "object": obj,
                "set_id": ["1"] * len(margins),
                "reason": ["contacts"] * len(margins),
                "margin": margins,
                "blocker_link_kind": kinds,
                "blocker_face": [["palm_face"]] * len(margins),
                "blocker_feature": [["edge"]] * len(margins),
            }
        )

    frames = {
        "r/b/blockers.parquet": rows("b", [-3.0, -1.0], [["palm"], ["finger_pad"]]),
        "r/a/blockers.parquet": rows("a", [-2.0, -0.5, -0.25], [["palm"], ["palm"], []]),
    }
    monkeypatch.setattr(module, "read", lambda table, path: frames[str(path)])
    sets = {"1": (1,), "2": (2,)}
    table = module.blockers_summary_by_object(list(frames), sets)
    pd.testing.assert_frame_equal(table, blockers_summary(pd.concat(frames.values(), ignore_index=True), sets), check_exact=True)
    pooled = table.set_index(["object", "set_id"]).loc[("all", "1")]
    assert pooled["n_failing"] == 5 and pooled["median_margin"] == -1.0 and pooled["pct_kind_palm"] == 60.0
    assert table["object"].tolist()[:2] == ["a", "a"]
