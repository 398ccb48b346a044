"""The step registry (synergrasp.steps): the keys each step reads, its hash, its typed
parameters, and the workflow's view of it (rules, outputs, costs, shared outputs)."""

import ast
import importlib
import os
import shutil
import re
from pathlib import Path

import pytest
import yaml
from conftest import schema_leaf_paths

from synergrasp.config import ConfigError, defaults, validate_config
from synergrasp.ids import set_id, synergy_sets
from synergrasp.steps import (
    HANDED,
    INPUT_SOURCES,
    STEPS,
    WORKFLOW_KEYS,
    reads_key,
    rule_costs,
    rule_handed,
    rule_inputs,
    rule_step,
    step_config,
    step_hash,
)
from synergrasp.wiring import RuleFiles

ROOT = Path(__file__).resolve().parents[1]
STUDY = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SMALL = yaml.safe_load((ROOT / "tests" / "config" / "small.yaml").read_text())


def _broken(path, value, config=SMALL):
    import copy

    out = copy.deepcopy(config)
    node = out
    for part in path[:-1]:
        node = node.setdefault(part, {})
    node[path[-1]] = value
    return out


def step_params(config, step, obj=None):
    """The step's typed parameters, built by its ``params`` class from ``config``."""
    module, name = STEPS[step].params.split(":")
    return getattr(importlib.import_module(module), name).from_config(config, obj)


def _read_by(path, steps_keys):
    parts = path.split(".")
    for key in steps_keys:
        key_parts = key.replace("{object}", "*").split(".")
        if parts[: len(key_parts)] == key_parts:
            return True
    return False


def test_every_key_of_the_schema_is_read_by_a_step_or_by_the_workflow():
    keys = [k for step in STEPS.values() for k in step.reads + sum((r for _, _, r in step.reads_when), ())]
    keys += list(WORKFLOW_KEYS)
    unread = [p for p in schema_leaf_paths() if not _read_by(p, keys)]
    assert unread == []


def test_the_closure_does_not_rerun_when_an_object_mass_changes():
    """Not with a placement that is not searched; with a searched one (the default) it does,
    through the search (it reads the weight)."""
    approach = _broken(("placement", "mode"), "approach", STUDY)
    heavier = _broken(("objects", "obj1", "mass_kg"), 2.0, approach)
    full, changed = validate_config(approach), validate_config(heavier)
    assert step_config(full, "simulate", "obj1") == step_config(changed, "simulate", "obj1")
    assert step_hash(full, "simulate", "obj1") == step_hash(changed, "simulate", "obj1")
    assert step_hash(full, "optimise", "obj1") != step_hash(changed, "optimise", "obj1")
    assert step_hash(full, "optimise", "obj2") == step_hash(changed, "optimise", "obj2")
    searched = validate_config(STUDY)
    heavier = validate_config(_broken(("objects", "obj1", "mass_kg"), 2.0, STUDY))
    assert step_config(searched, "simulate", "obj1") == step_config(heavier, "simulate", "obj1")
    assert step_hash(searched, "search", "obj1") != step_hash(heavier, "search", "obj1")
    assert step_hash(searched, "simulate", "obj1") != step_hash(heavier, "simulate", "obj1")
    assert step_hash(searched, "simulate", "obj2") == step_hash(heavier, "simulate", "obj2")


