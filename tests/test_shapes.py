"""The shape interface against brute force: nearest points, normals and segment distances
against dense sampling of the surface, the distance to a palm box, ray hits, the bounding
radius and the symmetries (docs/shapes.md)."""

from __future__ import annotations

import functools
import hashlib
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.spatial import ConvexHull, Delaunay, cKDTree
from scipy.spatial.transform import Rotation

import bullet_reference

from synergrasp.simulation.shapes import Box, Cylinder, Mesh, Sphere, start_rotation

RNG = np.random.default_rng(25)
#: Spacing (mm) of the dense surface samples; a sampled distance exceeds the exact one by less.
SPACING_MM = 0.25

DATA = Path(__file__).parent / "data"
#: Meshes: a convex one of 1000 faces (binary STL), a box (OBJ of quads), the duck of the
#: example study (non-convex: its convex decomposition, 5 parts).
MESHES = [
    Mesh(str(DATA / "rounded_cube_1000.stl"), 1.0),
    Mesh(str(DATA / "box_30x60x100.obj"), 1.0),
    Mesh(str(Path(__file__).parents[1] / "config" / "examples" / "meshes" / "duck.obj"), 50.0),
]
SHAPES = [Box((30.0, 60.0, 100.0)), Box((30.0, 30.0, 30.0)), Sphere(25.0), Cylinder(30.0, 120.0), Cylinder(40.0, 15.0), *MESHES]


def dense_surface(shape, spacing=SPACING_MM) -> np.ndarray:
    """Points (n, 3) covering the surface (own frame) no farther than ``spacing`` apart."""
    if shape.kind == "box":
        h = shape.half_extents_mm
        faces = []
        for k in range(3):
            i, j = [a for a in range(3) if a != k]
            u = np.linspace(-h[i], h[i], int(np.ceil(2 * h[i] / spacing)) + 1)
            v = np.linspace(-h[j], h[j], int(np.ceil(2 * h[j] / spacing)) + 1)
            uu, vv = np.meshgrid(u, v, indexing="ij")
            for side in (-1.0, 1.0):
                face = np.zeros((uu.size, 3))
                face[:, i], face[:, j], face[:, k] = uu.ravel(), vv.ravel(), side * h[k]
                faces.append(face)
        return np.concatenate(faces)
    if shape.kind == "sphere":  # a Fibonacci lattice, ~spacing apart
        n = int(np.ceil(4 * np.pi * shape.radius_mm**2 / spacing**2))
        k = np.arange(n) + 0.5
        z = 1 - 2 * k / n
        phi = np.pi * (1 + 5**0.5) * k
        s = np.sqrt(1 - z * z)
        return shape.radius_mm * np.c_[s * np.cos(phi), s * np.sin(phi), z]
    if shape.kind == "cylinder":
        r, hh = shape.radius_mm, shape.half_height_mm
        phi = np.linspace(0, 2 * np.pi, int(np.ceil(2 * np.pi * r / spacing)), endpoint=False)
        z = np.linspace(-hh, hh, int(np.ceil(2 * hh / spacing)) + 1)
        pp, zz = np.meshgrid(phi, z, indexing="ij")
        wall = np.c_[r * np.cos(pp.ravel()), r * np.sin(pp.ravel()), zz.ravel()]
        u = np.arange(-r, r + spacing / 2, spacing / 1.5)
        xx, yy = np.meshgrid(u, u, indexing="ij")
        disc = np.c_[xx.ravel(), yy.ravel()][xx.ravel() ** 2 + yy.ravel() ** 2 <= r * r]
        caps = [np.c_[disc, np.full(len(disc), side * hh)] for side in (-1.0, 1.0)]
        return np.concatenate([wall, *caps])
    if shape.kind == "mesh":  # every triangle of every part's hull, on a barycentric grid
        points = []
        for part in shape.geometry.parts:
            for a, b, c in part[ConvexHull(part).simplices]:
                n = int(np.ceil(max(np.linalg.norm(b - a), np.linalg.norm(c - a), np.linalg.norm(c - b)) / spacing))
                i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
                keep = i + j <= n
                u, v = i[keep] / n, j[keep] / n
                points.append(a + u[:, None] * (b - a) + v[:, None] * (c - a))
        return np.concatenate(points)
    raise AssertionError(f"no sampler for {shape.kind}")


