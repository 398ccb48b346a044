"""The study's tables, built one object at a time (docs/design.md, "The study-wide tables, one object at a time").

:class:`StudyReduction` takes the objects in sorted order, each as its gfo table and its
minima; it judges the object's rows (``with_verdicts``), keeps only what the tables need of
them (its success-rate, lost-pose, disagreement, check and preservation rows, its
successes and optimal forces per distinct pose and set, its null-model counts) and drops
the rows before the next object is read. So a job holds one object's rows at a time, and
what it keeps of an object is a few hundred kB (docs/measurements.md, tables_memory and
the benchmark of the tables' aggregation). The bootstrap's and the null model's generators draw for the objects in
the same sorted order as they did over every object's rows at once, and every sum over
objects is a sum of integers or is taken in that order: the tables are the same to the
byte (tests/test_study_tables.py).

:func:`study_tables` is the one front door: from a sequence of (object, loader) pairs, or
from every object's rows at once (:func:`frames_by_object`).
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import TypeAlias

import numpy as np
import pandas as pd

from synergrasp.analysis.bootstrap import PoseResampler
from synergrasp.analysis.chance import chance_tables, check_draws, object_pairs, object_resampled_preservation
from synergrasp.analysis.claims import claims_table, planner_claim
from synergrasp.analysis.intervals import StudyCounts
from synergrasp.analysis.invariants import check_success_rates, object_checks, reported_checks
from synergrasp.analysis.summaries import (
    HIERARCHY_VALUES,
    AnalysisSettings,
    NoSuccessWarning,
    hierarchy_input,
    hierarchy_matrices,
    incrementality_table,
    lost_poses,
    no_success_sentence,
    object_preservation,
    preservation_table,
    set_sort_key,
    success_rates,
    verdict_disagreements,
    with_intervals,
)
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.ids import incremental_set_id, set_members, set_order
from synergrasp.table_contracts import GFO, MINIMA, STUDY_TABLES, read

__all__ = ["ObjectLoader", "StudyReduction", "frames_by_object", "object_loaders", "study_tables", "study_claims"]

#: Reads one object's (gfo table, minima table) when called.
ObjectLoader: TypeAlias = Callable[[], tuple[pd.DataFrame, pd.DataFrame]]

_LOST_COLUMNS = [
    "object",
    "pose",
    "alpha_deg",
    "beta_deg",
    "full_force_norm",
    "first7_status",
    "first7_force_closure",
    "first7_load_feasible",
]


def _joined(parts: list[pd.DataFrame], by: list[str]) -> pd.DataFrame | None:
    """The non-empty ``parts`` one after the other, sorted by ``by`` (set ids by
    :func:`set_sort_key`); the first part where all are empty; None where there is none."""
    if not parts:
        return None
    kept = [p for p in parts if len(p)] or parts[:1]
    out = pd.concat(kept, ignore_index=True) if len(kept) > 1 else kept[0].reset_index(drop=True)
    return out.sort_values(by, key=lambda c: set_sort_key(c) if c.name == "set_id" else c, ignore_index=True)


class StudyReduction:
    """The study's tables, fed one object at a time in sorted order (:meth:`add`), made by
    :meth:`tables`. ``sets_config``: the configuration's ``synergy_sets``; ``claims_only``:
    keep only what the claims table needs (``study_claims``)."""

    def __init__(self, sets_config: Mapping[str, int], settings: AnalysisSettings, claims_only: bool = False):
        check_draws(settings.null_draws)
        self.settings = settings
        self.k_max = int(sets_config["incremental_max"])
        self.first = int(sets_config["hierarchy_first"])
        self.full = incremental_set_id(self.k_max)
        self.first_n = incremental_set_id(self.first)
        self.claims_only = claims_only
        self.resampler = PoseResampler(pd.DataFrame(columns=["object", "pose", "alpha_deg", "beta_deg"]), {}, settings.bootstrap)
        self.counts = StudyCounts(pd.DataFrame(columns=["object", "set_id"]), self.full, self.resampler)
        self._null_rng = np.random.default_rng(settings.null_seed)
        self.objects: list[str] = []
        self.sets: set[str] = set()
        self._pairs: list[dict] = []
        self._kept: list[dict] = []
        self._rates: list[pd.DataFrame] = []
        self._lost: list[pd.DataFrame] = []
        self._disagree: list[pd.DataFrame] = []
        self._checks: list[dict] = []
        self._preservation: list[dict] = []
        self._any_success = False
        self._n_fc = 0

    def add(self, obj: str, gfo: pd.DataFrame, minima: pd.DataFrame) -> None:
        """Reduce one object: ``gfo`` and ``minima`` its rows (gfo and minima tables); the
        objects in sorted order, each once."""
        if self.objects and not obj > self.objects[-1]:
            raise ValueError(f"StudyReduction.add: objects in sorted order, each once; {obj!r} after {self.objects[-1]!r}")
        self.objects.append(obj)
        s, period = self.settings, float(self.settings.periods_deg.get(obj, 360.0))
        alpha_start = float(gfo["alpha_deg"].min()) if len(gfo) else None
        if not self.claims_only:
            self._preservation += object_preservation(obj, minima, alpha_start, self.k_max, s.radius_deg, period)
        if not len(gfo):
            return
        own = with_verdicts(gfo, s.success, s.weights_N, s.marginal_weight_multiple)
        present = set(own["set_id"].astype(str).unique())
        self.sets |= present
        full_rows = own[own["set_id"] == self.full]
        if len(full_rows):
            self.resampler.add(obj, full_rows, period)
            self.counts.add(obj, own)
            self._kept.append(object_resampled_preservation(obj, minima, self.k_max, s.radius_deg, self.resampler))
        self._pairs += object_pairs(obj, own, minima, self.k_max, s.radius_deg, period, s.null_draws, self._null_rng)
        if self.claims_only:
            return
        rates = success_rates(own, self.full, {obj: period})
        self._rates.append(rates)
        self._checks += object_checks(obj, own, rates, period, s.success_rate_tolerance_percent)
        self._lost.append(lost_poses(own, self.full, self.first_n))
        self._disagree.append(verdict_disagreements(own))
        self._any_success |= bool(own["success"].astype(bool).any())
        self._n_fc += int(own["verdict_force_closure"].astype(bool).sum())

    def claims(self, planners: pd.DataFrame | None = None) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
        """(the claims table, claim 8 from ``planners`` where given; the null model's summary;
        its pairs), from the objects added."""
        self.counts.finish(sorted(self.sets, key=set_order))
        chance, pairs = chance_tables(self._pairs, self.settings.null_draws)
        kept = pd.DataFrame(self._kept, columns=["object", "n_minima", "n_preserved"])
        claims = claims_table(self.counts, kept, chance, self.settings.rules, self.first)
        if planners is not None:
            claims = pd.concat([claims, planner_claim(planners, self.settings.rules)], ignore_index=True)
        return claims, chance, pairs

    def tables(self, table2_k_max: int, planners: pd.DataFrame | None = None) -> dict[str, tuple[str, pd.DataFrame]]:
        """Every study table by name (``table_contracts.STUDY_TABLES``, in that order): (title, table)."""
        s = self.settings
        present = sorted(self.sets, key=lambda x: (len(set_members(x)), x))
        if self.full not in self.sets:
            raise ValueError(f"full_set_id {self.full!r} is not in the gfo table; allowed values: {present}")
        claims, chance, pairs = self.claims(planners)
        rates = _joined(self._rates, ["object", "set_id"])
        checks = reported_checks(self._checks, check_success_rates(rates, s.success_rate_tolerance_percent))
        lost = _joined(self._lost, ["object", "pose"]) if self.first_n in self.sets else None
        preservation = preservation_table(self._preservation, self.objects)
        preservation = preservation.merge(pairs.astype({"k": "Int64"}), on=["object", "k"], how="left")
        table2 = incrementality_table(rates, table2_k_max)
        rates = with_intervals(rates, self.counts)
        verdict = f"success = {s.success}"
        nothing = no_success_sentence(self._any_success, self._n_fc, s)
        if nothing:  # on the console, in the log and in the titles naming the verdict
            warnings.warn(nothing, NoSuccessWarning, stacklevel=2)
            verdict += f" (WARNING: {nothing})"
        level = f"{100 * s.bootstrap.level:g} % intervals: block bootstrap over distinct poses"
        k_max, first = self.k_max, self.first
        entries = {
            "success_rates": (
                f"Success rates per distinct pose (every verdict) and forces per object and synergy set, "
                f"and averaged over objects in both views; {level}; {verdict}",
                rates,
            ),
            "table2_success_rates": (
                f"Table II: success rate (%, per distinct pose) with {{S1..Sk}}, k = 1..{table2_k_max}; {verdict}",
                table2,
            ),
            "hierarchy": (
                f"Hierarchy: sets {{S_k, S_i, S_j}} of the first {first} synergies, averaged over objects "
                f"(per-object and pooled views); {level}; {verdict}",
                hierarchy_matrices(hierarchy_input(rates), first, HIERARCHY_VALUES),
            ),
            "minimum_preservation": (f"Local minima of {{S1..Sk}} preserved in {{S1..Sk+1}}; {verdict}", preservation),
            "preservation_vs_chance": (
                f"Minimum preservation against the null model ({s.null_draws} draws, seed {s.null_seed}); {verdict}",
                chance,
            ),
            "full_not_first7": (
                f"Poses where {{S1..S{k_max}}} succeeds and {{S1..S{first}}} does not; {verdict}",
                lost if lost is not None else pd.DataFrame(columns=_LOST_COLUMNS),
            ),
            "verdict_disagreements": (
                "Force closure (Definition 1) vs feasibility under the weight",
                _joined(self._disagree, ["object", "set_id"]),
            ),
            "invariant_checks": ("The pipeline's invariant checks on this run", checks),
            "claims": (
                f"The study's claims tested on this run, one row per view (headline first); {level}"
                + ("; claim 8: bootstrap over objects" if planners is not None else "")
                + f"; {verdict}",
                claims,
            ),
        }
        return {name: entries[name] for name in STUDY_TABLES}


def frames_by_object(gfo: pd.DataFrame, minima: pd.DataFrame) -> list[tuple[str, ObjectLoader]]:
    """Every object of ``gfo`` or ``minima`` (every object's rows at once), sorted, each with
    a loader of its own rows."""
    names = sorted(set(gfo["object"].unique()) | set(minima["object"].unique()))
    return [(obj, lambda obj=obj: (gfo[gfo["object"] == obj], minima[minima["object"] == obj])) for obj in names]


def object_loaders(gfo_paths: Sequence[str | Path], minima_paths: Sequence[str | Path]) -> list[tuple[str, ObjectLoader]]:
    """Every object's loader of its gfo and minima files (``results/objects/<object>/``, the
    two lists in the same order); a loader refuses, naming the file, a table whose rows are
    not of that object."""
    if len(gfo_paths) != len(minima_paths):
        raise ValueError(f"object_loaders: {len(gfo_paths)} gfo files but {len(minima_paths)} minima files")
    out = []
    for gfo_path, minima_path in zip(gfo_paths, minima_paths):
        obj = Path(gfo_path).parent.name
        if Path(minima_path).parent.name != obj:
            raise ValueError(f"object_loaders: minima file '{minima_path}' is not of object {obj!r} (gfo file '{gfo_path}')")
        out.append((obj, functools.partial(_load, obj, gfo_path, minima_path)))
    return out


def _load(obj: str, gfo_path: str | Path, minima_path: str | Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    frames = read(GFO, gfo_path), read(MINIMA, minima_path)
    for frame, path in zip(frames, (gfo_path, minima_path)):
        others = sorted(set(frame["object"].astype(str)) - {obj})
        if others:
            raise ValueError(f"'{path}': rows of object(s) {others[:3]} in the file of object {obj!r}")
    return frames


def _reduced(objects: Iterable[tuple[str, ObjectLoader]], reduction: StudyReduction) -> StudyReduction:
    for obj, load in sorted(objects, key=lambda pair: pair[0]):
        gfo, minima = load()
        reduction.add(obj, gfo, minima)
        del gfo, minima  # one object's rows at a time
    return reduction


def study_tables(
    objects: Iterable[tuple[str, ObjectLoader]],
    sets_config: Mapping[str, int],
    table2_k_max: int,
    settings: AnalysisSettings,
    planners: pd.DataFrame | None = None,
) -> dict[str, tuple[str, pd.DataFrame]]:
    """Every study table by name (``table_contracts.STUDY_TABLES``, in that order): (title, table).

    ``objects``: (object name, loader of its gfo and minima tables), read one at a time in
    sorted order (:func:`frames_by_object` for every object's rows at once);
    ``sets_config`` is the configuration's ``synergy_sets`` (incremental_max,
    hierarchy_first, ...): the full set is {S1..S_incremental_max}, the hierarchy uses the
    first ``hierarchy_first`` synergies. ``planners``: the planners compared per object
    (``table_contracts.PLANNERS``), whose claim 8 joins the claims (None: the seven only). Raises
    :class:`InvariantError` when a success rate exceeds 100 % beyond the tolerance; warns on
    the other invariant checks.
    """
    return _reduced(objects, StudyReduction(sets_config, settings)).tables(table2_k_max, planners)


def study_claims(
    gfo: pd.DataFrame, minima: pd.DataFrame, sets_config: Mapping[str, int], settings: AnalysisSettings
) -> pd.DataFrame:
    """The claims table of :func:`study_tables` alone (the other tables are not made)."""
    return _reduced(frames_by_object(gfo, minima), StudyReduction(sets_config, settings, claims_only=True)).claims()[0]
