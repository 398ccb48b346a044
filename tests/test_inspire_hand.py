"""The shipped Inspire dexterous hand (robosuite's MJCF, collision meshes fitted with capsules
and a box; docs/hand.md) against MuJoCo itself: fingertips and point Jacobians through the
coupling, the couplings against the model's joint equalities, the fitted shapes against
MuJoCo's distance to each mesh's convex hull; and the fits on hand-derivable cases."""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from synergrasp.hand.checks import check_hand
from synergrasp.hand.kinematics import forward_kinematics, load_hand, point_jacobian
from synergrasp.hand.mesh_fit import MeshFitError, enclosing_circle, fit_box, fit_capsule, hull_vertices
from synergrasp.hand.mjcf import MM_PER_M
from synergrasp.yaml_io import read_yaml

INSPIRE = Path(__file__).parents[1] / "src" / "synergrasp" / "data" / "hands" / "inspire"
#: the robosuite body of each project link (the link names of hand.yaml)
BODIES = {
    "palm": "r_palm",
    "thumb_base": "r_thumb_proximal_1",
    "thumb_proximal": "r_thumb_proximal_2",
    "thumb_middle": "r_thumb_middle",
    "thumb_distal": "r_thumb_distal",
}
BODIES.update(
    {
        f"{f}_{s}": f"r_{b}_{s}"
        for f, b in zip(("index", "middle", "ring", "little"), ("index", "middle", "ring", "pinky"))
        for s in ("proximal", "distal")
    }
)


@pytest.fixture(scope="module")
def inspire():
    hand = load_hand("inspire_hand")
    model = mujoco.MjModel.from_xml_path(str(INSPIRE / "inspire_hand.xml"))
    return hand, model, read_yaml(INSPIRE / "hand.yaml", "hand file")


def _qpos(hand, model, doc, q):
    """MuJoCo's qpos of the project's posture q: the named joints at q, every other joint set
    by the model's joint equalities (joint1 = polycoef · joint2), read here from MuJoCo."""
    qpos = np.zeros(model.nq)
    for finger in doc["fingers"].values():
        for entry in finger["joints"]:
            if "name" in entry:
                qpos[model.joint(entry["mjcf"]).qposadr[0]] = q[hand.joint_names.index(entry["name"])]
    for eq in range(model.neq):
        c = model.eq_data[eq][:5]
        x = qpos[model.jnt_qposadr[model.eq_obj2id[eq]]]
        qpos[model.jnt_qposadr[model.eq_obj1id[eq]]] = c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3 + c[4] * x**4
    return qpos


def _palm_frame(model, data, doc):
    """(rotation, origin) taking MuJoCo's world (m) into the project's palm frame (mm)."""
    palm = model.body(doc["palm"]).id
    x, z = np.array(doc["palm_normal"], dtype=float), np.array(doc["finger_direction"], dtype=float)
    frame = np.column_stack([x, np.cross(z, x), z])
    return frame.T @ data.xmat[palm].reshape(3, 3).T, data.xpos[palm].copy()


def _postures(hand, n=20, seed=7):
    return np.random.default_rng(seed).uniform(hand.lower, hand.upper, size=(n, hand.n_joints))


def test_inspire_tips_and_jacobians_equal_mujoco(inspire):
    hand, model, doc = inspire
    data = mujoco.MjData(model)
    e = np.column_stack([_qpos(hand, model, doc, np.eye(hand.n_joints)[k]) for k in range(hand.n_joints)])
    worst_tip = worst_jac = 0.0
    for q in _postures(hand):
        data.qpos[:] = _qpos(hand, model, doc, q)
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        rotation, origin = _palm_frame(model, data, doc)
        frames = forward_kinematics(hand, q)
        for f, (finger, node) in enumerate(doc["fingers"].items()):
            body = model.body(BODIES[f"{finger}_distal"]).id
            mj_point = data.xpos[body] + data.xmat[body].reshape(3, 3) @ np.array(node["tip_mm"]) / MM_PER_M
            link = int(hand.fingertip_link[f])
            ours_tip = frames[link, :3, :3] @ hand.fingertip_point[f] + frames[link, :3, 3]
            worst_tip = max(worst_tip, float(np.max(np.abs(ours_tip - rotation @ (mj_point - origin) * MM_PER_M))))
            jacp = np.zeros((3, model.nv))
            mujoco.mj_jac(model, data, jacp, None, mj_point, body)
            mj_jac = rotation @ jacp @ e * MM_PER_M  # the chain rule through the couplings (linear)
            worst_jac = max(worst_jac, float(np.max(np.abs(point_jacobian(hand, q, link, ours_tip) - mj_jac))))
    print(f"fingertips: largest difference {worst_tip:.3g} mm; Jacobians {worst_jac:.3g} mm/rad")
    assert worst_tip < 1e-6 and worst_jac < 1e-6


