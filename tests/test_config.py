"""The one config model: defaults from the schema, the overlay rule, every check before any
job (one message naming the key), scenarios, and the keys each step reads."""
import ast
import copy
import math
from pathlib import Path

import pytest
import yaml

from synergrasp.config import (
    STEP_KEYS,
    STEP_KEYS_WHEN,
    STEP_MODULES,
    WORKFLOW_KEYS,
    ConfigError,
    _resolve,
    defaults,
    load_schema,
    overlay,
    scenario_configs,
    set_id,
    step_config,
    step_hash,
    step_params,
    synergy_sets,
    validate_config,
)

ROOT = Path(__file__).resolve().parents[1]
STUDY = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SMALL = yaml.safe_load((ROOT / "tests" / "config" / "small.yaml").read_text())


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
        (("grid", "alpha_deg"), {"start": -180, "stop": 150, "step": 25},
         "'grid.alpha_deg.step': 25 does not divide stop - start (330)"),
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
    ],
)
def test_bad_values_name_the_key(path, value, expected):
    with pytest.raises(ConfigError) as info:
        validate_config(_broken(path, value), n_synergies=15)
    assert expected in str(info.value)


@pytest.mark.parametrize("path", [("mechanics", "mu"), ("closure", "step_mm"), ("grid", "alpha_deg", "step"),
                                  ("analyses", "minima_radius_deg"), ("objects", "obj1", "mass_kg")])
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_nan_and_inf_are_rejected_wherever_a_number_is_expected(path, value):
    with pytest.raises(ConfigError, match=rf"config error at '{'.'.join(path)}': {value} is not allowed; "
                                          "a finite number is required"):
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
    configs = scenario_configs(_with_scenarios({
        "mu1": {"mechanics": {"mu": 1.0}},
        "one_object": {"objects": {"obj4": None}},
    }))
    assert list(configs) == ["default", "mu1", "one_object"]
    assert configs["mu1"]["mechanics"]["mu"] == 1.0 and configs["default"]["mechanics"]["mu"] == 1.5
    assert configs["mu1"]["mechanics"]["f_min_N"] == 0.1
    assert list(configs["one_object"]["objects"]) == ["obj1"]
    assert configs["default"] == {**validate_config(SMALL)}


@pytest.mark.parametrize("scenarios, expected", [
    ({"s1": {"mechanics": {"muu": 1.0}}}, "scenario 's1': config error at 'mechanics': unknown key(s) ['muu']"),
    ({"s1": {"closure": {"step_mm": math.nan}}}, "scenario 's1': config error at 'closure.step_mm': nan"),
    ({"s1": {"grid": {"alpha_deg": {"step": 25}}}}, "scenario 's1': config error at 'grid.alpha_deg.step'"),
    ({"s1": {"scenarios": {"s2": {}}}}, "scenario 's1': config error at 'scenarios'"),
    ({"default": {"mechanics": {"mu": 1.0}}}, "config error at 'scenarios': name 'default' is not allowed"),
    ({"a b": {}}, "config error at 'scenarios': name 'a b' is not allowed"),
    ({"s1": 3}, "config error at 'scenarios.s1': 3 is not of type 'object'"),
])
def test_a_bad_scenario_names_the_scenario_and_the_key(scenarios, expected):
    with pytest.raises(ConfigError) as info:
        scenario_configs(_with_scenarios(scenarios))
    assert expected in str(info.value)


# ----------------------------------------------------------------------------- steps


def _leaf_paths(node, prefix=""):
    """Every key path of the schema, objects' own keys as objects.*.<key>."""
    schema = _resolve(node)
    props = schema.get("properties", {})
    extra = schema.get("additionalProperties")
    if not props and isinstance(extra, dict) and _resolve(extra).get("properties"):
        return _leaf_paths(extra, f"{prefix}*.")
    if not props:
        return [prefix.rstrip(".")]
    return [p for name, sub in props.items() for p in _leaf_paths(sub, f"{prefix}{name}.")]


