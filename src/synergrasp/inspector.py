"""One grasp in full: the closure at one pose, the optimisation for chosen synergy sets, the
quality indices (docs/inspector.md). The front door is :func:`inspect_grasp`; the console
command ``synergrasp grasp`` (``synergrasp.cli``) prints its result.

Units: mm, N, N·mm, deg for the pose; palm frame. Top layer: it runs the simulation and the
optimisation stages as the workflow's steps do, from the same configuration.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from synergrasp.ids import set_id, set_name
from synergrasp.optimisation.quality import GraspQuality, grasp_quality
from synergrasp.steps import RESULTS

__all__ = [
    "InspectionError",
    "searched_target",
    "object_closure",
    "BlockingContact",
    "SetResult",
    "GraspInspection",
    "parse_sets",
    "default_sets",
    "inspect_grasp",
    "grasp_picture",
    "grasp_view",
]


class InspectionError(ValueError):
    """A bad argument of the inspector (the message names it)."""


@dataclass(frozen=True)
class BlockingContact:
    """A contact that blocks a failing set (docs/blockers.md): its index among the grasp's
    contacts, link name and kind, the box face it pushes on, where it sits (face, edge,
    corner), its cone margin and normal force at the max-margin internal force (N per N of
    total normal force) and the angle of its force outside the cone (deg)."""

    contact: int
    link_name: str
    link_kind: str
    face: str
    feature: str
    margin: float
    normal_force: float
    angle_outside_deg: float


@dataclass(frozen=True)
class SetResult:
    """The optimisation of one synergy set at the inspected pose.

    status: the optimisation under the weight: 'feasible' | 'infeasible' |
        'numerical_failure' | 'rank_deficient' | 'no_grasp'
    force_closure: the study's verdict, Definition 1: rank(G) = 6 and a synergy-reachable
        internal force strictly inside every cone (independent of the weight)
    load_feasible: the optimisation under the weight is feasible (status 'feasible')
    force_N: optimal ‖f‖₂ under the object's weight (NaN unless load-feasible)
    e_s: dimension of the synergy-reachable internal forces
    cone_use: largest ‖f_t‖ / (μ f_n) over the contacts of the optimal forces (≤ 1: inside
        every circular cone; NaN unless feasible)
    forces_N: the optimal contact forces on the object, (f_x, f_y, f_z) of each contact in
        turn (3m, N, palm frame; empty unless load-feasible)
    blocked_by: why a set not in force closure fails (`optimisation.blocking.REASONS`:
        'contacts', 'no_internal_force', 'rank_deficient', ...; '' for force closure)
    margin: t*, the largest least cone margin over the set's internal forces, N per N of total
        normal force (NaN unless blocked_by is 'contacts')
    blockers: the contacts that block it (docs/blockers.md)
    """

    set_id: str
    synergies: tuple[int, ...]
    status: str
    force_closure: bool
    load_feasible: bool
    force_N: float
    e_s: int
    cone_use: float
    forces_N: tuple[float, ...] = ()
    blocked_by: str = ""
    margin: float = float("nan")
    blockers: tuple[BlockingContact, ...] = ()


@dataclass(frozen=True)
class GraspInspection:
    """Everything about one grasp: the pose, the closure's contacts, each set's optimisation
    and the quality indices (``quality`` None where the closure made no grasp); the posture
    ``q_rad`` (19 joint angles, rad) and the object's pose (centre mm, row-major rotation,
    palm frame) the closure ended at; the ``hand`` and the object's ``shape`` (for drawing)."""

    object: str
    pose: int
    alpha_deg: float
    beta_deg: float
    closure_status: str
    weight_N: float
    contacts: pd.DataFrame = field(repr=False)  # link, link_name, point_mm, normal, finger
    sets: tuple[SetResult, ...] = ()
    quality: GraspQuality | None = None
    q_rad: tuple[float, ...] = ()
    object_center_mm: tuple[float, ...] = ()
    object_rotation: tuple[float, ...] = ()
    hand: Any = field(default=None, repr=False, compare=False)
    shape: Any = field(default=None, repr=False, compare=False)
    opposition: str = "none"  # the grasp's opposition (docs/opposition.md)

    def to_dict(self) -> dict[str, Any]:
        """The inspection as plain data (lists and numbers), for ``--json``."""
        q = None if self.quality is None else {**asdict(self.quality), "manipulability": self.quality.manipulability.tolist()}
        return {
            "object": self.object,
            "pose": self.pose,
            "alpha_deg": self.alpha_deg,
            "beta_deg": self.beta_deg,
            "closure_status": self.closure_status,
            "weight_N": self.weight_N,
            "opposition": self.opposition,
            "contacts": [
                {
                    "link": int(r.link),
                    "link_name": r.link_name,
                    "point_mm": list(r.point_mm),
                    "normal": list(r.normal),
                    "face": r.face,
                    "feature": r.feature,
                }
                for r in self.contacts.itertuples()
            ],
            "sets": [asdict(s) for s in self.sets],
            "quality": q,
            "q_rad": list(self.q_rad),
            "object_center_mm": list(self.object_center_mm),
            "object_rotation": list(self.object_rotation),
        }


