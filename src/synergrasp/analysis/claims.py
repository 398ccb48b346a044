"""The study's claims as a table: each with what tests it, the compared difference with its
bootstrap interval, the distinct poses it rests on, and a verdict with its reason.

The claims are hypotheses of the study (Averta et al. 2018), tested on this run; nothing in
the model is chosen toward them. The rules (docs/analyses.md, "Verdicts from intervals"):
a claim ``holds`` or ``does not hold`` only when the interval of its compared difference
lies wholly beyond the tie band; otherwise, or with fewer than ``min_distinct_poses``
distinct poses behind it, or with nothing to compare, it is ``undefined`` with the reason.
Claims about averaged rates get one row per view (the headline view first).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.chance import ALL_PAIRS
from synergrasp.analysis.intervals import VIEWS, StudyCounts, mean_defined
from synergrasp.ids import ALL_OBJECTS, incremental_set_id, set_id, set_members

__all__ = [
    "HOLDS",
    "FAILS",
    "UNDEFINED",
    "CLAIM_VERDICTS",
    "VerdictRules",
    "Difference",
    "interval_verdict",
    "claims_table",
    "planner_claim",
    "CLAIM_COLUMNS",
]

HOLDS, FAILS, UNDEFINED = "holds", "does not hold", "undefined"
#: A claim's verdicts (a success verdict of a grasp is ``verdicts.SUCCESS_VERDICTS``).
CLAIM_VERDICTS = (HOLDS, FAILS, UNDEFINED)
CLAIM_COLUMNS = [
    "claim",
    "view",
    "headline",
    "statement",
    "tested_by",
    "measured",
    "difference",
    "low",
    "high",
    "unit",
    "tie_band",
    "n_distinct_poses",
    "verdict",
    "reason",
]
#: How a difference d decides a claim: "greater" (holds if d > band), "within_below" (a claim
#: of equality, d ≤ 0: holds if d ≥ −band), "within_above" (d ≥ 0: holds if d ≤ band).
KINDS = ("greater", "within_below", "within_above")


@dataclass(frozen=True)
class VerdictRules:
    """Config ``analyses``: tie band (percentage points; relative for forces), the least
    number of distinct poses behind a comparison, the headline view."""

    rate_points: float
    force_relative: float
    min_distinct_poses: int
    headline_view: str

    def __post_init__(self) -> None:
        if self.headline_view not in VIEWS:
            raise ValueError(f"VerdictRules.headline_view must be one of {list(VIEWS)}; got {self.headline_view!r}")


@dataclass(frozen=True)
class Difference:
    """A compared difference: its estimate and interval, its unit and band, the distinct poses
    it rests on, how it decides, and a reason that overrides the interval (e.g. a set not
    computed)."""

    estimate: float
    low: float
    high: float
    band: float
    n: int
    kind: str = "greater"
    unit: str = "percentage points"
    reason: str = ""
    note: str = ""


def interval_verdict(d: Difference, min_poses: int) -> tuple[str, str]:
    """(verdict, reason) of a compared difference by the rules of docs/analyses.md."""
    verdict, reason = _decide(d, min_poses)
    return verdict, f"{reason}; {d.note}" if d.note else reason


def _decide(d: Difference, min_poses: int) -> tuple[str, str]:
    if d.reason:
        return UNDEFINED, d.reason
    if d.n == 0:
        return UNDEFINED, "nothing to compare: 0 distinct poses"
    if d.n < min_poses:
        return UNDEFINED, f"fewer than {min_poses} distinct poses: {d.n}"
    low, high, band = d.low, d.high, d.band
    if not (np.isfinite(low) and np.isfinite(high)):
        return UNDEFINED, "no interval (a statistic undefined in every resample)"
    if d.kind == "greater":
        holds, fails = low > band, high < -band
    elif d.kind == "within_below":
        holds, fails = low >= -band, high < -band
    elif d.kind == "within_above":
        holds, fails = high <= band, low > band
    else:
        raise ValueError(f"kind must be one of {list(KINDS)}; got {d.kind!r}")
    if holds:
        return (
            HOLDS,
            f"interval wholly beyond the tie band (±{band:g})"
            if d.kind == "greater"
            else f"interval within the tie band (±{band:g})",
        )
    if fails:
        return FAILS, f"interval wholly beyond the tie band (±{band:g}) on the other side"
    if d.kind == "greater" and low >= -band and high <= band:
        return UNDEFINED, f"interval inside the tie band (±{band:g}): a tie"
    return UNDEFINED, f"interval overlaps the tie band (±{band:g})"


def _label(sid: str) -> str:
    return "{" + ",".join(f"S{i}" for i in set_members(sid)) + "}"


def _fmt(values: NDArray, counts: StudyCounts, unit: str = "%") -> str:
    est, low, high = counts.estimate_interval(values)
    return f"{est:.1f} {unit} [{low:.1f}, {high:.1f}]"


def _difference(
    values: NDArray,
    counts: StudyCounts,
    band: float,
    n: int,
    kind: str = "greater",
    unit: str = "percentage points",
    reason: str = "",
) -> Difference:
    est, low, high = counts.estimate_interval(values)
    return Difference(est, low, high, band, n, kind, unit, reason)


def _missing(counts: StudyCounts, set_ids: Sequence[str]) -> str:
    absent = [_label(s) for s in set_ids if not counts.has(s)]
    return f"sets not computed: {', '.join(absent)}" if absent else ""


def _best_of(
    counts: StudyCounts, view: str, target: str, others: Sequence[str], rules: VerdictRules, what: str
) -> tuple[str, Difference]:
    """rate(target) − the best of ``others``, the best taken inside each resample."""
    others = [s for s in others if counts.has(s)]
    reason = _missing(counts, [target]) or ("" if others else f"no other {what} computed")
    if reason:
        return reason, Difference(np.nan, np.nan, np.nan, rules.rate_points, 0, reason=reason)
    rates = np.vstack([counts.rate(s, view) for s in others])
    best_rows = np.nanmax(np.where(np.isfinite(rates), rates, -np.inf), axis=0)
    target_rate = counts.rate(target, view)
    best = others[int(np.nanargmax(np.where(np.isfinite(rates[:, 0]), rates[:, 0], -np.inf)))]
    text = (
        f"{_label(target)} {_fmt(target_rate, counts)}; best other {what} {_label(best)} {_fmt(counts.rate(best, view), counts)}"
    )
    return text, _difference(target_rate - best_rows, counts, rules.rate_points, counts.n_any([target, best]))


def _claim1(counts: StudyCounts, first: int, rules: VerdictRules) -> tuple[str, Difference]:
    sid = incremental_set_id(first)
    objects = counts.counted_objects()
    if not counts.has(sid) or not objects:
        reason = _missing(counts, [sid]) or "nothing to compare: the full set succeeds nowhere"
        return reason, Difference(np.nan, np.nan, np.nan, rules.rate_points, 0, "within_below", reason=reason)
    rates = [counts.object_rate(o, sid) for o in objects]
    text = "; ".join(f"{o} {_fmt(r, counts)}" for o, r in zip(objects, rates))
    parts = [(o, r - 100.0, int(counts.count(o, counts.full)[0])) for o, r in zip(objects, rates)]
    return (
        f"Table II at k = {first}: {text}",
        _worst_of(parts, counts, rules.rate_points, rules.min_distinct_poses, kind="within_below"),
    )


def _claim2(counts: StudyCounts, first: int, view: str, rules: VerdictRules) -> tuple[str, Difference]:
    sid = incremental_set_id(first)
    if not counts.has(sid):
        reason = _missing(counts, [sid])
        return reason, Difference(np.nan, np.nan, np.nan, rules.rate_points, 0, "within_above", reason=reason)
    if view == "pooled":
        full, lost = counts.n_lost(sid)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(full > 0, 100.0 * lost / np.where(full > 0, full, 1.0), np.nan)
    else:
        share = 100.0 - counts.rate(sid, "per_object")
    full, lost = counts.n_lost(sid)
    text = (
        f"{int(lost[0])} of the full set's {int(full[0])} distinct force-closure poses missed by "
        f"{_label(sid)}: {_fmt(share, counts)}"
    )
    return text, _difference(share, counts, rules.rate_points, int(full[0]), "within_above")


def _claim3(
    minima: pd.DataFrame, chance: pd.DataFrame, view: str, rules: VerdictRules, counts: StudyCounts
) -> tuple[str, Difference]:
    """``minima``: one row per object with (rows,) arrays n_minima, n_preserved (distinct poses)."""
    rows = minima[minima["n_minima"].map(lambda a: a[0] > 0)]
    if rows.empty:
        return "no local minima", Difference(
            np.nan, np.nan, np.nan, rules.rate_points, 0, reason="nothing to compare: no local minima"
        )
    high = chance.set_index(["object", "pairs"])["null_high_percent"]
    with np.errstate(invalid="ignore", divide="ignore"):
        if view == "pooled":
            share = 100.0 * np.sum(np.vstack(rows["n_preserved"]), axis=0) / np.sum(np.vstack(rows["n_minima"]), axis=0)
            null_high = float(high.get((ALL_OBJECTS, ALL_PAIRS), np.nan))
        else:
            share = mean_defined(
                np.vstack([100.0 * p / np.where(m > 0, m, np.nan) for p, m in zip(rows["n_preserved"], rows["n_minima"])])
            )
            null_high = float(np.mean([high.get((o, ALL_PAIRS), np.nan) for o in rows["object"]]))
    n = int(sum(m[0] for m in rows["n_minima"]))
    text = f"{_fmt(share, counts)} of {n} distinct minima preserved; null model's 97.5 percentile {null_high:.1f} %"
    return text, _difference(np.minimum(share - 90.0, share - null_high), counts, rules.rate_points, n)


def _worst_of(
    parts: Sequence[tuple[str, NDArray, int]],
    counts: StudyCounts,
    band: float,
    min_poses: int,
    unit: str = "percentage points",
    kind: str = "greater",
) -> Difference:
    """The least favourable of several compared differences (name, (rows,) values, distinct
    poses), taken inside each resample, over those resting on at least ``min_poses`` poses.
    Left-out comparisons are named in the reason unless a tested one lies wholly below the band
    (which decides "does not hold" alone)."""
    tested = [p for p in parts if p[2] >= min_poses]
    short = ", ".join(f"{name} ({n})" for name, _, n in parts if n < min_poses)
    if not tested:
        n = max((p[2] for p in parts), default=0)
        return Difference(
            np.nan,
            np.nan,
            np.nan,
            band,
            n,
            kind,
            unit=unit,
            reason=(
                f"fewer than {min_poses} distinct poses: {short}"
                if n
                else f"nothing to compare: 0 distinct poses ({short})"
                if short
                else ""
            ),
        )
    d = _difference(np.min(np.vstack([p[1] for p in tested]), axis=0), counts, band, min(p[2] for p in tested), kind, unit=unit)
    if short:
        left_out = f"comparisons with fewer than {min_poses} distinct poses: {short}"
        return Difference(
            d.estimate,
            d.low,
            d.high,
            band,
            d.n,
            kind,
            unit=unit,
            **({"note": f"left out: {left_out}"} if d.high < -band else {"reason": left_out}),
        )
    return d


def _claim5(counts: StudyCounts, view: str, rules: VerdictRules) -> tuple[str, Difference]:
    parts = [(("4", "5"), ("2", "3"), "singles"), (("1-4", "1-5"), ("1-2", "1-3"), "with S1")]
    reason = _missing(counts, [s for better, worse, _ in parts for s in (*better, *worse)])
    if reason:
        return reason, Difference(np.nan, np.nan, np.nan, rules.rate_points, 0, reason=reason)
    compared, texts = [], []
    for better, worse, what in parts:
        low_better = np.minimum(*(counts.rate(s, view) for s in better))
        high_worse = np.maximum(*(counts.rate(s, view) for s in worse))
        compared.append((what, low_better - high_worse, counts.n_any([*better, *worse])))
        texts.append(
            f"{what}: min({', '.join(map(_label, better))}) {_fmt(low_better, counts)} vs "
            f"max({', '.join(map(_label, worse))}) {_fmt(high_worse, counts)} ({compared[-1][2]} poses)"
        )
    return "; ".join(texts), _worst_of(compared, counts, rules.rate_points, rules.min_distinct_poses)


def _claim7(counts: StudyCounts, first: int, rules: VerdictRules) -> tuple[str, Difference]:
    band = float(np.log1p(rules.force_relative))
    unit = "log force ratio"
    named = [s for s in ("1", "4", "5") if int(s) <= first]
    others = [str(i) for i in range(1, first + 1) if str(i) not in ("1", "4", "5")]
    reason = _missing(counts, named + others) or (
        "" if len(named) == 3 and others else "S1, S4, S5 and another single synergy are needed"
    )
    if reason:
        return reason, Difference(np.nan, np.nan, np.nan, band, 0, unit=unit, reason=reason)
    compared = [(f"S{a}-S{b}", *counts.paired_log_ratio(a, b)) for a in named for b in others]
    shown = [
        f"F(S{name.split('-')[1][1:]})/F(S{name.split('-')[0][1:]}) {_fmt(np.exp(v), counts, '')} ({n})"
        for name, v, n in compared
        if n >= rules.min_distinct_poses
    ]
    short = [f"{name} ({n})" for name, _, n in compared if n < rules.min_distinct_poses]
    text = (
        "median ratio of optimal forces on the distinct poses where both succeed (poses): "
        + ("; ".join(shown) if shown else "no pair tested")
        + (f"; fewer than {rules.min_distinct_poses} common distinct poses: {', '.join(short)}" if short else "")
    )
    return text, _worst_of(compared, counts, band, rules.min_distinct_poses, unit)


STATEMENTS = {
    1: ("every object reaches 100 % of the full set's force-closure poses by k = {first}", "Table II"),
    2: ("the first {first} synergies reach force closure wherever the full set does", "full_not_first7 table"),
    3: (
        "local minima are preserved as synergies are added, well above chance (share >= 90 % and above the null "
        "model's 97.5 percentile)",
        "Fig. 4, minimum_preservation and preservation_vs_chance tables",
    ),
    4: ("S1 is the best single synergy for force closure", "Fig. 5A"),
    5: (
        "S4 and S5 are more useful for force closure than S2 and S3, as single synergies and as the second synergy with S1",
        "Fig. 5A",
    ),
    6: ("the best pair (by success rate) contains S1 and S5", "Fig. 5A"),
    7: (
        "among single synergies, S4, S5 and S1 need the lowest forces (like with like: two sets on the poses where both succeed)",
        "Fig. 5B",
    ),
    8: (
        "an incremental planner reaches <= 5 % regret at a lower cost (solve time) than the best planner that "
        "solves only the full set",
        "planners and planners_across tables, figures/planners.png",
    ),
}


def claims_table(
    counts: StudyCounts, minima: pd.DataFrame, chance: pd.DataFrame, rules: VerdictRules, first: int = 7
) -> pd.DataFrame:
    """The seven claims (docs/analyses.md), one row per (claim, view), the headline view first.

    ``counts``: the study's resampled success counts; ``minima``: per object, the (rows,)
    resampled counts of distinct minima and of preserved ones (columns object, n_minima,
    n_preserved); ``chance``: the preservation_vs_chance summary; ``first``: the hierarchy's
    leading synergies (the study's 7).
    """
    views = [rules.headline_view] + [v for v in VIEWS if v != rules.headline_view]
    singles = [str(i) for i in range(2, first + 1)]
    pairs = [set_id((i, j)) for i in range(1, first + 1) for j in range(i + 1, first + 1) if (i, j) != (1, 5)]
    found: list[tuple[int, str, str, Difference]] = [(1, "each_object", *_claim1(counts, first, rules))]
    for view in views:
        found.append((2, view, *_claim2(counts, first, view, rules)))
        found.append((3, view, *_claim3(minima, chance, view, rules, counts)))
        found.append((4, view, *_best_of(counts, view, "1", singles, rules, "single")))
        found.append((5, view, *_claim5(counts, view, rules)))
        found.append((6, view, *_best_of(counts, view, "1-5", pairs, rules, "pair")))
    found.append((7, "pooled", *_claim7(counts, first, rules)))  # like with like: both sets' common poses
    rows = []
    order = [*views, "each_object"]
    for claim, view, text, d in sorted(found, key=lambda f: (f[0], order.index(f[1]))):
        verdict, reason = interval_verdict(d, rules.min_distinct_poses)
        statement, tested_by = STATEMENTS[claim]
        headline = view == rules.headline_view or claim in (1, 7)
        rows.append(
            (
                claim,
                view,
                headline,
                statement.format(first=first),
                tested_by,
                text,
                d.estimate,
                d.low,
                d.high,
                d.unit,
                d.band,
                d.n,
                verdict,
                reason,
            )
        )
    return pd.DataFrame(rows, columns=CLAIM_COLUMNS)


def planner_claim(per_object: pd.DataFrame, rules: VerdictRules) -> pd.DataFrame:
    """Claim 8, the study's conjecture as a planner (docs/planner.md, written before it ran),
    one row of :data:`CLAIM_COLUMNS` (view ``across_objects``) from the per-object comparison
    of the planners (``table_contracts.PLANNERS``). The difference is 100 (C_full − C_inc) / C_full of
    the two families' chosen planners' solve times, % per object; its band the forces' tie band
    (relative, as %); no least number of poses applies (the interval is over objects, and
    ``n_distinct_poses`` holds the number of objects)."""
    from synergrasp.analysis.planners import OBJECTS_AIM, conjecture

    c = conjecture(per_object)
    band = 100.0 * rules.force_relative
    n = int(c.differences.size)
    if not c.incremental:
        reason = f"no incremental planner meets the aim on >= {OBJECTS_AIM:g} % of the objects"
        text = f"{reason}; the best planner solving only the full set: {c.full_set or 'none'}"
        verdict = FAILS if c.full_set else UNDEFINED
        d = Difference(np.nan, np.nan, np.nan, band, n, unit="% of the full-set planner's solve time")
    else:
        d = Difference(c.mean, c.low, c.high, band, n, unit="% of the full-set planner's solve time")
        text = (
            f"{c.incremental} against {c.full_set} over {n} objects: solve time {c.mean:.1f} % lower "
            f"[{c.low:.1f}, {c.high:.1f}] (negative: higher); closures {c.closures_incremental:.0f} against "
            f"{c.closures_full_set:.0f} (mean)"
        )
        verdict, reason = interval_verdict(d, 0)
    statement, tested_by = STATEMENTS[8]
    return pd.DataFrame(
        [(8, "across_objects", True, statement, tested_by, text, d.estimate, d.low, d.high, d.unit, d.band, n, verdict, reason)],
        columns=CLAIM_COLUMNS,
    )
