"""Block bootstrap over distinct poses: the intervals behind every verdict (docs/analyses.md).

Each object's pose grid is folded to its first α-period (the copies at α + P are the same
grasp) and cut into square blocks of ``block_deg`` × ``block_deg`` in (α, β); a resample
draws, within each object, as many blocks as it has, with replacement. It is carried out as
a weight per block (a multinomial draw), so every statistic is a function of weighted sums
over poses: a few matrix products for 1000 resamples. Row 0 of every weight matrix is the
data itself (every block once), rows 1.. are the resamples, so a statistic computed on all
rows gives its estimate and its resampled values together, from the same poses, and a
difference of two statistics is taken inside each resample. Seeded and deterministic: one
generator, the objects drawn in a fixed (sorted) order.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.periods import distinct_pose_mask

__all__ = [
    "BootstrapSettings",
    "PoseResampler",
    "block_index",
    "block_weighted_median",
    "interval",
    "weighted_median",
    "weighted_median_rows",
]

_TOL_DEG = 1e-6


@dataclass(frozen=True)
class BootstrapSettings:
    """Config ``analyses.bootstrap``: resamples, seed, block edge (deg), interval level."""

    resamples: int
    seed: int
    block_deg: float
    level: float

    def __post_init__(self) -> None:
        if not (isinstance(self.resamples, (int, np.integer)) and self.resamples >= 1):
            raise ValueError(f"BootstrapSettings.resamples must be an integer >= 1; got {self.resamples!r}")
        if not self.block_deg > 0:
            raise ValueError(f"BootstrapSettings.block_deg must be > 0; got {self.block_deg!r}")
        if not 0.5 < self.level < 1:
            raise ValueError(f"BootstrapSettings.level must lie in (0.5, 1); got {self.level!r}")


def block_index(
    alpha_deg: NDArray, beta_deg: NDArray, block_deg: float, alpha_start_deg: float, beta_start_deg: float
) -> NDArray:
    """Block number of each pose: square blocks of ``block_deg`` counted from the grid's start
    in α and in β (deg). Poses must lie in one α-period; numbers are 0..n_blocks − 1 (only
    blocks holding a pose are numbered)."""
    ia = np.floor((np.asarray(alpha_deg, float) - alpha_start_deg + _TOL_DEG) / block_deg).astype(np.int64)
    ib = np.floor((np.asarray(beta_deg, float) - beta_start_deg + _TOL_DEG) / block_deg).astype(np.int64)
    key = ia * (int(ib.max(initial=0)) + 1) + ib
    return np.unique(key, return_inverse=True)[1].astype(np.int64)


class PoseResampler:
    """The distinct poses of every object, their blocks and the bootstrap weights.

    ``poses``: one row per pose of the grid (columns object, pose, alpha_deg, beta_deg; a
    gfo table's rows of one set will do); ``periods_deg``: α-period per object (360 if
    absent). ``weights(obj)`` is a (1 + resamples, n_distinct) matrix of pose weights, row 0
    all ones (the data); ``poses(obj)`` the pose ids of the distinct poses, in that order.
    """

    def __init__(self, poses: pd.DataFrame, periods_deg: Mapping[str, float], settings: BootstrapSettings):
        self.settings = settings
        self._rng = np.random.default_rng(settings.seed)
        self._poses: dict[str, NDArray] = {}
        self._block_weights: dict[str, NDArray] = {}
        self._blocks: dict[str, NDArray] = {}
        unique = poses[["object", "pose", "alpha_deg", "beta_deg"]].drop_duplicates(["object", "pose"])
        for obj in sorted(unique["object"].unique()):
            self.add(obj, unique[unique["object"] == obj], float(periods_deg.get(obj, 360.0)))

    def add(self, obj: str, poses: pd.DataFrame, period_deg: float) -> None:
        """Draw the blocks of one more object: ``poses`` its rows (columns pose, alpha_deg,
        beta_deg; repeated poses are read once), ``period_deg`` its α-period. The objects must
        come in sorted order, each once: one generator draws for all of them, so that an
        object at a time (``synergrasp.analysis.study_tables``) gives the same weights as
        every object at once."""
        if self._poses and not str(obj) > list(self._poses)[-1]:
            raise ValueError(f"PoseResampler.add: objects in sorted order, each once; {obj!r} after {list(self._poses)[-1]!r}")
        own = poses[["pose", "alpha_deg", "beta_deg"]].drop_duplicates("pose").sort_values("pose")
        alpha, beta = own["alpha_deg"].to_numpy(float), own["beta_deg"].to_numpy(float)
        keep = distinct_pose_mask(alpha, period_deg)
        blocks = block_index(alpha[keep], beta[keep], self.settings.block_deg, float(alpha.min()), float(beta.min()))
        n_blocks = int(blocks.max()) + 1 if blocks.size else 0
        draws = (
            self._rng.multinomial(n_blocks, np.full(n_blocks, 1.0 / n_blocks), size=self.settings.resamples)
            if n_blocks
            else np.zeros((self.settings.resamples, 0), dtype=np.int64)
        )
        self._poses[obj] = own["pose"].to_numpy()[keep]
        self._blocks[obj] = blocks
        weights = np.vstack([np.ones((1, n_blocks), dtype=np.int64), draws])
        # held as the smallest integer type of the counts (a byte each, not eight: a thousand
        # objects' resamples fit in a job), read back as floats
        self._block_weights[obj] = weights.astype(np.min_scalar_type(int(weights.max(initial=1))))

    @property
    def objects(self) -> list[str]:
        return list(self._poses)

    def poses(self, obj: str) -> NDArray:
        """Pose ids of ``obj``'s distinct poses (sorted)."""
        return self._poses[obj]

    def n_blocks(self, obj: str) -> int:
        return self._block_weights[obj].shape[1]

    def blocks(self, obj: str) -> NDArray:
        """Block number of each of ``obj``'s distinct poses (in :meth:`poses`' order)."""
        return self._blocks[obj]

    def block_weights(self, obj: str, rows: slice = slice(None)) -> NDArray:
        """(1 + resamples, n_blocks) integer weights of ``obj``'s blocks: row 0 ones, then the
        resamples (``rows``: those rows only); a pose's weight is its block's."""
        return self._block_weights[obj][rows]

    def weights(self, obj: str, rows: slice = slice(None)) -> NDArray:
        """(1 + resamples, n_distinct) pose weights of ``obj``: row 0 ones, then the resamples
        (``rows``: those rows only)."""
        return self._block_weights[obj][rows][:, self._blocks[obj]].astype(float)

    def sums(self, obj: str, values: NDArray) -> NDArray:
        """Weighted sums over ``obj``'s distinct poses of ``values`` (n_distinct,) or
        (n_distinct, m): (1 + resamples,) or (1 + resamples, m)."""
        values = np.asarray(values, dtype=float)
        n_blocks = self.n_blocks(obj)
        flat = values.reshape(len(values), -1)
        per_block = np.zeros((n_blocks, flat.shape[1]))
        np.add.at(per_block, self._blocks[obj], flat)
        out = self._block_weights[obj].astype(float) @ per_block
        return out[:, 0] if values.ndim == 1 else out