_TOKEN = re.compile(r"^(\d+)(?:-(\d+))?$|^(\d+(?:,\d+)+)$")


def parse_sets(tokens: Sequence[str], n_synergies: int, argument: str = "--sets") -> list[tuple[int, ...]]:
    """Synergy sets from command-line tokens: ``3`` = {S3}, ``1-5`` = {S1..S5} (a range),
    ``2,5`` = {S2, S5}; 1-based, within 1 … ``n_synergies``; an error names ``argument``."""
    out = []
    for token in tokens:
        match = _TOKEN.match(str(token).strip())
        if not match:
            raise InspectionError(f"{argument}: {token!r} is not a set; give k, a-b (S_a..S_b) or a,b,c")
        if match.group(3):
            members = tuple(sorted({int(v) for v in match.group(3).split(",")}))
        else:
            lo = int(match.group(1))
            hi = int(match.group(2)) if match.group(2) else lo
            if hi < lo:
                raise InspectionError(f"{argument}: {token!r} is an empty range")
            members = tuple(range(lo, hi + 1))
        bad = [v for v in members if not 1 <= v <= n_synergies]
        if bad:
            raise InspectionError(f"{argument}: {token!r} names synergies {bad}; the table has S1..S{n_synergies}")
        out.append(members)
    return out


def default_sets(n_synergies: int) -> list[tuple[int, ...]]:
    """Each single synergy, then {S1..Sk} for k = 2 … n."""
    return [(k,) for k in range(1, n_synergies + 1)] + [tuple(range(1, k + 1)) for k in range(2, n_synergies + 1)]


def cone_use(forces: np.ndarray, normals: np.ndarray, mu: float) -> float:
    """Largest ‖f_t‖ / (μ f_n) over the contacts (forces (3m,) N, inward normals (m, 3))."""
    F = np.asarray(forces, dtype=float).reshape(-1, 3)
    n = np.asarray(normals, dtype=float)
    fn = np.einsum("ij,ij->i", F, n)
    ft = np.linalg.norm(F - fn[:, None] * n, axis=1)
    return float(np.max(ft / (mu * fn))) if len(fn) else float("nan")


def _pose_index(placement: Any, alpha_deg: float, beta_deg: float) -> tuple[int, Any]:
    from synergrasp.simulation.placement import pose_grid

    grid = pose_grid(placement)
    try:
        return grid.index(alpha_deg, beta_deg), grid
    except ValueError:
        a, b = placement.alpha_deg, placement.beta_deg
        raise InspectionError(
            f"--alpha/--beta: ({alpha_deg:g}, {beta_deg:g}) deg is not a pose of the grid (alpha {a[0]:g}..{a[1]:g} "
            f"step {a[2]:g}, beta {b[0]:g}..{b[1]:g} step {b[2]:g})"
        ) from None


