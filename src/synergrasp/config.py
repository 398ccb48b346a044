"""Loading and validating the study configuration.

The schema (``workflow/schemas/config.schema.yaml``) fixes keys, types and ranges; the
checks here add what a schema cannot say (cross-references between keys). Every problem
is reported as one :class:`ConfigError` naming the key, before any work starts.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import yaml

__all__ = [
    "ConfigError",
    "validate_config",
    "synergy_sets",
    "incremental_set_id",
    "set_id",
    "merge_config",
    "gfo_params",
]


class ConfigError(ValueError):
    """A configuration value is missing, unknown or out of range."""


def _key_path(path: Sequence[Any]) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "<top level>"


def _describe(error: Any) -> str:
    """One sentence for one jsonschema error, naming the key and what is allowed."""
    where = _key_path(list(error.absolute_path))
    schema = error.schema
    if error.validator == "additionalProperties":
        allowed = sorted(schema.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed))
        return f"config error at '{where}': unknown key(s) {extra}; allowed keys: {allowed}"
    if error.validator == "required":
        return f"config error at '{where}': {error.message}"
    if error.validator == "enum":
        return (f"config error at '{where}': {error.instance!r} is not allowed; "
                f"allowed values: {schema['enum']}")
    if error.validator == "propertyNames":
        return (f"config error at '{where}': name {error.instance!r} is not allowed; "
                "names may use letters, digits and '_' only")
    return f"config error at '{where}': {error.message}"


def load_schema(schema_path: str | Path) -> dict[str, Any]:
    with open(schema_path, encoding="utf-8") as handle:
        return yaml.safe_load(handle)


def validate_config(config: Mapping[str, Any], schema_path: str | Path,
                    n_synergies: int | None = None) -> None:
    """Validate ``config`` against the schema and the cross-key rules.

    Parameters
    ----------
    config : the merged configuration (as Snakemake holds it).
    schema_path : path of the JSON schema (YAML form).
    n_synergies : number of synergy columns of the synergy file in use, if known; the
        synergy-set bounds are checked against it.

    Raises
    ------
    ConfigError
        With one line per problem, each naming the key and the allowed values.
    """
    from jsonschema import Draft202012Validator

    validator = Draft202012Validator(load_schema(schema_path))
    errors = sorted(validator.iter_errors(dict(config)), key=lambda e: list(e.absolute_path))
    if errors:
        raise ConfigError("\n".join(_describe(e) for e in errors))

    problems: list[str] = []
    for axis in ("alpha_deg", "beta_deg"):
        rng = config["grid"][axis]
        if rng["stop"] < rng["start"]:
            problems.append(f"config error at 'grid.{axis}': stop ({rng['stop']}) is below start ({rng['start']})")
    if config["grid"]["alpha_deg"]["stop"] - config["grid"]["alpha_deg"]["start"] >= 360:
        problems.append("config error at 'grid.alpha_deg': alpha is periodic; the range must span less than 360 deg")
    if all(abs(v) < 1e-12 for v in config["mechanics"]["gravity_direction"]):
        problems.append("config error at 'mechanics.gravity_direction': must be a non-zero vector")
    objects = sorted(config["objects"])
    fig4 = config["analyses"]["fig4"]
    if fig4["object"] not in config["objects"]:
        problems.append(f"config error at 'analyses.fig4.object': unknown object {fig4['object']!r}; "
                        f"allowed values: {objects}")
    sets = config["synergy_sets"]
    k_max = sets["incremental_max"]
    if sets["hierarchy_max_size"] > sets["hierarchy_first"]:
        problems.append("config error at 'synergy_sets.hierarchy_max_size': cannot exceed hierarchy_first")
    if n_synergies is not None:
        for key in ("incremental_max", "hierarchy_first"):
            if sets[key] > n_synergies:
                problems.append(f"config error at 'synergy_sets.{key}': {sets[key]} exceeds the "
                                f"{n_synergies} synergies of the synergy file")
    if config["analyses"]["table2_k_max"] > k_max:
        problems.append(f"config error at 'analyses.table2_k_max': must be at most synergy_sets.incremental_max ({k_max})")
    bad_k = [k for k in fig4["panel_k"] if k > k_max]
    if bad_k:
        problems.append(f"config error at 'analyses.fig4.panel_k': {bad_k} exceed synergy_sets.incremental_max ({k_max})")
    if problems:
        raise ConfigError("\n".join(problems))


def set_id(synergies: Sequence[int]) -> str:
    """Canonical id of a synergy set: 1-based indices, sorted, joined by '-' ("1-2-3")."""
    return "-".join(str(i) for i in sorted(set(synergies)))


def incremental_set_id(k: int) -> str:
    """Id of the incremental set {S1..Sk}."""
    return set_id(range(1, k + 1))


def synergy_sets(sets_config: Mapping[str, int]) -> dict[str, tuple[int, ...]]:
    """All distinct synergy sets of the study, by id, in a fixed order.

    The incremental sets {S1..Sk}, k = 1..incremental_max, then every subset of
    S1..S_hierarchy_first with 1..hierarchy_max_size elements; sets that coincide (e.g.
    {S1, S2}) appear once.
    """
    out: dict[str, tuple[int, ...]] = {}
    for k in range(1, sets_config["incremental_max"] + 1):
        out[incremental_set_id(k)] = tuple(range(1, k + 1))
    first = sets_config["hierarchy_first"]
    for size in range(1, sets_config["hierarchy_max_size"] + 1):
        for combo in itertools.combinations(range(1, first + 1), size):
            out.setdefault(set_id(combo), combo)
    return out


def merge_config(base: Mapping[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    """Recursive merge of two config mappings (override wins; lists are replaced)."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge_config(out[key], value)
        else:
            out[key] = value
    return out


def gfo_params(mechanics: Mapping[str, Any], mass_kg: float):
    """:class:`synergrasp.optimisation.study.GFOParams` from the config's ``mechanics``
    block (units in its key names) and the object's mass (kg); gravity is normalised."""
    import numpy as np

    from synergrasp.optimisation.study import GFOParams

    gravity = np.asarray(mechanics["gravity_direction"], dtype=float)
    return GFOParams(
        gravity_direction=tuple(gravity / np.linalg.norm(gravity)),
        mu=float(mechanics["mu"]),
        f_min=float(mechanics["f_min_N"]),
        k_stru=float(mechanics["k_stru_N_per_mm"]),
        k_ss=float(mechanics["k_ss_Nmm_per_rad"]),
        mass_kg=float(mass_kg),
        g=float(mechanics["g_m_per_s2"]),
    )
