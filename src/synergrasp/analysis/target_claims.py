"""The study's claims at every target the placement search scored (docs/placement_search.md,
"The claims over the targets").

At each scored target, the box is placed toward it (the placement rule) at the poses of a
lattice over the first α-period (``analyses.target_claims``), the hand closes with the
search's kinematic closure, the grasp-force optimisation runs with every synergy set of
the study, and the local minima, the study's tables and the claims follow by the study's
own functions and rules (intervals, tie band, least number of distinct poses). It is a
report on how much the claims depend on where the box sits: nothing here feeds back into
the search, whose objective was fixed before (it reads no claim). mm, N, deg.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.claims import CLAIM_VERDICTS, FAILS, HOLDS, UNDEFINED
from synergrasp.analysis.minima import MinimaParams, minima_table
from synergrasp.analysis.study_tables import study_claims
from synergrasp.analysis.summaries import TablesParams
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.ids import synergy_sets
from synergrasp.optimisation.optimise import gfo_table
from synergrasp.optimisation.placement_search import SearchStepParams, TargetScorer, full_synergy_set, pose_subset
from synergrasp.optimisation.problem import SynergySets

__all__ = ["TargetClaimsParams", "ClaimsAtTargets", "claims_at_target", "claims_at_targets", "claims_summary"]


@dataclass(frozen=True)
class TargetClaimsParams:
    """The claims at the scored targets of one object (the ``target_claims`` step): the
    search's closure and placement, the synergy sets the claims read, its minima and
    table settings, the lattice of poses (every n-th α and β of the grid from its start,
    over the first α-period) and how many of the best-ranked targets (0: all)."""

    search: SearchStepParams
    sets: dict[str, tuple[int, ...]]
    minima: MinimaParams
    tables: TablesParams
    alpha_every: int
    beta_every: int
    max_targets: int

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> TargetClaimsParams:
        """From a configuration or the step's own part of it, for the object ``obj``."""
        spec = config["analyses"]["target_claims"]
        # the tables of this object alone; its α-period does not depend on the placement's target
        placement = {**config["placement"], "mode": "searched", "approach_point_mm": None, "center_mm": (0.0, 0.0, 0.0)}
        alone = {**config, "objects": {obj: config["objects"][obj]}, "placement": placement}
        return cls(
            SearchStepParams.from_config(config, obj),
            claim_sets(config["synergy_sets"]),
            MinimaParams.from_config(config, obj),
            TablesParams.from_config(alone, obj),
            int(spec["alpha_every"]),
            int(spec["beta_every"]),
            int(spec["max_targets"]),
        )


def claim_sets(sets_config: Mapping[str, int]) -> dict[str, tuple[int, ...]]:
    """The study's sets that its claims read (``synergrasp.analysis.claims``): the
    incremental sets {S1..Sk} and the sets of one or two of the first
    ``hierarchy_first`` synergies (the triples of Fig. 5 are read by no claim)."""
    return synergy_sets({**sets_config, "hierarchy_max_size": min(2, int(sets_config["hierarchy_max_size"]))})


class ClaimsAtTargets:
    """Computes the claims of one object at given targets (one closure model, one hand)."""

    def __init__(self, hand: Any, synergies: Any, params: TargetClaimsParams, period_deg: float) -> None:
        s = params.search
        lattice = replace(
            s.search,
            pose_alpha_step_deg=params.alpha_every * s.placement.alpha_deg[2],
            pose_beta_step_deg=params.beta_every * s.placement.beta_deg[2],
        )
        self.poses = pose_subset(s.placement, period_deg, lattice)
        # the scorer's closure and placement only: its full set is not used here
        self.scorer = TargetScorer(
            hand,
            synergies,
            s.object,
            s.placement,
            s.closure,
            s.gfo,
            full_synergy_set(synergies.matrix, s.full_set_size),
            self.poses,
        )
        self.sets = SynergySets(synergies.matrix, tuple(params.sets.values()))
        self.params, self.period_deg = params, float(period_deg)

    def close(self) -> None:
        self.scorer.close()

    def __call__(self, target_mm: Sequence[float]) -> pd.DataFrame:
        """The headline rows of the claims table (``synergrasp.analysis.claims``) at one target."""
        p = self.params
        gfo = gfo_table(self.scorer.contacts(target_mm), self.sets, p.search.gfo)
        name = str(p.search.object.name)
        weights = {name: p.minima.weight_N} if p.minima.weight_N is not None else None
        judged = with_verdicts(gfo, p.minima.success, weights, p.minima.bound_multiple)
        minima = minima_table(judged, p.minima.radius_deg, alpha_period_deg=self.period_deg)
        claims = study_claims(gfo, minima, p.tables.synergy_sets, p.tables.settings)
        return claims[claims["headline"]].reset_index(drop=True)