def _read_by(path, steps_keys):
    parts = path.split(".")
    for key in steps_keys:
        key_parts = key.replace("{object}", "*").split(".")
        if parts[:len(key_parts)] == key_parts:
            return True
    return False


def test_every_key_of_the_schema_is_read_by_a_step_or_by_the_workflow():
    keys = [k for v in STEP_KEYS.values() for k in v] + list(WORKFLOW_KEYS)
    unread = [p for p in _leaf_paths(load_schema()) if not _read_by(p, keys)]
    assert unread == []


def test_the_closure_does_not_rerun_when_an_object_mass_changes():
    heavier = _broken(("objects", "obj1", "mass_kg"), 2.0, STUDY)
    full, changed = validate_config(STUDY), validate_config(heavier)
    assert step_config(full, "simulate", "obj1") == step_config(changed, "simulate", "obj1")
    assert step_hash(full, "simulate", "obj1") == step_hash(changed, "simulate", "obj1")
    assert step_hash(full, "optimise", "obj1") != step_hash(changed, "optimise", "obj1")
    assert step_hash(full, "optimise", "obj2") == step_hash(changed, "optimise", "obj2")


def test_a_conditional_key_is_read_only_when_its_condition_holds():
    (key, value, reads), = STEP_KEYS_WHEN["simulate"]
    config = validate_config(STUDY)
    node = config
    for part in key.split(".")[:-1]:
        node = node[part]
    node[key.split(".")[-1]] = value  # e.g. closure.model = dynamic (not validated here)
    assert "mass_kg" in step_config(config, "simulate", "obj1")["objects"]["obj1"]


def test_an_analysis_key_leaves_simulation_and_optimisation_shared():
    wider = validate_config(_broken(("analyses", "minima_radius_deg"), 20, STUDY))
    full = validate_config(STUDY)
    for step in ("simulate", "optimise"):
        assert step_hash(full, step, "obj1") == step_hash(wider, step, "obj1")
    assert step_hash(full, "minima", "obj1") != step_hash(wider, "minima", "obj1")


def test_a_step_hash_follows_its_upstream_step():
    other_grid = validate_config(_broken(("grid", "beta_deg", "step"), 10, STUDY))
    full = validate_config(STUDY)
    assert step_config(full, "optimise", "obj1") == step_config(other_grid, "optimise", "obj1")
    assert step_hash(full, "optimise", "obj1") != step_hash(other_grid, "optimise", "obj1")


def test_a_scenario_wide_step_hash_follows_every_objects_upstream_step():
    """Fig. 1 reads no step's output; the tables read every object's minima; Fig. 5 the tables;
    Fig. 2 every object's contacts, which a heavier obj1 leaves alone."""
    full = validate_config(STUDY)
    wider = validate_config(_broken(("analyses", "minima_radius_deg"), 20, STUDY))
    heavier = validate_config(_broken(("objects", "obj1", "mass_kg"), 2.0, STUDY))
    assert step_config(full, "tables") != step_config(wider, "tables")  # reads the radius itself
    assert step_config(full, "fig5") == step_config(wider, "fig5")
    assert step_hash(full, "fig5") != step_hash(wider, "fig5")  # through the tables
    for step in ("fig1", "fig2", "realism"):
        assert step_hash(full, step) == step_hash(wider, step), step
    assert step_hash(full, "fig2") == step_hash(heavier, "fig2")
    assert step_config(full, "fig4", "obj2") == step_config(heavier, "fig4", "obj2")
    assert step_hash(full, "fig4", "obj1") != step_hash(heavier, "fig4", "obj1")  # its optimisation
    assert step_hash(full, "fig4", "obj2") == step_hash(heavier, "fig4", "obj2")


