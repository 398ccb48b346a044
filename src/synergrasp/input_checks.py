"""The one check of a study's inputs before any work, for the workflow and for every command of
the package alike (config/README.md, "Checked before any job runs").

:func:`checked_scenario` is that check: one scenario's configuration (the schema and every
relation, ``synergrasp.config``), its hand file, its synergy table against the hand, and its
objects' shapes; besides the problems (errors), the warnings on sizes far from a hand's and on
a thumb that cannot oppose along S1 (``synergrasp.simulation.thumb_check``). The
workflow asks it through ``synergrasp.wiring.Wiring.scenario`` (common.smk), ``synergrasp grasp``
through ``synergrasp.inspector``; :func:`read_overlays` reads a command's ``--configfile`` files as
strictly as the workflow reads its own. Checks that need a step's output where it exists
(:func:`search_rank_problems`), the objects' resolved placements and grasp types
(:func:`lattice_rank_problems`) or a target's whole configuration
(:func:`searched_objects_or_refuse`) are here too, and the tables of a results folder an older
version wrote (:func:`older_results_problems`). Every problem is one line naming the file or
the key.
"""

from __future__ import annotations

import csv
import functools
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from synergrasp.config import (
    DEFAULT_SCENARIO,
    ConfigError,
    check_relations,
    overlay,
    scenario_config,
    search_lattice_size,
    synergy_problems,
)
from synergrasp.preflight import refuse
from synergrasp.resolved import effective_placement, grasp_type
from synergrasp.yaml_io import read_yaml

__all__ = [
    "checked_scenario",
    "checked_configuration",
    "overlays_with_drawn_objects",
    "read_overlays",
    "search_rank_problems",
    "lattice_rank_problems",
    "search_table_or_refuse",
    "searched_objects_or_refuse",
    "older_results_problems",
    "unknown_object",
]


@functools.cache
def _hand(path: str | None) -> tuple[Any, tuple[str, ...], tuple[str, ...]]:
    """The hand of a ``hand:`` value, its problems and its warnings (read once per file)."""
    from synergrasp.hand.checks import check_hand

    hand, problems, warnings = check_hand(path)
    return hand, tuple(problems), tuple(warnings)


def checked_scenario(config: Mapping[str, Any], name: str = DEFAULT_SCENARIO) -> tuple[dict[str, Any], list[str]]:
    """Scenario ``name``'s complete, checked configuration (``default``: the configuration
    itself) and the warnings on it, each one line naming the file or the key.

    Raises
    ------
    ConfigError
        Every problem, one line each (a scenario's prefixed with its name): the configuration,
        the hand file, the synergy table, the objects' shapes.
    """
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.simulation.objects import object_problems, object_warnings
    from synergrasp.simulation.thumb_check import cached_opposition_warnings

    where = "" if name == DEFAULT_SCENARIO else f"scenario '{name}': "
    try:
        cfg = scenario_config(config, name)
        hand, problems, warnings = _hand(cfg["hand"])
        synergies = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
        problems = [
            *problems,
            *check_relations(cfg, synergies.matrix.shape[1]),
            *lattice_rank_problems(cfg),
            *synergy_problems(cfg, synergies.mean, synergies.matrix),
            *object_problems(cfg),
        ]
    except ConfigError:
        raise
    except ValueError as err:  # SynergyFileError, hand and YAML file errors: one line each, naming the file
        raise ConfigError("\n".join(where + line for line in str(err).splitlines())) from None
    if problems:
        raise ConfigError("\n".join(where + p for p in problems))
    thumb = cached_opposition_warnings(cfg["hand"], cfg["synergies"])
    return cfg, [*warnings, *(where + w for w in (*thumb, *object_warnings(cfg)))]


def read_overlays(paths: Sequence[str | Path], what: str = "config file") -> dict[str, Any]:
    """The configuration given by overlay files, in order (``config.overlay``), each read as
    the workflow reads its configuration files (``yaml_io.read_yaml``: a repeated key or
    invalid YAML is an error naming the file and the line) and required to be a mapping."""
    config: dict[str, Any] = {}
    for path in paths:
        doc = read_yaml(path, what) or {}
        if not isinstance(doc, Mapping):
            raise ConfigError(
                f"{what} '{path}': the top level must be a mapping of keys (key: value), got a {type(doc).__name__}"
            )
        config = overlay(config, doc)
    return config


def _distinct_targets(path: Path) -> int | None:
    """The number of distinct targets of a search's table (rows with a positive
    ``distinct_rank``); None if the file cannot be read as that table."""
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            return sum(1 for row in csv.DictReader(handle) if float(row["distinct_rank"]) > 0)
    except (OSError, KeyError, ValueError, TypeError, csv.Error):
        return None


def _rank_key(cfg: Mapping[str, Any], obj: str) -> str:
    """Where object ``obj``'s ``search_rank`` is set: its own placement or the global one."""
    return "placement" if "search_rank" not in (cfg["objects"][obj].get("placement") or {}) else f"objects.{obj}.placement"