def test_a_conditional_key_is_read_only_when_its_condition_holds():
    ((key, value, reads),) = STEPS["simulate"].reads_when
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
    Fig. 2 every object's contacts and, for its 3-D pages' forces, every weight."""
    approach = _broken(("placement", "mode"), "approach", STUDY)
    full = validate_config(approach)
    wider = validate_config(_broken(("analyses", "minima_radius_deg"), 20, approach))
    heavier = validate_config(_broken(("objects", "obj1", "mass_kg"), 2.0, approach))
    assert step_config(full, "tables") != step_config(wider, "tables")  # reads the radius itself
    assert step_config(full, "fig5") == step_config(wider, "fig5")
    assert step_hash(full, "fig5") != step_hash(wider, "fig5")  # through the tables
    for step in ("fig1", "fig2", "realism"):
        assert step_hash(full, step) == step_hash(wider, step), step
    assert step_hash(full, "fig2") != step_hash(heavier, "fig2")
    assert step_config(full, "fig4", "obj2") == step_config(heavier, "fig4", "obj2")
    assert step_hash(full, "fig4", "obj1") != step_hash(heavier, "fig4", "obj1")  # its optimisation
    assert step_hash(full, "fig4", "obj2") == step_hash(heavier, "fig4", "obj2")


@pytest.mark.parametrize("model", ["kinematic", "dynamic"])
def test_step_params_are_built_from_the_steps_own_keys_only(model):
    full = validate_config(_broken(("closure", "model"), model, STUDY))
    for step, spec in STEPS.items():
        if spec.params is None:
            continue
        obj = "obj4" if spec.scope == "object" else None
        assert step_params(full, step, obj) == step_params(step_config(full, step, obj), step, obj), step
    sim = step_params(step_config(full, "simulate", "obj4"), "simulate", "obj4")
    assert sim.placement.mode == "searched" and sim.placement.box_axes == (1, 0, 2)
    assert sim.placement.alpha_deg == (-180.0, 175.0, 5.0)
    assert sim.closure.step_mm == 8.0 and (sim.object.mass_kg is None) == (model == "kinematic")


def test_the_closure_is_handed_the_mean_posture_and_s1_only():
    """What the closure's hash holds is what it is given: q_m and S1, not the table."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.hand.synergies import load_synergies

    cut = step_config(validate_config(STUDY), "simulate", "obj1")
    assert set(cut["synergies"]) == {"mean_rad", "S1"}
    table = load_synergies(None, joint_names=load_hand(None).joint_names)
    sim = step_params(cut, "simulate", "obj1")
    synergies = sim.synergies(table.joint_names)
    assert synergies.n_synergies == 1
    assert (synergies.mean == table.mean).all() and (synergies.matrix[:, 0] == table.matrix[:, 0]).all()


def test_optimise_params_keep_the_mechanics_and_the_objects_weight():
    config = validate_config(_broken(("mechanics", "gravity_direction"), [0.0, 0.0, -2.0], STUDY))
    config["objects"]["obj1"]["mass_kg"] = 0.5
    params = step_params(config, "optimise", "obj1")
    gfo = params.gfo
    assert gfo.gravity_direction == (0.0, 0.0, -1.0)
    assert (gfo.mu, gfo.f_min_N, gfo.k_stru_N_per_mm, gfo.k_ss_Nmm_per_rad) == (1.5, 0.1, 1.0, 200.0)
    assert gfo.weight_N == 0.5 * 9.81  # m·g, synergrasp.resolved.weight_N
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


def _rules():
    """Every rule of the workflow (snakemake's own parse): name -> (its output files, its log
    files, its benchmark file or None, its script or None)."""
    from synergrasp.snakemake_adapter import workflow_rules

    def bare(path):  # wildcards without their constraints: {root,...} -> {root}
        return re.sub(r"\{(\w+),[^{}]*\}", r"{\1}", str(path))

    return {
        rule.name: (
            [bare(f) for f in rule.output],
            [bare(f) for f in rule.log],
            bare(rule.benchmark) if rule.benchmark else None,
            rule.script,
        )
        for rule in workflow_rules(ROOT / "Snakefile", ROOT)
    }


TARGET_RULES = ("all", "figures", "scenarios", "placement_claims", "plans", "across_objects")


def test_every_step_has_its_rules_outputs_and_costs_and_every_rule_its_step():
    rules = _rules()
    costs = rule_costs()
    jobs = [r for r in rules if r not in TARGET_RULES and not r.startswith(("object_", "scenario_"))]
    assert sorted(jobs) == sorted(costs)  # every rule has its step, every step's rule exists
    prefix = {"object": "{root}/objects/{object}/", "scenario": "{root}/", "workflow": "results/"}
    for name, step in STEPS.items():
        assert step.outputs, name
        written = rules[list(step.rules)[-1]][0]
        assert sorted(written) == sorted(prefix[step.scope] + rel for rel in step.outputs.values()), name
        assert all(
            c.unit in ("none", "pose", "closure_pose", "shard_pose_set", "pose_set", "object_pose", "object_pose_set")
            and c.fixed_s > 0
            and c.fixed_mb > 0
            and c.threads >= 1
            for c in step.rules.values()
        ), name
        assert set(step.upstream) <= set(STEPS), name
        assert set(step.report) | set(step.folders) <= set(step.outputs), name
        assert all((ROOT / "workflow" / "report" / f"{caption}.rst").is_file() for caption, _ in step.report.values())


