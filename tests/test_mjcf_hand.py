"""Hands read from MJCF (synergrasp.hand.mjcf): the shipped Shadow hand against MuJoCo itself,
and descriptions the project cannot use refused with one line naming the file and element."""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from synergrasp.hand.checks import check_hand
from synergrasp.hand.kinematics import forward_kinematics, load_hand, point_jacobian
from synergrasp.hand.mjcf import MM_PER_M
from synergrasp.yaml_io import read_yaml

SHADOW = Path(__file__).parents[1] / "src" / "synergrasp" / "data" / "hands" / "shadow"


@pytest.fixture(scope="module")
def shadow():
    hand = load_hand(SHADOW / "hand.yaml")
    model = mujoco.MjModel.from_xml_path(str(SHADOW / "shadow_hand.xml"))
    return hand, model, read_yaml(SHADOW / "hand.yaml", "hand file")


def _qpos(hand, model, doc, q):
    """MuJoCo's qpos of the project's posture q: fixed joints at their angle, a reversed joint
    at −q, a coupled joint at ratio × its master's MuJoCo angle."""
    qpos = np.zeros(model.nq)
    for name, value in doc["fixed_joints"].items():
        qpos[model.jnt_qposadr[model.joint(name).id]] = value
    for finger in doc["fingers"].values():
        for entry in finger["joints"]:
            if "name" in entry:
                sign = -1.0 if entry.get("reverse") else 1.0
                qpos[model.jnt_qposadr[model.joint(entry["mjcf"]).id]] = sign * q[hand.joint_names.index(entry["name"])]
    for name, coupling in doc["couplings"].items():
        qpos[model.jnt_qposadr[model.joint(name).id]] = (
            coupling["ratio"] * qpos[model.jnt_qposadr[model.joint(coupling["follows"]).id]]
        )
    return qpos


def _palm_frame(model, data, doc):
    """(rotation, origin) taking MuJoCo's world (m) into the project's palm frame (mm)."""
    palm = model.body(doc["palm"]).id
    x = np.array(doc["palm_normal"], dtype=float)
    z = np.array(doc["finger_direction"], dtype=float)
    frame = np.column_stack([x, np.cross(z, x), z])
    return frame.T @ data.xmat[palm].reshape(3, 3).T, data.xpos[palm].copy()


def _postures(hand, n=20, seed=5):
    rng = np.random.default_rng(seed)
    return rng.uniform(hand.lower, hand.upper, size=(n, hand.n_joints))


def test_shadow_tips_and_jacobians_equal_mujoco(shadow):
    hand, model, doc = shadow
    data = mujoco.MjData(model)
    worst_tip, worst_jac = 0.0, 0.0
    for q in _postures(hand):
        data.qpos[:] = _qpos(hand, model, doc, q)
        data.qpos[:2] = [0.3, -0.2]  # the wrist moves the palm, not the hand in the palm frame
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        rotation, origin = _palm_frame(model, data, doc)
        frames = forward_kinematics(hand, q)
        for f, (finger, node) in enumerate(doc["fingers"].items()):
            site = model.site(node["tip_site"]).id
            ours_tip = frames[hand.fingertip_link[f], :3, :3] @ hand.fingertip_point[f] + frames[hand.fingertip_link[f], :3, 3]
            mj_tip = rotation @ (data.site_xpos[site] - origin) * MM_PER_M
            worst_tip = max(worst_tip, float(np.max(np.abs(ours_tip - mj_tip))))
            jacp = np.zeros((3, model.nv))
            mujoco.mj_jac(model, data, jacp, None, data.site_xpos[site], model.site_bodyid[site])
            # d qpos / d q: the chain rule through reversal and coupling (columns per project joint)
            e = np.zeros((model.nv, hand.n_joints))
            for k in range(hand.n_joints):
                dq = np.zeros(hand.n_joints)
                dq[k] = 1.0
                e[:, k] = _qpos(hand, model, doc, dq) - _qpos(hand, model, doc, np.zeros(hand.n_joints))
            mj_jac = rotation @ jacp @ e * MM_PER_M
            ours_jac = point_jacobian(hand, q, int(hand.fingertip_link[f]), ours_tip)
            worst_jac = max(worst_jac, float(np.max(np.abs(ours_jac - mj_jac))))
    print(f"fingertips: largest difference {worst_tip:.3g} mm; Jacobians {worst_jac:.3g} mm/rad")
    assert worst_tip < 1e-6 and worst_jac < 1e-6


