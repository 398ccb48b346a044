"""The study across many objects (docs/random_objects.md): one row per object of what the
study's claims and the planner measure on it, and their distribution over objects with
percentile-bootstrap intervals over objects.

Per object (tables of the study, the planner's and the graspable-objects table):

- ``preserved_percent``: share of the local minima of {S1..Sk} kept by {S1..Sk+1}, all k
  (claim 3; the ``minimum_preservation`` total row);
- ``s1_minus_best_other``: success rate of {S1} minus the best other single synergy of the
  first ``hierarchy_first`` (claim 4; percentage points of the full set's successes);
- ``k_full``: the least k at which {S1..Sk} succeeds at every distinct pose where the full
  set does (claims 1, 2; NaN: never below the full set); ``greedy_k_full`` the same for the
  greedy enrollment order;
- per planner radius r: ``solve_share_percent_r``, ``regret_percent_r``, ``global_min_r``.

Across objects: the mean of each (the share of objects for a yes/no), its median, and a 95 %
percentile interval of the mean from resampling objects with replacement.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from synergrasp.ids import incremental_set_id, set_id

__all__ = [
    "ObjectsSummaryParams",
    "object_rows",
    "planner_budget",
    "planner_columns",
    "SOLVE_SHARE_BUDGET",
    "REGRET_BUDGET",
    "across_objects",
    "RESAMPLES",
    "SEED",
]

#: The planner's aims (docs/planner.md): at most this share of the exhaustive solves (%), and a
#: pose whose force is at most this far above the exhaustive minimum (%).
SOLVE_SHARE_BUDGET, REGRET_BUDGET = 20.0, 5.0

#: Bootstrap over objects: resamples and the seed of numpy.random.default_rng.
RESAMPLES, SEED = 1000, 2018


def object_rows(
    success_rates: pd.DataFrame,
    preservation: pd.DataFrame,
    graspable: pd.DataFrame,
    plans: pd.DataFrame,
    enrollment: pd.DataFrame,
    n_full: int,
    hierarchy_first: int,
) -> pd.DataFrame:
    """One row per object of ``graspable`` (the study's tables as written, concatenated plan and
    enrollment tables of every object)."""
    rates = success_rates[success_rates["view"] == "object"].set_index(["object", "set_id"])["success_rate"]
    total = preservation[preservation["k"].isna()].set_index("object")["preserved_percent"]
    rows = []
    for obj in graspable["object"]:
        row: dict[str, object] = {"object": obj}
        g = graspable.set_index("object").loc[obj]
        row["graspable"], row["reason"] = bool(g["graspable"]), str(g["reason"]) if isinstance(g["reason"], str) else ""
        row["force_closure_full_set"] = int(g["force_closure_full_set"])
        row["preserved_percent"] = float(total.get(obj, np.nan))
        singles = [float(rates.get((obj, set_id([s])), np.nan)) for s in range(1, hierarchy_first + 1)]
        row["s1_rate"] = singles[0]
        row["s1_minus_best_other"] = singles[0] - np.nanmax(singles[1:]) if np.isfinite(singles[1:]).any() else np.nan
        incremental = [float(rates.get((obj, incremental_set_id(k)), np.nan)) for k in range(1, n_full + 1)]
        row["k_full"] = _first_full(incremental)
        mine = enrollment[enrollment["object"] == obj].sort_values("k")
        row["greedy_k_full"] = _first_full(mine["greedy_success_rate"].tolist()) if len(mine) else np.nan
        row["greedy_order"] = "-".join(str(s) for s in mine["greedy_added"]) if len(mine) else ""
        for plan in plans[plans["object"] == obj].itertuples():
            r = f"{plan.radius_deg:g}"
            row[f"solve_share_percent_{r}"] = plan.solve_share_percent
            row[f"regret_percent_{r}"] = plan.regret_percent
            row[f"global_min_{r}"] = bool(plan.is_global_min) if plan.best_pose >= 0 else np.nan
        rows.append(row)
    return pd.DataFrame(rows)


def planner_columns(rows: pd.DataFrame, radius_deg: float) -> tuple[pd.Series, pd.Series]:
    """The planner's share of the exhaustive solves and its force regret (both %) at
    ``radius_deg``, per row of the summary (NaN where there is no plan or no column)."""
    return tuple(
        pd.to_numeric(rows[c], errors="coerce") if c in rows else pd.Series(np.nan, index=rows.index)
        for c in (f"solve_share_percent_{radius_deg:g}", f"regret_percent_{radius_deg:g}")
    )


def planner_budget(rows: pd.DataFrame, radii: Sequence[float]) -> pd.DataFrame:
    """Per planner radius (deg): the objects with a plan, and how many use at most
    ``SOLVE_SHARE_BUDGET`` % of the exhaustive solves, find a pose within ``REGRET_BUDGET`` %
    of the exhaustive minimum's force, and both; ``every_object_within_regret``: the regret aim
    met on every object with a plan (the rule that chooses the radius, docs/planner.md)."""
    out = []
    for r in radii:
        share, regret = planner_columns(rows, r)
        planned = share.notna() & regret.notna()
        cheap, close = planned & (share <= SOLVE_SHARE_BUDGET), planned & (regret <= REGRET_BUDGET)
        out.append(
            {
                "radius_deg": float(r),
                "objects": int(planned.sum()),
                "within_solves": int(cheap.sum()),
                "within_regret": int(close.sum()),
                "within_both": int((cheap & close).sum()),
                "every_object_within_regret": bool(planned.any() and close[planned].all()),
            }
        )
    return pd.DataFrame(out)


def _first_full(rates: Sequence[float]) -> float:
    """1-based index of the first rate at 100 % (to 1e-9), NaN if none."""
    for k, rate in enumerate(rates, start=1):
        if np.isfinite(rate) and rate >= 100.0 - 1e-9:
            return float(k)
    return float("nan")


def across_objects(rows: pd.DataFrame, columns: Sequence[str]) -> pd.DataFrame:
    """Per column: objects with a value, mean (a share in % for yes/no columns), median, and a
    95 % percentile interval of the mean over ``RESAMPLES`` resamples of the objects."""
    rng = np.random.default_rng(SEED)
    out = []
    for column in columns:
        values = pd.to_numeric(rows[column], errors="coerce").to_numpy(float) if column in rows else np.zeros(0)
        values = values[np.isfinite(values)]
        share = column.startswith("global_min")
        scale = 100.0 if share else 1.0
        if values.size:
            draws = rng.integers(0, values.size, size=(RESAMPLES, values.size))
            means = values[draws].mean(axis=1) * scale
            low, high = np.percentile(means, [2.5, 97.5])
            mean, median = values.mean() * scale, float(np.median(values)) * scale
        else:
            low = high = mean = median = np.nan
        out.append(
            {
                "quantity": column,
                "unit": "% of objects" if share else _unit(column),
                "n_objects": values.size,
                "mean": mean,
                "low": low,
                "high": high,
                "median": median,
            }
        )
    return pd.DataFrame(out)


def _unit(column: str) -> str:
    if column.startswith(("k_full", "greedy_k_full")):
        return "synergies"
    if column.startswith("s1_minus"):
        return "percentage points"
    return "%"


@dataclass(frozen=True)
class ObjectsSummaryParams:
    """The ``objects_summary`` step: the full set's size, the hierarchy's first synergies, the
    planner's radii (deg) and the ``random_objects`` block (None: the configured objects)."""

    n_full: int
    hierarchy_first: int
    radii_deg: tuple[float, ...]
    random_objects: dict | None

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> ObjectsSummaryParams:
        """From a configuration or the step's own part of it."""
        sets = config["synergy_sets"]
        return cls(
            int(sets["incremental_max"]),
            int(sets["hierarchy_first"]),
            tuple(float(r) for r in config["analyses"]["planner_radii_deg"]),
            config.get("random_objects"),
        )

    def quantities(self) -> list[str]:
        """The columns summarised across objects."""
        return [
            "preserved_percent",
            "s1_minus_best_other",
            "k_full",
            "greedy_k_full",
            *(f"{q}_{r:g}" for r in self.radii_deg for q in ("solve_share_percent", "regret_percent", "global_min")),
        ]
