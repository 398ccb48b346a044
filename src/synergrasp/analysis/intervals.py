"""Success counts per distinct pose, resampled, and the two views of "averaged over objects".

:class:`StudyCounts` holds, for every object, its successes per distinct pose and synergy set
(the verdict in use), their weighted sums under every bootstrap resample
(:class:`synergrasp.analysis.bootstrap.PoseResampler`; row 0 the data) and the optimal
forces of the successes. From them:

- the **per-object** view (the study's): each object's rate is 100 · successes / the full
  set's successes on that object; the view averages it over the objects whose full set
  succeeds anywhere (in the data);
- the **pooled** view: 100 · Σ successes / Σ the full set's successes over those objects.

Rates in percent; forces in N.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.bootstrap import PoseResampler, block_weighted_median, interval
from synergrasp.ids import set_order

__all__ = ["VIEWS", "StudyCounts", "mean_defined"]

#: The views of "averaged over objects", the study's first.
VIEWS: tuple[str, ...] = ("per_object", "pooled")


def mean_defined(values: NDArray) -> NDArray:
    """Column means of (objects, rows) values over the finite entries; NaN where none is."""
    finite = np.isfinite(values)
    count = finite.sum(axis=0)
    total = np.where(finite, values, 0.0).sum(axis=0)
    return np.where(count > 0, total / np.maximum(count, 1), np.nan)


class StudyCounts:
    """Successes per distinct pose of every object and set, and their resampled sums.

    ``table``: gfo table with the columns of ``with_verdicts`` (success, success_force);
    ``full_set_id``: the full set; ``resampler``: the distinct poses and bootstrap weights.
    """

    def __init__(self, table: pd.DataFrame, full_set_id: str, resampler: PoseResampler):
        self.resampler = resampler
        self.full = full_set_id
        self._success: dict[str, NDArray] = {}
        self._force: dict[str, tuple[NDArray, NDArray, NDArray]] = {}
        self._sums: dict[str, NDArray] = {}
        self._own_sets: dict[str, list[str]] = {}
        self._n: dict[str, int] = {}
        for obj in resampler.objects:
            self.add(obj, table[table["object"] == obj])
        self.finish(table["set_id"].astype(str).unique())

    def add(self, obj: str, own: pd.DataFrame) -> None:
        """Count one object of the resampler (``own``: its rows of the gfo table with its
        verdicts), over the sets it has; :meth:`finish` aligns every object on the study's sets."""
        poses = self.resampler.poses(obj)
        sets = sorted(own["set_id"].astype(str).unique(), key=set_order)
        success = own.pivot(index="pose", columns="set_id", values="success")
        force = own.pivot(index="pose", columns="set_id", values="success_force")
        success = success.reindex(index=poses, columns=sets).fillna(False).to_numpy(bool)
        self._store(obj, success, force.reindex(index=poses, columns=sets).to_numpy(float), self.resampler.sums(obj, success))
        self._own_sets[obj] = sets

    def _store(self, obj: str, success: NDArray, force: NDArray, sums: NDArray) -> None:
        """Hold an object's (distinct poses, sets) successes and forces and (rows, sets) sums
        compactly (a thousand objects in a job): successes as bits, forces only where finite
        (column by column), sums as integers (they are sums of integer weights)."""
        finite = np.isfinite(force)
        counts = np.rint(sums).astype(np.int64)
        exact = counts.astype(float) == sums
        self._success[obj] = np.packbits(success, axis=0)
        self._force[obj] = (np.packbits(finite, axis=0), force.T[finite.T], np.concatenate([[0], np.cumsum(finite.sum(axis=0))]))
        self._sums[obj] = counts.astype(np.min_scalar_type(int(counts.max(initial=0)))) if exact.all() else sums
        self._n[obj] = success.shape[0]

    def _dense(self, obj: str) -> tuple[NDArray, NDArray, NDArray]:
        """An object's successes, forces and sums as :meth:`_store` was handed them."""
        n, (finite_bits, values, _) = self._n[obj], self._force[obj]
        success = np.unpackbits(self._success[obj], axis=0, count=n).astype(bool)
        finite = np.unpackbits(finite_bits, axis=0, count=n).astype(bool)
        force = np.full(finite.shape, np.nan)
        force.T[finite.T] = values
        return success, force, self._sums[obj].astype(float)

    def finish(self, set_ids: Sequence[str]) -> None:
        """Every object counted: the study's sets are ``set_ids`` (every object's); an object
        without a set counts no success of it (weighted sums of integers: exact, so the counts
        are those of every object at once)."""
        self.sets: list[str] = sorted({str(s) for s in set_ids}, key=set_order)
        self.objects = self.resampler.objects
        for obj, own_sets in self._own_sets.items():
            if own_sets == self.sets:
                continue
            where = [self.sets.index(s) for s in own_sets]
            aligned = []
            for values, fill in zip(self._dense(obj), (False, np.nan, 0.0)):
                full = np.full((values.shape[0], len(self.sets)), fill, dtype=values.dtype)
                full[:, where] = values
                aligned.append(full)
            self._store(obj, *aligned)
        self._own_sets = {}
        self._col = {s: i for i, s in enumerate(self.sets)}

    @property
    def rows(self) -> int:
        """1 + resamples."""
        return self.resampler.settings.resamples + 1

    def has(self, sid: str) -> bool:
        return sid in self._col

    def success(self, obj: str, sid: str) -> NDArray:
        """(n_distinct,) success of set ``sid`` at ``obj``'s distinct poses."""
        return np.unpackbits(self._success[obj][:, self._col[sid]], count=self._n[obj]).astype(bool)

    def force(self, obj: str, sid: str) -> NDArray:
        """(n_distinct,) optimal force (N) of ``sid`` where it succeeds, NaN elsewhere."""
        col = self._col[sid]
        finite_bits, values, start = self._force[obj]
        finite = np.unpackbits(finite_bits[:, col], count=self._n[obj]).astype(bool)
        out = np.full(finite.size, np.nan)
        out[finite] = values[start[col] : start[col + 1]]
        return out

    def count(self, obj: str, sid: str) -> NDArray:
        """(rows,) weighted success count of ``sid`` on ``obj``: row 0 the distinct-pose count."""
        return self._sums[obj][:, self._col[sid]].astype(float)

    def counted_objects(self) -> list[str]:
        """Objects whose full set succeeds at some distinct pose (in the data)."""
        return [o for o in self.objects if self.count(o, self.full)[0] > 0]

    def object_rate(self, obj: str, sid: str) -> NDArray:
        """(rows,) 100 · count(sid) / count(full) on ``obj``; NaN where the full set has none."""
        full = self.count(obj, self.full)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(full > 0, 100.0 * self.count(obj, sid) / np.where(full > 0, full, 1.0), np.nan)

    def rate(self, sid: str, view: str) -> NDArray:
        """(rows,) the rate of ``sid`` averaged over the counted objects in ``view``; NaN for a
        set not computed or no counted object."""
        objects = self.counted_objects()
        if not self.has(sid) or not objects:
            return np.full(self.rows, np.nan)
        if view == "per_object":
            return mean_defined(np.vstack([self.object_rate(o, sid) for o in objects]))
        if view == "pooled":
            num = sum(self.count(o, sid) for o in objects)
            den = sum(self.count(o, self.full) for o in objects)
            with np.errstate(invalid="ignore", divide="ignore"):
                return np.where(den > 0, 100.0 * num / np.where(den > 0, den, 1.0), np.nan)
        raise ValueError(f"view must be one of {list(VIEWS)}; got {view!r}")

    def n_any(self, set_ids: Sequence[str]) -> int:
        """Distinct poses, over the counted objects, where at least one of ``set_ids`` succeeds."""
        present = [s for s in set_ids if self.has(s)]
        return (
            int(sum(np.column_stack([self.success(o, s) for s in present]).any(axis=1).sum() for o in self.counted_objects()))
            if present
            else 0
        )

    def n_lost(self, small: str) -> tuple[NDArray, NDArray]:
        """(rows,) weighted counts, over the counted objects, of the full set's distinct
        successes and of those where ``small`` does not succeed."""
        objects = self.counted_objects()
        full = sum((self.count(o, self.full) for o in objects), np.zeros(self.rows))
        lost = sum(
            (self.resampler.sums(o, (self.success(o, self.full) & ~self.success(o, small)).astype(float)) for o in objects),
            np.zeros(self.rows),
        )
        return full, lost

    def paired_log_ratio(self, a: str, b: str) -> tuple[NDArray, int]:
        """(rows,) weighted median over the distinct poses, of every object, where both ``a``
        and ``b`` succeed, of log(F_b / F_a); and the number of such poses. F_b / F_a > 1:
        ``a`` needs the lower force."""
        values, blocks, objects, offset = [], [], [], 0
        for obj in self.objects:
            fa, fb = self.force(obj, a), self.force(obj, b)
            both = np.isfinite(fa) & np.isfinite(fb) & (fa > 0) & (fb > 0)
            if not both.any():
                continue
            values.append(np.log(fb[both] / fa[both]))
            blocks.append(offset + self.resampler.blocks(obj)[both])  # numbered after the objects before it
            objects.append(obj)
            offset += self.resampler.n_blocks(obj)
        if not values:
            return np.full(self.rows, np.nan), 0

        def block_weights(rows: slice) -> NDArray:  # every object's block weights of those rows, a few rows at a time
            return np.hstack([self.resampler.block_weights(obj, rows) for obj in objects])

        v = np.concatenate(values)
        return block_weighted_median(v, np.concatenate(blocks), block_weights, self.rows), int(v.size)

    def pooled_ratio_to_full(self, sid: str) -> tuple[NDArray, int]:
        """(rows,) weighted median over every object's distinct successes of ``sid`` of its
        optimal force / the full set's at the same pose (Fig. 5B, like with like); and their
        number."""
        log_ratio, n = self.paired_log_ratio(self.full, sid) if self.has(sid) else (np.full(self.rows, np.nan), 0)
        return np.exp(log_ratio), n

    def estimate_interval(self, values: NDArray) -> tuple[float, float, float]:
        """(estimate, low, high) of a statistic computed on every row."""
        low, high = interval(values[1:], self.resampler.settings.level)
        return float(values[0]), low, high
