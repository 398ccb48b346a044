"""Bad input against a finished run of the small config (issue 27), one kind at a time, each
on a fresh copy of the run: the run stops before any job with one line naming the file or the
key, and every earlier result is byte-identical afterwards; an object that can never be
grasped is said in the log and in the tables with the reason. Cheap where no job should
start: the up-front check (or a dry run) is the whole run."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from test_workflow import ROOT, SMALL, digest, snakemake
from test_workflow import command as snakemake_command

pytestmark = pytest.mark.workflow


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    workdir = tmp_path_factory.mktemp("finished")
    out = snakemake(workdir, "-j2", "figures")
    assert out.returncode == 0, out.stderr[-5000:]
    return workdir


@pytest.fixture
def run(finished, tmp_path) -> Path:
    """A fresh copy of the finished run (results and Snakemake's records, times kept)."""
    copy = tmp_path / "run"
    shutil.copytree(finished, copy, symlinks=True)
    return copy


def _results(workdir: Path) -> dict[str, str]:
    return digest([p for p in (workdir / "results").rglob("*") if p.is_file()])


def _overlay(tmp_path: Path, **changes) -> Path:
    config = yaml.safe_load(SMALL.read_text())
    config.update(changes)
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    return path


def _refused(run: Path, configfile: Path, *args: str, env=None) -> str:
    """Run ``figures`` with ``configfile``: it must fail before any job and change no result;
    returns its output."""
    before = _results(run)
    out = snakemake(run, "-j2", "figures", *args, configfile=configfile, env=env)
    text = out.stdout + out.stderr
    assert out.returncode != 0, text[-3000:]
    assert "rule simulate" not in text and "Select jobs to execute" not in text, text[-3000:]
    assert _results(run) == before
    return text


def _one_line(text: str, *parts: str) -> str:
    lines = [line for line in text.splitlines() if all(p in line for p in parts)]
    assert len(lines) == 1, text[-3000:]
    return lines[0]


# --------------------------------------------------------------------------- kind 1: hand files


def _hand(tmp_path: Path, mutate) -> Path:
    doc = yaml.safe_load((ROOT / "src" / "synergrasp" / "data" / "hand.yaml").read_text())
    mutate(doc)
    path = tmp_path / "hand.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d["palm"].update(shapes=[]), "palm.shapes"),
        (
            lambda d: d["palm"].update(shapes=[{"capsule": {"from_mm": [0, 0, 20], "to_mm": [0, 0, 80], "radius_mm": 20}}]),
            "palm.shapes",
        ),
        (lambda d: d["fingers"]["index"]["joints"][2].pop("shapes"), "fingers.index.joints[2].shapes"),
    ],
    ids=["no palm shape", "capsule palm", "link without shapes"],
)
def test_a_hand_the_closure_cannot_use_starts_no_job(run, tmp_path, mutate, field):
    hand = _hand(tmp_path, mutate)
    text = _refused(run, _overlay(tmp_path, hand=str(hand)))
    _one_line(text, f"hand file '{hand}': {field}: the closure needs")


def test_a_hand_far_from_a_human_hand_is_warned_naming_the_field(run, tmp_path):
    hand = _hand(tmp_path, lambda d: d["fingers"]["index"]["joints"][1].update(offset_mm=[-9000.0, 0.0, 0.0]))
    before = _results(run)
    out = snakemake(run, "-n", "figures", configfile=_overlay(tmp_path, hand=str(hand)))
    assert out.returncode == 0, out.stderr[-3000:]
    _one_line(
        out.stdout + out.stderr,
        f"hand file '{hand}': fingers.index.joints[1] (index_mcp) offset: 9000 mm is far from a human hand's dimensions",
    )
    assert _results(run) == before


# --------------------------------------------------------------------------- kind 3: never graspable


def test_an_object_that_can_never_be_grasped_is_said_with_its_reason(run, tmp_path):
    """obj1 brought toward a point 1 m in front of the palm: no closure touches it. The run
    says so, the graspable-objects table gives the reason, and obj4's results are untouched."""
    config = yaml.safe_load(SMALL.read_text())
    config["objects"]["obj1"]["placement"] = {"approach_point_mm": [1000.0, 0.0, 0.0]}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config))
    obj4 = {p: d for p, d in _results(run).items() if "/objects/obj4/" in p}
    out = snakemake(run, "-j2", "figures", configfile=path)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    reason = "nothing touched: no closure ends touching the box (no_contact: 84)"
    _one_line(text, f"WARNING: obj1 can never be grasped: {reason}")
    table = pd.read_csv(run / "results" / "tables" / "graspable_objects.csv").set_index("object")
    assert table.loc["obj1", "reason"] == reason
    assert not table.loc["obj1", "graspable"] and table.loc["obj4", "graspable"]
    assert reason in (run / "results" / "logs" / "realism.log").read_text()
    assert {p: d for p, d in _results(run).items() if "/objects/obj4/" in p} == obj4