def test_shadow_collision_shapes_equal_mujoco_geoms(shadow):
    hand, model, doc = shadow
    data = mujoco.MjData(model)
    ignored = set(doc["ignore_geoms"])
    checked = 0
    for q in _postures(hand, n=5, seed=9):
        data.qpos[:] = _qpos(hand, model, doc, q)
        mujoco.mj_kinematics(model, data)
        rotation, origin = _palm_frame(model, data, doc)
        frames = forward_kinematics(hand, q)
        ours = [(frames[link] @ s.pose, s) for link in range(hand.n_links) for s in hand.link_shapes[link]]
        palm = model.body(doc["palm"]).id
        geoms = [
            g
            for g in range(model.ngeom)
            if model.geom(g).name not in ignored
            and model.geom_contype[g] + model.geom_conaffinity[g] > 0
            and _below(model, int(model.geom_bodyid[g]), palm)
        ]
        assert len(geoms) == len(ours) == 18  # 3 palm boxes (one the fixed little metacarpal), 15 capsules
        for g in geoms:
            centre = rotation @ (data.geom_xpos[g] - origin) * MM_PER_M
            axes = rotation @ data.geom_xmat[g].reshape(3, 3)
            pose, shape = min(ours, key=lambda o: np.linalg.norm(o[0][:3, 3] - centre))
            size = model.geom_size[g] * MM_PER_M
            np.testing.assert_allclose(pose[:3, 3], centre, atol=1e-9)
            np.testing.assert_allclose(pose[:3, :3], axes, atol=1e-12)
            if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE:
                assert (shape.kind, shape.radius, shape.length) == ("capsule", size[0], 2 * size[1])
            else:
                assert shape.kind == "box" and np.array_equal(shape.size, 2 * size)
            checked += 1
    assert checked == 90


def _below(model, body, ancestor):
    while body not in (ancestor, 0):
        body = int(model.body_parentid[body])
    return body == ancestor


def test_shadow_model_as_the_study_asks(shadow):
    hand, _, _ = shadow
    _, problems, warnings = check_hand(SHADOW / "hand.yaml")
    assert problems == [] and warnings == []
    assert hand.n_joints == 17 and len(hand.shapeless_links) == 6  # 4 knuckles, the thumb base and hub
    # a coupled distal: its link turns with the PIP's coordinate, 1.1418 times as fast
    index = hand.link_index("index_distal")
    assert hand.joint_names[hand.link_parent_joint[index]] == "index_pip"
    np.testing.assert_allclose(hand.upper[hand.joint_names.index("index_pip")], 1.571 / (0.00805 / 0.00705))


# --------------------------------------------------------------------------- refused descriptions

MINI = """<mujoco>
  <worldbody>
    <body name="palm">
      <geom type="box" size="0.04 0.01 0.05"/>
      <body name="{finger}1" pos="0 0 0.06">
        <joint name="{finger}_j1" type="{kind}" axis="1 0 0" range="0 1.5"/>
        <geom type="{geom}" size="0.008 0.02" {mesh}/>
      </body>
    </body>
  </worldbody>
  {asset}
</mujoco>
"""


def _mini(tmp_path, kind="hinge", geom="capsule", palm="palm", joint="j1"):
    mesh, asset = "", ""
    if geom == "mesh":
        mesh = 'mesh="tet"'
        asset = '<asset><mesh name="tet" vertex="0 0 0  0.01 0 0  0 0.01 0  0 0 0.01"/></asset>'
    bodies = "".join(
        MINI.format(finger=f, kind=kind, geom=geom, mesh=mesh, asset="")
        .split("<worldbody>")[1]
        .split("</worldbody>")[0]
        .replace('<body name="palm">', "")
        .replace('<geom type="box" size="0.04 0.01 0.05"/>', "")
        .rsplit("</body>", 1)[0]
        for f in ("thumb", "index", "middle", "ring", "little")
    )
    xml = (
        f'<mujoco><worldbody><body name="palm"><geom type="box" size="0.04 0.01 0.05"/>{bodies}</body>'
        f"</worldbody>{asset}</mujoco>"
    )
    (tmp_path / "mini.xml").write_text(xml)
    fingers = "\n".join(
        f"  {f}:\n    tip_site: null\n    joints: [{{mjcf: {f}_{joint}, name: {f}_flex, link: {f}_a}}]"
        for f in ("thumb", "index", "middle", "ring", "little")
    )
    (tmp_path / "hand.yaml").write_text(f"mjcf: mini.xml\npalm: {palm}\nfingers:\n{fingers}\n")
    return tmp_path / "hand.yaml"


