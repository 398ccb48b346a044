"""Study summaries from the gfo table (docs/design.md schema): success rates, Table II, the
hierarchy matrices of Fig. 5, minimum preservation, and cross-checks. Columns are
documented in docs/analyses.md. Pure functions: DataFrames in, DataFrames out.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.bootstrap import BootstrapSettings
from synergrasp.analysis.chance import level_pairs
from synergrasp.analysis.claims import VerdictRules
from synergrasp.analysis.forces import force_summary
from synergrasp.analysis.intervals import VIEWS, StudyCounts
from synergrasp.analysis.periods import distinct_pose_mask, object_periods
from synergrasp.config import ConfigError, build
from synergrasp.ids import ALL_OBJECTS, incremental_set_id, set_id, set_members, set_order
from synergrasp.resolved import effective_placement, weight_N

__all__ = [
    "AnalysisSettings",
    "TablesParams",
    "success_rates",
    "mean_over_objects",
    "with_intervals",
    "object_rows",
    "hierarchy_input",
    "incrementality_table",
    "hierarchy_matrices",
    "minimum_preservation",
    "object_preservation",
    "preservation_table",
    "full_but_not_first_n",
    "lost_poses",
    "verdict_disagreements",
    "set_sort_key",
    "NoSuccessWarning",
    "no_success_note",
    "no_success_sentence",
]


def set_sort_key(set_ids: pd.Series) -> pd.Series:
    """Sort key of set ids: by size, then by the synergy indices ("1-2" < "1-10" < "1-2-3")."""
    return set_ids.map(set_order)


def _require(table: pd.DataFrame, name: str, columns: Iterable[str]) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"{name}: missing columns {missing}")


@dataclass(frozen=True)
class AnalysisSettings:
    """What the study's tables need beyond the gfo and minima tables (config ``analyses``;
    docs/analyses.md), built by :meth:`TablesParams.from_config`; the schema holds the
    defaults and checks the values.

    success: the verdict the tables use (``force_closure`` | ``load_feasible``).
    marginal_weight_multiple: a success is marginal above this multiple of the weight.
    radius_deg: neighbourhood half-width of the local minima, deg.
    null_draws, null_seed: draws and seed of the preservation null model.
    success_rate_tolerance_percent: a success rate above 100 % by more than this stops the run.
    bootstrap: the block bootstrap's settings. rules: tie band, least distinct poses, headline view.
    weights_N: object → weight m·g, N. periods_deg: object → α-period, deg.
    """

    success: str
    marginal_weight_multiple: float
    radius_deg: float
    null_draws: int
    null_seed: int
    success_rate_tolerance_percent: float
    bootstrap: BootstrapSettings
    rules: VerdictRules
    weights_N: Mapping[str, float] = field(default_factory=dict)
    periods_deg: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class TablesParams:
    """The study's tables (the ``tables`` step): the synergy-set bounds (the configuration's
    ``synergy_sets``), Table II's k_max and the analysis settings."""

    synergy_sets: dict[str, int]
    table2_k_max: int
    settings: AnalysisSettings

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> TablesParams:
        """From a configuration or the step's own part of it (``obj`` is not read): the
        objects' weights m·g and α-periods (from their boxes, placements and the grid)."""
        analyses = config["analyses"]
        objects = {name: {**spec, "placement": effective_placement(config, name)} for name, spec in config["objects"].items()}
        try:
            periods_deg = object_periods(objects, config["grid"], config["hand"])
        except (TypeError, ValueError) as err:
            raise ConfigError(f"config error at 'objects' / 'placement': {err}") from None
        settings = AnalysisSettings(
            success=analyses["success"],
            marginal_weight_multiple=float(analyses["marginal_weight_multiple"]),
            radius_deg=float(analyses["minima_radius_deg"]),
            null_draws=int(analyses["null_model"]["draws"]),
            null_seed=int(analyses["null_model"]["seed"]),
            success_rate_tolerance_percent=float(analyses["success_rate_tolerance_percent"]),
            bootstrap=build(BootstrapSettings, "analyses.bootstrap", **analyses["bootstrap"]),
            rules=build(
                VerdictRules,
                "analyses",
                rate_points=float(analyses["tie_band"]["rate_points"]),
                force_relative=float(analyses["tie_band"]["force_relative"]),
                min_distinct_poses=int(analyses["min_distinct_poses"]),
                headline_view=analyses["headline_view"],
            ),
            weights_N={name: weight_N(config, name) for name in objects},
            periods_deg=periods_deg,
        )
        return cls(dict(config["synergy_sets"]), int(analyses["table2_k_max"]), settings)


