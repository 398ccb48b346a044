"""Synergies from posture data: the study's definition, principal components of the joint
angles (docs/synergies.md, "Synergies from data").

Postures X (m postures × n joints, rad) give the mean posture q_m (the column means) and
the synergies: the right singular vectors of the centred postures X − q_m (the eigenvectors
of the joint-angle covariance, computed by SVD, not by forming the covariance), unit
columns ordered by explained variance σ_i² / (m − 1) (rad²). A principal component's sign
is arbitrary; :func:`orient_columns` fixes it by one stated rule.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.synergies import Synergies, SynergyFileError, finite_cells, read_text_table

__all__ = ["SynergyFit", "read_postures", "posture_problems", "fit_synergies", "orient_columns"]

#: A column whose entries sum to less than this share of its 1-norm has no clear "closing"
#: direction; its sign is then set by its largest entry (:func:`orient_columns`).
_SUM_TOLERANCE = 1e-9
#: A component whose variance is below this share of the first's is not a synergy by default.
_RANK_TOLERANCE = 1e-12
#: Postures whose every joint spreads by at most this much (rad) do not differ: what a fit
#: would find is rounding noise.
_SAME_POSTURE_RAD = 1e-9
#: No joint angle of a posture exceeds a full turn (rad); a larger value is in degrees or an outlier.
_FULL_TURN_RAD = 2.0 * math.pi


@dataclass(frozen=True)
class SynergyFit:
    """A synergy table fitted from postures and the variance each synergy explains.

    ``synergies``: mean posture (rad) and unit columns S1…Sk (rad per unit σ);
    ``variance_rad2`` (k,): the postures' variance along each column (rad²);
    ``total_variance_rad2``: the postures' total variance (trace of the covariance, rad²).
    """

    synergies: Synergies
    variance_rad2: NDArray[np.float64]
    total_variance_rad2: float

    @property
    def explained(self) -> NDArray[np.float64]:
        """(k,) share of the total variance explained by each synergy (0 … 1)."""
        return self.variance_rad2 / self.total_variance_rad2

    @property
    def cumulative(self) -> NDArray[np.float64]:
        """(k,) share explained by S1 … Si together."""
        return np.cumsum(self.explained)


def read_postures(path: str | Path) -> tuple[tuple[str, ...], NDArray[np.float64]]:
    """The joint names (the header) and the postures (m × n, rad) of a postures CSV: one
    column per joint, one row per posture, angles in rad. SynergyFileError naming the file
    and the field: unreadable, fewer than two postures, a repeated joint, a value that is
    not a finite number, and every :func:`posture_problems` (one line each)."""
    where = f"postures file '{path}'"
    table = read_text_table(path, where)
    with open(path, encoding="utf-8", newline="") as handle:  # pandas renames a repeated column
        names = tuple(c.strip() for c in next(csv.reader(handle)))
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise SynergyFileError(f"{where}: joint column(s) {repeated} repeated; one column per joint")
    if len(table) < 2:
        raise SynergyFileError(f"{where}: {len(table)} posture(s); at least 2 rows are needed")
    values = finite_cells(
        table,
        list(table.columns),
        lambda i, col, text: (
            f"{where}: row {i + 1}, joint '{names[list(table.columns).index(col)]}' is {text!r}; "
            "a finite number (rad) is required"
        ),
    )
    problems = posture_problems(names, values)
    if problems:
        raise SynergyFileError("\n".join(f"{where}: {p}" for p in problems))
    return names, values


def posture_problems(joint_names: tuple[str, ...], postures: NDArray) -> list[str]:
    """What makes readable postures (m × n, rad) unfit for a synergy fit, one line per kind:
    a column without a joint name or counting the rows 0, 1, …, m − 1 (a table saved with its
    row index); postures that do not differ (every joint spreads by at most 1e-9 rad: the
    fit would be rounding noise); angles beyond a full turn, 2π rad (most postures: a table
    in degrees; a few: outliers, named by row, 1-based)."""
    x = np.asarray(postures, dtype=float)
    m = len(x)
    problems = []
    for j, name in enumerate(joint_names):
        if not name or name.startswith("Unnamed:"):
            problems.append(
                f"column {j + 1} has no joint name: a table saved with its row index? "
                "(pandas: to_csv(..., index=False)); one named column per joint"
            )
        elif m >= 3 and np.array_equal(x[:, j], np.arange(m)):
            problems.append(
                f"column {j + 1} ('{name}') counts the rows 0, 1, …, {m - 1}: a row index, not "
                "a joint angle (pandas: to_csv(..., index=False))"
            )
    if problems:
        return problems
    spread = np.ptp(x, axis=0)
    if spread.max() <= _SAME_POSTURE_RAD:
        problems.append(
            f"the {m} postures do not differ (every joint spreads by at most {spread.max():.3g} rad): "
            "no variance to fit synergies to"
        )
    beyond = np.abs(x) > _FULL_TURN_RAD
    rows = np.flatnonzero(beyond.any(axis=1))
    if 2 * len(rows) > m:
        problems.append(
            f"{len(rows)} of {m} postures have angles beyond 2π (up to {np.abs(x).max():.4g}); "
            "postures are in rad (is the table in degrees?)"
        )
    elif len(rows):
        i = int(rows[0])
        j = int(np.argmax(np.abs(x[i])))
        shown = ", ".join(str(r + 1) for r in rows[:5]) + (", …" if len(rows) > 5 else "")
        problems.append(
            f"row(s) {shown} beyond a full turn (row {i + 1}, joint '{joint_names[j]}' is "
            f"{x[i, j]:.4g} rad, beyond 2π): an outlier no joint reaches; remove or correct it"
        )
    return problems


def orient_columns(matrix: NDArray) -> NDArray[np.float64]:
    """``matrix`` with each column's sign fixed: the sum of its entries positive (for grasp
    postures, S1 then closes the hand as σ grows: its flexions outnumber its extensions);
    where that sum is below 1e-9 of the column's 1-norm, its entry of largest magnitude
    (the first such) positive."""
    out = np.array(matrix, dtype=float)
    for c in range(out.shape[1]):
        col = out[:, c]
        total = float(np.sum(col))
        if abs(total) > _SUM_TOLERANCE * float(np.sum(np.abs(col))):
            sign = math.copysign(1.0, total)
        else:
            sign = math.copysign(1.0, col[int(np.argmax(np.abs(col)))])
        out[:, c] = sign * col + 0.0  # + 0.0: no -0.0 in the table
    return out


def fit_synergies(joint_names: tuple[str, ...], postures: NDArray, n_synergies: int | None = None) -> SynergyFit:
    """Principal components of ``postures`` (m × n, rad): mean posture, unit synergy columns
    ordered by explained variance (signs by :func:`orient_columns`): ``n_synergies`` of them
    (at most min(n, m − 1)), by default every one whose variance exceeds 1e-12 of the
    largest (the others are directions the postures do not move in: arbitrary)."""
    x = np.asarray(postures, dtype=float)
    m, n = x.shape
    if len(joint_names) != n or m < 2:
        raise ValueError(f"postures must be (m >= 2, {len(joint_names)}), got {x.shape}")
    k_max = min(n, m - 1)
    mean = x.mean(axis=0)
    _, singular, vt = np.linalg.svd(x - mean, full_matrices=False)  # ordered by singular value
    variance = singular**2 / (m - 1)
    if np.ptp(x, axis=0).max() <= _SAME_POSTURE_RAD:
        raise ValueError(
            f"the {m} postures do not differ (every joint spreads by at most {_SAME_POSTURE_RAD:g} rad): "
            "no variance to fit synergies to"
        )
    k = int(np.sum(variance[:k_max] > _RANK_TOLERANCE * variance[0])) if n_synergies is None else int(n_synergies)
    if not 1 <= k <= k_max:
        raise ValueError(f"the number of synergies to keep must be 1 … {k_max} for {m} postures of {n} joints, got {n_synergies}")
    matrix = orient_columns(vt[:k].T)
    synergies = Synergies(tuple(joint_names), mean, matrix, tuple(f"S{i}" for i in range(1, k + 1)))
    return SynergyFit(synergies, variance[:k], float(np.sum(variance)))
