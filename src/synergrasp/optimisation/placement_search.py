"""The placement search: where each box sits best in the hand (docs/placement_search.md).

The objective is pre-registered in docs/placement_search.md, with this module, before any
search result existed (its second version, the grasp type, likewise: that page's "Changes
since pre-registration"). A target point t (palm frame, mm) is scored on a fixed subset of the
object's distinct poses (the α-period folded): the box is placed by the placement rule
(travels along the palm normal toward t, stops at t or at first touch of the open hand), the
hand closes on it, the grasp's opposition is read from its contacts
(``synergrasp.simulation.opposition``) and the grasp-force optimisation runs with the **full
synergy set only**; a pose counts when its grasp is of the object's grasp type and in force
closure.
:func:`score_target` turns the per-pose results into a :class:`TargetScore` (a pure
function), :func:`rank_targets` orders targets by the tie rules; :func:`search_object` runs
the coarse-to-fine search over the region. Nothing here reads a synergy subset, a claim or
a hierarchy figure. mm, N, deg; palm frame.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp import table_contracts
from synergrasp.config import build, dataclass_fields
from synergrasp.optimisation.mechanics import read_grasps
from synergrasp.optimisation.optimise import GFOParams, optimise_grasps
from synergrasp.optimisation.problem import SynergySets
from synergrasp.resolved import effective_placement
from synergrasp.resolved import grasp_type as resolved_grasp_type
from synergrasp.simulation.closure_params import ClosureParams
from synergrasp.simulation.contacts import contacts_row, contacts_table
from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.opposition import HandAxes, OppositionRule, contacts_oppositions, of_grasp_type
from synergrasp.simulation.placement import Placement, hand_region, palm_centre, pose_grid
from synergrasp.simulation.reach import ReachParams

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies

__all__ = [
    "SearchStepParams",
    "FallbackParams",
    "SearchParams",
    "TargetScore",
    "SearchResult",
    "score_target",
    "rank_targets",
    "pose_subset",
    "full_synergy_set",
    "TargetScorer",
    "search_object",
    "region_lattice",
    "distinct_ranks",
    "grown_region",
]

_TOL = 1e-6


@dataclass(frozen=True)
class SearchParams:
    """The search's settings (config ``placement.search``; defaults in the schema).

    region_mm:          ((x0, x1), (y0, y1), (z0, z1)): the box of target points, palm frame, mm
                        (the object's grasp type's region, config ``region_mm.<type>``)
    coarse_spacing_mm:  spacing of the first lattice, anchored at (x0, y0, z0)
    spacing_mm:         spacing of the refinement (the final resolution, ≤ 10 mm); divides
                        coarse_spacing_mm
    refine_top:         each round adds the unscored lattice neighbours (±spacing_mm on each
                        axis, 26 of them) of the best ``refine_top`` targets
    max_rounds:         refinement rounds at most (the search stops earlier when the best
                        targets' neighbours are all scored)
    pose_alpha_step_deg, pose_beta_step_deg: the scored poses: the grid's poses in the first
                        α-period whose α and β lie on these steps from the grid's start
    tie_band_points:    force-closure shares within this many percentage points of the best
                        count as tied
    force_tie_relative: median forces within this relative margin of the lowest count as tied
    grasp_type:         the object's grasp type (``opposition.GRASP_TYPES``): a scored pose
                        counts when its grasp's opposition is of this type
    grow_region:        version 3: when the chosen target lies on the region's boundary, the
                        region grows one ``spacing_mm`` step in that direction, within the
                        hand's reach (``search_object``'s ``bound_mm``), and the refinement
                        goes on, until the chosen target is inside or the reach stops it
    """

    region_mm: tuple[tuple[float, float], tuple[float, float], tuple[float, float]]
    coarse_spacing_mm: float
    spacing_mm: float
    refine_top: int
    max_rounds: int
    pose_alpha_step_deg: float
    pose_beta_step_deg: float
    tie_band_points: float
    force_tie_relative: float
    grasp_type: str = "any"
    grow_region: bool = False

    def __post_init__(self) -> None:
        region = tuple((float(a), float(b)) for a, b in self.region_mm)
        if len(region) != 3 or any(b < a for a, b in region):
            raise ValueError(f"region_mm must be three (start, stop) pairs with stop >= start, got {self.region_mm!r}")
        object.__setattr__(self, "region_mm", region)
        for name in (
            "coarse_spacing_mm",
            "spacing_mm",
            "pose_alpha_step_deg",
            "pose_beta_step_deg",
            "tie_band_points",
            "force_tie_relative",
        ):
            object.__setattr__(self, name, float(getattr(self, name)))
        ratio = self.coarse_spacing_mm / self.spacing_mm
        if not (self.spacing_mm > 0 and abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= 1):
            raise ValueError(
                f"coarse_spacing_mm ({self.coarse_spacing_mm}) must be a whole multiple of spacing_mm ({self.spacing_mm})"
            )


def _hand_region(hand: str | None, synergies: str | None) -> tuple[tuple[float, float], ...]:
    """``region_mm: hand``: the region of the hand file and synergy table (``hand_region``)."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies

    loaded = load_hand(hand)
    return hand_region(loaded, load_synergies(synergies, joint_names=loaded.joint_names))