def _rate_columns(table: pd.DataFrame, column: str, full_set_id: str) -> pd.DataFrame:
    """Per (object, set): count of ``column`` and its rate relative to the full set (percent)."""
    counts = table.groupby(["object", "set_id"], sort=False)[column].sum().rename("n").reset_index()
    full = counts[counts["set_id"] == full_set_id].set_index("object")["n"]
    ref = counts["object"].map(full).fillna(0).astype(float)
    counts["rate"] = 100.0 * counts["n"] / ref.where(ref > 0)
    return counts


#: Columns of the success-rates table, in order (docs/analyses.md).
RATE_COLUMNS = (
    "object",
    "view",
    "set_id",
    "n_synergies",
    "n_poses",
    "n_success",
    "success_rate",
    "success_rate_low",
    "success_rate_high",
    "full_set_empty",
    "n_success_grid",
    "success_rate_grid",
    "absolute_share",
    "success_rate_force_closure",
    "success_rate_load_feasible",
    "success_rate_force_closure_bounded",
    "above_bound_percent",
    "n_marginal",
    "marginal_percent",
    "force_ratio_median",
    "force_ratio_low",
    "force_ratio_high",
    "n_force_poses",
    "force_ratio_median_non_marginal",
    "n_ratio_undefined",
    "plain_mean_force_N",
    "plain_median_force_N",
    "plain_mean_force_non_marginal_N",
    "plain_median_force_non_marginal_N",
    "n_objects",
)
#: The ``view`` of a row of one object.
OBJECT_VIEW = "object"


def _distinct_poses(table: pd.DataFrame, periods_deg: Mapping[str, float]) -> NDArray[np.bool_]:
    """Per row: its pose lies in the first α-period of its object's grid."""
    distinct = np.zeros(len(table), dtype=bool)
    for obj, rows in table.groupby("object", sort=False).indices.items():
        alpha = table["alpha_deg"].to_numpy(float)[rows]
        distinct[rows] = distinct_pose_mask(alpha, periods_deg.get(obj, 360.0))
    return distinct


