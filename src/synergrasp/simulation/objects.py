"""The grasped objects: boxes with a name, edge lengths (mm) and a mass (kg)."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["Box", "ObjectError", "boxes_from_config", "STUDY_BOXES"]

_NAME = re.compile(r"[A-Za-z0-9_]+")
# Keys of an object's config entry; "placement" belongs to the closure (per-object
# override of the hand/object placement) and is ignored here.
_KEYS = ("name", "size_mm", "mass_kg")
_IGNORED = ("placement",)


class ObjectError(ValueError):
    """An object description is invalid; the message names the object and the field."""


@dataclass(frozen=True)
class Box:
    """A box-shaped object.

    Attributes
    ----------
    name : usable in file paths ([A-Za-z0-9_]+).
    size_mm : (3,) edge lengths along the box's own x, y, z axes, mm.
    mass_kg : mass, kg.
    """

    name: str
    size_mm: NDArray[np.float64]
    mass_kg: float

    def __post_init__(self) -> None:
        _check_name(self.name)
        size = _check_size(self.name, self.size_mm)
        mass = _check_mass(self.name, self.mass_kg)
        object.__setattr__(self, "size_mm", size)
        object.__setattr__(self, "mass_kg", mass)

    @property
    def half_extents_mm(self) -> NDArray[np.float64]:
        """(3,) half edge lengths, mm."""
        return self.size_mm / 2.0

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Box) and self.name == other.name and self.mass_kg == other.mass_kg
                and bool(np.array_equal(self.size_mm, other.size_mm)))

    def __hash__(self) -> int:
        return hash((self.name, tuple(self.size_mm.tolist()), self.mass_kg))


def _check_name(name: Any) -> None:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ObjectError(f"object {name!r}: field 'name' is not allowed; names must match "
                          "[A-Za-z0-9_]+ (letters, digits, '_'), as they become file-path components")


def _check_size(name: str, size: Any) -> NDArray[np.float64]:
    try:
        values = [float(v) for v in size]
    except (TypeError, ValueError):
        values = None
    if values is None or len(values) != 3 or not all(math.isfinite(v) and v > 0 for v in values):
        raise ObjectError(f"object '{name}': field 'size_mm' is {size!r}; three finite positive edge "
                          "lengths in mm are required")
    out = np.array(values)
    out.setflags(write=False)
    return out


def _check_mass(name: str, mass: Any) -> float:
    try:
        value = float(mass)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(mass, bool) or not (math.isfinite(value) and value > 0):
        raise ObjectError(f"object '{name}': field 'mass_kg' is {mass!r}; a finite positive mass in kg "
                          "is required")
    return value


def boxes_from_config(objects: Iterable[Mapping[str, Any]]) -> tuple[Box, ...]:
    """Boxes from config entries ``{name, size_mm: [a, b, c], mass_kg}``.

    A ``placement`` key (per-object placement override, used by the closure) is allowed
    and ignored here. Raises :class:`ObjectError` naming the object and the field for a
    bad name, size, mass, missing or unknown key, or a duplicated name.
    """
    boxes: list[Box] = []
    for entry in objects:
        if not isinstance(entry, Mapping):
            raise ObjectError(f"object entry {entry!r}: must be a mapping with keys {list(_KEYS)}")
        name = entry.get("name")
        _check_name(name)
        missing = [k for k in _KEYS if k not in entry]
        unknown = sorted(k for k in entry if k not in _KEYS + _IGNORED)
        if missing or unknown:
            raise ObjectError(f"object '{name}': missing fields {missing}, unknown fields {unknown}; "
                              f"allowed fields: {list(_KEYS + _IGNORED)}")
        if any(b.name == name for b in boxes):
            raise ObjectError(f"object '{name}': field 'name' is duplicated; names must be unique")
        boxes.append(Box(name, entry["size_mm"], entry["mass_kg"]))
    return tuple(boxes)


STUDY_BOXES: tuple[Box, ...] = boxes_from_config([
    {"name": "obj1", "size_mm": [30, 30, 30], "mass_kg": 1.0},    # precision, circular
    {"name": "obj2", "size_mm": [30, 60, 60], "mass_kg": 1.0},    # precision, prismatic
    {"name": "obj3", "size_mm": [60, 60, 60], "mass_kg": 1.0},    # power, circular
    {"name": "obj4", "size_mm": [100, 60, 100], "mass_kg": 1.0},  # power, prismatic
])
"""The four boxes of the study (Averta et al. 2018), all 1 kg."""
