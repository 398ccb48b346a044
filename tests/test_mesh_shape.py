"""Meshes (docs/shapes.md): OBJ and STL read alike, bad files and scales named by their key
before any job, the convex decomposition cached per file content, and a mesh of a box that
is the box (distances, normals, symmetry and the closure's contacts). Distances and normals
against dense sampling: tests/test_shapes.py, which runs every shape test on meshes too."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from synergrasp.config import ConfigError, defaults, validate_config
from synergrasp.simulation.objects import GraspedObject, object_problems
from synergrasp.simulation.shapes import Box, Mesh, ShapeError, shape_from_config
from synergrasp.simulation.shapes.mesh_file import read_mesh

DATA = Path(__file__).parent / "data"
BOX_OBJ = DATA / "box_30x60x100.obj"
HALF = np.array([15.0, 30.0, 50.0])
_CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
#: The box's faces as corner quads (indices into _CORNERS), counter-clockwise from outside.
_QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def _triangles(quads=_QUADS) -> list[tuple[int, int, int]]:
    return [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def _write_obj(path: Path, vertices, triangles) -> Path:
    lines = [f"v {x} {y} {z}" for x, y, z in vertices] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in triangles]
    path.write_text("\n".join(lines) + "\n")
    return path


def _write_stl(path: Path, vertices, triangles, binary: bool) -> Path:
    corners = np.asarray(vertices, dtype=float)[np.asarray(triangles)]
    if binary:
        path.write_bytes(
            b"box".ljust(80)
            + struct.pack("<I", len(corners))
            + b"".join(struct.pack("<12fH", 0, 0, 0, *t.ravel(), 0) for t in corners)
        )
    else:
        facets = "".join(
            "facet normal 0 0 0\n outer loop\n" + "".join(f"  vertex {x} {y} {z}\n" for x, y, z in t) + " endloop\nendfacet\n"
            for t in corners
        )
        path.write_text(f"solid box\n{facets}endsolid box\n")
    return path


# ------------------------------------------------------------------------------ reading


def test_obj_and_stl_of_one_box_read_alike(tmp_path):
    """Quads with ``v//vn`` tokens, negative indices, ASCII and binary STL: the same solid."""
    box = _CORNERS * HALF
    negative = tmp_path / "negative.obj"
    negative.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in box)
        + "vt 0 0\n"
        + "".join("f " + " ".join(f"{k - 8}/1" for k in q) + "\n" for q in _QUADS)
    )
    files = [
        BOX_OBJ,
        negative,
        _write_stl(tmp_path / "a.stl", box, _triangles(), binary=False),
        _write_stl(tmp_path / "b.STL", box, _triangles(), binary=True),
    ]
    for path in files:
        mesh = read_mesh(path)
        assert len(mesh.vertices) == 8 and len(mesh.triangles) == 12, path
        assert mesh.volume == pytest.approx(30 * 60 * 100, rel=1e-12)
        np.testing.assert_allclose(mesh.centroid, 0.0, atol=1e-12)
        np.testing.assert_array_equal(np.sort(mesh.vertices, axis=0), np.sort(box, axis=0))


def test_a_mesh_is_centred_on_its_solid_and_scaled(tmp_path):
    shifted = _write_obj(tmp_path / "shifted.obj", _CORNERS * HALF / 10.0 + [1.0, 2.0, 3.0], _triangles())
    mesh = Mesh(str(shifted), 10.0)  # cm: 10 mm per unit
    assert mesh.geometry.convex and len(mesh.geometry.parts) == 1
    np.testing.assert_allclose(np.sort(mesh.geometry.parts[0], axis=0), np.sort(_CORNERS * HALF, axis=0), atol=1e-12)
    assert mesh.bounding_radius_mm == pytest.approx(np.linalg.norm(HALF))
    assert mesh.label == "mesh, 30 × 60 × 100 mm"


# ------------------------------------------------------------------------ bad files, bad scales


def _config(path, scale=1.0):
    return validate_config({"objects": {"thing": {"shape": {"mesh": {"path": str(path), "scale": scale}}, "mass_kg": 0.3}}})