def success_rates(table: pd.DataFrame, full_set_id: str, periods_deg: Mapping[str, float] | None = None) -> pd.DataFrame:
    """Success rates per distinct pose under every verdict, and force statistics, per object and set.

    ``table``: a gfo table with the columns of :func:`synergrasp.analysis.verdicts.with_verdicts`;
    ``periods_deg``: α-period per object (360 if absent). Returns one row per (object,
    set_id) with the columns ``RATE_COLUMNS`` (docs/analyses.md; view ``object``): counts and
    the normalised rate (percent of the full set's successes; NaN where the full set has
    none) per distinct pose (α in one period) under the verdict in use, under each verdict,
    the same per grid pose, and the columns of :func:`synergrasp.analysis.forces.force_summary`.
    The interval columns are NaN here (:func:`with_intervals` fills them).
    """
    _require(
        table,
        "gfo table",
        (
            "object",
            "set_id",
            "n_synergies",
            "pose",
            "alpha_deg",
            "success",
            "verdict_force_closure",
            "verdict_load_feasible",
            "success_force",
        ),
    )
    present = sorted(table["set_id"].unique(), key=lambda s: (len(set_members(s)), s))
    if full_set_id not in present:
        raise ValueError(f"full_set_id {full_set_id!r} is not in the gfo table; allowed values: {present}")
    distinct = _distinct_poses(table, periods_deg or {})
    bounded = table.get("verdict_force_closure_bounded", table["verdict_force_closure"]).astype(bool)
    work = table.assign(
        **{f"{c}_d": table[c].astype(bool) & distinct for c in ("success", "verdict_force_closure", "verdict_load_feasible")},
        bounded_d=bounded & distinct,
        one_d=distinct,
        fc_above=table["verdict_force_closure"].astype(bool) & ~bounded,
    )
    keys = ["object", "set_id"]
    out = (
        work.groupby(keys, sort=False)
        .agg(
            n_synergies=("n_synergies", "first"),
            n_poses=("one_d", "sum"),
            n_grid=("success", "size"),
            n_fc=("verdict_force_closure", "sum"),
            n_above=("fc_above", "sum"),
        )
        .reset_index()
    )
    for name, column in (
        ("", "success_d"),
        ("_grid", "success"),
        ("_force_closure", "verdict_force_closure_d"),
        ("_load_feasible", "verdict_load_feasible_d"),
        ("_force_closure_bounded", "bounded_d"),
    ):
        rates = _rate_columns(work, column, full_set_id)
        out = out.merge(rates.rename(columns={"n": f"n_success{name}", "rate": f"success_rate{name}"}), on=keys)
    out["full_set_empty"] = out["success_rate"].isna()
    out["absolute_share"] = 100.0 * out["n_success"] / out["n_poses"]
    out["above_bound_percent"] = 100.0 * out["n_above"] / out["n_fc"].where(out["n_fc"] > 0)
    out = out.merge(force_summary(table, full_set_id).drop(columns="n_success"), on=keys)
    out = out.assign(
        view=OBJECT_VIEW,
        success_rate_low=np.nan,
        success_rate_high=np.nan,
        force_ratio_low=np.nan,
        force_ratio_high=np.nan,
        n_force_poses=pd.NA,
        n_objects=1,
    )
    out = out.sort_values(keys, key=lambda c: set_sort_key(c) if c.name == "set_id" else c, ignore_index=True)
    return out[list(RATE_COLUMNS)].astype({c: "int64" for c in ("n_poses", "n_success", "n_success_grid")})


def with_intervals(rates: pd.DataFrame, counts: StudyCounts) -> pd.DataFrame:
    """The success-rates table with each object's rate interval filled and, per set, one
    row per view of "averaged over objects" (object ``all``, view ``per_object`` or
    ``pooled``): the view's rate with its interval, the successes summed over objects, and
    the force ratio to the full set (per_object: mean over objects of the per-object
    medians, the study's; pooled: the median over every object's successes, like with like,
    with its interval and the number of those distinct poses)."""
    out = rates.copy()
    for i, r in enumerate(out.itertuples()):
        if r.object in counts.objects and counts.has(r.set_id):
            _, low, high = counts.estimate_interval(counts.object_rate(r.object, r.set_id))
            out.iat[i, out.columns.get_loc("success_rate_low")] = low
            out.iat[i, out.columns.get_loc("success_rate_high")] = high
    means = mean_over_objects(rates).set_index("set_id")
    summed = rates.groupby("set_id", sort=False)[["n_poses", "n_success", "n_success_grid", "n_marginal"]].sum()
    views = []
    for sid in means.index:
        for view in VIEWS:
            rate, low, high = counts.estimate_interval(counts.rate(sid, view))
            row = {
                "object": ALL_OBJECTS,
                "view": view,
                "set_id": sid,
                "n_synergies": means.at[sid, "n_synergies"],
                **summed.loc[sid].to_dict(),
                "success_rate": rate,
                "success_rate_low": low,
                "success_rate_high": high,
                "n_objects": means.at[sid, "n_objects"],
                "full_set_empty": not np.isfinite(rate),
            }
            if view == "per_object":
                row.update({c: means.at[sid, c] for c in AVERAGED if c in means.columns and c != "success_rate"})
            else:
                ratio, n = counts.pooled_ratio_to_full(sid)
                est, low, high = counts.estimate_interval(ratio)
                row.update(
                    force_ratio_median=est,
                    force_ratio_low=low,
                    force_ratio_high=high,
                    n_force_poses=n,
                    absolute_share=100.0 * row["n_success"] / row["n_poses"] if row["n_poses"] else np.nan,
                    marginal_percent=100.0 * row["n_marginal"] / row["n_success_grid"] if row["n_success_grid"] else np.nan,
                )
            views.append(row)
    out = pd.concat([out, pd.DataFrame(views)], ignore_index=True)
    return out[list(RATE_COLUMNS)].astype({"n_force_poses": "Int64"})