@dataclass(frozen=True)
class FallbackParams:
    """Version 3's settings (config ``placement.search.fallback``; defaults in the schema).

    enabled:           False: version 2 (the stated type only, its tie rules even among
                       targets that all score 0)
    min_typed_percent: a search whose best target scores T at most this (%) falls back; 0:
                       only when every target scores 0
    prismatic_aspect:  an object is prismatic when its longest own extent is at least this
                       many times its shortest, circular otherwise
    """

    enabled: bool
    min_typed_percent: float
    prismatic_aspect: float

    def __post_init__(self) -> None:
        if not 0.0 <= float(self.min_typed_percent) < 100.0:
            raise ValueError(f"min_typed_percent must lie in [0, 100), got {self.min_typed_percent!r}")
        if not float(self.prismatic_aspect) >= 1.0:
            raise ValueError(f"prismatic_aspect must be >= 1, got {self.prismatic_aspect!r}")

    @classmethod
    def from_config(cls, spec: Mapping[str, Any]) -> FallbackParams:
        """From the effective ``placement.search.fallback`` block."""
        return cls(bool(spec["enabled"]), float(spec["min_typed_percent"]), float(spec["prismatic_aspect"]))


@dataclass(frozen=True)
class SearchStepParams:
    """The placement search of one object (the ``search`` step; docs/placement_search.md):
    hand and synergy files, the object with its mass, its effective placement, the closure
    settings (the search closes with the kinematic model), the GFO parameters, the size of
    the full synergy set, the search's settings."""

    hand: str | None
    synergies: str | None
    object: GraspedObject
    placement: Placement
    closure: ClosureParams
    gfo: GFOParams
    full_set_size: int
    search: SearchParams
    distinct_mm: float
    opposition: OppositionRule
    regions: Mapping[str, tuple[tuple[float, float], ...]] | None = None
    fallback: FallbackParams | None = None
    reach: ReachParams | None = None

    def params_of(self, grasp_type: str) -> SearchParams:
        """The search's settings for one grasp type: its region (version 3 searches the types
        of the fallback chain, each over its own region)."""
        if grasp_type == self.search.grasp_type or self.regions is None:
            return replace(self.search, grasp_type=grasp_type)
        return replace(self.search, grasp_type=grasp_type, region_mm=self.regions[grasp_type])

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> SearchStepParams:
        """From a configuration or the step's own part of it, for the object ``obj``."""
        placement = effective_placement(config, obj)
        spec = placement["search"]
        grasp_type = resolved_grasp_type(config, obj)
        regions = {}
        for kind, value in spec["region_mm"].items():
            if value == "hand":  # derived from the hand's geometry (docs/placement_search.md)
                regions[kind] = _hand_region(config["hand"], config["synergies"])
            else:
                regions[kind] = tuple(tuple(value[axis]) for axis in ("x", "y", "z"))
        search = build(
            SearchParams,
            "placement.search",
            region_mm=regions[grasp_type],
            grasp_type=grasp_type,
            **dataclass_fields(SearchParams, {k: v for k, v in spec.items() if k != "region_mm"}),
        )
        fallback = build(FallbackParams, "placement.search.fallback", **spec["fallback"])
        closure = {**config["closure"], "model": "kinematic"}
        return cls(
            hand=config["hand"],
            synergies=config["synergies"],
            object=GraspedObject.from_config(config, obj),
            # the search places the box toward each of its targets: the modes' own targets are not read
            placement=Placement.from_config(
                {**placement, "mode": "searched", "approach_point_mm": None, "center_mm": (0.0, 0.0, 0.0)}, config["grid"]
            ),
            closure=build(ClosureParams, "closure", **{**dataclass_fields(ClosureParams, closure), "dynamic": None}),
            gfo=GFOParams.from_config(config, obj),
            full_set_size=int(config["synergy_sets"]["incremental_max"]),
            search=search,
            distinct_mm=float(spec["distinct_mm"]),
            opposition=OppositionRule.from_config(config),
            regions=regions,
            fallback=fallback,
            reach=ReachParams.from_config(config),
        )


