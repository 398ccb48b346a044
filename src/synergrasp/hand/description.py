"""The one front door from a ``hand:`` value to a checked :class:`HandSpec`: the project's YAML
hand file (``synergrasp.hand.hand_file``) or a hand description naming an MJCF model
(``synergrasp.hand.mjcf``), told apart by the key ``mjcf`` (docs/hand.md)."""

from __future__ import annotations

from pathlib import Path

from synergrasp.hand.hand_file import HandSpec, check_hand_doc, default_hand_path, read_hand_file
from synergrasp.hand.mjcf import mjcf_hand_spec

__all__ = ["hand_spec"]


def hand_spec(path: str | Path | None) -> tuple[HandSpec, str]:
    """The checked content of the hand file ``path`` (None: the shipped hand; a file with the
    key ``mjcf``: a hand description read through MuJoCo, ``synergrasp.hand.mjcf``) and how
    messages name it (``hand file '<path>'`` or ``the shipped hand``); ValueError naming
    the file and the field."""
    source = default_hand_path() if path is None else Path(path)
    where = "the shipped hand" if path is None else f"hand file '{source}'"
    doc = read_hand_file(source)
    if isinstance(doc, dict) and "mjcf" in doc:  # a hand described by an MJCF model (docs/hand.md)
        return mjcf_hand_spec(doc, source, where), where
    try:
        return check_hand_doc(doc), where
    except ValueError as exc:
        raise ValueError(str(exc).replace("hand file:", f"{where}:", 1)) from None
