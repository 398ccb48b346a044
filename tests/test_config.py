"""The one config model: defaults from the schema, the overlay rule, every check before any
job (one message naming the key) and scenarios."""

import copy
import math
from pathlib import Path

import pytest
import yaml
from conftest import scenario_configs, schema_leaf_paths

from synergrasp.config import (
    ConfigError,
    defaults,
    overlay,
    scenario_names,
    validate_config,
)

ROOT = Path(__file__).resolve().parents[1]
STUDY = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SMALL = yaml.safe_load((ROOT / "tests" / "config" / "small.yaml").read_text())


# --------------------------------------------------------------------------- typed parameters


@pytest.mark.parametrize("config", [STUDY, SMALL], ids=["study", "small"])
def test_shipped_configs_are_valid(config):
    validate_config(config, n_synergies=15)


def test_defaults_live_in_the_schema_and_are_the_study():
    # config/config.yaml spells the study out; it must be exactly the schema's defaults
    assert validate_config(STUDY) == defaults()
    assert validate_config({}) == defaults()


def test_study_config_holds_the_papers_parameters():
    study = defaults()
    assert study["mechanics"]["mu"] == 1.5
    assert study["mechanics"]["f_min_N"] == 0.1
    assert study["mechanics"]["k_stru_N_per_mm"] == 1.0
    assert study["mechanics"]["k_ss_Nmm_per_rad"] == 200.0
    sizes = {name: spec["shape"]["box"]["size_mm"] for name, spec in study["objects"].items()}
    assert sizes == {"obj1": [30, 30, 30], "obj2": [30, 60, 60], "obj3": [60, 60, 60], "obj4": [100, 60, 100]}
    alpha, beta = study["grid"]["alpha_deg"], study["grid"]["beta_deg"]
    n_alpha = (alpha["stop"] - alpha["start"]) / alpha["step"] + 1
    n_beta = (beta["stop"] - beta["start"]) / beta["step"] + 1
    assert n_alpha * n_beta == 1800


def test_a_left_out_key_takes_its_default_and_an_object_keeps_only_its_own_override():
    config = copy.deepcopy(SMALL)
    del config["closure"]["step_mm"], config["mechanics"]
    full = validate_config(config)
    assert full["closure"]["step_mm"] == 8.0 and full["mechanics"] == defaults()["mechanics"]
    assert "placement" not in full["objects"]["obj1"]


_DELETE = object()


def _broken(path, value, config=SMALL):
    config = copy.deepcopy(config)
    node = config
    for key in path[:-1]:
        node = node.setdefault(key, {})
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return config


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        (("mechanics", "muu"), 1.5, "'mechanics': unknown key(s) ['muu']"),
        (("mechanics", "mu"), "high", "'mechanics.mu': 'high' is not of type 'number'"),
        (("mechanics", "mu"), -1.0, "'mechanics.mu'"),
        (("objects", "obj1", "shape", "box", "size_mm"), [30, -1, 30], "'objects.obj1.shape.box.size_mm[1]'"),
        (("objects", "obj1", "shape"), {"cone": {"size_mm": [1, 2, 3]}}, "'objects.obj1.shape': unknown key(s) ['cone']"),
        (("objects", "obj1", "size_mm"), [30, 30, 30], "'objects.obj1': unknown key(s) ['size_mm']"),
        (("objects", "obj1", "mass_kg"), 0, "'objects.obj1.mass_kg'"),
        (("objects", "obj1", "mass_kg"), _DELETE, "'objects.obj1': 'mass_kg' is a required property"),
        (("solver", "method"), "newton", "'solver': unknown key(s) ['method']"),
        (("analyses", "fig4", "object"), "obj4", "'analyses.fig4': unknown key(s) ['object']"),
        (("placement", "rotation_order"), "any", "allowed values: ['alpha_then_beta', 'beta_then_alpha']"),
        (("closure", "sigma_closed"), 3.0, "'closure': unknown key(s) ['sigma_closed']"),
        (("mechanics", "gravity_direction"), [0, 0, 0], "'mechanics.gravity_direction'"),
        (("synergy_sets", "incremental_max"), 16, "exceeds the 15 synergies"),
        (("hand",), "", "'hand': '' should be non-empty"),
        # issue 12, defect 1: relations between values, before any job
        (
            ("grid", "alpha_deg"),
            {"start": -180, "stop": 150, "step": 25},
            "'grid.alpha_deg.step': 25 does not divide stop - start (330)",
        ),
        (("grid", "beta_deg"), {"start": 60, "stop": -60, "step": 20}, "'grid.beta_deg.stop': -60 is below start"),
        (("grid", "alpha_deg"), {"start": -180, "stop": 180, "step": 30}, "'grid.alpha_deg': alpha is periodic"),
        (("closure", "contact_distance_mm"), 0.1, "'closure.contact_distance_mm': 0.1 must be at least closure.tolerance_mm"),
        (("closure", "step_mm"), 0.2, "'closure.step_mm': 0.2 must exceed closure.tolerance_mm (0.2)"),
        (("analyses", "fig4", "alpha_slice_deg"), -35, "'analyses.fig4.alpha_slice_deg': -35 is not on grid.alpha_deg"),
        (("analyses", "fig4", "beta_slice_deg"), 10, "'analyses.fig4.beta_slice_deg': 10 is not on grid.beta_deg"),
        (("analyses", "table2_k_max"), 16, "'analyses.table2_k_max': 16 exceeds synergy_sets.incremental_max (15)"),
        (("synergy_sets", "hierarchy_max_size"), 5, "'synergy_sets.hierarchy_max_size': 5 exceeds"),
        # defect 2: the tables compare {S1..Sk} with {S1..Sk+1}
        (("synergy_sets", "incremental_max"), 1, "'synergy_sets.incremental_max': 1 is less than the minimum of 2"),
        # defect 12: more shards than poses (12 x 7 = 84 poses in the small config)
        (("solver", "pose_shards"), 85, "'solver.pose_shards': 85 exceeds the 84 poses of the grid; allowed values: 1..84"),
        # defect 7: a fractional number where an integer is expected
        (("solver", "pose_shards"), 2.5, "'solver.pose_shards': 2.5 is not of type 'integer'"),
        # issue 48, kind 8: a value matching no form of a oneOf names the closest form's error
        (
            ("placement", "search", "region_mm", "power"),
            {"x": [0, 10, 20], "y": [0, 10], "z": [0, 10]},
            "config error at 'placement.search.region_mm.power.x': [0, 10, 20] is too long",
        ),
        (
            ("placement", "search", "region_mm", "power"),
            {"x": [0, 10], "y": [0, 10]},
            "config error at 'placement.search.region_mm.power': 'z' is a required property",
        ),
        (
            ("placement", "search", "region_mm", "power"),
            "hands",
            "config error at 'placement.search.region_mm.power': 'hands' is not allowed; allowed values: ['hand']",
        ),
    ],
)
def test_bad_values_name_the_key(path, value, expected):
    with pytest.raises(ConfigError) as info:
        validate_config(_broken(path, value), n_synergies=15)
    assert expected in str(info.value)


