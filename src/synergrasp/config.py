"""The one configuration model of the study.

- **Defaults** live in one place: the ``default:`` values of the schema
  (``config.schema.yaml``, package data beside the shipped hand and synergies); :func:`defaults` builds the full default
  configuration from them and :func:`validate_config` fills every key a config leaves out.
- **Overlays** (a user's config file, a scenario) follow one rule, :func:`overlay`: a mapping
  merges key by key, any other value replaces, ``null`` removes the key (which then takes
  its default, or, for an object, drops it).
- **Checks** run once, before any job: the schema (keys, types, ranges; no NaN or inf; whole
  numbers for integers; text names), then :func:`check_relations` (every relation between
  values). Each problem is one line naming the config key and what is allowed.
- **Parameters**: each stage builds its typed parameters from the configuration itself (a
  ``from_config`` beside the parameter class), with :func:`build` turning a value the class
  rejects into a ConfigError naming the config key. Which keys each step of the workflow
  reads is stated once, in :mod:`synergrasp.steps`.

This module is the lowest layer of the package: it imports no stage.
"""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from synergrasp.yaml_io import read_yaml

__all__ = [
    "ConfigError",
    "SCHEMA_PATH",
    "defaults",
    "overlay",
    "validate_config",
    "block_problems",
    "check_relations",
    "synergy_problems",
    "scenario_names",
    "scenario_config",
    "grid_axis_deg",
    "search_lattice_size",
    "object_names",
    "build",
    "dataclass_fields",
]

#: The schema: keys, types, ranges, descriptions and every default.
SCHEMA_PATH = Path(str(resources.files("synergrasp") / "data" / "config.schema.yaml"))
#: Name of the main configuration among the scenarios.
DEFAULT_SCENARIO = "default"


class ConfigError(ValueError):
    """A configuration value is missing, unknown or out of range (one line per problem)."""


# --------------------------------------------------------------------------- schema walk


@functools.cache
def load_schema() -> dict[str, Any]:
    return read_yaml(SCHEMA_PATH, "schema")


def _resolve(node: Mapping[str, Any]) -> dict[str, Any]:
    """A schema node with ``$ref`` followed and ``allOf`` parts merged (properties deeply)."""
    out: dict[str, Any] = {}
    parts = [node]
    while parts:
        part = parts.pop(0)
        if "$ref" in part:
            target: Any = load_schema()
            for name in part["$ref"].removeprefix("#/").split("/"):
                target = target[name]
            parts.insert(0, target)
        parts.extend(part.get("allOf", []))
        for key, value in part.items():
            if key in ("$ref", "allOf"):
                continue
            if key == "properties":
                props = out.setdefault("properties", {})
                for name, sub in value.items():
                    props[name] = {"allOf": [props[name], sub]} if name in props else sub
            else:
                out.setdefault(key, value)
    return out


def _fill(node: Mapping[str, Any], value: Any) -> Any:
    """``value`` with schema defaults filled in where keys are missing, and whole-number
    floats turned into ints where the schema wants an integer."""
    schema = _resolve(node)
    types = schema.get("type")
    if isinstance(value, float) and value.is_integer() and "integer" in (types if isinstance(types, list) else [types]):
        return int(value)
    if isinstance(value, list) and isinstance(schema.get("items"), Mapping):
        return [_fill(schema["items"], v) for v in value]
    if not isinstance(value, Mapping):
        return value
    out = dict(value)
    for name, sub in schema.get("properties", {}).items():
        if name in out:
            out[name] = _fill(sub, out[name])
        else:
            default = _default(sub)
            if default is not _MISSING:
                out[name] = default
    extra = schema.get("additionalProperties")
    if isinstance(extra, Mapping):
        for name in out:
            if name not in schema.get("properties", {}):
                out[name] = _fill(extra, out[name])
    return out


_MISSING = object()