def object_rows(rates: pd.DataFrame) -> pd.DataFrame:
    """The rows of one object each (``view`` ``object``) of a success-rates table."""
    return rates[rates["view"] == OBJECT_VIEW] if "view" in rates.columns else rates


#: Columns of the success-rates table averaged over objects (mean_over_objects, Fig. 5).
AVERAGED = (
    "success_rate",
    "success_rate_grid",
    "success_rate_force_closure",
    "success_rate_load_feasible",
    "success_rate_force_closure_bounded",
    "above_bound_percent",
    "absolute_share",
    "marginal_percent",
    "force_ratio_median",
    "force_ratio_median_non_marginal",
    "plain_mean_force_N",
)


def mean_over_objects(rates: pd.DataFrame) -> pd.DataFrame:
    """Per set: the columns of ``AVERAGED`` present in ``rates``, averaged over the objects
    where each is defined (NaN entries skipped), and n_objects (objects in the average of
    success_rate)."""
    _require(rates, "rates table", ("set_id", "n_synergies", "success_rate"))
    rates = object_rows(rates)
    rates = rates.assign(set_id=rates["set_id"].astype(str))  # a CSV round trip may read "1" as 1
    present = [c for c in AVERAGED if c in rates.columns]
    grouped = rates.groupby("set_id", sort=False)
    out = grouped[present].mean()
    out.insert(0, "n_synergies", grouped["n_synergies"].first())
    out["n_objects"] = grouped["success_rate"].count()
    return out.reset_index().sort_values("set_id", key=set_sort_key, ignore_index=True)


def incrementality_table(rates: pd.DataFrame, k_max: int) -> pd.DataFrame:
    """Table II: one row per object, columns k = 1..k_max: success rate (percent) with {S1..Sk}.

    A set missing from ``rates`` gives NaN. The first column is ``object``; the others are
    named by k (int).
    """
    _require(rates, "rates table", ("object", "set_id", "success_rate"))
    if not (isinstance(k_max, (int, np.integer)) and k_max >= 1):
        raise ValueError(f"k_max must be an integer >= 1; got {k_max!r}")
    rates = object_rows(rates)
    wide = rates.pivot(index="object", columns="set_id", values="success_rate")
    table = pd.DataFrame(
        {k: wide.get(incremental_set_id(k), pd.Series(np.nan, index=wide.index)) for k in range(1, k_max + 1)}, index=wide.index
    )
    return table.reset_index().rename_axis(columns=None)


#: The hierarchy table's values per set (docs/analyses.md).
HIERARCHY_VALUES = (
    "success_rate",
    "success_rate_low",
    "success_rate_high",
    "success_rate_pooled",
    "success_rate_pooled_low",
    "success_rate_pooled_high",
    "force_ratio_median",
    "force_ratio_low",
    "force_ratio_high",
    "n_force_poses",
    "plain_mean_force_N",
)


