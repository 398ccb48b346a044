"""Version 3 of the placement search: grasps this hand can make (docs/placement_search.md,
"Version 3", pre-registered with this module and tests/test_grasp_type_search.py).

The object's stated grasp type (``objects.<name>.grasp_type``) is searched only when the hand
can make it (``synergrasp.simulation.reach.feasible_types``: power when the object's thickness
is at most the hand's d_max, precision when its width fits the thumb-to-fingertip aperture).
When it cannot, or when the search's best target scores T ≤ ``min_typed_percent`` (0: every
target scores 0, and the tie rules would choose among failures), the search falls back along
one chain: power-<class> → precision-<class> → any, the class (circular or prismatic) read from
the object's shape (``reach.shape_class``). When every type fails, no target is chosen by a
score: the box is brought to the palm centre (the ``approach`` target) and the reason says so.
The objective, the region of each type, the tie rules and the scored poses are version 2's;
the search reads no synergy subset, claim or hierarchy figure. mm, %.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING

from synergrasp.optimisation.placement_search import FallbackParams
from synergrasp.simulation.reach import feasible_types, shape_class

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.optimisation.placement_search import SearchResult, SearchStepParams
    from synergrasp.simulation.reach import HandReach
    from synergrasp.simulation.shapes import Shape

__all__ = [
    "FallbackParams",
    "NEXT_TYPE",
    "type_label",
    "type_family",
    "search_with_fallback",
    "search_object_types",
    "fallback_line",
    "KEPT",
]

#: The fallback chain: the next grasp type tried when one is infeasible or scores no target.
NEXT_TYPE: dict[str, str | None] = {"power": "precision", "precision": "any", "any": None}
#: The reason recorded when the stated type was searched and chosen.
KEPT = "stated type feasible and scored"


def type_label(grasp_type: str, klass: str) -> str:
    """The grasp type with the object's shape class (``power-circular``); ``any`` has none."""
    return grasp_type if grasp_type == "any" else f"{grasp_type}-{klass}"


def type_family(label: str) -> str:
    """The grasp type of a label (``precision-circular`` -> ``precision``; ``any`` -> ``any``):
    what the opposition rule counts (``opposition.GRASP_TYPES``)."""
    return label.split("-", 1)[0]


def search_with_fallback(
    stated: str,
    shape: Shape,
    reach: HandReach,
    fallback: FallbackParams,
    run_search: Callable[[str], SearchResult],
    palm_centre_result: Callable[[], SearchResult],
) -> SearchResult:
    """The search of one object under version 3 (module docstring): ``run_search(type)`` runs
    the search of one grasp type over its region; ``palm_centre_result()`` scores the palm
    centre alone (the last resort, chosen by no score). The result carries the stated and the
    effective type (with the shape class) and the reason of every fallback."""
    klass = shape_class(shape, fallback.prismatic_aspect)
    if not fallback.enabled:
        result = run_search(stated)
        return replace(
            result,
            stated_type=type_label(stated, klass),
            effective_type=type_label(stated, klass),
            type_reason="version 2: the stated type, no fallback",
        )
    feasible = feasible_types(shape, reach)
    reasons: list[str] = []
    grasp_type: str | None = stated
    while grasp_type is not None:
        label = type_label(grasp_type, klass)
        if grasp_type in feasible and not feasible[grasp_type][0]:
            reasons.append(f"{label} infeasible for this hand: {feasible[grasp_type][1]}")
        else:
            result = run_search(grasp_type)
            best = result.chosen.typed_percent
            if best > fallback.min_typed_percent:
                return replace(
                    result,
                    stated_type=type_label(stated, klass),
                    effective_type=label,
                    type_reason="; ".join(reasons) if reasons else KEPT,
                )
            reasons.append(
                f"{label}: the best of {len(result.ranked)} targets scores T = {best:.3g} % "
                f"(<= min_typed_percent {fallback.min_typed_percent:g})"
            )
        grasp_type = NEXT_TYPE[grasp_type]
    result = palm_centre_result()
    reasons.append("no type scores: the box is brought to the palm centre, chosen by no score")
    return replace(result, stated_type=type_label(stated, klass), effective_type="any", type_reason="; ".join(reasons))


def fallback_line(result: SearchResult) -> str | None:
    """One WARNING line for an object whose effective type is not its stated one (None else)."""
    if result.stated_type == result.effective_type:
        return None
    return f"{result.object}: stated grasp type {result.stated_type}, effective {result.effective_type} ({result.type_reason})"


def search_object_types(
    hand: Hand,
    synergies: Synergies,
    sim: SearchStepParams,
    period_deg: float,
    processes: int = 1,
    reach: HandReach | None = None,
) -> SearchResult:
    """The search step's one front door: the hand's reach (the gate: ``reach``, the ``reach``
    step's, else measured here), the hand's region (the bound of the region's growth) and the
    search of each grasp type the chain reaches."""
    from synergrasp.optimisation.placement_search import SearchResult, TargetScorer, full_synergy_set, pose_subset, search_object
    from synergrasp.simulation.placement import hand_region, palm_centre
    from synergrasp.simulation.reach import hand_reach

    if reach is None:
        reach = hand_reach(hand, synergies, sim.closure, sim.reach)
    bound = hand_region(hand, synergies)
    full_set = full_synergy_set(synergies.matrix, sim.full_set_size)

    def run_search(grasp_type: str) -> SearchResult:
        return search_object(
            hand,
            synergies,
            sim.object,
            sim.placement,
            sim.closure,
            sim.gfo,
            full_set,
            sim.params_of(grasp_type),
            period_deg,
            processes=processes,
            opposition=sim.opposition,
            bound_mm=bound,
        )

    def palm_centre_result() -> SearchResult:
        params = sim.params_of("any")
        scorer = TargetScorer(
            hand,
            synergies,
            sim.object,
            sim.placement,
            sim.closure,
            sim.gfo,
            full_set,
            pose_subset(sim.placement, period_deg, params),
            "any",
            sim.opposition,
        )
        try:
            score = scorer(tuple(float(v) for v in palm_centre(hand)))
        finally:
            scorer.close()
        return SearchResult(str(sim.object.name), (score,), {score.target_mm: 0}, "any", params.region_mm)

    return search_with_fallback(sim.search.grasp_type, sim.object.shape, reach, sim.fallback, run_search, palm_centre_result)
