"""Exact capsule/box distances of the closure against brute-force sampling and the hand's own kinematics."""

from __future__ import annotations

import numpy as np

from synergrasp.hand.kinematics import forward_kinematics, load_hand
from synergrasp.simulation.capsules import HandCapsules, segment_segment_distance
from synergrasp.simulation.shapes.kernels import segment_box_distance

RNG = np.random.default_rng(7)


def _segments(k: int, spread: float = 40.0, length: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    p0 = RNG.normal(size=(k, 3)) * spread
    return p0, p0 + RNG.normal(size=(k, 3)) * length


def test_segment_box_distance_matches_dense_sampling():
    p0, p1 = _segments(400)
    half = np.abs(RNG.normal(size=(400, 3))) * 20 + 2
    dist, t = segment_box_distance(p0, p1, half)
    ts = np.linspace(0.0, 1.0, 20001)
    for i in range(len(p0)):
        x = p0[i] + ts[:, None] * (p1[i] - p0[i])
        sampled = np.linalg.norm(np.maximum(np.abs(x) - half[i], 0.0), axis=1).min()
        if sampled > 1e-6:  # outside: exact, and t attains it
            assert abs(dist[i] - sampled) < 1e-5
            at = p0[i] + t[i] * (p1[i] - p0[i])
            assert abs(np.linalg.norm(np.maximum(np.abs(at) - half[i], 0.0)) - dist[i]) < 1e-9
        else:  # crossing: minus a penetration depth, at most the deepest of the segment's points
            depth = np.max(np.min(half[i] - np.abs(x), axis=1))  # sampled: within 1e-3 mm of the true one
            assert -depth - 1e-3 <= dist[i] < 0.0


def test_segment_segment_distance_matches_dense_sampling():
    p0, p1 = _segments(200)
    q0, q1 = _segments(200, spread=30.0)
    exact = segment_segment_distance(p0, p1, q0, q1)
    s = np.linspace(0.0, 1.0, 2001)
    for i in range(len(p0)):
        # points densely along the first segment, each one's distance to the second by hand
        # (the projection onto its line clamped to its ends): the least is an upper bound
        # within half a step of the first segment's length
        a = p0[i] + s[:, None] * (p1[i] - p0[i])
        d = q1[i] - q0[i]
        u = np.clip((a - q0[i]) @ d / (d @ d), 0.0, 1.0)
        sampled = np.min(np.linalg.norm(a - (q0[i] + u[:, None] * d), axis=1))
        assert exact[i] <= sampled + 1e-9 and sampled - exact[i] < 0.1
    parallel = segment_segment_distance(
        np.array([[0.0, 0, 0]]), np.array([[10.0, 0, 0]]), np.array([[5.0, 3, 0]]), np.array([[15.0, 3, 0]])
    )
    np.testing.assert_allclose(parallel, [3.0])


def test_capsule_segments_follow_the_hands_forward_kinematics(hand):
    caps = HandCapsules.of(hand)
    for q in (np.zeros(hand.n_joints), 0.5 * (hand.lower + hand.upper), hand.upper):
        p0, p1 = caps.segments(q)
        frames = forward_kinematics(hand, q)
        for row, link in enumerate(caps.links):
            (shape,) = hand.link_shapes[link]
            pose = frames[link] @ shape.pose
            half = 0.5 * shape.length * pose[:3, 2]
            np.testing.assert_allclose(p0[row], pose[:3, 3] - half, atol=1e-9)
            np.testing.assert_allclose(p1[row], pose[:3, 3] + half, atol=1e-9)


def test_the_hand_encloses_its_palm_not_points_far_in_front_or_beside_it():
    """Open hand (every joint at its lower limit, fingers straight along palm z): the palm box's
    centre is inside; a point 60 mm in front of the palm face, or 100 mm beside the little
    finger, is outside."""
    hand = load_hand()
    caps = HandCapsules.of(hand)
    open_q = np.asarray(hand.lower, dtype=float)
    palm = caps.palm_centre[0]
    assert caps.encloses(open_q, palm)
    assert not caps.encloses(open_q, palm + [60.0 + caps.palm_half[0][0], 0.0, 0.0])
    assert not caps.encloses(open_q, palm + [0.0, -100.0 - caps.palm_half[0][1], 0.0])


def test_posture_gaps_skips_only_distances_the_closure_masks(hand, synergies):
    """The closure's per-posture query leaves +inf for a link that does not move and for one
    surely beyond the query margin (its axis farther from the object's centre than the margin,
    both radii and the object's bounding ball); every other distance within the margin is
    ``capsule_object``'s, to the last bit, and one beyond it is beyond it (the closure masks
    both). Checked at postures along S1 and object poses near and far from the hand."""
    from pathlib import Path

    from scipy.spatial.transform import Rotation

    from synergrasp.hand.synergies import SynergyPath
    from synergrasp.simulation.capsules import capsule_object, posture_gaps
    from synergrasp.simulation.placement import ObjectPose
    from synergrasp.simulation.scene import HandScene
    from synergrasp.simulation.shapes import Mesh

    mesh = Mesh(str(Path(__file__).parent / "data" / "box_30x60x100.obj"), 0.5)
    scene = HandScene(hand)
    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    pairs = ((1, 2),)
    rng = np.random.default_rng(3)
    margin, skipped, kept = 40.0, 0, 0
    for sigma in np.linspace(*path.closure_range(hand.flexion_joints), 4):
        q = np.array(path.reference(sigma), dtype=float)
        for centre in ([60.0, 0.0, 80.0], [45.0, 20.0, 120.0], [150.0, 0.0, 60.0], [30.0, -40.0, 40.0]):
            scene.set_posture(q)
            scene.place_object(ObjectPose(np.array(centre), Rotation.random(random_state=rng).as_matrix(), mesh))
            placed = scene.placed
            every = np.full(hand.n_links, np.inf)  # every link's distance, nothing skipped
            every[scene.capsules.links] = capsule_object(
                *scene.capsules.segments(q), scene.capsules.radius, placed.rotation, placed.center_mm, 3, mesh.kernel_params
            )[0]
            assert np.array_equal(scene.object_distance()[1:], every[1:])  # the gaps alone: the same bits
            moving = rng.random(hand.n_links) < 0.7
            d_obj, _, _ = posture_gaps(q, *scene.query_args(), *scene.pair_args(pairs), moving, margin)
            for link in scene.capsules.links:
                if not moving[link]:
                    assert d_obj[link] == np.inf
                elif d_obj[link] == np.inf:  # skipped by the bound: surely beyond the margin
                    assert every[link] > margin
                    skipped += 1
                elif every[link] <= margin:
                    assert d_obj[link] == every[link]
                    kept += 1
                else:
                    assert d_obj[link] > margin
    assert skipped > 0 and kept > 0  # both branches ran