def hierarchy_input(rates: pd.DataFrame) -> pd.DataFrame:
    """One row per set from the view rows of a success-rates table (:func:`with_intervals`):
    the per-object view's rate and interval, the pooled view's (``success_rate_pooled``...),
    the pooled like-with-like force ratio to the full set with its interval and count, and the
    per-object mean of the plain mean force."""
    per = rates[rates["view"] == "per_object"].set_index("set_id")
    pooled = rates[rates["view"] == "pooled"].set_index("set_id")
    out = per[["n_synergies", "success_rate", "success_rate_low", "success_rate_high", "plain_mean_force_N"]].copy()
    for c in ("success_rate", "success_rate_low", "success_rate_high"):
        out[c.replace("success_rate", "success_rate_pooled")] = pooled[c]
    for c in ("force_ratio_median", "force_ratio_low", "force_ratio_high", "n_force_poses"):
        out[c] = pooled[c].astype(float)
    return out.reset_index()


def hierarchy_matrices(
    rates_mean_over_objects: pd.DataFrame,
    first: int = 7,
    values: Sequence[str] = ("success_rate", "force_ratio_median", "plain_mean_force_N"),
) -> pd.DataFrame:
    """Fig. 5 data: ``first`` matrices ``first`` × ``first`` in long form.

    Cell (i, j) of matrix k is the set {S_k, S_i, S_j}, duplicates collapsing ((k, k) is
    {S_k}; row k, column k and the diagonal are pairs). One row per (k, i, j), 1-based, with
    set_id and the ``values`` columns of that set (NaN if absent).
    """
    _require(rates_mean_over_objects, "rates table", ("set_id", *values))
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
                row = {"k": k, "i": i, "j": j, "set_id": sid}
                row.update({v: by_set.at[sid, v] if sid in by_set.index else np.nan for v in values})
                rows.append(row)
    return pd.DataFrame(rows).astype({v: float for v in values})


def minimum_preservation(
    gfo: pd.DataFrame,
    minima_table: pd.DataFrame,
    k_max: int,
    radius_deg: float = 10.0,
    periods_deg: Mapping[str, float] | None = None,
) -> pd.DataFrame:
    """Preservation of the local minima of {S1..Sk} in {S1..Sk+1}, k = 1..k_max-1.

    One row per object and k, then per object a total over k (k = <NA>), then the same for
    all objects together (object = "all"). Columns: object, k, n_minima, n_preserved,
    preserved_percent (NaN where there are no minima), n_minima_distinct,
    n_preserved_distinct (the minima in one α-period of the grid, i.e. per distinct pose).
    """
    _require(gfo, "gfo table", ("object",))
    _require(minima_table, "minima table", ("object", "set_id", "alpha_deg", "beta_deg"))
    if not (isinstance(k_max, (int, np.integer)) and k_max >= 2):
        raise ValueError(f"k_max must be an integer >= 2; got {k_max!r}")
    periods = dict(periods_deg or {})
    objects = sorted(set(gfo["object"].unique()) | set(minima_table["object"].unique()))
    rows = []
    for obj in objects:
        alpha_start = float(gfo.loc[gfo["object"] == obj, "alpha_deg"].min()) if (gfo["object"] == obj).any() else None
        rows += object_preservation(
            obj, minima_table[minima_table["object"] == obj], alpha_start, k_max, radius_deg, periods.get(obj, 360.0)
        )
    return preservation_table(rows, objects)


def object_preservation(
    obj: str, mins: pd.DataFrame, alpha_start: float | None, k_max: int, radius_deg: float, period_deg: float
) -> list[dict]:
    """The rows k = 1..k_max − 1 of :func:`minimum_preservation` of one object: ``mins`` its
    minima, ``alpha_start`` the first α of its grid (deg; None: its first minimum's)."""
    rows = []
    for k, this, _, kept in level_pairs(mins, k_max, radius_deg):
        one = distinct_pose_mask(this["alpha_deg"].to_numpy(float), period_deg, alpha_start)
        rows.append(
            {
                "object": obj,
                "k": k,
                "n_minima": len(this),
                "n_preserved": int(kept.sum()),
                "n_minima_distinct": int(one.sum()),
                "n_preserved_distinct": int((kept & one).sum()),
            }
        )
    return rows


