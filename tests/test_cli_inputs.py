"""Every command of the package against bad input a user can give (issue 39): one line per
problem naming the argument, the file or the key, exit status 2, no traceback, and nothing
done first (no closure run, no file written). The configuration goes through the workflow's
own check (``input_checks.checked_scenario``), so whatever the workflow refuses the command
refuses too."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from synergrasp import cli, inspector
from synergrasp.cli import main

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "config" / "small.yaml"
POSE = ["grasp", "obj1", "--alpha", "-30", "--beta", "0"]


def _besides_the_thumb(lines: list[str]) -> list[str]:
    """Standard-error lines without the study hand's thumb-opposition warning (its thumb folds
    onto the palm along S1: tests/test_thumb_check.py), which every command on it prints."""
    return [line for line in lines if "warning: thumb opposition: hand 'softhand_like'" not in line]


def _overlay(tmp_path: Path, text: str | None = None, **changes) -> str:
    path = tmp_path / "my.yaml"
    if text is None:
        config = yaml.safe_load(SMALL.read_text())
        config.update(changes)
        text = yaml.safe_dump(config, sort_keys=False)
    path.write_text(text)
    return str(path)


def _degrees_table(tmp_path: Path) -> str:
    table = pd.read_csv(ROOT / "src" / "synergrasp" / "data" / "synergies_softhand_opposed.csv")
    columns = [c for c in table.columns if c != "joint"]
    table[columns] = np.degrees(table[columns])
    path = tmp_path / "degrees.csv"
    table.to_csv(path, index=False)
    return str(path)


def _searched(tmp_path: Path, placement_csv: str | None, rank: int = 1) -> list[str]:
    results = tmp_path / "results"
    (results / "objects" / "obj1").mkdir(parents=True)
    if placement_csv is not None:
        (results / "objects" / "obj1" / "placement.csv").write_text(placement_csv)
    config = _overlay(
        tmp_path, placement={**yaml.safe_load(SMALL.read_text())["placement"], "mode": "searched", "search_rank": rank}
    )
    return ["--configfile", config, "--results", str(results)]


#: (arguments after the pose, or a function of tmp_path giving them; text every line must hold)
BAD = {
    "unknown object": (lambda t: ["--configfile", str(SMALL)], "object: 'obj9'"),
    "a drawn object without its block": (
        lambda t: ["--configfile", str(SMALL)],
        "objects drawn by random_objects are objects of a --configfile",
    ),
    "pose off the grid": (["--alpha", "7"], "--alpha/--beta"),
    "pose not a number": (["--alpha", "nan"], "--alpha/--beta"),
    "set beyond the table": (["--sets", "16"], "--sets"),
    "set not a set": (["--sets", "1-x"], "--sets"),
    "empty range": (["--sets", "5-3"], "--sets"),
    "synergy zero": (["--sets", "0"], "--sets"),
    "forces beyond the table": (["--forces", "99"], "--forces"),
    "missing overlay": (lambda t: ["--configfile", str(t / "none.yaml")], "none.yaml': cannot be read"),
    "overlay is a folder": (lambda t: ["--configfile", str(t)], "cannot be read"),
    "YAML syntax error": (lambda t: ["--configfile", _overlay(t, "objects:\n  obj1: {shape: [\n")], "not a readable YAML file"),
    "top level a list": (lambda t: ["--configfile", _overlay(t, "- a\n- b\n")], "top level must be a mapping"),
    "top level a number": (lambda t: ["--configfile", _overlay(t, "3\n")], "top level must be a mapping"),
    "not text": (lambda t: ["--configfile", str(_binary(t))], "not UTF-8 text"),
    "key written twice": (
        lambda t: ["--configfile", _overlay(t, "mechanics:\n  mu: 1\n  mu: 2\n")],
        "key 'mechanics.mu' appears twice",
    ),
    "unknown key": (
        lambda t: ["--configfile", _overlay(t, "mechanics: {muu: 1}\n")],
        "config error at 'mechanics': unknown key(s) ['muu']",
    ),
    "not a finite number": (lambda t: ["--configfile", _overlay(t, "mechanics: {mu: .nan}\n")], "config error at 'mechanics.mu'"),
    "relation broken": (
        lambda t: ["--configfile", _overlay(t, "closure: {step_mm: 0.1}\n")],
        "config error at 'closure.step_mm'",
    ),
    "synergy table in degrees": (lambda t: ["--configfile", _overlay(t, synergies=_degrees_table(t))], "exceed 2π"),
    "broken hand file": (lambda t: ["--configfile", _overlay(t, hand=str(_written(t, "hand.yaml", "palm: 3\n")))], "hand file"),
    "hand file a folder": (lambda t: ["--configfile", _overlay(t, hand=str(t))], "hand file"),
    "missing mesh": (
        lambda t: [
            "--configfile",
            _overlay(t, objects={"obj1": {"shape": {"mesh": {"path": str(t / "none.obj"), "scale": 1.0}}, "mass_kg": 1.0}}),
        ],
        "config error at 'objects.obj1.shape.mesh.path'",
    ),
    "png folder missing": (lambda t: ["--png", str(t / "no" / "g.png")], "--png"),
    "png folder a file": (lambda t: ["--png", str(_written(t, "f.txt", "x") / "g.png")], "--png"),
    "png not a png": (lambda t: ["--png", str(t / "g.txt")], "--png"),
    "png a folder": (lambda t: ["--png", str(_folder(t, "g.png"))], "--png"),
    "html folder missing": (lambda t: ["--html", str(t / "no" / "g.html")], "--html"),
    "searched without its table": (lambda t: _searched(t, None), "placement.csv, which does not exist"),
    "searched, table not a table": (lambda t: _searched(t, "a,b\n1,2\n"), "placement.csv"),
    "searched, rank beyond the table": (lambda t: _searched(t, _PLACEMENT, rank=3), "search_rank"),
}

_PLACEMENT = (
    "object,rank,chosen,distinct_rank,x_mm,y_mm,z_mm,round,n_poses,grasp_type,typed_percent,"
    "force_closure_percent,median_force_per_weight,median_contacts,distance_to_chosen_mm,"
    "stated_type,effective_type,type_reason,region_mm\n"
    "obj1,1,True,1,38.0,5.0,112.0,0,10,any,50.0,50.0,3.0,4.0,0.0,any,any,stated type feasible and scored,\n"
    "obj1,2,False,2,38.0,5.0,132.0,0,10,any,40.0,40.0,3.0,4.0,20.0,any,any,stated type feasible and scored,\n"
)


def _written(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _folder(tmp_path: Path, name: str) -> Path:
    path = tmp_path / name
    path.mkdir()
    return path


def _binary(tmp_path: Path) -> Path:
    path = tmp_path / "binary.yaml"
    path.write_bytes(b"\xff\xfe\x00mechanics")
    return path


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_input_gives_one_line_per_problem_and_does_no_work(case, tmp_path, capsys, monkeypatch):
    args, text = BAD[case]
    args = args(tmp_path) if callable(args) else ["--configfile", str(SMALL), *args]
    obj = {"unknown object": "obj9", "a drawn object without its block": "rand_305"}.get(case, "obj1")
    argv = ["grasp", obj, *POSE[2:], *args]
    closures = []
    monkeypatch.setattr("synergrasp.simulation.closure.simulate_object", lambda *a, **k: closures.append(a))
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert main(argv) == 2
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert lines and all(line.startswith("synergrasp grasp: ") for line in lines), out.err
    assert any(text in line for line in lines), out.err
    assert not out.out and not closures  # nothing printed as a result, no closure run
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written


def test_argparse_errors_and_the_console_command_print_no_traceback(tmp_path):
    for argv in (
        ["grasp", "obj1", "--alpha", "x", "--beta", "0"],
        ["grasp"],
        ["nothing"],
        POSE + ["--configfile", _overlay(tmp_path, "- a\n")],
    ):
        run = subprocess.run([sys.executable, "-m", "synergrasp.cli", *argv], capture_output=True, text=True, timeout=120)
        assert run.returncode == 2, run.stderr
        assert "Traceback" not in run.stderr and run.stderr.strip(), run.stderr


def test_output_paths_are_checked_before_the_grasp_is_printed(tmp_path, capsys):
    assert main(POSE + ["--configfile", str(SMALL), "--html", str(tmp_path / "none" / "g.html")]) == 2
    out = capsys.readouterr()
    assert out.out == "" and "folder" in out.err and str(tmp_path / "none") in out.err


def test_a_disk_error_while_writing_is_one_line(tmp_path, capsys, monkeypatch):
    """The folder is checked before the work; a write that fails afterwards (a full disk) is
    one line naming the file, exit 2, and no partial file is left."""

    def full(self, *args, **kwargs):
        raise OSError(28, "No space left on device", str(self))

    monkeypatch.setattr(Path, "write_text", full)
    page = tmp_path / "g.html"
    assert main(POSE + ["--configfile", str(SMALL), "--sets", "1", "--html", str(page)]) == 2
    err = _besides_the_thumb(capsys.readouterr().err.strip().splitlines())
    assert err == [f"synergrasp grasp: --html {page}: cannot be written (No space left on device)"]
    assert list(tmp_path.iterdir()) == []


def test_a_mesh_far_from_a_hands_size_is_warned_naming_the_key(tmp_path, capsys):
    """A 30 mm cube written in metres (0.03 units at scale 1): a warning naming the key,
    before the grasp."""
    corners = [(x, y, z) for x in (-0.015, 0.015) for y in (-0.015, 0.015) for z in (-0.015, 0.015)]
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = tmp_path / "cube_m.obj"
    mesh.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join("f " + " ".join(str(k + 1) for k in q) + "\n" for q in quads)
    )
    config = _overlay(tmp_path, objects={"obj1": {"shape": {"mesh": {"path": str(mesh), "scale": 1.0}}, "mass_kg": 1.0}})
    assert main(POSE + ["--configfile", config, "--sets", "1"]) == 0
    err = _besides_the_thumb(capsys.readouterr().err.strip().splitlines())
    assert err == [
        "synergrasp grasp: warning: objects.obj1.shape: 0.052 mm across, far from what a hand grasps "
        "(1 to 1000 mm); sizes are in mm: a file in metres needs objects.obj1.shape.mesh.scale: 1000"
    ]


def test_cli_has_one_check_of_the_configuration():
    """The command reads its configuration through the workflow's check, not a second one."""
    source = Path(cli.__file__).read_text() + Path(inspector.__file__).read_text()
    assert "checked_scenario" in source and "validate_config" not in source


