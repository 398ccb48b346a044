"""The quasi-static kinematic closure along S1 (docs/closure.md).

The joint reference follows q_r(σ) = clip(q_m + σ·S1, lower, upper) (``SynergyPath``) from
σ_open to σ_closed; a link that touches the object (or the hand itself) holds the joints
proximal to it, the distal joints and the other fingers keep following the reference (soft
synergies). The scene is never stepped: joints are set and the collision pipeline is
queried (``HandScene``). mm, rad, palm frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.synergies import SynergyPath
from synergrasp.simulation import bullet
from synergrasp.simulation.contacts import ClosureResult, closure_result
from synergrasp.simulation.placement import ObjectPose
from synergrasp.simulation.scene import HandScene

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.closure import ClosureParams

__all__ = ["KinematicClosure"]

_LONG_FINGERS = ("index", "middle", "ring", "little")
#: Distance (mm) within which the hand is queried for the next step size.
_QUERY_MARGIN_MM = 40.0
_MAX_REFINE = 40


class KinematicClosure:
    """The quasi-static kinematic closure along S1 on one pybullet scene (hand + box)."""

    def __init__(self, hand: Hand, synergies: Synergies, params: ClosureParams) -> None:
        self.hand = hand
        self.params = params
        names = tuple(synergies.joint_names)
        if names != tuple(hand.joint_names):
            raise ValueError(f"synergies.joint_names must equal hand.joint_names {hand.joint_names}, got {names}")
        self.path = SynergyPath.along(synergies, hand.lower, hand.upper)
        self.s1 = self.path.direction
        # σ interval on which each joint's reference is inside its limits (clipped outside)
        self.active_lo, self.active_hi = self.path.active_interval()
        self.scene = HandScene(hand)
        self.fingers = [(tuple(j), tuple(li)) for j, li in zip(hand.finger_joints, hand.finger_links)]
        self.link_finger_index = np.full(hand.n_links, -1)
        self.link_chain_pos = np.full(hand.n_links, -1)
        for f, (_, links) in enumerate(self.fingers):
            for i, link in enumerate(links):
                self.link_finger_index[link] = f
                self.link_chain_pos[link] = i
        self.reach = self._finger_reach()
        self._profiles: dict[tuple[int, tuple[int, ...]], tuple[NDArray, NDArray]] = {}
        self.q_open = self.reference(params.sigma_open)
        self.self_pairs = self._monitored_pairs()

    def close(self) -> None:
        """Release the pybullet scene."""
        self.scene.close()

    def grasp(self, size_mm: NDArray, placed: ObjectPose) -> ClosureResult:
        """Close the hand on a box of edge lengths ``size_mm`` (mm) placed at ``placed``."""
        self.scene.place_box(size_mm, placed)
        q, state, intersects = self.run()
        if intersects:
            return closure_result(self.hand, q, state, np.zeros(0, dtype=np.int64), np.zeros((0, 3)),
                                  np.zeros((0, 3)), 0.0, intersects_open_hand=True)
        links, points, normals, depth = self.scene.object_contacts(q, self.params.contact_distance_mm)
        return closure_result(self.hand, q, state, links, points, normals, depth)

    # -- kinematic helpers -------------------------------------------------------------
    def reference(self, sigma: float) -> NDArray:
        """q_r(σ), rad (``SynergyPath.reference``)."""
        return self.path.reference(sigma)

    def _finger_reach(self) -> NDArray:
        """Per finger, an upper bound (mm) on the distance of any point of its links from any
        of its joint axes: the extended chain (q = 0) from the finger's first axis, plus radius."""
        from synergrasp.hand.kinematics import forward_kinematics

        frames = forward_kinematics(self.hand, np.zeros(self.hand.n_joints))
        reach = np.zeros(len(self.fingers))
        for f, (_, links) in enumerate(self.fingers):
            base = frames[links[0], :3, 3]
            r = 0.0
            for link in links:
                for shape in self.hand.link_shapes[link]:
                    centre = frames[link] @ shape.pose
                    half = 0.5 * shape.length if shape.kind == "capsule" else 0.5 * float(np.linalg.norm(shape.size))
                    ext = half + shape.radius
                    r = max(r, float(np.linalg.norm(centre[:3, 3] - base)) + ext)
            reach[f] = r + 10.0  # the first axis sits up to one rolling gap before the base frame
        return reach

    def _monitored_pairs(self) -> tuple[tuple[int, int], ...]:
        """Self-collision pairs that stop a finger: a finger link against the palm or against a
        link of another finger, except long finger against long finger (they flex in
        side-by-side planes and slide along each other) and pairs already overlapping at the
        open posture (a property of the model, not an event)."""
        hand = self.hand
        pairs = []
        for i, j in bullet.self_collision_pairs(hand):
            fi, fj = hand.link_finger[i], hand.link_finger[j]
            if fi == fj:
                continue
            if fi in _LONG_FINGERS and fj in _LONG_FINGERS:
                continue
            # the knuckles barely move: only the outer links can run into the palm or the thumb
            if any(hand.link_names[k].endswith("_knuckle") for k in (i, j)):
                continue
            pairs.append((i, j))
        self.scene.set_posture(self.q_open)
        overlap = bullet.self_closest_points(self.scene.client, self.scene.body, 0.0, tuple(pairs))
        bad = {(int(a), int(b)) for a, b, d in zip(overlap.link_a, overlap.link_b, overlap.distance) if d < 0}
        return tuple(p for p in pairs if p not in bad and (p[1], p[0]) not in bad)

    # -- the closure ------------------------------------------------------------------------
    def _travel_profile(self, f: int, moving: tuple[int, ...]) -> tuple[NDArray, NDArray]:
        """Knots σ_k on [σ_open, σ_closed] and the travel bound T(σ_k) (mm) accumulated from
        σ_open by any point of finger f when only the joints ``moving`` follow the reference.

        T is piecewise linear: joint j adds |S1_j| · reach(f) mm per unit σ while its
        reference is inside its limits (a clipped joint does not move). Cached per
        (finger, moving joints): there are only a few such sets per finger.
        """
        key = (f, moving)
        profile = self._profiles.get(key)
        if profile is None:
            p = self.params
            idx = list(moving)
            lo, hi = self.active_lo[idx], self.active_hi[idx]
            rate = np.abs(self.s1[idx]) * self.reach[f]  # mm per unit σ while active
            knots = np.unique(np.clip(np.concatenate([lo, hi, [p.sigma_open, p.sigma_closed]]),
                                      p.sigma_open, p.sigma_closed))
            mids = 0.5 * (knots[:-1] + knots[1:])
            speed = np.array([float(np.sum(rate[(lo <= m) & (hi >= m)])) for m in mids])
            profile = (knots, np.concatenate([[0.0], np.cumsum(speed * np.diff(knots))]))
            self._profiles[key] = profile
        return profile

    def advance(self, sigma: float, budget_mm: NDArray, held: NDArray) -> float:
        """Largest σ' ≤ σ_closed such that no point of finger f travels more than
        budget_mm[f] on [σ, σ'] (clipped joints do not move; held joints do not move)."""
        best = self.params.sigma_closed
        for f, (joints, _) in enumerate(self.fingers):
            moving = tuple(j for j in joints if not held[j])
            if not moving:
                continue
            knots, travel = self._travel_profile(f, moving)
            level = float(np.interp(sigma, knots, travel)) + budget_mm[f]
            if level > travel[-1]:
                continue  # the budget outlasts the closure
            k = int(np.searchsorted(travel, level, side="left"))  # travel[k-1] < level <= travel[k]
            t0, t1 = travel[k - 1], travel[k]
            best = min(best, knots[k - 1] + (level - t0) / (t1 - t0) * (knots[k] - knots[k - 1]))
        return best

    def posture(self, sigma: float, held: NDArray, q_held: NDArray) -> NDArray:
        return np.where(held, q_held, self.reference(sigma))

    def gaps(self, q: NDArray, moving_links: NDArray, pairs: tuple[tuple[int, int], ...],
             margin_mm: float) -> tuple[NDArray, NDArray]:
        """Per link: distance to the box and to the monitored hand links, at posture q (mm)."""
        self.scene.set_posture(q)
        d_obj = self.scene.object_distance(margin_mm)
        d_self = self.scene.self_distance(pairs, margin_mm)
        d_obj[~moving_links] = np.inf
        d_self[~moving_links] = np.inf
        return d_obj, d_self

    def run(self) -> tuple[NDArray, list[str], bool]:
        """Close the hand on the placed box from σ_open. Returns (q, finger_state,
        intersects_open_hand)."""
        p = self.params
        hand = self.hand
        n = hand.n_joints
        held = np.zeros(n, dtype=bool)
        q_held = np.zeros(n)
        touched_obj = np.zeros(len(self.fingers), dtype=bool)
        touched_self = np.zeros(len(self.fingers), dtype=bool)
        q = self.q_open.copy()
        self.scene.set_posture(q)
        d_all = self.scene.object_distance(p.contact_distance_mm)
        if np.min(d_all) < -p.penetration_tolerance_mm:
            return q, [], True

        def moving_links() -> NDArray:
            mv = np.zeros(hand.n_links, dtype=bool)
            for joints, links in self.fingers:
                for i, link in enumerate(links):
                    mv[link] = not held[joints[i]]  # a link moves unless its own joint (and so all proximal) is held
            return mv

        def hold(links_touching: NDArray, q_now: NDArray) -> None:
            for link in np.flatnonzero(links_touching):
                f = self.link_finger_index[link]
                if f < 0:
                    continue
                joints = self.fingers[f][0][: self.link_chain_pos[link] + 1]
                for j in joints:
                    if not held[j]:
                        held[j] = True
                        q_held[j] = q_now[j]

        # links touching (or slightly penetrating) the box in the open posture hold at once
        touching = d_all <= p.contact_distance_mm
        touching[0] = False
        hold(touching, q)
        touched_obj[self.link_finger_index[np.flatnonzero(touching)]] = True

        sigma = p.sigma_open
        mv = moving_links()
        pairs = tuple(pr for pr in self.self_pairs if mv[pr[0]] or mv[pr[1]])
        # gaps (margin _QUERY_MARGIN_MM) at the posture of σ, when already known from the
        # previous step's check or event: every query is made once
        known: tuple[NDArray, NDArray] | None = None
        while sigma < p.sigma_closed:
            if not mv.any():
                break
            q = self.posture(sigma, held, q_held)
            d_obj, d_self = known if known is not None else self.gaps(q, mv, pairs, _QUERY_MARGIN_MM)
            budget = np.full(len(self.fingers), p.step_mm)
            for f, (_, links) in enumerate(self.fingers):
                free = min(float(np.min(d_obj[list(links)])), 0.5 * float(np.min(d_self[list(links)])))
                budget[f] = max(p.step_mm, min(free, _QUERY_MARGIN_MM))
            sigma_next = self.advance(sigma, budget, held)
            if sigma_next <= sigma:
                break
            q_next = self.posture(sigma_next, held, q_held)
            o_next, s_next = self.gaps(q_next, mv, pairs, _QUERY_MARGIN_MM)
            if min(o_next.min(), s_next.min()) >= 0.0:
                sigma, known = sigma_next, (o_next, s_next)
                continue
            # a moving link crosses something in (σ, σ_next]: find where, to within tolerance_mm
            lo, hi = sigma, sigma_next
            d_lo = min(d_obj.min(), d_self.min())
            d_hi = min(o_next.min(), s_next.min())
            side = 0
            o_at, s_at, q_at = None, None, None
            for _ in range(_MAX_REFINE):
                # Illinois false position on the smallest gap, bisection when it stalls
                if np.isfinite(d_lo) and (hi - lo) > 1e-12:
                    mid = hi - d_hi * (hi - lo) / (d_hi - d_lo)
                    if not lo < mid < hi:
                        mid = 0.5 * (lo + hi)
                else:
                    mid = 0.5 * (lo + hi)
                q_mid = self.posture(mid, held, q_held)
                o_mid, s_mid = self.gaps(q_mid, mv, pairs, _QUERY_MARGIN_MM)
                d_mid = min(o_mid.min(), s_mid.min())
                if d_mid < 0.0:
                    hi, d_hi = mid, d_mid
                    if side == -1:
                        d_lo *= 0.5
                    side = -1
                else:
                    lo, d_lo = mid, d_mid
                    o_at, s_at, q_at = o_mid, s_mid, q_mid
                    if d_mid <= p.tolerance_mm:
                        break
                    if side == +1:
                        d_hi *= 0.5
                    side = +1
            if q_at is None:  # never left σ: the gaps at σ are the event
                q_at, o_at, s_at = q, d_obj, d_self
                lo = sigma
            obj_touch = o_at <= p.contact_distance_mm
            self_touch = s_at <= p.contact_distance_mm
            if not (obj_touch.any() or self_touch.any()):
                # refinement ran out of iterations: hold the closest link so the loop progresses
                nearest = np.argmin(np.minimum(o_at, s_at))
                (obj_touch if o_at[nearest] <= s_at[nearest] else self_touch)[nearest] = True
            hold(obj_touch | self_touch, q_at)
            for link in np.flatnonzero(obj_touch):
                touched_obj[self.link_finger_index[link]] = True
            for link in np.flatnonzero(self_touch):
                touched_self[self.link_finger_index[link]] = True
            sigma = lo
            # the posture at σ is q_at again (the new holds keep q_at's values); a link that
            # still moves keeps all its pairs, so its gaps are those of the event
            mv = moving_links()
            pairs = tuple(pr for pr in self.self_pairs if mv[pr[0]] or mv[pr[1]])
            o_at, s_at = o_at.copy(), s_at.copy()
            o_at[~mv] = np.inf
            s_at[~mv] = np.inf
            known = (o_at, s_at)
        q_final = self.posture(min(sigma, p.sigma_closed), held, q_held)
        state = ["contact" if touched_obj[f] else "self" if touched_self[f] else "limit"
                 for f in range(len(self.fingers))]
        return q_final, state, False
