"""The grasped objects: a name, a shape (``synergrasp.simulation.shapes``) and a mass (kg)."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from collections.abc import Mapping
from typing import Any

from synergrasp.config import ConfigError, build
from synergrasp.resolved import study_object
from synergrasp.simulation.shapes import Shape, ShapeError, shape_from_config

__all__ = ["GraspedObject", "ObjectError", "object_problems", "object_warnings"]

_NAME = re.compile(r"[A-Za-z0-9_]+")


class ObjectError(ValueError):
    """An object description is invalid; the message names the object and the field."""


@dataclass(frozen=True)
class GraspedObject:
    """An object the hand grasps.

    Attributes
    ----------
    name : usable in file paths ([A-Za-z0-9_]+).
    shape : its geometry (a box, ...), in its own frame, mm.
    mass_kg : mass, kg; None where it is not given (a step that does not read it).
    weight_N : its weight m·g, N (``synergrasp.resolved``); None likewise.

    Built from the configuration by :meth:`from_config`.
    """

    name: str
    shape: Shape
    mass_kg: float | None = None
    weight_N: float | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)
        if not isinstance(self.shape, Shape):
            raise ObjectError(
                f"object '{self.name}': field 'shape' must be a shape (synergrasp.simulation.shapes), got {self.shape!r}"
            )
        object.__setattr__(self, "mass_kg", _check_mass(self.name, self.mass_kg))

    @classmethod
    def from_config(cls, config: Mapping[str, Any], name: str, with_mass: bool = True) -> GraspedObject:
        """The object ``name`` of the configuration; without a mass and a weight (None) where
        the step does not read them (``with_mass`` false)."""
        spec = config["objects"][name]
        try:
            shape = shape_from_config(spec["shape"], f"objects.{name}.shape")
        except ShapeError as err:
            raise ConfigError(f"config error at {err}") from None
        if not with_mass:
            return build(cls, f"objects.{name}", name=name, shape=shape)
        resolved = study_object(config, name)
        return build(cls, f"objects.{name}", name=name, shape=shape, mass_kg=spec["mass_kg"], weight_N=resolved.weight_N)


def _check_name(name: Any) -> None:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ObjectError(
            f"object {name!r}: field 'name' is not allowed; names must match "
            "[A-Za-z0-9_]+ (letters, digits, '_'), as they become file-path components"
        )


def _check_mass(name: str, mass: Any) -> float | None:
    if mass is None:
        return None
    try:
        value = float(mass)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(mass, bool) or not (math.isfinite(value) and value > 0):
        raise ObjectError(f"object '{name}': field 'mass_kg' is {mass!r}; a finite positive mass in kg is required")
    return value


def object_problems(config: Mapping[str, Any]) -> list[str]:
    """What the schema cannot check of a complete configuration's objects: each shape's own
    relations (one line per problem, naming the key), checked before any job runs."""
    problems = []
    for name, spec in config["objects"].items():
        try:
            shape_from_config(spec["shape"], f"objects.{name}.shape")
        except ShapeError as err:
            problems.append(f"config error at {err}")
    return problems


#: Sizes a hand can close on (mm, across the object: twice its bounding radius); the shipped
#: hand is about 190 mm long and its fingers close to a few mm. Far outside: a warning.
GRASPABLE_ACROSS_MM = (1.0, 1000.0)


def object_warnings(config: Mapping[str, Any]) -> list[str]:
    """Objects whose size is far from what a hand grasps (a mesh in metres at ``scale: 1``, or
    a scale off by 10^6), one line each naming the key; such an object would only show as
    never graspable. Shapes that cannot be built are :func:`object_problems`'."""
    warnings = []
    lo, hi = GRASPABLE_ACROSS_MM
    for name, spec in config["objects"].items():
        where = f"objects.{name}.shape"
        try:
            across = shape_from_config(spec["shape"], where).across_mm
        except ShapeError:
            continue
        if not lo <= across <= hi:
            kind = next(iter(spec["shape"]))
            hint = (
                f"; sizes are in mm: a file in metres needs {where}.mesh.scale: 1000" if kind == "mesh" else "; sizes are in mm"
            )
            warnings.append(f"{where}: {across:.3g} mm across, far from what a hand grasps ({lo:g} to {hi:g} mm){hint}")
    return warnings
