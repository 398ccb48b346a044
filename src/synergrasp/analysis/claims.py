"""The study's claims as a table, each with the figure that tests it and a verdict.

The claims are hypotheses of the study (Averta et al. 2018), tested on this run; nothing
in the model is chosen toward them. Verdicts: ``holds``, ``does not hold``, ``undefined``
(a tie, or a quantity this run cannot give). Success rates are the chosen verdict's,
averaged over objects (objects whose full set never succeeds are skipped). A comparison
of two measured quantities, or of a quantity with a round threshold (claims 3–7), is a
tie when they differ by at most ``TIE_PERCENT_POINTS`` percentage points or, for forces,
by at most ``TIE_FORCE_RELATIVE`` relative; a tie is ``undefined``. Claims 1 and 2 carry
their own tolerance (99.5 %, a count of 0). docs/analyses.md gives every rule.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from synergrasp.ids import set_id

__all__ = ["HOLDS", "FAILS", "UNDEFINED", "compare", "combine", "claims_table", "TIE_PERCENT_POINTS",
           "TIE_FORCE_RELATIVE"]

HOLDS, FAILS, UNDEFINED = "holds", "does not hold", "undefined"
TIE_PERCENT_POINTS = 1.0
TIE_FORCE_RELATIVE = 0.05
CLAIM_COLUMNS = ["claim", "statement", "tested_by", "measured", "verdict"]


def compare(higher: float, lower: float, tie: float = TIE_PERCENT_POINTS) -> str:
    """``holds`` if higher − lower > tie, ``does not hold`` if < −tie, else (or NaN) ``undefined``."""
    if not (np.isfinite(higher) and np.isfinite(lower)):
        return UNDEFINED
    diff = higher - lower
    return HOLDS if diff > tie else FAILS if diff < -tie else UNDEFINED


def compare_lower_force(lower: float, higher: float, tie: float = TIE_FORCE_RELATIVE) -> str:
    """``holds`` if ``lower`` is below ``higher`` by more than the relative tie (lower·(1+tie) <
    higher), ``does not hold`` if above by more, else ``undefined``."""
    if not (np.isfinite(lower) and np.isfinite(higher) and lower > 0 and higher > 0):
        return UNDEFINED
    return HOLDS if lower * (1 + tie) < higher else FAILS if higher * (1 + tie) < lower else UNDEFINED


def combine(verdicts: Sequence[str]) -> str:
    """All hold → holds; any does not hold → does not hold; else undefined."""
    if verdicts and all(v == HOLDS for v in verdicts):
        return HOLDS
    return FAILS if FAILS in verdicts else UNDEFINED


def _label(sid: str) -> str:
    return "{" + ",".join(f"S{i}" for i in sid.split("-")) + "}"


def _rate(mean_rates: pd.Series, *synergies: int) -> float:
    return float(mean_rates.get(set_id(synergies), np.nan))


def _claim1(table2: pd.DataFrame, first: int) -> tuple[str, str]:
    if first not in table2.columns or table2[first].isna().all():
        return f"Table II has no k = {first}", UNDEFINED
    column = table2.set_index("object")[first]
    worst = column.idxmin() if column.notna().any() else None
    if column.isna().any():
        return f"Table II k = {first} undefined for {sorted(column[column.isna()].index)}", UNDEFINED
    verdict = HOLDS if (column >= 99.5).all() else FAILS
    return f"lowest Table II at k = {first}: {column[worst]:.2f} % ({worst})", verdict


def _claim3(preservation: pd.DataFrame) -> tuple[str, str]:
    row = preservation[(preservation["object"] == "all") & (preservation["pairs"] == "all")]
    if row.empty or not np.isfinite(row["preserved_percent"].iloc[0]):
        return "no local minima", UNDEFINED
    r = row.iloc[0]
    text = (f"{r.preserved_percent:.1f} % preserved; null model {r.null_mean_percent:.1f} % "
            f"[{r.null_low_percent:.1f}, {r.null_high_percent:.1f}]")
    return text, combine([compare(r.preserved_percent, 90.0), compare(r.preserved_percent, r.null_high_percent)])


def _claim5(rates: pd.Series) -> tuple[str, str]:
    singles = (min(_rate(rates, 4), _rate(rates, 5)), max(_rate(rates, 2), _rate(rates, 3)))
    pairs = (min(_rate(rates, 1, 4), _rate(rates, 1, 5)), max(_rate(rates, 1, 2), _rate(rates, 1, 3)))
    text = (f"singles: min(S4,S5) {singles[0]:.1f} % vs max(S2,S3) {singles[1]:.1f} %; with S1: "
            f"min {pairs[0]:.1f} % vs max {pairs[1]:.1f} %")
    return text, combine([compare(*singles), compare(*pairs)])


def _claim6(rates: pd.Series, first: int) -> tuple[str, str]:
    pairs = {set_id((i, j)): _rate(rates, i, j) for i in range(1, first + 1) for j in range(i + 1, first + 1)}
    target = pairs.pop(set_id((1, 5)), np.nan)
    others = {s: v for s, v in pairs.items() if np.isfinite(v)}
    if not others:
        return "no other pair computed", UNDEFINED
    best = max(others, key=others.get)
    return (f"{{S1,S5}} {target:.1f} %; best other pair {_label(best)} {others[best]:.1f} %",
            compare(target, others[best]))


def _claim7(per_object: pd.DataFrame, first: int) -> tuple[str, str]:
    singles = [str(i) for i in range(1, first + 1)]
    ratios = per_object[per_object["set_id"].astype(str).isin(singles)].assign(set_id=lambda t: t["set_id"].astype(str))
    grouped = ratios.groupby("set_id")["force_ratio_median"]
    mean, count = grouped.mean(), grouped.count()
    named = ["1", "4", "5"]
    if first < 5 or mean.reindex(named).isna().any():
        return "S1, S4 or S5 never succeeds alone (no paired force)", UNDEFINED
    rest = mean.drop(named).dropna()
    if rest.empty:
        return "no other single synergy succeeds", UNDEFINED
    shown = ", ".join(f"S{s} {mean[s]:.2f} ({count[s]})" for s in sorted(mean.dropna().index, key=int))
    never = [f"S{s}" for s in singles if s not in mean.dropna().index]
    text = (f"paired force ratio, mean over objects (objects): {shown}"
            + (f"; never succeed alone: {', '.join(never)}" if never else ""))
    return text, compare_lower_force(float(mean[named].max()), float(rest.min()))


def claims_table(table2: pd.DataFrame, n_full_not_first: int | None, preservation: pd.DataFrame,
                 mean_rates: pd.DataFrame, per_object: pd.DataFrame, first: int = 7) -> pd.DataFrame:
    """The seven claims (docs/analyses.md).

    Parameters
    ----------
    table2 : Table II (object, then columns k = 1..).
    n_full_not_first : poses where {S1..S_full} succeeds and {S1..S_first} does not (None:
        that set was not computed).
    preservation : the summary of :func:`synergrasp.analysis.chance.preservation_vs_chance`.
    mean_rates : per set, success_rate averaged over objects (``mean_over_objects``).
    per_object : per object and set, force_ratio_median (paired force measure).
    first : the number of leading synergies of the hierarchy (the study's 7).
    """
    rates = mean_rates.assign(set_id=mean_rates["set_id"].astype(str)).set_index("set_id")["success_rate"]
    singles = {i: _rate(rates, i) for i in range(2, first + 1)}
    best_other = max(singles, key=lambda i: singles[i] if np.isfinite(singles[i]) else -np.inf) if singles else None
    c2 = (("set not computed", UNDEFINED) if n_full_not_first is None
          else (f"{n_full_not_first} poses", HOLDS if n_full_not_first == 0 else FAILS))
    c4 = ((f"S1 {_rate(rates, 1):.1f} %; best other single S{best_other} {singles[best_other]:.1f} %",
           compare(_rate(rates, 1), singles[best_other])) if best_other else ("no other single", UNDEFINED))
    found = [
        (1, f"every object reaches 100 % of the full set's force-closure poses by k = {first} "
            f"(Table II at k = {first} >= 99.5 % for every object)", "Table II", *_claim1(table2, first)),
        (2, f"the first {first} synergies reach force closure wherever the full set does "
            f"(poses where the full set succeeds and {{S1..S{first}}} does not = 0)",
         "full_not_first7 table", *c2),
        (3, "local minima are preserved as synergies are added, well above chance (share >= 90 % and above "
            "the null model's 95 % interval)", "Fig. 4, minimum_preservation and preservation_vs_chance tables",
         *_claim3(preservation)),
        (4, "S1 is the best single synergy for force closure", "Fig. 5A", *c4),
        (5, "S4 and S5 are more useful for force closure than S2 and S3, as single synergies and as the second "
            "synergy with S1", "Fig. 5A", *_claim5(rates)),
        (6, "the best pair (by success rate) contains S1 and S5", "Fig. 5A", *_claim6(rates, first)),
        (7, "among single synergies, S4, S5 and S1 need the lowest forces (paired force measure)", "Fig. 5B",
         *_claim7(per_object, first)),
    ]
    return pd.DataFrame(found, columns=CLAIM_COLUMNS)
