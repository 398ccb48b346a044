"""What grasps a hand can make: its reach, the thickest box it presses toward the palm, its
widest pinch, and from these which grasp types an object admits (docs/hand_reach.md).

Everything here is a property of the hand (its capsules, joint limits and the S1 closure path
with soft adaptation) and of the object's dimensions only: it is computed before any
placement search and reads no grasp of the study.

Per finger (``hand_reach``):

- ``reach_s1_mm``: the farthest point along the palm normal that the finger's link surfaces
  (capsule axis + radius) reach on the free closure path q_r(σ), σ_open … σ_closed;
- ``reach_any_mm``: the same over every posture within the finger's joint limits (a lattice
  of ``posture_steps`` values per joint, the limits included);
- ``press_mm`` (d_max of the finger): the largest thickness d of a slab lying on the palm
  (across the palm from its little-finger edge: the palm's whole width, and as wide as it
  lies on the palm face itself, shortened in ``length_step_mm`` steps where a link stands
  out of the face; along the palm
  from its wrist end to a far end tried at the palm's end and every ``length_step_mm``
  nearer the wrist; d thick along the palm normal, brought onto the open hand by the
  placement rule) such that, when the hand closes on it along S1
  with the study's kinematic closure (soft adaptation: a blocked link holds its chain, the
  distal joints go on flexing), one of the finger's links touches it pushing it toward the
  palm (the object's inward normal within ``angle_deg`` of −p, the palm rule's clause of
  docs/opposition.md); 0 when no slab of at least ``step_mm`` is pressed;
- ``aperture_mm`` (long fingers): the largest gap between the thumb's pad and the finger's
  pad (distance of their capsule axes less both radii) on the free closure path.

The hand's d_max is the largest ``press_mm`` of its fingers (thumb included: the palm rule
accepts a push back toward the palm from any finger); its aperture the largest of the long
fingers'. An object's thickness is its smallest own extent (for a box its shortest edge: the
thinnest it can lie on the palm at any orientation); its grasped width for a pinch the same.
Power is feasible when thickness ≤ d_max, precision when width ≤ aperture
(:func:`feasible_types`). mm, rad; palm frame.

The ``reach`` step computes it once per hand (``hand/reach.parquet``); the placement search of
every object and the ``hand_reach`` table read that file (:func:`read_hand_reach`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.hand.kinematics import FINGERS

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.closure_params import ClosureParams
    from synergrasp.simulation.shapes import Shape

__all__ = [
    "ReachParams",
    "ReachStepParams",
    "HandReachStepParams",
    "HandReach",
    "hand_reach",
    "finger_postures",
    "object_extents",
    "shape_class",
    "feasible_types",
    "path_postures",
    "palm_face_mm",
    "read_hand_reach",
]

#: Samples of the free closure path σ_open … σ_closed (as ``placement.hand_region``).
PATH_SAMPLES = 201


@dataclass(frozen=True)
class ReachParams:
    """How finely the reach is measured (config ``hand_reach``; defaults in the schema).

    posture_steps: values per joint of the lattice over the joint limits (reach in any posture)
    step_mm:       thickness step of the slab scan for d_max (mm)
    length_step_mm: the slab's far end (toward the fingers) is tried at the palm's end and
                   every this many mm nearer the wrist (mm)
    angle_deg:     a push counts as toward the palm within this angle of −p (deg; the
                   opposition rule's angle)
    """

    posture_steps: int
    step_mm: float
    angle_deg: float
    length_step_mm: float = 10.0

    @classmethod
    def from_config(cls, config: Mapping[str, Any]) -> ReachParams:
        """From a configuration or a step's part of it (``hand_reach``, ``opposition.angle_deg``)."""
        spec = config["hand_reach"]
        return cls(
            int(spec["posture_steps"]),
            float(spec["step_mm"]),
            float(config["opposition"]["angle_deg"]),
            float(spec["length_step_mm"]),
        )

    def __post_init__(self) -> None:
        if int(self.posture_steps) < 2:
            raise ValueError(f"hand_reach.posture_steps must be >= 2, got {self.posture_steps!r}")
        for name in ("step_mm", "length_step_mm"):
            if not float(getattr(self, name)) > 0:
                raise ValueError(f"hand_reach.{name} must be > 0, got {getattr(self, name)!r}")


@dataclass(frozen=True)
class ReachStepParams:
    """The ``reach`` step, once per hand: hand and synergy files, the closure settings
    (kinematic) and how finely to measure."""

    hand: str | None
    synergies: str | None
    closure: ClosureParams
    reach: ReachParams

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> ReachStepParams:
        from synergrasp.config import build, dataclass_fields
        from synergrasp.simulation.closure_params import ClosureParams

        closure = build(
            ClosureParams,
            "closure",
            **{**dataclass_fields(ClosureParams, config["closure"]), "model": "kinematic", "dynamic": None},
        )
        return cls(config["hand"], config["synergies"], closure, ReachParams.from_config(config))


@dataclass(frozen=True)
class HandReachStepParams:
    """The ``hand_reach`` step (the table and the side view): hand and synergy files, how
    finely the reach was measured, and the study's objects (drawn beside the finger)."""

    hand: str | None
    synergies: str | None
    reach: ReachParams
    objects: dict[str, Shape]

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> HandReachStepParams:
        from synergrasp.simulation.objects import GraspedObject

        objects = {name: GraspedObject.from_config(config, name, with_mass=False).shape for name in config["objects"]}
        return cls(config["hand"], config["synergies"], ReachParams.from_config(config), objects)


@dataclass(frozen=True)
class HandReach:
    """The reach table of one hand (``table_contracts.HAND_REACH``: one row per finger) and the hand's
    two numbers: d_max (mm, the thickest slab on the palm some link presses toward the palm)
    and the aperture (mm, the widest thumb-to-fingertip gap on the path)."""

    table: pd.DataFrame
    palm_face_mm: float

    @property
    def d_max_mm(self) -> float:
        return float(self.table["press_mm"].max())

    @property
    def aperture_mm(self) -> float:
        return float(np.nanmax(self.table["aperture_mm"].to_numpy(dtype=float)))


def read_hand_reach(path: str | Path, hand: Hand) -> HandReach:
    """The reach the ``reach`` step wrote for ``hand`` (its table, ``table_contracts.HAND_REACH``)."""
    from synergrasp import table_contracts

    return HandReach(table_contracts.read(table_contracts.HAND_REACH, path), palm_face_mm(hand))


def palm_face_mm(hand: Hand) -> float:
    """Where the palm's face lies along the palm normal (mm): its shapes' outermost point."""
    from synergrasp.simulation.placement import _palm_points

    return float(np.max(_palm_points(hand) @ _unit(hand.palm_normal)))


def _unit(v: Sequence[float]) -> NDArray:
    a = np.asarray(v, dtype=float)
    return a / np.linalg.norm(a)


def path_postures(hand: Hand, synergies: Synergies) -> NDArray:
    """(PATH_SAMPLES, n_joints) postures q_r(σ) of the free closure path along S1 (rad)."""
    from synergrasp.hand.synergies import SynergyPath

    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    sigma_open, sigma_closed = path.closure_range(hand.flexion_joints)
    return np.array([path.reference(s) for s in np.linspace(sigma_open, sigma_closed, PATH_SAMPLES)])


def _surface_reach(capsules, q: NDArray, rows: NDArray, normal: NDArray) -> float:
    """The farthest point along ``normal`` of the capsules ``rows`` at q (axis ends + radius)."""
    p0, p1 = capsules.segments(q)
    ends = np.concatenate([p0[rows], p1[rows]]) @ normal
    return float(np.max(ends + np.concatenate([capsules.radius[rows]] * 2)))


def finger_postures(hand: Hand, q0: NDArray, finger: int, steps: int) -> Iterator[NDArray]:
    """The postures of a lattice over one finger's joint limits (``steps`` values per joint,
    the limits included), the other joints at ``q0`` (rad); one array, changed in place."""
    joints = list(hand.finger_joints[finger])
    values = [np.linspace(hand.lower[j], hand.upper[j], steps) for j in joints]
    q = np.array(q0, dtype=float)
    for combo in itertools.product(*values):
        q[joints] = combo
        yield q


def _any_posture_reach(hand: Hand, capsules, q0: NDArray, finger: int, rows: NDArray, normal: NDArray, steps: int) -> float:
    """Largest surface reach of one finger over a lattice of its joints' limits."""
    return max(_surface_reach(capsules, q, rows, normal) for q in finger_postures(hand, q0, finger, steps))


def _slab_press(hand: Hand, synergies: Synergies, closure: ClosureParams, params: ReachParams, ceiling_mm: float) -> NDArray:
    """Per finger, the largest slab thickness (mm, multiples of ``step_mm``) that one of its
    links presses toward the palm when the hand closes on the slab lying on the palm (0: none)."""
    from dataclasses import replace

    from synergrasp.simulation.kinematic_closure import KinematicClosure
    from synergrasp.simulation.placement import _palm_points, palm_centre
    from synergrasp.simulation.shapes.box import Box

    pts = _palm_points(hand)
    normal = _unit(hand.palm_normal)
    cos = math.cos(math.radians(params.angle_deg))
    model = KinematicClosure(hand, synergies, replace(closure, model="kinematic"))
    link_finger = np.full(hand.n_links, -1)
    for f, links in enumerate(hand.finger_links):
        link_finger[list(links)] = f
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = palm_centre(hand)
    out = np.zeros(len(hand.finger_links))
    n_steps = int(math.floor(ceiling_mm / params.step_mm))
    face = float(np.max(pts @ normal))

    def placed_slab(d: float, y_end: float, z_end: float):
        slab = Box((d, y_end - float(lo[1]), z_end - float(lo[2])))
        point = np.array([centre[0], 0.5 * (y_end + float(lo[1])), 0.5 * (z_end + float(lo[2]))]) + 0.5 * d * normal
        return model.scene.bring_object(slab, np.eye(3), point, normal, model.q_open, 0.0, stop_at_point=True)

    # the slab's far end (toward the fingers): the palm's end, then every length_step_mm nearer the wrist
    ends = [float(hi[2]) - k * params.length_step_mm for k in range(int(math.floor((hi[2] - lo[2]) / params.length_step_mm)))]
    try:
        # the palm's whole width, and the widest slab from the palm's little-finger edge that lies on
        # the palm face itself (not on a link standing out of it, as the SoftHand's thumb knuckle does)
        y_end = float(hi[1])
        while placed_slab(
            params.step_mm, y_end, float(hi[2])
        ).center_mm @ normal - 0.5 * params.step_mm > face + 0.5 and y_end - params.length_step_mm > float(lo[1]):
            y_end -= params.length_step_mm
        for y_end, end in itertools.product(sorted({float(hi[1]), y_end}, reverse=True), ends):
            found = np.zeros(len(hand.finger_links))
            for k in range(n_steps, 0, -1):  # thickest first: a finger's first success is its d_max
                d = k * params.step_mm
                if np.all((found > 0) | (out >= d)):
                    break
                # from the palm's wrist end to ``end``, d thick along the normal
                result = model.grasp(placed_slab(d, y_end, end))
                if result.status != "grasp":
                    continue
                toward_palm = np.asarray(result.normals).reshape(-1, 3) @ normal <= -cos + 1e-12
                for link in np.asarray(result.links)[toward_palm]:
                    f = link_finger[int(link)]
                    if f >= 0 and found[f] == 0:
                        found[f] = d
            out = np.maximum(out, found)
    finally:
        model.close()
    return out


def hand_reach(hand: Hand, synergies: Synergies, closure: ClosureParams, params: ReachParams) -> HandReach:
    """The reach table of ``hand`` with its synergy table's S1 path (module docstring)."""
    from synergrasp.simulation.capsules import HandCapsules, segment_segment_distance

    if not np.allclose(hand.palm_normal, (1.0, 0.0, 0.0)):
        raise ValueError(
            f"{hand.source}: palm_normal: the reach needs the palm frame of docs/hand.md "
            f"(palm normal +x), got {list(hand.palm_normal)}"
        )
    capsules = HandCapsules.of(hand)
    normal = _unit(hand.palm_normal)
    path = path_postures(hand, synergies)
    face = palm_face_mm(hand)
    names = [hand.link_finger[chain[0]] for chain in hand.finger_links]
    rows_of = [np.flatnonzero(np.isin(capsules.links, list(chain))) for chain in hand.finger_links]
    reach_s1 = [max(_surface_reach(capsules, q, rows, normal) for q in path) for rows in rows_of]
    reach_any = [
        _any_posture_reach(hand, capsules, path[0], f, rows, normal, int(params.posture_steps)) for f, rows in enumerate(rows_of)
    ]
    press = _slab_press(hand, synergies, closure, params, max(reach_any) - face)
    thumb = names.index("thumb")
    pad = [int(np.flatnonzero(capsules.links == chain[-1])[0]) for chain in hand.finger_links]
    segments = [capsules.segments(q) for q in path]
    apertures = []
    for f, name in enumerate(names):
        if name == "thumb":
            apertures.append(math.nan)
            continue
        a, b = pad[thumb], pad[f]
        p0 = np.array([s[0][a] for s in segments]), np.array([s[1][a] for s in segments])
        q0 = np.array([s[0][b] for s in segments]), np.array([s[1][b] for s in segments])
        gap = segment_segment_distance(p0[0], p0[1], q0[0], q0[1]) - capsules.radius[a] - capsules.radius[b]
        apertures.append(float(np.max(gap)))
    order = {name: k for k, name in enumerate(FINGERS)}
    table = (
        pd.DataFrame(
            {
                "finger": names,
                "reach_s1_mm": reach_s1,
                "reach_any_mm": reach_any,
                "reach_s1_over_palm_mm": [r - face for r in reach_s1],
                "reach_any_over_palm_mm": [r - face for r in reach_any],
                "press_mm": press,
                "aperture_mm": apertures,
            }
        )
        .sort_values("finger", key=lambda s: s.map(order), kind="stable")
        .reset_index(drop=True)
    )
    return HandReach(table, face)


def object_extents(shape: Shape) -> NDArray:
    """The object's own extents (mm), smallest first: its own-frame bounding box (for a box,
    its edges; for a sphere, its diameter three times), from the points and radii whose
    spheres cover it (``Shape.extent``)."""
    points, radii = shape.extent(np.eye(3), np.zeros(3))
    points, radii = np.asarray(points, dtype=float).reshape(-1, 3), np.asarray(radii, dtype=float)[:, None]
    return np.sort((points + radii).max(axis=0) - (points - radii).min(axis=0))


def shape_class(shape: Shape, prismatic_aspect: float) -> str:
    """Cutkosky's shape class of an object from its shape only: ``prismatic`` when its
    longest own extent is at least ``prismatic_aspect`` times its shortest (elongated or
    flat), ``circular`` otherwise (compact: cube, sphere, short cylinder)."""
    extents = object_extents(shape)
    return "prismatic" if extents[-1] >= prismatic_aspect * extents[0] - 1e-9 else "circular"


def feasible_types(shape: Shape, reach: HandReach) -> dict[str, tuple[bool, str]]:
    """Per grasp type (power, precision), whether the hand can make it on ``shape`` and why
    (one line with the numbers): power when the object's thickness (smallest extent) is at
    most the hand's d_max, precision when its width (the same) fits the aperture."""
    thickness = float(object_extents(shape)[0])
    d_max, aperture = reach.d_max_mm, reach.aperture_mm
    return {
        "power": (
            thickness <= d_max + 1e-9,
            f"thickness {thickness:g} mm {'<=' if thickness <= d_max + 1e-9 else '>'} "
            f"d_max {d_max:g} mm (the thickest box on the palm a link presses toward the palm)",
        ),
        "precision": (
            thickness <= aperture + 1e-9,
            f"width {thickness:g} mm {'<=' if thickness <= aperture + 1e-9 else '>'} "
            f"aperture {aperture:.1f} mm (the widest thumb-to-fingertip gap on the S1 path)",
        ),
    }