def _default(node: Mapping[str, Any]) -> Any:
    """The default of a schema node: its ``default:``, or an object built from its
    properties' defaults (if any has one); _MISSING if it has none."""
    schema = _resolve(node)
    if "default" in schema:
        return _fill(schema, copy.deepcopy(schema["default"]))
    built = _fill(schema, {}) if "properties" in schema else None
    return built if built else _MISSING


def defaults() -> dict[str, Any]:
    """The full default configuration (the study of Averta et al. 2018), from the schema."""
    return _default(load_schema())


# --------------------------------------------------------------------------- overlays


def overlay(base: Mapping[str, Any], over: Mapping[str, Any] | None) -> dict[str, Any]:
    """``base`` overlaid with ``over``: a mapping merges key by key, any other value (lists
    included) replaces, and ``None`` removes the key. Neither argument is changed."""
    out = copy.deepcopy(dict(base))
    for key, value in (over or {}).items():
        if value is None:
            out.pop(key, None)
        elif isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = overlay(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _drop_nulls(config: Mapping[str, Any], top: bool = True) -> dict[str, Any]:
    """Keys whose value is None removed at every depth (the overlay rule applied to a
    configuration that Snakemake merged from several files); a scenario set to None is
    removed, the others keep their nulls, as they are overlays still to be applied."""
    return {
        k: _live_scenarios(v) if top and k == "scenarios" else _drop_nulls(v, False) if isinstance(v, Mapping) else v
        for k, v in config.items()
        if v is not None
    }


def _live_scenarios(scenarios: Any) -> Any:
    """The scenarios that an overlay did not remove (``name: null``)."""
    return {n: s for n, s in scenarios.items() if s is not None} if isinstance(scenarios, Mapping) else scenarios


# --------------------------------------------------------------------------- validation


def _key_path(path: Sequence[Any]) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "<top level>"


def _raw_problems(value: Any, path: tuple = ()) -> list[str]:
    """What a JSON schema cannot see: non-text keys and NaN/inf numbers, by key."""
    problems = []
    if isinstance(value, Mapping):
        for key, sub in value.items():
            if not isinstance(key, str):
                problems.append(
                    f"config error at '{_key_path(path)}': name {key!r} "
                    f"({type(key).__name__}) is not allowed; names are text "
                    "(letters, digits and '_'; quote a name such as '1')"
                )
            elif path or key != "scenarios" or not isinstance(sub, Mapping):
                problems += _raw_problems(sub, (*path, key))
            else:  # scenarios: their names here, their values as configurations of their own
                problems += _raw_problems(dict.fromkeys(sub), (key,))
    elif isinstance(value, list):
        for i, sub in enumerate(value):
            problems += _raw_problems(sub, (*path, i))
    elif isinstance(value, float) and not math.isfinite(value):
        problems.append(f"config error at '{_key_path(path)}': {value} is not allowed; a finite number is required")
    return problems


def _describe(error: Any) -> str:
    """One line for one jsonschema error, naming the key and what is allowed; for a value that
    matches none of several forms (``oneOf``/``anyOf``), the error of the form it comes
    closest to: a form of the value's kind (not a ``type``/``enum`` mismatch of the whole
    value) whose error lies deepest inside the value (a mapping with one wrong entry), then
    ``jsonschema.exceptions.best_match``."""
    if error.validator in ("oneOf", "anyOf") and error.context:
        from jsonschema.exceptions import best_match

        near = [e for e in error.context if e.relative_path or e.validator not in ("type", "enum", "const")]
        near = near or list(error.context)
        depth = max(len(e.relative_path) for e in near)
        return _describe(best_match(e for e in near if len(e.relative_path) == depth))
    where = _key_path(list(error.absolute_path))
    schema = error.schema
    if error.validator == "additionalProperties" and isinstance(error.instance, Mapping):
        allowed = sorted(schema.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed))
        return f"config error at '{where}': unknown key(s) {extra}; allowed keys: {allowed}"
    if error.validator == "enum":
        return f"config error at '{where}': {error.instance!r} is not allowed; allowed values: {schema['enum']}"
    if "propertyNames" in error.schema_path:
        name = error.instance
        shown = repr(name) if len(str(name)) <= 70 else f"'{str(name)[:40]}…' ({len(str(name))} characters)"
        return (
            f"config error at '{where}': name {shown} is not allowed; names become file "
            "names: letters, digits and '_' only, at most 64 characters (and not 'default' for a scenario)"
        )
    return f"config error at '{where}': {error.message}"


