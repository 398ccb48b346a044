"""The one front door from a ``hand:`` value to a checked :class:`HandSpec`: the project's YAML
hand file (``synergrasp.hand.hand_file``) or a hand description naming an MJCF model
(``synergrasp.hand.mjcf``), told apart by the key ``mjcf`` (docs/hand.md)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from synergrasp.hand.hand_file import HandSpec, check_hand_doc, default_hand_path, read_hand_file, size_warnings
from synergrasp.hand.mjcf import mjcf_hand_spec

__all__ = ["hand_spec", "SHIPPED_HANDS", "shipped_hand_path"]

#: Hands shipped besides the default, by name (a ``hand:`` value), and their folders under
#: data/hands/ (each with its hand description, hand.yaml).
_SHIPPED_FOLDERS: dict[str, str] = {"shadow_hand": "shadow", "inspire_hand": "inspire"}
SHIPPED_HANDS: tuple[str, ...] = tuple(_SHIPPED_FOLDERS)


def shipped_hand_path(name: str) -> Path:
    """The hand description of the shipped hand ``name`` (one of SHIPPED_HANDS)."""
    return default_hand_path().parent / "hands" / _SHIPPED_FOLDERS[name] / "hand.yaml"


def hand_spec(path: str | Path | None) -> tuple[HandSpec, str]:
    """The checked content of the hand file ``path`` (None: the shipped hand; a name of
    SHIPPED_HANDS: that hand's description; a file with the
    key ``mjcf``: a hand description read through MuJoCo, ``synergrasp.hand.mjcf``) and how
    messages name it (``hand file '<path>'`` or ``the shipped hand``), its ``warnings`` the
    size warnings of every format (``hand_file.size_warnings``); ValueError naming the file
    and the field."""
    if path is not None and str(path) in SHIPPED_HANDS:
        source, where = shipped_hand_path(str(path)), f"the shipped hand '{path}'"
    else:
        source = default_hand_path() if path is None else Path(path)
        where = "the shipped hand" if path is None else f"hand file '{source}'"
    doc = read_hand_file(source)
    if isinstance(doc, dict) and ("mjcf" in doc or "urdf" in doc):  # a hand described by an MJCF/URDF model
        spec = mjcf_hand_spec(doc, source, where)
        return replace(spec, warnings=size_warnings(spec, "m")), where
    try:
        spec = check_hand_doc(doc)
    except ValueError as exc:
        raise ValueError(str(exc).replace("hand file:", f"{where}:", 1)) from None
    return replace(spec, warnings=size_warnings(spec, "mm")), where
