"""How much the simulated grasps look like grasps a hand makes: the grasp-realism table.

Per object and closure model (the contacts table's ``closure_model``):
poses simulated and dropped, the distribution of contacts per grasp, the share of grasps
that touch with the thumb, the palm, a proximal or middle phalanx, the share whose grasp
matrix has full rank 6, and the median optimal force with every synergy enrolled as a
multiple of the object's weight (‖f‖₂ / (m·g), dimensionless); where the closure model
records per-contact normal forces (the dynamic one), how many contacts per grasp carry load.
Columns: :data:`synergrasp.table_contracts.GRASP_REALISM`. Pure functions: DataFrames
in, a DataFrame out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from synergrasp.analysis.graspability import graspable_objects
from synergrasp.analysis.verdicts import verdict_columns
from synergrasp.hand.kinematics import Hand
from synergrasp.hand.synergies import Synergies, synergy_values
from synergrasp.ids import incremental_set_id
from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium
from synergrasp.optimisation.grasp_type_search import type_family
from synergrasp.resolved import friction_mu, grasp_type, weight_N
from synergrasp.simulation.opposition import (
    OPPOSITIONS,
    HandAxes,
    OppositionRule,
    contacts_oppositions,
    edge_contacts,
    of_grasp_type,
)
from synergrasp.table_contracts import CONTACTS, GFO, GRASP_REALISM, read

__all__ = [
    "RealismParams",
    "SIMULATED_STATUSES",
    "CONTACT_BINS",
    "NORMAL_FORCE_COLUMN",
    "LONG_FINGERS",
    "link_categories",
    "grasp_labels",
    "grasp_realism",
    "realism_of",
    "link_shares",
    "representative_grasps",
    "realism_by_object",
]

#: Statuses of the poses whose closure ran (synergrasp.simulation.contacts.CLOSURE_STATUSES): a
#: ``no_contact`` closure is a simulated grasp with 0 contacts; any other status is a dropped pose.
SIMULATED_STATUSES: tuple[str, ...] = ("grasp", "no_contact")
#: Contact-count bins of the table: 0, 1, …, 5 and "6 or more".
CONTACT_BINS: tuple[int, ...] = (0, 1, 2, 3, 4, 5, 6)
#: Contacts column: normal force per contact, N (NaN entries where the model computes none).
NORMAL_FORCE_COLUMN = "contact_normal_force_N"
#: The long fingers, each a column of the table (grasps touching the box with that finger).
LONG_FINGERS: tuple[str, ...] = ("index", "middle", "ring", "little")
#: Segments (the part of a link name after the finger) counted as proximal or middle phalanges.
_PROXIMAL_OR_MIDDLE = ("proximal", "middle")


@dataclass(frozen=True)
class RealismParams:
    """The grasp-realism table (the ``realism`` step): hand file, the full set's id, each
    object's weight (N), the least normal force (N) of a load-carrying contact (None: the
    closure model records no loads), and for the equilibrium checks the mean posture q_m and
    S1 of the synergy table (rad, the hand's joint order), the joint stiffness k_ss (N·mm/rad)
    and μ."""

    hand: str | None
    full_set_id: str
    weights_N: dict[str, float]
    load_threshold_N: float | None
    mean_rad: tuple[float, ...]
    s1: tuple[float, ...]
    k_ss_Nmm_per_rad: float
    mu: float
    grasp_types: dict[str, str]
    shapes: dict[str, Any]
    opposition: OppositionRule
    random_objects: dict | None = None  # the drawn meshes' block: those left out join the graspable table

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str | None = None) -> RealismParams:
        """From a configuration, or from the step's own part of it (whose ``synergies`` holds
        q_m and S1 themselves; ``obj`` is not read)."""
        mechanics = config["mechanics"]
        closure = config["closure"]
        threshold = closure["dynamic"]["load_threshold_N"] if closure["model"] == "dynamic" else None
        from synergrasp.simulation.shapes import shape_from_config

        values = config["synergies"]
        if not isinstance(values, Mapping):
            values = synergy_values(config["hand"], values, (1,))
        objects = config["objects"]
        return cls(
            config["hand"],
            incremental_set_id(config["synergy_sets"]["incremental_max"]),
            {name: weight_N(config, name) for name in objects},
            threshold,
            tuple(values["mean_rad"]),
            tuple(values["S1"]),
            float(mechanics["k_ss_Nmm_per_rad"]),
            friction_mu(config),
            {name: grasp_type(config, name) for name in objects},
            {name: shape_from_config(spec["shape"], f"objects.{name}.shape") for name, spec in objects.items()},
            OppositionRule.from_config(config),
            config.get("random_objects"),
        )

    def synergies(self, joint_names: tuple[str, ...]) -> Synergies:
        """q_m and S1 as a one-synergy :class:`Synergies` of the hand's joints."""
        return Synergies(tuple(joint_names), np.array(self.mean_rad), np.array(self.s1)[:, None], ("S1",))