def validate_config(config: Mapping[str, Any], n_synergies: int | None = None) -> dict[str, Any]:
    """The complete, checked configuration: ``config`` (None values removed, see
    :func:`overlay`) with every missing key filled from the schema's defaults.

    Parameters
    ----------
    config : a configuration as read from YAML (or as Snakemake merged it).
    n_synergies : number of synergies of the synergy file in use, if known; the
        synergy-set bounds are checked against it.

    Raises
    ------
    ConfigError
        With one line per problem, each naming the key and the allowed values.
    """
    from jsonschema import Draft202012Validator

    if not isinstance(config, Mapping):
        raise ConfigError(f"config error at '<top level>': a mapping of keys is required, got {config!r}")
    problems = _raw_problems(config)
    if problems:
        raise ConfigError("\n".join(problems))
    full = _fill(load_schema(), _drop_nulls(config))
    errors = sorted(Draft202012Validator(load_schema()).iter_errors(full), key=lambda e: list(e.absolute_path))
    if errors:
        raise ConfigError("\n".join(_describe(e) for e in errors))
    problems = check_relations(full, n_synergies)
    if problems:
        raise ConfigError("\n".join(problems))
    return full


def block_problems(key: str, value: Any) -> list[str]:
    """The schema's problems of one top-level block ``key: value`` alone (no defaults filled,
    nothing else of the configuration read), one line each naming ``key.<field>``: for a
    block whose values are used before the whole configuration is checked
    (``random_objects``)."""
    from jsonschema import Draft202012Validator

    problems = _raw_problems({key: value})
    if problems:
        return problems
    schema = load_schema()
    sub = {"$defs": schema.get("$defs", {}), "type": "object", "properties": {key: schema["properties"][key]}}
    errors = sorted(Draft202012Validator(sub).iter_errors({key: value}), key=lambda e: list(e.absolute_path))
    return [_describe(e) for e in errors]


def grid_axis_deg(axis: Mapping[str, float]) -> list[float]:
    """The inclusive grid start, start + step, ..., stop of a ``grid`` axis (deg)."""
    n = round((axis["stop"] - axis["start"]) / axis["step"])
    return [axis["start"] + i * axis["step"] for i in range(n + 1)]


def _grid_problems(grid: Mapping[str, Any]) -> list[str]:
    problems = []
    for name, rng in grid.items():
        span, step = rng["stop"] - rng["start"], rng["step"]
        if span < 0:
            problems.append(f"config error at 'grid.{name}.stop': {rng['stop']} is below start ({rng['start']})")
        elif abs(span / step - round(span / step)) > 1e-9:
            problems.append(
                f"config error at 'grid.{name}.step': {step} does not divide stop - start ({span}); the grid must end on stop"
            )
    alpha = grid["alpha_deg"]
    if alpha["stop"] - alpha["start"] >= 360:
        problems.append("config error at 'grid.alpha_deg': alpha is periodic; stop - start must be below 360 deg")
    return problems


def _on_grid(value: float, axis: Mapping[str, float], periodic: bool) -> bool:
    def gap(a: float) -> float:
        d = value - a
        return abs((d + 180.0) % 360.0 - 180.0) if periodic else abs(d)

    return min(gap(a) for a in grid_axis_deg(axis)) < 1e-6