def preservation_table(rows: list[dict], objects: Sequence[str]) -> pd.DataFrame:
    """:func:`minimum_preservation`'s table from every object's :func:`object_preservation`
    rows: per object its k rows and their total, then every object's per k and in total."""
    counts = ["n_minima", "n_preserved", "n_minima_distinct", "n_preserved_distinct"]
    per_k = pd.DataFrame(rows, columns=["object", "k", *counts])
    totals = per_k.groupby("object", sort=True)[counts].sum().reset_index()
    totals["k"] = pd.NA
    all_k = per_k.groupby("k", sort=True)[counts].sum().reset_index()
    all_k["object"] = ALL_OBJECTS
    grand = pd.DataFrame([{"object": ALL_OBJECTS, "k": pd.NA, **{c: per_k[c].sum() for c in counts}}])
    parts = []
    for obj in objects:
        parts += [per_k[per_k["object"] == obj], totals[totals["object"] == obj]]
    parts += [all_k, grand]
    out = pd.concat([p for p in parts if len(p)], ignore_index=True)[["object", "k", *counts]]
    out = out.astype({"k": "Int64", **{c: "int64" for c in counts}})
    out["preserved_percent"] = (100.0 * out["n_preserved"] / out["n_minima"].where(out["n_minima"] > 0)).astype(float)
    return out[["object", "k", "n_minima", "n_preserved", "preserved_percent", "n_minima_distinct", "n_preserved_distinct"]]


def full_but_not_first_n(table: pd.DataFrame, full_set_id: str, first_n_set_id: str) -> pd.DataFrame:
    """Poses where the full set succeeds and {S1..S7} does not (the chosen verdict).

    ``table``: gfo table with the columns of ``with_verdicts``. Columns: object, pose,
    alpha_deg, beta_deg, full_force_norm (N), first7_status (the smaller set's gfo status;
    "missing" if it was not computed at that pose), first7_force_closure,
    first7_load_feasible (its two verdicts).
    """
    _require(
        table,
        "gfo table",
        (
            "object",
            "pose",
            "alpha_deg",
            "beta_deg",
            "set_id",
            "status",
            "success",
            "force_norm",
            "verdict_force_closure",
            "verdict_load_feasible",
        ),
    )
    present = set(table["set_id"].unique())
    for name, sid in (("full_set_id", full_set_id), ("first_n_set_id", first_n_set_id)):
        if sid not in present:
            raise ValueError(f"{name} {sid!r} is not in the gfo table; allowed values: {sorted(present)}")
    return lost_poses(table, full_set_id, first_n_set_id)


def lost_poses(table: pd.DataFrame, full_set_id: str, first_n_set_id: str) -> pd.DataFrame:
    """:func:`full_but_not_first_n` without checking that the two sets are in ``table`` (one
    object's rows, of a study whose tables hold both): a pose where the smaller set was not
    computed counts as lost, status "missing"."""
    keys = ["object", "pose"]
    full = table[(table["set_id"] == full_set_id) & table["success"].astype(bool)]
    small = table.loc[
        table["set_id"] == first_n_set_id, keys + ["status", "success", "verdict_force_closure", "verdict_load_feasible"]
    ]
    merged = full.merge(small, on=keys, how="left", suffixes=("", "_first_n"))
    lost = merged[~merged["success_first_n"].astype("boolean").fillna(False).to_numpy(bool)]
    out = pd.DataFrame(
        {
            "object": lost["object"],
            "pose": lost["pose"],
            "alpha_deg": lost["alpha_deg"],
            "beta_deg": lost["beta_deg"],
            "full_force_norm": lost["force_norm"],
            "first7_status": lost["status_first_n"].fillna("missing"),
            "first7_force_closure": lost["verdict_force_closure_first_n"].astype("boolean").fillna(False).astype(bool),
            "first7_load_feasible": lost["verdict_load_feasible_first_n"].astype("boolean").fillna(False).astype(bool),
        }
    )
    return out.sort_values(keys, ignore_index=True)