def _contacts_frame(hand: Any, row: pd.Series, shape: Any, rule: Any) -> pd.DataFrame:
    """The contacts of a contacts-table row with the face each pushes on and where it sits
    (docs/opposition.md)."""
    from synergrasp.simulation.opposition import HandAxes, face_classes, surface_features

    m = int(row["n_contacts"])
    links = np.asarray(row["contact_link"], dtype=np.int64)
    points = np.asarray(row["contact_point"], dtype=float).reshape(m, 3)
    normals = np.asarray(row["contact_normal"], dtype=float).reshape(m, 3)
    R, c = np.asarray(row["object_rotation"], dtype=float), np.asarray(row["object_center"], dtype=float)
    return pd.DataFrame(
        {
            "link": links,
            "link_name": [hand.link_names[k] for k in links],
            "point_mm": [tuple(p) for p in points],
            "normal": [tuple(n) for n in normals],
            "face": face_classes(normals, HandAxes.from_hand(hand)),
            "feature": surface_features(points, shape, R, c, rule),
        }
    )


def searched_target(placement: Any, path: Path) -> Any:
    """The searched placement with the target the object's search chose (its placement.csv)."""
    from synergrasp import table_contracts
    from synergrasp.simulation.placement import searched_placement

    if not path.is_file():
        raise InspectionError(
            f"placement: mode 'searched' takes the object's target from {path}, which does not "
            f"exist: make it with `snakemake -j2 {path}`, or give placement.mode approach or fixed"
        )
    return searched_placement(placement, table_contracts.read_csv(table_contracts.PLACEMENT, path))


def inspect_grasp(
    config: Mapping[str, Any],
    obj: str,
    alpha_deg: float,
    beta_deg: float,
    sets: Sequence[Sequence[int]] | None = None,
    results: str | Path = RESULTS,
) -> GraspInspection:
    """Close the hand on object ``obj`` at pose (α, β) deg with the configuration's hand,
    synergies, placement and closure, then optimise the grasp for each synergy set in ``sets``
    (1-based synergies; None: :func:`default_sets`), as the study's steps do.

    ``config`` is a configuration as read from YAML (an overlay on the defaults); it is
    checked by the workflow's own check (``input_checks.checked_scenario``: the schema, every
    relation, the hand, the synergy table, the objects). With ``placement.mode: searched`` the object's target is read
    from the search's table ``<results>/objects/<obj>/placement.csv``. Raises InspectionError (naming the argument) or
    ``synergrasp.config.ConfigError``; a closure or solver failure is a status in the result.
    """
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.input_checks import checked_scenario, unknown_object
    from synergrasp.optimisation.mechanics import read_grasps
    from synergrasp.optimisation.optimise import OptimiseParams, optimise_grasps
    from synergrasp.optimisation.problem import SynergySets
    from synergrasp.simulation.closure import SimulateParams, simulate_object
    from synergrasp.simulation.contacts import ContactsParams, load_carrying_contacts
    from synergrasp.simulation.opposition import HandAxes, OppositionRule, contacts_oppositions
    from synergrasp.steps import object_file

    cfg, _ = checked_scenario(config)
    if unknown_object(cfg, obj):
        raise InspectionError(unknown_object(cfg, obj))
    sim = SimulateParams.from_config(cfg, obj)
    pose, _ = _pose_index(sim.placement, alpha_deg, beta_deg)
    placement = sim.placement
    if placement.mode == "searched":
        placement = searched_target(placement, object_file(cfg, "search", obj, results))
    hand = load_hand(sim.hand)
    full = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
    chosen = default_sets(full.matrix.shape[1]) if sets is None else [tuple(sorted(set(s))) for s in sets]
    table = simulate_object(
        hand,
        sim.synergies(hand.joint_names),
        sim.object,
        placement,
        sim.closure,
        poses=[pose],
        mechanics=sim.mechanics,
        as_in_grid=True,
    )
    selection = ContactsParams.from_config(cfg, obj)
    if selection.drop_unloaded:
        table = load_carrying_contacts(table, selection.load_threshold_N)
    row = table.iloc[0]
    opt = OptimiseParams.from_config(cfg, obj)
    grasp = read_grasps(table)[0]
    weight = opt.gfo.weight_N
    rule = OppositionRule.from_config(cfg)
    drawing = dict(
        q_rad=_floats(row["q"]),
        object_center_mm=_floats(row["object_center"]),
        object_rotation=_floats(row["object_rotation"]),
        hand=hand,
        shape=sim.object.shape,
        opposition=contacts_oppositions(table.iloc[:1], HandAxes.from_hand(hand), rule)[0],
    )
    contacts = _contacts_frame(hand, row, sim.object.shape, rule)
    if grasp is None:
        return GraspInspection(
            obj,
            pose,
            float(row["alpha_deg"]),
            float(row["beta_deg"]),
            str(row["status"]),
            weight,
            contacts if int(row["n_contacts"]) else pd.DataFrame(),
            **drawing,
        )
    out = optimise_grasps([grasp], SynergySets(full.matrix, tuple(chosen)), opt.gfo, forces=True)
    mu = float(opt.gfo.mu)
    results = tuple(
        SetResult(
            set_id(s),
            s,
            str(out["status"][k]),
            bool(out["force_closure_def1"][k]),
            bool(out["load_feasible"][k]),
            float(out["force_norm"][k]),
            int(out["e_s"][k]),
            cone_use(out["forces"][k], grasp.normals, mu) if out["forces"][k] is not None else float("nan"),
            _floats(out["forces"][k]) if out["forces"][k] is not None else (),
        )
        for k, s in enumerate(chosen)
    )
    results = _with_blockers(results, grasp, full.matrix, opt.gfo, cfg, hand, sim.object.shape, row)
    quality = grasp_quality(grasp, mu, sim.object.shape.bounding_radius_mm, synergies=full.matrix)
    return GraspInspection(
        obj,
        pose,
        float(row["alpha_deg"]),
        float(row["beta_deg"]),
        str(row["status"]),
        weight,
        contacts,
        results,
        quality,
        **drawing,
    )


