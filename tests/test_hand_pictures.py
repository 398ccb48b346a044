"""Shaded pictures of the hand: exact ray casting of capsules and boxes, the hand where its
kinematics puts it, the highlight of touching links, Fig. 1 and Fig. 2 written the same on
every run."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from synergrasp.figures import hand_pictures as hp
from synergrasp.figures.hand_pictures import PALM_CAMERA, SKIN, TOUCHING, Camera, ShapeInPicture, hand_shapes, render
from synergrasp.simulation.shapes import Box

# Looking along -x (from the palm side), 100 mm wide image of 200 px: 0.5 mm per pixel.
_CAMERA = Camera(direction=(-1.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), center_mm=(0.0, 0.0, 0.0), width_mm=100.0)


def test_capsule_silhouette_depth_and_normal_are_exact():
    rays = hp._Rays(_CAMERA, 200, 200)
    hp._cast_capsule(rays, np.array([0.0, 0.0, -20.0]), np.array([0.0, 0.0, 20.0]), 10.0, label=5)
    hit = rays.label == 5
    # Silhouette: a 20 mm wide band (40 px) from z = -30 to 30 mm with round ends: area of a
    # 20 x 40 mm rectangle plus a 10 mm disc, in pixels of 0.25 mm^2.
    expected = (20.0 * 40.0 + np.pi * 10.0**2) / 0.25
    assert abs(hit.sum() - expected) / expected < 0.01
    assert hit[100].sum() == 40
    # Pixel (100, 100) looks at y = +0.25 mm (image right is +y), z = -0.25 mm: the cylinder's
    # surface there is at x = sqrt(100 - 0.25^2), its normal (x, 0.25, 0) / 10.
    x = np.sqrt(100.0 - 0.25**2)
    assert rays.depth[100, 100] == pytest.approx(rays.depth_of(np.array([[x, 0.25, -0.25]]))[0], abs=1e-9)
    np.testing.assert_allclose(rays.normal[100, 100], [x / 10.0, 0.025, 0.0], atol=1e-12)
    # Row 50 looks at z = 24.75 mm, 4.75 mm beyond the segment end: on the end sphere.
    x = np.sqrt(100.0 - 0.25**2 - 4.75**2)
    assert rays.depth[50, 100] == pytest.approx(rays.depth_of(np.array([[x, 0.25, 24.75]]))[0], abs=1e-9)


def test_rotated_box_covers_its_projected_area():
    angle = np.radians(30.0)
    rotation = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])
    rays = hp._Rays(_CAMERA, 200, 200)
    face = hp._cast_shape(rays, ShapeInPicture(Box((10.0, 30.0, 40.0)), np.zeros(3), rotation), label=0)
    # Seen along x the box is its 30 x 40 mm face turned in the image plane: 1200 mm^2.
    assert abs((face >= 0).sum() - 1200.0 / 0.25) / 4800.0 < 0.01
    assert set(np.unique(face)) == {-1, 1}  # only the +x face is seen (axis 0, side +)
    assert rays.depth[100, 100] == pytest.approx(rays.depth_of(np.array([[5.0, 0.0, 0.0]]))[0], abs=1e-6)


def test_a_fitted_camera_frames_the_spheres_with_its_margin():
    points = np.array([[0.0, -30.0, 10.0], [5.0, 40.0, 90.0], [-20.0, 0.0, 50.0]])
    radii = np.array([5.0, 8.0, 0.0])
    camera = _CAMERA.fitted(points, radii, margin_mm=4.0)
    # Seen along -x: image right is +y, up is +z. Extents y -35 … 48, z 5 … 98 -> 93 + 2 x 4 mm wide.
    assert camera.width_mm == pytest.approx(101.0)
    rays = hp._Rays(camera, 202, 202)  # 0.5 mm per pixel
    px = rays.to_image(points)
    assert px[:, 1].min() - 8.0 / 0.5 == pytest.approx(4.0 / 0.5)  # top sphere: 8 mm radius, 4 mm margin
    assert px[:, 0].min() - 5.0 / 0.5 == pytest.approx((101.0 - 83.0) / 2.0 / 0.5)  # centred across


def test_the_hand_is_where_its_kinematics_puts_it(hand):
    """At the flat posture, the pixel halfway between each distal link's frame origin and its
    fingertip (hand.kinematics, independent of the drawn shapes) and the pixel of the palm
    box's front face show that link."""
    from synergrasp.hand.kinematics import fingertip_positions, forward_kinematics

    q = np.zeros(hand.n_joints)
    picture = render(hand, q, PALM_CAMERA, (200, 200))
    frames, tips = forward_kinematics(hand, q), fingertip_positions(hand, q)
    points = [0.5 * (frames[link][:3, 3] + tip) for link, tip in zip(hand.fingertip_link, tips)]
    links = list(hand.fingertip_link)
    points.append(np.array([9.5, -9.0, 52.0]))  # the palm box's front face (x = 9.5 mm) centre
    links.append(0)
    px = np.floor(picture.pixels(np.array(points))).astype(int)
    assert list(picture.link[px[:, 1], px[:, 0]]) == links
    # Nothing is drawn near the image corners: the hand sits inside the picture.
    assert np.all(picture.rgb[:5, :5] == 1.0) and np.all(picture.rgb[-5:, -5:] == 1.0)