def _read_steps(step):
    """The steps whose outputs a step's rules read (its registry inputs), in a set."""
    sources = [source for rule in STEPS[step].rules for source in rule_inputs(rule).values()]
    return {source.split(".")[0] for source in sources if source.split(".")[0] in STEPS}


def _upstream_closure(step):
    """A step's upstream steps (``upstream`` and ``upstream_when``) and theirs, in turn."""
    found, todo = set(), [step]
    while todo:
        spec = STEPS[todo.pop()]
        for up in (*spec.upstream, *(up for _, _, up in spec.upstream_when)):
            if up not in found:
                found.add(up)
                todo.append(up)
    return found


def test_every_input_of_a_rule_names_a_source_the_registry_knows():
    """An input is a file of the study's own, a step's one output, a step's named output, or
    an earlier rule of the same step (its shards); nothing else resolves."""
    for rule in rule_costs():
        step = STEPS[rule_step()[rule]]
        for name, source in rule_inputs(rule).items():
            producer, _, output = source.partition(".")
            if source in INPUT_SOURCES:
                continue
            if producer in STEPS:
                assert (output in STEPS[producer].outputs) if output else len(STEPS[producer].outputs) == 1, (rule, name)
            else:  # an earlier rule of the same step
                assert producer in step.rules and producer != rule and not output, (rule, name, source)


def test_a_steps_hash_holds_every_step_whose_outputs_it_reads():
    """Every upstream step's output is read by one of the step's rules, and every step read is
    upstream, directly or through another upstream step: so the hash of a step (which decides
    where its outputs are shared between scenarios) changes with every file it reads."""
    for name, step in STEPS.items():
        read = _read_steps(name)
        assert set(step.upstream) | {up for _, _, up in step.upstream_when} <= read, name
        assert read <= _upstream_closure(name), (name, sorted(read - _upstream_closure(name)))


def test_what_a_rule_is_handed_by_hand():
    assert rule_handed("optimise_shard") == ("cfg",)  # the optimisation reads its keys
    assert rule_handed("optimise") == ()  # merging the shards reads none
    assert rule_handed("summarise_target_claims") == ()  # its step reads no key
    assert rule_handed("fig3") == ("configfile",)
    assert all(set(rule_handed(rule)) <= set(HANDED) for rule in rule_costs())


def test_a_key_read_is_a_key_of_reads_or_inside_a_block_of_it_and_not_of_not_reads():
    assert reads_key("simulate", "placement.search_rank")  # reads the whole block `placement`
    assert not reads_key("placement_map", "placement.search_rank")  # the search's keys, not its target
    assert reads_key("minima", "analyses.success") and not reads_key("minima", "analyses")
    assert not reads_key("simulate", "closure.dynamic.load_threshold_N")  # in `closure`, but not read


def _folder(path, kind):
    """The name under ``<root>/<kind>/`` of a log or benchmark path: its folder, or the file's stem."""
    below = path.split(f"/{kind}/", 1)[1]
    return below.split("/")[0] if "/" in below else below.rsplit(".", 1)[0]


def test_a_steps_name_is_its_rules_its_scripts_and_its_log_and_benchmark_folders():
    """One name per step: the step's last rule (the one writing its outputs) is named as the
    step, an earlier rule ``<step>_<what>``; each rule runs workflow/scripts/<rule>.py and
    keeps its log and benchmark under logs/<rule> and benchmarks/<rule> (or <rule>.log and
    <rule>.tsv for a step run once). What the rules are checked against is Snakemake's own parse."""
    rules = _rules()
    for name, step in STEPS.items():
        *earlier, last = step.rules
        assert last == name and all(rule.startswith(f"{name}_") for rule in earlier), name
        for rule in step.rules:
            _, logs, benchmark, script = rules[rule]
            assert [_folder(p, "logs") for p in logs] == [rule], (rule, logs)
            assert benchmark is not None and _folder(benchmark, "benchmarks") == rule, (rule, benchmark)
            assert Path(script).name == f"{rule}.py", (rule, script)
            assert logs == [RuleFiles(rule).log()] and benchmark == RuleFiles(rule).benchmark()