def _with_blockers(
    results: tuple[SetResult, ...],
    grasp: Any,
    matrix: np.ndarray,
    gfo: Any,
    cfg: Mapping[str, Any],
    hand: Any,
    shape: Any,
    row: pd.Series,
) -> tuple[SetResult, ...]:
    """The sets, each failing one with what blocks it (`analysis.blockers.set_blockers`)."""
    from dataclasses import replace

    from synergrasp.analysis.blockers import contact_labels, set_blockers
    from synergrasp.simulation.opposition import HandAxes, OppositionRule

    failing = [k for k, s in enumerate(results) if not s.force_closure]
    if not failing:
        return results
    found = set_blockers(grasp, matrix, [results[k].synergies for k in failing], gfo)
    rotation = np.asarray(row["object_rotation"], dtype=float).reshape(3, 3)
    labels = contact_labels(grasp, rotation, shape, hand.link_names, HandAxes.from_hand(hand), OppositionRule.from_config(cfg))
    out = list(results)
    for k, one in zip(failing, found):
        b = one.blocking
        at = np.flatnonzero(b.blockers)
        out[k] = replace(
            out[k],
            blocked_by=one.reason,
            margin=float(b.margin),
            blockers=tuple(
                BlockingContact(
                    int(i),
                    labels.names[i],
                    labels.kinds[i],
                    labels.faces[i],
                    labels.features[i],
                    float(b.contact_margin[i]),
                    float(b.normal_force[i]),
                    float(b.angle_outside_deg[i]),
                )
                for i in at
            ),
        )
    return tuple(out)


def _floats(values: Any) -> tuple[float, ...]:
    return tuple(float(v) for v in np.ravel(np.asarray(values, dtype=float)))


def _object_in_picture(result: GraspInspection) -> Any:
    from synergrasp.figures.hand_pictures import ShapeInPicture

    return ShapeInPicture(result.shape, np.asarray(result.object_center_mm), np.asarray(result.object_rotation).reshape(3, 3))


