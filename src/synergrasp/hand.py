"""The 19-joint anthropomorphic hand: joint and finger names (the contract of docs/design.md)."""

from __future__ import annotations

FINGERS: tuple[str, ...] = ("thumb", "index", "middle", "ring", "little")

JOINT_NAMES: tuple[str, ...] = (
    "thumb_abd", "thumb_flex1", "thumb_flex2",
    "index_abd", "index_mcp", "index_pip", "index_dip",
    "middle_abd", "middle_mcp", "middle_pip", "middle_dip",
    "ring_abd", "ring_mcp", "ring_pip", "ring_dip",
    "little_abd", "little_mcp", "little_pip", "little_dip",
)