@dataclass(frozen=True)
class TargetScore:
    """The objective at one target: what the whole hand does on the scored poses.

    typed_percent:           the score T: share of the scored poses whose grasp is of the
                             object's grasp type **and** in force closure with the full set, %
    force_closure_percent:   share of the scored poses in force closure (the study's
                             Definition 1: rank(G) = 6 and a strictly internal force) with
                             the full synergy set, whatever their opposition, % (reported)
    median_force_per_weight: median optimal contact force ‖f‖₂ under the weight over the
                             poses that count for T, divided by the weight (inf when none)
    median_contacts:         median number of contacts per scored pose
    """

    target_mm: tuple[float, float, float]
    n_poses: int
    typed_percent: float
    force_closure_percent: float
    median_force_per_weight: float
    median_contacts: float


def score_target(
    target_mm: Sequence[float],
    force_closure: NDArray,
    force_N: NDArray,
    n_contacts: NDArray,
    weight_N: float,
    of_type: NDArray | None = None,
) -> TargetScore:
    """The objective of one target from its per-pose results with the full synergy set
    (one entry per scored pose): force closure (bool), optimal force under the weight (N,
    NaN where none), the number of contacts, and whether the grasp's opposition is of the
    object's grasp type (bool; None: every pose is). Pure: reads nothing else."""
    fc = np.asarray(force_closure, dtype=bool)
    force = np.asarray(force_N, dtype=float)
    contacts = np.asarray(n_contacts, dtype=float)
    typed = np.ones_like(fc) if of_type is None else np.asarray(of_type, dtype=bool)
    if not (fc.shape == force.shape == contacts.shape == typed.shape and fc.ndim == 1 and fc.size > 0):
        raise ValueError("force_closure, force_N, n_contacts and of_type must be equal-length 1-d arrays of the scored poses")
    if not weight_N > 0:
        raise ValueError(f"weight_N must be > 0, got {weight_N}")
    counted = fc & typed
    held = counted & np.isfinite(force)
    median_force = float(np.median(force[held])) / float(weight_N) if held.any() else math.inf
    return TargetScore(
        tuple(float(v) for v in target_mm),
        int(fc.size),
        100.0 * float(counted.mean()),
        100.0 * float(fc.mean()),
        median_force,
        float(np.median(contacts)),
    )


def _best(scores: Sequence[TargetScore], reference_mm: NDArray, tie_band_points: float, force_tie_relative: float) -> TargetScore:
    """The tie rules: the highest score T (typed force-closure share), shares within
    ``tie_band_points`` tied; among them the lowest median force over the weight, forces
    within ``force_tie_relative`` of it tied; then the most median contacts; then the target
    nearest the reference (the palm centre); then the smallest (x, y, z)."""
    top = max(s.typed_percent for s in scores)
    tied = [s for s in scores if s.typed_percent >= top - tie_band_points - _TOL]
    low = min(s.median_force_per_weight for s in tied)
    if math.isfinite(low):
        tied = [s for s in tied if s.median_force_per_weight <= low * (1.0 + force_tie_relative) + _TOL]
    most = max(s.median_contacts for s in tied)
    tied = [s for s in tied if s.median_contacts >= most]
    return min(tied, key=lambda s: (round(float(np.linalg.norm(np.subtract(s.target_mm, reference_mm))), 9), s.target_mm))


