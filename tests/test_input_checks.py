"""The checks that run before any job, one kind of bad input at a time (issue 27): repeated
YAML keys, hand files the closure cannot use or far from a human hand, names the file system
or Snakemake cannot take, relations that make a step impossible, a SLURM profile in a shell
that cannot submit; and objects that can never be grasped, said per object with the reason."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from synergrasp.analysis.graspability import graspable_objects, ungraspable_lines
from synergrasp.config import SCHEMA_PATH, ConfigError, defaults, validate_config
from synergrasp.hand.checks import check_hand, closure_shape_problems
from synergrasp.hand.kinematics import default_hand_path, load_hand
from synergrasp.preflight import configfile_problems, group_problems, partition_nodes, slurm_problems
from synergrasp.simulation.capsules import HandCapsules
from synergrasp.yaml_io import YamlFileError, read_yaml

ROOT = Path(__file__).resolve().parents[1]


# --------------------------------------------------------------------------- kind 6: repeated keys


def test_a_repeated_key_names_the_file_the_line_and_the_key(tmp_path):
    path = tmp_path / "my.yaml"
    path.write_text("scenarios:\n  s: {mechanics: {mu: 1.0}}\n  s: {mechanics: {mu: 2.0}}\nobjects:\n  - {a: 1, b: 2, a: 3}\n")
    with pytest.raises(YamlFileError) as info:
        read_yaml(path, "config file")
    lines = str(info.value).splitlines()
    assert lines == [
        f"config file '{path}', line 3: key 'scenarios.s' appears twice (first at line 2); each key may appear once",
        f"config file '{path}', line 5: key 'objects[0].a' appears twice (first at line 5); each key may appear once",
    ]


def test_keys_that_differ_only_in_type_or_nesting_are_not_repeats(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text("a: {x: 1}\nb: {x: 2}\n'1': one\n1: int one\n")
    assert read_yaml(path) == {"a": {"x": 1}, "b": {"x": 2}, "1": "one", 1: "int one"}


@pytest.mark.parametrize(
    "path",
    [
        ROOT / "config" / "config.yaml",
        ROOT / "config" / "sensitivity.yaml",
        ROOT / "tests" / "config" / "small.yaml",
        SCHEMA_PATH,
        default_hand_path(),
        *sorted((ROOT / "src" / "synergrasp" / "data").glob("synergy_mapping_*.yaml")),
    ],
    ids=lambda p: p.name,
)
def test_every_shipped_yaml_reads_as_plain_yaml_does(path):
    assert read_yaml(path) == yaml.safe_load(path.read_text(encoding="utf-8"))


def test_configfile_problems_lists_each_file_once(tmp_path):
    good, bad = tmp_path / "good.yaml", tmp_path / "bad.yaml"
    good.write_text("objects: {obj1: {mass_kg: 1.0}}\n")
    bad.write_text("hand: a.yaml\nhand: b.yaml\n")
    assert configfile_problems([good, bad, str(bad)]) == [
        f"config file '{bad}', line 2: key 'hand' appears twice (first at line 1); each key may appear once"
    ]


def test_a_hand_file_with_a_repeated_key_is_refused_naming_it(tmp_path):
    text = default_hand_path().read_text()
    path = tmp_path / "hand.yaml"
    path.write_text(text.replace("name: softhand_like\n", "name: softhand_like\nname: other\n", 1))
    line = text.splitlines().index("name: softhand_like") + 1  # 1-based line of the first 'name'
    with pytest.raises(
        ValueError, match=f"hand file '{path}', line {line + 1}: key 'name' appears twice \\(first at line {line}\\)"
    ):
        load_hand(path)


# --------------------------------------------------------------------------- kind 1/7: hand files


def _hand_doc() -> dict:
    return yaml.safe_load(default_hand_path().read_text())


def _write(tmp_path: Path, doc: dict) -> Path:
    path = tmp_path / "hand.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


def _capsule_palm(doc):
    doc["palm"]["shapes"] = [{"capsule": {"from_mm": [0, 0, 20], "to_mm": [0, 0, 80], "radius_mm": 20}}]


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d["palm"].update(shapes=[]), "palm.shapes: the closure needs a palm made of one or more boxes, got []"),
        (_capsule_palm, "palm.shapes: the closure needs a palm made of one or more boxes, got ['capsule']"),
        (
            lambda d: d["fingers"]["ring"]["joints"][2].pop("shapes"),
            "fingers.ring.joints[2].shapes: the closure needs exactly one capsule per finger link (link 'ring_middle'), got []",
        ),
        (
            lambda d: d["fingers"]["thumb"]["joints"][0]["shapes"].append(
                {"box": {"center_mm": [0, 0, 0], "size_mm": [5, 5, 5]}}
            ),
            "fingers.thumb.joints[0].shapes: the closure needs exactly one capsule per finger link "
            "(link 'thumb_knuckle'), got ['capsule', 'box']",
        ),
    ],
)
def test_a_hand_the_closure_cannot_collide_is_a_problem_naming_file_and_field(tmp_path, mutate, field):
    doc = _hand_doc()
    mutate(doc)
    path = _write(tmp_path, doc)
    hand, problems, warnings = check_hand(path)
    assert problems == [f"hand file '{path}': {field}"]
    assert warnings == []
    # the same requirement, raised inside a job, names the file and the field too
    with pytest.raises(ValueError) as info:
        HandCapsules.of(hand)
    assert str(info.value) == problems[0]


def test_the_shipped_hand_has_no_problem_and_no_warning():
    hand, problems, warnings = check_hand(None)
    assert problems == [] and warnings == []
    assert closure_shape_problems(load_hand()) == []


def test_a_link_offset_of_minus_9000_mm_is_warned_naming_the_field(tmp_path):
    doc = _hand_doc()
    doc["fingers"]["index"]["joints"][1]["offset_mm"] = [-9000.0, 0.0, 0.0]
    path = _write(tmp_path, doc)
    _, problems, warnings = check_hand(path)
    assert problems == []
    assert warnings == [
        f"hand file '{path}': fingers.index.joints[1] (index_mcp) offset: 9000 mm is far from a "
        "human hand's dimensions (a hand is about 190 mm long); lengths are in mm"
    ]


def test_a_hand_file_in_metres_is_warned(tmp_path):
    doc = _hand_doc()

    def scale(node):
        if isinstance(node, dict):
            return {k: (scale(v) if not k.endswith(("_rad", "_deg")) and k != "axis" else v) for k, v in node.items()}
        if isinstance(node, list):
            return [scale(v) for v in node]
        return node / 1000.0 if isinstance(node, float | int) and not isinstance(node, bool) else node

    metres = scale(doc)
    metres["palm_normal"] = doc["palm_normal"]
    path = _write(tmp_path, metres)
    _, _, warnings = check_hand(path)
    assert len(warnings) == 1 and "<top level>: no length of the hand exceeds 0.1" in warnings[0]
    assert "lengths are in mm, not m" in warnings[0]


# --------------------------------------------------------------------------- kinds 3 and 5: the configuration


def _with_object(name: str) -> dict:
    config = defaults()
    config["objects"] = {name: config["objects"]["obj1"]}
    return config


def test_a_300_character_object_name_is_refused_naming_the_key():
    with pytest.raises(ConfigError) as info:
        validate_config(_with_object("o" * 300))
    assert str(info.value).startswith(
        "config error at 'objects': name 'oooooooooooooooooooooooooooooooooooooooo…' (300 characters) is not allowed"
    )
    assert "at most 64 characters" in str(info.value)


def test_names_up_to_64_characters_and_periodic_names_are_valid():
    assert "obj_00000000000000000000" in validate_config(_with_object("obj_" + "0" * 20))["objects"]
    assert validate_config(_with_object("a" * 64))
    config = defaults()
    config["scenarios"] = {"s" * 65: {}}
    with pytest.raises(ConfigError, match="config error at 'scenarios': name 's{65}' is not allowed.*at most 64"):
        validate_config(config)


@pytest.mark.parametrize("window, ok", [(0.69, True), (0.7, False), (0.8, False)])
def test_a_settle_window_the_time_limit_cannot_hold_is_a_config_error(window, ok):
    # ramp 0.3 s, limit 1.0 s, step 1/240 s: 168 steps after the ramp hold a window of 167
    config = defaults()
    config["closure"]["dynamic"].update(ramp_time_s=0.3, time_limit_s=1.0, time_step_s=1 / 240, settle_window_s=window)
    if ok:
        assert validate_config(config)
    else:
        with pytest.raises(
            ConfigError,
            match="config error at 'closure.dynamic.settle_window_s': .* must be "
            "shorter than closure.dynamic.time_limit_s - ramp_time_s",
        ):
            validate_config(config)


# --------------------------------------------------------------------------- kind 3: never graspable


def _contacts(obj: str, statuses: list[str], settled: bool = True, model: str = "kinematic") -> pd.DataFrame:
    return pd.DataFrame(
        {"object": obj, "pose": range(len(statuses)), "status": statuses, "settled": settled, "closure_model": model}
    )


def _gfo(obj: str, fc_poses: list[int], n_poses: int, full: str = "1-2-3") -> pd.DataFrame:
    rows = [
        {
            "object": obj,
            "pose": p,
            "set_id": s,
            "status": "feasible" if p in fc_poses else "infeasible",
            "load_feasible": p in fc_poses,
            "force_closure_def1": p in fc_poses,
            "rank_G": 6,
            "force_norm": np.nan,
        }
        for p in range(n_poses)
        for s in ("1", full)
    ]
    return pd.DataFrame(rows)


def test_each_object_that_can_never_be_grasped_has_its_reason():
    contacts = pd.concat(
        [
            _contacts("a", ["intersects_open_hand"] * 3 + ["lost"]),
            _contacts("b", ["no_contact"] * 2 + ["caged"]),
            _contacts("c", ["grasp"] * 3, settled=False, model="dynamic"),
            _contacts("d", ["grasp", "no_contact"]),
            _contacts("e", ["grasp", "grasp"]),
        ],
        ignore_index=True,
    )
    gfo = pd.concat(
        [_gfo("a", [], 4), _gfo("b", [], 3), _gfo("c", [], 3), _gfo("d", [], 2), _gfo("e", [1], 2)], ignore_index=True
    )
    table = graspable_objects(contacts, gfo, "1-2-3")
    assert list(table["object"]) == ["a", "b", "c", "d", "e"]
    assert list(table["graspable"]) == [False, False, False, False, True]
    assert list(table["force_closure_full_set"]) == [0, 0, 0, 0, 1]
    assert list(table["reason"]) == [
        "every pose dropped (intersects_open_hand: 3, lost: 1)",
        "nothing touched: no closure ends touching the box (caged: 1, no_contact: 2)",
        "no pose settled: every closure stopped at closure.dynamic.time_limit_s, and no force closure with the full set {S1..S3}",
        "no force closure with the full set {S1..S3} at any of the 1 grasps",
        "",
    ]
    assert ungraspable_lines(table)[0] == "a can never be grasped: every pose dropped (intersects_open_hand: 3, lost: 1)"
    assert len(ungraspable_lines(table)) == 4


# --------------------------------------------------------------------------- kind 4: the SLURM profile


class _Settings:
    def __init__(self, status_command=None, no_account=False):
        self.status_command, self.no_account = status_command, no_account


_PROFILE = {"slurm_partition": "$SBATCH_PARTITION", "slurm_account": "$SBATCH_ACCOUNT", "mem_mb": 1000}


def _which(available):
    return lambda name: f"/usr/bin/{name}" if name in available else None


def test_slurm_profile_without_variables_or_commands_names_them():
    problems = slurm_problems(_Settings(), _PROFILE, environ={}, which=_which(set()))
    assert problems == [
        "$SBATCH_PARTITION is not set (the profile's slurm_partition reads it; export it, empty if your site has none)",
        "$SBATCH_ACCOUNT is not set (the profile's slurm_account reads it; export it, empty if your site has none)",
        "not on PATH: sbatch, scancel, sacct or squeue",
    ]


def test_slurm_profile_needs_what_its_account_setting_calls():
    everything = {"sbatch", "scancel", "squeue", "sacct", "sacctmgr"}
    env = {"SBATCH_PARTITION": "main", "SBATCH_ACCOUNT": ""}
    assert slurm_problems(_Settings("squeue"), _PROFILE, env, _which(everything)) == []
    # no account given: the executor guesses one with sacct
    assert slurm_problems(_Settings("squeue"), _PROFILE, env, _which(everything - {"sacct"})) == ["not on PATH: sacct"]
    assert slurm_problems(_Settings("squeue", no_account=True), _PROFILE, env, _which(everything - {"sacct"})) == []
    # an account given: the executor checks it with sacctmgr or sshare
    env["SBATCH_ACCOUNT"] = "lab"
    assert slurm_problems(_Settings("squeue"), _PROFILE, env, _which(everything - {"sacctmgr"})) == [
        "not on PATH: sacctmgr or sshare"
    ]


#: profiles/slurm's groups: the submitted rules of one object.
_GROUPS = {rule: "object" for rule in ("mesh_parts", "search", "simulate", "optimise_shard")}
_ENV = {"SBATCH_PARTITION": "main"}


def _nodes(*sizes):
    """A partition of nodes of these (CPUs, MB), as sinfo would report it; records the partition asked."""
    asked = []

    def nodes_of(partition):
        asked.append(partition)
        return list(sizes)

    nodes_of.asked = asked
    return nodes_of


def test_a_group_that_fits_the_partitions_node_is_accepted():
    nodes = _nodes((2, 23081))
    # the cluster test's node: 2 CPUs, 23,081 MB; groups cut to exactly that fit
    assert group_problems(_GROUPS, 2, 23081, [("search", 1300), ("tables", 400)], _PROFILE, _ENV, nodes) == []
    assert nodes.asked == ["main"]  # $SBATCH_PARTITION read from the environment
    # a node of a larger kind besides a smaller one: the group fits the larger
    assert group_problems(_GROUPS, 4, 16000, [], _PROFILE, _ENV, _nodes((2, 8000), (32, 192000))) == []


def test_a_group_larger_than_every_node_is_refused_naming_the_limits_and_the_nodes():
    # the profile's 4 CPUs on the 2-CPU test node: SLURM would hold the job (PartitionConfig)
    (line,) = group_problems(_GROUPS, 4, 16000, [], _PROFILE, _ENV, _nodes((2, 23081)))
    assert line == (
        "a group job may ask for 4 CPUs and 16000 MB (cores and resources mem_mb), more than any node of "
        "partition 'main' has (sinfo: 2 CPUs 23081 MB); set them to a node's size, e.g. --cores 2 --resources mem_mb=23081"
    )
    # CPUs on one kind of node, memory on another: no node holds both
    (line,) = group_problems(_GROUPS, 8, 64000, [], _PROFILE, _ENV, _nodes((8, 32000), (4, 96000)))
    assert "(sinfo: 4 CPUs 96000 MB, 8 CPUs 32000 MB)" in line and line.endswith("--cores 8 --resources mem_mb=32000")


def test_a_job_asking_more_memory_than_the_node_is_refused_once_per_rule():
    requests = [("tables", 43900), ("tables", 400), ("simulate", 300), ("realism", 16001), ("fig1", 16000)]
    problems = group_problems(_GROUPS, 2, 16000, requests, _PROFILE, _ENV, _nodes((2, 23081)))
    assert [p.split(":")[0] for p in problems] == ["rule tables", "rule realism"]
    assert problems[0].startswith("rule tables: a job asks for 43900 MB, more than resources mem_mb (16000 MB")
    assert problems[0].endswith("(--resources mem_mb=43900)")
    # no memory limit given: nothing to compare a job with (groups then refused for the missing limit)
    assert group_problems({}, None, None, requests, _PROFILE, _ENV, _nodes()) == []


def test_groups_without_limits_or_without_a_readable_node_are_refused():
    problems = group_problems(_GROUPS, None, None, [], _PROFILE, _ENV, _nodes((2, 23081)))
    assert len(problems) == 2
    assert problems[0].startswith("groups (mesh_parts, optimise_shard, search, simulate) without cores")
    assert "without resources mem_mb" in problems[1]
    (line,) = group_problems(_GROUPS, 2, 1000, [], _PROFILE, {"SBATCH_PARTITION": ""}, lambda p: "sinfo lists no node")
    assert line.startswith("the size of a node of the default partition cannot be read") and line.endswith("sinfo lists no node")
    # ungrouped: no group job to fit, sinfo not asked
    nodes = _nodes()
    assert group_problems({}, 2, 1000, [], _PROFILE, _ENV, nodes) == [] and nodes.asked == []


def test_sinfo_output_is_read_as_cpus_and_megabytes():
    def run(output="", code=0, err=""):
        calls = []

        def fake(command, **kwargs):
            calls.append(command)
            return subprocess.CompletedProcess(command, code, output, err)

        fake.calls = calls
        return fake

    fake = run("2 23081\n48+ 191000+\n")
    assert partition_nodes("main", fake) == [(2, 23081), (48, 191000)]  # "+": the line's smallest
    assert fake.calls == [["sinfo", "--noheader", "--format=%c %m", "--partition", "main"]]
    fake = run("")
    assert partition_nodes("", fake) == "sinfo --noheader --format=%c %m lists no node"
    assert fake.calls[0][-1] == "--format=%c %m"  # no partition: sinfo's default
    said = partition_nodes("gpu", run(code=1, err="sinfo: error: x\nsinfo: fatal: Could not establish a configuration source\n"))
    assert said.endswith("failed: sinfo: fatal: Could not establish a configuration source") and "\n" not in said


# --------------------------------------------------------------------------- kind 8: make report first


def test_make_report_before_the_study_says_it_must_run_first(tmp_path):
    for name in ("Makefile", "environment.lock", "pyproject.toml"):
        shutil.copy2(ROOT / name, tmp_path / name)
    venv = Path(sys.executable).parent.parent  # this venv, taken as built (-o: not remade)
    out = subprocess.run(
        ["make", "-s", "-o", str(venv / "bin" / ".installed"), "report", f"VENV={venv}"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode != 0
    assert out.stdout.strip() == ("make report: the study has not run yet (no results/tables/claims.csv): run 'make study' first")
    assert not (tmp_path / "results").exists()


# --------------------------------------------------------------------------- issue 39: the checks' own arithmetic


def test_the_object_names_include_the_defaults_a_scenario_takes_by_null():
    from synergrasp.config import object_names

    config = {"scenarios": {"a": {"objects": None}, "b": {"objects": {"obj9": {"mass_kg": 1}}}, "c": {"mu": 1}, "gone": None}}
    assert object_names(config, ["x"]) == {"x", "obj1", "obj2", "obj3", "obj4", "obj9"}
    assert object_names({"scenarios": {"c": {"mechanics": {"mu": 1.0}}}}, ["x"]) == {"x"}


def test_a_scenario_removing_an_object_the_study_lacks_names_it():
    from synergrasp.config import scenario_config

    config = {"objects": {"obj1": defaults()["objects"]["obj1"]}, "scenarios": {"s": {"objects": {"obj9": None}}}}
    with pytest.raises(
        ConfigError,
        match=r"^scenario 's': config error at 'objects.obj9': null removes an object, "
        r"but the study has no object 'obj9'; objects: \['obj1'\]$",
    ):
        scenario_config(config, "s")
    config["scenarios"]["s"] = {"objects": {"obj1": None, "obj2": {"shape": {"sphere": {"radius_mm": 20}}, "mass_kg": 1.0}}}
    assert list(scenario_config(config, "s")["objects"]) == ["obj2"]


def test_the_search_lattice_bounds_the_rank():
    """The regions at 10 mm: any x 9.5..49.5, y -50..30, z 20..180: 5 x 9 x 17 = 765 points;
    power x 9.5, z 20..100: 1 x 9 x 9 = 81; precision x 19.5..49.5, z 60..140: 4 x 9 x 9 = 324."""
    from synergrasp.config import search_lattice_size

    search = defaults()["placement"]["search"]
    assert [search_lattice_size(search, kind) for kind in ("any", "power", "precision")] == [765, 81, 324]
    assert not [p for p in _rank(81) if "search_rank" in p]
    (line,) = [p for p in _rank(82) if "search_rank" in p]  # obj3 and obj4 are power objects
    assert line.startswith(
        "config error at 'placement.search_rank': 82 exceeds the 81 points of the search "
        "lattice of obj3, obj4 (search.region_mm of its grasp type at search.spacing_mm 10 mm)"
    )


def _rank(rank: int) -> list[str]:
    from synergrasp.input_checks import checked_scenario

    config = defaults()
    config["placement"]["search_rank"] = rank
    try:
        checked_scenario(config)
    except ConfigError as err:
        return str(err).splitlines()
    return []


def test_a_search_rank_beyond_an_existing_table_is_a_problem(tmp_path):
    from synergrasp.input_checks import search_rank_problems

    cfg = validate_config({**defaults(), "placement": {**defaults()["placement"], "search_rank": 3}})
    table = tmp_path / "placement.csv"
    assert search_rank_problems(cfg, "obj1", table) == []  # no table yet: the closure judges it
    table.write_text("distinct_rank\n1\n0\n2\n")
    assert search_rank_problems(cfg, "obj1", table) == [
        f"config error at 'placement.search_rank': 3 exceeds the 2 distinct targets of obj1's placement search ({table})"
    ]
    table.write_text("distinct_rank\n1\n2\n3\n")
    assert search_rank_problems(cfg, "obj1", table) == []


@pytest.mark.parametrize(
    "shape, warned",
    [
        ({"box": {"size_mm": [30, 30, 30]}}, None),
        ({"box": {"size_mm": [0.03, 0.03, 0.03]}}, "0.052 mm across"),
        ({"sphere": {"radius_mm": 600}}, "1.2e+03 mm across"),
        ({"sphere": {"radius_mm": 0.5}}, None),  # 1 mm across: the limit itself is no warning
    ],
)
def test_an_object_far_from_a_hands_size_is_warned_naming_the_key(shape, warned):
    from synergrasp.simulation.objects import object_warnings

    lines = object_warnings({"objects": {"o": {"shape": shape, "mass_kg": 1.0}}})
    if warned is None:
        assert lines == []
    else:
        assert lines == [f"objects.o.shape: {warned}, far from what a hand grasps (1 to 1000 mm); sizes are in mm"]


def test_no_success_under_the_setting_is_one_sentence_with_its_reason():
    from synergrasp.analysis.summaries import no_success_note

    table = pd.DataFrame({"success": [False, False], "verdict_force_closure": [True, False]})
    settings = type("S", (), {"success": "force_closure_bounded", "marginal_weight_multiple": 0.001})
    assert no_success_note(table, settings).startswith(
        "no grasp succeeds under analyses.success = force_closure_bounded: none of the 1 force-closure (pose, set) "
        "rows holds the weight within analyses.marginal_weight_multiple = 0.001 times the weight"
    )
    table.loc[0, "success"] = True
    assert no_success_note(table, settings) == ""


def test_an_output_is_its_old_or_its_complete_new_content(tmp_path):
    from synergrasp.file_output import replacing, replacing_folder

    path = tmp_path / "t.csv"
    path.write_text("old")
    with pytest.raises(RuntimeError), replacing(path) as partial:
        partial.write_text("half")
        raise RuntimeError("the disk is full")
    assert path.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]
    with replacing(path) as partial:
        assert partial.suffix == ".csv" and partial.parent == tmp_path
        partial.write_text("new")
    assert path.read_text() == "new" and sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]
    folder = tmp_path / "pages"
    folder.mkdir()
    (folder / "gone.html").write_text("old page")
    with pytest.raises(RuntimeError), replacing_folder(folder) as partial:
        (partial / "a.html").write_text("half")
        raise RuntimeError
    assert [p.name for p in folder.iterdir()] == ["gone.html"]
    with replacing_folder(folder) as partial:
        (partial / "a.html").write_text("new page")
    assert [p.name for p in folder.iterdir()] == ["a.html"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pages", "t.csv"]


def test_refuse_prints_the_lines_alone_and_exits_1(capsys):
    from synergrasp.preflight import REFUSED, refuse

    refuse([])  # nothing to refuse
    with pytest.raises(SystemExit) as stop:
        refuse(["config error at 'a': b"])
    assert stop.value.code == 1
    assert capsys.readouterr().err == f"{REFUSED}\nconfig error at 'a': b\n"
