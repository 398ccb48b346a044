"""Synergies carried over to another hand in the object's terms (docs/synergies.md, "Mapping a
synergy table onto another hand").

What a grasp depends on is where the fingertips are and how the thumb's tip stands against the
other tips, not the joint angles that put them there. So a synergy table of a *source* hand
(the study's SoftHand model with its table) is carried over to a *target* hand by

1. sampling postures along each source synergy, q_s = clip(q_m + σ·S_k) (S1 over the source's
   whole closure path σ_open … σ_closed, every other column over σ ∈ [−1, 1]);
2. taking, at each sample, the five fingertip points relative to the hand's knuckle centre
   and the four thumb-to-fingertip vectors, both in the palm frame (docs/hand.md) and divided
   by the hand's size (:func:`hand_size`);
3. finding the target's joint angles whose same quantities, times the target's size, match
   them in the least-squares sense within the target's joint limits (inverse kinematics on the
   target's own kinematics: for a hand read from MJCF, MuJoCo's, docs/hand.md), with a small
   pull toward the previous sample's solution so that the walk along a synergy is continuous;
4. fitting the target's table to the mapped postures by principal components
   (:func:`synergrasp.hand.synergy_fit.fit_synergies`), with the variance each explains.

Steps 2–3 are *vector retargeting* as in the ``dex-retargeting`` package (Qin et al., "AnyTeleop",
RSS 2023: the robot's keypoint vectors matched to the human's, scaled, with a smoothness term);
sampling along the synergies and fitting the target's synergies from the mapped postures
follows the object-based synergy mapping of Gioioso et al. (IEEE T-RO 29(4), 2013), which maps
synergies through what the fingertips do to an object rather than joint by joint. Everything
here is deterministic: fixed samples, a fixed start, a deterministic solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from synergrasp.hand.kinematics import Hand, contact_jacobian, fingertip_positions, forward_kinematics
from synergrasp.hand.synergies import Synergies, SynergyPath
from synergrasp.hand.synergy_fit import SynergyFit, fit_synergies

__all__ = ["MapParams", "MappedPostures", "hand_size", "grasp_features", "map_postures", "map_synergies"]

#: Thumb first, then index, middle, ring, little (FINGERS order): the long fingers are 1 … 4.
_LONG = (1, 2, 3, 4)


@dataclass(frozen=True)
class MapParams:
    """How the mapping samples and weighs (docs/synergies.md).

    ``s1_samples``: postures along S1 over the source's closure path σ_open … σ_closed;
    ``other_samples``: postures along each other column over σ ∈ [−``other_sigma``,
    +``other_sigma``] (unit σ: the tables' columns are unit vectors, rad per unit σ);
    ``tip_weight``, ``vector_weight``: weights of the fingertip-point and the thumb-to-fingertip
    residuals (both mm on the target hand); ``smoothing_mm_per_rad``: weight of the pull toward
    the previous sample's posture (mm of residual per rad of joint motion);
    ``tolerance``: the solver's relative tolerance on the cost and the joint angles.
    """

    s1_samples: int = 49
    other_samples: int = 9
    other_sigma: float = 1.0
    tip_weight: float = 1.0
    vector_weight: float = 2.0
    smoothing_mm_per_rad: float = 2.0
    tolerance: float = 1e-10


@dataclass(frozen=True)
class MappedPostures:
    """The sampled source postures and their images on the target hand.

    ``synergy`` (m,) the 1-based source column each sample lies on (0: the mean posture);
    ``sigma`` (m,) its coordinate; ``source`` (m, n_s) and ``target`` (m, n_t) postures, rad;
    ``residual_mm`` (m,) the root mean square of the weighted tip and vector residuals, mm on
    the target hand.
    """

    synergy: NDArray[np.int64]
    sigma: NDArray[np.float64]
    source: NDArray[np.float64]
    target: NDArray[np.float64]
    residual_mm: NDArray[np.float64]


def _straight(hand: Hand) -> NDArray[np.float64]:
    """Every joint at 0 (clipped to its limits): the fingers straight."""
    return np.clip(np.zeros(hand.n_joints), hand.lower, hand.upper)


def hand_size(hand: Hand) -> tuple[NDArray[np.float64], float]:
    """The hand's knuckle centre (palm frame, mm) and size (mm): the mean of the four long
    fingers' first-joint origins and the mean distance from those origins to their fingertips,
    fingers straight (every joint at 0, clipped to its limits)."""
    q = _straight(hand)
    frames = forward_kinematics(hand, q)
    knuckles = np.array([frames[hand.finger_links[f][0], :3, 3] for f in _LONG])
    tips = fingertip_positions(hand, q)[list(_LONG)]
    return knuckles.mean(axis=0), float(np.mean(np.linalg.norm(tips - knuckles, axis=1)))


def grasp_features(hand: Hand, q: NDArray, centre: NDArray, size_mm: float) -> NDArray[np.float64]:
    """(9, 3) what the grasp depends on at q (rad), divided by the hand's size: the five
    fingertips relative to the knuckle centre, then the four vectors from the thumb's tip to
    the index, middle, ring and little tips (palm frame)."""
    tips = fingertip_positions(hand, q)
    return np.vstack([tips - centre, tips[1:] - tips[0]]) / size_mm


class _Retarget:
    """The least-squares problem of one target posture (mm residuals, analytic Jacobian)."""

    def __init__(self, hand: Hand, params: MapParams) -> None:
        self.hand = hand
        self.centre, self.size = hand_size(hand)
        self.weights = np.repeat([params.tip_weight] * 5 + [params.vector_weight] * 4, 3)
        self.smoothing = params.smoothing_mm_per_rad
        self.tolerance = params.tolerance
        # the features are linear in the tips: F = A @ tips (+ constant), A (9, 5)
        a = np.vstack([np.eye(5), np.hstack([-np.ones((4, 1)), np.eye(4)])])
        self.tip_map = np.kron(a, np.eye(3)) * self.weights[:, None]

    def residual(self, q: NDArray, goal: NDArray, previous: NDArray) -> NDArray:
        features = grasp_features(self.hand, q, self.centre, self.size) * self.size
        return np.concatenate([(features.ravel() - goal) * self.weights, self.smoothing * (q - previous)])

    def jacobian(self, q: NDArray, goal: NDArray, previous: NDArray) -> NDArray:
        tips = fingertip_positions(self.hand, q)
        jac = contact_jacobian(self.hand, q, self.hand.fingertip_link, tips)  # (15, n)
        return np.vstack([self.tip_map @ jac, self.smoothing * np.eye(self.hand.n_joints)])

    def solve(self, goal: NDArray, start: NDArray) -> tuple[NDArray, float]:
        """The posture matching ``goal`` (27,) mm, started from and pulled toward ``start``;
        and the RMS of its weighted feature residuals, mm."""
        lower, upper = self.hand.lower, self.hand.upper
        x0 = np.clip(start, lower + 1e-9 * (upper - lower), upper - 1e-9 * (upper - lower))
        result = least_squares(
            self.residual,
            x0,
            jac=self.jacobian,
            bounds=(lower, upper),
            method="trf",
            xtol=self.tolerance,
            ftol=self.tolerance,
            gtol=self.tolerance,
            max_nfev=200,
            args=(goal, start),
        )
        q = np.clip(result.x, lower, upper)
        rms = float(np.sqrt(np.mean(self.residual(q, goal, start)[: goal.size] ** 2)))
        return q, rms


def _sigmas(path: SynergyPath, synergy: int, source: Hand, params: MapParams) -> NDArray[np.float64]:
    """The σ samples of a source column, 0 included."""
    if synergy == 1:
        lo, hi = path.closure_range(source.flexion_joints)
        grid = np.linspace(lo, hi, params.s1_samples)
    else:
        grid = np.linspace(-params.other_sigma, params.other_sigma, params.other_samples)
    return np.unique(np.concatenate([grid, [0.0]]))


def map_postures(source: Hand, table: Synergies, target: Hand, params: MapParams = MapParams()) -> MappedPostures:
    """Sample the source table's postures (module docstring, step 1) and map each onto the
    target by vector retargeting (steps 2–3). The mean posture is solved first, from the middle
    of the target's joint ranges; each column's samples are then walked outward from σ = 0 in
    both directions, each solve started from and pulled toward the previous one."""
    if tuple(table.joint_names) != tuple(source.joint_names):
        raise ValueError(
            f"the synergy table's joints {list(table.joint_names)} are not the source hand's {list(source.joint_names)}"
        )
    centre, size = hand_size(source)
    problem = _Retarget(target, params)
    scale = problem.size

    def goal(q_source: NDArray) -> NDArray:
        return (grasp_features(source, q_source, centre, size) * scale).ravel()

    q_mean_source = np.clip(table.mean, source.lower, source.upper)
    q_mean, rms_mean = problem.solve(goal(q_mean_source), 0.5 * (target.lower + target.upper))
    rows: list[tuple[int, float, NDArray, NDArray, float]] = [(0, 0.0, q_mean_source, q_mean, rms_mean)]
    for k in range(1, table.n_synergies + 1):
        path = SynergyPath.along(table, source.lower, source.upper, synergy=k)
        sigmas = _sigmas(path, k, source, params)
        zero = int(np.flatnonzero(sigmas == 0.0)[0])
        for walk in (sigmas[zero + 1 :], sigmas[:zero][::-1]):
            previous = q_mean
            for sigma in walk:
                q_source = path.reference(float(sigma))
                previous, rms = problem.solve(goal(q_source), previous)
                rows.append((k, float(sigma), q_source, previous, rms))
    return MappedPostures(
        np.array([r[0] for r in rows], dtype=np.int64),
        np.array([r[1] for r in rows]),
        np.array([r[2] for r in rows]),
        np.array([r[3] for r in rows]),
        np.array([r[4] for r in rows]),
    )


def map_synergies(
    source: Hand, table: Synergies, target: Hand, n_synergies: int | None = None, params: MapParams = MapParams()
) -> tuple[SynergyFit, MappedPostures]:
    """The target hand's synergy table fitted to the mapped postures (:func:`map_postures`) by
    principal components (:func:`fit_synergies`): ``n_synergies`` columns (default: as many as
    the source table has, at most as many as the mapped postures span)."""
    mapped = map_postures(source, table, target, params)
    k = n_synergies
    if k is None:
        k = min(table.n_synergies, fit_synergies(target.joint_names, mapped.target).synergies.n_synergies)
    return fit_synergies(target.joint_names, mapped.target, k), mapped
