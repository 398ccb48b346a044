"""Objects drawn from pybullet's 1,000 procedurally generated meshes (docs/random_objects.md).

The configuration's ``random_objects`` block (config/examples/random_objects.yaml) names how
many objects to draw, a seed, the range of their longest side and their mass. The meshes
``random_urdfs/NNN/NNN.obj`` are read where the installed ``pybullet_data`` package holds
them (not copied), each checked against the sha256 of a shipped manifest. The rule:

1. ``numpy.random.default_rng(seed)`` draws ``n_objects`` distinct indices of 0…999 (sorted),
   then one longest side per object, uniform in ``longest_side_mm`` (mm);
2. each mesh is scaled (mm per file unit) so that the longest side of its axis-aligned
   bounding box is that length;
3. an object whose file is missing, differs from the manifest, cannot be read as a closed
   mesh or is degenerate (no volume) is left out of ``objects`` with the reason, and the
   others go on; :func:`drawn_objects` lists every drawn object with its reason.

Objects are named ``rand_NNN`` (NNN the mesh's index).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, MutableMapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from synergrasp.config import ConfigError, block_problems
from synergrasp.simulation.shapes.mesh_file import MeshFileError, checked_mesh

__all__ = ["DrawnObject", "drawn_objects", "random_objects_problems", "add_random_objects", "left_out", "N_MESHES"]

#: Meshes in pybullet_data/random_urdfs.
N_MESHES = 1000


@dataclass(frozen=True)
class DrawnObject:
    """One drawn mesh: name, index, path (where this machine's ``pybullet_data`` holds it),
    scale (mm per unit; NaN if unread), longest side (mm), why it is left out ('' if it is
    studied) and ``source``, its path within the package (``pybullet_data/random_urdfs/…``),
    which the tables and the reasons name so that they read the same from every checkout."""

    name: str
    index: int
    path: str
    scale: float
    longest_side_mm: float
    problem: str
    source: str

    def row(self) -> dict[str, Any]:
        """The drawn-meshes table's row: the mesh named by its ``source``."""
        return {**vars(self), "path": self.source}


def _manifest(path: str | Path) -> dict[str, str]:
    """``sha256sum`` lines -> {relative path: digest}."""
    out = {}
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        if line.strip():
            digest, name = line.split(maxsplit=1)
            out[name.lstrip("*").strip()] = digest
    return out


def _data_path() -> Path:
    import pybullet_data

    return Path(pybullet_data.getDataPath())


def _check(path: Path, expected: str | None, longest_mm: float) -> tuple[float, str]:
    """(scale, problem) of one mesh file."""
    if not path.is_file():
        return float("nan"), f"file missing: {path}"
    data = path.read_bytes()
    if expected is None:
        return float("nan"), "not in the sha256 manifest"
    if hashlib.sha256(data).hexdigest() != expected:
        return float("nan"), "sha256 differs from the manifest"
    try:
        mesh = checked_mesh(path)
    except MeshFileError as err:
        return float("nan"), f"mesh cannot be read: {err}"
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    if not extent > 0 or not mesh.volume > 1e-9 * extent**3:
        return float("nan"), "degenerate mesh (no extent or no volume)"
    return longest_mm / extent, ""


def drawn_objects(spec: Mapping[str, Any], root: str | Path = ".", manifest: str | Path | None = None) -> list[DrawnObject]:
    """Every object the ``random_objects`` block draws, in index order; the manifest
    ``manifest``, else the block's ``sha256_file`` relative to ``root`` (the project's root)."""
    rng = np.random.default_rng(int(spec["seed"]))
    n = int(spec["n_objects"])
    indices = np.sort(rng.choice(N_MESHES, size=n, replace=False))
    lo, hi = (float(v) for v in spec["longest_side_mm"])
    longest = rng.uniform(lo, hi, size=n)
    digests = _manifest(manifest if manifest is not None else Path(root) / spec["sha256_file"])
    base = _data_path()
    out = []
    for index, side in zip(indices.tolist(), longest.tolist()):
        rel = f"random_urdfs/{index:03d}/{index:03d}.obj"
        scale, problem = _check(base / rel, digests.get(rel), side)
        source = f"pybullet_data/{rel}"
        problem = problem.replace(str(base / rel), source)
        out.append(DrawnObject(f"rand_{index:03d}", index, str(base / rel), scale, side, problem, source))
    return out


def left_out(spec: Mapping[str, Any] | None, manifest: Sequence[str | Path]) -> list[tuple[str, str]]:
    """(name, reason) of every drawn mesh left out of the study (none without a block);
    ``manifest``: the block's sha256 file, as the workflow's input (zero or one path)."""
    if not spec:
        return []
    return [(d.name, d.problem) for d in drawn_objects(spec, manifest=manifest[0]) if d.problem]


def random_objects_problems(spec: Any, root: str | Path = ".") -> list[str]:
    """What keeps a ``random_objects`` block from being drawn, one line each naming
    ``random_objects.<key>``, before any number of it is used: the schema's checks of the
    block alone (``config.block_problems``: every key given, whole numbers, ranges), its
    ``longest_side_mm`` in order, and its manifest a readable ``sha256sum`` file (relative to
    ``root``)."""
    problems = block_problems("random_objects", spec)
    if not isinstance(spec, Mapping) or any("'random_objects'" in p for p in problems):
        return problems  # not a mapping, or a key missing or unknown

    def fine(key: str) -> bool:
        return key in spec and not any(f"'random_objects.{key}'" in p for p in problems)

    if fine("longest_side_mm") and spec["longest_side_mm"][1] < spec["longest_side_mm"][0]:
        problems.append(
            f"config error at 'random_objects.longest_side_mm': {spec['longest_side_mm']} is reversed; "
            "give [shortest, longest] (mm)"
        )
    if not fine("sha256_file"):
        return problems
    manifest = Path(root) / spec["sha256_file"]
    try:
        _manifest(manifest)
    except OSError as err:
        problems.append(
            f"config error at 'random_objects.sha256_file': '{manifest}' cannot be read "
            f"({'is a folder' if manifest.is_dir() else err.strerror or err}); a sha256sum manifest "
            "relative to the project's root is required"
        )
    except (ValueError, UnicodeDecodeError):
        problems.append(
            f"config error at 'random_objects.sha256_file': '{manifest}' is not a sha256sum manifest "
            "(lines of '<digest>  <path>')"
        )
    return problems


def add_random_objects(config: MutableMapping[str, Any], root: str | Path = ".") -> list[DrawnObject]:
    """Add the studied objects of ``config["random_objects"]`` (if any) to ``config["objects"]``
    (a mesh shape, the block's mass); return every drawn object. ConfigError, before anything
    is drawn or added, with every :func:`random_objects_problems` and every object of the
    configuration named like a drawn one (one line each, naming both)."""
    spec = config.get("random_objects")
    if spec is None:
        return []
    problems = random_objects_problems(spec, root)
    if problems:
        raise ConfigError("\n".join(problems))
    drawn = drawn_objects(spec, root)
    objects = config.get("objects")
    objects = {} if not isinstance(objects, MutableMapping) else objects
    clashes = [d.name for d in drawn if not d.problem and objects.get(d.name) is not None]
    if clashes:
        raise ConfigError(
            "\n".join(
                f"config error at 'objects.{name}': an object of the configuration has the name of an object "
                f"random_objects draws ({name}); rename the object or change random_objects.seed"
                for name in clashes
            )
        )
    for obj in drawn:
        if not obj.problem:
            objects[obj.name] = {"shape": {"mesh": {"path": obj.path, "scale": obj.scale}}, "mass_kg": float(spec["mass_kg"])}
    config["objects"] = objects
    return drawn