def verdict_disagreements(table: pd.DataFrame) -> pd.DataFrame:
    """Where the two verdicts disagree, per object and set (only groups with a disagreement).

    Columns: object, set_id, n_synergies, n_poses, n_disagree, n_load_feasible_only
    (optimisation under the weight feasible, no force closure: the weight helps through
    f_p), n_force_closure_only (force closure without a feasible optimisation: a solver
    disagreement, see the invariant checks), disagree_percent (of the group's poses).
    """
    _require(table, "gfo table", ("object", "set_id", "n_synergies", "verdict_force_closure", "verdict_load_feasible"))
    fc = table["verdict_force_closure"].astype(bool)
    lf = table["verdict_load_feasible"].astype(bool)
    work = pd.DataFrame(
        {
            "object": table["object"],
            "set_id": table["set_id"],
            "n_synergies": table["n_synergies"],
            "lf_only": lf & ~fc,
            "fc_only": fc & ~lf,
        }
    )
    out = (
        work.groupby(["object", "set_id"], sort=False)
        .agg(
            n_synergies=("n_synergies", "first"),
            n_poses=("lf_only", "size"),
            n_load_feasible_only=("lf_only", "sum"),
            n_force_closure_only=("fc_only", "sum"),
        )
        .reset_index()
    )
    out["n_disagree"] = out["n_load_feasible_only"] + out["n_force_closure_only"]
    out = out[out["n_disagree"] > 0].copy()
    out["disagree_percent"] = 100.0 * out["n_disagree"] / out["n_poses"]
    out = out.sort_values(["object", "set_id"], key=lambda c: set_sort_key(c) if c.name == "set_id" else c, ignore_index=True)
    cols = [
        "object",
        "set_id",
        "n_synergies",
        "n_poses",
        "n_disagree",
        "n_load_feasible_only",
        "n_force_closure_only",
        "disagree_percent",
    ]
    return out[cols].astype({c: "int64" for c in cols[3:7]})


class NoSuccessWarning(UserWarning):
    """No grasp of any object succeeds under the analyses' success setting (said in the log and
    in the title of every table that names the success verdict)."""


def no_success_note(table: pd.DataFrame, settings: AnalysisSettings) -> str:
    """'' if some (object, pose, set) row of ``table`` (a gfo table with its verdicts,
    ``with_verdicts``) succeeds; else one sentence saying that nothing can succeed under
    ``analyses.success`` and why (the setting, or no force closure at all)."""
    return no_success_sentence(
        bool(table["success"].astype(bool).any()), int(table["verdict_force_closure"].astype(bool).sum()), settings
    )


def no_success_sentence(any_success: bool, n_fc: int, settings: AnalysisSettings) -> str:
    """:func:`no_success_note` from whether any row succeeds and the number of force-closure rows."""
    if any_success:
        return ""
    if settings.success == "force_closure_bounded" and n_fc:
        why = (
            f"none of the {n_fc} force-closure (pose, set) rows holds the weight within "
            f"analyses.marginal_weight_multiple = {settings.marginal_weight_multiple:g} times the weight"
        )
    elif settings.success == "load_feasible":
        why = "no optimisation under the weight is feasible"
    else:
        why = "no pose of any object is in force closure with any set"
    return (
        f"no grasp succeeds under analyses.success = {settings.success}: {why}; every success rate is 0 "
        "and the rates relative to the full set (Table II) are undefined"
    )
