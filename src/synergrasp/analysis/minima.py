"""Local minima of the optimal grasp force over the (α, β) pose grid, and their preservation.

Method (docs/analyses.md, docs/method.md §5): for one object and one synergy set,

1. candidates are force-closure poses whose optimal force is below the median optimal
   force of that set's force-closure poses (by more than FORCE_TIE_RTOL, relative);
2. the neighbourhood of a pose is every *other* grid pose within ±radius in α (α is an
   angle: distances wrap around the period) and ±radius in β (no wrap);
3. a candidate is a local minimum if no neighbour is force closure, or if its force is
   lower than the force of every force-closure neighbour by more than FORCE_TIE_RTOL
   (relative; a closer force is a tie, and a tie discards it).

A minimum of {S1..Sk} is *preserved* if {S1..Sk+1} has a minimum within ±radius in α
(wrapping) and in β.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from synergrasp.analysis.verdicts import force_bound

__all__ = ["MinimaParams", "local_minima", "preserved", "preserved_counts", "minima_table", "MINIMA_COLUMNS", "FORCE_TIE_RTOL"]

# Grid angles are multiples of a step; the tolerance makes "within ±radius" inclusive
# despite rounding in the stored degrees.
_TOL_DEG = 1e-6
#: Forces closer than this (relative) are a tie: the optimiser decides forces to about
#: 1e-6 relative (the same grasp at α and α + period differs by up to ~2e-6), so a smaller
#: difference must not decide which of two poses is the minimum.
FORCE_TIE_RTOL = 1e-5

MINIMA_COLUMNS = ("object", "set_id", "n_synergies", "pose", "alpha_deg", "beta_deg", "force_norm")


@dataclass(frozen=True)
class MinimaParams:
    """Local minima of one object (the ``minima`` step): neighbourhood radius (deg), the
    success verdict and, for ``force_closure_bounded``, the object's weight (N) and the
    bound's multiple of it."""

    radius_deg: float
    success: str
    weight_N: float | None = None
    bound_multiple: float = math.inf

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> MinimaParams:
        """From a configuration or the step's own part of it, for the object ``obj``."""
        return cls(float(config["analyses"]["minima_radius_deg"]), config["analyses"]["success"], **force_bound(config, obj))


def _as_1d(name: str, values: ArrayLike, n: int | None = None, dtype: type = float) -> NDArray:
    arr = np.asarray(values, dtype=dtype)
    if arr.ndim != 1 or (n is not None and arr.shape[0] != n):
        want = f"({n},)" if n is not None else "1-D"
        raise ValueError(f"{name} must have shape {want}; got {arr.shape}")
    return arr


def _within(
    alpha_a: NDArray, beta_a: NDArray, alpha_b: NDArray, beta_b: NDArray, radius_deg: float, alpha_period_deg: float
) -> NDArray[np.bool_]:
    """(..., len a, len b) mask: pose b within ±radius of pose a in wrapped α and in β (deg);
    leading axes of b (several sets of poses b) broadcast."""
    d_alpha = np.abs(alpha_a[..., :, None] - alpha_b[..., None, :]) % alpha_period_deg
    d_alpha = np.minimum(d_alpha, alpha_period_deg - d_alpha)
    d_beta = np.abs(beta_a[..., :, None] - beta_b[..., None, :])
    return (d_alpha <= radius_deg + _TOL_DEG) & (d_beta <= radius_deg + _TOL_DEG)


def _check_radius(radius_deg: float, alpha_period_deg: float) -> None:
    if not (np.isfinite(radius_deg) and radius_deg >= 0):
        raise ValueError(f"radius_deg must be a finite number >= 0; got {radius_deg}")
    if not (np.isfinite(alpha_period_deg) and alpha_period_deg > 0):
        raise ValueError(f"alpha_period_deg must be a finite number > 0; got {alpha_period_deg}")


def local_minima(
    alpha_deg: ArrayLike,
    beta_deg: ArrayLike,
    force: ArrayLike,
    force_closure: ArrayLike,
    radius_deg: float = 10.0,
    alpha_period_deg: float = 360.0,
) -> NDArray[np.bool_]:
    """Local minima of the optimal force over one object's pose grid, for one synergy set.

    Parameters
    ----------
    alpha_deg, beta_deg : (p,) pose angles, deg.
    force : (p,) optimal force ‖f‖₂, N (ignored where not force closure; may be NaN there).
    force_closure : (p,) bool.
    radius_deg : neighbourhood half-width in α and in β, deg.
    alpha_period_deg : period of α, deg (α distances wrap around it).

    Returns
    -------
    (p,) bool, True at the local minima.
    """
    _check_radius(radius_deg, alpha_period_deg)
    alpha = _as_1d("alpha_deg", alpha_deg)
    p = alpha.shape[0]
    beta = _as_1d("beta_deg", beta_deg, p)
    f = _as_1d("force", force, p)
    fc = _as_1d("force_closure", force_closure, p, dtype=bool)
    if np.any(fc & ~np.isfinite(f)):
        raise ValueError("force must be finite at every force-closure pose")
    result = np.zeros(p, dtype=bool)
    if not fc.any():
        return result
    candidates = np.flatnonzero(fc & (f < np.median(f[fc]) * (1.0 - FORCE_TIE_RTOL)))
    closure = np.flatnonzero(fc)
    if candidates.size == 0:
        return result
    near = _within(alpha[candidates], beta[candidates], alpha[closure], beta[closure], radius_deg, alpha_period_deg)
    near &= candidates[:, None] != closure[None, :]  # a pose is not its own neighbour
    # lowest force among each candidate's force-closure neighbours (inf if none)
    lowest = np.where(near, f[closure][None, :], np.inf).min(axis=1)
    result[candidates] = f[candidates] < lowest * (1.0 - FORCE_TIE_RTOL)
    return result


