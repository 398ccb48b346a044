"""What a new user can still break (issue 48), one kind at a time, each on a fresh copy of a
finished run of the small config: one line per problem, prefixed, naming the key, the
argument or the file; a non-zero exit; nothing run and nothing changed (the results and the
user's own files hashed before and after)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from synergrasp.hand.checks import check_hand
from test_mjcf_hand import softhand_urdf
from test_workflow import ROOT, SMALL, digest, snakemake
from test_workflow_checks import _no_frames, finished, run  # noqa: F401  (fixtures: a fresh copy of the finished run)
from test_workflow_checks import _overlay as _config

pytestmark = pytest.mark.workflow

MANIFEST = ROOT / "config" / "examples" / "meshes" / "pybullet_random_urdfs.sha256"
#: The small study's drawn objects with n_objects 3 and seed 2018 (tests/test_workflow.py draws the same).
DRAWN = {"n_objects": 3, "seed": 2018, "longest_side_mm": [50, 110], "mass_kg": 0.1, "sha256_file": str(MANIFEST)}


def _state(run: Path, *files: Path) -> dict[str, str]:
    """Hashes of every result and of the user's ``files``."""
    return digest([p for p in (run / "results").rglob("*") if p.is_file()] + [f for f in files if f.is_file()])


def _command(run: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "synergrasp.cli", *args], cwd=run, capture_output=True, text=True, timeout=600)


def _without_thumb_warning(stderr: str) -> list[str]:
    """Standard-error lines less the thumb-opposition warning that every command prints for
    the small study's hand (its thumb folds onto the palm along S1: docs/synergies.md)."""
    return [line for line in stderr.strip().splitlines() if "warning: thumb opposition:" not in line]


def _refused_command(run: Path, args: list[str], prefix: str, *expected: str, files: tuple[Path, ...] = ()) -> None:
    """The command exits 2 with exactly the ``expected`` lines' fragments, one line each, each
    starting with ``prefix``; nothing printed on standard output; nothing changed."""
    before = _state(run, *files)
    out = _command(run, *args)
    _no_frames(out.stderr)
    lines = _without_thumb_warning(out.stderr)
    assert out.returncode == 2 and out.stdout == "", out.stdout + out.stderr
    assert len(lines) == len(expected) and all(line.startswith(prefix) for line in lines), out.stderr
    for line, fragment in zip(lines, expected):
        assert fragment in line, out.stderr
    assert _state(run, *files) == before


def _refused_run(run: Path, configfile: Path, *expected: str) -> None:
    """``snakemake figures`` stops before any job with exactly one line per ``expected``
    fragment after the refusal's first line, and changes no result."""
    before = _state(run)
    out = snakemake(run, "-j1", "figures", configfile=configfile)
    text = out.stdout + out.stderr
    assert out.returncode != 0, text[-3000:]
    _no_frames(text)
    assert "Select jobs to execute" not in text and "rule simulate" not in text, text[-3000:]
    lines = text[text.index("Invalid input, nothing was run:") :].strip().splitlines()[1:]
    assert len(lines) == len(expected), text[-3000:]
    for fragment in expected:
        assert sum(fragment in line for line in lines) == 1, text[-3000:]
    assert _state(run) == before


def _postures(run: Path, name: str = "postures.csv", m: int = 30, change=None, **to_csv) -> Path:
    rng = np.random.default_rng(4)
    frame = pd.DataFrame(
        rng.uniform(0.0, 1.2, (m, 5)), columns=["thumb_abd", "index_mcp", "index_pip", "middle_mcp", "middle_pip"]
    )
    frame = change(frame) if change else frame
    path = run / name
    frame.to_csv(path, **({"index": False} | to_csv))
    return path


# --------------------------------------------------------------------------- kind 1: input never output


@pytest.mark.parametrize("link", ["same name", "another spelling", "symbolic link", "hard link"])
def test_no_command_writes_over_the_file_it_reads(run, link):
    postures = _postures(run)
    out = {
        "same name": "postures.csv",
        "another spelling": "./results/../postures.csv",
        "symbolic link": "linked.csv",
        "hard link": "hard.csv",
    }[link]
    if link == "symbolic link":
        os.symlink(postures, run / out)
    if link == "hard link":
        os.link(postures, run / out)
    _refused_command(
        run,
        ["synergies", "fit", "postures.csv", "--out", out],
        "synergrasp synergies fit: ",
        f"--out {out}: is the file the command reads (POSTURES postures.csv)",
        files=(postures,),
    )


def test_hand_show_does_not_draw_over_its_hand_file(run):
    hand = run / "hand.png"  # a hand description with a .png name: the one output suffix it could take
    hand.write_text((ROOT / "src" / "synergrasp" / "data" / "hand.yaml").read_text())
    _refused_command(
        run,
        ["hand", "show", "hand.png", "--png", "./hand.png"],
        "synergrasp hand show: ",
        "--png ./hand.png: is the file the command reads (HAND hand.png)",
        files=(hand,),
    )


# --------------------------------------------------------------------------- kind 2: a hand in the wrong units