def test_couplings_are_the_models_joint_equalities(inspire):
    """Six coordinates for twelve joints: each coupled joint's frame turns by the equality's
    polycoef c1 (1: robosuite drives them with one value) times its master's q; at postures
    so coupled MuJoCo's own equality constraints are met (constraint residuals zero)."""
    hand, model, doc = inspire
    assert hand.joint_names == ("thumb_abd", "thumb_flex1", "index_mcp", "middle_mcp", "ring_mcp", "little_mcp")
    coupled = {
        hand.frame_joint_names[k]: (hand.joint_names[hand.frame_joint[k]], hand.frame_scale[k])
        for k in range(1, len(hand.frame_names))
        if hand.frame_joint_names[k].startswith("joint_r_")
    }
    expected = {
        model.joint(model.eq_obj1id[eq]).name: (model.joint(model.eq_obj2id[eq]).name, model.eq_data[eq][1])
        for eq in range(model.neq)
    }
    names = {e["mjcf"]: e.get("name") for node in doc["fingers"].values() for e in node["joints"]}
    assert len(expected) == 6 and {k: (names[m], r) for k, (m, r) in expected.items()} == coupled
    data = mujoco.MjData(model)
    for q in _postures(hand, n=5):
        data.qpos[:] = _qpos(hand, model, doc, q)
        mujoco.mj_forward(model, data)
        rows = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert rows.sum() == 6 and np.max(np.abs(data.efc_pos[: data.nefc][rows])) < 1e-12
    # the master's range keeps every coupled joint inside its own (distal ranges 0.77-1.87 rad)
    assert np.allclose(hand.upper, [1.3, 0.68, 1.62, 1.62, 1.62, 1.62]) and np.all(hand.lower == 0.0)


def _world_geom(spec_body, shape, palm_pose):
    """Add the fitted ``shape`` (palm frame, mm) to ``spec_body`` as a MuJoCo geom (m, world)."""
    pose = palm_pose @ shape.pose
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, pose[:3, :3].flatten())
    if shape.kind == "capsule":
        return spec_body.add_geom(
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            pos=pose[:3, 3] / MM_PER_M,
            quat=quat,
            size=[shape.radius / MM_PER_M, 0.5 * shape.length / MM_PER_M, 0],
        )
    return spec_body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX, pos=pose[:3, 3] / MM_PER_M, quat=quat, size=0.5 * shape.size / MM_PER_M
    )