def link_categories(link_names: Sequence[str], link_finger: Sequence[str]) -> dict[str, frozenset[int]]:
    """Hand link indices per category: ``thumb`` (every thumb link), ``palm`` (links of the
    palm), ``proximal_or_middle`` (links named ``<finger>_proximal`` or ``<finger>_middle``),
    and every long finger's links (``index``, ``middle``, ``ring``, ``little``)."""

    def finger(name: str) -> frozenset[int]:
        return frozenset(i for i, f in enumerate(link_finger) if f == name)

    phalanx = frozenset(
        i
        for i, (name, f) in enumerate(zip(link_names, link_finger))
        if f != "palm" and name.rsplit("_", 1)[-1] in _PROXIMAL_OR_MIDDLE
    )
    return {
        "thumb": finger("thumb"),
        "palm": finger("palm"),
        "proximal_or_middle": phalanx,
        **{name: finger(name) for name in LONG_FINGERS},
    }


def grasp_labels(contacts: pd.DataFrame, axes: HandAxes, rule: OppositionRule, shapes: Mapping[str, Any]) -> pd.DataFrame:
    """Per row of the contacts tables: object, closure_model, pose, the grasp's opposition
    and how many of its contacts sit on an edge or a corner of the object (docs/opposition.md)."""
    parts = []
    for obj, rows in contacts.groupby("object", sort=True):
        parts.append(
            pd.DataFrame(
                {
                    "object": obj,
                    "closure_model": rows["closure_model"].to_numpy(),
                    "pose": rows["pose"].astype(int).to_numpy(),
                    "opposition": contacts_oppositions(rows, axes, rule),
                    "edge_contacts": edge_contacts(rows, shapes[obj], rule),
                }
            )
        )
    columns = ["object", "closure_model", "pose", "opposition", "edge_contacts"]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=columns)


def _touches(links: pd.Series, category: frozenset[int]) -> pd.Series:
    return links.map(lambda ls: bool(len(ls)) and any(int(i) in category for i in ls))


def _loaded(contacts: pd.DataFrame, threshold_N: float | None) -> pd.Series:
    """Contacts per row whose normal force is at least ``threshold_N``; NaN where the forces
    are unknown (NaN entries, as the kinematic model writes them, or no threshold)."""

    def count(forces) -> float:
        if threshold_N is None or forces is None or (np.isscalar(forces) and pd.isna(forces)):
            return np.nan
        values = np.asarray(forces, dtype=float)
        return np.nan if np.isnan(values).any() else float(np.count_nonzero(values >= threshold_N))

    return contacts[NORMAL_FORCE_COLUMN].map(count)


def _weight_multiples(gfo: pd.DataFrame, full_set_id: str, weights_N: Mapping[str, float]) -> pd.DataFrame:
    """Per (object, pose[, closure_model]) of the full set: rank_G, force_closure (the study's
    definition: rank(G) = 6 and the strict internal-force test, see analysis.verdicts),
    load_feasible, and the optimal ‖f‖₂ under the weight / (m·g) where in force closure."""
    full = gfo[gfo["set_id"].astype(str) == full_set_id]
    missing = sorted(set(full["object"].unique()) - set(weights_N))
    if missing:
        raise ValueError(f"weights_N: no weight for object(s) {missing}; given: {sorted(weights_N)}")
    weight = full["object"].map(weights_N).astype(float)
    verdicts = verdict_columns(full)
    fc = verdicts["force_closure"]
    out = pd.DataFrame(
        {
            "object": full["object"],
            "pose": full["pose"].astype(int),
            "rank_G": full["rank_G"],
            "force_closure": fc,
            "load_feasible": verdicts["load_feasible"],
            "force_per_weight": (full["force_norm"] / weight).where(fc),
        }
    )
    if "closure_model" in full.columns:  # results of several closure models side by side
        out["closure_model"] = full["closure_model"]
    return out.reset_index(drop=True)