@pytest.mark.parametrize(
    "path",
    [
        ("mechanics", "mu"),
        ("closure", "step_mm"),
        ("grid", "alpha_deg", "step"),
        ("analyses", "minima_radius_deg"),
        ("objects", "obj1", "mass_kg"),
    ],
)
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_nan_and_inf_are_rejected_wherever_a_number_is_expected(path, value):
    with pytest.raises(
        ConfigError,
        match=rf"config error at '{'.'.join(path)}': {value} is not allowed; "
        "a finite number is required",
    ):
        validate_config(_broken(path, value))


def test_nan_inside_a_list_names_its_index():
    with pytest.raises(ConfigError, match=r"'mechanics.gravity_direction\[1\]': nan"):
        validate_config(_broken(("mechanics", "gravity_direction"), [1.0, math.nan, 0.0]))


def test_whole_number_floats_are_accepted_as_integers():
    config = _broken(("solver", "pose_shards"), 2.0)
    config["synergy_sets"]["incremental_max"] = 15.0
    full = validate_config(config)
    assert full["solver"]["pose_shards"] == 2 and type(full["solver"]["pose_shards"]) is int
    assert type(full["synergy_sets"]["incremental_max"]) is int
    assert list(range(full["solver"]["pose_shards"])) == [0, 1]


@pytest.mark.parametrize("name", [1, None, 2.5, True])
def test_non_text_object_names_are_rejected_clearly(name):
    config = copy.deepcopy(SMALL)
    config["objects"][name] = config["objects"]["obj1"]
    with pytest.raises(ConfigError, match=rf"config error at 'objects': name {name!r} .* is not allowed; names are text"):
        validate_config(config)


def test_object_name_characters_are_checked():
    config = copy.deepcopy(SMALL)
    config["objects"]["bad name"] = config["objects"].pop("obj1")
    with pytest.raises(ConfigError, match="'objects'.*'bad name'"):
        validate_config(config)


def test_every_problem_is_reported_at_once():
    config = _broken(("closure", "step_mm"), 0.1)
    config["closure"]["contact_distance_mm"] = 0.1
    lines = str(pytest.raises(ConfigError, validate_config, config).value).splitlines()
    assert len(lines) == 2 and all(line.startswith("config error at 'closure.") for line in lines)


# ----------------------------------------------------------------------------- overlays


def test_overlay_merges_mappings_replaces_other_values_and_null_removes():
    base = {"a": {"x": 1, "y": [1, 2]}, "b": 2, "c": {"z": 3}}
    assert overlay(base, {"a": {"y": [3]}, "b": None, "c": 5}) == {"a": {"x": 1, "y": [3]}, "c": 5}
    assert base == {"a": {"x": 1, "y": [1, 2]}, "b": 2, "c": {"z": 3}}  # unchanged


def test_a_user_file_can_drop_an_object_and_reset_a_key_with_null():
    # what Snakemake hands over after `--configfile my.yaml` merged my.yaml into config.yaml
    merged = _broken(("objects", "obj4"), None)
    merged["closure"]["step_mm"] = None
    full = validate_config(merged)
    assert list(full["objects"]) == ["obj1"]
    assert full["closure"]["step_mm"] == defaults()["closure"]["step_mm"]