def test_fitted_shapes_contain_each_meshs_hull_by_mujocos_distance(inspire):
    """A shape C holds the hull H to within ε iff d(p, C) ≤ d(p, H) + ε for every point p.
    MuJoCo measures both (mj_geomDistance; a mesh collides as its convex hull) from probes
    2 mm outside every hull vertex and 5 mm outside the hull's bounding sphere in 200
    directions, at the open hand: ε = 1 mm. Also how far each shape reaches past its hull."""
    hand, _, doc = inspire
    spec = mujoco.MjSpec.from_file(str(INSPIRE / "inspire_hand.xml"))
    model0 = spec.compile()
    data0 = mujoco.MjData(model0)
    mujoco.mj_kinematics(model0, data0)
    rotation, origin = _palm_frame(model0, data0, doc)
    palm_pose = np.eye(4)
    palm_pose[:3, :3], palm_pose[:3, 3] = rotation.T, origin * MM_PER_M  # palm frame -> MuJoCo's world, mm
    frames = forward_kinematics(hand, np.zeros(hand.n_joints))
    for link, name in enumerate(hand.link_names):
        (shape,) = hand.link_shapes[link]
        placed = type(shape)(shape.kind, frames[link] @ shape.pose, shape.radius, shape.length, shape.size)
        _world_geom(spec.worldbody, placed, palm_pose).name = f"fit_{name}"
    probe = spec.worldbody.add_body(name="probe", mocap=True)
    probe.add_geom(name="probe", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[1e-4, 0, 0])
    model = spec.compile()
    data = mujoco.MjData(model)
    sphere = np.random.default_rng(0).normal(size=(200, 3))
    sphere /= np.linalg.norm(sphere, axis=1)[:, None]
    worst_inside, reach = -np.inf, {}
    for name, body in BODIES.items():
        mesh = _collision_geom(model, body)
        mujoco.mj_kinematics(model, data)
        hull = hull_vertices(model, mesh) / MM_PER_M @ data.geom_xmat[mesh].reshape(3, 3).T + data.geom_xpos[mesh]
        centre = hull.mean(axis=0)
        bound = np.max(np.linalg.norm(hull - centre, axis=1))
        outward = (hull - centre) / np.linalg.norm(hull - centre, axis=1)[:, None]
        probes = np.vstack([hull + 0.002 * outward, centre + (bound + 0.005) * sphere])
        excess = []
        for p in probes:
            data.mocap_pos[0] = p
            mujoco.mj_kinematics(model, data)
            d_hull = mujoco.mj_geomDistance(model, data, model.geom("probe").id, mesh, 1.0, None)
            d_fit = mujoco.mj_geomDistance(model, data, model.geom("probe").id, model.geom(f"fit_{name}").id, 1.0, None)
            excess.append((d_fit - d_hull) * MM_PER_M)
        worst_inside = max(worst_inside, max(excess))
        reach[name] = -min(excess)
    print(
        "largest d(p, fit) - d(p, hull): %.3g mm; the fits reach past their hulls by up to (mm): %s"
        % (worst_inside, ", ".join(f"{k} {v:.1f}" for k, v in reach.items()))
    )
    assert worst_inside <= 1.0
    assert all(v > 0.5 for v in reach.values())  # the probes see the fits: no shape equals its hull


def _collision_geom(model, body):
    (geom,) = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == model.body(body).id
        and model.geom_contype[g] + model.geom_conaffinity[g] > 0
        and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH
    ]
    return geom


def test_fingertips_are_the_distal_hulls_far_vertices(inspire):
    """tip_mm of hand.yaml: the distal mesh's hull vertex farthest along its capsule's axis
    (pointed away from the joint), in the distal body's frame (= the link frame: every joint
    sits at its body's origin)."""
    hand, model, doc = inspire
    for f, (finger, node) in enumerate(doc["fingers"].items()):
        geom = _collision_geom(model, BODIES[f"{finger}_distal"])
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.geom_quat[geom])
        points = hull_vertices(model, geom) @ rot.reshape(3, 3).T + model.geom_pos[geom] * MM_PER_M
        (capsule,) = hand.link_shapes[int(hand.fingertip_link[f])]
        axis = capsule.pose[:3, 2] * np.sign(capsule.pose[:3, 2] @ capsule.pose[:3, 3])
        np.testing.assert_allclose(node["tip_mm"], points[np.argmax(points @ axis)], atol=1e-5)


def test_inspire_as_the_study_asks(inspire):
    hand, _, _ = inspire
    _, problems, warnings = check_hand("inspire_hand")
    assert problems == [] and warnings == []
    assert hand.n_links == 13 and hand.shapeless_links == ()
    assert [s.kind for s in hand.link_shapes[0]] == ["box"]
    # the model's contact exclusions: the palm with the thumb's first three links, and two thumb pairs
    names = {tuple(hand.link_names[i] for i in pair) for pair in hand.ignored_link_pairs}
    assert {("palm", "thumb_proximal"), ("palm", "thumb_middle"), ("thumb_proximal", "thumb_middle")} <= names
    assert ("palm", "thumb_distal") not in names
    # palm box by hand: the palm mesh spans 45.5 mm along the palm normal, its face 23 mm in front
    (box,) = hand.link_shapes[0]
    assert np.allclose(box.pose[:3, :3], np.eye(3)) and 22.5 < box.pose[0, 3] + box.size[0] / 2 < 23.5


# --------------------------------------------------------------------------- the fits, by hand