def rank_targets(
    scores: Sequence[TargetScore], reference_mm: Sequence[float], tie_band_points: float, force_tie_relative: float
) -> list[TargetScore]:
    """Every target, best first: the first is the one the tie rules pick among all, the next
    the one they pick among the rest, and so on (a total order, independent of input order)."""
    left = sorted(scores, key=lambda s: s.target_mm)
    ref = np.asarray(reference_mm, dtype=float)
    out = []
    while left:
        best = _best(left, ref, tie_band_points, force_tie_relative)
        out.append(best)
        left.remove(best)
    return out


def region_lattice(params: SearchParams, spacing_mm: float) -> NDArray:
    """(n, 3) the lattice points of the region at ``spacing_mm``, anchored at its lower corner."""
    axes = [
        start + spacing_mm * np.arange(int(math.floor((stop - start) / spacing_mm + 1e-9)) + 1)
        for start, stop in params.region_mm
    ]
    return np.array(list(itertools.product(*axes)), dtype=float)


def _in_region(point: NDArray, params: SearchParams) -> bool:
    return all(a - _TOL <= v <= b + _TOL for v, (a, b) in zip(point, params.region_mm))


def pose_subset(placement: Placement, period_deg: float, params: SearchParams) -> list[int]:
    """The scored poses: those of the placement's grid with α in the first α-period
    [α0, α0 + period) and α − α0, β − β0 whole multiples of the search's pose steps."""
    grid = pose_grid(placement)
    a0, b0 = float(grid.alpha_deg[0]), float(grid.beta_deg[0])

    def on_step(values: NDArray, start: float, step: float) -> NDArray:
        k = (values - start) / step
        return np.abs(k - np.round(k)) < 1e-9

    alphas = np.flatnonzero(on_step(grid.alpha_deg, a0, params.pose_alpha_step_deg) & (grid.alpha_deg < a0 + period_deg - 1e-9))
    betas = np.flatnonzero(on_step(grid.beta_deg, b0, params.pose_beta_step_deg))
    if alphas.size == 0 or betas.size == 0:
        raise ValueError("placement.search: no pose of the grid lies on the search's pose steps")
    return [int(ia) * grid.n_beta + int(ib) for ia in alphas for ib in betas]


def full_synergy_set(matrix: NDArray, n_full: int) -> SynergySets:
    """The one synergy set the search reads: the full set {S1..S_n_full}."""
    return SynergySets(np.asarray(matrix, dtype=float), (tuple(range(1, int(n_full) + 1)),))


class TargetScorer:
    """Scores targets of one object: placement rule, closure, the grasps' opposition, GFO with
    the full set only; a pose counts when its grasp is of ``grasp_type``."""

    def __init__(
        self,
        hand: Hand,
        synergies: Synergies,
        box: Any,
        placement: Placement,
        closure: ClosureParams,
        gfo: GFOParams,
        full_set: SynergySets,
        poses: Sequence[int],
        grasp_type: str = "any",
        opposition: OppositionRule | None = None,
    ) -> None:
        from synergrasp.simulation.closure import closure_model
        from synergrasp.simulation.scene import HandScene

        if len(full_set) != 1:
            raise ValueError("the search reads the full synergy set only: give exactly one set")
        self.box, self.placement, self.gfo, self.full_set = box, placement, gfo, full_set
        self.poses = [int(p) for p in poses]
        self.grid = pose_grid(placement)
        self.model = closure_model(hand, synergies, replace(closure, model="kinematic"))
        self.placer = HandScene(hand)
        self.axes, self.grasp_type = HandAxes.from_hand(hand), grasp_type
        self.rule = opposition  # None: the scorer only places and closes (contacts)

    def close(self) -> None:
        self.model.close()
        self.placer.close()

    def contacts(self, target_mm: Sequence[float]) -> pd.DataFrame:
        """The contacts table of the scored poses with the box placed toward ``target_mm``."""
        from synergrasp.simulation.closure import place_object

        placement = replace(self.placement, mode="searched", target_mm=tuple(float(v) for v in target_mm))
        rows = []
        for pose in self.poses:
            a, b = self.grid.angles_deg(pose)
            placed = place_object(self.placer, self.model.q_open, placement, self.box.shape, a, b)
            rows.append(contacts_row(str(self.box.name), pose, a, b, self.model.grasp(placed), placed))
        return contacts_table(rows)

    def __call__(self, target_mm: Sequence[float]) -> TargetScore:
        table = self.contacts(target_mm)
        out = optimise_grasps(read_grasps(table), self.full_set, self.gfo)
        fc = np.asarray(out["force_closure_def1"], dtype=bool)
        weight = self.gfo.weight_N
        if self.rule is None:
            raise ValueError("TargetScorer: scoring reads the grasps' opposition: give the opposition rule")
        typed = [of_grasp_type(o, self.grasp_type) for o in contacts_oppositions(table, self.axes, self.rule)]
        return score_target(target_mm, fc, out["force_norm"], table["n_contacts"].to_numpy(), weight, np.array(typed))