def inside(shape, points: np.ndarray) -> np.ndarray:
    """Brute-force membership (own frame), independent of the shape's methods."""
    if shape.kind == "box":
        return np.all(np.abs(points) <= shape.half_extents_mm, axis=-1)
    if shape.kind == "sphere":
        return np.linalg.norm(points, axis=-1) <= shape.radius_mm
    if shape.kind == "cylinder":
        return (np.hypot(points[..., 0], points[..., 1]) <= shape.radius_mm) & (np.abs(points[..., 2]) <= shape.half_height_mm)
    if shape.kind == "mesh":  # in the hull of a part's vertices (a triangulation of it)
        return np.any([d.find_simplex(points) >= 0 for d in _triangulations(shape)], axis=0)
    raise AssertionError(shape.kind)


@functools.cache
def _triangulations(shape):
    return [Delaunay(part) for part in shape.geometry.parts]


def _on_one_face(shape, point) -> bool:
    """Whether a point of a mesh lies on one face plane only (inside a face, off its edges)."""
    return any(int((np.abs(planes[:, :3] @ point - planes[:, 3]) <= 1e-6).sum()) == 1 for planes in shape.geometry.planes)


def _pose():
    return Rotation.from_rotvec(RNG.normal(size=3)).as_matrix(), RNG.normal(size=3) * 20.0


@pytest.fixture(scope="module", params=SHAPES, ids=lambda s: f"{s.kind}-{s.label}")
def shape(request):
    return request.param


class Sampled:
    """A shape's dense surface samples (own frame) and a k-d tree of them."""

    def __init__(self, shape, spacing=SPACING_MM) -> None:
        self.points = dense_surface(shape, spacing)
        self.tree = cKDTree(self.points)

    def nearest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Sampled distance and nearest sample of every point."""
        d, i = self.tree.query(points)
        return d, self.points[i]


@pytest.fixture(scope="module")
def surface(shape):
    return Sampled(shape)


def test_surface_point_and_normal_match_dense_sampling(shape, surface):
    R, c = _pose()
    r = shape.bounding_radius_mm
    local = RNG.uniform(-1.6 * r, 1.6 * r, size=(300, 3))
    sampled, _ = surface.nearest(local)
    several = shape.kind == "mesh" and len(shape.geometry.parts) > 1
    for p, d_s in zip(local, sampled):
        if several and inside(shape, p[None])[0]:
            continue  # inside a union of parts: the nearest face of one part, maybe inside another
        point, normal = shape.surface_point(R @ p + c, R, c)
        on = R.T @ (point - c)
        d = np.linalg.norm(on - p)
        assert d <= d_s + 1e-9 and d_s - d <= SPACING_MM  # exact: never farther than a sample
        assert surface.nearest(on[None])[0][0] <= SPACING_MM  # on the surface
        assert abs(np.linalg.norm(normal) - 1.0) < 1e-12
        n = R.T @ normal
        if not inside(shape, p[None])[0] and d > 1e-3:  # outside: the normal points from p to the surface
            np.testing.assert_allclose(n, (on - p) / d, atol=1e-9)
        # inward: a step along the normal from the surface point goes in (off a mesh's edges,
        # which may be sharper than the step), against it out
        assert not inside(shape, (on - 0.05 * n)[None])[0]
        assert inside(shape, (on + 0.05 * n)[None])[0] or (shape.kind == "mesh" and not _on_one_face(shape, on))


def test_segment_distance_matches_dense_sampling(shape):
    """The closure's compiled query: outside exact (and attained at its t), crossing minus a
    penetration depth, at most the deepest of the segment's points."""
    r = shape.bounding_radius_mm
    p0 = RNG.uniform(-1.5 * r, 1.5 * r, size=(150, 3))
    p1 = p0 + RNG.normal(size=(150, 3)) * 0.5 * r
    dist, t = shape.segment_distance(p0, p1)
    ts = np.linspace(0.0, 1.0, 4001)
    R, c = np.eye(3), np.zeros(3)
    for i in range(len(p0)):
        x = p0[i] + ts[:, None] * (p1[i] - p0[i])
        gap = shape.gap(x, R, c)
        if gap.min() > 1e-6:
            step = np.linalg.norm(p1[i] - p0[i]) / (len(ts) - 1)  # the gap is 1-Lipschitz along the segment
            assert dist[i] <= gap.min() + 1e-9 and gap.min() - dist[i] <= step
            at = p0[i] + t[i] * (p1[i] - p0[i])
            assert abs(shape.gap(at[None], R, c)[0] - dist[i]) < 1e-9
        else:
            assert dist[i] < 0.0