def lattice_rank_problems(cfg: Mapping[str, Any]) -> list[str]:
    """A searched placement's rank that no search under the configuration can reach (one
    line per key and lattice, naming the objects)."""
    found: dict[tuple[str, int, int, float], list[str]] = {}
    for name in cfg["objects"]:
        placement, kind = effective_placement(cfg, name), grasp_type(cfg, name)
        region = placement["search"]["region_mm"][kind]
        if placement["mode"] != "searched" or (region != "hand" and any(hi < lo for lo, hi in region.values())):
            continue
        n = search_lattice_size(placement["search"], kind)
        if placement["search_rank"] > n:
            key = (_rank_key(cfg, name), placement["search_rank"], n, placement["search"]["spacing_mm"])
            found.setdefault(key, []).append(name)
    return [
        f"config error at '{where}.search_rank': {rank} exceeds the {n} points of the search lattice of "
        f"{', '.join(names)} (search.region_mm of its grasp type at search.spacing_mm {spacing:g} mm): no search "
        "has that many distinct targets"
        for (where, rank, n, spacing), names in found.items()
    ]


def search_rank_problems(cfg: Mapping[str, Any], obj: str, table: str | Path) -> list[str]:
    """Object ``obj``'s ``search_rank`` against its search's table ``table`` where that table
    exists already (the closure would fail after other jobs ran, and the search does not
    read the rank). A table made in this run is judged by the closure, before it writes."""
    placement = effective_placement(cfg, obj)
    n = _distinct_targets(Path(table)) if Path(table).is_file() else None
    if placement["mode"] != "searched" or n is None or placement["search_rank"] <= n:
        return []
    where = _rank_key(cfg, obj)
    return [
        f"config error at '{where}.search_rank': {placement['search_rank']} exceeds the {n} distinct targets of "
        f"{obj}'s placement search ({table})"
    ]


def search_table_or_refuse(cfg: Mapping[str, Any], obj: str, table: str, stop: Callable[[list[str]], Any] = refuse) -> str:
    """``table`` (object ``obj``'s search table, an input); its :func:`search_rank_problems`
    stop the run before any job."""
    stop(search_rank_problems(cfg, obj, table))
    return table


def searched_objects_or_refuse(
    files: list[str], target: str, cfg: Mapping[str, Any], stop: Callable[[list[str]], Any] = refuse
) -> list[str]:
    """``files`` (one per object whose placement is searched); an empty list stops the run:
    ``target`` needs the placement search's targets and no object of ``cfg`` is searched."""
    if not files:
        modes = sorted({effective_placement(cfg, name)["mode"] for name in cfg["objects"]})
        stop(
            [
                f"{target}: no object's placement is searched (placement.mode: {', '.join(modes)}); the claims at the "
                "placement search's targets need placement.mode: searched (docs/placement_search.md)"
            ]
        )
    return files


def older_results_problems(results: str | Path = "results") -> list[str]:
    """Every table under ``results`` (scenarios' folders included) written by an older version
    of the study (``table_contracts.older_version``: a column under its old name), one line each naming
    the file; read from the files' schemas before any job, so that a run refuses them up
    front as ``synergrasp plan`` does, not inside the jobs that read them."""
    from synergrasp import table_contracts

    problems = []
    for table in table_contracts.CONTRACTS.values():
        if table.renamed and Path(results).is_dir():
            problems += [
                line
                for path in sorted(Path(results).rglob(f"{table.name}.parquet"))
                if (line := table_contracts.older_version(table, path))
            ]
    return problems


def unknown_object(cfg: Mapping[str, Any], obj: str) -> str:
    """The line a command gives for an object ``obj`` that the checked configuration ``cfg``
    does not have ('' if it has it): its objects, and for a name like a drawn object's
    (``rand_NNN``) without a ``random_objects`` block, where the drawn objects come from."""
    if obj in cfg["objects"]:
        return ""
    hint = (
        ("; objects drawn by random_objects are objects of a --configfile with that block (docs/random_objects.md)")
        if obj.startswith("rand_") and not cfg.get("random_objects")
        else ""
    )
    return f"object: {obj!r} is not an object of the configuration; objects: {list(cfg['objects'])}{hint}"


def overlays_with_drawn_objects(configfiles: Sequence[str | Path]) -> dict[str, Any]:
    """The configuration of ``--configfile`` overlays as the workflow has it: with the objects
    its ``random_objects`` block draws (manifest relative to the working folder, the project's
    root), the block checked before anything is drawn. Raises ``ConfigError``."""
    from synergrasp.simulation.random_objects import add_random_objects

    config = read_overlays(configfiles)
    add_random_objects(config, ".")
    return config


def checked_configuration(configfiles: Sequence[str | Path]) -> dict[str, Any]:
    """The checked configuration of overlay files, drawn objects included
    (``overlays_with_drawn_objects``). Raises ``ConfigError`` naming the file or the key."""
    return checked_scenario(overlays_with_drawn_objects(configfiles))[0]