def _one_group(rows: pd.DataFrame, categories: dict[str, frozenset[int]], grasp_type: str) -> dict[str, float]:
    simulated = rows["status"].isin(SIMULATED_STATUSES)
    grasps = rows[simulated]
    n = len(grasps)
    m = grasps["n_contacts"].astype(int).clip(upper=CONTACT_BINS[-1])

    def share(mask: pd.Series) -> float:  # % of the simulated grasps
        return 100.0 * float(mask.sum()) / n if n else np.nan

    dropped = rows.loc[~simulated, "status"].value_counts().sort_index()
    out: dict[str, float] = {
        "poses": len(rows),
        "simulated": n,
        "dropped": int((~simulated).sum()),
        "dropped_by": ", ".join(f"{s}: {c}" for s, c in dropped.items()),
        "contacts_median": float(grasps["n_contacts"].median()) if n else np.nan,
    }
    for b in CONTACT_BINS:
        out[_bin_column(b)] = share(m == b)
    for name, links in categories.items():
        out[f"pct_{name}"] = share(_touches(grasps["contact_link"], links))
    out["grasp_type"] = grasp_type
    for opposition in OPPOSITIONS:
        out[f"pct_{'no' if opposition == 'none' else opposition}_opposition"] = share(grasps["opposition"] == opposition)
    typed = grasps["opposition"].map(lambda o: of_grasp_type(o, grasp_type))
    out["pct_of_grasp_type"] = share(typed)
    out["pct_of_grasp_type_force_closure"] = share(typed & grasps["force_closure"].fillna(False).astype(bool))
    total = int(grasps["n_contacts"].sum())
    out["pct_contacts_on_edges"] = 100.0 * float(grasps["edge_contacts"].sum()) / total if total else np.nan
    out["pct_rank6"] = share(grasps["rank_G"] == 6)
    out["pct_force_closure"] = share(grasps["force_closure"].fillna(False).astype(bool))
    out["pct_load_feasible"] = share(grasps["load_feasible"].fillna(False).astype(bool))
    out["median_force_per_weight"] = float(grasps["force_per_weight"].median()) if n else np.nan
    out["median_torque_residual"] = float(grasps["torque_residual"].median()) if n else np.nan
    out["pct_s1_outside_cone"] = share(grasps["s1_outside_cone"].fillna(0) > 0)
    loaded = grasps["loaded_contacts"]
    known = loaded[grasps["n_contacts"] > 0].notna().any()  # forces recorded where there are contacts
    out["loaded_contacts_median"] = float(loaded.median()) if known else np.nan
    return out


def _bin_column(b: int) -> str:
    return f"pct_m{b}plus" if b == CONTACT_BINS[-1] else f"pct_m{b}"