# --------------------------------------------------------------------------- issue 48: every command, before the work


def _postures_file(tmp_path: Path) -> Path:
    rng = np.random.default_rng(5)
    path = tmp_path / "postures.csv"
    pd.DataFrame(rng.uniform(0, 1, (12, 3)), columns=["a", "b", "c"]).to_csv(path, index=False)
    return path


#: (argv of tmp_path with postures.csv in it, the one line expected after the command's prefix)
COMMANDS = {
    "fit over its postures": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(t / "postures.csv")],
        "--out {t}/postures.csv: is the file the command reads (POSTURES {t}/postures.csv); write to another file",
    ),
    "fit over a symbolic link to them": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(_linked(t, "link.csv", symbolic=True))],
        "--out {t}/link.csv: is the file the command reads (POSTURES {t}/postures.csv); write to another file",
    ),
    "fit over a hard link to them": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(_linked(t, "hard.csv", symbolic=False))],
        "--out {t}/hard.csv: is the file the command reads (POSTURES {t}/postures.csv); write to another file",
    ),
    "fit into a missing folder": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(t / "no/x.csv")],
        "--out {t}/no/x.csv: folder '{t}/no' is not an existing folder",
    ),
    "fit png suffix": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(t / "x.csv"), "--png", str(t / "v.pdf")],
        "--png {t}/v.pdf: the file name must end in .png",
    ),
    "fit 0 synergies": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(t / "x.csv"), "--synergies", "0"],
        "--synergies 0: must be a whole number of at least 1",
    ),
    "fit more synergies than the postures hold": (
        lambda t: ["synergies", "fit", str(t / "postures.csv"), "--out", str(t / "x.csv"), "--synergies", "4"],
        "--synergies 4: at most 3 for 12 postures of 3 joints",
    ),
    "fit postures a folder": (
        lambda t: ["synergies", "fit", str(t), "--out", str(t / "x.csv")],
        "postures file '{t}': cannot be read: is a folder; give a file",
    ),
    "hand count 0": (lambda t: ["hand", "show", "--count", "0"], "--count 0: must be a whole number of at least 1"),
    "hand png a folder": (lambda t: ["hand", "show", "--png", str(t)], "--png {t}: is a folder; give a file name"),
    "plan radius -10": (
        lambda t: ["plan", "obj4", "--radius", "-10"],
        "--radius -10: each radius must be a positive finite number of degrees",
    ),
    "plan radius nan": (
        lambda t: ["plan", "obj4", "--radius", "nan"],
        "--radius nan: each radius must be a positive finite number of degrees",
    ),
    "plan csv into a missing folder": (
        lambda t: ["plan", "obj4", "--csv", str(t / "no/p.csv")],
        "--csv {t}/no/p.csv: folder '{t}/no' is not an existing folder",
    ),
    "plan results a file": (
        lambda t: ["plan", "obj4", "--results", str(t / "postures.csv")],
        "--results {t}/postures.csv: is a file; give the folder of the study's outputs",
    ),
    "grasp results a file": (
        lambda t: [*POSE, "--results", str(t / "postures.csv")],
        "--results {t}/postures.csv: is a file; give the folder of the study's outputs",
    ),
}


def _linked(tmp_path: Path, name: str, symbolic: bool) -> Path:
    link = tmp_path / name
    (link.symlink_to if symbolic else link.hardlink_to)(tmp_path / "postures.csv")
    return link


@pytest.mark.parametrize("case", list(COMMANDS), ids=list(COMMANDS))
def test_every_command_checks_its_arguments_and_outputs_first(case, tmp_path, capsys, monkeypatch):
    postures = _postures_file(tmp_path)
    argv = COMMANDS[case][0](tmp_path)
    expected = COMMANDS[case][1].format(t=tmp_path)
    for work in (
        "synergrasp.hand.synergy_fit.fit_synergies",
        "synergrasp.analysis.plan_study.plan_object",
        "synergrasp.hand.checks.check_hand",
    ):
        monkeypatch.setattr(work, lambda *a, **k: pytest.fail("work done before the arguments were checked"))
    before = {p: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    assert main(argv) == 2
    out = capsys.readouterr()
    prefix = "synergrasp " + " ".join(argv[:2] if argv[0] in ("synergies", "hand") else argv[:1]) + ": "
    assert out.err.strip().splitlines() == [prefix + expected] and out.out == ""
    assert {p: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before
    assert postures.read_bytes() == before[postures]