def _bad_files(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    box = _CORNERS * HALF
    flat = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [5.0, 5.0, 0.0]])
    two = np.vstack([box, box + [30.0, 60.0, 0.0]])  # two boxes sharing one edge
    shared = np.unique(two, axis=0, return_inverse=True)[1].reshape(-1)
    edge_pair = [tuple(shared[list(t)]) for t in _triangles()] + [tuple(shared[[k + 8 for k in t]]) for t in _triangles()]
    flipped = _triangles()
    flipped[0] = flipped[0][::-1]
    (tmp_path / "empty.obj").write_text("# nothing\n")
    (tmp_path / "text.stl").write_text("not a mesh\n")
    (tmp_path / "box.ply").write_text("ply\n")
    return {
        "missing": (tmp_path / "nowhere.obj", "does not exist"),
        "empty": (tmp_path / "empty.obj", "holds no triangles"),
        "not an STL": (tmp_path / "text.stl", "is neither a binary STL"),
        "wrong extension": (tmp_path / "box.ply", "is not an OBJ or STL file"),
        "a folder": (tmp_path, "is a folder; give an OBJ or STL file"),
        "open": (_write_obj(tmp_path / "open.obj", box, _triangles()[:-1]), "is not closed: 3 edges belong to one"),
        "non-manifold": (
            _write_obj(tmp_path / "pair.obj", np.unique(two, axis=0), edge_pair),
            "is non-manifold: 1 edges are shared by more than two triangles",
        ),
        "inconsistent": (_write_obj(tmp_path / "flip.obj", box, flipped), "are not consistently oriented"),
        "flat": (_write_obj(tmp_path / "flat.obj", flat, [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]), "encloses no volume"),
        "bad line": (_write_obj(tmp_path / "line.obj", box, _triangles()), ""),
    }


@pytest.mark.parametrize(
    "case", ["missing", "empty", "not an STL", "wrong extension", "a folder", "open", "non-manifold", "inconsistent", "flat"]
)
def test_a_bad_mesh_file_is_one_error_naming_the_key(tmp_path, case):
    path, problem = _bad_files(tmp_path)[case]
    problems = object_problems(_config(path))
    assert len(problems) == 1
    assert problems[0].startswith("config error at 'objects.thing.shape.mesh.path': ") and problem in problems[0]
    with pytest.raises(ConfigError, match=r"'objects\.thing\.shape\.mesh\.path'"):
        GraspedObject.from_config(_config(path), "thing")


