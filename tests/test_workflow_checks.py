"""Bad input against a finished run of the small config (issue 27), one kind at a time, each
on a fresh copy of the run: the run stops before any job with one line naming the file or the
key, and every earlier result is byte-identical afterwards; an object that can never be
grasped is said in the log and in the tables with the reason. Cheap where no job should
start: the up-front check (or a dry run) is the whole run."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pandas as pd
import pytest
import yaml

from test_workflow import ROOT, SMALL, digest, snakemake

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


@pytest.mark.parametrize("mutate, field", [
    (lambda d: d["palm"].update(shapes=[]), "palm.shapes"),
    (lambda d: d["palm"].update(shapes=[{"capsule": {"from_mm": [0, 0, 20], "to_mm": [0, 0, 80], "radius_mm": 20}}]),
     "palm.shapes"),
    (lambda d: d["fingers"]["index"]["joints"][2].pop("shapes"), "fingers.index.joints[2].shapes"),
], ids=["no palm shape", "capsule palm", "link without shapes"])
def test_a_hand_the_closure_cannot_use_starts_no_job(run, tmp_path, mutate, field):
    hand = _hand(tmp_path, mutate)
    text = _refused(run, _overlay(tmp_path, hand=str(hand)))
    _one_line(text, f"hand file '{hand}': {field}: the closure needs")


def test_a_hand_far_from_a_human_hand_is_warned_naming_the_field(run, tmp_path):
    hand = _hand(tmp_path, lambda d: d["fingers"]["index"]["joints"][1].update(offset_mm=[-9000.0, 0.0, 0.0]))
    before = _results(run)
    out = snakemake(run, "-n", "figures", configfile=_overlay(tmp_path, hand=str(hand)))
    assert out.returncode == 0, out.stderr[-3000:]
    _one_line(out.stdout + out.stderr, f"hand file '{hand}': fingers.index.joints[1].offset_mm: 9000 mm is far "
                                       "from a human hand's dimensions")
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
    mesh.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners)
                    + "".join("f " + " ".join(str(k + 1) for k in q) + "\n" for q in quads))
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
    line = _one_line(text, "The SLURM profile cannot submit from this shell, nothing was run:")
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