def test_a_touching_link_gets_the_highlight_colour(hand):
    q = np.zeros(hand.n_joints)
    index_tip = hand.link_index("index_distal")
    shapes = hand_shapes(hand, q)
    centre = shapes.ends[shapes.link == index_tip][0].mean(axis=0)
    plain = render(hand, q, PALM_CAMERA, (200, 200))
    lit = render(hand, q, PALM_CAMERA, (200, 200), touching=[index_tip])
    c, r = np.floor(lit.pixels(centre[None])[0]).astype(int)

    def nearer_to_highlight(rgb):  # by chromaticity: shading scales brightness, not hue
        chroma = [np.asarray(x, dtype=float) / np.sum(x) for x in (rgb, TOUCHING, SKIN)]
        return np.linalg.norm(chroma[0] - chroma[1]) < np.linalg.norm(chroma[0] - chroma[2])

    assert nearer_to_highlight(lit.rgb[r, c]) and not nearer_to_highlight(plain.rgb[r, c])
    from scipy.ndimage import binary_dilation

    away = ~binary_dilation(plain.link == index_tip, iterations=2)  # pixels 2 or more away from the link
    np.testing.assert_array_equal(lit.rgb[away], plain.rgb[away])


def _one_grasp_table(hand, synergies) -> pd.DataFrame:
    q = np.clip(synergies.mean, hand.lower, hand.upper)
    return pd.DataFrame(
        [
            {
                "object": "cube",
                "pose": 0,
                "alpha_deg": 0.0,
                "beta_deg": 0.0,
                "status": "grasp",
                "q": list(q),
                "finger_state": ["contact"] * 5,
                "n_contacts": 1,
                "contact_link": [hand.link_index("index_distal")],
                "contact_point": [40.0, 10.0, 120.0],
                "contact_normal": [0.0, 0.0, 1.0],
                "jacobian": [0.0] * 57,
                "object_center": [45.0, 0.0, 110.0],
                "object_rotation": list(np.eye(3).ravel()),
                "max_penetration_mm": 0.0,
            }
        ]
    )


def test_touching_links_in_words(hand):
    from synergrasp.figures.fig1_fig2_postures_grasps import _touching_words

    links = [hand.link_index(n) for n in ("palm", "thumb_distal", "index_middle", "index_distal")]
    assert _touching_words(hand, links) == "touching: palm, thumb tip, index middle + tip"


def test_figures_are_written_and_the_same_on_rerun(hand, synergies, tmp_path):
    from synergrasp.figures.fig1_fig2_postures_grasps import figure_example_grasps, figure_synergy_postures
    from synergrasp.simulation.objects import GraspedObject

    box = GraspedObject("cube", Box((30.0, 30.0, 30.0)), 1.0)
    table = _one_grasp_table(hand, synergies)
    dropped = table.assign(object="big", status="intersects_open_hand", n_contacts=0, contact_link=[[]])
    for run in ("a", "b"):
        figure_synergy_postures(
            hand, synergies, tmp_path / f"f1{run}.png", tmp_path / f"f1{run}.pdf", n_synergies=1, sigmas=(-1.0, 0.0)
        )
        figure_example_grasps(
            hand,
            [box, GraspedObject("big", Box((90.0, 60.0, 90.0)), 1.0)],
            [table, dropped],
            tmp_path / f"f2{run}.png",
            tmp_path / f"f2{run}.pdf",
            n_grasps=2,
        )
    for name in ("f1", "f2"):
        for ext in ("png", "pdf"):
            first = (tmp_path / f"{name}a.{ext}").read_bytes()
            assert len(first) > 10_000, (name, ext)
            assert first == (tmp_path / f"{name}b.{ext}").read_bytes(), (name, ext)


def test_placement_map_is_written_and_the_same_on_rerun(hand, synergies, tmp_path):
    from synergrasp.figures.placement_map import figure_placement_map
    from synergrasp.simulation.objects import GraspedObject

    box = GraspedObject("cube", Box((30.0, 30.0, 30.0)), 1.0)
    targets = [(9.5, y, z) for y in (-10.0, 10.0) for z in (60.0, 80.0)] + [(19.5, -10.0, 60.0)]
    placement = pd.DataFrame(
        {
            "object": "cube",
            "rank": range(1, 6),
            "chosen": [True] + [False] * 4,
            "distinct_rank": range(1, 6),
            "x_mm": [t[0] for t in targets],
            "y_mm": [t[1] for t in targets],
            "z_mm": [t[2] for t in targets],
            "round": 0,
            "n_poses": 27,
            "grasp_type": "power",
            "typed_percent": [80.0, 60.0, 0.0, 0.0, 90.0],
            "force_closure_percent": [90.0, 80.0, 50.0, 0.0, 90.0],
            "median_force_per_weight": [1.0, 2.0, 3.0, float("inf"), 1.0],
            "median_contacts": 4.0,
            "distance_to_chosen_mm": 0.0,
        }
    )
    for run in ("a", "b"):
        figure_placement_map(
            hand, box, placement, _one_grasp_table(hand, synergies), 10.0, tmp_path / f"m{run}.png", tmp_path / f"m{run}.pdf"
        )
    for ext in ("png", "pdf"):
        first = (tmp_path / f"ma.{ext}").read_bytes()
        assert len(first) > 10_000 and first == (tmp_path / f"mb.{ext}").read_bytes(), ext