# ----------------------------------------------------------------------------- scenarios


def _with_scenarios(scenarios):
    return {**copy.deepcopy(SMALL), "scenarios": scenarios}


def test_scenarios_are_overlays_of_the_main_config():
    configs = scenario_configs(
        _with_scenarios(
            {
                "mu1": {"mechanics": {"mu": 1.0}},
                "one_object": {"objects": {"obj4": None}},
            }
        )
    )
    assert list(configs) == ["default", "mu1", "one_object"]
    assert configs["mu1"]["mechanics"]["mu"] == 1.0 and configs["default"]["mechanics"]["mu"] == 1.5
    assert configs["mu1"]["mechanics"]["f_min_N"] == 0.1
    assert list(configs["one_object"]["objects"]) == ["obj1"]
    assert configs["default"] == {**validate_config(SMALL)}


def test_a_scenario_set_to_null_by_an_overlay_is_removed():
    """`--configfile` with `scenarios: {mu1: null}` runs the sweep without mu1 (the overlay rule)."""
    merged = _with_scenarios({"mu1": None, "kss": {"mechanics": {"k_ss_Nmm_per_rad": 100.0}}})
    assert scenario_names(merged) == ["default", "kss"]
    assert list(scenario_configs(merged)) == ["default", "kss"]
    assert list(validate_config(merged)["scenarios"]) == ["kss"]


@pytest.mark.parametrize(
    "scenarios, expected",
    [
        ({"s1": {"mechanics": {"muu": 1.0}}}, "scenario 's1': config error at 'mechanics': unknown key(s) ['muu']"),
        ({"s1": {"closure": {"step_mm": math.nan}}}, "scenario 's1': config error at 'closure.step_mm': nan"),
        ({"s1": {"grid": {"alpha_deg": {"step": 25}}}}, "scenario 's1': config error at 'grid.alpha_deg.step'"),
        ({"s1": {"scenarios": {"s2": {}}}}, "scenario 's1': config error at 'scenarios'"),
        ({"default": {"mechanics": {"mu": 1.0}}}, "config error at 'scenarios': name 'default' is not allowed"),
        ({"a b": {}}, "config error at 'scenarios': name 'a b' is not allowed"),
        ({"s1": 3}, "config error at 'scenarios.s1': 3 is not of type 'object'"),
        (
            {"s1": {"random_objects": {"n_objects": 3}}},
            "scenario 's1': config error at 'scenarios.s1.random_objects': a scenario cannot draw objects of its own",
        ),
    ],
)
def test_a_bad_scenario_names_the_scenario_and_the_key(scenarios, expected):
    with pytest.raises(ConfigError) as info:
        scenario_configs(_with_scenarios(scenarios))
    assert expected in str(info.value)


# ----------------------------------------------------------------------------- steps


def test_every_key_of_the_schema_is_described_in_config_readme():
    text = (ROOT / "config" / "README.md").read_text()

    def documented(path):  # the key itself or the block it belongs to has a row
        parts = path.replace("objects.*.", "objects.<name>.").split(".")
        return any(f"| `{'.'.join(parts[:n])}` |" in text for n in range(len(parts), 0, -1))

    missing = [p for p in schema_leaf_paths() if not documented(p)]
    assert missing == []


# ----------------------------------------------------------------------------- the workflow's view


def test_a_synergy_table_that_cannot_close_the_hand_or_is_not_in_rad_is_named():
    from synergrasp.config import synergy_problems

    config = validate_config(SMALL)
    mean, matrix = [0.1, 0.2], [[0.5, 0.1], [0.2, 0.0]]
    assert synergy_problems(config, mean, matrix) == []
    zero_s1 = synergy_problems(config, mean, [[0.0, 0.1], [0.0, 0.0]])
    assert zero_s1 == [
        "config error at 'synergies' (the shipped table): S1 is zero for every joint; closing along S1 would move no joint"
    ]
    degrees = synergy_problems({**config, "synergies": "mine.csv"}, [10.0, 45.0], matrix)
    assert len(degrees) == 1 and "'synergies' (mine.csv): values up to 45 exceed 2π" in degrees[0]
    assert "exceed 2π" in synergy_problems(config, mean, [[1e300, 0.1], [0.2, 0.0]])[0]


def test_config_readme_defaults_are_the_schemas():
    """Every `| `key` | `value` | ...` row of config/README.md gives the schema's default."""
    import re

    full = defaults()
    text = (ROOT / "config" / "README.md").read_text()
    rows = re.findall(r"^\| `([a-z_.0-9]+)` \| `([^`|]*)` \|", text, flags=re.MULTILINE)
    checked = []
    for key, shown in rows:
        node = full
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                break
            node = node[part]
        else:
            value = yaml.safe_load(shown)
            assert value == node or (isinstance(node, (list, tuple)) and list(node) == value), (key, shown, node)
            checked.append(key)
    assert len(checked) > 20