def test_step_params_are_built_from_the_steps_own_keys_only():
    full = validate_config(STUDY)
    for step in STEP_KEYS:
        obj = "obj4" if step in ("simulate", "optimise", "search") else None
        assert step_params(full, step, obj) == step_params(step_config(full, step, obj), step, obj)
    sim = step_params(step_config(full, "simulate", "obj4"), "simulate", "obj4")
    assert sim.placement.mode == "approach" and sim.placement.box_axes == (1, 0, 2)
    assert sim.placement.alpha_deg == (-180.0, 175.0, 5.0)
    assert sim.closure.step_mm == 8.0 and sim.object.mass_kg is None


def test_optimise_params_keep_the_mechanics_and_the_objects_weight():
    config = validate_config(_broken(("mechanics", "gravity_direction"), [0.0, 0.0, -2.0], STUDY))
    config["objects"]["obj1"]["mass_kg"] = 0.5
    params = step_params(config, "optimise", "obj1")
    gfo = params.gfo
    assert gfo.gravity_direction == (0.0, 0.0, -1.0)
    assert (gfo.mu, gfo.f_min_N, gfo.k_stru_N_per_mm, gfo.k_ss_Nmm_per_rad, gfo.g_m_per_s2) == (1.5, 0.1, 1.0, 200.0, 9.81)
    assert gfo.wrench()[2] == pytest.approx(0.5 * 9.81)  # the contacts hold the weight: +z
    assert len(params.sets) == 75 and params.pose_shards == 1
    assert gfo.friction_cone == "circular"
    pyramid = validate_config(_broken(("mechanics", "friction_cone"), "pyramid8_circumscribed", STUDY))
    assert step_params(pyramid, "optimise", "obj1").gfo.cone.kind == "pyramid"
    with pytest.raises(ConfigError, match=r"mechanics.friction_cone.*allowed values: \['circular', 'pyramid4_inscribed'"):
        validate_config(_broken(("mechanics", "friction_cone"), "pyramid6", STUDY))


def test_errors_of_the_typed_parameters_name_the_config_key():
    # a job is handed only checked values (each checked once, by the schema and
    # check_relations); what a typed class must still refuse names the config key
    config = _broken(("mechanics", "gravity_direction"), [0.0, 0.0, 0.0], defaults())
    with pytest.raises(ConfigError, match="config error at 'mechanics'"):
        step_params(config, "optimise", "obj1")


