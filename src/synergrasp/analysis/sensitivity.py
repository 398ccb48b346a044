"""The study's findings across scenarios: one row per scenario of a sensitivity sweep.

Each scenario (config/README.md) is a complete study; this module gathers, from each one's
claims table, Table II, success-rate table, minimum-preservation table and grasp-realism
table, the figures a reader needs to see which findings survive which modelling choice, and
on which grasps (docs/sensitivity.md). Success rates and shares are in percent.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from synergrasp.analysis.chance import ALL_PAIRS
from synergrasp.ids import ALL_OBJECTS

__all__ = [
    "ScenarioTables",
    "scenario_row",
    "sensitivity_table",
    "table2_long",
    "TABLE2_ROWS",
    "SINGLE_SYNERGIES",
    "REALISM_COLUMNS",
]

#: Table II's k shown in the summary (k = 1, 2, 3: where the study's curves rise).
TABLE2_ROWS: tuple[int, ...] = (1, 2, 3)
#: Single-synergy success rates S1..S7 shown in the summary.
SINGLE_SYNERGIES: tuple[int, ...] = tuple(range(1, 8))


@dataclass(frozen=True)
class ScenarioTables:
    """One scenario's study tables, as read from its tables/*.csv."""

    claims: pd.DataFrame  #: claim, statement, tested_by, measured, verdict
    table2: pd.DataFrame  #: object, then one column per k (success rate, %)
    success_rates: pd.DataFrame  #: object, set_id, n_synergies, success_rate (%), ...
    preservation: pd.DataFrame  #: object, pairs, preserved_percent, ...
    realism: pd.DataFrame | None = None  #: table_contracts.GRASP_REALISM: one row per object


#: The grasp-realism columns in the summary (table_contracts.GRASP_REALISM), each object's value in the
#: scenario's object order joined by "/": what the grasps behind a row's verdicts look like.
REALISM_COLUMNS: dict[str, tuple[str, str]] = {
    "grasp_contacts_median": ("contacts_median", "{:.0f}"),
    "grasp_palm_percent": ("pct_palm", "{:.0f}"),
    "grasp_thumb_percent": ("pct_thumb", "{:.0f}"),
    "grasp_index_percent": ("pct_index", "{:.0f}"),
    "grasp_force_closure_percent": ("pct_force_closure", "{:.0f}"),
    "grasp_force_per_weight_median": ("median_force_per_weight", "{:.2f}"),
}


def _k_column(table2: pd.DataFrame, k: int) -> pd.Series:
    """Table II's column k (CSV headers are text), indexed by object; empty when absent."""
    table = table2.set_index("object")
    for name in (k, str(k)):
        if name in table.columns:
            return table[name].astype(float)
    return pd.Series(dtype=float)


def _single_rate(success_rates: pd.DataFrame, synergy: int, view: str = "per_object") -> float:
    """Success rate (%) of the set {S<synergy>} alone, averaged over objects in ``view`` (its
    row of the table; a table without view rows: the mean over objects); NaN if absent."""
    rows = success_rates[success_rates["set_id"].astype(str) == str(synergy)]
    if "view" in rows.columns:
        chosen = rows[rows["view"] == view]
        if len(chosen):
            return float(chosen["success_rate"].iloc[0])
        rows = rows[rows["view"] == "object"]
    return float(rows["success_rate"].mean()) if len(rows) else np.nan


def _interval(claim: pd.Series) -> str:
    """A claim row's compared difference with its interval, in the row's unit."""
    if "difference" not in claim.index or not np.isfinite(claim["difference"]):
        return "—"
    scale = np.exp if claim.get("unit") == "log force ratio" else (lambda v: v)
    name = "force ratio" if claim.get("unit") == "log force ratio" else "pp"
    return f"{scale(claim['difference']):.3g} [{scale(claim['low']):.3g}, {scale(claim['high']):.3g}] {name}"


def _preservation_share(preservation: pd.DataFrame) -> float:
    """Share (%) of local minima preserved over all objects and pairs; NaN if none."""
    if "pairs" in preservation.columns:
        row = preservation[(preservation["object"] == ALL_OBJECTS) & (preservation["pairs"] == ALL_PAIRS)]
        if len(row):
            return float(row["preserved_percent"].iloc[0])
    total = preservation["n_minima"].sum() if "n_minima" in preservation.columns else 0
    return float(100.0 * preservation["n_preserved"].sum() / total) if total else np.nan


def scenario_row(name: str, tables: ScenarioTables) -> dict[str, object]:
    """One scenario's summary: per claim its headline verdict, the compared difference with its
    interval, the reason, the other view's verdict and the figures behind it; Table II at
    k = 1, 2, 3 per object; S1..S7 alone (the study's view); minima preserved (%); the grasps'
    realism per object (REALISM_COLUMNS)."""
    row: dict[str, object] = {"scenario": name}
    claims = tables.claims
    headline = claims[claims["headline"].astype(bool)] if "headline" in claims.columns else claims
    for _, claim in headline.iterrows():
        n = claim["claim"]
        row[f"claim{n}_verdict"] = claim["verdict"]
        if "difference" in claim.index:
            row[f"claim{n}_interval"] = _interval(claim)
            row[f"claim{n}_reason"] = claim["reason"]
            other = claims[(claims["claim"] == n) & (claims["view"] != claim["view"])]
            if len(other):
                row[f"claim{n}_{other['view'].iloc[0]}_verdict"] = other["verdict"].iloc[0]
        row[f"claim{n}_measured"] = claim["measured"]
    for k in TABLE2_ROWS:
        column = _k_column(tables.table2, k)
        for obj, rate in column.items():
            row[f"table2_k{k}_{obj}"] = float(rate)
    for synergy in SINGLE_SYNERGIES:
        row[f"S{synergy}_success_percent"] = _single_rate(tables.success_rates, synergy)
    row["minima_preserved_percent"] = _preservation_share(tables.preservation)
    if tables.realism is not None:
        row.update(_realism_row(tables.realism))
    return row


def _realism_row(realism: pd.DataFrame) -> dict[str, str]:
    """The grasp-realism summary (REALISM_COLUMNS) of one scenario: per column, each object's
    value joined by "/" (NaN: "—")."""
    return {
        name: "/".join("—" if pd.isna(v) else fmt.format(v) for v in realism[column])
        for name, (column, fmt) in REALISM_COLUMNS.items()
        if column in realism.columns
    }


def sensitivity_table(scenarios: Mapping[str, ScenarioTables]) -> pd.DataFrame:
    """One row per scenario (in the given order, ``default`` first by convention); a claim or
    object a scenario lacks is empty (NaN) in its row."""
    if not scenarios:
        raise ValueError("sensitivity summary: no scenarios given")
    return pd.DataFrame([scenario_row(name, tables) for name, tables in scenarios.items()])


def table2_long(scenarios: Mapping[str, ScenarioTables]) -> pd.DataFrame:
    """Table II of every scenario in long form: scenario, object, k, success_rate (%)."""
    frames = []
    for name, tables in scenarios.items():
        long = tables.table2.melt(id_vars="object", var_name="k", value_name="success_rate")
        long.insert(0, "scenario", name)
        frames.append(long)
    out = pd.concat(frames, ignore_index=True)
    out["k"] = out["k"].astype(int)
    return out