def test_enclosing_circle_against_an_independent_minimiser():
    from scipy.optimize import minimize

    rng = np.random.default_rng(3)
    for n in (3, 7, 40, 300):
        points = rng.normal(size=(n, 2)) * [10.0, 4.0]
        centre, radius = enclosing_circle(points)
        assert np.max(np.linalg.norm(points - centre, axis=1)) <= radius * (1 + 1e-9)
        best = minimize(
            lambda c: np.max(np.linalg.norm(points - c, axis=1)),
            points.mean(axis=0),
            method="Nelder-Mead",
            options={"xatol": 1e-10, "fatol": 1e-10, "maxiter": 20000},
        )
        assert radius <= best.fun + 1e-6 and radius >= best.fun - 1e-3


def test_capsule_of_a_capsules_points_is_that_capsule():
    """Points on a capsule of radius 5 mm from z = 0 to z = 20 (two rings, and the two poles):
    the fit is that capsule, centred at z = 10, along z, length 20."""
    angles = np.linspace(0, 2 * np.pi, 36, endpoint=False)
    ring = np.column_stack([5 * np.cos(angles), 5 * np.sin(angles), np.zeros_like(angles)])
    points = np.vstack([ring, ring + [0, 0, 20], [[0, 0, -5], [0, 0, 25]]]) + [1.0, -2.0, 3.0]
    pose, radius, length = fit_capsule(points)
    assert radius == pytest.approx(5.0, abs=1e-9) and length == pytest.approx(20.0, abs=1e-9)
    np.testing.assert_allclose(pose[:3, 3], [1.0, -2.0, 13.0], atol=1e-9)
    assert abs(pose[2, 2]) == pytest.approx(1.0)


def test_box_fit_picks_the_smaller_of_principal_and_given_axes():
    corners = np.array([[x, y, z] for x in (0, 40) for y in (0, 10) for z in (0, 4)], dtype=float)
    pose, size = fit_box(corners, np.eye(3))
    assert np.allclose(np.sort(size), [4, 10, 40]) and np.allclose(pose[:3, 3], [20, 5, 2])
    turned = np.array([[np.cos(0.3), -np.sin(0.3), 0], [np.sin(0.3), np.cos(0.3), 0], [0, 0, 1]])
    _, size = fit_box(corners @ turned.T, np.eye(3))  # the principal axes find the turned box
    assert np.allclose(np.sort(size), [4, 10, 40])


def test_flat_mesh_is_refused():
    with pytest.raises(MeshFitError, match="flat or degenerate"):
        fit_capsule(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float))


# --------------------------------------------------------------------------- the door, on a small model

_FINGER = """<body name="{f}1" pos="0 {y} 0.06"><joint name="{f}_j1" axis="0 1 0" range="0 1.5"/>
  <geom type="mesh" mesh="{mesh}"/>
  <body name="{f}2" pos="0 0 0.03"><joint name="{f}_j2" axis="0 1 0" range="0 1.5"/><geom type="mesh" mesh="tet"/></body>
</body>"""


def _mesh_hand(tmp_path, fit="true", polycoef="0 0.5 0 0 0", couplings="", mesh="tet"):
    """Five two-joint fingers of tetrahedron meshes on a box palm, each distal joint held to
    its proximal one by a joint equality; a flat mesh when ``mesh='flat'``."""
    fingers = "".join(
        _FINGER.format(f=f, y=0.02 * k, mesh=mesh) for k, f in enumerate(("thumb", "index", "middle", "ring", "little"))
    )
    equalities = "".join(
        f'<joint joint1="{f}_j2" joint2="{f}_j1" polycoef="{polycoef}"/>' for f in ("thumb", "index", "middle", "ring", "little")
    )
    flat = '<mesh name="flat" vertex="0 0 0  0.01 0 0  0 0.01 0  0.01 0.01 0"/>' if mesh == "flat" else ""
    (tmp_path / "mini.xml").write_text(
        f'<mujoco><asset><mesh name="tet" vertex="0 0 0  0.01 0 0  0 0.01 0  0 0 0.03"/>{flat}</asset>'
        f'<worldbody><body name="palm"><geom type="box" size="0.04 0.01 0.05"/>{fingers}</body></worldbody>'
        f"<equality>{equalities}</equality></mujoco>"
    )
    chains = "\n".join(
        f"  {f}:\n    tip_mm: [0, 0, 10]\n    joints:\n"
        f"      - {{mjcf: {f}_j1, name: {f}_flex, link: {f}_a}}\n      - {{mjcf: {f}_j2, link: {f}_b}}"
        for f in ("thumb", "index", "middle", "ring", "little")
    )
    (tmp_path / "hand.yaml").write_text(f"mjcf: mini.xml\npalm: palm\nfit_meshes: {fit}\n{couplings}fingers:\n{chains}\n")
    return tmp_path / "hand.yaml"


