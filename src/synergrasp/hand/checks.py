"""What the study asks of a hand beyond a well-formed hand file, checked before any job.

Every closure model, the placement of the box against the open hand and the pictures collide
the hand as capsules and boxes (``synergrasp.simulation.capsules.HandCapsules``): each finger
link must be exactly one capsule and the palm one or more boxes. :func:`closure_shape_problems`
states that once (the closure raises with its first line); :func:`check_hand` runs it with
the file's checks and returns the warnings on dimensions far from a human hand's.
"""

from __future__ import annotations

from pathlib import Path

from synergrasp.hand.description import hand_spec
from synergrasp.hand.hand_file import FINGERS
from synergrasp.hand.kinematics import Hand, build_hand

__all__ = ["link_field", "closure_shape_problems", "check_hand"]


def link_field(hand: Hand, link: int) -> str:
    """The hand-file field holding the shapes of ``link`` (``palm.shapes`` for the palm)."""
    if link == 0:
        return "palm.shapes"
    finger = hand.link_finger[link]
    joint = hand.finger_links[FINGERS.index(finger)].index(link)
    return f"fingers.{finger}.joints[{joint}].shapes"


def closure_shape_problems(hand: Hand) -> list[str]:
    """Where ``hand``'s shapes are not what the closure collides (one capsule per finger link,
    none for a link that only carries a joint in a hand read from MJCF, a palm of boxes),
    one line per field (empty: none)."""
    problems = []
    palm = [s.kind for s in hand.link_shapes[0]]
    if not palm or any(kind != "box" for kind in palm):
        problems.append(f"palm.shapes: the closure needs a palm made of one or more boxes, got {palm}")
    for link in range(1, hand.n_links):
        kinds = [s.kind for s in hand.link_shapes[link]]
        if kinds != ["capsule"] and not (link in hand.shapeless_links and not kinds):
            problems.append(
                f"{link_field(hand, link)}: the closure needs exactly one capsule per finger link "
                f"(link '{hand.link_names[link]}'), got {kinds}"
            )
    return problems


def check_hand(path: str | Path | None) -> tuple[Hand, list[str], list[str]]:
    """The hand of a ``hand:`` value (None: the shipped one), the problems that make it
    unusable by the study and the warnings on its dimensions, each line naming the file and
    the field. A malformed file raises ValueError naming the file and the field."""
    spec, where = hand_spec(path)
    hand = build_hand(spec, where)
    return (hand, [f"{where}: {p}" for p in closure_shape_problems(hand)], [f"{where}: {w}" for w in spec.warnings])