def grasp_realism(
    contacts: pd.DataFrame,
    gfo: pd.DataFrame,
    equilibrium: pd.DataFrame,
    link_names: Sequence[str],
    link_finger: Sequence[str],
    full_set_id: str,
    weights_N: Mapping[str, float],
    load_threshold_N: float | None,
    labels: pd.DataFrame,
    grasp_types: Mapping[str, str],
) -> pd.DataFrame:
    """The grasp-realism table (columns of :data:`synergrasp.table_contracts.GRASP_REALISM`).

    ``contacts``: contacts tables of the objects (CONTACTS contract; rows are grouped by
    ``closure_model``, loads read from ``contact_normal_force_N``, N).
    ``gfo``: their optimisation results (joined on ``closure_model`` too when it has that
    column); rank(G), force closure and ‖f‖₂ are taken from the full set ``full_set_id`` (e.g.
    ``"1-2-…-15"``). ``weights_N``: m·g per object, N.
    ``equilibrium``: the per-grasp equilibrium checks of the same contacts
    (``synergrasp.optimisation.equilibrium.grasp_equilibrium``: object, closure_model, pose,
    torque_residual, s1_outside_cone, …); grasps missing from it count as unknown residual and
    no contact pushed outside its cone.
    ``labels``: each grasp's opposition and edge contacts (:func:`grasp_labels`);
    ``grasp_types``: each object's grasp type (docs/opposition.md).
    ``link_names`` / ``link_finger``: the hand's links (``Hand.link_names``, ``Hand.link_finger``).
    Shares are percent of the simulated poses (``SIMULATED_STATUSES``); a contact carries load if
    its normal force is at least ``load_threshold_N`` (N; the configuration's
    ``closure.dynamic.load_threshold_N``, None where no model records loads). One row per
    (object, closure model).
    """
    for table, frame in ((CONTACTS, contacts), (GFO, gfo)):
        absent = [c for c in table.names if c not in frame.columns]
        if absent:
            raise ValueError(f"{table.name} table: missing column(s) {absent}")
    if full_set_id not in set(gfo["set_id"].astype(str).unique()):
        raise ValueError(f"full_set_id {full_set_id!r} is not in the gfo table")
    work = contacts[["object", "closure_model", "pose", "status", "n_contacts", "contact_link"]].assign(
        pose=contacts["pose"].astype(int), loaded_contacts=_loaded(contacts, load_threshold_N)
    )
    full = _weight_multiples(gfo, full_set_id, weights_N)
    keys = ["object", "pose", "closure_model"] if "closure_model" in full.columns else ["object", "pose"]
    work = work.merge(full, on=keys, how="left", validate="many_to_one")
    checks = equilibrium[["object", "closure_model", "pose", "torque_residual", "s1_outside_cone"]]
    work = work.merge(checks.astype({"pose": int}), on=["object", "closure_model", "pose"], how="left", validate="one_to_one")
    work = work.merge(labels.astype({"pose": int}), on=["object", "closure_model", "pose"], how="left", validate="one_to_one")
    categories = link_categories(link_names, link_finger)
    rows = [
        {"object": obj, "closure_model": cm, **_one_group(group, categories, grasp_types[obj])}
        for (obj, cm), group in work.groupby(["object", "closure_model"], sort=True)
    ]
    return pd.DataFrame(rows, columns=list(GRASP_REALISM.names))


def realism_of(
    contacts: pd.DataFrame,
    gfo: pd.DataFrame,
    checks: pd.DataFrame,
    hand: Hand,
    params: RealismParams,
    grasp_types: Mapping[str, str],
    axes: HandAxes | None = None,
) -> pd.DataFrame:
    """:func:`grasp_realism` of ``contacts`` with the configuration's choices (``params``) and
    ``hand``'s links: each grasp labelled (:func:`grasp_labels`, ``axes`` the hand's, built
    when not given), then tabled. ``checks``: the equilibrium checks of the same contacts."""
    labels = grasp_labels(contacts, HandAxes.from_hand(hand) if axes is None else axes, params.opposition, params.shapes)
    return grasp_realism(
        contacts,
        gfo,
        checks,
        hand.link_names,
        hand.link_finger,
        params.full_set_id,
        params.weights_N,
        params.load_threshold_N,
        labels,
        grasp_types,
    )


def link_shares(contacts: pd.DataFrame, link_names: Sequence[str], link_finger: Sequence[str]) -> pd.DataFrame:
    """Which links touch the box: per (object, closure model) and hand link, the share of the
    simulated grasps (``SIMULATED_STATUSES``) with a contact on that link (``pct_grasps``, %).
    Columns: object, closure_model, finger, link, pct_grasps; links in the hand's order."""
    rows = []
    for (obj, model), group in contacts.groupby(["object", "closure_model"], sort=True):
        grasps = group[group["status"].isin(SIMULATED_STATUSES)]
        touched = grasps["contact_link"].map(lambda ls: {int(i) for i in ls})
        for index, (name, finger) in enumerate(zip(link_names, link_finger)):
            hits = int(touched.map(lambda s, i=index: i in s).sum())
            rows.append(
                {
                    "object": obj,
                    "closure_model": model,
                    "finger": finger,
                    "link": name,
                    "pct_grasps": 100.0 * hits / len(grasps) if len(grasps) else np.nan,
                }
            )
    return pd.DataFrame(rows, columns=["object", "closure_model", "finger", "link", "pct_grasps"])


def _pattern(links) -> tuple[int, ...]:
    return tuple(sorted({int(i) for i in links}))


