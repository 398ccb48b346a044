"""Does the thumb oppose? A check of a hand with its synergy table, before any job
(docs/synergies.md, "The thumb-opposition check").

The study's closure follows the first synergy, q_r(σ) = clip(q_m + σ·S1), from the open hand
(σ_open) to the end of the path (σ_closed). A thumb that opposes meets the index or the middle
fingertip in front of the palm, with room for an object between them and the palm; a thumb
that cannot oppose lies folded onto the palm and the fingers curl onto it (a fist). The check
walks the path on a fine grid of σ with the hand's own collision capsules and palm boxes
(``synergrasp.simulation.capsules``) and asks

- **meets**: the first σ at which the thumb's distal capsule touches the index's or the
  middle's distal capsule (signed distance ≤ 0);
- **in front**: there, both fingertips (the thumb's and the one it meets) lie at least
  :data:`MIN_FRONT_MM` in front of the palm face (the outermost point of the palm's shapes
  along the palm normal) — room for the study's smallest box between the pinch and the palm;
- **palm free**: no thumb link that is not joined to the palm by design
  (``Hand.ignored_link_pairs``) touches the palm's boxes before that σ.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from synergrasp.hand.kinematics import Hand, fingertip_positions
from synergrasp.hand.synergies import Synergies, SynergyPath

__all__ = [
    "MIN_FRONT_MM",
    "ThumbOpposition",
    "thumb_opposition",
    "checked_opposition",
    "opposition_warnings",
    "opposition_line",
    "closing_sigmas",
    "cached_opposition_warnings",
]

#: How far in front of the palm face (mm, along the palm normal) the thumb must meet a finger.
MIN_FRONT_MM = 20.0
#: σ samples of the S1 path the check walks (σ_open … σ_closed).
_SAMPLES = 4001


@dataclass(frozen=True)
class ThumbOpposition:
    """The check's findings along S1 (σ in the table's units; mm in the palm frame).

    ``meet_sigma``: first σ at which the thumb's distal capsule touches the index's or the
    middle's (None: never on the path); ``partner``: that finger; ``front_mm``: the lower of
    the two fingertips' heights above the palm face there (nan if they never meet);
    ``palm_sigma``: first σ at which a thumb link touches the palm, if before the meeting (or
    on a path where they never meet), else None; ``palm_link``: that link's name.
    """

    hand: str
    meet_sigma: float | None
    partner: str
    front_mm: float
    palm_sigma: float | None
    palm_link: str

    @property
    def opposes(self) -> bool:
        return self.meet_sigma is not None and self.front_mm >= MIN_FRONT_MM and self.palm_sigma is None

    def warning(self) -> str | None:
        """One line naming the hand and the σ where the check fails (None: it passes)."""
        if self.opposes:
            return None
        why = []
        if self.palm_sigma is not None:
            why.append(f"the thumb's link '{self.palm_link}' touches the palm at sigma = {self.palm_sigma:.2f}")
        if self.meet_sigma is None:
            why.append("the thumb's tip never meets the index or middle fingertip")
        elif self.front_mm < MIN_FRONT_MM:
            why.append(
                f"the thumb meets the {self.partner} fingertip at sigma = {self.meet_sigma:.2f} only "
                f"{self.front_mm:.1f} mm in front of the palm face (at least {MIN_FRONT_MM:g} mm needed)"
            )
        return (
            f"thumb opposition: hand '{self.hand}': along S1 "
            + "; ".join(why)
            + ": the thumb cannot oppose the fingers (docs/synergies.md)"
        )

    def summary(self) -> str:
        """``WARNING: `` and the warning, or one line saying where the thumb meets a finger."""
        warning = self.warning()
        if warning:
            return f"WARNING: {warning}"
        return (
            f"thumb opposition: hand '{self.hand}': along S1 the thumb meets the {self.partner} fingertip at "
            f"sigma = {self.meet_sigma:.2f}, {self.front_mm:.1f} mm in front of the palm face, the palm untouched"
        )


def closing_sigmas(check: ThumbOpposition) -> list[float]:
    """The σ at which to draw the closing hand: −1, 0, +1 and where the check found the thumb
    touching the palm and meeting a finger, in order."""
    found = [s for s in (check.palm_sigma, check.meet_sigma) if s is not None]
    return sorted({-1.0, 0.0, 1.0, *(round(s, 2) for s in found)})


def thumb_opposition(hand: Hand, synergies: Synergies, samples: int = _SAMPLES) -> ThumbOpposition:
    """Walk the S1 path of ``synergies`` on ``hand`` (module docstring). ValueError if the
    thumb's, the index's or the middle finger's distal link has no capsule."""
    from synergrasp.simulation.capsules import HandCapsules, pair_gaps
    from synergrasp.simulation.placement import palm_centre

    normal = np.asarray(hand.palm_normal, dtype=float) / np.linalg.norm(hand.palm_normal)
    face = float(palm_centre(hand) @ normal)
    caps = HandCapsules.of(hand)
    row = {int(link): i for i, link in enumerate(caps.links)}
    thumb, index, middle = (int(hand.fingertip_link[f]) for f in (0, 1, 2))
    missing = [hand.link_names[link] for link in (thumb, index, middle) if link not in row]
    if missing:
        raise ValueError(f"{hand.source}: the thumb-opposition check needs a capsule on the links {missing}")
    ignored = {tuple(sorted(p)) for p in hand.ignored_link_pairs}
    thumb_links = [link for link in hand.finger_links[0] if link in row and (0, link) not in ignored]
    first = np.array([row[thumb], row[thumb]] + [row[link] for link in thumb_links], dtype=np.int64)
    second = np.array([row[index], row[middle]] + [-1] * len(thumb_links), dtype=np.int64)
    path = SynergyPath.along(synergies, hand.lower, hand.upper)
    sigma_open, sigma_closed = path.closure_range(hand.flexion_joints)
    palm_sigma, palm_link = None, ""
    for sigma in np.linspace(sigma_open, sigma_closed, samples):
        q = path.reference(float(sigma))
        p0, p1 = caps.segments(q)
        gaps = pair_gaps(p0, p1, caps.radius, first, second, caps.palm_rotation, caps.palm_centre, caps.palm_half)
        if palm_sigma is None and np.any(gaps[2:] <= 0.0):
            palm_sigma, palm_link = float(sigma), hand.link_names[thumb_links[int(np.argmax(gaps[2:] <= 0.0))]]
        if np.any(gaps[:2] <= 0.0):
            partner = 1 if gaps[0] <= 0.0 else 2
            tips = fingertip_positions(hand, q)
            front = float(min(tips[0] @ normal, tips[partner] @ normal)) - face
            return ThumbOpposition(hand.name, float(sigma), ("index", "middle")[partner - 1], front, palm_sigma, palm_link)
    return ThumbOpposition(hand.name, None, "", float("nan"), palm_sigma, palm_link)