def test_gap_matches_dense_sampling(shape, surface):
    r = shape.bounding_radius_mm
    points = RNG.uniform(-1.6 * r, 1.6 * r, size=(400, 3))
    R, c = np.eye(3), np.zeros(3)
    gap = shape.gap(points, R, c)
    sampled, _ = surface.nearest(points)
    out = ~inside(shape, points)
    assert np.all(gap[~out] == 0.0)
    assert np.all(gap[out] <= sampled[out] + 1e-9) and np.all(sampled[out] - gap[out] <= SPACING_MM)


def test_distance_to_a_palm_box_matches_dense_sampling(shape):
    """``box_gap``: the shape against a box of the palm, both turned; positive gaps exact to
    the sampling, and the point it gives lies between the two."""
    palm_half = np.array([12.0, 39.0, 38.0])
    palm = Box(tuple(2 * palm_half))
    palm_surface, coarse = Sampled(palm, 0.5), dense_surface(shape, 0.5)
    for _ in range(8):
        R, c = _pose()
        pose = np.eye(4)
        pose[:3, :3] = Rotation.from_rotvec(RNG.normal(size=3)).as_matrix()
        direction = RNG.normal(size=3)
        pose[:3, 3] = c + direction / np.linalg.norm(direction) * (shape.bounding_radius_mm + 60.0 + RNG.uniform(-40, 20))
        d, point = shape.box_gap(R, c, pose, palm_half)
        own = coarse @ R.T + c
        if d > 0:
            sampled = palm_surface.tree.query((own - pose[:3, 3]) @ pose[:3, :3])[0].min()
            assert d <= sampled + 1e-9 and sampled - d <= 0.75  # two samplings, each within 0.5/√2 mm
            assert shape.gap(point[None], R, c)[0] <= d + 1e-6
            assert palm.gap(point[None], pose[:3, :3], pose[:3, 3])[0] <= d + 1e-6
        else:
            assert palm.gap(own, pose[:3, :3], pose[:3, 3]).min() == 0.0  # they overlap


def test_ray_hits_enter_the_surface_first(shape):
    R, c = np.eye(3), np.zeros(3)
    r = shape.bounding_radius_mm
    direction = RNG.normal(size=3)
    direction /= np.linalg.norm(direction)
    origins = RNG.uniform(-r, r, size=(500, 3)) - 3 * r * direction
    t, normal, face = shape.ray_hits(origins, direction)
    hit = face >= 0
    assert hit.any() and (~hit).any()
    entry = origins[hit] + t[hit, None] * direction
    assert np.all(shape.gap(entry, R, c) < 1e-9)
    assert not inside(shape, entry - 1e-3 * direction).any()  # nothing of it before the entry
    assert np.all(normal[hit] @ direction < 0)  # an entry faces against the ray
    ts = np.linspace(0, 6 * r, 3001)  # missed rays: no sample along them is inside
    for o in origins[~hit][:50]:
        assert not inside(shape, o + ts[:, None] * direction).any()


def test_bounding_radius_holds_the_shape_and_is_reached(shape, surface):
    reach = np.linalg.norm(surface.points, axis=1)
    assert reach.max() <= shape.bounding_radius_mm + 1e-9
    assert reach.max() >= shape.bounding_radius_mm - SPACING_MM


def _volume(shape) -> float:
    if shape.kind == "box":
        return float(np.prod(shape.size_mm))
    if shape.kind == "sphere":
        return 4.0 / 3.0 * np.pi * shape.radius_mm**3
    if shape.kind == "cylinder":
        return np.pi * shape.radius_mm**2 * shape.height_mm
    return sum(ConvexHull(part).volume for part in shape.geometry.parts)  # a mesh: its convex parts