def _imports(path):
    found = set()
    for node in ast.walk(ast.parse(Path(path).read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return found


@pytest.mark.parametrize("step, script", [("simulate", "simulate_contacts"), ("optimise", "optimise_shard")])
def test_a_steps_script_imports_the_modules_its_parameters_come_from(step, script):
    # so the rule's code inputs (derived from the script's imports) cover them
    todo, seen = [ROOT / "workflow" / "scripts" / f"{script}.py"], set()
    while todo:
        for name in _imports(todo.pop()) - seen:
            if name.startswith("synergrasp"):
                seen.add(name)
                path = ROOT / "src" / Path(*name.split(".")).with_suffix(".py")
                if path.is_file():
                    todo.append(path)
    assert set(STEP_MODULES[step]) <= seen


def test_study_synergy_sets_are_the_75_distinct_sets():
    sets = synergy_sets(defaults()["synergy_sets"])
    # 15 incremental + (7 + 21 + 35) hierarchy - 3 shared ({S1}, {S1,S2}, {S1,S2,S3})
    assert len(sets) == 15 + 63 - 3
    assert sets["1-2-3"] == (1, 2, 3)
    assert "2-5-7" in sets and "1-2-3-4-5-6-7-8-9-10-11-12-13-14-15" in sets
    assert all(set_id(v) == k for k, v in sets.items())


def test_every_key_of_the_schema_is_described_in_config_readme():
    text = (ROOT / "config" / "README.md").read_text()
    def documented(path):  # the key itself or the block it belongs to has a row
        parts = path.replace("objects.*.", "objects.<name>.").split(".")
        return any(f"| `{'.'.join(parts[:n])}` |" in text for n in range(len(parts), 0, -1))
    missing = [p for p in _leaf_paths(load_schema()) if not documented(p)]
    assert missing == []


# ----------------------------------------------------------------------------- the workflow's view


def _dry_run(tmp_path, target, scenarios):
    """``snakemake -n target`` on the small config with ``scenarios``: (return code, output,
    {rule: [output files]} of the jobs it would run)."""
    import subprocess
    import sys

    config = tmp_path / "config.yaml"
    config.write_text(yaml.safe_dump({**SMALL, "scenarios": scenarios}))
    run = subprocess.run([sys.executable, "-m", "snakemake", target, "-n", "-s", str(ROOT / "Snakefile"),
                          "--directory", str(tmp_path), "--configfile", str(config),
                          "--replace-workflow-config"], capture_output=True, text=True, timeout=600)
    jobs, rule = {}, None
    for line in run.stdout.splitlines():
        if line.startswith(("rule ", "localrule ")):
            rule = line.split()[1].rstrip(":")
        elif line.strip().startswith("output:") and rule:
            jobs.setdefault(rule, []).extend(p.strip() for p in line.split(":", 1)[1].split(","))
    return run.returncode, run.stdout + run.stderr, jobs


def test_scenarios_differing_in_an_analysis_key_share_simulation_and_optimisation(tmp_path):
    code, out, jobs = _dry_run(tmp_path, "scenario_wide", {"wide": {"analyses": {"minima_radius_deg": 60}},
                                                           "mu1": {"mechanics": {"mu": 1.0}}})
    assert code == 0, out[-3000:]
    shared = jobs["simulate_contacts"] + jobs["optimise_shard"] + jobs["aggregate_gfo"]
    assert sorted(shared) == sorted(
        [f"results/objects/{o}/contacts.parquet" for o in ("obj1", "obj4")]
        + [f"results/objects/{o}/gfo_shards/{i}.parquet" for o in ("obj1", "obj4") for i in (0, 1)]
        + [f"results/objects/{o}/gfo.parquet" for o in ("obj1", "obj4")])
    assert sorted(jobs["local_minima"]) == [f"results/scenarios/wide/objects/{o}/minima.parquet"
                                            for o in ("obj1", "obj4")]
    assert "results/scenarios/wide/tables/table2_success_rates.csv" in jobs["study_tables"]
    # an optimisation key: the contacts are shared, the optimisation is its own
    code, out, jobs = _dry_run(tmp_path, "scenario_mu1", {"mu1": {"mechanics": {"mu": 1.0}}})
    assert code == 0, out[-3000:]
    assert all(p.startswith("results/objects/") for p in jobs["simulate_contacts"])
    assert all(p.startswith("results/scenarios/mu1/") for p in jobs["aggregate_gfo"] + jobs["optimise_shard"])


def test_dropping_or_keeping_unloaded_contacts_shares_one_dynamic_closure(tmp_path):
    """`unloaded_contacts` is read by the contacts step, not by the closure: the two dynamic
    scenarios run one closure per object; only `drop` selects the load-carrying contacts, and
    each scenario optimises its own contacts."""
    scenarios = {"dyn": {"closure": {"model": "dynamic"}},
                 "dyn_all": {"closure": {"model": "dynamic", "dynamic": {"unloaded_contacts": "keep"}}}}
    code, out, jobs = _dry_run(tmp_path, "scenarios", scenarios)
    assert code == 0, out[-3000:]
    closures = sorted(p for p in jobs["simulate_contacts"] if "/scenarios/" in p)
    assert closures == [f"results/scenarios/dyn/objects/{o}/contacts.parquet" for o in ("obj1", "obj4")]
    assert sorted(jobs["select_contacts"]) == [f"results/scenarios/dyn/objects/{o}/load_carrying_contacts.parquet"
                                              for o in ("obj1", "obj4")]
    gfo_roots = sorted({p.split("/objects/")[0] for p in jobs["aggregate_gfo"]})
    assert gfo_roots == ["results", "results/scenarios/dyn", "results/scenarios/dyn_all"]


def test_the_closure_shares_across_synergy_tables_that_agree_in_the_mean_and_s1():
    """The closure reads q_m and S1 only: two thumb readings that differ in S2…S15 share it (the
    figure of S1…S7 and the optimisation do not); a table with another S1 does not."""
    full = validate_config(STUDY)
    higher = validate_config(_broken(("synergies",), "softhand_human_higher", STUDY))
    legacy = validate_config(_broken(("synergies",), "legacy_thumb", STUDY))
    assert step_hash(full, "simulate", "obj1") == step_hash(higher, "simulate", "obj1")
    assert step_hash(full, "fig2") == step_hash(higher, "fig2")
    for step, obj in (("fig1", None), ("optimise", "obj1")):
        assert step_hash(full, step, obj) != step_hash(higher, step, obj), step
    assert step_hash(full, "simulate", "obj1") != step_hash(legacy, "simulate", "obj1")


def test_the_closure_reads_no_contact_selection_key():
    full = validate_config(STUDY)
    keep = validate_config(_broken(("closure", "dynamic", "unloaded_contacts"), "keep", STUDY))
    dynamic, dynamic_keep = ({**c, "closure": {**c["closure"], "model": "dynamic"}} for c in (full, keep))
    assert "unloaded_contacts" not in step_config(dynamic, "simulate", "obj1")["closure"]["dynamic"]
    assert step_hash(dynamic, "simulate", "obj1") == step_hash(dynamic_keep, "simulate", "obj1")
    assert step_hash(dynamic, "contacts", "obj1") != step_hash(dynamic_keep, "contacts", "obj1")
    assert step_hash(dynamic, "optimise", "obj1") != step_hash(dynamic_keep, "optimise", "obj1")
    assert step_params(dynamic, "contacts", "obj1").drop_unloaded and not step_params(full, "contacts", "obj1").drop_unloaded
    assert step_hash(full, "contacts", "obj1") == step_hash(keep, "contacts", "obj1")  # kinematic: nothing to select


def test_resources_follow_each_scenarios_own_size(tmp_path):
    """A job's requests come from its scenario: on the study's 5° grid a closure asks for more
    than on the small config's grid, a dynamic one for more than a kinematic one."""
    fine = {"alpha_deg": {"start": -180, "stop": 175, "step": 5}, "beta_deg": {"start": -60, "stop": 60, "step": 5}}
    scenarios = {"fine": {"grid": fine}, "fine_dyn": {"grid": fine, "closure": {"model": "dynamic"}}}
    code, out, _ = _dry_run(tmp_path, "scenarios", scenarios)
    assert code == 0, out[-3000:]
    requests, output = {}, None
    for line in out.splitlines():
        if line.strip().startswith("output:"):
            output = line.split(":", 1)[1].split(",")[0].strip()
        elif line.strip().startswith("resources:") and output:
            fields = dict(kv.split("=", 1) for kv in line.split(":", 1)[1].replace(" ", "").split(","))
            if "runtime" in fields:
                requests[output] = (int(fields["runtime"]), int(fields["mem_mb"]))
    small, fine_kin, fine_dyn = (requests[f"{root}/objects/obj1/contacts.parquet"] for root in
                                 ("results", "results/scenarios/fine", "results/scenarios/fine_dyn"))
    assert small[0] < fine_kin[0] < fine_dyn[0] and small[1] <= fine_kin[1] <= fine_dyn[1]


def _target_inputs(out, rule):
    """The input files of the target rule ``rule`` in a dry run's output."""
    lines = out.splitlines()
    start = lines.index(f"rule {rule}:") if f"rule {rule}:" in lines else lines.index(f"localrule {rule}:")
    line = next(x for x in lines[start:] if x.strip().startswith("input:"))
    return [p.strip() for p in line.split(":", 1)[1].split(",")]


def test_scenarios_differing_in_an_analysis_key_draw_each_shared_figure_once(tmp_path):
    """Fig. 1 (hand, synergies) and Fig. 2 (hand, box sizes, contacts) are made once, under the
    default's root, for scenarios that change only analysis keys; a scenario changing only
    Fig. 4's keys shares the tables, the realism table and Fig. 5 too; each scenario's target
    still lists every file of its study."""
    scenarios = {"wide": {"analyses": {"minima_radius_deg": 60}}, "panels": {"analyses": {"fig4": {"panel_k": [1, 15]}}}}
    code, out, jobs = _dry_run(tmp_path, "scenarios", scenarios)
    assert code == 0, out[-3000:]
    assert jobs["fig1_synergy_postures"] == [f"results/figures/fig1_synergy_postures.{e}" for e in ("png", "pdf")]
    assert jobs["fig2_example_grasps"] == [f"results/figures/fig2_example_grasps.{e}" for e in ("png", "pdf")]
    # the minima radius changes the tables and Fig. 5 (they read the minima), not the realism table
    roots = lambda rule, name: sorted(p.rsplit("/", 2)[0] for p in jobs[rule] if p.endswith(name))  # noqa: E731
    assert roots("study_tables", "/claims.csv") == ["results", "results/scenarios/wide"]
    assert roots("fig5_hierarchy", "/fig5a_hierarchy_success.png") == ["results", "results/scenarios/wide"]
    assert roots("grasp_realism", "/grasp_realism.csv") == ["results"]
    fig4 = sorted(p for p in jobs["fig4_force_maps"] if p.endswith("obj1/fig4_force_maps.png"))
    assert fig4 == [f"{r}/objects/obj1/fig4_force_maps.png" for r in
                    ("results", "results/scenarios/panels", "results/scenarios/wide")]
    default, panels = (_target_inputs(_dry_run(tmp_path, f"scenario_{name}", scenarios)[1], f"scenario_{name}")
                       for name in ("default", "panels"))
    assert len(panels) == len(default) == len(set(default))
    assert [p for p in panels if p not in default] == [
        f"results/scenarios/panels/objects/{o}/fig4_{k}.{e}" for o in ("obj1", "obj4")
        for k in ("force_maps", "exploded") for e in ("png", "pdf")]


@pytest.mark.parametrize("scenarios, expected", [
    ({"s1": {"mechanics": {"muu": 1.0}}}, "scenario 's1': config error at 'mechanics': unknown key(s) ['muu']"),
    ({"s1": {"synergy_sets": {"incremental_max": 20}}},
     "scenario 's1': config error at 'synergy_sets.incremental_max': 20 exceeds the 15 synergies"),
])
def test_a_bad_scenario_stops_the_workflow_before_any_job(tmp_path, scenarios, expected):
    code, out, jobs = _dry_run(tmp_path, "figures", scenarios)
    assert code != 0 and jobs == {}
    assert "Invalid input, nothing was run" in out and expected in out


def test_a_synergy_table_that_cannot_close_the_hand_or_is_not_in_rad_is_named():
    from synergrasp.config import synergy_problems

    config = validate_config(SMALL)
    mean, matrix = [0.1, 0.2], [[0.5, 0.1], [0.2, 0.0]]
    assert synergy_problems(config, mean, matrix) == []
    zero_s1 = synergy_problems(config, mean, [[0.0, 0.1], [0.0, 0.0]])
    assert zero_s1 == ["config error at 'synergies' (the shipped table): S1 is zero for every joint; "
                       "closing along S1 would move no joint"]
    degrees = synergy_problems({**config, "synergies": "mine.csv"}, [10.0, 45.0], matrix)
    assert len(degrees) == 1 and "'synergies' (mine.csv): values up to 45 exceed 2π" in degrees[0]
    assert "exceed 2π" in synergy_problems(config, mean, [[1e300, 0.1], [0.2, 0.0]])[0]
