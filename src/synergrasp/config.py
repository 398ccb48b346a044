"""The one configuration model of the study.

- **Defaults** live in one place: the ``default:`` values of the schema
  (``workflow/schemas/config.schema.yaml``); :func:`defaults` builds the full default
  configuration from them and :func:`validate_config` fills every key a config leaves out.
- **Overlays** (a user's config file, a scenario) follow one rule, :func:`overlay`: a mapping
  merges key by key, any other value replaces, ``null`` removes the key (which then takes
  its default, or, for an object, drops it).
- **Checks** run once, before any job: the schema (keys, types, ranges; no NaN or inf; whole
  numbers for integers; text names), then :func:`check_relations` (every relation between
  values). Each problem is one line naming the config key and what is allowed.
- **Steps**: :data:`STEP_KEYS` says which keys each step of the workflow reads;
  :func:`step_config` cuts a configuration down to them (the workflow passes only that to a
  rule, so a step reruns only when a key it reads changes, and scenarios share a step's
  outputs when its keys agree, :func:`step_hash`), and :func:`step_params` turns it into
  the step's typed parameters (units kept in the names).
"""

from __future__ import annotations

import copy
import functools
import hashlib
import importlib
import itertools
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from synergrasp.simulation.objects import GraspedObject
from synergrasp.simulation.shapes import ShapeError, shape_from_config
from synergrasp.yaml_io import read_yaml

__all__ = [
    "ConfigError",
    "SCHEMA_PATH",
    "STEP_KEYS",
    "defaults",
    "overlay",
    "validate_config",
    "check_relations",
    "synergy_problems",
    "scenario_configs",
    "step_config",
    "step_hash",
    "step_upstream_when",
    "step_params",
    "placement_params",
    "grid_axis_deg",
    "synergy_sets",
    "incremental_set_id",
    "set_id",
]