@pytest.mark.parametrize(
    "case, expected",
    [
        ({"palm": "wrist"}, "palm: no body named 'wrist' in 'mini.xml'"),
        ({"joint": "j9"}, "fingers.thumb.joints[0].mjcf: no joint named 'thumb_j9' in 'mini.xml'"),
        ({"kind": "ball"}, "fingers.thumb.joints[0].mjcf: joint 'thumb_j1' in 'mini.xml' is a ball joint"),
        ({"kind": "slide"}, "fingers.thumb.joints[0].mjcf: joint 'thumb_j1' in 'mini.xml' is a slide joint"),
        ({"geom": "mesh"}, "a mesh collision geom is refused"),
    ],
)
def test_unusable_description_is_one_line_naming_file_and_element(tmp_path, case, expected):
    path = _mini(tmp_path, **case)
    with pytest.raises(ValueError) as err:
        check_hand(path)
    message = str(err.value)
    assert "\n" not in message and message.startswith(f"hand file '{path}': ") and expected in message, message


def test_missing_mjcf_file_is_named(tmp_path):
    (tmp_path / "hand.yaml").write_text("mjcf: nowhere.xml\npalm: palm\nfingers: {}\n")
    with pytest.raises(ValueError, match=r"hand file '.*hand.yaml': mjcf: file '.*nowhere.xml' does not exist"):
        check_hand(tmp_path / "hand.yaml")


# --------------------------------------------------------------------------- its synergies


def test_shadow_thumb_meets_the_middle_tip_in_front_of_the_palm():
    """Along q_r(σ) the thumb's distal capsule reaches the middle finger's while both tips stand
    well in front of the palm face and before any thumb link touches the palm (a pinch, not
    the fingertips curling onto a thumb folded in the palm, which the former test accepted:
    its check, the σ of the meeting alone, passed on the joint-by-joint mapping whose thumb
    lies on the palm; tests/test_thumb_check.py); the index is still inside its limits there.
    The table itself: tests/test_synergy_map.py."""
    from synergrasp.hand.synergies import SynergyPath, load_synergies, shadow_hand_files
    from synergrasp.simulation.thumb_check import thumb_opposition

    hand_path, _, table_path = shadow_hand_files()
    hand = load_hand(hand_path)
    table = load_synergies(table_path, joint_names=hand.joint_names)
    check = thumb_opposition(hand, table)
    assert check.partner == "middle" and check.palm_sigma is None and check.front_mm > 15.0
    q = SynergyPath.along(table, hand.lower, hand.upper).reference(check.meet_sigma)
    index = [hand.joint_names.index(n) for n in ("index_mcp", "index_pip")]
    assert np.all(q[index] < hand.upper[index] - 0.05)


def test_search_region_from_the_hands_geometry():
    """region_mm: hand. The palm-derived bounds by hand: the SoftHand's palm box is x −14.5 … 9.5,
    y −48 … 30, z 14 … 90; the Shadow's palm boxes (MuJoCo, half-sizes) C_palm0 at x 11 ± 32,
    z 38 ± 49 and C_palm1 at x −32 ± 11 (MuJoCo x is the project's y), face at 11.1 mm."""
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.simulation.placement import hand_region

    soft = load_hand(None)
    (x0, x1), y, (z0, z1) = hand_region(soft, load_synergies(None))
    assert (x0, y, z0) == (9.0, (-48.0, 30.0), 14.0) and 50 < x1 < 60 and 180 < z1 < 200
    shadow = load_hand("shadow_hand")
    (x0, x1), y, (z0, z1) = hand_region(shadow, load_synergies("shadow_hand", joint_names=shadow.joint_names))
    # the open hand of the mapped table spreads the middle finger by its -20 deg limit: its tip at
    # 96 cos(20 deg) + 99 = 189.2 mm (straight: 99 + 96 = 195 mm)
    assert (x0, y, z0) == (11.0, (-43.0, 43.0), -11.0) and x1 > 60 and z1 == 190.0


def test_config_region_hand_is_accepted():
    from synergrasp.config import validate_config
    from synergrasp.optimisation.placement_search import SearchStepParams

    config = validate_config(
        {"hand": "shadow_hand", "synergies": "shadow_hand", "placement": {"search": {"region_mm": {"precision": "hand"}}}}
    )  # obj1: a precision object
    params = SearchStepParams.from_config(config, "obj1")
    assert params.search.region_mm[1] == (-43.0, 43.0)


def test_hand_show_prints_the_joints_and_draws(tmp_path, capsys):
    from synergrasp.cli import main

    png = tmp_path / "hand.png"
    assert main(["hand", "show", "shadow_hand", "--png", str(png), "--count", "2"]) == 0
    text = capsys.readouterr().out
    assert "17 joints, 22 links (6 without shape)" in text and "index_pip           0.0    78.8    53.3" in text
    assert png.stat().st_size > 10_000
    assert main(["hand", "show", str(tmp_path / "none.yaml")]) == 2
    assert "none.yaml" in capsys.readouterr().err


