"""What blocks a synergy set: for every (pose, set) that fails Definition 1 where the full
set succeeds, the contacts that stop the set's internal forces from entering every friction
cone (docs/blockers.md; the conic problem: `synergrasp.optimisation.blocking`).

Each blocker is labelled by its hand link (name, and kind for the opposition rule:
`simulation.opposition.HandAxes.link_kind`), the face of the box it pushes on
(`opposition.face_classes`) and where on the surface it sits (`opposition.surface_features`).
Only the sets of the study's hierarchy table are examined, {S1..Sk} and {Sk} for k = 1 ..
``synergy_sets.hierarchy_first``; each distinct grasp (`mechanics.first_same_grasp`) is
solved once and its rows shared by its twin poses.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp.analysis.verdicts import verdict_columns
from synergrasp.ids import ALL_OBJECTS, incremental_set_id, set_id
from synergrasp.optimisation.blocking import Blocking, blocking_contacts
from synergrasp.optimisation.mechanics import Grasp, first_same_grasp, internal_force_basis, read_grasps
from synergrasp.optimisation.optimise import GFOParams, mechanics_for
from synergrasp.optimisation.problem import GFOProblem
from synergrasp.simulation.opposition import (
    FACE_CLASSES,
    LINK_KINDS,
    SURFACE_FEATURES,
    HandAxes,
    OppositionRule,
    face_classes,
    surface_features,
)
from synergrasp.table_contracts import BLOCKERS, read

__all__ = [
    "BlockersParams",
    "ContactLabels",
    "SetBlockers",
    "blocker_sets",
    "contact_labels",
    "set_blockers",
    "blockers_table",
    "blockers_summary",
    "SUMMARY_GROUPS",
    "blockers_summary_by_object",
]


def blocker_sets(sets_config: Mapping[str, int]) -> dict[str, tuple[int, ...]]:
    """The sets examined, by id: {S1..Sk} for k = 1 .. hierarchy_first (at most
    incremental_max: the study solves no larger incremental set), then the singles
    {S2} .. {S_hierarchy_first} ({S1} is the first of both)."""
    first = int(sets_config["hierarchy_first"])
    out = {incremental_set_id(k): tuple(range(1, k + 1)) for k in range(1, min(first, int(sets_config["incremental_max"])) + 1)}
    out.update({set_id([k]): (k,) for k in range(2, first + 1)})
    return out


@dataclass(frozen=True)
class BlockersParams:
    """The ``blockers`` step of one object: hand and synergy files (None: shipped), the
    mechanics and weight (`GFOParams`), the sets examined (`blocker_sets`), the full set's
    id, the opposition rule (its ``reach_mm`` decides edges and corners) and the object's
    shape."""

    hand: str | None
    synergies: str | None
    gfo: GFOParams
    sets: dict[str, tuple[int, ...]]
    full_set_id: str
    rule: OppositionRule
    shape: Any

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> BlockersParams:
        from synergrasp.simulation.objects import GraspedObject

        return cls(
            config["hand"],
            config["synergies"],
            GFOParams.from_config(config, obj),
            blocker_sets(config["synergy_sets"]),
            incremental_set_id(config["synergy_sets"]["incremental_max"]),
            OppositionRule.from_config(config),
            GraspedObject.from_config(config, obj, with_mass=False).shape,
        )


@dataclass(frozen=True)
class ContactLabels:
    """Per contact of one grasp: hand link, its name and kind, the face class and surface feature."""

    links: NDArray
    names: tuple[str, ...]
    kinds: tuple[str, ...]
    faces: tuple[str, ...]
    features: tuple[str, ...]


def contact_labels(
    grasp: Grasp, rotation: NDArray, shape: Any, link_names: Sequence[str], axes: HandAxes, rule: OppositionRule
) -> ContactLabels:
    """The labels of a grasp's contacts (rotation: the box's 3 x 3 orientation, palm frame)."""
    links = grasp.links
    return ContactLabels(
        links,
        tuple(link_names[int(k)] for k in links),
        tuple(axes.link_kind[int(k)] for k in links),
        tuple(face_classes(grasp.normals, axes)),
        tuple(surface_features(grasp.points, shape, rotation, grasp.center, rule)),
    )


@dataclass(frozen=True)
class SetBlockers:
    """One (grasp, set): e_s, rank(G), the reason it fails (`blocking.REASONS`), t* (N per N of
    total normal force) and the solution (`blocking.Blocking`: per-contact margins, normal
    forces, angles outside the cone and which contacts block)."""

    e_s: int
    rank_G: int
    blocking: Blocking

    @property
    def reason(self) -> str:
        return self.blocking.reason


def set_blockers(grasp: Grasp, synergy_matrix: NDArray, sets: Sequence[Sequence[int]], params: GFOParams) -> list[SetBlockers]:
    """The blockers of each set (1-based synergies) at one grasp, with E_s as the study's
    solver derives it (`internal_force_basis` with the same tolerance)."""
    mech = mechanics_for(grasp, params)
    m = grasp.n_contacts
    if mech.rank_G < 6 or mech.projector is None:
        return [SetBlockers(0, mech.rank_G, Blocking.without_contacts("rank_deficient", m)) for _ in sets]
    out = []
    for members in sets:
        S = np.asarray(synergy_matrix, dtype=float)[:, [k - 1 for k in sorted(members)]]
        E = internal_force_basis(mech.projector, S, mech.response_norm, params.basis_rtol)
        problem = GFOProblem(mech.f_p, E, mech.normals, params.f_min_N, params.cone)
        out.append(SetBlockers(int(E.shape[1]), mech.rank_G, blocking_contacts(problem)))
    return out


def _failing(gfo: pd.DataFrame, sets: Mapping[str, Any], full_set_id: str) -> pd.DataFrame:
    """Rows of the examined sets that fail Definition 1 where the full set succeeds."""
    ok = verdict_columns(gfo)["force_closure"]
    full = set(gfo.loc[(gfo["set_id"] == full_set_id) & ok, "pose"].tolist())
    pick = gfo["set_id"].isin(list(sets)) & ~ok & gfo["pose"].isin(full)
    return gfo[pick]


def blockers_table(
    contacts: pd.DataFrame,
    gfo: pd.DataFrame,
    link_names: Sequence[str],
    axes: HandAxes,
    synergy_matrix: NDArray,
    params: BlockersParams,
) -> pd.DataFrame:
    """One row per (pose, set) of the examined sets that fails where the full set succeeds
    (columns of `table_contracts.BLOCKERS`), in the gfo table's order."""
    failing = _failing(gfo, params.sets, params.full_set_id)
    grasps = read_grasps(contacts)
    first = first_same_grasp(grasps)
    row_of = {int(p): i for i, p in enumerate(contacts["pose"].tolist())}
    solved: dict[int, dict[str, SetBlockers]] = {}
    labels: dict[int, ContactLabels] = {}
    rows = []
    for rec in failing.itertuples(index=False):
        i = first[row_of[int(rec.pose)]]
        if i not in solved:
            wanted = sorted(set(failing.loc[failing["pose"].isin(contacts["pose"].iloc[np.flatnonzero(first == i)]), "set_id"]))
            solved[i] = dict(zip(wanted, set_blockers(grasps[i], synergy_matrix, [params.sets[s] for s in wanted], params.gfo)))
            rotation = np.asarray(contacts["object_rotation"].iloc[i], dtype=float).reshape(3, 3)
            labels[i] = contact_labels(grasps[i], rotation, params.shape, link_names, axes, params.rule)
        rows.append(_row(rec, solved[i][rec.set_id], labels[i]))
    from synergrasp.table_contracts import BLOCKERS, empty

    return pd.DataFrame(rows, columns=list(BLOCKERS.names)) if rows else empty(BLOCKERS)