def test_the_surface_mesh_is_closed_outward_and_on_the_surface(shape):
    R, c = _pose()
    vertices, triangles = shape.surface_mesh(R, c)
    local = (vertices - c) @ R
    if shape.kind == "mesh":  # its parts' own vertices
        known = {tuple(v) for v in np.round(np.concatenate(shape.geometry.parts), 6)}
        assert {tuple(v) for v in np.round(local, 6)} <= known
    else:  # convex about its centre: inside it, and outside it a hair further out
        outward = local * (1.0 + 1e-6) + 1e-9 * np.sign(local)
        assert inside(shape, local * (1.0 - 1e-9)).all() and not inside(shape, outward).any()
    # welded at shared positions, every edge is used as often in one direction as in the other:
    # closed surfaces (one per convex part of a mesh), each of one orientation
    _, weld = np.unique(np.round(local, 6), axis=0, return_inverse=True)
    t = weld.ravel()[triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    edges = [tuple(e) for e in np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])]
    assert Counter(edges) == Counter((b, a) for a, b in edges)
    # outward: the divergence theorem gives the volume, positive (a polygon's: the exact one or a little less)
    a, b, d = (local[triangles[:, k]] for k in range(3))
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, d)).sum() / 6.0)
    assert 0.97 * _volume(shape) <= volume <= _volume(shape) * (1.0 + 1e-9)


def test_start_rotation_puts_the_own_axes_on_the_palm_axes():
    for axes in [(0, 1, 2), (1, 0, 2), (2, 0, 1), (0, 2, 1)]:
        R0 = start_rotation(axes)
        assert np.allclose(R0 @ R0.T, np.eye(3)) and np.isclose(np.linalg.det(R0), 1.0)
        for k, own in enumerate(axes):
            assert abs(R0[k, own]) == 1.0  # own axis `own` along palm axis k (reversed for an odd permutation)


def test_box_symmetries_are_its_own():
    box = Box((30.0, 60.0, 100.0))
    c = np.array([1.0, 2.0, 3.0])
    half_turn_x = Rotation.from_euler("x", 180, degrees=True).as_matrix()
    quarter_turn_x = Rotation.from_euler("x", 90, degrees=True).as_matrix()
    assert box.same_region(np.eye(3), c, half_turn_x, c)
    assert not box.same_region(np.eye(3), c, quarter_turn_x, c)
    assert Box((30.0, 60.0, 60.0)).same_region(np.eye(3), c, quarter_turn_x, c)
    assert not box.same_region(np.eye(3), c, np.eye(3), c + 1e-3)


def test_a_cylinder_tilted_by_a_microradian_is_another_region():
    """Its rim moves by θ·R ≈ 6e-5 mm, far beyond 1e-9 of its size; 1 − cos θ (5e-13) would not see it."""
    can = Cylinder(30.0, 120.0)
    c = np.zeros(3)
    spin = Rotation.from_euler("z", 37, degrees=True).as_matrix()
    tilt = Rotation.from_euler("x", 1e-6).as_matrix()
    assert can.same_region(np.eye(3), c, spin, c)
    assert can.same_region(np.eye(3), c, Rotation.from_euler("x", 180, degrees=True).as_matrix(), c)
    assert not can.same_region(np.eye(3), c, tilt, c)