def test_a_urdf_hand_in_mm_is_warned_like_a_yaml_hand(run, tmp_path):
    """The same warning, from the same check, in the workflow and in `hand show`; the hand in
    metres gets none."""
    assert _command(run, "hand", "show", str(softhand_urdf(run))).stderr == ""
    hand = softhand_urdf(run, 1000.0)
    (warning,) = check_hand(hand)[2]  # tests/test_mjcf_hand.py checks the line itself
    assert "lengths exceed 250 mm" in warning and warning.endswith("lengths are in m, not mm")
    out = _command(run, "hand", "show", str(hand))
    assert out.returncode == 0 and _without_thumb_warning(out.stderr) == [f"synergrasp hand show: warning: {warning}"]
    before = _state(run)
    planned = snakemake(run, "-n", "figures", configfile=_config(tmp_path, hand=str(hand)))
    text = planned.stdout + planned.stderr
    assert planned.returncode == 0, text[-3000:]
    assert sum(warning in line for line in text.splitlines()) == 1, text[-3000:]
    assert _state(run) == before


# --------------------------------------------------------------------------- kind 3: drawn objects


def test_an_object_named_like_a_drawn_one_is_refused_naming_both(run, tmp_path):
    objects = {
        **yaml.safe_load(SMALL.read_text())["objects"],
        "rand_305": {"shape": {"sphere": {"radius_mm": 20}}, "mass_kg": 0.5},
    }
    _refused_run(
        run,
        _config(tmp_path, objects=objects, random_objects=DRAWN),
        "config error at 'objects.rand_305': an object of the configuration has the name of an object "
        "random_objects draws (rand_305)",
    )


def test_a_random_objects_block_in_a_scenario_is_refused_in_one_line(run, tmp_path):
    before = _state(run)
    out = snakemake(run, "-n", "scenario_s", configfile=_config(tmp_path, scenarios={"s": {"random_objects": DRAWN}}))
    text = out.stdout + out.stderr
    assert out.returncode != 0 and _state(run) == before, text[-3000:]
    _no_frames(text)
    assert (
        sum("config error at 'scenarios.s.random_objects': a scenario cannot draw objects" in line for line in text.splitlines())
        == 1
    ), text[-3000:]


def test_grasp_knows_the_drawn_objects(run, tmp_path):
    """`synergrasp grasp rand_305` finds the object the workflow studies: here its pose is off the
    grid, the first check that needs the object (no closure runs)."""
    _refused_command(
        run,
        ["grasp", "rand_305", "--alpha", "7", "--beta", "0", "--configfile", str(_config(tmp_path, random_objects=DRAWN))],
        "synergrasp grasp: ",
        "--alpha/--beta",
    )


# --------------------------------------------------------------------------- kind 4: postures to question

POSTURE_CASES = {
    "identical postures": (lambda f: f.iloc[[0] * len(f)].reset_index(drop=True), {}, "the 30 postures do not differ"),
    "saved with its index": (None, {"index": True}, "column 1 has no joint name"),
    "index as a column": (lambda f: f.reset_index(), {}, "column 1 ('index') counts the rows"),
    "degrees": (lambda f: f * 180.0 / np.pi, {}, "30 of 30 postures have angles beyond 2π"),
    "one posture at 50 rad": (
        lambda f: f.assign(index_pip=[50.0] + list(f.index_pip[1:])),
        {},
        "row(s) 1 beyond a full turn (row 1, joint 'index_pip' is 50 rad",
    ),
}


@pytest.mark.parametrize("case", list(POSTURE_CASES), ids=list(POSTURE_CASES))
def test_synergies_fit_questions_its_postures(run, case):
    change, to_csv, expected = POSTURE_CASES[case]
    postures = _postures(run, change=change, **to_csv)
    _refused_command(
        run,
        ["synergies", "fit", "postures.csv", "--out", "fitted.csv"],
        "synergrasp synergies fit: ",
        f"postures file 'postures.csv': {expected}",
        files=(postures,),
    )
    assert not (run / "fitted.csv").exists()


# --------------------------------------------------------------------------- kind 5: random_objects values

RANDOM_CASES = {
    "n_objects -1": ({"n_objects": -1}, ["'random_objects.n_objects': -1 is less than the minimum of 1"]),
    "n_objects 1e9": ({"n_objects": 1000000000}, ["'random_objects.n_objects': 1000000000 is greater than"]),
    "n_objects three": ({"n_objects": "three"}, ["'random_objects.n_objects': 'three' is not of type 'integer'"]),
    "seed abc and -1 objects": ({"seed": "abc", "n_objects": -1}, ["'random_objects.n_objects'", "'random_objects.seed': 'abc'"]),
    "seed -1": ({"seed": -1}, ["'random_objects.seed': -1 is less than the minimum of 0"]),
    "reversed sides": ({"longest_side_mm": [110, 50]}, ["'random_objects.longest_side_mm': [110, 50] is reversed"]),
    "three sides": ({"longest_side_mm": [50, 80, 110]}, ["'random_objects.longest_side_mm': [50, 80, 110] is too long"]),
    "missing manifest": ({"sha256_file": "none.sha256"}, ["none.sha256' cannot be read"]),
    "missing key": ({"seed": None}, ["'random_objects': 'seed' is a required property"]),
    "mass 0": ({"mass_kg": 0}, ["'random_objects.mass_kg': 0 is less than or equal to the minimum of 0"]),
}