def _row(rec: Any, found: SetBlockers, labels: ContactLabels) -> dict[str, Any]:
    b = found.blocking
    at = np.flatnonzero(b.blockers)
    outside = np.flatnonzero(b.contact_margin <= 0.0) if b.reason == "contacts" else np.zeros(0, dtype=int)
    return {
        "object": rec.object,
        "pose": int(rec.pose),
        "alpha_deg": rec.alpha_deg,
        "beta_deg": rec.beta_deg,
        "set_id": rec.set_id,
        "n_synergies": int(rec.n_synergies),
        "e_s": found.e_s,
        "rank_G": found.rank_G,
        "n_contacts": len(labels.links),
        "reason": b.reason,
        "margin": b.margin,
        "n_blockers": len(at),
        "blocker_contact": at.tolist(),
        "blocker_link": [int(labels.links[k]) for k in at],
        "blocker_link_name": [labels.names[k] for k in at],
        "blocker_link_kind": [labels.kinds[k] for k in at],
        "blocker_face": [labels.faces[k] for k in at],
        "blocker_feature": [labels.features[k] for k in at],
        "blocker_margin": b.contact_margin[at].tolist(),
        "blocker_normal_force": b.normal_force[at].tolist(),
        "blocker_angle_outside_deg": b.angle_outside_deg[at].tolist(),
        "n_outside": len(outside),
        "outside_link_kind": [labels.kinds[k] for k in outside],
    }