def test_a_settle_window_longer_than_the_time_limit_allows_is_a_config_error(run, tmp_path):
    config = yaml.safe_load(SMALL.read_text())
    config["closure"]["dynamic"]["settle_window_s"] = 0.8
    text = _refused(run, _overlay(tmp_path, closure=config["closure"]))
    _one_line(text, "config error at 'closure.dynamic.settle_window_s': 0.8 s leaves no pose able to settle")


def test_a_mesh_file_that_bounds_no_solid_starts_no_job(run, tmp_path):
    """A box mesh with one face missing: one line naming the object's key, before any job."""
    corners = [(x, y, z) for x in (-15, 15) for y in (-15, 15) for z in (-15, 15)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4)]  # no sixth face
    mesh = tmp_path / "open.obj"
    mesh.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join("f " + " ".join(str(k + 1) for k in q) + "\n" for q in quads)
    )
    config = yaml.safe_load(SMALL.read_text())
    config["objects"]["obj1"] = {"shape": {"mesh": {"path": str(mesh), "scale": 1.0}}, "mass_kg": 1.0}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config))
    text = _refused(run, path)
    _one_line(text, "config error at 'objects.obj1.shape.mesh.path'", "is not closed: 4 edges belong to one triangle")


# --------------------------------------------------------------------------- kind 4: SLURM profile


def test_the_slurm_profile_in_a_shell_that_cannot_submit_starts_no_job(run, tmp_path):
    (run / "results" / "tables" / "claims.csv").unlink()  # a local job would remake it
    tools = tmp_path / "bin"  # a PATH with a shell and nothing of SLURM
    tools.mkdir()
    for name in ("bash", "which"):
        os.symlink(shutil.which(name), tools / name)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SBATCH_")}
    env["PATH"] = str(tools)
    text = _refused(run, SMALL, "--workflow-profile", str(ROOT / "profiles" / "slurm"), env=env)
    line = _one_line(text, "The SLURM profile cannot run this workflow here, nothing was run:")
    assert "$SBATCH_ACCOUNT is not set" in line and "$SBATCH_PARTITION is not set" in line
    assert "not on PATH: sbatch, scancel, sacct or squeue" in line
    assert not (run / "results" / "tables" / "claims.csv").exists()


# --------------------------------------------------------------------------- kind 5: names


def test_a_name_ending_in_a_repeated_digit_is_planned_like_any_other(run, tmp_path):
    config = yaml.safe_load(SMALL.read_text())
    config["objects"] = {"obj_" + "0" * 20: config["objects"]["obj1"], "obj4": config["objects"]["obj4"]}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config))
    before = _results(run)
    out = snakemake(run, "-n", "figures", configfile=path)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "results/objects/obj_00000000000000000000/contacts.parquet" in out.stdout + out.stderr
    assert _results(run) == before


def test_a_300_character_name_is_refused_naming_the_key(run, tmp_path):
    config = yaml.safe_load(SMALL.read_text())
    config["objects"]["o" * 300] = config["objects"].pop("obj1")
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config))
    _one_line(_refused(run, path), "config error at 'objects': name 'oooo", "(300 characters)", "at most 64")


# --------------------------------------------------------------------------- kind 6: repeated keys


def test_a_repeated_scenario_is_refused_naming_the_file_and_the_key(run, tmp_path):
    path = tmp_path / "my.yaml"
    path.write_text(SMALL.read_text() + "scenarios:\n  s: {mechanics: {mu: 1.0}}\n  s: {mechanics: {mu: 2.0}}\n")
    lines = len(SMALL.read_text().splitlines())
    _one_line(_refused(run, path), f"config file '{path}', line {lines + 3}: key 'scenarios.s' appears twice")