#: The contacts of tests/config/small.yaml per object, pinned value by value in
#: tests/data/small_contacts.npz (``_contacts_columns``; key "<object>/<column>", each float
#: column's rows concatenated). Pinned at main 8966525, before the shape interface (the box
#: through the interface gave them bit for bit), re-pinned when the kinematic closure began
#: closing once per region, and stored from the rows whose sha256 (first 16 hex digits,
#: ``_contacts_digest``) was {"obj1": "896279045619b53c", "obj4": "27a04a85f5f811e1"}.
#: Bytes are not compared across machines: OpenBLAS's kernels (e.g. Haswell against
#: SkylakeX, chosen by OPENBLAS_CORETYPE) round differently, and the closure's rows then differ
#: by at most 6.4e-14 (mm or rad) between them; a single machine's runs are compared byte for
#: byte (test_the_closure_gives_the_same_bytes_twice_on_one_machine).
PINNED_SMALL_CONTACTS = Path(__file__).parent / "data" / "small_contacts.npz"
#: Absolute tolerances of the pinned values, per column (mm for lengths, rad for q, unitless
#: for normals and rotations); columns not listed must match exactly.
PINNED_ATOL = {
    "q": 1e-12,
    "contact_point": 1e-9,
    "contact_normal": 1e-12,
    "jacobian": 1e-9,
    "object_center": 1e-9,
    "object_rotation": 1e-12,
    "max_penetration_mm": 1e-9,
}
_DIGESTED = (
    "pose",
    "status",
    "q",
    "finger_state",
    "contact_link",
    "contact_point",
    "contact_normal",
    "jacobian",
    "object_center",
    "object_rotation",
    "max_penetration_mm",
)


def _is_text(value) -> bool:
    return isinstance(value, str) or bool(len(np.shape(value)) and len(value) and isinstance(value[0], str))


def _contacts_digest(table) -> str:
    h = hashlib.sha256()
    for column in _DIGESTED:
        for value in table[column]:
            if isinstance(value, str):
                h.update(value.encode())
            elif _is_text(value):
                h.update("|".join(value).encode())
            else:
                h.update(np.ascontiguousarray(np.asarray(value, dtype=np.float64)).tobytes())
    return h.hexdigest()[:16]


def _contacts_columns(table) -> dict[str, np.ndarray]:
    """The digested columns as arrays: text joined per row, floats concatenated over rows."""
    out = {}
    for column in _DIGESTED:
        values = list(table[column])
        if _is_text(values[0]):
            out[column] = np.array([v if isinstance(v, str) else "|".join(v) for v in values])
        else:
            out[column] = np.concatenate([np.asarray(v, dtype=np.float64).ravel() for v in values])
    return out


def _small_config_table(hand, synergies, name):
    from synergrasp.config import validate_config
    from synergrasp.simulation.closure import SimulateParams, simulate_object

    config = validate_config(yaml.safe_load((Path(__file__).parent / "config" / "small.yaml").read_text()))
    sim = SimulateParams.from_config(config, name)
    return simulate_object(hand, synergies, sim.object, sim.placement, sim.closure)


def test_the_box_gives_the_pinned_contacts_on_the_small_config(hand, synergies):
    pinned = np.load(PINNED_SMALL_CONTACTS)
    for name in ("obj1", "obj4"):
        got = _contacts_columns(_small_config_table(hand, synergies, name))
        for column, value in got.items():
            expected = pinned[f"{name}/{column}"]
            assert value.shape == expected.shape, (name, column)
            if column in PINNED_ATOL:
                np.testing.assert_allclose(value, expected, rtol=0, atol=PINNED_ATOL[column], err_msg=f"{name} {column}")
            else:
                np.testing.assert_array_equal(value, expected, err_msg=f"{name} {column}")


def test_the_closure_gives_the_same_bytes_twice_on_one_machine(hand, synergies):
    first, second = (_small_config_table(hand, synergies, "obj1") for _ in range(2))
    assert _contacts_digest(first) == _contacts_digest(second)


# ------------------------------------------------------------------ symmetry through the closure

_COMPARED = ("status", "q", "contact_link", "contact_point", "contact_normal", "object_center")


def _same_grasps(table, rows, atol=1e-6):
    first = table.iloc[rows[0]]
    for i in rows[1:]:
        other = table.iloc[i]
        for column in _COMPARED:
            a, b = first[column], other[column]
            if isinstance(a, str):
                assert a == b, (column, i)
            else:
                np.testing.assert_allclose(
                    np.asarray(b, dtype=float), np.asarray(a, dtype=float), atol=atol, err_msg=f"{column} at row {i}"
                )


