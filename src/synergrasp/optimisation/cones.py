"""Friction-cone models of a grasp-force optimisation problem (a field of `GFOProblem`).

A model says which contact forces f_i (N) a contact can transmit, in the contact frame
(n, t1, t2) of `mechanics.contact_frames`. Two kinds: the exact Coulomb cone
(`CircularCone`, a second-order cone) and its pyramid approximations (`PyramidCone`,
linear faces: a problem carrying one is a QP). Each model has a `kind`;
`synergrasp.optimisation.gfo.METHODS` says which back ends accept which kind.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from synergrasp.optimisation.mechanics import contact_frames

__all__ = ["CONE_MODELS", "CircularCone", "FrictionCone", "PyramidCone", "cone_model"]


def _check_mu(mu: float) -> None:
    if not (isinstance(mu, (int, float, np.floating)) and math.isfinite(mu) and mu > 0):
        raise ValueError(f"cone.mu must be a finite number > 0, got {mu!r}")


@dataclass(frozen=True)
class CircularCone:
    """The exact Coulomb cone: ||f_i - (n_i.f_i) n_i|| <= mu n_i.f_i at every contact.

    mu: friction coefficient (dimensionless, > 0).
    """

    mu: float
    kind: ClassVar[str] = "circular"

    def __post_init__(self) -> None:
        _check_mu(self.mu)
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


@dataclass(frozen=True)
class PyramidCone:
    """A pyramid (polyhedral) model of the Coulomb cone with `sides` faces, one edge along the
    t1 axis of the contact frame (`mechanics.contact_frames`), the others every 2 pi / sides.

    inscribed=True: the edges lie on the circular cone (the faces cut it, every admissible
    force is admissible for the circular cone: conservative; along a face's middle the
    friction is mu cos(pi / sides)); False: circumscribed, the faces touch the circular cone
    (along the edges the friction reaches mu / cos(pi / sides)). A problem with this cone has
    linear constraints only: a QP.
    """

    mu: float
    sides: int = 4
    inscribed: bool = True
    kind: ClassVar[str] = "pyramid"

    def __post_init__(self) -> None:
        _check_mu(self.mu)
        object.__setattr__(self, "mu", float(self.mu))
        if not (isinstance(self.sides, (int, np.integer)) and self.sides >= 3):
            raise ValueError(f"cone.sides must be an int >= 3, got {self.sides!r}")
        if not isinstance(self.inscribed, bool):
            raise ValueError(f"cone.inscribed must be true or false, got {self.inscribed!r}")

    def narrowed(self, shrink: float) -> PyramidCone:
        """The pyramid with mu (1 - shrink) (the strict internal-force test)."""
        return PyramidCone(self.mu * (1.0 - shrink), self.sides, self.inscribed)

    def face_rows(self, frames: NDArray) -> NDArray:
        """Rows (m, sides, 3) a_k per contact: f_i is inside the pyramid iff a_k . f_i <= 0 for
        every face k, a_k = cos(phi_k) t1 + sin(phi_k) t2 - mu_face n with phi_k = (2k + 1) pi /
        sides (the faces' outward directions) and mu_face = mu cos(pi / sides) (inscribed) or
        mu (circumscribed)."""
        frames = np.asarray(frames, dtype=float)
        phi = (2.0 * np.arange(self.sides) + 1.0) * math.pi / self.sides
        mu_face = self.mu * math.cos(math.pi / self.sides) if self.inscribed else self.mu
        return (
            np.cos(phi)[None, :, None] * frames[:, None, 1]
            + np.sin(phi)[None, :, None] * frames[:, None, 2]
            - mu_face * frames[:, None, 0]
        )

    def violation(self, forces: NDArray, normals: NDArray, f_min: float) -> float:
        """Worst violation (N) of n.f >= f_min and of the faces a_k . f <= 0 (<= 0 if admissible)."""
        F = np.asarray(forces, dtype=float).reshape(-1, 3)
        if F.shape[0] == 0:
            return float("nan")
        frames = contact_frames(normals)
        fn = np.einsum("ij,ij->i", F, frames[:, 0])
        faces = np.einsum("ikj,ij->ik", self.face_rows(frames), F)
        return float(max(np.max(f_min - fn), np.max(faces)))


#: Every friction-cone model a problem may carry.
FrictionCone = CircularCone | PyramidCone

#: The study's friction-cone models by name (`GFOParams.friction_cone`).
CONE_MODELS: dict[str, tuple[type, dict]] = {
    "circular": (CircularCone, {}),
    "pyramid4_inscribed": (PyramidCone, {"sides": 4, "inscribed": True}),
    "pyramid8_inscribed": (PyramidCone, {"sides": 8, "inscribed": True}),
    "pyramid8_circumscribed": (PyramidCone, {"sides": 8, "inscribed": False}),
}


def cone_model(name: str, mu: float) -> FrictionCone:
    """The friction-cone model `name` (one of CONE_MODELS) with friction coefficient mu."""
    if name not in CONE_MODELS:
        raise ValueError(f"friction_cone must be one of {list(CONE_MODELS)}, got {name!r}")
    cls, options = CONE_MODELS[name]
    return cls(mu, **options)