def test_an_unreadable_line_is_named_with_its_number(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")
    (problem,) = object_problems(_config(path))
    assert "line 4: cannot read 'f 1 2 x'" in problem and "'objects.thing.shape.mesh.path'" in problem


@pytest.mark.parametrize("scale", [0, -2.0, "big", math.inf])
def test_a_bad_scale_is_named(scale):
    with pytest.raises(ConfigError, match=r"objects\.thing\.shape\.mesh\.scale"):
        _config(BOX_OBJ, scale)
    with pytest.raises(ShapeError, match=r"^'s\.mesh\.scale': "):
        shape_from_config({"mesh": {"path": str(BOX_OBJ), "scale": scale}}, "s")


# --------------------------------------------------------------------------- decomposition


def _l_shape(tmp_path: Path, name: str, long_mm: float) -> Path:
    """An L-shaped prism (non-convex): two boxes, 20 mm thick, unioned."""
    xy = [(0, 0), (long_mm, 0), (long_mm, 20), (20, 20), (20, 60), (0, 60)]
    vertices = [(x, y, z) for z in (0.0, 20.0) for x, y in xy]
    n = len(xy)
    bottom = [(0, 5, 4), (0, 4, 3), (0, 3, 1), (1, 3, 2)]
    tri = bottom + [(a + n, c + n, b + n) for a, b, c in bottom]
    for i in range(n):
        j = (i + 1) % n
        tri += [(i, j, j + n), (i, j + n, i + n)]
    return _write_obj(tmp_path / name, vertices, tri)


def test_a_non_convex_mesh_is_decomposed_once_per_file_content(tmp_path, monkeypatch):
    import pybullet

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    calls = []
    real = pybullet.vhacd
    monkeypatch.setattr(pybullet, "vhacd", lambda *a, **k: (calls.append(a[0]), real(*a, **k))[1])
    first = Mesh(str(_l_shape(tmp_path, "l.obj", 60.0)), 1.0)
    assert not first.geometry.convex and len(first.geometry.parts) >= 2 and len(calls) == 1
    again = _l_shape(tmp_path, "copy.obj", 60.0)  # same content, another name: from the cache
    assert Mesh(str(again), 2.0).geometry.parts[0] == pytest.approx(2.0 * first.geometry.parts[0])
    assert len(calls) == 1
    longer = Mesh(str(_l_shape(tmp_path, "longer.obj", 70.0)), 1.0)  # new content: decomposed on first use
    assert longer.across_mm > 0 and len(calls) == 1  # building the shape (the configuration's checks) does not
    assert not longer.geometry.convex
    assert len(calls) == 2
    # the parts cover the L: points inside it are inside the union, its notch is not filled
    inside = np.array([[10.0, 10.0, 10.0], [50.0, 10.0, 10.0], [10.0, 50.0, 10.0]]) - _centroid(first)
    assert (first.gap(inside, np.eye(3), np.zeros(3)) == 0.0).all()
    assert first.gap(np.array([[45.0, 45.0, 10.0]]) - _centroid(first), np.eye(3), np.zeros(3))[0] > 15.0


@pytest.mark.parametrize("concave", [True, False])
def test_the_parts_file_of_the_workflow_gives_the_parts_made_on_first_use(tmp_path, monkeypatch, concave):
    """The rule mesh_parts writes a file (write_parts) from which the shape reads exactly the
    parts it would make itself (V-HACD's for the L, the hull of a box), decomposing nothing."""
    import pybullet

    from synergrasp.simulation.shapes.convex_parts import write_parts

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    path = str(_l_shape(tmp_path, "l.obj", 60.0) if concave else BOX_OBJ)
    made = Mesh(path, 1.5).geometry
    write_parts(read_mesh(path), tmp_path / "parts.obj")
    monkeypatch.setattr(pybullet, "vhacd", lambda *a, **k: pytest.fail("decomposed although the parts are given"))
    read = Mesh(path, 1.5, parts=str(tmp_path / "parts.obj")).geometry
    assert len(read.parts) == len(made.parts) == (len(read.parts) if concave else 1) and (len(read.parts) > 1) == concave
    assert all(np.array_equal(a, b) for a, b in zip(read.parts, made.parts))
    assert all(np.array_equal(a, b) for a, b in zip(read.planes, made.planes))
    assert read.convex == made.convex == (not concave) and np.array_equal(read.region, made.region)


def test_a_missing_parts_file_is_named_when_the_parts_are_first_needed(tmp_path):
    mesh = Mesh(str(BOX_OBJ), 1.0, parts=str(tmp_path / "none.obj"))  # the checks read the mesh file only
    with pytest.raises(ShapeError, match="parts: .*none.obj.* cannot be read.*mesh_parts"):
        mesh.bounding_radius_mm


def _centroid(mesh: Mesh) -> np.ndarray:
    return read_mesh(mesh.path).centroid


# ------------------------------------------------------------------------ a mesh of a box is the box


@pytest.fixture(scope="module")
def pair():
    return Box((30.0, 60.0, 100.0)), Mesh(str(BOX_OBJ), 1.0)


def test_a_mesh_of_a_box_has_the_boxs_distances_normals_and_symmetry(pair):
    box, mesh = pair
    rng = np.random.default_rng(7)
    p0 = rng.uniform(-90, 90, (3000, 3))
    p1 = p0 + rng.normal(size=(3000, 3)) * 25.0
    d_box, t_box = box.segment_distance(p0, p1)
    d_mesh, t_mesh = mesh.segment_distance(p0, p1)
    out = d_box > 0
    np.testing.assert_allclose(d_mesh[out], d_box[out], atol=1e-9)
    # t: exact where the nearest point is unique; along a stretch of nearly equal distance the
    # two shapes' flatness tolerances differ (1e-9 mm over the segment against 1e-9 mm²)
    assert np.median(np.abs(t_mesh - t_box)[out]) < 1e-12 and np.abs(t_mesh - t_box)[out].max() < 1e-4
    assert ((d_mesh < 0) == (d_box < 0)).all()
    R, c = Rotation.from_rotvec([0.4, -0.2, 0.9]).as_matrix(), np.array([5.0, -3.0, 70.0])
    for x in rng.uniform(-90, 90, (200, 3)):
        for got, want in zip(mesh.surface_point(c + x, R, c), box.surface_point(c + x, R, c)):
            np.testing.assert_allclose(got, want, atol=1e-9)
    np.testing.assert_allclose(mesh.gap(p0, R, c), box.gap(p0, R, c), atol=1e-9)
    for x in ([15.2, 30.1, 0.0], [15.0, 0.0, 0.0], [14.7, -29.8, 49.9], [0.0, 0.0, 60.0]):  # faces within reach
        normals = [sorted(map(tuple, np.round(s.normals_near(c + R @ np.array(x), R, c, 0.5), 12))) for s in pair]
        assert normals[0] == normals[1]
    palm = np.eye(4)
    palm[:3, 3] = [-70.0, 10.0, 60.0]
    assert mesh.box_gap(R, c, palm, np.array([12.0, 39.0, 38.0]))[0] == pytest.approx(
        box.box_gap(R, c, palm, np.array([12.0, 39.0, 38.0]))[0], abs=1e-9
    )
    # overlapping: minus the penetration depth (2 mm along x); touching edge on edge (a box
    # turned 45° about z with an edge on the mesh's edge): 0
    palm[:3, 3] = [15.0 + 12.0 - 2.0, 5.0, -3.0]
    assert mesh.box_gap(np.eye(3), np.zeros(3), palm, np.array([12.0, 39.0, 38.0]))[0] == pytest.approx(-2.0, abs=1e-12)
    palm[:3, :3] = Rotation.from_euler("z", 45, degrees=True).as_matrix()
    palm[:3, 3] = [15.0 + 10.0 / np.sqrt(2), 30.0 + 10.0 / np.sqrt(2), 0.0]
    assert mesh.box_gap(np.eye(3), np.zeros(3), palm, np.array([10.0, 10.0, 20.0]))[0] == pytest.approx(0.0, abs=1e-9)
    half_turn, quarter_turn = (Rotation.from_euler("x", a, degrees=True).as_matrix() for a in (180, 90))
    assert mesh.same_region(np.eye(3), c, half_turn, c) and not mesh.same_region(np.eye(3), c, quarter_turn, c)


def test_a_mesh_of_a_box_gets_the_boxs_period_and_contacts(pair, hand, synergies):
    from conftest import study_closure_params, study_placement
    from synergrasp.analysis.periods import alpha_period_deg
    from synergrasp.simulation.closure import simulate_object

    box, mesh = pair
    placement = study_placement()
    assert alpha_period_deg(placement, mesh) == alpha_period_deg(placement, box) == 180.0
    poses = [0, 301, 777, 1024, 1500, 1799]
    tables = [
        simulate_object(hand, synergies, GraspedObject(name, shape, 1.0), placement, study_closure_params(), poses=poses)
        for name, shape in (("box", box), ("mesh", mesh))
    ]
    for column in ("status", "finger_state", "contact_link"):
        assert [list(np.ravel(v)) for v in tables[1][column]] == [list(np.ravel(v)) for v in tables[0][column]]
    for column in ("q", "contact_point", "contact_normal", "object_center"):
        for got, want in zip(tables[1][column], tables[0][column]):
            np.testing.assert_allclose(np.asarray(got, dtype=float), np.asarray(want, dtype=float), atol=1e-6, err_msg=column)
    assert (tables[0].n_contacts >= 1).all() and tables[0].n_contacts.sum() >= 12


def test_defaults_hold_no_mesh():
    assert all("mesh" not in spec["shape"] for spec in defaults()["objects"].values())


# ----------------------------------------------------------------- the example study's meshes, fast


ROOT = Path(__file__).resolve().parents[1]


def _example_config() -> dict:
    """config/config.yaml with the example study's overlay, at the palm centre (the searched
    targets need the search's output; the full example runs it)."""
    import yaml

    from synergrasp.config import overlay

    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    config = overlay(base, yaml.safe_load((ROOT / "config" / "examples" / "everyday_objects.yaml").read_text()))
    config["placement"] = {**config["placement"], "mode": "approach"}
    return config


@pytest.mark.parametrize("obj, alpha, beta", [("duck", -30.0, 0.0), ("duck", 95.0, -40.0), ("blob", 10.0, 25.0)])
def test_the_example_studys_meshes_are_grasped_and_optimised(monkeypatch, obj, alpha, beta):
    """The mesh path of `snakemake figures --configfile config/examples/everyday_objects.yaml`
    on a few poses through the one-grasp front door (its files read from the project's
    root): closed without intersecting the open hand, the contacts on the mesh's parts with
    unit normals pointing into it, and optimised with every synergy."""
    from synergrasp.inspector import inspect_grasp

    monkeypatch.chdir(ROOT)
    full = tuple(range(1, 16))
    result = inspect_grasp(_example_config(), obj, alpha, beta, sets=[(1,), full])
    assert result.closure_status == "grasp" and len(result.contacts) >= 2
    np.testing.assert_allclose(np.linalg.norm(np.array(result.contacts["normal"].tolist()), axis=1), 1.0, atol=1e-9)
    (one, every) = result.sets
    assert every.status in {"feasible", "infeasible", "rank_deficient"} and not (one.force_closure and not every.force_closure)


def test_fig2_draws_a_mesh(hand, synergies, tmp_path, monkeypatch):
    """Fig. 2's picture of a grasp of the duck: written, the same bytes on a rerun."""
    from conftest import study_closure_params, study_placement
    from synergrasp.figures.fig1_fig2_postures_grasps import figure_example_grasps
    from synergrasp.simulation.closure import simulate_object

    monkeypatch.chdir(ROOT)
    duck = GraspedObject("duck", Mesh("config/examples/meshes/duck.obj", 50.0), 0.1)
    table = simulate_object(hand, synergies, duck, study_placement(), study_closure_params(), poses=[300, 900])
    for run in ("a", "b"):
        figure_example_grasps(hand, [duck], [table], tmp_path / f"f{run}.png", tmp_path / f"f{run}.pdf", n_grasps=2)
    first = (tmp_path / "fa.png").read_bytes()
    assert len(first) > 10_000 and first == (tmp_path / "fb.png").read_bytes()


def test_a_meshs_gap_to_a_box_is_the_least_over_its_parts(tmp_path, monkeypatch):
    """One compiled call over the parts (``polytope_axes.parts_box_gap``) is the part-by-part
    least of the GJK distance, or minus the overlap where they touch, to the last bit; the
    palm's box apart, overlapping and touching."""
    from synergrasp.simulation.shapes.box import box_edges
    from synergrasp.simulation.shapes.polytope import convex_distance
    from synergrasp.simulation.shapes.polytope_axes import part_box_overlap

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    mesh = Mesh(str(_l_shape(tmp_path, "l.obj", 60.0)), 1.0)
    assert len(mesh.geometry.parts) >= 2
    rng = np.random.default_rng(11)
    half = np.array([6.0, 25.0, 15.0])
    outcomes = set()
    for _ in range(60):
        R = Rotation.random(random_state=rng).as_matrix()
        box = np.eye(4)
        box[:3, :3], box[:3, 3] = Rotation.random(random_state=rng).as_matrix(), rng.uniform(-45, 45, 3)
        corners = np.unique(np.vstack(box_edges(box, half)), axis=0)
        local = np.ascontiguousarray(corners @ R)  # the mesh at the origin, turned by R
        best, point = np.inf, np.zeros(3)
        for k in range(len(mesh.geometry.parts)):
            d, a, b, touching = convex_distance(mesh._params, k, local)
            if touching:
                d = part_box_overlap(mesh._params, k, local, np.ascontiguousarray(box[:3, :3].T @ R))
            if d < best:
                best, point = d, R @ (0.5 * (a + b))
        got, at = mesh.box_gap(R, np.zeros(3), box, half)
        assert got == best and np.array_equal(at, point)
        outcomes.add(bool(got > 0))
    assert outcomes == {True, False}


def test_the_gap_alone_is_the_segment_query_s_distance_to_the_last_bit(tmp_path, monkeypatch):
    """``polytope.segment_parts_gap`` (the closure's query: parts nearest sphere first, none
    beyond a cutoff) gives ``segment_parts``'s distance to the last bit below the cutoff, and
    at least the cutoff above it; segments crossing the L, near it and far from it."""
    from synergrasp.simulation.shapes.polytope import WORK, segment_parts, segment_parts_gap

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    mesh = Mesh(str(_l_shape(tmp_path, "l.obj", 60.0)), 1.0)
    assert len(mesh.geometry.parts) >= 2
    rng = np.random.default_rng(5)
    work = np.zeros(WORK)
    signs, cut = set(), 0
    for _ in range(300):
        p0, d = rng.uniform(-70.0, 70.0, 3), rng.normal(size=3) * rng.uniform(1.0, 40.0)
        reference = segment_parts(p0, d, mesh._params, work)[0]
        assert segment_parts_gap(p0, d, mesh._params, work) == reference
        cutoff = float(rng.uniform(0.0, 30.0))
        got = segment_parts_gap(p0, d, mesh._params, work, cutoff)
        if reference < cutoff:
            assert got == reference
        else:
            assert got >= cutoff
            cut += 1
        signs.add(bool(reference > 0))
    assert signs == {True, False} and cut > 0  # crossing and clear, both sides of the cutoff