def weighted_median(values: NDArray, weights: NDArray) -> NDArray:
    """Median of ``values`` (n,) under each row of ``weights`` (r, n) (≥ 0): the mean of the
    lower and upper weighted medians, so that unit weights give numpy's median. NaN for a row
    of zero weight or no values."""
    weights = np.atleast_2d(np.asarray(weights, dtype=float))
    return weighted_median_rows(values, lambda rows: weights[rows], weights.shape[0])


#: Weights held at once by :func:`weighted_median_rows` (cells of 8 bytes: 64 MB).
_CELLS = 8_000_000


def weighted_median_rows(values: NDArray, weight_rows: Callable[[slice], NDArray], n_rows: int) -> NDArray:
    """:func:`weighted_median` of ``values`` (n,) under ``n_rows`` rows of weights handed a few
    rows at a time (``weight_rows(slice)``: those rows, (rows, n)), so that the weights of
    many poses under every resample are never held at once; each row's median is its own,
    so the result is the same as with every row at once."""
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return np.full(n_rows, np.nan)
    order = np.argsort(values, kind="stable")
    v = values[order]
    out = np.empty(n_rows)
    step = max(1, _CELLS // values.size)
    for start in range(0, n_rows, step):
        rows = slice(start, min(start + step, n_rows))
        cum = np.cumsum(np.asarray(weight_rows(rows), dtype=float)[:, order], axis=1)
        total = cum[:, -1:]
        lower = np.minimum((cum < total / 2.0 - 1e-9).sum(axis=1), v.size - 1)
        upper = np.minimum((cum <= total / 2.0 + 1e-9).sum(axis=1), v.size - 1)
        out[rows] = np.where(total[:, 0] > 0, 0.5 * (v[lower] + v[upper]), np.nan)
    return out


#: Block weights held at once by :func:`block_weighted_median` (cells of 8 bytes: 32 MB).
_BLOCK_CELLS = 4_000_000
#: Least half-width (sorted positions; n / 64 where larger) of the first window around the middle in
#: :func:`block_weighted_median`.
_WINDOW = 512


def block_weighted_median(
    values: NDArray, blocks: NDArray, block_weight_rows: Callable[[slice], NDArray], n_rows: int
) -> NDArray:
    """:func:`weighted_median_rows` where every weight is an integer and a value's weight is
    that of its block: ``values`` (n,), ``blocks`` (n,) each value's block number, and
    ``block_weight_rows(slice)`` those rows of the blocks' integer weights, (rows, n_blocks).
    The same medians to the bit (the same sorted values picked: on integer weights the lower
    and upper medians are the first sorted positions where the cumulative weight reaches
    ⌈total / 2⌉ and exceeds ⌊total / 2⌋), found without every row's cumulative weights:
    the weight below the middle of the sorted values is a product of the block weights with
    the number of values of each block there, and the cumulative weights are summed only in a
    window around the middle, widened (doubled) for the rows whose median lies outside it.
    Costs about rows · (n_blocks + window) instead of rows · n."""
    values = np.asarray(values, dtype=float)
    blocks = np.asarray(blocks, dtype=np.int64)
    if values.shape != blocks.shape:
        raise ValueError(f"block_weighted_median: {values.size} values but {blocks.size} block numbers")
    if values.size == 0:
        return np.full(n_rows, np.nan)
    order = np.argsort(values, kind="stable")
    used, b = np.unique(blocks[order], return_inverse=True)  # only the blocks holding a value, renumbered
    v, n, n_blocks = values[order], values.size, int(blocks.max()) + 1
    per_block = np.bincount(b, minlength=used.size)
    out = np.empty(n_rows)
    step = max(1, _BLOCK_CELLS // max(used.size, 2 * _WINDOW))
    for start in range(0, n_rows, step):
        rows = slice(start, min(start + step, n_rows))
        handed = np.asarray(block_weight_rows(rows))
        if handed.dtype.kind not in "iub" or handed.ndim != 2 or handed.shape[1] < n_blocks:
            raise ValueError(
                f"block_weighted_median: block weights must be integers, (rows, >= {n_blocks} blocks); "
                f"got {handed.dtype} {handed.shape}"
            )
        weights = handed[:, used].astype(np.int64)  # integer sums: exact
        total = weights @ per_block
        # the first sorted position where the cumulative weight reaches ceil(total / 2), and
        # where it exceeds floor(total / 2)
        lower, upper = _first_reaching(weights, b, np.stack([(total + 1) // 2, total // 2 + 1]))
        lower, upper = np.minimum(lower, n - 1), np.minimum(upper, n - 1)
        out[rows] = np.where(total > 0, 0.5 * (v[lower] + v[upper]), np.nan)
    return out


def _first_reaching(weights: NDArray, b: NDArray, thresholds: NDArray) -> NDArray:
    """Per threshold (``thresholds``: (k, rows)) and row of ``weights`` (rows, n_blocks;
    integers), the number of sorted positions whose cumulative weight (the weights of the
    blocks ``b`` of the positions up to and including it) is below the threshold: the first
    position that reaches it (0 where the threshold is not positive). Summed in a window
    around the middle position, doubled for the rows whose answers lie outside it; (k, rows)."""
    n = b.size
    out = np.zeros(thresholds.shape, dtype=np.int64)
    todo = np.flatnonzero((thresholds > 0).any(axis=0))
    half = max(_WINDOW, n // 64)
    while todo.size:
        lo, hi = max(0, n // 2 - half), min(n, n // 2 + half)
        w = weights if todo.size == len(weights) else weights[todo]
        before = w @ np.bincount(b[:lo], minlength=weights.shape[1])  # weight of the positions < lo
        x = thresholds[:, todo]
        inside = ((before < x) | (lo == 0) | (x <= 0)).all(axis=0)
        outside = []
        for part in np.array_split(np.arange(todo.size), -(-todo.size * (hi - lo) // _BLOCK_CELLS)):
            cum = before[part, None] + np.cumsum(w[part[:, None], b[lo:hi]], axis=1)  # positions lo, lo + 1, ...
            ok = inside[part] & ((cum[:, -1] >= x[:, part]) | (hi == n) | (x[:, part] <= 0)).all(axis=0)
            for k in range(len(x)):
                out[k, todo[part[ok]]] = np.where(x[k, part[ok]] > 0, lo + (cum[ok] < x[k, part[ok], None]).sum(axis=1), 0)
            outside.append(part[~ok])
        todo = todo[np.concatenate(outside)]
        half *= 2
    return out


def interval(resampled: NDArray, level: float) -> tuple[float, float]:
    """Percentile interval of the resampled values (NaN resamples left out; NaN if all are)."""
    finite = np.asarray(resampled, dtype=float)
    finite = finite[np.isfinite(finite)]
    if finite.size == 0:
        return np.nan, np.nan
    low, high = np.percentile(finite, [50.0 * (1.0 - level), 50.0 * (1.0 + level)])
    return float(low), float(high)
