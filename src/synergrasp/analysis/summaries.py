"""Study summaries from the gfo table (docs/design.md schema): success rates, Table II, the
hierarchy matrices of Fig. 5, minimum preservation, and cross-checks. Columns are
documented in docs/analyses.md. Pure functions: DataFrames in, DataFrames out.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from synergrasp.config import incremental_set_id, set_id
from synergrasp.analysis.minima import preserved

__all__ = [
    "success_rates",
    "mean_over_objects",
    "incrementality_table",
    "hierarchy_matrices",
    "minimum_preservation",
    "full_but_not_first7",
    "verdict_disagreements",
    "set_sort_key",
    "study_tables",
]

ALL_OBJECTS = "all"


def set_sort_key(set_ids: pd.Series) -> pd.Series:
    """Sort key of set ids: by size, then by the synergy indices ("1-2" < "1-10" < "1-2-3")."""
    return set_ids.map(lambda s: (len(s.split("-")), tuple(int(x) for x in s.split("-"))))


def _require(table: pd.DataFrame, name: str, columns: Iterable[str]) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{name}: missing columns {missing}")


def success_rates(gfo: pd.DataFrame, full_set_id: str) -> pd.DataFrame:
    """Success rate and force summaries per object and synergy set.

    Returns one row per (object, set_id) with columns: object, set_id, n_synergies,
    n_poses, n_force_closure, success_rate (percent of the full set's force-closure count;
    NaN where the full set has none), full_set_empty (True there), absolute_share (percent
    of all poses), mean_force and median_force (N, over force-closure poses; NaN if none).
    """
    _require(gfo, "gfo table", ("object", "set_id", "n_synergies", "force_closure", "force_norm"))
    present = sorted(gfo["set_id"].unique(), key=lambda s: (len(s.split("-")), s))
    if full_set_id not in present:
        raise ValueError(f"full_set_id {full_set_id!r} is not in the gfo table; allowed values: {present}")
    fc = gfo["force_closure"].astype(bool)
    work = pd.DataFrame({"object": gfo["object"], "set_id": gfo["set_id"], "n_synergies": gfo["n_synergies"],
                         "fc": fc, "force": gfo["force_norm"].where(fc)})
    grouped = work.groupby(["object", "set_id"], sort=False)
    out = grouped.agg(n_synergies=("n_synergies", "first"), n_poses=("fc", "size"),
                      n_force_closure=("fc", "sum"), mean_force=("force", "mean"),
                      median_force=("force", "median")).reset_index()
    full = out[out["set_id"] == full_set_id].set_index("object")["n_force_closure"]
    full_count = out["object"].map(full).fillna(0).astype(float)
    out["full_set_empty"] = full_count == 0
    out["success_rate"] = np.where(full_count > 0, 100.0 * out["n_force_closure"] / full_count.where(full_count > 0),
                                   np.nan)
    out["absolute_share"] = 100.0 * out["n_force_closure"] / out["n_poses"]
    out["n_force_closure"] = out["n_force_closure"].astype("int64")
    out = out.sort_values(["object", "set_id"], key=lambda c: set_sort_key(c) if c.name == "set_id" else c,
                          ignore_index=True)
    return out[["object", "set_id", "n_synergies", "n_poses", "n_force_closure", "success_rate",
                "full_set_empty", "absolute_share", "mean_force", "median_force"]]


def mean_over_objects(rates: pd.DataFrame) -> pd.DataFrame:
    """Per set: success_rate, absolute_share, mean_force averaged over the objects where each
    is defined (NaN entries skipped), and n_objects (objects in the average of success_rate)."""
    _require(rates, "rates table", ("set_id", "n_synergies", "success_rate", "absolute_share", "mean_force"))
    rates = rates.assign(set_id=rates["set_id"].astype(str))  # a CSV round trip may read "1" as 1
    grouped = rates.groupby("set_id", sort=False)
    out = grouped.agg(n_synergies=("n_synergies", "first"), success_rate=("success_rate", "mean"),
                      absolute_share=("absolute_share", "mean"), mean_force=("mean_force", "mean"),
                      n_objects=("success_rate", "count")).reset_index()
    return out.sort_values("set_id", key=set_sort_key, ignore_index=True)


def incrementality_table(rates: pd.DataFrame, k_max: int) -> pd.DataFrame:
    """Table II: one row per object, columns k = 1..k_max: success rate (percent) with {S1..Sk}.

    A set missing from ``rates`` gives NaN. The first column is ``object``; the others are
    named by k (int).
    """
    _require(rates, "rates table", ("object", "set_id", "success_rate"))
    if not (isinstance(k_max, (int, np.integer)) and k_max >= 1):
        raise ValueError(f"k_max must be an integer >= 1; got {k_max!r}")
    wide = rates.pivot(index="object", columns="set_id", values="success_rate")
    table = pd.DataFrame({k: wide.get(incremental_set_id(k), pd.Series(np.nan, index=wide.index))
                          for k in range(1, k_max + 1)}, index=wide.index)
    return table.reset_index().rename_axis(columns=None)


def hierarchy_matrices(rates_mean_over_objects: pd.DataFrame, first: int = 7) -> pd.DataFrame:
    """Fig. 5 data: ``first`` matrices ``first`` × ``first`` in long form.

    Cell (i, j) of matrix k is the set {S_k, S_i, S_j}, duplicates collapsing ((k, k) is
    {S_k}; row k, column k and the diagonal are pairs). One row per (k, i, j), 1-based, with
    set_id, success_rate (percent) and mean_force (N) of that set (NaN if absent).
    """
    _require(rates_mean_over_objects, "rates table", ("set_id", "success_rate", "mean_force"))
    if rates_mean_over_objects["set_id"].duplicated().any():
        raise ValueError("rates table: one row per set_id is required (average over objects first)")
    if not (isinstance(first, (int, np.integer)) and first >= 1):
        raise ValueError(f"first must be an integer >= 1; got {first!r}")
    by_set = rates_mean_over_objects.set_index("set_id")
    rows = []
    for k in range(1, first + 1):
        for i in range(1, first + 1):
            for j in range(1, first + 1):
                sid = set_id((k, i, j))
                present = sid in by_set.index
                rows.append({"k": k, "i": i, "j": j, "set_id": sid,
                             "success_rate": by_set.at[sid, "success_rate"] if present else np.nan,
                             "mean_force": by_set.at[sid, "mean_force"] if present else np.nan})
    return pd.DataFrame(rows).astype({"success_rate": float, "mean_force": float})


def minimum_preservation(gfo: pd.DataFrame, minima_table: pd.DataFrame, k_max: int,
                         radius_deg: float = 10.0, alpha_period_deg: float = 360.0) -> pd.DataFrame:
    """Preservation of the local minima of {S1..Sk} in {S1..Sk+1}, k = 1..k_max-1.

    One row per object and k, then per object a total over k (k = <NA>), then the same for
    all objects together (object = "all"). Columns: object, k, n_minima, n_preserved,
    preserved_percent (NaN where there are no minima).
    """
    _require(gfo, "gfo table", ("object",))
    _require(minima_table, "minima table", ("object", "set_id", "alpha_deg", "beta_deg"))
    if not (isinstance(k_max, (int, np.integer)) and k_max >= 2):
        raise ValueError(f"k_max must be an integer >= 2; got {k_max!r}")
    objects = sorted(set(gfo["object"]) | set(minima_table["object"]))
    rows = []
    for obj in objects:
        mins = minima_table[minima_table["object"] == obj]
        for k in range(1, k_max):
            this = mins[mins["set_id"] == incremental_set_id(k)]
            nxt = mins[mins["set_id"] == incremental_set_id(k + 1)]
            kept = preserved(this["alpha_deg"].to_numpy(float), this["beta_deg"].to_numpy(float),
                             nxt["alpha_deg"].to_numpy(float), nxt["beta_deg"].to_numpy(float),
                             radius_deg, alpha_period_deg)
            rows.append({"object": obj, "k": k, "n_minima": len(this), "n_preserved": int(kept.sum())})
    per_k = pd.DataFrame(rows, columns=["object", "k", "n_minima", "n_preserved"])
    totals = per_k.groupby("object", sort=True)[["n_minima", "n_preserved"]].sum().reset_index()
    totals["k"] = pd.NA
    all_k = per_k.groupby("k", sort=True)[["n_minima", "n_preserved"]].sum().reset_index()
    all_k["object"] = ALL_OBJECTS
    grand = pd.DataFrame([{"object": ALL_OBJECTS, "k": pd.NA, "n_minima": per_k["n_minima"].sum(),
                           "n_preserved": per_k["n_preserved"].sum()}])
    parts = []
    for obj in objects:
        parts += [per_k[per_k["object"] == obj], totals[totals["object"] == obj]]
    parts += [all_k, grand]
    out = pd.concat([p for p in parts if len(p)], ignore_index=True)[["object", "k", "n_minima", "n_preserved"]]
    out = out.astype({"k": "Int64", "n_minima": "int64", "n_preserved": "int64"})
    out["preserved_percent"] = (100.0 * out["n_preserved"] / out["n_minima"].where(out["n_minima"] > 0)).astype(float)
    return out


def full_but_not_first7(gfo: pd.DataFrame, full_set_id: str, first7_set_id: str) -> pd.DataFrame:
    """Poses where the full set reaches force closure and {S1..S7} does not.

    Columns: object, pose, alpha_deg, beta_deg, full_force_norm (N), first7_status
    (the smaller set's status; "missing" if it was not computed at that pose).
    """
    _require(gfo, "gfo table", ("object", "pose", "alpha_deg", "beta_deg", "set_id", "status",
                                "force_closure", "force_norm"))
    present = set(gfo["set_id"])
    for name, sid in (("full_set_id", full_set_id), ("first7_set_id", first7_set_id)):
        if sid not in present:
            raise ValueError(f"{name} {sid!r} is not in the gfo table; allowed values: {sorted(present)}")
    keys = ["object", "pose"]
    full = gfo[(gfo["set_id"] == full_set_id) & gfo["force_closure"].astype(bool)]
    small = gfo.loc[gfo["set_id"] == first7_set_id, keys + ["status", "force_closure"]]
    merged = full.merge(small, on=keys, how="left", suffixes=("", "_first7"))
    missing = merged["force_closure_first7"].isna()
    lost = merged[missing | ~merged["force_closure_first7"].fillna(False).astype(bool)]
    out = pd.DataFrame({
        "object": lost["object"], "pose": lost["pose"], "alpha_deg": lost["alpha_deg"],
        "beta_deg": lost["beta_deg"], "full_force_norm": lost["force_norm"],
        "first7_status": lost["status_first7"].fillna("missing"),
    })
    return out.sort_values(keys, ignore_index=True)


def verdict_disagreements(gfo: pd.DataFrame) -> pd.DataFrame:
    """Where the optimisation verdict (force_closure) and Bicchi's strict internal-force test
    (strict_internal) disagree, per object and set (only groups with a disagreement).

    Columns: object, set_id, n_synergies, n_poses, n_disagree, n_fc_not_strict,
    n_strict_not_fc, disagree_percent (of the group's poses).
    """
    _require(gfo, "gfo table", ("object", "set_id", "n_synergies", "force_closure", "strict_internal"))
    fc = gfo["force_closure"].astype(bool)
    strict = gfo["strict_internal"].astype(bool)
    work = pd.DataFrame({"object": gfo["object"], "set_id": gfo["set_id"], "n_synergies": gfo["n_synergies"],
                         "fc_not_strict": fc & ~strict, "strict_not_fc": strict & ~fc})
    out = work.groupby(["object", "set_id"], sort=False).agg(
        n_synergies=("n_synergies", "first"), n_poses=("fc_not_strict", "size"),
        n_fc_not_strict=("fc_not_strict", "sum"), n_strict_not_fc=("strict_not_fc", "sum")).reset_index()
    out["n_disagree"] = out["n_fc_not_strict"] + out["n_strict_not_fc"]
    out = out[out["n_disagree"] > 0].copy()
    out["disagree_percent"] = 100.0 * out["n_disagree"] / out["n_poses"]
    out = out.sort_values(["object", "set_id"], key=lambda c: set_sort_key(c) if c.name == "set_id" else c,
                          ignore_index=True)
    cols = ["object", "set_id", "n_synergies", "n_poses", "n_disagree", "n_fc_not_strict", "n_strict_not_fc",
            "disagree_percent"]
    return out[cols].astype({c: "int64" for c in cols[3:7]})


def study_tables(gfo: pd.DataFrame, minima: pd.DataFrame, sets_config: dict, table2_k_max: int,
                 radius_deg: float = 10.0) -> dict[str, tuple[str, pd.DataFrame]]:
    """Every study table by name: (title, table).

    ``sets_config`` is the configuration's ``synergy_sets`` (incremental_max,
    hierarchy_first, ...): the full set is {S1..S_incremental_max}, the hierarchy uses the
    first ``hierarchy_first`` synergies.
    """
    k_max = int(sets_config["incremental_max"])
    first = int(sets_config["hierarchy_first"])
    full = incremental_set_id(k_max)
    first_n = incremental_set_id(first)
    rates = success_rates(gfo, full)
    if first_n in set(gfo["set_id"]):
        lost = full_but_not_first7(gfo, full, first_n)
    else:
        lost = pd.DataFrame(columns=["object", "pose", "alpha_deg", "beta_deg", "full_force_norm", "first7_status"])
    return {
        "success_rates": ("Success rate and optimal force per object and synergy set", rates),
        "table2_success_rates": (f"Table II: success rate (%) with {{S1..Sk}}, k = 1..{table2_k_max}",
                                 incrementality_table(rates, table2_k_max)),
        "hierarchy": (f"Hierarchy: sets {{S_k, S_i, S_j}} of the first {first} synergies, mean over objects",
                      hierarchy_matrices(mean_over_objects(rates), first)),
        "minimum_preservation": ("Local minima of {S1..Sk} preserved in {S1..Sk+1}",
                                 minimum_preservation(gfo, minima, k_max, radius_deg)),
        "full_not_first7": (f"Poses where {{S1..S{k_max}}} is force closure and {{S1..S{first}}} is not", lost),
        "verdict_disagreements": ("Optimisation verdict vs strict internal-force test", verdict_disagreements(gfo)),
    }