def test_a_repeated_key_in_a_hand_file_is_refused_naming_it(run, tmp_path):
    hand = tmp_path / "hand.yaml"
    text = (ROOT / "src" / "synergrasp" / "data" / "hand.yaml").read_text()
    hand.write_text(text.replace("palm_normal: [1.0, 0.0, 0.0]\n", "palm_normal: [1.0, 0.0, 0.0]\n" * 2, 1))
    _one_line(_refused(run, _overlay(tmp_path, hand=str(hand))), f"hand file '{hand}'", "key 'palm_normal' appears twice")


# --------------------------------------------------------------------------- kind 7: errors inside jobs


def test_an_unreadable_input_inside_a_job_names_the_file(run):
    gfo = run / "results" / "objects" / "obj1" / "gfo.parquet"
    gfo.write_bytes(b"not a parquet file")
    out = snakemake(run, "-j1", "results/tables/grasp_realism.csv", "--forcerun", "realism")
    assert out.returncode != 0
    log = (run / "results" / "logs" / "realism.log").read_text()
    assert "ValueError: gfo table 'results/objects/obj1/gfo.parquet': cannot be read as Parquet" in log


# A gfo table of an older version is refused before any job: tests/test_user_input_kinds.py (kind 7).


# --------------------------------------------------------------------------- issue 39: what a new user can still break
# One test (or table) per kind, each on a fresh copy of the finished small run.


def _with_scenario(tmp_path: Path, overlay: dict) -> Path:
    config = yaml.safe_load(SMALL.read_text())
    config["scenarios"] = {"s": overlay}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    return path


def _no_frames(text: str) -> None:
    """No Python or Snakemake traceback: no frame lines, no exception names of the workflow."""
    assert "Traceback" not in text and '  File "' not in text and "Exception in" not in text, text[-3000:]


#: Every overlay form config/README.md documents, as a scenario of the small study, and a file
#: the plan must hold.
OVERLAY_FORMS = {
    "a mapping merges": ({"mechanics": {"mu": 1.0}}, "results/scenarios/s/objects/obj1/gfo.parquet"),
    "a list replaces": ({"analyses": {"fig4": {"panel_k": [1, 15]}}}, "results/scenarios/s/objects/obj1/fig4_"),
    "null: a key takes its default": (
        {"analyses": {"minima_radius_deg": None}},
        "results/scenarios/s/objects/obj1/minima.parquet",
    ),
    "null: objects take their default": ({"objects": None}, "results/scenarios/s/objects/obj2/gfo.parquet"),
    "null: an object is dropped": ({"objects": {"obj1": None}}, "results/scenarios/s/tables/claims.csv"),
    "a new object": (
        {"objects": {"obj5": {"shape": {"sphere": {"radius_mm": 20}}, "mass_kg": 0.5}}},
        "results/scenarios/s/objects/obj5/contacts.parquet",
    ),
}


@pytest.mark.parametrize("form", list(OVERLAY_FORMS), ids=list(OVERLAY_FORMS))
def test_every_documented_overlay_form_is_planned(run, tmp_path, form):
    """Kind 1: `scenarios: {s: {objects: null}}` was a MissingInputException (its default
    objects were not among the workflow's object names)."""
    overlay, planned = OVERLAY_FORMS[form]
    before = _results(run)
    out = snakemake(run, "-n", "scenario_s", configfile=_with_scenario(tmp_path, overlay))
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    assert planned in text, text[-3000:]
    assert _results(run) == before


def test_a_removed_scenario_and_an_overlay_on_the_shipped_study_are_planned(run, tmp_path):
    """Kind 1, the main configuration's forms: `scenarios: {<name>: null}` and an overlay on
    config/config.yaml (without --replace-workflow-config) dropping objects."""
    path = tmp_path / "my.yaml"
    path.write_text("objects: {obj2: null, obj3: null}\nscenarios: {mu_1_0: null}\n")
    before = _results(run)
    command = [a for a in snakemake_command(run, "-n", "sensitivity", configfile=path) if a != "--replace-workflow-config"]
    out = subprocess.run(command, capture_output=True, text=True, timeout=600)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    assert "results/scenarios/mu_1_0/" not in text and "results/objects/obj2/" not in text
    assert "results/objects/obj4/contacts.parquet" in text
    assert _results(run) == before


def _grasp(run: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "synergrasp.cli", "grasp", *args], cwd=run, capture_output=True, text=True, timeout=600
    )