def representative_grasps(contacts: pd.DataFrame, n: int = 3) -> pd.DataFrame:
    """Up to ``n`` grasps of one object that show what its grasps are like, chosen by rule.

    A grasp's contact pattern is the set of hand links touching the box. The choices, in
    order: (1) the most common pattern; (2) the most common pattern among the grasps with
    the typical number of contacts (the count nearest the median, the larger on a tie) not
    shown yet; (3…) the next most common patterns not shown yet. Each pattern is drawn at
    its pose nearest (α, β) = (0°, 0°) (α wrapped; then the lower pose index). Only
    simulated grasps (status ``grasp``) with at least one contact count.

    Returns one row per choice: ``pose``, ``alpha_deg``, ``beta_deg``, ``pattern`` (tuple of
    link indices), ``share_pct`` (percent of the simulated grasps with that pattern) and
    ``reason`` ("most common contacts", "typical count (m = 4)", "next most common").
    """
    grasps = contacts[(contacts["status"] == "grasp") & (contacts["n_contacts"] > 0)]
    if grasps.empty or n < 1:
        return pd.DataFrame(columns=["pose", "alpha_deg", "beta_deg", "pattern", "share_pct", "reason"])
    patterns = grasps["contact_link"].map(_pattern)
    share = patterns.value_counts(sort=False)
    order = sorted(share.index, key=lambda p: (-share[p], len(p), p))  # most common first, then fewer links
    counts = grasps["n_contacts"].astype(int)
    median = float(counts.median())
    typical = min(sorted(counts.unique()), key=lambda c: (abs(c - median), -c))
    chosen: list[tuple[tuple[int, ...], str]] = [(order[0], "most common contacts")]
    among = [p for p in order if p != order[0] and (counts[patterns == p] == typical).any()]
    if among:
        chosen.append((among[0], f"typical count (m = {typical})"))
    chosen += [(p, "next most common") for p in order if p not in {c for c, _ in chosen}]
    wrapped = (grasps["alpha_deg"].to_numpy() + 180.0) % 360.0 - 180.0
    distance = np.hypot(wrapped, grasps["beta_deg"].to_numpy())
    rows = []
    for pattern, reason in chosen[:n]:
        mine = np.flatnonzero((patterns == pattern).to_numpy())
        best = mine[np.lexsort((grasps["pose"].to_numpy()[mine], distance[mine]))[0]]
        row = grasps.iloc[best]
        rows.append(
            {
                "pose": int(row["pose"]),
                "alpha_deg": float(row["alpha_deg"]),
                "beta_deg": float(row["beta_deg"]),
                "pattern": pattern,
                "share_pct": 100.0 * share[pattern] / len(grasps),
                "reason": reason,
            }
        )
    return pd.DataFrame(rows)


def realism_by_object(
    files: Sequence[tuple[str | Path, str | Path]],
    hand: Hand,
    params: RealismParams,
    types: Mapping[str, tuple[str, str, str]],
) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """The grasp-realism table, the link shares and the graspable-objects table (before the
    objects left out join it) of every object, one object at a time: ``files`` the (contacts,
    gfo) files of each object (``results/objects/<object>/``), read in the objects' sorted
    order and each dropped before the next is read, so that a job holds one object's rows
    whatever the number of objects; every table is one of groups by object, so the rows are
    those of every object's rows at once. ``types``: each object's (stated, effective, reason)
    grasp type (``graspability.grasp_types_of``)."""
    synergies = params.synergies(hand.joint_names)
    equilibrium = EquilibriumParams.of(hand, synergies, params.k_ss_Nmm_per_rad, params.mu)
    axes = HandAxes.from_hand(hand)
    families = {name: type_family(effective) for name, (_, effective, _) in types.items()}
    parts: list[tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]] = []
    for contacts_path, gfo_path in sorted(files, key=lambda pair: Path(pair[0]).parent.name):
        contacts, gfo = read(CONTACTS, contacts_path), read(GFO, gfo_path)
        checks = grasp_equilibrium(contacts, equilibrium, synergies.columns([1])[:, 0])
        parts.append(
            (
                realism_of(contacts, gfo, checks, hand, params, families, axes),
                link_shares(contacts, hand.link_names, hand.link_finger),
                graspable_objects(contacts, gfo, params.full_set_id, types),
            )
        )
        del contacts, gfo, checks
    if not parts:
        raise ValueError("realism_by_object: no object's files")
    return tuple(pd.concat([p[i] for p in parts], ignore_index=True) for i in range(3))  # type: ignore[return-value]
