"""Friction-cone models of a grasp-force optimisation problem (a field of `GFOProblem`).

A model says which contact forces f_i (N) a contact can transmit, in the contact frame
(n, t1, t2) of `mechanics.contact_frames`. Today there is one model, the exact Coulomb
cone (`CircularCone`), a second-order cone solved by every back end of
`synergrasp.optimisation.gfo.solve_gfo`. A polyhedral (pyramid) model is a linear
constraint set, so a problem carrying one is a QP; it takes its place here with its own
`kind`, and the front door sends it to the back ends that accept that kind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

__all__ = ["CircularCone", "FrictionCone"]


@dataclass(frozen=True)
class CircularCone:
    """The exact Coulomb cone: ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i at every contact.

    mu: friction coefficient (dimensionless, > 0).
    """

    mu: float
    kind: ClassVar[str] = "circular"

    def __post_init__(self) -> None:
        if not (isinstance(self.mu, (int, float, np.floating)) and math.isfinite(self.mu) and self.mu > 0):
            raise ValueError(f"cone.mu must be a finite number > 0, got {self.mu!r}")
        object.__setattr__(self, "mu", float(self.mu))

    def narrowed(self, shrink: float) -> CircularCone:
        """The cone with mu (1 - shrink): strictly inside it means strictly inside this one
        (the strict internal-force test)."""
        return CircularCone(self.mu * (1.0 - shrink))

    def soc_rows(self, frames: NDArray) -> NDArray:
        """Rows (m, 3, 3) [mu n; t1; t2] per contact: the cone is rows @ f_i in SOC(3),
        {(u, v): u >= ||v||}. frames: (m, 3, 3) from `mechanics.contact_frames`."""
        rows = np.array(frames, dtype=float)
        rows[:, 0] = self.mu * rows[:, 0]
        return rows

    def violation(self, forces: NDArray, normals: NDArray, f_min: float) -> float:
        """Worst violation (N) of n.f >= f_min and ||f_t|| <= mu n.f over the contacts
        (<= 0 if the forces (3m,) N are admissible; NaN without contacts)."""
        n = np.asarray(normals, dtype=float)
        F = np.asarray(forces, dtype=float).reshape(-1, 3)
        if F.shape[0] == 0:
            return float("nan")
        fn = np.einsum("ij,ij->i", F, n)
        ft = np.linalg.norm(F - fn[:, None] * n, axis=1)
        return float(max(np.max(f_min - fn), np.max(ft - self.mu * fn)))


#: Every friction-cone model a problem may carry (a union once there is more than one).
FrictionCone = CircularCone