def test_the_inspector_refuses_what_the_workflow_refuses_with_the_same_line(run, tmp_path):
    """Kind 2: a synergy table in degrees; a key written twice in the overlay."""
    table = pd.read_csv(ROOT / "src" / "synergrasp" / "data" / "synergies_softhand_opposed.csv")
    columns = [c for c in table.columns if c != "joint"]
    table[columns] = table[columns] * 180.0 / 3.141592653589793
    degrees = tmp_path / "degrees.csv"
    table.to_csv(degrees, index=False)
    twice = tmp_path / "twice.yaml"
    twice.write_text(SMALL.read_text() + "solver: {pose_shards: 1}\n")
    for configfile, expected in (
        (_overlay(tmp_path, synergies=str(degrees)), "exceed 2π"),
        (twice, "key 'solver' appears twice"),
    ):
        before = _results(run)
        line = _one_line(_refused(run, configfile), expected)
        out = _grasp(run, "obj1", "--alpha", "-30", "--beta", "0", "--configfile", str(configfile))
        assert out.returncode == 2 and out.stdout == "", out.stdout + out.stderr
        assert out.stderr.strip().splitlines() == [f"synergrasp grasp: {line}"]
        assert _results(run) == before


@pytest.mark.parametrize(
    "args, names",
    [
        (["--html", "no/such/folder/g.html"], "--html no/such/folder/g.html: folder 'no/such/folder'"),
        (["--png", "results/tables/claims.csv/g.png"], "--png results/tables/claims.csv/g.png"),
        (["--configfile", "results/tables/claims.csv"], "not a readable YAML file"),
        (["--configfile", "results"], "config file 'results': cannot be read"),
    ],
    ids=["html folder missing", "png folder a file", "overlay not YAML", "overlay a folder"],
)
def test_the_inspectors_errors_are_one_line_before_any_work(run, args, names):
    """Kind 3: output paths and overlays checked before the grasp, one line, exit 2."""
    before = _results(run)
    out = _grasp(run, "obj1", "--alpha", "-30", "--beta", "0", "--configfile", str(SMALL), *args)
    assert out.returncode == 2 and out.stdout == "", out.stdout + out.stderr
    _no_frames(out.stderr)
    assert len(out.stderr.strip().splitlines()) == 1 and names in out.stderr, out.stderr
    assert _results(run) == before


def test_a_search_rank_no_search_can_reach_starts_no_job(run, tmp_path):
    """Kind 4: `search_rank: 999` ran both searches and then lost obj4's contacts; the lattice
    of the small study's search region has 765 points, so the rank is refused up front."""
    placement = {**yaml.safe_load(SMALL.read_text())["placement"], "mode": "searched", "search_rank": 999}
    text = _refused(run, _overlay(tmp_path, placement=placement))
    _one_line(text, "config error at 'placement.search_rank': 999 exceeds the 765 points of the search lattice of obj1, obj4")


def test_a_search_rank_beyond_an_existing_search_table_starts_no_job(run, tmp_path):
    """Kind 4: the search's table exists: the rank is judged against it before any job."""
    table = run / "results" / "objects" / "obj1" / "placement.csv"
    table.write_text(
        "object,rank,chosen,distinct_rank,x_mm,y_mm,z_mm,round,n_poses,force_closure_percent,"
        "median_force_per_weight,median_contacts,distance_to_chosen_mm\n"
        "obj1,1,True,1,38.0,5.0,112.0,0,10,50.0,3.0,4.0,0.0\n"
        "obj1,2,False,0,38.0,5.0,122.0,0,10,49.0,3.0,4.0,10.0\n"
    )
    config = yaml.safe_load(SMALL.read_text())
    config["objects"]["obj1"]["placement"] = {"mode": "searched", "search_rank": 2}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    text = _refused(run, path)
    _one_line(
        text,
        "config error at 'objects.obj1.placement.search_rank': 2 exceeds the 1 distinct targets of "
        "obj1's placement search (results/objects/obj1/placement.csv)",
    )
    _no_frames(text)


def test_placement_claims_without_a_searched_placement_starts_no_job(run):
    """Kind 4: `snakemake placement_claims` under `mode: approach` failed inside its job."""
    before = _results(run)
    out = snakemake(run, "-j2", "placement_claims")
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "Select jobs to execute" not in text, text[-3000:]
    _one_line(text, "placement_claims: no object's placement is searched (placement.mode: approach)")
    _no_frames(text)
    assert _results(run) == before


