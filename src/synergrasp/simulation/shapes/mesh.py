"""A mesh from an OBJ or STL file: its hull if it is convex, else its convex parts (mm).

``path``: the file, absolute or relative to the working directory (the project's root for
the workflow, which runs there); ``scale``: mm per unit of the file; ``parts``: the file of its
convex parts (``convex_parts.write_parts``), which the workflow makes in a job of its own
(rule ``mesh_parts``, ``results/meshes/``) and names here; without it the parts are made on
first use and cached per user (``convex_parts.convex_parts``). Building a ``Mesh`` reads and
checks the file only (a closed manifold bounding a volume): its parts and everything made
from them are made when a query first needs them, so that checking a configuration does no
decomposition (docs/shapes.md). The own frame is the
file's axes with the origin moved to the centroid of the solid the mesh bounds (its centre
of mass at uniform density). The object *is* the convex parts (``convex_parts``): every
query, the physics engine and the pictures use them. Every query is exact for them
(``polytope``): distances by GJK, normals from the faces (docs/shapes.md).
"""

from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from synergrasp.simulation.shapes import Shape, ShapeError, positive_length
from synergrasp.simulation.shapes.box import box_edges
from synergrasp.simulation.shapes.mesh_file import MeshFileError, checked_mesh

# scipy's sparse graphs and hulls and the compiled polytope queries are imported where a mesh
# uses them: the shapes package is imported by every Snakemake start (the configuration's
# checks), for most configurations without a mesh, and they were a third of a dry run's CPU.

__all__ = ["Mesh", "MeshGeometry"]

#: Neighbouring faces meeting at less than this angle (deg) are one region of the pictures.
_CREASE_DEG = 30.0


@dataclass(frozen=True)
class MeshGeometry:
    """The convex parts of a mesh in mm, centred (``Mesh``): ``parts`` vertices (k, 3) each,
    ``planes`` (f, 4) each (outward unit normal, offset b: n·x ≤ b inside), ``region`` a label
    per face over all parts (faces meeting at less than 30° share one), ``convex`` whether
    the mesh was its own hull, ``size`` (3,) the extent along its own axes."""

    parts: tuple[NDArray, ...]
    planes: tuple[NDArray, ...]
    region: NDArray
    convex: bool
    size: NDArray

    @property
    def vertices(self) -> NDArray:
        return np.concatenate(self.parts)


@functools.lru_cache(maxsize=32)
def _geometry(path: str, stamp: tuple[int, int], scale: float, parts: str) -> MeshGeometry:
    """The geometry of the file at ``path`` (``stamp``: its change time and size, so that an
    edited file is read again) scaled to mm; its convex parts read from the file ``parts``, or
    made (and cached per user) where it is ''."""
    from scipy.spatial import ConvexHull

    from synergrasp.simulation.shapes.convex_parts import convex_parts, is_convex, read_parts

    del stamp
    mesh = checked_mesh(path)
    if parts:
        try:
            file_parts = read_parts(Path(parts))
        except OSError as err:
            raise ShapeError(
                f"parts: {parts!r} cannot be read ({err.strerror or err}); the workflow's rule mesh_parts makes it"
            ) from None
    else:
        file_parts = convex_parts(mesh, hashlib.sha256(Path(path).read_bytes()).hexdigest())
    parts, planes, regions, first = [], [], [], 0
    for part in file_parts:
        vertices = np.ascontiguousarray((part - mesh.centroid) * scale)
        hull = ConvexHull(vertices)
        equations = np.c_[hull.equations[:, :3], -hull.equations[:, 3]]
        unique, face_of = np.unique(np.round(equations, 9), axis=0, return_inverse=True)
        planes.append(np.ascontiguousarray(equations[[int(np.flatnonzero(face_of == f)[0]) for f in range(len(unique))]]))
        labels = _regions(hull, face_of.reshape(-1), len(unique))
        regions.append(labels + first)
        first += int(labels.max()) + 1
        parts.append(vertices)
    return MeshGeometry(
        tuple(parts),
        tuple(planes),
        np.concatenate(regions).astype(np.int64),
        is_convex(mesh),
        np.ptp(np.concatenate(parts), axis=0),
    )