def softhand_urdf(folder: Path, factor: float = 1.0) -> Path:
    """A hand description of the shipped hand through its own URDF (``write_urdf``: metres, 9
    digits, a rolling joint as two revolute halves), written in ``folder``: each first half
    named (scale 0.5: MuJoCo turns it by q/2), the second half coupled to it (ratio 1), the root
    link fused into MuJoCo's world; every length of the URDF times ``factor`` (1000: a URDF
    written in mm). Returns the description's path."""
    import re

    import yaml

    from synergrasp.hand.kinematics import write_urdf

    soft = load_hand(None)
    write_urdf(soft, folder / "soft.urdf")
    if factor != 1.0:

        def scaled(m):
            return f'{m.group(1)}="' + " ".join(f"{float(v) * factor:.9g}" for v in m.group(2).split()) + '"'

        text = re.sub(r'\b(xyz|size|radius|length)="([^"]*)"', scaled, (folder / "soft.urdf").read_text())
        (folder / "soft.urdf").write_text(text)
    fingers, couplings = {}, {}
    for finger, links in zip(("thumb", "index", "middle", "ring", "little"), soft.finger_links):
        entries = []
        for link in links:
            joint = soft.joint_names[soft.link_parent_joint[link]]
            if joint.endswith("_abd"):
                entries.append({"mjcf": joint, "name": joint, "link": soft.link_names[link]})
            else:
                entries.append({"mjcf": f"{joint}_a", "name": joint, "link": f"{finger}_{joint}_half", "scale": 0.5})
                entries.append({"mjcf": f"{joint}_b", "link": soft.link_names[link]})
                couplings[f"{joint}_b"] = {"follows": f"{joint}_a", "ratio": 1.0}
        fingers[finger] = {"joints": entries, "tip_mm": soft.fingertip_point[len(fingers)].tolist()}
    path = folder / "hand.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "urdf": "soft.urdf",
                "palm": "world",
                "palm_normal": [1, 0, 0],
                "finger_direction": [0, 0, 1],
                "couplings": couplings,
                "fingers": fingers,
            }
        )
    )
    return path


def test_softhand_through_its_own_urdf_equals_the_yaml_hand(tmp_path):
    """URDF through MuJoCo's compiler: the shipped hand's URDF (softhand_urdf). Same joints,
    limits, fingertips and Jacobians as the YAML hand."""
    from synergrasp.hand.kinematics import fingertip_positions

    soft = load_hand(None)
    softhand_urdf(tmp_path)
    read = load_hand(tmp_path / "hand.yaml")
    assert read.joint_names == soft.joint_names
    np.testing.assert_allclose(read.lower, soft.lower, atol=1e-9)
    np.testing.assert_allclose(read.upper, soft.upper, atol=1e-9)
    worst = 0.0
    for q in _postures(soft, n=10):
        tips = fingertip_positions(soft, q)
        tip_gap = float(np.max(np.abs(fingertip_positions(read, q) - tips)))
        assert tip_gap < 1e-5, tip_gap  # the URDF's 9 digits, in m
        for f in range(5):
            a = point_jacobian(soft, q, int(soft.fingertip_link[f]), tips[f])
            b = point_jacobian(read, q, int(read.fingertip_link[f]), tips[f])
            worst = max(worst, float(np.max(np.abs(a - b))))
    print(f"URDF: Jacobians within {worst:.2g} mm/rad")
    assert worst < 1e-5
    assert sum(len(s) for s in read.link_shapes) == sum(len(s) for s in soft.link_shapes) == 20


def test_a_urdf_in_mm_gets_the_size_warning_a_yaml_hand_gets(tmp_path):
    """One size check for every format (hand_file.size_warnings): the shipped hand's URDF with
    its lengths in mm is 1000 times a hand, one line naming the unit MuJoCo reads; in m, none."""
    assert check_hand(softhand_urdf(tmp_path))[1:] == ([], [])
    path = softhand_urdf(tmp_path, 1000.0)
    _, problems, warnings = check_hand(path)
    assert problems == [] and len(warnings) == 1
    assert warnings[0].startswith(f"hand file '{path}': <top level>: ")
    assert "lengths exceed 250 mm" in warnings[0] and warnings[0].endswith("lengths are in m, not mm")


def test_a_folder_given_as_the_model_says_so(tmp_path):
    (tmp_path / "hand.yaml").write_text("mjcf: .\npalm: palm\nfingers: {}\n")
    with pytest.raises(
        ValueError, match=f"^hand file '{tmp_path / 'hand.yaml'}': mjcf: '{tmp_path}' is a folder; give the model's file$"
    ):
        check_hand(tmp_path / "hand.yaml")