def distinct_ranks(ranked: Sequence[TargetScore], distinct_mm: float) -> list[int]:
    """Per target of a ranking, its rank among the targets at least ``distinct_mm`` from every
    better distinct one (1, 2, …), 0 for a target closer than that to one of them."""
    kept: list[NDArray] = []
    out = []
    for s in ranked:
        p = np.asarray(s.target_mm)
        if all(np.linalg.norm(p - q) >= distinct_mm - _TOL for q in kept):
            kept.append(p)
            out.append(len(kept))
        else:
            out.append(0)
    return out


@dataclass(frozen=True)
class SearchResult:
    """Every scored target of one object, best first (``ranked[0]`` is the chosen one), and
    the refinement round in which each target was first scored (0 = the coarse lattice)."""

    object: str
    ranked: tuple[TargetScore, ...]
    rounds: dict[tuple[float, float, float], int]
    grasp_type: str = "any"
    region_mm: tuple[tuple[float, float], ...] = ()
    stated_type: str = ""
    effective_type: str = ""
    type_reason: str = ""

    @property
    def chosen(self) -> TargetScore:
        return self.ranked[0]

    def table(self, distinct_mm: float) -> pd.DataFrame:
        """The placement table (``table_contracts.PLACEMENT``), best first."""
        chosen = np.asarray(self.chosen.target_mm)
        distinct = distinct_ranks(self.ranked, distinct_mm)
        region = "; ".join(f"{axis} {lo:g} … {hi:g}" for axis, (lo, hi) in zip("xyz", self.region_mm))
        rows = [
            {
                "object": self.object,
                "rank": k + 1,
                "chosen": k == 0,
                "distinct_rank": distinct[k],
                "x_mm": s.target_mm[0],
                "y_mm": s.target_mm[1],
                "z_mm": s.target_mm[2],
                "round": self.rounds[s.target_mm],
                "n_poses": s.n_poses,
                "grasp_type": self.grasp_type,
                "typed_percent": s.typed_percent,
                "force_closure_percent": s.force_closure_percent,
                "median_force_per_weight": s.median_force_per_weight,
                "median_contacts": s.median_contacts,
                "distance_to_chosen_mm": float(np.linalg.norm(np.asarray(s.target_mm) - chosen)),
                "stated_type": self.stated_type or self.grasp_type,
                "effective_type": self.effective_type or self.grasp_type,
                "type_reason": self.type_reason,
                "region_mm": region,
            }
            for k, s in enumerate(self.ranked)
        ]
        return pd.DataFrame(rows, columns=list(table_contracts.PLACEMENT.names))


_WORKER: TargetScorer | None = None


def _init_worker(args: tuple) -> None:
    global _WORKER
    _WORKER = TargetScorer(*args)


def _score_in_worker(target: tuple[float, float, float]) -> TargetScore:
    assert _WORKER is not None
    return _WORKER(target)


def _key(point: NDArray) -> tuple[float, float, float]:
    return tuple(float(round(v, 6)) for v in point)