def _regions(hull: Any, face_of: NDArray, n_faces: int) -> NDArray:
    """A label per face (plane) of a hull (a scipy ``ConvexHull``): faces whose triangles
    neighbour at less than the crease angle are joined."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    cos = math.cos(math.radians(_CREASE_DEG))
    rows, cols = [], []
    for tri, neighbours in enumerate(hull.neighbors):
        for other in neighbours:
            if hull.equations[tri, :3] @ hull.equations[other, :3] >= cos:
                rows.append(face_of[tri])
                cols.append(face_of[other])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_faces, n_faces))
    return connected_components(graph, directed=False)[1]


@dataclass(frozen=True)
class Mesh(Shape):
    """A mesh read from ``path`` (OBJ or STL), ``scale`` mm per unit of the file, its convex
    parts read from ``parts`` where given (module docstring)."""

    path: str
    scale: float
    parts: str = ""

    kind: ClassVar[str] = "mesh"
    kernel_code: ClassVar[int] = 3

    def __post_init__(self) -> None:
        scale = positive_length("scale", self.scale, "a finite positive number of mm per unit of the file")
        if not isinstance(self.path, str) or not self.path:
            raise ShapeError(f"path: {self.path!r} is not allowed; the path of an OBJ or STL file is required")
        if not isinstance(self.parts, str):
            raise ShapeError(f"parts: {self.parts!r} is not allowed; the path of the mesh's convex parts is required")
        file = Path(self.path)
        try:
            stat = file.stat()
            key = (str(file.resolve()), (stat.st_mtime_ns, stat.st_size))
            mesh = checked_mesh(file)
        except FileNotFoundError:
            raise ShapeError(
                f"path: {self.path!r} does not exist (relative paths are read from the working directory, {Path.cwd()})"
            ) from None
        except (MeshFileError, OSError) as err:
            raise ShapeError(f"path: {err}") from None
        object.__setattr__(self, "scale", scale)
        object.__setattr__(self, "_file", key)
        object.__setattr__(self, "_file_radius_mm", scale * float(np.linalg.norm(mesh.vertices - mesh.centroid, axis=1).max()))
        object.__setattr__(self, "_faces", {})  # (part, plane) -> its face polygon packed (normals_near)
        object.__setattr__(self, "_corners", {})  # a box's (pose, half extents) -> its corners (box_gap)

    @functools.cached_property
    def geometry(self) -> MeshGeometry:
        """Its convex parts in mm and what is made of them (made on first use)."""
        return _geometry(*self._file, self.scale, self.parts)

    @functools.cached_property
    def _params(self) -> NDArray:
        from synergrasp.simulation.shapes.polytope import pack_parts

        params = pack_parts(list(zip(self.geometry.parts, self.geometry.planes)))
        params.setflags(write=False)
        return params

    @functools.cached_property
    def _every(self) -> NDArray:
        return self.geometry.vertices

    @functools.cached_property
    def _radius(self) -> float:
        return float(np.linalg.norm(self._every, axis=1).max())

    @functools.cached_property
    def _hull(self) -> NDArray:
        from scipy.spatial import ConvexHull

        return self._every[ConvexHull(self._every).vertices]

    @functools.cached_property
    def _landmarks(self) -> NDArray:
        # the parts' vertices and centroids: a turn that maps the vertices onto themselves but
        # the parts onto other places (two wedges of a bow-tie) moves a centroid
        return np.vstack([self._every, [np.mean(part, axis=0) for part in self.geometry.parts]])

    @property
    def bounding_radius_mm(self) -> float:
        return self._radius

    @property
    def across_mm(self) -> float:
        # the file's vertices about its centroid: no decomposition needed (the parts' differ a little)
        return 2.0 * self._file_radius_mm

    @property
    def label(self) -> str:
        return f"mesh, {' × '.join(f'{v:.0f}' for v in self.geometry.size)} mm"

    def surface_point(self, point: NDArray, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        from synergrasp.simulation.shapes.polytope import point_parts

        local = rotation.T @ (np.asarray(point, dtype=float) - center)
        _, near, normal = point_parts(np.ascontiguousarray(local), self._params)
        n = rotation @ normal
        return rotation @ near + center, n / np.linalg.norm(n)

    def gap(self, points: NDArray, rotation: NDArray, center: NDArray) -> NDArray:
        from synergrasp.simulation.shapes.polytope import points_gap

        local = (np.asarray(points, dtype=float).reshape(-1, 3) - center) @ rotation
        return points_gap(np.ascontiguousarray(local), self._params).reshape(np.shape(points)[:-1])

    def samples(self, rotation: NDArray, center: NDArray) -> NDArray:
        # the vertices of its hull: those touching a flat palm face span the contact patch
        return self._hull @ rotation.T + center

    def normals_near(self, point: NDArray, rotation: NDArray, center: NDArray, reach_mm: float) -> list[NDArray]:
        from synergrasp.simulation.shapes.polytope import convex_distance, pack_parts

        local = rotation.T @ (np.asarray(point, dtype=float) - center)
        out = []
        for k, (vertices, planes) in enumerate(zip(self.geometry.parts, self.geometry.planes)):
            for j in np.flatnonzero(np.abs(planes[:, :3] @ local - planes[:, 3]) <= reach_mm):  # the planes in reach
                n, b = planes[j, :3], planes[j, 3]
                face_params = self._faces.get((k, j))
                if face_params is None:  # the face polygon, packed once per shape
                    face = vertices[np.abs(vertices @ n - b) <= 1e-6 * max(self.geometry.size)]
                    face_params = self._faces[k, j] = pack_parts([(np.ascontiguousarray(face), np.zeros((0, 4)))])
                if convex_distance(face_params, 0, local[None])[0] <= reach_mm:
                    out.append(-(rotation @ n))
        return out

    def box_gap(self, rotation: NDArray, center: NDArray, box_pose: NDArray, box_half: NDArray) -> tuple[float, NDArray]:
        from synergrasp.simulation.shapes.polytope_axes import parts_box_gap

        key = (box_pose.tobytes(), np.asarray(box_half).tobytes())
        corners = self._corners.get(key)
        if corners is None:  # the box's corners, once per box (the palm's boxes do not move)
            corners = self._corners[key] = np.unique(np.vstack(box_edges(box_pose, box_half)), axis=0)
        local = np.ascontiguousarray((corners - center) @ rotation)
        best, a, b = parts_box_gap(self._params, local, np.ascontiguousarray(box_pose[:3, :3].T @ rotation))
        if not best < np.inf:
            return float(best), np.asarray(center, dtype=float).copy()
        return float(best), rotation @ (0.5 * (a + b)) + center

    def same_region(self, rotation_a: NDArray, center_a: NDArray, rotation_b: NDArray, center_b: NDArray) -> bool:
        # a symmetry maps the parts' vertices and centroids onto themselves (none declared: found or not)
        from scipy.spatial import cKDTree

        tol = 1e-9 * max(self.geometry.size) + 1e-12
        a, b = self._landmarks @ rotation_a.T + center_a, self._landmarks @ rotation_b.T + center_b
        return bool(cKDTree(b).query(a)[0].max() <= tol and cKDTree(a).query(b)[0].max() <= tol)

    def collision_geometry(self) -> tuple[str, dict[str, Any]]:
        return "convex_parts", {"parts_mm": self.geometry.parts}

    def ray_hits(self, origins: NDArray, direction: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        from synergrasp.simulation.shapes.polytope_axes import ray_parts

        o = np.asarray(origins, dtype=float)
        d = np.broadcast_to(np.asarray(direction, dtype=float), o.shape).reshape(-1, 3)
        flat = np.ascontiguousarray(o.reshape(-1, 3))
        t, normal, face = np.full(len(flat), np.inf), np.zeros((len(flat), 3)), np.full(len(flat), -1, np.int64)
        groups: dict[bytes, list[int]] = {}  # rows by direction: one (a picture's) or a few (closure's probes)
        for i, u in enumerate(d):
            groups.setdefault(u.tobytes(), []).append(i)
        for rows in groups.values():
            t[rows], normal[rows], face[rows] = ray_parts(
                flat[rows], np.ascontiguousarray(d[rows[0]]), self._params, self.geometry.region
            )
        return t.reshape(o.shape[:-1]), normal.reshape(o.shape), face.reshape(o.shape[:-1])

    def extent(self, rotation: NDArray, center: NDArray) -> tuple[NDArray, NDArray]:
        return self._hull @ rotation.T + center, np.zeros(len(self._hull))

    def own_mesh(self) -> tuple[NDArray, NDArray]:
        from synergrasp.simulation.shapes.surface import hull_mesh, merge_meshes

        return merge_meshes([hull_mesh(part) for part in self.geometry.parts])  # the object is its convex parts
