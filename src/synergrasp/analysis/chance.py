"""Minimum preservation against chance: a null model that keeps the spacing of the minima.

For a pair ({S1..Sk}, {S1..Sk+1}) of one object, the null model shifts every minimum of
{S1..Sk+1} by one common random offset on the (α, β) grid, wrapping in α (periodic) and
reflected at the ends of the β range (β is not periodic), and counts the minima of {S1..Sk} that have a shifted minimum within the
neighbourhood (the same test as the observed statistic, :func:`synergrasp.analysis.minima.
preserved`). The shift keeps how many minima there are and how they are spread, and
destroys where they are. Offsets that leave the map where it was are excluded: α offset
within the radius of a multiple of the object's α-period *and* β offset within the radius. Each
draw gives every pair its own offset; the share is pooled over pairs as the
observed share is. ``draws`` draws from a generator seeded with ``seed``: deterministic.

Pairs whose two force maps are identical (same success at every pose, forces equal to
``rtol``) preserve every minimum trivially; the share is also reported without them.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.bootstrap import PoseResampler
from synergrasp.analysis.minima import preserved, preserved_counts
from synergrasp.ids import ALL_OBJECTS, incremental_set_id

__all__ = [
    "identical_force_maps",
    "allowed_offsets",
    "null_preserved",
    "object_pairs",
    "chance_tables",
    "check_draws",
    "preservation_vs_chance",
    "resampled_preservation",
    "object_resampled_preservation",
    "level_pairs",
]

#: The ``pairs`` of a row over every pair of consecutive levels (besides ``non_identical``).
ALL_PAIRS = "all"
_TOL_DEG = 1e-6


def identical_force_maps(table: pd.DataFrame, set_a: str, set_b: str, rtol: float = 1e-6) -> bool:
    """Whether two sets of one object have the same success at every pose and the same
    optimal force (relative ``rtol``) at every success. ``table``: one object's gfo table
    with the ``success`` and ``success_force`` columns of ``with_verdicts``."""
    a = table[table["set_id"] == set_a].set_index("pose").sort_index()
    b = table[table["set_id"] == set_b].set_index("pose").sort_index()
    if a.empty or b.empty or not a.index.equals(b.index):
        return False
    if not (a["success"].to_numpy(bool) == b["success"].to_numpy(bool)).all():
        return False
    fa, fb = a["success_force"].to_numpy(float), b["success_force"].to_numpy(float)
    both = np.isfinite(fa) & np.isfinite(fb)
    if (np.isfinite(fa) != np.isfinite(fb)).any():
        return False
    return bool(np.all(np.abs(fa[both] - fb[both]) <= rtol * np.maximum(np.abs(fa[both]), np.abs(fb[both]))))


def _wrapped(offset: NDArray, length: float) -> NDArray:
    offset = np.mod(offset, length)
    return np.minimum(offset, length - offset)


def allowed_offsets(alphas: NDArray, betas: NDArray, radius_deg: float, period_deg: float) -> NDArray:
    """(n, 2) grid-index offsets (dα, dβ) of the null model: dα = 0..n_α − 1 (wrapping, α is
    periodic), dβ = −(n_β − 1)..n_β − 1 (reflected at the grid's ends, β is not periodic),
    except those within ``radius_deg`` of a multiple of the α-period in α and within
    ``radius_deg`` in β. ``alphas``, ``betas``: the grid's sorted values, deg (uniform steps)."""
    n_a, n_b = len(alphas), len(betas)
    step_a = float(alphas[1] - alphas[0]) if n_a > 1 else 360.0
    step_b = float(betas[1] - betas[0]) if n_b > 1 else 1.0
    da, db = np.meshgrid(np.arange(n_a), np.arange(-(n_b - 1), n_b), indexing="ij")
    near_a = _wrapped(da * step_a, period_deg) <= radius_deg + _TOL_DEG
    near_b = np.abs(db) * step_b <= radius_deg + _TOL_DEG
    keep = ~(near_a & near_b)
    return np.column_stack([da[keep], db[keep]])


def reflected(index: NDArray, n: int) -> NDArray:
    """Grid indices shifted beyond 0..n − 1 mapped back by reflection at the ends (no wrap):
    −1 → 1, n → n − 2; the number of points is kept."""
    if n == 1:
        return np.zeros_like(index)
    period = 2 * (n - 1)
    folded = np.mod(index, period)
    return np.where(folded > n - 1, period - folded, folded)


def _indices(values: NDArray, grid: NDArray) -> NDArray:
    idx = np.searchsorted(grid, np.asarray(values, dtype=float) - _TOL_DEG)
    if idx.size and (idx.max() >= grid.size or not np.allclose(grid[idx], values, atol=1e-6)):
        raise ValueError("minima lie off the pose grid")
    return idx


def null_preserved(
    this: pd.DataFrame,
    nxt: pd.DataFrame,
    alphas: NDArray,
    betas: NDArray,
    radius_deg: float,
    offsets: NDArray,
    rng: np.random.Generator,
    draws: int,
) -> NDArray:
    """(draws,) number of minima of ``this`` preserved by ``nxt`` shifted by random offsets
    (rows of ``offsets``, drawn uniformly). ``this``, ``nxt``: alpha_deg, beta_deg (deg)."""
    if this.empty or nxt.empty or offsets.size == 0:
        return np.zeros(draws, dtype=np.int64)
    ia = _indices(nxt["alpha_deg"].to_numpy(float), alphas)
    ib = _indices(nxt["beta_deg"].to_numpy(float), betas)
    shift = offsets[rng.integers(len(offsets), size=draws)]  # (draws, 2) grid steps in α, β
    shifted_a = alphas[(ia[None, :] + shift[:, :1]) % alphas.size]
    shifted_b = betas[reflected(ib[None, :] + shift[:, 1:], betas.size)]
    return preserved_counts(this["alpha_deg"].to_numpy(float), this["beta_deg"].to_numpy(float), shifted_a, shifted_b, radius_deg)


def level_pairs(mins: pd.DataFrame, k_max: int, radius_deg: float) -> Iterator[tuple[int, pd.DataFrame, pd.DataFrame, NDArray]]:
    """(k, the minima of {S1..Sk}, those of {S1..Sk+1}, which of the first are preserved) for
    k = 1 … k_max − 1, from one object's minima table."""
    for k in range(1, k_max):
        this = mins[mins["set_id"] == incremental_set_id(k)]
        nxt = mins[mins["set_id"] == incremental_set_id(k + 1)]
        kept = preserved(
            this["alpha_deg"].to_numpy(float),
            this["beta_deg"].to_numpy(float),
            nxt["alpha_deg"].to_numpy(float),
            nxt["beta_deg"].to_numpy(float),
            radius_deg,
        )
        yield k, this, nxt, kept


def object_pairs(
    obj: str,
    own: pd.DataFrame,
    mins: pd.DataFrame,
    k_max: int,
    radius_deg: float,
    period_deg: float,
    draws: int,
    rng: np.random.Generator,
) -> list[dict]:
    """Observed and null preserved counts of every k of one object: ``own`` its gfo table with
    its verdicts, ``mins`` its minima; ``rng`` the study's generator (objects in sorted order)."""
    alphas, betas = np.sort(own["alpha_deg"].unique()), np.sort(own["beta_deg"].unique())
    offsets = allowed_offsets(alphas, betas, radius_deg, period_deg)
    rows = []
    for k, this, nxt, kept in level_pairs(mins, k_max, radius_deg):
        rows.append(
            {
                "object": obj,
                "k": k,
                "n_minima": len(this),
                "n_preserved": int(kept.sum()),
                "identical": identical_force_maps(own, incremental_set_id(k), incremental_set_id(k + 1)),
                "null": null_preserved(this, nxt, alphas, betas, radius_deg, offsets, rng, draws),
            }
        )
    return rows


def _summary(name: str, which: str, group: list[dict], draws: int) -> dict:
    n_minima = sum(r["n_minima"] for r in group)
    n_kept = sum(r["n_preserved"] for r in group)
    null = sum((r["null"] for r in group), np.zeros(draws, dtype=np.int64))
    share = 100.0 * n_kept / n_minima if n_minima else np.nan
    null_share = 100.0 * null / n_minima if n_minima else np.full(draws, np.nan)
    low, high = np.percentile(null_share, [2.5, 97.5]) if n_minima else (np.nan, np.nan)
    return {
        "object": name,
        "pairs": which,
        "n_pairs": len(group),
        "n_minima": n_minima,
        "n_preserved": n_kept,
        "preserved_percent": share,
        "null_mean_percent": float(np.mean(null_share)) if n_minima else np.nan,
        "null_low_percent": float(low),
        "null_high_percent": float(high),
        "above_chance": bool(n_minima and share > high),
    }


def preservation_vs_chance(
    table: pd.DataFrame, minima: pd.DataFrame, k_max: int, radius_deg: float, periods: dict[str, float], draws: int, seed: int
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Observed preservation share beside the null model's, per object and over all objects.

    Returns ``(summary, pairs)``. ``summary``: one row per (object or "all", pairs ∈
    {"all", "non_identical"}) with n_pairs, n_minima, n_preserved, preserved_percent,
    null_mean_percent, null_low_percent, null_high_percent (the null's 2.5 and 97.5
    percentiles over the draws) and above_chance (observed > null_high). ``pairs``: one row
    per (object, k) with identical_maps (the two force maps are identical).

    ``table``: gfo table with the columns of ``with_verdicts``; ``minima``: minima table;
    ``periods``: α-period per object, deg (360 if absent); ``draws`` ≥ 1; ``seed``: int.
    """
    check_draws(draws)
    rng = np.random.default_rng(seed)
    rows = []
    for obj in sorted(set(table["object"].unique())):
        own = table[table["object"] == obj]
        rows += object_pairs(obj, own, minima[minima["object"] == obj], k_max, radius_deg, periods.get(obj, 360.0), draws, rng)
    return chance_tables(rows, draws)


def check_draws(draws: int) -> None:
    """One line naming the key when the null model's number of draws is not an integer >= 1."""
    if not (isinstance(draws, (int, np.integer)) and draws >= 1):
        raise ValueError(f"config error at 'analyses.null_model.draws': must be an integer >= 1; got {draws!r}")


def chance_tables(rows: list[dict], draws: int) -> tuple[pd.DataFrame, pd.DataFrame]:
    """``(summary, pairs)`` of :func:`preservation_vs_chance` from every object's
    :func:`object_pairs` rows."""
    summary = []
    for obj in [*sorted({r["object"] for r in rows}), ALL_OBJECTS]:
        group = [r for r in rows if obj in (ALL_OBJECTS, r["object"])]
        summary.append(_summary(obj, ALL_PAIRS, group, draws))
        summary.append(_summary(obj, "non_identical", [r for r in group if not r["identical"]], draws))
    pairs = pd.DataFrame(
        [{"object": r["object"], "k": r["k"], "identical_maps": r["identical"]} for r in rows],
        columns=["object", "k", "identical_maps"],
    )
    return pd.DataFrame(summary), pairs


def resampled_preservation(minima: pd.DataFrame, k_max: int, radius_deg: float, resampler: PoseResampler) -> pd.DataFrame:
    """Per object: the minima of {S1..Sk} (k = 1..k_max − 1) at distinct poses and those
    preserved in {S1..Sk+1}, counted under every bootstrap resample.

    One row per object of the resampler: ``n_minima``, ``n_preserved`` — (1 + resamples,)
    arrays of weighted counts, element 0 the counts on the data (minima per distinct pose).
    """
    rows = [
        object_resampled_preservation(obj, minima[minima["object"] == obj], k_max, radius_deg, resampler)
        for obj in resampler.objects
    ]
    return pd.DataFrame(rows, columns=["object", "n_minima", "n_preserved"])


def object_resampled_preservation(obj: str, mins: pd.DataFrame, k_max: int, radius_deg: float, resampler: PoseResampler) -> dict:
    """One row of :func:`resampled_preservation`: ``obj``'s minima ``mins`` counted under
    every resample of ``resampler``."""
    poses = resampler.poses(obj)
    where = {int(p): i for i, p in enumerate(poses)}
    n_min, n_kept = np.zeros(len(poses)), np.zeros(len(poses))
    for _, this, _, kept in level_pairs(mins, k_max, radius_deg):
        index = np.array([where.get(int(p), -1) for p in this["pose"]], dtype=np.int64)
        here = index >= 0
        np.add.at(n_min, index[here], 1.0)
        np.add.at(n_kept, index[here], kept[here].astype(float))
    return {"object": obj, "n_minima": resampler.sums(obj, n_min), "n_preserved": resampler.sums(obj, n_kept)}