#: The summary's columns: per label group, the table's list column and the labels counted.
SUMMARY_GROUPS: dict[str, tuple[str, tuple[str, ...]]] = {
    "kind": ("blocker_link_kind", LINK_KINDS),
    "face": ("blocker_face", FACE_CLASSES),
    "feature": ("blocker_feature", SURFACE_FEATURES),
}


def blockers_summary(blockers: pd.DataFrame, sets: Mapping[str, Any]) -> pd.DataFrame:
    """The study table: per object (and ``all`` objects pooled) and examined set, the poses
    that fail where the full set succeeds (``n_failing``), the share (%) whose reason is
    e_s = 0, and the share with a blocker of each link kind, face class and surface feature
    (a pose with several blockers counts in several columns)."""
    objects = sorted(blockers["object"].unique()) if len(blockers) else []
    return _summary(((obj, blockers[blockers["object"] == obj]) for obj in objects), sets)


def blockers_summary_by_object(paths: Sequence[str | Path], sets: Mapping[str, Any]) -> pd.DataFrame:
    """:func:`blockers_summary` of every object's blockers file (``table_contracts.BLOCKERS``), one
    object at a time in sorted order (``results/objects/<object>/``): each object's rows are
    reduced to its counts and margins and dropped before the next is read."""

    def objects():
        for path in sorted(paths, key=lambda p: Path(p).parent.name):
            blockers = read(BLOCKERS, path)
            for obj in sorted(blockers["object"].unique()):
                yield obj, blockers[blockers["object"] == obj]

    return _summary(objects(), sets)


def _tally(here: pd.DataFrame) -> dict[str, Any]:
    """What a row of the summary needs of one (object, set)'s blockers: their number, those of
    reason e_s = 0, their margins and how many hold each label of ``SUMMARY_GROUPS``."""
    held = {column: [set(v) for v in here[column]] for column, _ in SUMMARY_GROUPS.values()}
    return {
        "n": len(here),
        "none": int((here["reason"] == "no_internal_force").sum()),
        "margins": here["margin"].to_numpy(float),
        **{
            f"{group}_{label}": sum(label in h for h in held[column])
            for group, (column, labels) in SUMMARY_GROUPS.items()
            for label in labels
        },
    }


def _summary_row(obj: str, sid: str, size: int, tally: Mapping[str, Any]) -> dict[str, Any]:
    n = tally["n"]
    row: dict[str, Any] = {
        "object": obj,
        "set_id": sid,
        "n_synergies": size,
        "n_failing": n,
        "pct_no_internal_force": _pct(tally["none"], n),
        "median_margin": float(pd.Series(tally["margins"]).median()) if n else np.nan,
    }
    for group, (_, labels) in SUMMARY_GROUPS.items():
        for label in labels:
            row[f"pct_{group}_{label}"] = _pct(tally[f"{group}_{label}"], n)
    return row


def _summary(objects: Iterable[tuple[str, pd.DataFrame]], sets: Mapping[str, Any]) -> pd.DataFrame:
    """The summary's rows from (object, its blockers) in order, then the ``all`` rows from
    their tallies pooled (counts summed, margins joined)."""
    rows: list[dict[str, Any]] = []
    pooled: dict[str, list[dict[str, Any]]] = {sid: [] for sid in sets}
    for obj, part in objects:
        for sid in sets:
            tally = _tally(part[part["set_id"] == sid])
            rows.append(_summary_row(obj, sid, len(sets[sid]), tally))
            pooled[sid].append(tally)
    for sid, tallies in pooled.items():
        counts = ["n", "none", *(f"{g}_{label}" for g, (_, labels) in SUMMARY_GROUPS.items() for label in labels)]
        total: dict[str, Any] = {k: sum(t[k] for t in tallies) for k in counts}
        total["margins"] = np.concatenate([t["margins"] for t in tallies]) if tallies else np.zeros(0)
        rows.append(_summary_row(ALL_OBJECTS, sid, len(sets[sid]), total))
    return pd.DataFrame(rows)


def _pct(count: int, n: int) -> float:
    return 100.0 * float(count) / n if n else float("nan")