def claims_at_target(computer: ClaimsAtTargets, target: Mapping[str, Any]) -> pd.DataFrame:
    """Rows of ``table_contracts.TARGET_CLAIMS`` for one row of the placement table."""
    point = (float(target["x_mm"]), float(target["y_mm"]), float(target["z_mm"]))
    claims = computer(point)
    return pd.DataFrame(
        {
            "object": str(target["object"]),
            "rank": int(target["rank"]),
            "x_mm": point[0],
            "y_mm": point[1],
            "z_mm": point[2],
            "force_closure_percent": float(target["force_closure_percent"]),
            "n_poses": len(computer.poses),
            "claim": claims["claim"].astype("int32"),
            "view": claims["view"],
            "verdict": claims["verdict"],
            "difference": claims["difference"].astype(float),
            "low": claims["low"].astype(float),
            "high": claims["high"].astype(float),
            "n_distinct_poses": claims["n_distinct_poses"].astype("int32"),
            "reason": claims["reason"],
        }
    )


_WORKER: ClaimsAtTargets | None = None


def _init_worker(args: tuple) -> None:
    global _WORKER
    _WORKER = ClaimsAtTargets(*args)


def _in_worker(target: dict) -> pd.DataFrame:
    assert _WORKER is not None
    return claims_at_target(_WORKER, target)


def claims_at_targets(
    hand: Any, synergies: Any, params: TargetClaimsParams, period_deg: float, placement: pd.DataFrame, processes: int = 1
) -> pd.DataFrame:
    """``table_contracts.TARGET_CLAIMS`` of one object: the claims at each target of its placement
    table (``table_contracts.PLACEMENT``, best first; the best ``max_targets`` when > 0), in rank
    order. Deterministic: the same table for any ``processes``."""
    rows = placement.sort_values("rank")
    if params.max_targets > 0:
        rows = rows.head(params.max_targets)
    targets = rows.to_dict("records")
    args = (hand, synergies, params, period_deg)
    if processes > 1:
        import multiprocessing

        with multiprocessing.get_context("fork").Pool(processes, initializer=_init_worker, initargs=(args,)) as pool:
            parts = pool.map(_in_worker, targets, chunksize=1)
    else:
        computer = ClaimsAtTargets(*args)
        try:
            parts = [claims_at_target(computer, t) for t in targets]
        finally:
            computer.close()
    if not parts:
        return table_contracts.empty(table_contracts.TARGET_CLAIMS)
    return pd.concat(parts, ignore_index=True)[list(table_contracts.TARGET_CLAIMS.names)]


def claims_summary(per_target: pd.DataFrame) -> pd.DataFrame:
    """Per object and claim: the scored targets, the share (%) where the claim holds, does
    not hold and is undefined, and the verdict at the chosen target (rank 1)."""
    rows = []
    for (obj, claim), group in per_target.groupby(["object", "claim"], sort=True):
        shares = {v: 100.0 * float(np.mean(group["verdict"] == v)) for v in CLAIM_VERDICTS}
        chosen = group.loc[group["rank"] == 1, "verdict"]
        rows.append(
            {
                "object": obj,
                "claim": int(claim),
                "n_targets": len(group),
                "holds_percent": shares[HOLDS],
                "does_not_hold_percent": shares[FAILS],
                "undefined_percent": shares[UNDEFINED],
                "at_chosen_target": chosen.iloc[0] if len(chosen) else "",
            }
        )
    return pd.DataFrame(
        rows,
        columns=[
            "object",
            "claim",
            "n_targets",
            "holds_percent",
            "does_not_hold_percent",
            "undefined_percent",
            "at_chosen_target",
        ],
    )