def _closed_apart(hand, synergies, grasped, placement, poses):
    """One closure per pose, each in its own run: within a run, poses that fill one region
    share the first one's closure (docs/closure.md), which would make equality trivial."""
    from conftest import study_closure_params
    from synergrasp.simulation.closure import simulate_object

    return pd.concat(
        [simulate_object(hand, synergies, grasped, placement, study_closure_params(), poses=[p]) for p in poses],
        ignore_index=True,
    )


def test_a_sphere_on_the_approach_gives_the_same_grasp_at_every_pose(hand, synergies):
    """A sphere turned about its centre fills the same region: brought toward the palm centre
    it stops at the same place and the hand closes on it the same way at every (α, β)."""
    from conftest import study_placement
    from synergrasp.simulation.objects import GraspedObject

    ball = GraspedObject("ball", Sphere(30.0), 0.2)
    poses = [0, 137, 512, 901, 1250, 1799]
    table = _closed_apart(hand, synergies, ball, study_placement(), poses)
    assert (table.status == "grasp").all() and (table.n_contacts >= 2).all()
    _same_grasps(table, list(range(len(poses))))


@pytest.mark.parametrize("axes, period", [((2, 0, 1), 5.0), ((0, 1, 2), 180.0)])
def test_the_cylinders_period_and_its_grasps_repeat_with_it(hand, synergies, axes, period):
    """Axis along the palm normal (the α axis): every α step is a symmetry; axis along the
    fingers: the half turn. The α-period says so, and the closure repeats with it."""
    from conftest import study_placement
    from synergrasp.analysis.periods import alpha_period_deg
    from synergrasp.simulation.objects import GraspedObject
    from synergrasp.simulation.placement import pose_grid

    can = GraspedObject("can", Cylinder(30.0, 120.0), 0.5)
    placement = study_placement(box_axes=axes)
    assert alpha_period_deg(placement, can.shape) == period
    grid = pose_grid(placement)
    for alpha, beta in [(-30.0, 0.0), (40.0, 25.0)]:
        shifted = (alpha + period + 180.0) % 360.0 - 180.0
        poses = [grid.index(alpha, beta), grid.index(shifted, beta)]
        table = _closed_apart(hand, synergies, can, placement, poses)
        assert (table.status == "grasp").all()
        _same_grasps(table, [0, 1])
    if period < 90.0:  # not the half turn: the grasp is the same at every α
        poses = [grid.index(a, 10.0) for a in (-180.0, -95.0, 0.0, 135.0)]
        _same_grasps(_closed_apart(hand, synergies, can, placement, poses), [0, 1, 2, 3])


@pytest.mark.parametrize(
    "shape",
    [Box((30.0, 60.0, 100.0)), Sphere(25.0), Cylinder(30.0, 120.0), MESHES[0], MESHES[2]],
    ids=lambda s: s.kind if s.kind != "mesh" else Path(s.path).stem,
)
def test_the_engines_collision_shape_is_the_same_shape(shape):
    """pybullet's body of the shape (``collision_geometry``), turned and moved, against small
    probe spheres off the middle of its faces (where the engine does not round its edges):
    the engine's distances are the shape's ``gap`` (float32 and its solver: 0.05 mm; on a
    hull of many faces, whose nearly coplanar faces the engine merges, 0.1 mm: measured
    0.002–0.05 mm, always farther); so its sizes and axes are the shape's."""
    from synergrasp.simulation import bullet

    R, c = Rotation.from_rotvec([0.3, -0.5, 0.2]).as_matrix(), np.array([10.0, -4.0, 30.0])
    client = bullet.connect()
    try:
        obj = bullet_reference.load_object(client, shape, c, R)
        for u in np.vstack([np.eye(3), -np.eye(3)]) @ R.T:  # its own axes, palm frame
            on, _ = shape.surface_point(c + u * (shape.bounding_radius_mm + 5.0), R, c)
            for offset in (3.0, 7.5):
                point = on + offset * u
                probe = bullet_reference.load_object(client, Sphere(1.0), point)
                near = bullet.closest_points(client, obj, probe, 50.0)
                tolerance = 0.1 if shape.kind == "mesh" else 0.05
                assert abs(float(near.distance.min()) + 1.0 - shape.gap(point[None], R, c)[0]) < tolerance
                bullet.remove_body(client, probe)
    finally:
        bullet.disconnect(client)