@pytest.mark.parametrize("step", [s for s in STEPS if STEPS[s].params and STEPS[s].rules])
def test_a_steps_script_imports_the_module_its_parameters_come_from(step):
    # so the rule's code digest (derived from the script's imports) covers them
    script = ROOT / "workflow" / "scripts" / f"{list(STEPS[step].rules)[0]}.py"
    module, name = STEPS[step].params.split(":")
    tree = ast.parse(script.read_text())
    assert any(
        isinstance(n, ast.ImportFrom) and n.module == module and name in {a.name for a in n.names} for n in ast.walk(tree)
    ), (script, module, name)


def test_study_synergy_sets_are_the_75_distinct_sets():  # synergrasp.ids
    sets = synergy_sets(defaults()["synergy_sets"])
    # 15 incremental + (7 + 21 + 35) hierarchy - 3 shared ({S1}, {S1,S2}, {S1,S2,S3})
    assert len(sets) == 15 + 63 - 3
    assert sets["1-2-3"] == (1, 2, 3)
    assert "2-5-7" in sets and "1-2-3-4-5-6-7-8-9-10-11-12-13-14-15" in sets
    assert all(set_id(v) == k for k, v in sets.items())


def _path(shown: str) -> str:
    """A path as a dry run lists it, without Snakemake's flag in parentheses (``(update)``)."""
    return shown.strip().split(" (")[0]


def _dry_run(tmp_path, target, scenarios, root=ROOT):
    """``snakemake -n target`` (a target or a list of them) on the small config with
    ``scenarios``, with the project (workflow and sources) at ``root``: (return code, output,
    {rule: [output files]} of the jobs it would run)."""
    import subprocess
    import sys

    config = tmp_path / "config.yaml"
    config.write_text(yaml.safe_dump({**SMALL, "scenarios": scenarios}))
    targets = [target] if isinstance(target, str) else list(target)
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            *targets,
            "-n",
            "-s",
            str(root / "Snakefile"),
            "--directory",
            str(tmp_path),
            "--configfile",
            str(config),
            "--replace-workflow-config",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "PYTHONPATH": str(root / "src")},
    )
    jobs, rule = {}, None
    for line in run.stdout.splitlines():
        if line.startswith(("rule ", "localrule ")):
            rule = line.split()[1].rstrip(":")
        elif line.strip().startswith("output:") and rule:
            jobs.setdefault(rule, []).extend(_path(p) for p in line.split(":", 1)[1].split(","))
    return run.returncode, run.stdout + run.stderr, jobs


#: A toy step: one registry entry (a table from the study's hierarchy table) ...
_TOY_STEP = """

STEPS["toy"] = Step(
    rules={"toy": Cost("none", 1.0, 100)},
    outputs={"csv": "tables/toy.csv"},
    reads=("synergy_sets.hierarchy_first",),
    upstream=("tables",),
    inputs={"hierarchy": "tables.hierarchy_csv"},
)
"""
#: ... and its script.
_TOY_SCRIPT = """import shutil

shutil.copy(snakemake.input.hierarchy, snakemake.output.csv)
"""


def test_a_step_added_to_the_registry_alone_is_planned(tmp_path):
    """A new step is its registry entry and its script (with its science and its test): in a
    copy of the project with a toy step added so, Snakemake plans its rule for the study,
    with the input the entry names and the output, log and params the registry gives."""
    root, run = tmp_path / "project", tmp_path / "run"
    root.mkdir(), run.mkdir()
    for name in ("Snakefile", "environment.lock"):
        shutil.copy2(ROOT / name, root / name)
    for name in ("workflow", "src", "config"):
        shutil.copytree(ROOT / name, root / name, ignore=shutil.ignore_patterns("*.egg-info", "__pycache__"))
    steps = root / "src" / "synergrasp" / "steps.py"
    steps.write_text(steps.read_text() + _TOY_STEP)
    (root / "workflow" / "scripts" / "toy.py").write_text(_TOY_SCRIPT)
    code, out, jobs = _dry_run(run, "figures", {}, root=root)
    assert code == 0, out[-3000:]
    assert jobs["toy"] == ["results/tables/toy.csv"]
    toy = out.split("rule toy:", 1)[1].split("\n\n", 1)[0]
    assert "input: results/tables/hierarchy.csv\n" in toy and "log: results/logs/toy.log" in toy