def test_an_analysis_under_which_nothing_succeeds_is_said_in_the_log_and_the_tables(run, tmp_path):
    """Kind 5: force closure bounded by 0.001 times the weight: no grasp can hold it."""
    config = yaml.safe_load(SMALL.read_text())
    config["analyses"].update(success="force_closure_bounded", marginal_weight_multiple=0.001)
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    upstream = {p: d for p, d in _results(run).items() if p.endswith(("contacts.parquet", "gfo.parquet"))}
    out = snakemake(run, "-j2", "figures", configfile=path)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    said = "no grasp succeeds under analyses.success = force_closure_bounded: none of the"
    _one_line(text, "WARNING: " + said)
    assert said in (run / "results" / "logs" / "tables.log").read_text()
    assert said in (run / "results" / "tables" / "table2_success_rates.md").read_text().splitlines()[0]
    assert {p: d for p, d in _results(run).items() if p in upstream} == upstream


def test_a_scenario_removing_an_object_the_study_lacks_is_refused(run, tmp_path):
    """Kind 5: `objects: {obj9: null}` removed nothing, silently."""
    before = _results(run)
    out = snakemake(run, "-j2", "scenario_s", configfile=_with_scenario(tmp_path, {"objects": {"obj9": None}}))
    text = out.stdout + out.stderr
    assert out.returncode != 0 and "Select jobs to execute" not in text, text[-3000:]
    _one_line(
        text,
        "scenario 's': config error at 'objects.obj9': null removes an object, but the study has no "
        "object 'obj9'; objects: ['obj1', 'obj4']",
    )
    _no_frames(text)
    assert _results(run) == before


def _cube(tmp_path: Path, half: float) -> Path:
    corners = [(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = tmp_path / f"cube_{half:g}.obj"
    mesh.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join("f " + " ".join(str(k + 1) for k in q) + "\n" for q in quads)
    )
    return mesh


@pytest.mark.parametrize(
    "half, scale, across", [(0.015, 1.0, "0.052 mm"), (15.0, 1e6, "5.2e+07 mm")], ids=["metres at scale 1", "scale 1e6"]
)
def test_a_mesh_far_from_a_hands_size_is_warned_naming_the_key(run, tmp_path, half, scale, across):
    """Kind 6: such a mesh was only reported as never graspable, after the jobs."""
    config = yaml.safe_load(SMALL.read_text())
    config["objects"]["obj1"] = {"shape": {"mesh": {"path": str(_cube(tmp_path, half)), "scale": scale}}, "mass_kg": 1.0}
    path = tmp_path / "my.yaml"
    path.write_text(yaml.safe_dump(config))
    before = _results(run)
    out = snakemake(run, "-n", "figures", configfile=path)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-3000:]
    _one_line(
        text,
        f"Warning: objects.obj1.shape: {across} across, far from what a hand grasps (1 to 1000 mm)",
        "objects.obj1.shape.mesh.scale",
    )
    assert _results(run) == before


def test_a_scenario_error_is_its_line_alone(run, tmp_path):
    """Kind 6: the clear line was followed by about 7 frames of the workflow's code."""
    before = _results(run)
    out = snakemake(run, "-n", "scenario_s", configfile=_with_scenario(tmp_path, {"mechanics": {"muu": 1.0}}))
    text = out.stdout + out.stderr
    assert out.returncode != 0
    _one_line(text, "scenario 's': config error at 'mechanics': unknown key(s) ['muu']")
    _no_frames(text)
    assert _results(run) == before


def test_a_corrupted_intermediate_keeps_every_finished_output(run):
    """Kind 7: a corrupted contacts table made Fig. 2 and the 3-D pages rerun, fail and lose
    their outputs. Now every failed job keeps its outputs (Snakemake's `update` flag, set on
    every output by snakemake_adapter.keep_outputs_until_replaced), and the next run still redoes them."""
    contacts = run / "results" / "objects" / "obj1" / "contacts.parquet"
    contacts.write_bytes(b"not a parquet file")
    kept = {p: d for p, d in _results(run).items() if "/results/logs/" not in p}
    out = snakemake(run, "-j2", "figures")
    text = out.stdout + out.stderr
    assert out.returncode != 0, text[-3000:]
    assert "cannot be read as Parquet" in text
    assert {p: d for p, d in _results(run).items() if "/results/logs/" not in p} == kept
    assert not list(run.rglob(".*partial*"))  # no temporary output left
    plan = snakemake(run, "-n", "figures")
    assert plan.returncode == 0 and "rule fig2:" in plan.stdout, plan.stdout[-3000:]