#: The schema: keys, types, ranges, descriptions and every default.
SCHEMA_PATH = Path(__file__).resolve().parents[2] / "workflow" / "schemas" / "config.schema.yaml"
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
    if isinstance(value, float) and value.is_integer() and "integer" in (
            types if isinstance(types, list) else [types]):
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
    configuration that Snakemake merged from several files); scenarios keep theirs, as
    they are overlays still to be applied."""
    return {k: v if top and k == "scenarios" else _drop_nulls(v, False) if isinstance(v, Mapping) else v
            for k, v in config.items() if v is not None}


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
                problems.append(f"config error at '{_key_path(path)}': name {key!r} "
                                f"({type(key).__name__}) is not allowed; names are text "
                                "(letters, digits and '_'; quote a name such as '1')")
            elif path or key != "scenarios" or not isinstance(sub, Mapping):
                problems += _raw_problems(sub, (*path, key))
            else:  # scenarios: their names here, their values as configurations of their own
                problems += _raw_problems(dict.fromkeys(sub), (key,))
    elif isinstance(value, list):
        for i, sub in enumerate(value):
            problems += _raw_problems(sub, (*path, i))
    elif isinstance(value, float) and not math.isfinite(value):
        problems.append(f"config error at '{_key_path(path)}': {value} is not allowed; "
                        "a finite number is required")
    return problems


def _describe(error: Any) -> str:
    """One line for one jsonschema error, naming the key and what is allowed."""
    where = _key_path(list(error.absolute_path))
    schema = error.schema
    if error.validator == "additionalProperties" and isinstance(error.instance, Mapping):
        allowed = sorted(schema.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed))
        return f"config error at '{where}': unknown key(s) {extra}; allowed keys: {allowed}"
    if error.validator == "enum":
        return (f"config error at '{where}': {error.instance!r} is not allowed; "
                f"allowed values: {schema['enum']}")
    if "propertyNames" in error.schema_path:
        name = error.instance
        shown = repr(name) if len(str(name)) <= 70 else f"'{str(name)[:40]}…' ({len(str(name))} characters)"
        return (f"config error at '{where}': name {shown} is not allowed; names become file "
                "names: letters, digits and '_' only, at most 64 characters (and not 'default' for a scenario)")
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
            problems.append(f"config error at 'grid.{name}.step': {step} does not divide stop - start "
                            f"({span}); the grid must end on stop")
    alpha = grid["alpha_deg"]
    if alpha["stop"] - alpha["start"] >= 360:
        problems.append("config error at 'grid.alpha_deg': alpha is periodic; stop - start must be "
                        "below 360 deg")
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
        problems.append(f"config error at 'closure.contact_distance_mm': {closure['contact_distance_mm']} "
                        f"must be at least closure.tolerance_mm ({closure['tolerance_mm']})")
    if closure["step_mm"] <= closure["tolerance_mm"]:
        problems.append(f"config error at 'closure.step_mm': {closure['step_mm']} must exceed "
                        f"closure.tolerance_mm ({closure['tolerance_mm']})")
    dynamic = closure["dynamic"]
    if dynamic["time_limit_s"] < dynamic["ramp_time_s"]:
        problems.append(f"config error at 'closure.dynamic.time_limit_s': {dynamic['time_limit_s']} must be "
                        f"at least closure.dynamic.ramp_time_s ({dynamic['ramp_time_s']})")
    else:
        problems += _settle_problems(dynamic)
    if all(abs(v) < 1e-12 for v in config["mechanics"]["gravity_direction"]):
        problems.append("config error at 'mechanics.gravity_direction': must be a non-zero vector")
    sets = config["synergy_sets"]
    k_max = sets["incremental_max"]
    if sets["hierarchy_max_size"] > sets["hierarchy_first"]:
        problems.append(f"config error at 'synergy_sets.hierarchy_max_size': {sets['hierarchy_max_size']} "
                        f"exceeds synergy_sets.hierarchy_first ({sets['hierarchy_first']})")
    if n_synergies is not None:
        for key in ("incremental_max", "hierarchy_first"):
            if sets[key] > n_synergies:
                problems.append(f"config error at 'synergy_sets.{key}': {sets[key]} exceeds the "
                                f"{n_synergies} synergies of the synergy file")
    analyses = config["analyses"]
    if analyses["table2_k_max"] > k_max:
        problems.append(f"config error at 'analyses.table2_k_max': {analyses['table2_k_max']} exceeds "
                        f"synergy_sets.incremental_max ({k_max})")
    bad_k = [k for k in analyses["fig4"]["panel_k"] if k > k_max]
    if bad_k:
        problems.append(f"config error at 'analyses.fig4.panel_k': {bad_k} exceed "
                        f"synergy_sets.incremental_max ({k_max})")
    for name, spec in config["objects"].items():
        try:
            shape_from_config(spec["shape"], f"objects.{name}.shape")
        except ShapeError as err:
            problems.append(f"config error at {err}")
    if not _grid_problems(config["grid"]):
        problems += _pose_problems(config)
        problems += _search_problems(config)
    return problems


def _search_problems(config: Mapping[str, Any]) -> list[str]:
    """The placement search's relations (docs/placement_search.md), globally and per object:
    the refinement spacing divides the coarse one, every region interval is ordered."""
    problems = []
    for where, block in [("placement", config["placement"])] + [
            (f"objects.{name}.placement", spec.get("placement") or {}) for name, spec in config["objects"].items()]:
        search = overlay(config["placement"]["search"], block.get("search")) if where != "placement" else block["search"]
        if where != "placement" and "search" not in block:
            continue
        ratio = search["coarse_spacing_mm"] / search["spacing_mm"]
        if abs(ratio - round(ratio)) > 1e-9:
            problems.append(f"config error at '{where}.search.coarse_spacing_mm': {search['coarse_spacing_mm']} must be "
                            f"a whole multiple of search.spacing_mm ({search['spacing_mm']})")
        for axis, (lo, hi) in search["region_mm"].items():
            if hi < lo:
                problems.append(f"config error at '{where}.search.region_mm.{axis}': stop {hi} is below start {lo}")
    return problems


def _settle_problems(dynamic: Mapping[str, Any]) -> list[str]:
    """The dynamic closure can settle: after the ramp, the time left to the limit holds one
    settle window and one step more (in whole time steps, as the closure counts them)."""
    dt = dynamic["time_step_s"]
    ramp = max(1, round(dynamic["ramp_time_s"] / dt))
    left = max(ramp, round(dynamic["time_limit_s"] / dt)) - ramp
    window = max(1, round(dynamic["settle_window_s"] / dt))
    if left >= window + 1:
        return []
    return [f"config error at 'closure.dynamic.settle_window_s': {dynamic['settle_window_s']} s leaves no pose "
            f"able to settle: it must be shorter than closure.dynamic.time_limit_s - ramp_time_s "
            f"({dynamic['time_limit_s']} - {dynamic['ramp_time_s']} s) by at least one time_step_s ({dt:.4g} s)"]


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
        problems.append(f"{where}: values up to {max(np.abs(mean).max(), np.abs(syn).max()):.4g} exceed "
                        "2π; postures and synergies are in rad (is the table in degrees?)")
    return problems


def _pose_problems(config: Mapping[str, Any]) -> list[str]:
    """Poses named by the analyses lie on the grid; no more shards than poses."""
    problems = []
    alpha, beta = config["grid"]["alpha_deg"], config["grid"]["beta_deg"]
    fig4 = config["analyses"]["fig4"]
    if not _on_grid(fig4["alpha_slice_deg"], alpha, periodic=True):
        problems.append(f"config error at 'analyses.fig4.alpha_slice_deg': {fig4['alpha_slice_deg']} is "
                        f"not on grid.alpha_deg {grid_axis_deg(alpha)}")
    if not _on_grid(fig4["beta_slice_deg"], beta, periodic=False):
        problems.append(f"config error at 'analyses.fig4.beta_slice_deg': {fig4['beta_slice_deg']} is "
                        f"not on grid.beta_deg {grid_axis_deg(beta)}")
    n_poses = len(grid_axis_deg(alpha)) * len(grid_axis_deg(beta))
    if config["solver"]["pose_shards"] > n_poses:
        problems.append(f"config error at 'solver.pose_shards': {config['solver']['pose_shards']} exceeds "
                        f"the {n_poses} poses of the grid; allowed values: 1..{n_poses}")
    return problems


# --------------------------------------------------------------------------- scenarios

def scenario_configs(config: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Every scenario's complete configuration by name, ``default`` (the configuration
    itself) first, then the ``scenarios:`` in their given order.

    Each scenario is the configuration (without ``scenarios``) overlaid with the scenario's
    mapping (:func:`overlay`), validated like the configuration itself. Synergy-count
    bounds are checked by the caller (they need the synergy file).

    Raises
    ------
    ConfigError
        Naming the scenario and the key.
    """
    main = validate_config(config)
    base = {k: v for k, v in config.items() if k != "scenarios"}
    out = {DEFAULT_SCENARIO: {**main, "scenarios": {}}}
    problems = []
    for name, changes in main["scenarios"].items():
        if "scenarios" in changes:
            problems.append(f"scenario '{name}': config error at 'scenarios': a scenario cannot define scenarios")
            continue
        try:
            out[name] = validate_config(overlay(base, changes))
        except ConfigError as err:
            problems += [f"scenario '{name}': {line}" for line in str(err).splitlines()]
    if problems:
        raise ConfigError("\n".join(problems))
    return out