def test_scenarios_differing_in_an_analysis_key_share_simulation_and_optimisation(tmp_path):
    code, out, jobs = _dry_run(
        tmp_path, "scenario_wide", {"wide": {"analyses": {"minima_radius_deg": 60}}, "mu1": {"mechanics": {"mu": 1.0}}}
    )
    assert code == 0, out[-3000:]
    shared = jobs["simulate"] + jobs["optimise_shard"] + jobs["optimise"]
    assert sorted(shared) == sorted(
        [f"results/objects/{o}/contacts.parquet" for o in ("obj1", "obj4")]
        + [f"results/objects/{o}/gfo_shards/{i}.parquet" for o in ("obj1", "obj4") for i in (0, 1)]
        + [f"results/objects/{o}/gfo.parquet" for o in ("obj1", "obj4")]
    )
    assert sorted(jobs["minima"]) == [f"results/scenarios/wide/objects/{o}/minima.parquet" for o in ("obj1", "obj4")]
    assert "results/scenarios/wide/tables/table2_success_rates.csv" in jobs["tables"]
    # an optimisation key: the contacts are shared, the optimisation is its own
    code, out, jobs = _dry_run(tmp_path, "scenario_mu1", {"mu1": {"mechanics": {"mu": 1.0}}})
    assert code == 0, out[-3000:]
    assert all(p.startswith("results/objects/") for p in jobs["simulate"])
    assert all(p.startswith("results/scenarios/mu1/") for p in jobs["optimise"] + jobs["optimise_shard"])


def test_dropping_or_keeping_unloaded_contacts_shares_one_dynamic_closure(tmp_path):
    """`unloaded_contacts` is read by the contacts step, not by the closure: the two dynamic
    scenarios run one closure per object; only `drop` selects the load-carrying contacts, and
    each scenario optimises its own contacts."""
    scenarios = {
        "dyn": {"closure": {"model": "dynamic"}},
        "dyn_all": {"closure": {"model": "dynamic", "dynamic": {"unloaded_contacts": "keep"}}},
    }
    code, out, jobs = _dry_run(tmp_path, "scenarios", scenarios)
    assert code == 0, out[-3000:]
    closures = sorted(p for p in jobs["simulate"] if "/scenarios/" in p)
    assert closures == [f"results/scenarios/dyn/objects/{o}/contacts.parquet" for o in ("obj1", "obj4")]
    assert sorted(jobs["contacts"]) == [
        f"results/scenarios/dyn/objects/{o}/load_carrying_contacts.parquet" for o in ("obj1", "obj4")
    ]
    gfo_roots = sorted({p.split("/objects/")[0] for p in jobs["optimise"]})
    assert gfo_roots == ["results", "results/scenarios/dyn", "results/scenarios/dyn_all"]


