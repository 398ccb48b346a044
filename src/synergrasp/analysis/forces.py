"""Force comparisons that compare like with like: each set against the full set on the same pose.

Synergy sets succeed on different poses (a set of weak synergies only on the easiest
ones), so a plain mean of the optimal force over a set's successes compares different
grasps. The *paired force ratio* of a set at a pose is its optimal force divided by the
full set's optimal force at the same pose; it is defined wherever the set succeeds and the
full set has an optimal force there (always, in exact arithmetic: the full set's
internal forces include the set's), and it is ≥ 1 up to solver tolerance. Per object and set
the tables give its median; over objects, the mean of those medians.

Forces in N; ratios dimensionless.
"""

from __future__ import annotations

import pandas as pd

__all__ = ["paired_force_ratio", "force_summary"]


def paired_force_ratio(table: pd.DataFrame, full_set_id: str) -> pd.Series:
    """Per row of ``table`` (a gfo table with the columns of
    :func:`synergrasp.analysis.verdicts.with_verdicts`): success_force of the row's set
    divided by the full set's optimal force (force_norm) at the same object and pose; NaN
    where the row's set does not succeed or the full set has no optimal force there.
    """
    missing = [c for c in ("object", "pose", "set_id", "success_force", "force_norm") if c not in table.columns]
    if missing:
        raise ValueError(f"table: missing columns {missing}")
    full = table.loc[table["set_id"] == full_set_id, ["object", "pose", "force_norm"]]
    if full.empty:
        raise ValueError(f"full_set_id {full_set_id!r} is not in the table")
    reference = table[["object", "pose"]].merge(full, on=["object", "pose"], how="left")["force_norm"].to_numpy()
    return pd.Series(table["success_force"].to_numpy(float) / reference, index=table.index, name="force_ratio")


def force_summary(table: pd.DataFrame, full_set_id: str) -> pd.DataFrame:
    """Per object and set: the paired and the plain force statistics, with and without the
    marginal successes.

    Columns: object, set_id, n_success, n_marginal, marginal_percent (of the successes;
    NaN if none), force_ratio_median and force_ratio_median_non_marginal (paired measure),
    n_ratio_undefined (successes where the full set has no optimal force),
    plain_mean_force_N, plain_median_force_N, plain_mean_force_non_marginal_N,
    plain_median_force_non_marginal_N (over the set's own successes).
    """
    work = table[["object", "set_id", "success", "marginal", "success_force"]].copy()
    work["ratio"] = paired_force_ratio(table, full_set_id)
    work["ratio_nm"] = work["ratio"].where(~work["marginal"])
    work["force_nm"] = work["success_force"].where(~work["marginal"])
    work["ratio_undefined"] = work["success"] & work["ratio"].isna()
    out = (
        work.groupby(["object", "set_id"], sort=False)
        .agg(
            n_success=("success", "sum"),
            n_marginal=("marginal", "sum"),
            n_ratio_undefined=("ratio_undefined", "sum"),
            force_ratio_median=("ratio", "median"),
            force_ratio_median_non_marginal=("ratio_nm", "median"),
            plain_mean_force_N=("success_force", "mean"),
            plain_median_force_N=("success_force", "median"),
            plain_mean_force_non_marginal_N=("force_nm", "mean"),
            plain_median_force_non_marginal_N=("force_nm", "median"),
        )
        .reset_index()
    )
    out["marginal_percent"] = 100.0 * out["n_marginal"] / out["n_success"].where(out["n_success"] > 0)
    for c in ("n_success", "n_marginal", "n_ratio_undefined"):
        out[c] = out[c].astype("int64")
    return out[
        [
            "object",
            "set_id",
            "n_success",
            "n_marginal",
            "marginal_percent",
            "force_ratio_median",
            "force_ratio_median_non_marginal",
            "n_ratio_undefined",
            "plain_mean_force_N",
            "plain_median_force_N",
            "plain_mean_force_non_marginal_N",
            "plain_median_force_non_marginal_N",
        ]
    ]