@pytest.mark.parametrize("case", list(RANDOM_CASES), ids=list(RANDOM_CASES))
def test_random_objects_values_are_checked_before_any_is_used(run, tmp_path, case):
    changes, expected = RANDOM_CASES[case]
    block = {k: v for k, v in (DRAWN | changes).items() if v is not None}
    _refused_run(
        run, _config(tmp_path, random_objects=block), *(f"config error at {e}" if e.startswith("'") else e for e in expected)
    )


# --------------------------------------------------------------------------- kind 6: outputs before the work

OUTPUT_CASES = {
    "fit into a missing folder": (
        ["synergies", "fit", "postures.csv", "--out", "/nonexistent/x.csv"],
        "--out /nonexistent/x.csv: folder '/nonexistent' is not an existing folder",
    ),
    "fit out not a csv": (["synergies", "fit", "postures.csv", "--out", "x.txt"], "--out x.txt: the file name must end"),
    "fit out a folder": (["synergies", "fit", "postures.csv", "--out", "results"], "--out results: is a folder"),
    "fit png into a missing folder": (
        ["synergies", "fit", "postures.csv", "--out", "x.csv", "--png", "no/v.png"],
        "--png no/v.png: folder 'no'",
    ),
    "fit png suffix": (
        ["synergies", "fit", "postures.csv", "--out", "x.csv", "--png", "v.jpg"],
        "--png v.jpg: the file name must end in .png",
    ),
    "fit 0 synergies": (["synergies", "fit", "postures.csv", "--out", "x.csv", "--synergies", "0"], "--synergies 0"),
    "hand count 0": (["hand", "show", "--count", "0"], "--count 0: must be a whole number of at least 1"),
    "hand png into a missing folder": (["hand", "show", "--png", "no/h.png"], "--png no/h.png: folder 'no'"),
    "hand png suffix": (["hand", "show", "--png", "h.svg"], "--png h.svg: the file name must end in .png"),
    "plan radius -10": (["plan", "obj4", "--radius", "-10"], "--radius -10: each radius must be a positive"),
    "plan radius nan": (["plan", "obj4", "--radius", "10", "nan"], "--radius nan: each radius must be a positive"),
    "plan csv into a missing folder": (["plan", "obj4", "--csv", "no/plan.csv"], "--csv no/plan.csv: folder 'no'"),
}


@pytest.mark.parametrize("case", list(OUTPUT_CASES), ids=list(OUTPUT_CASES))
def test_every_command_checks_its_outputs_before_the_work(run, case):
    args, expected = OUTPUT_CASES[case]
    postures = _postures(run)
    prefix = "synergrasp " + " ".join(args[:2] if args[0] in ("synergies", "hand") else args[:1]) + ": "
    if args[0] == "plan":
        args = [*args, "--configfile", str(SMALL)]
    listed = sorted(p.name for p in run.iterdir())
    _refused_command(run, args, prefix, expected, files=(postures,))
    assert sorted(p.name for p in run.iterdir()) == listed


# --------------------------------------------------------------------------- kind 7: an older results folder


def test_an_older_results_folder_is_refused_before_any_job(run):
    """A gfo table with the old column names: one line naming the file, before any job (it
    was refused from inside two jobs, each traceback printed twice)."""
    gfo = run / "results" / "objects" / "obj1" / "gfo.parquet"
    pd.read_parquet(gfo).rename(columns={"load_feasible": "force_closure", "force_closure_def1": "strict_internal"}).to_parquet(
        gfo
    )
    _refused_run(
        run,
        SMALL,
        "gfo table 'results/objects/obj1/gfo.parquet': written by an older version of the study "
        "(column 'force_closure' (now 'load_feasible'), 'strict_internal' (now "
        "'force_closure_def1')); delete it (or its results folder) and rerun the study",
    )
    _refused_command(
        run,
        ["plan", "obj1", "--configfile", str(SMALL)],
        "synergrasp plan: ",
        "gfo table 'results/objects/obj1/gfo.parquet': written by an older version",
    )


# --------------------------------------------------------------------------- kind 8: messages naming the right thing


def test_a_search_region_of_the_wrong_length_names_the_axis(run, tmp_path):
    placement = {
        **yaml.safe_load(SMALL.read_text())["placement"],
        "search": {"region_mm": {"power": {"x": [0, 10, 20], "y": [0, 10], "z": [0, 10]}}},
    }
    _refused_run(
        run,
        _config(tmp_path, placement=placement),
        "config error at 'placement.search.region_mm.power.x': [0, 10, 20] is too long",
    )


def test_a_folder_given_for_a_model_file_says_so(run, tmp_path):
    description = run / "folder_hand.yaml"
    description.write_text("mjcf: .\npalm: palm\nfingers: {}\n")
    _refused_run(
        run,
        _config(tmp_path, hand=str(description)),
        f"hand file '{description}': mjcf: '{run}' is a folder; give the model's file",
    )