def check_relations(config: Mapping[str, Any], n_synergies: int | None = None) -> list[str]:
    """Every relation between values of a schema-valid, complete configuration, as a list
    of problems (empty: none). One line per problem, naming the key."""
    problems = _grid_problems(config["grid"])
    closure = config["closure"]
    if closure["contact_distance_mm"] < closure["tolerance_mm"]:
        problems.append(
            f"config error at 'closure.contact_distance_mm': {closure['contact_distance_mm']} "
            f"must be at least closure.tolerance_mm ({closure['tolerance_mm']})"
        )
    if closure["step_mm"] <= closure["tolerance_mm"]:
        problems.append(
            f"config error at 'closure.step_mm': {closure['step_mm']} must exceed "
            f"closure.tolerance_mm ({closure['tolerance_mm']})"
        )
    dynamic = closure["dynamic"]
    if dynamic["time_limit_s"] < dynamic["ramp_time_s"]:
        problems.append(
            f"config error at 'closure.dynamic.time_limit_s': {dynamic['time_limit_s']} must be "
            f"at least closure.dynamic.ramp_time_s ({dynamic['ramp_time_s']})"
        )
    else:
        problems += _settle_problems(dynamic)
    if all(abs(v) < 1e-12 for v in config["mechanics"]["gravity_direction"]):
        problems.append("config error at 'mechanics.gravity_direction': must be a non-zero vector")
    sets = config["synergy_sets"]
    k_max = sets["incremental_max"]
    if sets["hierarchy_max_size"] > sets["hierarchy_first"]:
        problems.append(
            f"config error at 'synergy_sets.hierarchy_max_size': {sets['hierarchy_max_size']} "
            f"exceeds synergy_sets.hierarchy_first ({sets['hierarchy_first']})"
        )
    if n_synergies is not None:
        for key in ("incremental_max", "hierarchy_first"):
            if sets[key] > n_synergies:
                problems.append(
                    f"config error at 'synergy_sets.{key}': {sets[key]} exceeds the {n_synergies} synergies of the synergy file"
                )
    analyses = config["analyses"]
    if analyses["table2_k_max"] > k_max:
        problems.append(
            f"config error at 'analyses.table2_k_max': {analyses['table2_k_max']} exceeds synergy_sets.incremental_max ({k_max})"
        )
    bad_k = [k for k in analyses["fig4"]["panel_k"] if k > k_max]
    if bad_k:
        problems.append(f"config error at 'analyses.fig4.panel_k': {bad_k} exceed synergy_sets.incremental_max ({k_max})")
    if not _grid_problems(config["grid"]):
        problems += _pose_problems(config)
        problems += _search_problems(config)
    return problems


def _search_problems(config: Mapping[str, Any]) -> list[str]:
    """The placement search's relations (docs/placement_search.md), globally and per object:
    the refinement spacing divides the coarse one, every region interval is ordered."""
    problems = []
    for where, block in [("placement", config["placement"])] + [
        (f"objects.{name}.placement", spec.get("placement") or {}) for name, spec in config["objects"].items()
    ]:
        search = overlay(config["placement"]["search"], block.get("search")) if where != "placement" else block["search"]
        if where != "placement" and "search" not in block:
            continue
        ratio = search["coarse_spacing_mm"] / search["spacing_mm"]
        if abs(ratio - round(ratio)) > 1e-9:
            problems.append(
                f"config error at '{where}.search.coarse_spacing_mm': {search['coarse_spacing_mm']} must be "
                f"a whole multiple of search.spacing_mm ({search['spacing_mm']})"
            )
        for kind, region in search["region_mm"].items():
            for axis, (lo, hi) in region.items() if region != "hand" else ():
                if hi < lo:
                    problems.append(f"config error at '{where}.search.region_mm.{kind}.{axis}': stop {hi} is below start {lo}")
    return problems


