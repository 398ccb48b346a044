"""The study's derived values, each stated once: what every step's ``from_config`` and the
workflow read instead of working them out again from the configuration.

- an object's effective placement: the global ``placement`` overlaid with the object's own
  ``placement`` (config/README.md);
- an object's weight: ``mass_kg`` × ``mechanics.g_m_per_s2``, N;
- the hand–object friction μ (``mechanics.mu``);
- an object's grasp type: the top-level ``grasp_type`` when set (every object's), else the
  object's own ``grasp_type`` (docs/opposition.md).

A step is handed only the part of the configuration it reads (``synergrasp.steps.step_config``),
so every value here is resolved from whatever part it is given: a key the part does not hold
resolves to None (``StudyObject``) or is an error naming it (the functions). The synergy sets'
ids are ``synergrasp.ids``'.

Layer: above ``config`` and ``ids`` (no stage); every stage and the workflow may read it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from synergrasp.config import overlay

__all__ = ["StudyObject", "study_object", "study_objects", "effective_placement", "weight_N", "friction_mu", "grasp_type"]


def effective_placement(config: Mapping[str, Any], obj: str) -> dict[str, Any]:
    """Object ``obj``'s placement: the global ``placement`` overlaid with its own override."""
    return overlay(config["placement"], config["objects"][obj].get("placement"))


def weight_N(config: Mapping[str, Any], obj: str) -> float:
    """Object ``obj``'s weight m·g (N) from its ``mass_kg`` and ``mechanics.g_m_per_s2``."""
    return float(config["objects"][obj]["mass_kg"]) * float(config["mechanics"]["g_m_per_s2"])


def grasp_type(config: Mapping[str, Any], obj: str) -> str:
    """Object ``obj``'s grasp type: the top-level ``grasp_type`` when set, else its own."""
    return str(config.get("grasp_type") or config["objects"][obj]["grasp_type"])


def friction_mu(config: Mapping[str, Any]) -> float:
    """The hand–object Coulomb friction coefficient μ (``mechanics.mu``)."""
    return float(config["mechanics"]["mu"])


@dataclass(frozen=True)
class StudyObject:
    """One object of the study as the steps read it: its ``shape`` block (as configured), its
    mass (kg) and weight (N), and its effective placement; None where the part of the
    configuration resolved does not hold the keys."""

    name: str
    shape: Mapping[str, Any] | None
    mass_kg: float | None
    weight_N: float | None
    placement: Mapping[str, Any] | None


def study_object(config: Mapping[str, Any], obj: str) -> StudyObject:
    """Object ``obj`` of ``config`` (a whole configuration or a step's part of it) resolved."""
    spec = config["objects"][obj]
    mass = float(spec["mass_kg"]) if "mass_kg" in spec else None
    g = (config.get("mechanics") or {}).get("g_m_per_s2")
    return StudyObject(
        name=obj,
        shape=spec.get("shape"),
        mass_kg=mass,
        weight_N=weight_N(config, obj) if mass is not None and g is not None else None,
        placement=effective_placement(config, obj) if "placement" in config else None,
    )


def study_objects(config: Mapping[str, Any]) -> dict[str, StudyObject]:
    """Every object of ``config`` resolved, in the configuration's order."""
    return {name: study_object(config, name) for name in config["objects"]}