def _title(result: GraspInspection) -> str:
    shape = result.shape.label if result.shape.kind in result.shape.label else f"{result.shape.kind} {result.shape.label}"
    return (
        f"{result.object} ({shape}) at α = {result.alpha_deg:g}°, "
        f"β = {result.beta_deg:g}° (pose {result.pose}): {result.closure_status}, {len(result.contacts)} contacts, "
        f"opposition {result.opposition}"
    )


def grasp_picture(result: GraspInspection, png_path: str | Path) -> None:
    """The inspected grasp drawn as in Fig. 2 from two views (``figure_grasp_views``), as a PNG."""
    from synergrasp.figures.fig1_fig2_postures_grasps import figure_grasp_views

    links = result.contacts["link"] if len(result.contacts) else []
    points = np.array(list(result.contacts["point_mm"]), dtype=float) if len(result.contacts) else np.zeros((0, 3))
    figure_grasp_views(result.hand, _object_in_picture(result), result.q_rad, links, points, _title(result), png_path)


def grasp_view(result: GraspInspection, synergies: Sequence[int] | None = None) -> Any:
    """The inspected grasp in 3-D (``synergrasp.figures.grasp_3d.grasp_figure``: a plotly
    figure as its dict) with the optimal contact forces of the set ``synergies`` (1-based;
    None: the last set inspected) as arrows; ``grasp_page(grasp_view(...))`` is the page
    ``--html`` writes."""
    from synergrasp.figures.grasp_3d import GraspScene, grasp_figure

    chosen = result.sets[-1] if synergies is None and result.sets else None
    if synergies is not None:
        wanted = tuple(sorted(set(synergies)))
        chosen = next((s for s in result.sets if s.synergies == wanted), None)
        if chosen is None:
            raise InspectionError(f"--forces: {set_name(wanted)} is not among the sets inspected")
    links = result.contacts["link"] if len(result.contacts) else []
    points = np.array(list(result.contacts["point_mm"]), dtype=float) if len(result.contacts) else np.zeros((0, 3))
    name = set_name(chosen.synergies) if chosen is not None else ""
    scene = GraspScene.of(
        result.hand,
        result.q_rad,
        _object_in_picture(result),
        links,
        points,
        chosen.forces_N if chosen is not None else None,
        name,
        _title(result),
    )
    return grasp_figure(scene)


def object_closure(cfg: Mapping[str, Any], obj: str, results: str | Path) -> tuple[Callable[[Sequence[int]], pd.DataFrame], Any]:
    """``close(poses)``: the hand closed on ``obj`` at those grid poses with the configuration's
    hand, first synergy, placement (a searched target read from ``<results>/objects/<obj>/
    placement.csv``) and closure, the ``contacts`` step's contacts kept; and the pose grid.
    ``cfg``: a checked configuration. Raises InspectionError (a searched placement without its
    table). The grid is an ``analysis.planners.PoseGrid`` (synergrasp plan --on-demand)."""
    from synergrasp.analysis.planners import PoseGrid
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.simulation.closure import SimulateParams, simulate_object
    from synergrasp.simulation.contacts import ContactsParams, load_carrying_contacts
    from synergrasp.simulation.placement import pose_grid

    sim = SimulateParams.from_config(cfg, obj)
    placement = sim.placement
    if placement.mode == "searched":
        placement = searched_target(placement, Path(results) / "objects" / obj / "placement.csv")
    hand = load_hand(sim.hand)
    synergies = sim.synergies(hand.joint_names)
    selection = ContactsParams.from_config(cfg, obj)
    grid = pose_grid(placement)
    angles = np.array([grid.angles_deg(p) for p in range(grid.n_poses)])

    def close(poses: Sequence[int]) -> pd.DataFrame:
        table = simulate_object(hand, synergies, sim.object, placement, sim.closure, poses=poses, mechanics=sim.mechanics)
        return load_carrying_contacts(table, selection.load_threshold_N) if selection.drop_unloaded else table

    return close, PoseGrid.from_angles(angles[:, 0], angles[:, 1])