def test_mesh_hand_through_the_door(tmp_path):
    """The tetrahedron (0, 0, 0), (10, 0, 0), (0, 10, 0), (0, 0, 30) mm becomes a capsule that
    holds its four vertices, the farthest on its surface; the equality's c1 = 0.5 is the
    coupled frame's scale."""
    hand = load_hand(_mesh_hand(tmp_path))
    assert hand.joint_names == tuple(f"{f}_flex" for f in ("thumb", "index", "middle", "ring", "little"))
    distal = hand.link_index("index_b")
    frame = int(hand.link_frame[distal])
    assert hand.frame_scale[frame] == 0.5 and hand.joint_names[hand.frame_joint[frame]] == "index_flex"
    (capsule,) = hand.link_shapes[distal]
    tet = np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 30]], dtype=float)
    local = (tet - capsule.pose[:3, 3]) @ capsule.pose[:3, :3]
    along = np.clip(local[:, 2], -capsule.length / 2, capsule.length / 2)
    gap = np.linalg.norm(local - np.column_stack([np.zeros((4, 2)), along]), axis=1) - capsule.radius
    assert np.all(gap <= 1e-5) and np.max(gap) > -1e-5  # MuJoCo keeps mesh vertices in float32


@pytest.mark.parametrize(
    "case, expected",
    [
        ({"fit": "maybe"}, "fit_meshes: must be true or false, got 'maybe'"),
        ({"fit": "false"}, "a mesh collision geom is refused"),
        ({"polycoef": "0.1 1 0 0 0"}, "only a coupling joint1 = c1 × joint2"),
        (
            {"couplings": "couplings: {index_j2: {follows: index_j1, ratio: 1.0}}\n"},
            "couplings.index_j2: joint 'index_j2' is coupled by equality",
        ),
        ({"mesh": "flat"}, "MuJoCo cannot compile"),
    ],
)
def test_mesh_hand_refused_in_one_line(tmp_path, case, expected):
    path = _mesh_hand(tmp_path, **case)
    with pytest.raises(ValueError) as err:
        check_hand(path)
    message = str(err.value)
    assert "\n" not in message and message.startswith(f"hand file '{path}': ") and expected in message, message


def test_provenance_table_names_every_copied_file_with_its_sha256():
    import hashlib
    import re

    rows = re.findall(r"^\| `([^`]+)` \| .* \| `([0-9a-f]{64})` \| no \|$", (INSPIRE / "README.md").read_text(), re.M)
    assert len(rows) == 15  # the XML, 13 meshes, the licence
    for name, digest in rows:
        assert hashlib.sha256((INSPIRE / name).read_bytes()).hexdigest() == digest, name


def test_shipped_inspire_table_equals_a_fresh_mapping(inspire):
    """synergies: inspire_hand is `synergies map` of the study's table onto this hand."""
    from synergrasp.hand.synergies import load_synergies, shipped_hand_table
    from synergrasp.hand.synergy_map import map_synergies

    hand = inspire[0]
    fit, _ = map_synergies(load_hand(None), load_synergies(None), hand)
    shipped = load_synergies(shipped_hand_table("inspire_hand"), joint_names=hand.joint_names)
    assert shipped.n_synergies == hand.n_joints == 6
    assert np.array_equal(shipped.mean, fit.synergies.mean) and np.array_equal(shipped.matrix, fit.synergies.matrix)


def test_inspire_thumb_opposes_along_its_mapped_s1(inspire):
    """The thumb-opposition check (docs/synergies.md) on the shipped table: the thumb's tip
    meets the index tip at σ ≈ 0.23, 37.6 mm in front of the palm face, the palm untouched
    (only thumb_distal may touch the palm: the model excludes the palm's pairs with the
    thumb's three proximal links)."""
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.simulation.thumb_check import thumb_opposition

    hand = inspire[0]
    check = thumb_opposition(hand, load_synergies("inspire_hand", joint_names=hand.joint_names))
    assert check.opposes and check.partner == "index" and check.palm_sigma is None
    assert 0.2 < check.meet_sigma < 0.26 and 35.0 < check.front_mm < 40.0