# --------------------------------------------------------------------------- steps

#: The configuration keys each step reads ("objects.{object}" is the step's object,
#: "objects.*" every object). A step's rule is given only these (step_config), so it reruns
#: only when one of them changes, and two scenarios share its outputs when they agree on
#: them. A new key: one schema entry, plus its path here if a step reads it.
STEP_KEYS: dict[str, tuple[str, ...]] = {
    "simulate": ("hand", "synergies", "grid", "placement", "closure",
                 "objects.{object}.shape", "objects.{object}.placement"),
    "contacts": ("closure.model",),
    "optimise": ("synergies", "mechanics", "synergy_sets", "solver.pose_shards", "objects.{object}.mass_kg"),
    "minima": ("analyses.minima_radius_deg", "analyses.success"),
    "tables": ("synergy_sets", "analyses.minima_radius_deg", "analyses.table2_k_max", "analyses.success",
               "analyses.marginal_weight_multiple", "analyses.success_rate_tolerance_percent",
               "analyses.null_model", "analyses.headline_view", "analyses.tie_band", "analyses.min_distinct_poses",
               "analyses.bootstrap", "objects", "placement", "grid", "hand", "mechanics.g_m_per_s2"),
    "realism": ("hand", "synergy_sets.incremental_max", "objects.*.mass_kg", "mechanics.g_m_per_s2"),
    "fig1": ("hand", "synergies"),
    "fig2": ("hand", "objects.*.shape"),
    "fig4": ("analyses.fig4", "analyses.success"),
    "fig5": ("synergy_sets.hierarchy_first", "analyses.success"),
    # the placement search (docs/placement_search.md): the kinematic closure and the
    # optimisation with the full set {S1..S_incremental_max} only
    "search": ("hand", "synergies", "grid", "placement", "closure", "mechanics", "synergy_sets.incremental_max",
               "objects.{object}.shape", "objects.{object}.mass_kg", "objects.{object}.placement"),
}
#: The keys of the choice of which contacts count (the ``contacts`` step).
_CONTACT_SELECTION = ("closure.dynamic.unloaded_contacts", "closure.dynamic.load_threshold_N")
#: The keys of the force bound of ``analyses.success: force_closure_bounded``.
_FORCE_BOUND = ("analyses.marginal_weight_multiple", "objects.{object}.mass_kg", "mechanics.g_m_per_s2")
#: Keys a step reads only when another key has a given value: step -> ((key, value, reads), ...).
STEP_KEYS_WHEN: dict[str, tuple[tuple[str, Any, tuple[str, ...]], ...]] = {
    # the dynamic closure: a free box of the object's mass, μ, k_ss and gravity of mechanics
    "simulate": (("closure.model", "dynamic", ("objects.{object}.mass_kg", "mechanics")),),
    # which contacts count: only the dynamic model records the load each contact carries
    "contacts": (("closure.model", "dynamic", _CONTACT_SELECTION),),
    "realism": (("closure.model", "dynamic", ("closure.dynamic.load_threshold_N",)),),
    # force closure within a multiple of the weight: the minima and Fig. 4 read the bound
    "minima": (("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
    "fig4": (("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
}
#: Keys inside a block a step reads that the step itself does not read: step -> key paths.
#: The closure lists every touching link with its load; which of them count is the
#: ``contacts`` step's choice, so that ``drop`` and ``keep`` share one simulation.
#: The closure does not read the search's settings (a searched placement reads its output);
#: the search does not read which target a mode uses, nor the closure model (it always
#: closes with the kinematic model, docs/placement_search.md).
_PLACEMENT_TARGETS = ("mode", "search_rank", "approach_point_mm", "center_mm")
STEP_KEYS_EXCEPT: dict[str, tuple[str, ...]] = {
    "simulate": (*_CONTACT_SELECTION, "placement.search", "objects.{object}.placement.search"),
    "search": ("closure.model", "closure.dynamic",
               *(f"{where}.{key}" for where in ("placement", "objects.{object}.placement") for key in _PLACEMENT_TARGETS)),
}
#: The steps whose outputs a step reads (its hash includes theirs): for a step run per object
#: (OBJECT_STEPS), that object's; for a step run once per scenario, every object's.
UPSTREAM: dict[str, tuple[str, ...]] = {
    "contacts": ("simulate",), "optimise": ("contacts",), "minima": ("optimise",), "tables": ("optimise", "minima"),
    "realism": ("contacts", "optimise"), "fig2": ("contacts",), "fig4": ("optimise", "minima"),
    "fig5": ("tables",)}
#: Steps whose outputs a step reads only when a key of the object's effective placement
#: has a value: the closure of a searched placement reads the search's targets.
UPSTREAM_WHEN: dict[str, tuple[tuple[str, Any, str], ...]] = {"simulate": (("mode", "searched", "search"),)}
#: Steps run once per object (the others once per scenario).
OBJECT_STEPS: frozenset[str] = frozenset({"simulate", "contacts", "optimise", "minima", "fig4", "search"})
#: Steps that read only some synergies of the synergy table: step -> the synergies (1-based)
#: it reads besides the mean posture. Their hash holds those values, not the table's name,
#: so tables that agree there (thumb readings that differ in S2…S15 only) share the step.
SYNERGY_COLUMNS_READ: dict[str, tuple[int, ...]] = {"simulate": (1,)}
#: Keys read by the workflow itself, not by a step.
WORKFLOW_KEYS: tuple[str, ...] = ("scenarios",)


def _get(config: Mapping[str, Any], path: str) -> Any:
    node: Any = config
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return _MISSING
        node = node[part]
    return node


def _put(out: dict[str, Any], path: str, value: Any) -> None:
    *parents, last = path.split(".")
    for part in parents:
        out = out.setdefault(part, {})
    out[last] = copy.deepcopy(value)


def step_keys(config: Mapping[str, Any], step: str, obj: str | None = None) -> list[str]:
    """The key paths ``step`` reads in ``config`` (for object ``obj`` where it matters)."""
    if step not in STEP_KEYS:
        raise ValueError(f"unknown step {step!r}; allowed values: {sorted(STEP_KEYS)}")
    paths = list(STEP_KEYS[step])
    for key, value, reads in STEP_KEYS_WHEN.get(step, ()):
        if _get(config, key) == value:
            paths += reads
    out = []
    for path in paths:
        if path.startswith("objects.*"):
            out += [path.replace("*", name, 1) for name in config["objects"]]
        elif "{object}" in path:
            if obj is None:
                raise ValueError(f"step {step!r} reads {path}: an object is required")
            out.append(path.format(object=obj))
        else:
            out.append(path)
    return out


def step_config(config: Mapping[str, Any], step: str, obj: str | None = None) -> dict[str, Any]:
    """The part of ``config`` that ``step`` reads, in the configuration's own shape."""
    out: dict[str, Any] = {}
    for path in step_keys(config, step, obj):
        value = _get(config, path)
        if value is not _MISSING:
            _put(out, path, value)
    for path in STEP_KEYS_EXCEPT.get(step, ()):
        if "{object}" in path:
            if obj is None:
                continue
            path = path.format(object=obj)
        *parents, last = path.split(".")
        node = _get(out, ".".join(parents))
        if isinstance(node, dict):
            node.pop(last, None)
    return out


def step_hash(config: Mapping[str, Any], step: str, obj: str | None = None) -> str:
    """Hash of what a step's outputs depend on: the keys it reads and, through
    :data:`UPSTREAM`, those of the steps before it (12 hex digits). ``obj``: the object of
    a step of :data:`OBJECT_STEPS`; None for a step run once per scenario."""
    own = step_config(config, step, obj)
    if step in SYNERGY_COLUMNS_READ:
        own["synergies"] = _synergy_digest(own.get("hand"), own["synergies"], SYNERGY_COLUMNS_READ[step])
    parts: list[Any] = [own]
    for upstream in (*UPSTREAM.get(step, ()), *step_upstream_when(config, step, obj)):
        if upstream in OBJECT_STEPS and obj is None:
            parts.append([[name, step_hash(config, upstream, name)] for name in config["objects"]])
        else:
            parts.append(step_hash(config, upstream, obj if upstream in OBJECT_STEPS else None))
    text = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def step_upstream_when(config: Mapping[str, Any], step: str, obj: str | None = None) -> tuple[str, ...]:
    """The steps ``step`` reads for ``obj`` besides :data:`UPSTREAM`, from the object's
    effective placement (:data:`UPSTREAM_WHEN`): ``search`` for a searched placement."""
    if obj is None or step not in UPSTREAM_WHEN:
        return ()
    placement = overlay(config["placement"], config["objects"][obj].get("placement"))
    return tuple(up for key, value, up in UPSTREAM_WHEN[step] if placement.get(key) == value)


@functools.cache
def _synergy_digest(hand: str | None, synergies: str | None, columns: tuple[int, ...]) -> str:
    """SHA-256 of the mean posture and the synergies ``columns`` (1-based) of a synergy table,
    as loaded for ``hand`` (the exact float64 values, rad)."""
    kinematics = importlib.import_module("synergrasp.hand.kinematics")
    loader = importlib.import_module("synergrasp.hand.synergies")
    table = loader.load_synergies(synergies, joint_names=kinematics.load_hand(hand).joint_names)
    values = np.concatenate([table.mean, table.columns(list(columns)).ravel(order="F")])
    return "sha256:" + hashlib.sha256(np.ascontiguousarray(values, dtype=np.float64).tobytes()).hexdigest()


# --------------------------------------------------------------------------- typed parameters

@dataclass(frozen=True)
class SimulateParams:
    """The closure of one object: hand and synergy files (None = shipped), the object, its
    effective placement (with the pose grid) and the closure settings."""
    hand: str | None
    synergies: str | None
    object: GraspedObject
    placement: Any  # synergrasp.simulation.placement.Placement
    closure: Any    # synergrasp.simulation.closure.ClosureParams
    mechanics: dict[str, Any] | None = None  # the mechanics block, where the closure model reads it


@dataclass(frozen=True)
class SearchStepParams:
    """The placement search of one object (docs/placement_search.md): hand and synergy files,
    the object with its mass, its effective placement, the closure settings (the search closes
    with the kinematic model), the GFO parameters, the size of the full synergy set, the
    search's settings."""
    hand: str | None
    synergies: str | None
    object: GraspedObject
    placement: Any  # synergrasp.simulation.placement.Placement
    closure: Any    # synergrasp.simulation.closure.ClosureParams
    gfo: Any        # synergrasp.optimisation.study.GFOParams
    full_set_size: int
    search: Any     # synergrasp.simulation.placement_search.SearchParams
    distinct_mm: float


@dataclass(frozen=True)
class OptimiseParams:
    """The optimisation of one object: synergy file, the study's synergy sets by id, the
    GFO parameters (mechanics and the object's weight) and the number of pose shards."""
    synergies: str | None
    sets: dict[str, tuple[int, ...]]
    gfo: Any  # synergrasp.optimisation.study.GFOParams
    pose_shards: int


@dataclass(frozen=True)
class MinimaParams:
    """Local minima of one object: neighbourhood radius (deg), the success verdict and, for
    ``force_closure_bounded``, the object's weight (N) and the bound's multiple of it."""
    radius_deg: float
    success: str
    weight_N: float | None = None
    bound_multiple: float = math.inf


def _force_bound(config: Mapping[str, Any], obj: str | None) -> dict[str, Any]:
    """weight_N and bound_multiple of ``obj`` where the verdict is force_closure_bounded."""
    analyses = config["analyses"]
    if analyses["success"] != "force_closure_bounded":
        return {}
    weight = float(config["objects"][obj]["mass_kg"]) * float(config["mechanics"]["g_m_per_s2"])
    return {"weight_N": weight, "bound_multiple": float(analyses["marginal_weight_multiple"])}


@dataclass(frozen=True)
class TablesParams:
    """The study's tables: the synergy-set bounds, Table II's k_max and the analysis settings."""
    synergy_sets: dict[str, int]
    table2_k_max: int
    settings: Any  # synergrasp.analysis.summaries.AnalysisSettings


@dataclass(frozen=True)
class ContactsParams:
    """Which contacts of a closure count. ``drop_unloaded``: keep only the contacts carrying
    at least ``load_threshold_N`` (N); only the dynamic model records loads (None otherwise)."""
    drop_unloaded: bool
    load_threshold_N: float | None


@dataclass(frozen=True)
class RealismParams:
    """The grasp-realism table: hand file, the full set's id, each object's weight (N), and
    the least normal force (N) of a load-carrying contact (None: the model records no loads)."""
    hand: str | None
    full_set_id: str
    weights_N: dict[str, float]
    load_threshold_N: float | None


@dataclass(frozen=True)
class FiguresParams:
    """Parameters of the figures (each figure's rule is given its own keys only)."""
    hand: str | None = None
    synergies: str | None = None
    objects: tuple = ()  # GraspedObject
    success: str = ""
    fig4_panel_k: tuple[int, ...] = ()
    fig4_alpha_slice_deg: float = math.nan
    fig4_beta_slice_deg: float = math.nan
    hierarchy_first: int = 0
    weight_N: float | None = None
    bound_multiple: float = math.inf


#: Modules holding the typed parameter classes a step's parameters are built from (the
#: step's script imports them itself; tests/test_config.py checks it).
STEP_MODULES: dict[str, tuple[str, ...]] = {
    "simulate": ("synergrasp.simulation.closure", "synergrasp.simulation.placement"),
    "search": ("synergrasp.simulation.closure", "synergrasp.simulation.placement_search",
               "synergrasp.optimisation.study"),
    "optimise": ("synergrasp.optimisation.study",),
    "tables": ("synergrasp.analysis.summaries", "synergrasp.analysis.periods", "synergrasp.analysis.bootstrap",
               "synergrasp.analysis.claims"),
}

def _build(cls: Any, where: str, **kwargs: Any) -> Any:
    """``cls(**kwargs)``; a rejected value becomes a ConfigError naming the config key."""
    try:
        return cls(**kwargs)
    except (TypeError, ValueError) as err:
        message = str(err).replace(f"{cls.__name__}.", f"{where}.")
        raise ConfigError(f"config error at '{where}': {message}") from None


def _object(config: Mapping[str, Any], name: str) -> GraspedObject:
    """The object ``name``; its mass is None where the step does not read it."""
    spec = config["objects"][name]
    try:
        shape = shape_from_config(spec["shape"], f"objects.{name}.shape")
    except ShapeError as err:
        raise ConfigError(f"config error at {err}") from None
    return _build(GraspedObject, f"objects.{name}", name=name, shape=shape, mass_kg=spec.get("mass_kg"))


def placement_params(placement: Mapping[str, Any], grid: Mapping[str, Any]) -> Any:
    """The :class:`synergrasp.simulation.placement.Placement` of an effective ``placement``
    block (the global one with an object's override laid over it) and the ``grid`` block."""
    placing = importlib.import_module("synergrasp.simulation.placement")
    ranges = {k: (v["start"], v["stop"], v["step"]) for k, v in grid.items()}
    return _build(placing.Placement, "placement", **_fields(placing.Placement, {**placement, **ranges}))


def _simulate(config: Mapping[str, Any], obj: str) -> SimulateParams:
    closure = importlib.import_module("synergrasp.simulation.closure")
    placement = overlay(config["placement"], config["objects"][obj].get("placement"))
    return SimulateParams(
        hand=config["hand"], synergies=config["synergies"], object=_object(config, obj),
        placement=placement_params(placement, config["grid"]),
        closure=_build(closure.ClosureParams, "closure", **{
            **_fields(closure.ClosureParams, config["closure"]),
            "dynamic": closure.DynamicParams(**config["closure"]["dynamic"])}),
        mechanics=config.get("mechanics"))


def _search(config: Mapping[str, Any], obj: str) -> SearchStepParams:
    closure = importlib.import_module("synergrasp.simulation.closure")
    searching = importlib.import_module("synergrasp.simulation.placement_search")
    gfo = importlib.import_module("synergrasp.optimisation.study")
    placement = overlay(config["placement"], config["objects"][obj].get("placement"))
    spec = placement["search"]
    region = tuple(tuple(spec["region_mm"][axis]) for axis in ("x", "y", "z"))
    search = _build(searching.SearchParams, "placement.search", region_mm=region, **_fields(
        searching.SearchParams, {k: v for k, v in spec.items() if k != "region_mm"}))
    dynamic = config["closure"].get("dynamic")
    return SearchStepParams(
        hand=config["hand"], synergies=config["synergies"], object=_object(config, obj),
        # the search places the box toward each of its targets: the modes' own targets are not read
        placement=placement_params({**placement, "mode": "searched", "approach_point_mm": None,
                                    "center_mm": (0.0, 0.0, 0.0)}, config["grid"]),
        closure=_build(closure.ClosureParams, "closure", **{
            **_fields(closure.ClosureParams, {**config["closure"], "model": "kinematic"}),
            "dynamic": closure.DynamicParams(**dynamic) if dynamic else None}),
        gfo=_build(gfo.GFOParams, "mechanics", **_fields(gfo.GFOParams, config["mechanics"]),
                   mass_kg=float(config["objects"][obj]["mass_kg"])),
        full_set_size=int(config["synergy_sets"]["incremental_max"]), search=search,
        distinct_mm=float(spec["distinct_mm"]))


def _fields(cls: Any, values: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``values`` that are fields of the dataclass ``cls``, lists as tuples."""
    names = set(cls.__dataclass_fields__)
    return {k: tuple(v) if isinstance(v, list) else v for k, v in values.items() if k in names}


def _optimise(config: Mapping[str, Any], obj: str) -> OptimiseParams:
    gfo = importlib.import_module("synergrasp.optimisation.study")
    params = _build(gfo.GFOParams, "mechanics", **_fields(gfo.GFOParams, config["mechanics"]),
                    mass_kg=float(config["objects"][obj]["mass_kg"]))
    return OptimiseParams(config["synergies"], synergy_sets(config["synergy_sets"]), params,
                          int(config["solver"]["pose_shards"]))


def _tables(config: Mapping[str, Any]) -> TablesParams:
    summaries = importlib.import_module("synergrasp.analysis.summaries")
    periods = importlib.import_module("synergrasp.analysis.periods")
    bootstrap = importlib.import_module("synergrasp.analysis.bootstrap")
    claims = importlib.import_module("synergrasp.analysis.claims")
    analyses, g = config["analyses"], config["mechanics"]["g_m_per_s2"]
    objects = {name: {**spec, "placement": overlay(config["placement"], spec.get("placement"))}
               for name, spec in config["objects"].items()}
    try:
        periods_deg = periods.object_periods(objects, config["grid"], config["hand"])
    except (TypeError, ValueError) as err:
        raise ConfigError(f"config error at 'objects' / 'placement': {err}") from None
    settings = summaries.AnalysisSettings(
        success=analyses["success"], marginal_weight_multiple=float(analyses["marginal_weight_multiple"]),
        radius_deg=float(analyses["minima_radius_deg"]), null_draws=int(analyses["null_model"]["draws"]),
        null_seed=int(analyses["null_model"]["seed"]),
        success_rate_tolerance_percent=float(analyses["success_rate_tolerance_percent"]),
        bootstrap=_build(bootstrap.BootstrapSettings, "analyses.bootstrap", **analyses["bootstrap"]),
        rules=_build(claims.VerdictRules, "analyses", rate_points=float(analyses["tie_band"]["rate_points"]),
                     force_relative=float(analyses["tie_band"]["force_relative"]),
                     min_distinct_poses=int(analyses["min_distinct_poses"]), headline_view=analyses["headline_view"]),
        weights_N={name: float(spec["mass_kg"]) * float(g) for name, spec in objects.items()},
        periods_deg=periods_deg)
    return TablesParams(dict(config["synergy_sets"]), int(analyses["table2_k_max"]), settings)


def _figures(config: Mapping[str, Any], step: str, obj: str | None = None) -> FiguresParams:
    if step == "fig1":
        return FiguresParams(hand=config["hand"], synergies=config["synergies"])
    if step == "fig2":
        return FiguresParams(hand=config["hand"], objects=tuple(_object(config, n) for n in config["objects"]))
    success = config["analyses"]["success"]
    if step == "fig4":
        fig4 = config["analyses"]["fig4"]
        return FiguresParams(success=success, fig4_panel_k=tuple(fig4["panel_k"]),
                             fig4_alpha_slice_deg=fig4["alpha_slice_deg"], fig4_beta_slice_deg=fig4["beta_slice_deg"],
                             **_force_bound(config, obj))
    return FiguresParams(success=success, hierarchy_first=config["synergy_sets"]["hierarchy_first"])


def step_params(config: Mapping[str, Any], step: str, obj: str | None = None) -> Any:
    """The typed parameters of ``step`` (for object ``obj`` where it has one), from a
    complete configuration or from the step's own part of it (:func:`step_config`).

    The one path from configuration to the parameters of every module: ``simulate`` →
    :class:`SimulateParams`, ``contacts`` → :class:`ContactsParams`, ``optimise`` → :class:`OptimiseParams`, ``minima`` →
    :class:`MinimaParams`, ``tables`` → :class:`TablesParams`, ``realism`` →
    :class:`RealismParams`, ``fig1``/``fig2``/``fig4``/
    ``fig5`` → :class:`FiguresParams`. A value a typed class rejects raises ConfigError
    naming the config key (not the class's field). Only the keys the step reads
    (:data:`STEP_KEYS`) are used, so its parameters cannot depend on any other.
    """
    config = step_config(config, step, obj)
    if step == "simulate":
        return _simulate(config, obj)
    if step == "search":
        return _search(config, obj)
    if step == "contacts":
        dynamic = config["closure"].get("dynamic", {})
        return ContactsParams(dynamic.get("unloaded_contacts") == "drop", dynamic.get("load_threshold_N"))
    if step == "optimise":
        return _optimise(config, obj)
    if step == "minima":
        return MinimaParams(float(config["analyses"]["minima_radius_deg"]), config["analyses"]["success"],
                            **_force_bound(config, obj))
    if step == "tables":
        return _tables(config)
    if step == "realism":
        g = config["mechanics"]["g_m_per_s2"]
        return RealismParams(config["hand"], incremental_set_id(config["synergy_sets"]["incremental_max"]),
                             {name: spec["mass_kg"] * g for name, spec in config["objects"].items()},
                             config.get("closure", {}).get("dynamic", {}).get("load_threshold_N"))
    if step in ("fig1", "fig2", "fig4", "fig5"):
        return _figures(config, step, obj)
    raise ValueError(f"unknown step {step!r}; allowed values: {sorted(STEP_KEYS)}")


# --------------------------------------------------------------------------- synergy sets

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
