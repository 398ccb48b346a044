"""Success verdicts of a (pose, synergy set) from the gfo table, and marginal grasps.

Two verdicts are derived from the columns the optimisation writes (docs/analyses.md):

- ``force_closure`` — the study's Definition 1 (after Bicchi 1995): rank(G) = 6 and the grasp
  is prehensile, i.e. some synergy-reachable internal force E_s·y lies strictly inside every
  friction cone. The gfo column ``force_closure_def1`` is that verdict: rank(G) = 6 and the
  strict internal-force test, the SOCP with f_p = 0,
  a normal component of at least 1 N at every contact (a scale only: internal forces form a
  cone) and the friction coefficient shrunk to μ(1 − 1e-5) (the margin that makes "strictly
  inside" decidable). It is a property of the grasp, independent of the load.
- ``load_feasible`` — the optimisation under the object's weight is feasible (gfo column
  ``load_feasible``, i.e. status ``feasible``): the weight may help through f_p, so a
  box resting in curled fingers passes.
- ``force_closure_bounded`` — force closure whose optimal force under the weight is at most
  ``marginal_multiple`` times the weight: non-marginal force closure.

In exact arithmetic force closure implies load feasibility (a strictly interior internal
force scaled up absorbs any load), so the optimal force under the weight exists at every
force-closure pose; :mod:`synergrasp.analysis.invariants` counts the poses where the
solvers disagree with that.

A success whose optimal force exceeds ``marginal_multiple`` times the object's weight is
*marginal*: barely feasible, with forces no hand would apply.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from synergrasp.ids import set_members
from synergrasp.resolved import weight_N

__all__ = ["SUCCESS_VERDICTS", "verdict_columns", "with_verdicts", "force_bound"]

#: The success verdicts the tables can use (config ``analyses.success``).
SUCCESS_VERDICTS: tuple[str, ...] = ("force_closure", "load_feasible", "force_closure_bounded")
_NEEDED = ("object", "set_id", "status", "load_feasible", "force_closure_def1", "rank_G", "force_norm")


def verdict_columns(gfo: pd.DataFrame) -> pd.DataFrame:
    """The two verdicts of every gfo row: columns ``force_closure`` (Definition 1: the gfo
    column ``force_closure_def1``) and ``load_feasible`` (optimisation under the weight
    feasible), index aligned with ``gfo``."""
    missing = [c for c in _NEEDED if c not in gfo.columns]
    if missing:
        raise ValueError(f"gfo table: missing columns {missing}")
    return pd.DataFrame(
        {"force_closure": gfo["force_closure_def1"].astype(bool), "load_feasible": gfo["load_feasible"].astype(bool)},
        index=gfo.index,
    )


def force_lower_bound(table: pd.DataFrame, rows: np.ndarray) -> np.ndarray:
    """For the ``rows`` (bool mask) of a gfo table, a lower bound of the optimal force (N):
    the largest optimal force of any computed superset of the row's set at the same object
    and pose (a superset reaches every internal force the set reaches, so its minimum is no
    larger); NaN elsewhere or without such a superset."""
    bound = np.full(len(table), np.nan)
    if not rows.any():
        return bound
    groups = table.groupby(["object", "pose"], sort=False).indices
    set_ids, forces = table["set_id"].astype(str).to_numpy(), table["force_norm"].to_numpy(float)
    for i in np.flatnonzero(rows):
        here = groups[(table["object"].iat[i], table["pose"].iat[i])]
        members = frozenset(set_members(set_ids[i]))
        bigger = np.array([members < frozenset(set_members(set_ids[j])) for j in here], dtype=bool)
        found = forces[here[bigger]]
        bound[i] = np.nanmax(found) if np.isfinite(found).any() else np.nan
    return bound


def with_verdicts(
    gfo: pd.DataFrame, success: str, weights_N: Mapping[str, float] | None = None, marginal_multiple: float = math.inf
) -> pd.DataFrame:
    """A copy of the gfo table with the analysis columns added.

    Force closure without an optimal force under the weight cannot happen in exact
    arithmetic; where the optimal force of a computed superset at the same pose
    (``force_lower_bound_N``) already exceeds ``marginal_multiple`` × the weight, the
    optimisation left a force beyond the solver's accuracy undecided (the cvxpy reference
    finds 0.2–1.3 MN at the default study's nine such rows): the row is reclassified
    load-feasible, never bounded, and flagged ``force_beyond_solver``. Other such rows stay
    as they are (the invariant checks count them).

    Columns added: ``verdict_force_closure``, ``verdict_load_feasible``,
    ``verdict_force_closure_bounded`` (bool, see the module docstring; without weights the
    bound is not applied); ``success`` (the one picked by ``success``); ``success_force``
    (optimal ‖f‖₂ in N under the weight where ``success``, NaN elsewhere); ``marginal``
    (success and success_force > marginal_multiple × weight, or no optimal force; False
    when ``weights_N`` is None or lacks the object); ``force_lower_bound_N``,
    ``force_beyond_solver`` (above).

    Parameters
    ----------
    success : one of :data:`SUCCESS_VERDICTS` (config ``analyses.success``); ``force_closure_bounded``
        needs ``weights_N`` for every object and a finite ``marginal_multiple``.
    weights_N : object name → weight m·g of the object, N.
    marginal_multiple : a success is marginal above this multiple of the weight
        (config ``analyses.marginal_weight_multiple``; none is marginal by default).
    """
    if success not in SUCCESS_VERDICTS:
        raise ValueError(f"success must be one of {list(SUCCESS_VERDICTS)}, got {success!r}")
    verdicts = verdict_columns(gfo)
    out = gfo.copy()
    out["verdict_force_closure"] = verdicts["force_closure"]
    weight = out["object"].map(dict(weights_N or {})).astype(float)
    unresolved = verdicts["force_closure"] & ~np.isfinite(out["force_norm"].to_numpy(float))
    out["force_lower_bound_N"] = force_lower_bound(out, unresolved.to_numpy(bool))
    out["force_beyond_solver"] = unresolved & (out["force_lower_bound_N"] > marginal_multiple * weight).fillna(False)
    out["verdict_load_feasible"] = verdicts["load_feasible"] | out["force_beyond_solver"]
    above = (out["force_norm"] > marginal_multiple * weight).fillna(False).astype(bool) | (unresolved & weight.notna())
    if success == "force_closure_bounded":
        if weights_N is None or weight.isna().any() or not math.isfinite(marginal_multiple):
            raise ValueError(
                "success 'force_closure_bounded' needs every object's weight and a finite "
                "marginal_multiple (config analyses.marginal_weight_multiple)"
            )
        out["success"] = verdicts["force_closure"] & ~above
    else:
        out["success"] = out[f"verdict_{success}"]
    out["verdict_force_closure_bounded"] = verdicts["force_closure"] & ~above
    out["success_force"] = out["force_norm"].where(out["success"])
    out["marginal"] = out["success"] & above
    return out


def force_bound(config: Mapping[str, Any], obj: str) -> dict[str, Any]:
    """``weight_N`` and ``bound_multiple`` of ``obj`` where the configuration's verdict is
    ``force_closure_bounded`` (else none: the verdict reads no bound)."""
    analyses = config["analyses"]
    if analyses["success"] != "force_closure_bounded":
        return {}
    return {"weight_N": weight_N(config, obj), "bound_multiple": float(analyses["marginal_weight_multiple"])}
