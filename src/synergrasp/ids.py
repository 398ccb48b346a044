"""Ids of synergy sets, and the sets of the study (the lowest layer: imports nothing of the package).

An id names a set of synergies by their 1-based indices, sorted and joined by '-' ("1-2-3").
The study's tables name a row pooled over every object :data:`ALL_OBJECTS`.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

__all__ = ["ALL_OBJECTS", "set_id", "set_members", "set_order", "set_name", "incremental_set_id", "synergy_sets"]

#: The ``object`` of a table's row pooled over every object.
ALL_OBJECTS = "all"


def set_id(synergies: Sequence[int]) -> str:
    """Canonical id of a synergy set: 1-based indices, sorted, joined by '-' ("1-2-3")."""
    return "-".join(str(i) for i in sorted(set(synergies)))


def set_members(set_id: str) -> tuple[int, ...]:
    """The synergies (1-based) of a set's id: "1-2-3" -> (1, 2, 3)."""
    return tuple(int(i) for i in str(set_id).split("-"))


def set_order(set_id: str) -> tuple[int, tuple[int, ...]]:
    """Sort key of set ids: by size, then by members ("2" < "1-3" < "1-2-3")."""
    members = set_members(set_id)
    return len(members), members


def set_name(synergies: Sequence[int]) -> str:
    """A set in words: {S1..S7} for a run of three or more consecutive synergies, {S2,S5} otherwise."""
    s = sorted(set(synergies))
    if len(s) > 2 and s == list(range(s[0], s[-1] + 1)):
        return f"{{S{s[0]}..S{s[-1]}}}"
    return "{" + ",".join(f"S{k}" for k in s) + "}"


def incremental_set_id(k: int) -> str:
    """Id of the incremental set {S1..Sk}."""
    return set_id(range(1, k + 1))


def synergy_sets(sets_config: Mapping[str, int]) -> dict[str, tuple[int, ...]]:
    """All distinct synergy sets of the study, by id, in a fixed order.

    ``sets_config`` is the configuration's ``synergy_sets`` block. The incremental sets
    {S1..Sk}, k = 1..incremental_max, then every subset of S1..S_hierarchy_first with
    1..hierarchy_max_size elements; sets that coincide (e.g. {S1, S2}) appear once.
    """
    out: dict[str, tuple[int, ...]] = {}
    for k in range(1, sets_config["incremental_max"] + 1):
        out[incremental_set_id(k)] = tuple(range(1, k + 1))
    first = sets_config["hierarchy_first"]
    for size in range(1, sets_config["hierarchy_max_size"] + 1):
        for combo in itertools.combinations(range(1, first + 1), size):
            out.setdefault(set_id(combo), combo)
    return out