def preserved(
    minima_alpha: ArrayLike,
    minima_beta: ArrayLike,
    next_alpha: ArrayLike,
    next_beta: ArrayLike,
    radius_deg: float = 10.0,
    alpha_period_deg: float = 360.0,
) -> NDArray[np.bool_]:
    """For each minimum of {S1..Sk}: does {S1..Sk+1} have a minimum within ±radius (α wraps)?

    Parameters
    ----------
    minima_alpha, minima_beta : (m,) the minima of the smaller set, deg.
    next_alpha, next_beta : (m',) the minima of the set with one more synergy, deg.

    Returns
    -------
    (m,) bool.
    """
    _check_radius(radius_deg, alpha_period_deg)
    a = _as_1d("minima_alpha", minima_alpha)
    b = _as_1d("minima_beta", minima_beta, a.shape[0])
    na = _as_1d("next_alpha", next_alpha)
    nb = _as_1d("next_beta", next_beta, na.shape[0])
    if a.size == 0 or na.size == 0:
        return np.zeros(a.shape[0], dtype=bool)
    return _within(a, b, na, nb, radius_deg, alpha_period_deg).any(axis=1)


def preserved_counts(
    minima_alpha: NDArray,
    minima_beta: NDArray,
    next_alpha: NDArray,
    next_beta: NDArray,
    radius_deg: float = 10.0,
    alpha_period_deg: float = 360.0,
) -> NDArray[np.int64]:
    """For each row of ``next_alpha``, ``next_beta`` ((d, m'): d sets of minima, deg): how many
    of the m minima ``minima_alpha``, ``minima_beta`` it preserves (:func:`preserved`, summed);
    (d,) counts, computed a few hundred rows at a time."""
    _check_radius(radius_deg, alpha_period_deg)
    a, b = _as_1d("minima_alpha", minima_alpha), _as_1d("minima_beta", minima_beta, len(minima_alpha))
    na, nb = np.asarray(next_alpha, dtype=float), np.asarray(next_beta, dtype=float)
    if na.ndim != 2 or nb.shape != na.shape:
        raise ValueError(f"next_alpha and next_beta must be equal (d, m') arrays; got {na.shape} and {nb.shape}")
    counts = np.zeros(na.shape[0], dtype=np.int64)
    if a.size == 0 or na.shape[1] == 0:
        return counts
    for start in range(0, na.shape[0], 250):
        rows = slice(start, start + 250)
        counts[rows] = _within(a, b, na[rows], nb[rows], radius_deg, alpha_period_deg).any(axis=-1).sum(axis=-1)
    return counts


def minima_table(table: pd.DataFrame, radius_deg: float = 10.0, alpha_period_deg: float = 360.0) -> pd.DataFrame:
    """Every local minimum of every (object, synergy set), one row each.

    ``table``: a gfo table with the columns ``success`` and ``success_force`` of
    :func:`synergrasp.analysis.verdicts.with_verdicts` (the chosen verdict and the optimal
    force there, N); a success without an optimal force is left out of the map.
    Columns: object, set_id, n_synergies, pose, alpha_deg, beta_deg, force_norm (N);
    rows sorted by object, n_synergies, set_id, pose.
    """
    missing = [
        c
        for c in ("object", "set_id", "n_synergies", "pose", "alpha_deg", "beta_deg", "success", "success_force")
        if c not in table.columns
    ]
    if missing:
        raise ValueError(f"gfo table: missing columns {missing}")
    parts = []
    for _, group in table.groupby(["object", "set_id"], sort=False):
        force = group["success_force"].to_numpy(float)
        success = group["success"].to_numpy(dtype=bool) & np.isfinite(force)
        mask = local_minima(
            group["alpha_deg"].to_numpy(), group["beta_deg"].to_numpy(), force, success, radius_deg, alpha_period_deg
        )
        parts.append(
            group.loc[mask, list(MINIMA_COLUMNS[:-1]) + ["success_force"]].rename(columns={"success_force": "force_norm"})
        )
    if not parts:
        return pd.DataFrame(
            {c: pd.Series(dtype=table[c].dtype) for c in MINIMA_COLUMNS[:-1]} | {"force_norm": pd.Series(dtype=float)}
        )
    out = pd.concat(parts, ignore_index=True)
    return out.sort_values(["object", "n_synergies", "set_id", "pose"], ignore_index=True)
