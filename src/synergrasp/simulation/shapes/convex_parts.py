"""A mesh as convex parts: its hull when it is convex, else an approximate convex decomposition.

The decomposition is V-HACD's as pybullet ships it (``pybullet.vhacd``, no package beyond
the engine the study already uses), with pybullet's parameters, written down here. It is
deterministic (the same parts for the same file on every run) and takes seconds. Its file is
named by :func:`parts_key`, the hash of the mesh file's bytes, these parameters and pybullet's
version: the workflow makes it in a job of its own (rule ``mesh_parts``,
``results/meshes/<key>.obj``, :func:`write_parts`) and hands its path to the shape (the mesh's
``parts``); outside the workflow it is made on first use and cached per user,
``$XDG_CACHE_HOME/synergrasp-meshes/<key>.obj`` (``~/.cache`` without it). The physics engine
reads the parts from a file too (``bullet_file``), cached per user likewise.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import tempfile
from collections.abc import Sequence
from importlib import metadata
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from synergrasp.simulation.shapes.mesh_file import TriangleMesh

__all__ = [
    "convex_parts",
    "is_convex",
    "cache_dir",
    "bullet_file",
    "parts_key",
    "write_parts",
    "read_parts",
    "VHACD_PARAMETERS",
    "CONVEX_RTOL",
]

#: A mesh whose volume is this close to its hull's (relatively) is convex: its hull is it.
CONVEX_RTOL = 1e-6
#: V-HACD's parameters (pybullet's defaults, fixed here so the cache key holds them).
VHACD_PARAMETERS = {
    "resolution": 1_000_000,
    "depth": 20,
    "concavity": 0.001,
    "planeDownsampling": 4,
    "convexhullDownsampling": 4,
    "alpha": 0.05,
    "beta": 0.05,
    "gamma": 0.0005,
    "pca": 0,
    "mode": 0,
    "maxNumVerticesPerCH": 64,
    "minVolumePerCH": 0.0001,
    "convexhullApproximation": 1,
}


def cache_dir() -> Path:
    """Where decompositions are kept: ``$XDG_CACHE_HOME`` or ``~/.cache``, ``synergrasp-meshes``."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "synergrasp-meshes"


def is_convex(mesh: TriangleMesh) -> bool:
    """Whether the mesh's volume is its hull's (to CONVEX_RTOL)."""
    return mesh.volume >= (1.0 - CONVEX_RTOL) * ConvexHull(mesh.vertices).volume


def parts_key(digest: str) -> str:
    """The name of a mesh's parts file (24 hex digits) from ``digest``, the sha256 of the mesh
    file's bytes: the hash of it, :data:`VHACD_PARAMETERS` and pybullet's version."""
    version = _pybullet_version()
    return hashlib.sha256(f"{digest} {sorted(VHACD_PARAMETERS.items())} pybullet {version}".encode()).hexdigest()[:24]


@functools.cache
def _pybullet_version() -> str:
    return metadata.version("pybullet")


def convex_parts(mesh: TriangleMesh, digest: str) -> list[NDArray]:
    """Vertices (k, 3) of each convex part, in the file's units: the hull's vertices of a
    convex mesh, else the parts of its decomposition (cached per user under
    :func:`parts_key` of ``digest``, the sha256 of the file's bytes)."""
    if is_convex(mesh):
        return [mesh.vertices[ConvexHull(mesh.vertices).vertices]]
    cached = cache_dir() / f"{parts_key(digest)}.obj"
    if not cached.is_file():
        _decompose(mesh, cached)
    return read_parts(cached)


def write_parts(mesh: TriangleMesh, out: Path) -> None:
    """Write the convex parts of ``mesh`` to the OBJ file ``out`` (one object per part, in the
    file's units), read back by :func:`read_parts` as :func:`convex_parts` gives them: a convex
    mesh's hull (its vertices in the mesh's order), else V-HACD's decomposition."""
    out = Path(out)
    if not is_convex(mesh):
        _decompose(mesh, out)
        return
    hull = ConvexHull(mesh.vertices)
    rank = np.full(len(mesh.vertices), -1)
    rank[hull.vertices] = np.arange(len(hull.vertices))
    out.parent.mkdir(parents=True, exist_ok=True)
    _write_obj(out, [mesh.vertices[hull.vertices]], [rank[hull.simplices]])


def _decompose(mesh: TriangleMesh, out: Path) -> None:
    import pybullet

    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out.parent) as work:
        source, parts, log = (Path(work) / name for name in ("mesh.obj", "parts.obj", "vhacd.log"))
        _write_obj(source, [mesh.vertices], [mesh.triangles])
        with _quiet():  # V-HACD prints its progress on the process's standard output
            pybullet.vhacd(str(source), str(parts), str(log), **VHACD_PARAMETERS)
        if not parts.is_file() or not read_parts(parts):
            raise RuntimeError(f"the convex decomposition wrote no parts (its log: {log.read_text()[-500:]!r})")
        os.replace(parts, out)  # atomic: a concurrent job reads the whole file or none


class _quiet:
    """Send what the process writes on file descriptors 1 and 2 to /dev/null meanwhile."""

    def __enter__(self) -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        self.saved = [os.dup(1), os.dup(2)]
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        os.close(null)

    def __exit__(self, *exc: object) -> None:
        for fd, saved in zip((1, 2), self.saved):
            os.dup2(saved, fd)
            os.close(saved)


def read_parts(path: Path) -> list[NDArray]:
    """The vertices of each object (``o``) of an OBJ file with at least 4 not in one plane."""
    parts: list[list[list[float]]] = []
    for line in path.read_text().splitlines():
        if line.startswith("o ") or (line.startswith("v ") and not parts):
            parts.append([])
        if line.startswith("v "):
            parts[-1].append([float(x) for x in line.split()[1:4]])
    out = []
    for vertices in parts:
        points = np.asarray(vertices, dtype=float).reshape(-1, 3)
        try:
            out.append(points[ConvexHull(points).vertices])
        except (QhullError, ValueError):  # fewer than 4 points or flat: no volume
            continue
    return out


def _write_obj(path: Path, vertices: Sequence[NDArray], triangles: Sequence[NDArray]) -> None:
    lines, offset = [], 1
    for k, (v, t) in enumerate(zip(vertices, triangles)):
        lines.append(f"o part{k}")
        lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
        lines += [f"f {a} {b} {c}" for a, b, c in (t + offset).tolist()]
        offset += len(v)
    path.write_text("\n".join(lines) + "\n")


def bullet_file(parts_mm: Sequence[NDArray]) -> Path:
    """An OBJ file of the convex parts (mm) for the physics engine, which makes one convex hull
    of each object of the file; named by the parts' own hash, so that it is never stale (the
    engine keeps what it read by file name)."""
    digest = hashlib.sha256(b"".join(np.ascontiguousarray(p, dtype=float).tobytes() for p in parts_mm)).hexdigest()
    path = cache_dir() / f"bullet-{digest[:24]}.obj"
    if not path.is_file():
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".obj")
        os.close(fd)
        _write_obj(Path(tmp), parts_mm, [ConvexHull(p).simplices for p in parts_mm])
        os.replace(tmp, path)
    return path
