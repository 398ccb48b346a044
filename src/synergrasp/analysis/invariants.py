"""The pipeline's own invariant checks on its results.

- Nested sets: a pose where a set succeeds and a superset of it does not is impossible in
  exact arithmetic (the superset's internal forces include the set's); each is counted as a
  numerical inconsistency and warned about, naming the object and the sets.
- Success rate: a rate above 100 % means a subset succeeded where the full set did not. Up
  to ``tolerance_percent`` above 100 it is a warning (near-boundary verdicts can differ);
  beyond it the run stops with :class:`InvariantError` (a wrong input, e.g. a synergy entry
  of 1e300, must not give a table).
- Force closure implies load feasibility (the optimal force under the weight exists);
  the poses where it does not are counted.
- α-period: the poses whose results do not repeat with the object's period are counted.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

from synergrasp.analysis.periods import period_violations
from synergrasp.ids import set_members

__all__ = [
    "InvariantError",
    "InvariantWarning",
    "check_success_rates",
    "superset_inconsistencies",
    "invariant_checks",
    "object_checks",
    "reported_checks",
]

CHECK_COLUMNS = ["check", "object", "count", "detail"]
_SHOWN = 5  # offending set pairs named per object in the table and the warning


class InvariantError(ValueError):
    """A result that cannot be right (e.g. a success rate far above 100 %)."""


class InvariantWarning(UserWarning):
    """A numerical inconsistency in the results (counted in the invariant-checks table)."""


def check_success_rates(rates: pd.DataFrame, tolerance_percent: float) -> list[str]:
    """Rates above 100 %: raise :class:`InvariantError` beyond ``tolerance_percent``
    (percentage points), else return one warning message per offending row."""
    over = rates[rates["success_rate"] > 100.0]
    far = over[over["success_rate"] > 100.0 + tolerance_percent]
    if len(far):
        listed = ", ".join(f"{r.object} {{{r.set_id}}}: {r.success_rate:.4g} %" for r in far.head(_SHOWN).itertuples())
        raise InvariantError(
            f"success rate above 100 % + analyses.success_rate_tolerance_percent ({tolerance_percent}) in "
            f"{len(far)} (object, set) rows ({listed}): a set succeeds on poses where the full set does not; "
            "check the synergy file and the solver settings"
        )
    return [
        f"success rate {r.success_rate:.4g} % (above 100 %, within the tolerance) for {r.object} {{{r.set_id}}}"
        for r in over.itertuples()
    ]


def superset_inconsistencies(table: pd.DataFrame, column: str = "success") -> pd.DataFrame:
    """Per object and (set, strict superset) pair present in ``table``: poses where
    ``column`` is True for the set and False for the superset. Only pairs with such poses;
    columns object, set_id, superset_id, n_poses."""
    rows = []
    for obj, own in table.groupby("object", sort=True):
        wide = own.pivot(index="pose", columns="set_id", values=column)
        members = {s: frozenset(set_members(s)) for s in wide.columns}
        values = {s: wide[s].fillna(False).to_numpy(bool) for s in wide.columns}
        for small, small_set in members.items():
            for big, big_set in members.items():
                if small_set < big_set:
                    n = int((values[small] & ~values[big]).sum())
                    if n:
                        rows.append({"object": obj, "set_id": small, "superset_id": big, "n_poses": n})
    return pd.DataFrame(rows, columns=["object", "set_id", "superset_id", "n_poses"])


def _row(check: str, obj: str, count: int, detail: str) -> dict:
    return {"check": check, "object": obj, "count": int(count), "detail": detail}


def invariant_checks(
    table: pd.DataFrame, rates: pd.DataFrame, periods: dict[str, float], tolerance_percent: float
) -> pd.DataFrame:
    """Every check, one row per (check, object): count of offending items and a detail.
    Raises :class:`InvariantError` for a success rate beyond the tolerance; warns
    (``warnings.warn``) for every other non-zero count."""
    messages = check_success_rates(rates, tolerance_percent)
    rows = []
    for obj in sorted(set(table["object"].unique())):
        rows += object_checks(obj, table[table["object"] == obj], rates, float(periods.get(obj, 360.0)), tolerance_percent)
    return reported_checks(rows, messages)


def object_checks(obj: str, own: pd.DataFrame, rates: pd.DataFrame, period: float, tolerance_percent: float) -> list[dict]:
    """The rows of :func:`invariant_checks` of one object: ``own`` its gfo table with its
    verdicts, ``rates`` a success-rates table holding its rows, ``period`` its α-period (deg)."""
    rows = []
    bad = superset_inconsistencies(own).sort_values("n_poses", ascending=False)
    named = "; ".join(
        f"{{{r.set_id}}} succeeds, {{{r.superset_id}}} does not: {r.n_poses} poses" for r in bad.head(_SHOWN).itertuples()
    )
    rows.append(
        _row(
            "nested_sets",
            obj,
            bad["n_poses"].sum(),
            f"{len(bad)} (set, superset) pairs; {named}" if len(bad) else "success is monotone in the sets",
        )
    )
    beyond = own["force_beyond_solver"] if "force_beyond_solver" in own else pd.Series(False, index=own.index)
    lost = own["verdict_force_closure"] & ~np.isfinite(own["force_norm"].to_numpy(float)) & ~beyond
    rows.append(
        _row(
            "force_closure_has_optimal_force",
            obj,
            lost.sum(),
            "force-closure (pose, set) rows without an optimal force under the weight, unexplained",
        )
    )
    explained = own[beyond.to_numpy(bool)]
    listed = "; ".join(
        f"{{{r.set_id}}} at alpha {r.alpha_deg:g}, beta {r.beta_deg:g}: a superset needs {r.force_lower_bound_N:.0f} N"
        for r in explained.head(_SHOWN).itertuples()
    )
    rows.append(
        _row(
            "force_beyond_solver",
            obj,
            len(explained),
            (
                "force closure whose optimal force under the weight exceeds the solver's accuracy (no "
                "force; a superset at the pose already needs more than the bound): reclassified "
                f"load-feasible, never bounded (not a warning); {listed}"
            )
            if len(explained)
            else "none",
        )
    )
    broken = period_violations(own, period)
    poses = broken[["alpha_deg", "beta_deg"]].drop_duplicates()
    rows.append(
        _row(
            "alpha_period",
            obj,
            len(poses),
            f"period {period:g} deg: {len(poses)} poses whose results differ at alpha + period ({len(broken)} (pose, set) rows)",
        )
    )
    over = rates[(rates["object"] == obj) & (rates["success_rate"] > 100.0)]
    rows.append(
        _row(
            "success_rate_at_most_100",
            obj,
            len(over),
            f"sets above 100 %, within the tolerance of {tolerance_percent} percentage points"
            if len(over)
            else "no rate above 100 %",
        )
    )
    return rows


def reported_checks(rows: list[dict], messages: list[str]) -> pd.DataFrame:
    """The invariant-checks table of every object's :func:`object_checks` rows; warns
    (``warnings.warn``) ``messages`` (:func:`check_success_rates`'s) and every other non-zero count."""
    out = pd.DataFrame(rows, columns=CHECK_COLUMNS)
    for r in out[(out["count"] > 0) & (out["check"] != "force_beyond_solver")].itertuples():
        messages.append(f"invariant check {r.check} ({r.object}): {r.count} — {r.detail}")
    for message in messages:
        warnings.warn(message, InvariantWarning, stacklevel=2)
    return out