def search_lattice_size(search: Mapping[str, Any], grasp_type: str) -> int:
    """The number of points of the placement search's final lattice for an object of
    ``grasp_type`` (``search.region_mm.<grasp_type>`` at ``search.spacing_mm``): no search can
    have more distinct targets."""
    region = search["region_mm"][grasp_type]
    if region == "hand":  # derived from the hand when the search runs: bounded by a generous box
        return math.prod(int(math.floor(400.0 / search["spacing_mm"])) + 1 for _ in range(3))
    return math.prod(int(math.floor((hi - lo) / search["spacing_mm"] + 1e-9)) + 1 for lo, hi in region.values())


def _settle_problems(dynamic: Mapping[str, Any]) -> list[str]:
    """The dynamic closure can settle: after the ramp, the time left to the limit holds one
    settle window and one step more (in whole time steps, as the closure counts them)."""
    dt = dynamic["time_step_s"]
    ramp = max(1, round(dynamic["ramp_time_s"] / dt))
    left = max(ramp, round(dynamic["time_limit_s"] / dt)) - ramp
    window = max(1, round(dynamic["settle_window_s"] / dt))
    if left >= window + 1:
        return []
    return [
        f"config error at 'closure.dynamic.settle_window_s': {dynamic['settle_window_s']} s leaves no pose "
        f"able to settle: it must be shorter than closure.dynamic.time_limit_s - ramp_time_s "
        f"({dynamic['time_limit_s']} - {dynamic['ramp_time_s']} s) by at least one time_step_s ({dt:.4g} s)"
    ]


def synergy_problems(config: Mapping[str, Any], mean_rad: Any, matrix: Any) -> list[str]:
    """What makes a readable synergy table unusable for the study: S1 moving no joint (the
    hand would never close) or values no posture in rad can have (|value| > 2π: a table in
    degrees, or a stray huge entry). ``mean_rad`` (n,), ``matrix`` (n, k) as loaded."""
    where = f"config error at 'synergies' ({config['synergies'] or 'the shipped table'})"
    mean, syn = np.asarray(mean_rad, dtype=float), np.asarray(matrix, dtype=float)
    problems = []
    if not np.any(np.abs(syn[:, 0]) > 0):
        problems.append(f"{where}: S1 is zero for every joint; closing along S1 would move no joint")
    if np.abs(mean).max() > 2 * math.pi or np.abs(syn).max() > 2 * math.pi:
        problems.append(
            f"{where}: values up to {max(np.abs(mean).max(), np.abs(syn).max()):.4g} exceed "
            "2π; postures and synergies are in rad (is the table in degrees?)"
        )
    return problems


def _pose_problems(config: Mapping[str, Any]) -> list[str]:
    """Poses named by the analyses lie on the grid; no more shards than poses."""
    problems = []
    alpha, beta = config["grid"]["alpha_deg"], config["grid"]["beta_deg"]
    fig4 = config["analyses"]["fig4"]
    if not _on_grid(fig4["alpha_slice_deg"], alpha, periodic=True):
        problems.append(
            f"config error at 'analyses.fig4.alpha_slice_deg': {fig4['alpha_slice_deg']} is "
            f"not on grid.alpha_deg {grid_axis_deg(alpha)}"
        )
    if not _on_grid(fig4["beta_slice_deg"], beta, periodic=False):
        problems.append(
            f"config error at 'analyses.fig4.beta_slice_deg': {fig4['beta_slice_deg']} is "
            f"not on grid.beta_deg {grid_axis_deg(beta)}"
        )
    n_poses = len(grid_axis_deg(alpha)) * len(grid_axis_deg(beta))
    if config["solver"]["pose_shards"] > n_poses:
        problems.append(
            f"config error at 'solver.pose_shards': {config['solver']['pose_shards']} exceeds "
            f"the {n_poses} poses of the grid; allowed values: 1..{n_poses}"
        )
    return problems


# --------------------------------------------------------------------------- scenarios


