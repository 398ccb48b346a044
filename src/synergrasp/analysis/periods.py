"""The α-period of an object's pose grid, distinct poses, and the check on the results.

An object occupies the same region of space at (α, β) and (α + P, β) when the rotation by P
about the palm normal, applied after the placement at (0, β), maps the placed object onto
itself (it is one of its shape's symmetries, ``Shape.same_region``). For a box: With ``rotation_order: alpha_then_beta``
(R = R_z(β)·R_n(α)·R_0) the condition does not depend on β: the α-rotation acts on the box
before β, so P must be a symmetry of R_0·box about the palm normal — 180° for any box
whose edge lies along the palm normal, 90° if the face toward the palm is square. With
``beta_then_alpha`` (R = R_n(α)·R_z(β)·R_0) it must hold for the β-rotated box at every β of
the grid, which a box tilted by β generally breaks (period 360°).

The hand, the closure and the optimisation see only the region the box occupies (contact
points, normals, the centre about which it turns, gravity in the palm frame), so every
result repeats with that period; a placement that moves the box until it touches the open
hand along the palm normal keeps the argument, since the region it starts from is the same.
:func:`period_violations` checks this on the results instead of assuming it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

__all__ = ["alpha_period_deg", "object_periods", "distinct_pose_mask", "period_violations"]

#: Candidate periods, deg: the rotations of a box about one axis that can be symmetries
#: (a shape turning freely about the α axis, a cylinder or a sphere, adds every divisor of
#: 360° on the α grid: :func:`_candidates_deg`).
_CANDIDATES_DEG = (90.0, 120.0, 180.0)


def _candidates_deg(step_deg: float) -> list[float]:
    """The candidate periods, deg: the box's, and every divisor of 360° below it that is a
    whole number of α grid steps, ascending."""
    on_grid = [
        k * step_deg
        for k in range(1, int(180.0 // step_deg) + 1)
        if abs(360.0 / (k * step_deg) - round(360.0 / (k * step_deg))) < 1e-9
    ]
    return sorted(set(_CANDIDATES_DEG) | set(on_grid))


_DEG_TOL = 1e-6


def alpha_period_deg(placement, shape, palm_normal: Sequence[float] = (1.0, 0.0, 0.0)) -> float:
    """Smallest P among the candidates (90, 120, 180 deg and the divisors of 360° on the α
    grid) such that the object at (α + P, β) fills the same region as at (α, β) for every β
    of the placement's grid; 360 if none.

    ``placement`` is a :class:`synergrasp.simulation.placement.Placement` (centre, starting
    axes, rotation order, grid); ``shape`` a :class:`synergrasp.simulation.shapes.Shape`;
    ``palm_normal`` the hand's palm normal (the α axis).
    """
    from synergrasp.simulation.placement import object_pose, pose_grid

    betas = pose_grid(placement).beta_deg
    for period in _candidates_deg(float(placement.alpha_deg[2])):
        ok = True
        for beta in betas:
            here = object_pose(placement, shape, 0.0, float(beta), palm_normal)
            there = object_pose(placement, shape, period, float(beta), palm_normal)
            if not shape.same_region(here.rotation, here.center_mm, there.rotation, there.center_mm):
                ok = False
                break
        if ok:
            return period
    return 360.0


def object_periods(
    objects: Mapping[str, Mapping[str, Any]], grid: Mapping[str, Any], hand: str | None = None
) -> dict[str, float]:
    """α-period (deg) of every object from the config: ``objects`` maps a name to its
    ``shape`` and effective ``placement`` (the global placement with its override),
    ``grid`` is the config's grid block, ``hand`` the hand file (None: the shipped hand,
    whose palm normal is the α axis)."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.simulation.placement import Placement
    from synergrasp.simulation.shapes import shape_from_config

    normal = load_hand(hand).palm_normal
    return {
        name: alpha_period_deg(
            Placement.from_config(spec["placement"], grid), shape_from_config(spec["shape"], f"objects.{name}.shape"), normal
        )
        for name, spec in objects.items()
    }


def distinct_pose_mask(alpha_deg: NDArray, period_deg: float, alpha_start_deg: float | None = None) -> NDArray:
    """True for the poses whose α lies in the first period of the grid,
    [alpha_start, alpha_start + period) (deg): one representative of every distinct pose.

    ``alpha_start_deg`` defaults to the smallest α given.
    """
    alpha = np.asarray(alpha_deg, dtype=float)
    if alpha.size == 0:
        return np.zeros(0, dtype=bool)
    start = float(alpha.min()) if alpha_start_deg is None else float(alpha_start_deg)
    return (alpha >= start - _DEG_TOL) & (alpha < start + period_deg - _DEG_TOL)


def period_violations(table: pd.DataFrame, period_deg: float, force_rtol: float = 1e-4) -> pd.DataFrame:
    """Poses of one object whose results differ from those at α + period (same β, same set).

    ``table`` is a gfo table with the verdict columns of
    :func:`synergrasp.analysis.verdicts.with_verdicts`. Compared: both verdicts and the
    optimal force (relative tolerance ``force_rtol``). Returns one row per differing
    (set, pose pair): object, set_id, alpha_deg, beta_deg, alpha_shifted_deg, what
    ("verdict" or "force"), with zero rows when every pose repeats. Pairs whose shifted α is
    not on the grid are not compared.
    """
    columns = ["object", "set_id", "alpha_deg", "beta_deg", "alpha_shifted_deg", "what"]
    if period_deg >= 360.0 - _DEG_TOL or table.empty:
        return pd.DataFrame(columns=columns)
    keep = ["object", "set_id", "alpha_deg", "beta_deg", "verdict_force_closure", "verdict_load_feasible", "force_norm"]
    here = table[keep].copy()
    there = table[keep].copy()
    there["alpha_deg"] = np.round((there["alpha_deg"] - period_deg + 180.0) % 360.0 - 180.0, 6)
    here["alpha_deg"] = np.round(here["alpha_deg"], 6)
    pairs = here.merge(there, on=["object", "set_id", "alpha_deg", "beta_deg"], suffixes=("", "_shifted"))
    verdict = (pairs["verdict_force_closure"] != pairs["verdict_force_closure_shifted"]) | (
        pairs["verdict_load_feasible"] != pairs["verdict_load_feasible_shifted"]
    )
    f, g = pairs["force_norm"].to_numpy(float), pairs["force_norm_shifted"].to_numpy(float)
    both = np.isfinite(f) & np.isfinite(g)
    force = np.zeros(len(pairs), dtype=bool)
    force[both] = np.abs(f[both] - g[both]) > force_rtol * np.maximum(np.abs(f[both]), np.abs(g[both]))
    force |= np.isfinite(f) != np.isfinite(g)
    bad = pairs[verdict.to_numpy() | force].copy()
    bad["alpha_shifted_deg"] = np.round((bad["alpha_deg"] + period_deg + 180.0) % 360.0 - 180.0, 6)
    bad["what"] = np.where(verdict[bad.index], "verdict", "force")
    return bad[columns].reset_index(drop=True)
