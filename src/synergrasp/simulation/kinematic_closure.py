"""The quasi-static kinematic closure along S1 (docs/closure.md).

The joint reference follows q_r(σ) = clip(q_m + σ·S1, lower, upper) (``SynergyPath``) from
σ_open to σ_closed; a link that touches the object (or the hand itself) holds the joints
proximal to it, the distal joints and the other fingers keep following the reference (soft
synergies). The scene is never stepped: joints are set and the collision pipeline is
queried (``HandScene``). mm, rad, palm frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from synergrasp.hand.kinematics import FINGERS
from synergrasp.hand.synergies import SynergyPath
from synergrasp.simulation import bullet
from synergrasp.simulation.closure_march import MARCH_CROSS, march
from synergrasp.simulation.contacts import ClosureResult, closure_result
from synergrasp.simulation.placement import ObjectPose
from synergrasp.simulation.scene import HandScene

if TYPE_CHECKING:  # pragma: no cover
    from synergrasp.hand.kinematics import Hand
    from synergrasp.hand.synergies import Synergies
    from synergrasp.simulation.closure_params import ClosureParams

__all__ = ["KinematicClosure"]

_LONG_FINGERS = ("index", "middle", "ring", "little")
#: Distance (mm) within which the hand is queried for the next step size.
_QUERY_MARGIN_MM = 40.0
_MAX_REFINE = 40
#: Placeholder for gaps not yet known (``march`` computes them).
_NO_GAPS_ARGS = (np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0, dtype=np.int64))


class KinematicClosure:
    """The quasi-static kinematic closure along S1 on one scene of our own (hand capsules + object)."""

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
        # the path: from the fully open hand to where every joint moved by S1 is at a limit
        self.sigma_open, self.sigma_closed = self.path.closure_range(hand.flexion_joints)
        self.scene = HandScene(hand)
        self.fingers = [(tuple(j), tuple(li)) for j, li in zip(hand.finger_joints, hand.finger_links)]
        self.link_finger_index = np.full(hand.n_links, -1)
        self.link_chain_pos = np.full(hand.n_links, -1)
        for f, (_, links) in enumerate(self.fingers):
            for i, link in enumerate(links):
                self.link_finger_index[link] = f
                self.link_chain_pos[link] = i
        self.reach = self._joint_reach()
        self._profiles: dict[tuple[int, tuple[int, ...]], tuple[list[float], list[float]]] = {}
        self._profile_arrays: dict[bytes, tuple[NDArray, NDArray, NDArray]] = {}
        self.q_open = self.reference(self.sigma_open)
        self.self_pairs = self._monitored_pairs()
        self._chain: tuple[NDArray, NDArray, NDArray] | None = None  # made by the first ``_moving``
        self.finger_link_mask = np.zeros((len(self.fingers), hand.n_links), dtype=bool)
        for f, (_, links) in enumerate(self.fingers):
            self.finger_link_mask[f, list(links)] = True
        self.long_fingers = {f for f, name in enumerate(FINGERS) if name in _LONG_FINGERS}

    def close(self) -> None:
        """Release the scene."""
        self.scene.close()

    def grasp(self, placed: ObjectPose) -> ClosureResult:
        """Close the hand on the object ``placed`` (its shape at its pose)."""
        self.scene.place_object(placed)
        q, state, intersects = self.run()
        if intersects:
            return closure_result(
                self.hand,
                q,
                state,
                np.zeros(0, dtype=np.int64),
                np.zeros((0, 3)),
                np.zeros((0, 3)),
                0.0,
                intersects_open_hand=True,
            )
        links, points, normals, depth = self.scene.object_contacts(q, self.params.contact_distance_mm)
        return closure_result(self.hand, q, state, links, points, normals, depth)

    # -- kinematic helpers -------------------------------------------------------------
    def reference(self, sigma: float) -> NDArray:
        """q_r(σ), rad (``SynergyPath.reference``)."""
        return self.path.reference(sigma)

    def _joint_reach(self) -> NDArray:
        """Per joint, an upper bound (mm) on the distance of any point of the links it moves
        from its axis: from the joint's first axis to the farthest shape point of its link
        and the links distal to it in the extended chain (q = 0, where a chain is longest),
        plus one rolling gap (a joint's first axis sits that far before its link frame)."""
        from synergrasp.hand.kinematics import forward_kinematics

        hand = self.hand
        frames = forward_kinematics(hand, np.zeros(hand.n_joints))
        reach = np.zeros(hand.n_joints)
        for joints, links in self.fingers:
            for i, (joint, link) in enumerate(zip(joints, links)):
                base = frames[link, :3, 3]
                r = 0.0
                for distal in links[i:]:
                    for shape in hand.link_shapes[distal]:
                        centre = frames[distal] @ shape.pose
                        half = 0.5 * shape.length if shape.kind == "capsule" else 0.5 * float(np.linalg.norm(shape.size))
                        r = max(r, float(np.linalg.norm(centre[:3, 3] - base)) + half + shape.radius)
                # a coupled joint moves two links of its chain (hand file: ``follows``): the larger reach
                reach[joint] = max(reach[joint], r + 10.0)
        return reach

    def _monitored_pairs(self) -> tuple[tuple[int, int], ...]:
        """Hand–hand pairs checked during the closure: a finger link against the palm, the
        thumb or a neighbouring long finger (the long fingers lie side by side: one cannot
        reach a finger beyond its neighbour without touching the neighbour), except the
        knuckles (they barely move) and pairs already overlapping at the open posture (a
        property of the model, not an event)."""
        hand = self.hand
        pairs = []
        order = {name: k for k, name in enumerate(_LONG_FINGERS)}
        for i, j in bullet.self_collision_pairs(hand):
            fi, fj = hand.link_finger[i], hand.link_finger[j]
            if fi == fj:
                continue
            if fi in order and fj in order and abs(order[fi] - order[fj]) > 1:
                continue  # long fingers side by side: only neighbours can touch
            if any(hand.link_names[k].endswith("_knuckle") for k in (i, j)):
                continue
            pairs.append((i, j))
        self.scene.set_posture(self.q_open)
        gaps = self.scene.pair_distances(tuple(pairs))
        return tuple(p for p, gap in zip(pairs, gaps) if gap >= 0.0)

    # -- the closure ------------------------------------------------------------------------
    def _travel_profile(self, f: int, moving: tuple[int, ...]) -> tuple[list[float], list[float]]:
        """Knots σ_k on [σ_open, σ_closed] and the travel bound T(σ_k) (mm) accumulated from
        σ_open by any point of finger f when only the joints ``moving`` follow the reference.

        T is piecewise linear: joint j adds |S1_j| · reach_j mm per unit σ while its
        reference is inside its limits (a clipped joint does not move). Cached per
        (finger, moving joints): there are only a few such sets per finger.
        """
        key = (f, moving)
        profile = self._profiles.get(key)
        if profile is None:
            idx = list(moving)
            lo, hi = self.active_lo[idx], self.active_hi[idx]
            rate = np.abs(self.s1[idx]) * self.reach[idx]  # mm per unit σ while active
            knots = np.unique(
                np.clip(np.concatenate([lo, hi, [self.sigma_open, self.sigma_closed]]), self.sigma_open, self.sigma_closed)
            )
            mids = 0.5 * (knots[:-1] + knots[1:])
            speed = np.array([float(np.sum(rate[(lo <= m) & (hi >= m)])) for m in mids])
            profile = (knots.tolist(), np.concatenate([[0.0], np.cumsum(speed * np.diff(knots))]).tolist())
            self._profiles[key] = profile
        return profile

    def _profiles_of(self, held: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Every finger's travel profile (``_travel_profile``) for the joints that are not
        ``held``, as the padded arrays ``closure_march.march`` reads: knots (F, K), travel
        (F, K) and the number of knots per finger (0: none of its joints moves). Cached per
        held set."""
        key = held.tobytes()
        arrays = self._profile_arrays.get(key)
        if arrays is None:
            held_list = held.tolist()
            rows = []
            for f, (joints, _) in enumerate(self.fingers):
                moving = tuple(j for j in joints if not held_list[j])
                rows.append(self._travel_profile(f, moving) if moving else ([], []))
            width = max(1, max(len(k) for k, _ in rows))
            knots, travel = np.zeros((len(rows), width)), np.zeros((len(rows), width))
            for f, (k, t) in enumerate(rows):
                knots[f, : len(k)], travel[f, : len(t)] = k, t
            arrays = self._profile_arrays[key] = (knots, travel, np.array([len(k) for k, _ in rows], dtype=np.int64))
        return arrays

    def posture(self, sigma: float, held: NDArray, q_held: NDArray) -> NDArray:
        return np.where(held, q_held, self.reference(sigma))

    def run(self) -> tuple[NDArray, list[str], bool]:
        """Close the hand on the placed box from σ_open to σ_closed. Returns (q, finger_state,
        intersects_open_hand)."""
        p = self.params
        state = _HoldState(self)
        q = self.q_open.copy()
        self.scene.set_posture(q)
        d_all = self.scene.object_distance(p.contact_distance_mm)
        if np.min(d_all) < -p.penetration_tolerance_mm:
            return q, [], True
        # links touching (or slightly penetrating) the box in the open posture hold at once
        touching = d_all <= p.contact_distance_mm
        touching[0] = False
        state.touch_object(touching, q)
        sigma = self.sigma_open
        mv, pairs = self._moving(state)
        known: _Gaps | None = None  # the gaps at σ when known from the previous event
        path = (self.path.mean, self.path.direction, self.path.lower, self.path.upper)
        while sigma < self.sigma_closed and mv.any():
            knots, travel, n_knots = self._profiles_of(state.held)
            now = known if known is not None else _NO_GAPS
            status, sigma, parts = march(
                sigma,
                self.sigma_closed,
                (now.q, now.d_obj, now.d_self, now.partner),
                known is not None,
                state.held,
                state.q_held,
                path,
                self.scene.query_args(),
                self.scene.pair_args(pairs),
                mv,
                self.finger_link_mask,
                knots,
                travel,
                n_knots,
                p.step_mm,
                _QUERY_MARGIN_MM,
                p.tolerance_mm,
                _MAX_REFINE,
            )
            if status != MARCH_CROSS:
                break
            event = _Gaps(*parts)
            touch = p.contact_distance_mm
            if not (np.any(event.d_obj <= touch) or np.any(event.d_self <= touch)):
                event = event.forced_touch(touch)  # the refinement ran out: the closest link touches
            state.touch_object(event.d_obj <= touch, event.q)
            state.touch_hand(event, touch)
            # the posture at σ is the event's again (new holds keep its values); a link that
            # still moves keeps all its pairs, so its gaps are those of the event
            mv, pairs = self._moving(state)
            known = event.masked(mv)
        q_final = self.posture(min(sigma, self.sigma_closed), state.held, state.q_held)
        return q_final, state.finger_states(), False

    def _moving(self, state: _HoldState) -> tuple[NDArray, tuple[tuple[int, int], ...]]:
        """Links that still move (their own joint is not held) and the monitored pairs with one."""
        if self._chain is None:  # each finger link with its own joint, and the pairs' ends, as arrays
            links = [link for _, chain in self.fingers for link in chain]
            joints = [joints[i] for joints, chain in self.fingers for i in range(len(chain))]
            ends = np.asarray(self.self_pairs, dtype=np.int64).reshape(-1, 2)
            self._chain = (np.asarray(links, dtype=np.int64), np.asarray(joints, dtype=np.int64), ends)
        links, joints, ends = self._chain
        mv = np.zeros(self.hand.n_links, dtype=bool)
        mv[links] = ~state.held[joints]
        keep = (mv[ends[:, 0]] | mv[ends[:, 1]]).tolist()
        return mv, tuple(pr for pr, k in zip(self.self_pairs, keep) if k)


@dataclass
class _Gaps:
    """Gaps of the moving links at posture q (mm): to the box, to the nearest monitored
    hand link and which link that is (-1 if none)."""

    q: NDArray
    d_obj: NDArray
    d_self: NDArray
    partner: NDArray

    def masked(self, moving: NDArray) -> _Gaps:
        d_obj, d_self = self.d_obj.copy(), self.d_self.copy()
        d_obj[~moving] = np.inf
        d_self[~moving] = np.inf
        return _Gaps(self.q, d_obj, d_self, self.partner)

    def forced_touch(self, touch_mm: float) -> _Gaps:
        """The same gaps with the closest link set to touch (``touch_mm``)."""
        d_obj, d_self = self.d_obj.copy(), self.d_self.copy()
        k = int(np.argmin(np.minimum(d_obj, d_self)))
        if d_obj[k] <= d_self[k]:
            d_obj[k] = min(d_obj[k], touch_mm)
        else:
            d_self[k] = min(d_self[k], touch_mm)
        return _Gaps(self.q, d_obj, d_self, self.partner)


_NO_GAPS = _Gaps(*_NO_GAPS_ARGS)


class _HoldState:
    """Which joints are held (and at what angle), and what each finger has touched.

    A link touching the box, the palm or the thumb holds the joints of its chain up to
    its own. Two long fingers touching each other hold only their abduction joints, and
    flexion goes on (docs/closure.md); if they touch again with both abductions held, it
    is a block like any other.
    """

    def __init__(self, closure: KinematicClosure) -> None:
        self.c = closure
        n = closure.hand.n_joints
        self.held = np.zeros(n, dtype=bool)
        self.q_held = np.zeros(n)
        self.object = np.zeros(len(closure.fingers), dtype=bool)
        self.hand = np.zeros(len(closure.fingers), dtype=bool)

    def _hold(self, joints: tuple[int, ...], q: NDArray) -> None:
        for j in joints:
            if not self.held[j]:
                self.held[j], self.q_held[j] = True, q[j]

    def _hold_chain(self, link: int, q: NDArray) -> int:
        f = int(self.c.link_finger_index[link])
        if f >= 0:
            self._hold(self.c.fingers[f][0][: self.c.link_chain_pos[link] + 1], q)
        return f

    def touch_object(self, touching: NDArray, q: NDArray) -> None:
        for link in np.flatnonzero(touching):
            f = self._hold_chain(int(link), q)
            if f >= 0:
                self.object[f] = True

    def touch_hand(self, gaps: _Gaps, touch_mm: float) -> None:
        c = self.c
        for link in np.flatnonzero(gaps.d_self <= touch_mm):
            other = int(gaps.partner[link])
            fa, fb = int(c.link_finger_index[link]), int(c.link_finger_index[other]) if other >= 0 else -1
            if fa in c.long_fingers and fb in c.long_fingers:
                abd = (c.fingers[fa][0][0], c.fingers[fb][0][0])
                if not (self.held[abd[0]] and self.held[abd[1]]):
                    self._hold(abd, gaps.q)
                    continue
            if self._hold_chain(int(link), gaps.q) >= 0:
                self.hand[fa] = True

    def finger_states(self) -> list[str]:
        return ["contact" if self.object[f] else "self" if self.hand[f] else "limit" for f in range(len(self.c.fingers))]