def scenario_names(config: Mapping[str, Any]) -> list[str]:
    """The scenarios' names, ``default`` (the configuration itself) first, then the
    ``scenarios:`` in their given order; nothing of them is checked here."""
    return [DEFAULT_SCENARIO, *(_live_scenarios(config.get("scenarios")) or {})]


def object_names(config: Mapping[str, Any], study_objects: Sequence[str]) -> set[str]:
    """Every object name the study (``study_objects``, checked) or a scenario may have, read
    from the scenarios' overlays without checking them: the names each gives, and the default
    objects where a scenario removes ``objects`` (it then takes its default)."""
    names = set(study_objects)
    for over in (_live_scenarios(config.get("scenarios")) or {}).values():
        if not isinstance(over, Mapping) or "objects" not in over:
            continue
        objects = over["objects"]
        names |= set(map(str, defaults()["objects"])) if objects is None else set(map(str, objects or {}))
    return names


def _removed_unknown_objects(base: Mapping[str, Any], changes: Mapping[str, Any]) -> list[str]:
    """A scenario's ``objects: {<name>: null}`` naming an object the configuration does not
    have (a typo would otherwise remove nothing, silently)."""
    objects = changes.get("objects")
    if not isinstance(objects, Mapping):
        return []
    known = base.get("objects") if isinstance(base.get("objects"), Mapping) else defaults()["objects"]
    return [
        f"config error at 'objects.{key}': null removes an object, but the study has no object {key!r}; "
        f"objects: {sorted(map(str, known))}"
        for key, value in objects.items()
        if value is None and key not in known
    ]


def scenario_config(config: Mapping[str, Any], name: str) -> dict[str, Any]:
    """One scenario's complete, checked configuration: the configuration (without
    ``scenarios``) overlaid with the scenario's mapping (:func:`overlay`), validated like the
    configuration itself; ``default`` is the configuration. Synergy-count bounds are checked
    by the caller (they need the synergy file).

    Raises
    ------
    ConfigError
        Naming the scenario and the key.
    """
    main = validate_config(config)
    if name == DEFAULT_SCENARIO:
        return {**main, "scenarios": {}}
    if name not in main["scenarios"]:
        raise ConfigError(f"config error at 'scenarios': no scenario {name!r}; allowed values: {scenario_names(main)}")
    changes = main["scenarios"][name]
    if "scenarios" in changes:
        raise ConfigError(f"scenario '{name}': config error at 'scenarios': a scenario cannot define scenarios")
    if "random_objects" in changes:
        raise ConfigError(
            f"scenario '{name}': config error at 'scenarios.{name}.random_objects': a scenario cannot "
            "draw objects of its own; the main configuration's random_objects are every scenario's "
            "objects (a scenario may drop some with objects: {rand_NNN: null})"
        )
    try:
        base = {k: v for k, v in config.items() if k != "scenarios"}
        problems = _removed_unknown_objects(_drop_nulls(base), changes)
        if problems:
            raise ConfigError("\n".join(problems))
        return validate_config(overlay(base, changes))
    except ConfigError as err:
        raise ConfigError("\n".join(f"scenario '{name}': {line}" for line in str(err).splitlines())) from None


def build(cls: Any, where: str, **kwargs: Any) -> Any:
    """``cls(**kwargs)``; a value the class rejects becomes a ConfigError naming the config
    key ``where`` (not the class's field)."""
    try:
        return cls(**kwargs)
    except (TypeError, ValueError) as err:
        message = str(err).replace(f"{cls.__name__}.", f"{where}.")
        raise ConfigError(f"config error at '{where}': {message}") from None


def dataclass_fields(cls: Any, values: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``values`` that are fields of the dataclass ``cls``, lists as tuples."""
    names = set(cls.__dataclass_fields__)
    return {k: tuple(v) if isinstance(v, list) else v for k, v in values.items() if k in names}