def checked_opposition(hand: Hand, synergies: Synergies) -> tuple[ThumbOpposition | None, str | None]:
    """The check (None if it cannot run) and its warning (None if the thumb opposes). A table
    whose S1 does not close the hand (a negative flexion entry) or a hand without the distal
    capsules cannot be checked: the warning says why, in one line naming the hand."""
    try:
        check = thumb_opposition(hand, synergies)
    except ValueError as err:
        return None, f"thumb opposition: hand '{hand.name}': cannot be checked: {err}"
    return check, check.warning()


def opposition_warnings(hand: Hand, synergies: Synergies) -> list[str]:
    """The check's warning for a hand with a thumb, as a list (empty: it opposes)."""
    warning = checked_opposition(hand, synergies)[1]
    return [] if warning is None else [warning]


def opposition_line(hand: Hand, synergies: Synergies) -> tuple[str, list[float]]:
    """What a command prints of the check (``WARNING: `` and the warning, or where the thumb
    meets a finger) and the σ at which to draw the closing hand (:func:`closing_sigmas`)."""
    check, warning = checked_opposition(hand, synergies)
    if check is None:
        return f"WARNING: {warning}", [-1.0, 0.0, 1.0]
    return check.summary(), closing_sigmas(check)


@functools.cache
def cached_opposition_warnings(hand_value: str | Path | None, synergies_value: str | Path | None) -> tuple[str, ...]:
    """:func:`opposition_warnings` of a ``hand:`` and a ``synergies:`` value, computed once per pair."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies

    hand = load_hand(hand_value)
    return tuple(opposition_warnings(hand, load_synergies(synergies_value, joint_names=hand.joint_names)))
