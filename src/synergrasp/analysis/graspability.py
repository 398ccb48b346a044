"""Which objects the study can grasp at all, and why not: the graspable-objects table.

An object whose every pose fails at one stage leaves its rows of Table II undefined (NaN);
this table says so per object with the first stage at which every pose failed:

1. ``every pose dropped``: no closure ran (the box intersects the open hand at every pose, or
   the closure model dropped it: ``caged``/``lost``; counts per status);
2. ``nothing touched``: closures ran and no link touches the box at the end of any;
3. ``no pose settled``: (dynamic closure) touching grasps exist but none came to rest before
   ``closure.dynamic.time_limit_s``, and none reaches force closure with the full set;
4. ``no force closure with the full set``: touching grasps exist, none is in force closure
   (the study's definition, ``analysis.verdicts``) with every synergy enrolled.

Columns: :data:`synergrasp.table_contracts.GRASPABLE_OBJECTS`. Pure functions: DataFrames in, a
DataFrame (or lines) out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from synergrasp.analysis.verdicts import verdict_columns
from synergrasp.ids import set_members, set_name
from synergrasp.table_contracts import GRASPABLE_OBJECTS

__all__ = ["graspable_objects", "with_left_out", "studied", "ungraspable_lines", "grasp_types_of", "fallback_lines", "LEFT_OUT"]

#: How the reason of an object left out before the study begins.
LEFT_OUT = "left out: "

#: Statuses of a closure that ran (synergrasp.simulation.contacts.CLOSURE_STATUSES).
_RAN = ("grasp", "no_contact")


def _counts(statuses: pd.Series) -> str:
    return ", ".join(f"{s}: {c}" for s, c in statuses.value_counts().sort_index().items())


def _set_name(set_id: str) -> str:
    return set_name(set_members(set_id))


def _reason(rows: pd.DataFrame, n_fc: int, dynamic: bool, full_set_id: str) -> str:
    ran = rows["status"].isin(_RAN)
    grasps = rows["status"] == "grasp"
    if not ran.any():
        return f"every pose dropped ({_counts(rows['status'])})"
    if not grasps.any():
        return f"nothing touched: no closure ends touching the box ({_counts(rows['status'])})"
    if n_fc:
        return ""
    if dynamic and not rows.loc[grasps, "settled"].astype(bool).any():
        return (
            "no pose settled: every closure stopped at closure.dynamic.time_limit_s, and no force closure "
            f"with the full set {_set_name(full_set_id)}"
        )
    return f"no force closure with the full set {_set_name(full_set_id)} at any of the {int(grasps.sum())} grasps"


def grasp_types_of(grasp_types: Mapping[str, str], placements: Sequence[pd.DataFrame]) -> dict[str, tuple[str, str, str]]:
    """Per object (stated, effective, reason): the chosen row of its placement-search table
    (``table_contracts.PLACEMENT``; version 3 of docs/placement_search.md) where its placement was
    searched, else its configured grasp type ``grasp_types[object]`` both stated and effective."""
    out = {name: (kind, kind, "") for name, kind in grasp_types.items()}
    for table in placements:
        row = table[table["chosen"].astype(bool)].iloc[0]
        reason = "" if pd.isna(row["type_reason"]) else str(row["type_reason"])
        out[str(row["object"])] = (str(row["stated_type"]), str(row["effective_type"]), reason)
    return out


def fallback_lines(table: pd.DataFrame) -> list[str]:
    """One line per object of a graspable-objects table whose effective grasp type is not its
    stated one (version 3's fallback), with the reason."""
    return [
        f"{row.object}: stated grasp type {row.stated_type}, effective {row.effective_type} ({row.type_reason})"
        for row in table.itertuples()
        if row.stated_type != row.effective_type
    ]


def graspable_objects(
    contacts: pd.DataFrame, gfo: pd.DataFrame, full_set_id: str, types: Mapping[str, tuple[str, str, str]] | None = None
) -> pd.DataFrame:
    """One row per object of ``contacts`` (contacts tables of every object): poses, closures
    that ran, touching grasps, grasps that settled, force-closure poses with the full set
    ``full_set_id`` (from ``gfo``), whether any pose is graspable and, if none is, why; its
    stated and effective grasp type and the reason they differ (``types``: :func:`grasp_types_of`)."""
    types = types or {}
    full = gfo[gfo["set_id"].astype(str) == full_set_id]
    fc = full.loc[verdict_columns(full)["force_closure"], "object"].value_counts() if len(full) else pd.Series()
    rows = []
    for obj, group in contacts.groupby("object", sort=True):
        n_fc = int(fc.get(obj, 0))
        dynamic = bool((group["closure_model"] == "dynamic").any())
        grasps = group["status"] == "grasp"
        reason = _reason(group, n_fc, dynamic, full_set_id)
        rows.append(
            {
                "object": obj,
                "poses": len(group),
                "simulated": int(group["status"].isin(_RAN).sum()),
                "grasps": int(grasps.sum()),
                "settled": int(group.loc[grasps, "settled"].astype(bool).sum()),
                "force_closure_full_set": n_fc,
                "graspable": not reason,
                "reason": reason,
                **dict(zip(("stated_type", "effective_type", "type_reason"), types.get(obj, ("", "", "")))),
            }
        )
    return pd.DataFrame(rows, columns=list(GRASPABLE_OBJECTS.names))


def with_left_out(table: pd.DataFrame, left_out: Sequence[tuple[str, str]]) -> pd.DataFrame:
    """A graspable-objects table with one more row per (object, reason) left out before the
    study (a drawn mesh that cannot be read, is degenerate or differs from its manifest):
    nothing simulated, not graspable, reason ``left out: <reason>``."""
    extra = pd.DataFrame(
        [
            {
                "object": name,
                "poses": 0,
                "simulated": 0,
                "grasps": 0,
                "settled": 0,
                "force_closure_full_set": 0,
                "graspable": False,
                "reason": f"{LEFT_OUT}{reason}",
                "stated_type": "",
                "effective_type": "",
                "type_reason": "",
            }
            for name, reason in left_out
        ],
        columns=list(GRASPABLE_OBJECTS.names),
    )
    return pd.concat([table, extra], ignore_index=True) if len(extra) else table


def studied(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of a table with a ``reason`` column (graspable objects, the summary per object)
    whose object was studied, not left out before the study."""
    return table[~table["reason"].fillna("").astype(str).str.startswith(LEFT_OUT)]


def ungraspable_lines(table: pd.DataFrame) -> list[str]:
    """One line per object of a graspable-objects table that can never be grasped."""
    return [f"{row.object} can never be grasped: {row.reason}" for row in table.itertuples() if not row.graspable]
