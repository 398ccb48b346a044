"""tools/closure_sample.py: its command line is checked before any work, and the closure runs
at the default study's searched placements (a missing one is named, not defaulted)."""

import importlib.util
from pathlib import Path

import pytest

SPEC = importlib.util.spec_from_file_location("closure_sample", Path(__file__).parents[1] / "tools" / "closure_sample.py")
closure_sample = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(closure_sample)


@pytest.mark.parametrize(
    "argv, said",
    [
        ([], "tools/closure_sample.py OUT_DIR [EVERY] [MODEL ...]"),
        (["out", "x"], "EVERY must be a whole number of at least 1, not 'x'"),
        (["out", "0"], "EVERY must be a whole number of at least 1, not '0'"),
        (["out", "6", "kinematik"], "MODEL ['kinematik'] unknown"),
        (["--pictures", "out", "p.png", "-3"], "POSE must be a whole number of at least 0, not '-3'"),
        (["--summary"], "--summary OUT_DIR"),
    ],
)
def test_a_malformed_command_line_is_named_before_any_work(argv, said, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        closure_sample._main(argv)
    assert said in str(stop.value)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_the_searched_placements_must_be_there_and_each_missing_one_is_named(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "objects" / "obj2").mkdir(parents=True)
    (tmp_path / "results" / "objects" / "obj2" / "placement.csv").write_text("")
    with pytest.raises(SystemExit) as stop:
        closure_sample.simulate(tmp_path / "out", 6, ["kinematic"])
    said = str(stop.value)
    assert "results/objects/obj1/placement.csv" in said and "results/objects/obj2/placement.csv" not in said
    assert not (tmp_path / "out").exists()
