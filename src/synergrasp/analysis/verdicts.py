"""Success verdicts of a (pose, synergy set) from the gfo table, and marginal grasps.

Two verdicts are derived from the columns the optimisation writes (docs/analyses.md):

- ``force_closure`` — the study's Definition 1 (after Bicchi 1995): rank(G) = 6 and the grasp
  is prehensile, i.e. some synergy-reachable internal force E_s·y lies strictly inside every
  friction cone. The gfo column ``strict_internal`` is that test: the SOCP with f_p = 0,
  a normal component of at least 1 N at every contact (a scale only: internal forces form a
  cone) and the friction coefficient shrunk to μ(1 − 1e-5) (the margin that makes "strictly
  inside" decidable). It is a property of the grasp, independent of the load.
- ``load_feasible`` — the optimisation under the object's weight is feasible (gfo column
  ``force_closure``, i.e. status ``force_closure``): the weight may help through f_p, so a
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

import pandas as pd

__all__ = ["VERDICTS", "verdict_columns", "with_verdicts"]

#: The success verdicts the tables can use (config ``analyses.success``).
VERDICTS: tuple[str, ...] = ("force_closure", "load_feasible", "force_closure_bounded")
_NEEDED = ("object", "set_id", "status", "force_closure", "strict_internal", "rank_G", "force_norm")


def verdict_columns(gfo: pd.DataFrame) -> pd.DataFrame:
    """The two verdicts of every gfo row: columns ``force_closure`` (rank(G) = 6 and the
    strict internal-force test) and ``load_feasible`` (optimisation under the weight
    feasible), index aligned with ``gfo``."""
    missing = [c for c in _NEEDED if c not in gfo.columns]
    if missing:
        raise ValueError(f"gfo table: missing columns {missing}")
    closure = gfo["strict_internal"].astype(bool) & (gfo["rank_G"].astype(int) == 6)
    return pd.DataFrame({"force_closure": closure, "load_feasible": gfo["force_closure"].astype(bool)},
                        index=gfo.index)


def with_verdicts(gfo: pd.DataFrame, success: str,
                  weights_N: Mapping[str, float] | None = None, marginal_multiple: float = math.inf) -> pd.DataFrame:
    """A copy of the gfo table with the analysis columns added.

    Columns added: ``verdict_force_closure``, ``verdict_load_feasible`` (bool, see the
    module docstring); ``success`` (the one picked by ``success``); ``success_force``
    (optimal ‖f‖₂ in N under the weight where ``success``, NaN elsewhere); ``marginal``
    (success and success_force > marginal_multiple × weight; False when ``weights_N`` is
    None or lacks the object).

    Parameters
    ----------
    success : one of :data:`VERDICTS` (config ``analyses.success``); ``force_closure_bounded``
        needs ``weights_N`` for every object and a finite ``marginal_multiple``.
    weights_N : object name → weight m·g of the object, N.
    marginal_multiple : a success is marginal above this multiple of the weight
        (config ``analyses.marginal_weight_multiple``; none is marginal by default).
    """
    if success not in VERDICTS:
        raise ValueError(f"success must be one of {list(VERDICTS)}, got {success!r}")
    verdicts = verdict_columns(gfo)
    out = gfo.copy()
    out["verdict_force_closure"] = verdicts["force_closure"]
    out["verdict_load_feasible"] = verdicts["load_feasible"]
    weight = out["object"].map(dict(weights_N or {})).astype(float)
    above = (out["force_norm"] > marginal_multiple * weight).fillna(False).astype(bool)
    if success == "force_closure_bounded":
        if weights_N is None or weight.isna().any() or not math.isfinite(marginal_multiple):
            raise ValueError("success 'force_closure_bounded' needs every object's weight and a finite "
                             "marginal_multiple (config analyses.marginal_weight_multiple)")
        out["success"] = verdicts["force_closure"] & ~above
    else:
        out["success"] = verdicts[success]
    out["success_force"] = out["force_norm"].where(out["success"])
    out["marginal"] = out["success"] & above
    return out