def grown_region(
    region_mm: Sequence[tuple[float, float]], target_mm: Sequence[float], step_mm: float, bound_mm: Sequence[tuple[float, float]]
) -> tuple[tuple[float, float], ...]:
    """Version 3's region growth (docs/placement_search.md): on every axis where the target
    lies on the region's lower or upper bound, that bound moves one ``step_mm`` outward,
    unless it would pass ``bound_mm`` (the hand's reach, ``placement.hand_region``); an axis
    the region pins to one value (the power region's x, the palm face) never grows. The same
    region when nothing grows."""
    out = []
    for (lo, hi), v, (b_lo, b_hi) in zip(region_mm, target_mm, bound_mm):
        if hi - lo > _TOL:
            if abs(v - hi) <= _TOL and hi + step_mm <= b_hi + _TOL:
                hi = hi + step_mm
            if abs(v - lo) <= _TOL and lo - step_mm >= b_lo - _TOL:
                lo = lo - step_mm
        out.append((float(lo), float(hi)))
    return tuple(out)


def search_object(
    hand: Hand,
    synergies: Synergies,
    box: Any,
    placement: Placement,
    closure: ClosureParams,
    gfo: GFOParams,
    full_set: SynergySets,
    params: SearchParams,
    period_deg: float,
    processes: int = 1,
    opposition: OppositionRule | None = None,
    bound_mm: Sequence[tuple[float, float]] | None = None,
) -> SearchResult:
    """The coarse-to-fine search of one object (docs/placement_search.md): score the coarse
    lattice, then, round by round, the unscored neighbours at ``spacing_mm`` of the best
    ``refine_top`` targets, until they are all scored or ``max_rounds`` is reached. With
    ``params.grow_region`` and the hand's reach ``bound_mm``, a chosen target (T > 0) on the
    region's boundary grows the region (:func:`grown_region`) and the refinement goes on with
    a fresh round budget, until the target is inside or nothing can grow.
    Deterministic: the same result for any ``processes``."""
    args = (
        hand,
        synergies,
        box,
        placement,
        closure,
        gfo,
        full_set,
        pose_subset(placement, period_deg, params),
        params.grasp_type,
        opposition,
    )
    reference = palm_centre(hand)
    scores: dict[tuple[float, float, float], TargetScore] = {}
    rounds: dict[tuple[float, float, float], int] = {}
    pool = None
    if processes > 1:
        import multiprocessing

        pool = multiprocessing.get_context("fork").Pool(processes, initializer=_init_worker, initargs=(args,))
        score_many = lambda targets: pool.map(_score_in_worker, targets, chunksize=1)  # noqa: E731
    else:
        scorer = TargetScorer(*args)
        score_many = lambda targets: [scorer(t) for t in targets]  # noqa: E731
    steps = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if any(d)], dtype=float)

    def neighbours(region: SearchParams) -> list[tuple[float, float, float]]:
        ranked = rank_targets(list(scores.values()), reference, params.tie_band_points, params.force_tie_relative)
        near = {_key(np.asarray(s.target_mm) + params.spacing_mm * d) for s in ranked[: params.refine_top] for d in steps}
        return sorted(t for t in near if t not in scores and _in_region(np.asarray(t), region))

    grow = params.grow_region and bound_mm is not None
    k = 0
    try:
        todo = [_key(p) for p in region_lattice(params, params.coarse_spacing_mm)]
        while True:
            for budget in range(params.max_rounds + 1):
                for target, score in zip(todo, score_many(todo)):
                    scores[target], rounds[target] = score, k
                k += 1
                todo = neighbours(params) if budget < params.max_rounds else []
                if not todo:
                    break
            if not grow:
                break
            best = rank_targets(list(scores.values()), reference, params.tie_band_points, params.force_tie_relative)[0]
            if not best.typed_percent > 0:
                break  # nothing chosen (version 3 falls back): no region to decide
            region = grown_region(params.region_mm, best.target_mm, params.spacing_mm, bound_mm)
            if region == params.region_mm:
                break
            params = replace(params, region_mm=region)
            todo = neighbours(params)
    finally:
        if pool is not None:
            pool.close()
            pool.join()
        else:
            scorer.close()
    ranked = rank_targets(list(scores.values()), reference, params.tie_band_points, params.force_tie_relative)
    return SearchResult(str(box.name), tuple(ranked), rounds, params.grasp_type, params.region_mm)
