"""The optimisation's shards: which poses a shard takes, and an object's gfo table from its shards.

Kept apart from `study` (the solver's imports) so that the aggregate step reads and writes
tables without loading the solver.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from numpy.typing import NDArray

__all__ = ["merge_shards", "shard_positions"]


def shard_positions(n_poses: int, shard: int, n_shards: int) -> NDArray:
    """Positions of shard `shard` of `n_shards` among `n_poses` rows: consecutive, sizes differing by at most one."""
    if not (isinstance(n_shards, (int, np.integer)) and n_shards >= 1):
        raise ValueError(f"n_shards (solver.pose_shards) must be an int >= 1, got {n_shards!r}")
    if not (isinstance(shard, (int, np.integer)) and 0 <= shard < n_shards):
        raise ValueError(f"shard must be an int in 0..{n_shards - 1}, got {shard!r}")
    return np.array_split(np.arange(n_poses), n_shards)[shard]


def merge_shards(shards: Sequence[pd.DataFrame]) -> pd.DataFrame:
    """One object's gfo table from its shards, in pose order (each pose's sets keep their order)."""
    return pd.concat(shards, ignore_index=True).sort_values("pose", kind="stable", ignore_index=True)