def test_the_closure_shares_across_synergy_tables_that_agree_in_the_mean_and_s1():
    """The closure reads q_m and S1 only: two thumb readings that differ in S2…S15 share it (the
    figure of S1…S7, the optimisation and Fig. 2's 3-D pages with their forces do not); a table
    with another S1 does not. With a
    searched placement they do not share it: the search reads the full set."""
    approach = _broken(("placement", "mode"), "approach", STUDY)
    full = validate_config(approach)
    higher = validate_config(_broken(("synergies",), "softhand_human_higher", approach))
    legacy = validate_config(_broken(("synergies",), "legacy_thumb", approach))
    searched = validate_config(STUDY)
    searched_higher = validate_config(_broken(("synergies",), "softhand_human_higher", STUDY))
    assert step_hash(searched, "search", "obj1") != step_hash(searched_higher, "search", "obj1")
    assert step_hash(searched, "simulate", "obj1") != step_hash(searched_higher, "simulate", "obj1")
    assert step_hash(full, "simulate", "obj1") == step_hash(higher, "simulate", "obj1")
    for step, obj in (("fig1", None), ("fig2", None), ("optimise", "obj1")):
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
    """A job's requests come from its scenario: on a 2.5° grid (7,056 poses) a closure asks for
    more than on the small config's grid, a dynamic one for more than a kinematic one."""
    fine = {"alpha_deg": {"start": -180, "stop": 177.5, "step": 2.5}, "beta_deg": {"start": -60, "stop": 60, "step": 2.5}}
    scenarios = {"fine": {"grid": fine}, "fine_dyn": {"grid": fine, "closure": {"model": "dynamic"}}}
    code, out, _ = _dry_run(tmp_path, "scenarios", scenarios)
    assert code == 0, out[-3000:]
    requests, output = {}, None
    for line in out.splitlines():
        if line.strip().startswith("output:"):
            output = _path(line.split(":", 1)[1].split(",")[0])
        elif line.strip().startswith("resources:") and output:
            fields = dict(kv.split("=", 1) for kv in line.split(":", 1)[1].replace(" ", "").split(","))
            if "runtime" in fields:
                requests[output] = (int(fields["runtime"]), int(fields["mem_mb"]))
    small, fine_kin, fine_dyn = (
        requests[f"{root}/objects/obj1/contacts.parquet"]
        for root in ("results", "results/scenarios/fine", "results/scenarios/fine_dyn")
    )
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
    assert jobs["fig1"] == [f"results/figures/fig1_synergy_postures.{e}" for e in ("png", "pdf")]
    assert jobs["fig2"] == [*(f"results/figures/fig2_example_grasps.{e}" for e in ("png", "pdf")), "results/figures/grasps_3d"]
    # the minima radius changes the tables and Fig. 5 (they read the minima), not the realism table
    roots = lambda rule, name: sorted(p.rsplit("/", 2)[0] for p in jobs[rule] if p.endswith(name))  # noqa: E731
    assert roots("tables", "/claims.csv") == ["results", "results/scenarios/wide"]
    assert roots("fig5", "/fig5a_hierarchy_success.png") == ["results", "results/scenarios/wide"]
    assert roots("realism", "/grasp_realism.csv") == ["results"]
    fig4 = sorted(p for p in jobs["fig4"] if p.endswith("obj1/fig4_force_maps.png"))
    assert fig4 == [
        f"{r}/objects/obj1/fig4_force_maps.png" for r in ("results", "results/scenarios/panels", "results/scenarios/wide")
    ]
    out = _dry_run(tmp_path, ["scenario_default", "scenario_panels"], scenarios)[1]
    default, panels = (_target_inputs(out, f"scenario_{name}") for name in ("default", "panels"))
    assert len(panels) == len(default) == len(set(default))
    assert [p for p in panels if p not in default] == [
        f"results/scenarios/panels/objects/{o}/fig4_{k}.{e}"
        for o in ("obj1", "obj4")
        for k in ("force_maps", "exploded")
        for e in ("png", "pdf")
    ]


@pytest.mark.parametrize(
    "scenarios, expected",
    [
        ({"s1": {"mechanics": {"muu": 1.0}}}, "scenario 's1': config error at 'mechanics': unknown key(s) ['muu']"),
        (
            {"s1": {"synergy_sets": {"incremental_max": 20}}},
            "scenario 's1': config error at 'synergy_sets.incremental_max': 20 exceeds the 15 synergies",
        ),
    ],
)
def test_a_bad_scenario_stops_the_workflow_before_any_job(tmp_path, scenarios, expected):
    # a scenario is read only by the targets that need it: `figures` does not
    code, out, jobs = _dry_run(tmp_path, "figures", scenarios)
    assert code == 0 and "scenarios/s1" not in out
    code, out, jobs = _dry_run(tmp_path, "scenarios", scenarios)
    assert code != 0 and jobs == {}
    assert "Invalid input, nothing was run" in out and expected in out


def test_no_module_of_the_package_imports_another_by_name_at_run_time():
    """The layers (pyproject.toml, `make lint`) see every import: none is made by name."""
    for path in (ROOT / "src" / "synergrasp").rglob("*.py"):
        text = path.read_text()
        assert "import_module(" not in text and "__import__(" not in text, path
