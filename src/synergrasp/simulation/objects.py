"""The grasped objects: boxes with a name, edge lengths (mm) and a mass (kg)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from synergrasp.config import build

__all__ = ["Box", "ObjectError"]

_NAME = re.compile(r"[A-Za-z0-9_]+")


class ObjectError(ValueError):
    """An object description is invalid; the message names the object and the field."""


@dataclass(frozen=True)
class Box:
    """A box-shaped object.

    Attributes
    ----------
    name : usable in file paths ([A-Za-z0-9_]+).
    size_mm : (3,) edge lengths along the box's own x, y, z axes, mm.
    mass_kg : mass, kg; None where it is not given (a step that does not read it).

    Built from the configuration by :meth:`from_config`.
    """

    name: str
    size_mm: NDArray[np.float64]
    mass_kg: float | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)
        size = _check_size(self.name, self.size_mm)
        mass = _check_mass(self.name, self.mass_kg)
        object.__setattr__(self, "size_mm", size)
        object.__setattr__(self, "mass_kg", mass)

    @classmethod
    def from_config(cls, config: Mapping[str, Any], name: str, with_mass: bool = True) -> Box:
        """The object ``name`` of the configuration; without a mass (None) where the step
        does not read it (``with_mass`` false)."""
        spec = config["objects"][name]
        return build(cls, f"objects.{name}", name=name, size_mm=spec["size_mm"],
                     mass_kg=spec["mass_kg"] if with_mass else None)

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


def _check_mass(name: str, mass: Any) -> float | None:
    if mass is None:
        return None
    try:
        value = float(mass)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(mass, bool) or not (math.isfinite(value) and value > 0):
        raise ObjectError(f"object '{name}': field 'mass_kg' is {mass!r}; a finite positive mass in kg "
                          "is required")
    return value
