"""Objects drawn from pybullet's random meshes: the draw, the scale rule, the sha256 check and
the meshes left out with their reason; and the summary across objects on hand-made tables."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.graspability import studied, with_left_out
from synergrasp.analysis.objects_summary import across_objects, object_rows, planner_budget
from synergrasp.config import ConfigError
from synergrasp.simulation import random_objects as ro

BOX = Path(__file__).parent / "data" / "box_30x60x100.obj"  # 30 x 60 x 100 units


def _fake_package(tmp_path: Path, monkeypatch) -> Path:
    """A pybullet_data with 4 meshes: 000 a box, 001 a box edited after the manifest,
    002 missing, 003 an open surface (one face); and its manifest."""
    data = tmp_path / "pybullet_data"
    for i in range(4):
        (data / "random_urdfs" / f"{i:03d}").mkdir(parents=True)
    shutil.copy(BOX, data / "random_urdfs/000/000.obj")
    shutil.copy(BOX, data / "random_urdfs/001/001.obj")
    (data / "random_urdfs/003/003.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    lines = []
    for i in range(4):
        path = data / f"random_urdfs/{i:03d}/{i:03d}.obj"
        digest = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "0" * 64
        lines.append(f"{digest}  random_urdfs/{i:03d}/{i:03d}.obj")
    (tmp_path / "manifest.sha256").write_text("\n".join(lines) + "\n")
    with open(data / "random_urdfs/001/001.obj", "a") as handle:
        handle.write("# edited\n")
    monkeypatch.setattr(ro, "_data_path", lambda: data)
    monkeypatch.setattr(ro, "N_MESHES", 4)
    return data


def test_every_drawn_mesh_is_studied_or_left_out_with_its_reason(tmp_path, monkeypatch):
    _fake_package(tmp_path, monkeypatch)
    spec = {"n_objects": 4, "seed": 7, "longest_side_mm": [50, 110], "mass_kg": 0.1, "sha256_file": "manifest.sha256"}
    drawn = ro.drawn_objects(spec, tmp_path)
    assert [d.name for d in drawn] == ["rand_000", "rand_001", "rand_002", "rand_003"]
    # the sizes: the rule's own draw, after the indices
    rng = np.random.default_rng(7)
    rng.choice(4, size=4, replace=False)
    sides = rng.uniform(50, 110, size=4)
    box, edited, missing, flat = drawn
    assert box.problem == "" and box.longest_side_mm == pytest.approx(sides[0])
    assert box.scale == pytest.approx(sides[0] / 100.0)  # the box's longest side is 100 units
    assert edited.problem == "sha256 differs from the manifest"
    assert missing.problem.startswith("file missing")
    assert flat.problem.startswith("mesh cannot be read")
    # the reasons and the table's rows name each mesh within the package, never this checkout
    assert missing.problem == "file missing: pybullet_data/random_urdfs/002/002.obj"
    assert "'pybullet_data/random_urdfs/003/003.obj'" in flat.problem and str(tmp_path) not in flat.problem
    assert flat.row()["path"] == "pybullet_data/random_urdfs/003/003.obj" and flat.path.startswith(str(tmp_path))
    assert ro.left_out(spec, [tmp_path / "manifest.sha256"]) == [(d.name, d.problem) for d in (edited, missing, flat)]
    assert ro.left_out(None, []) == []
    config = {"objects": {"obj1": None}, "random_objects": spec}
    ro.add_random_objects(config, tmp_path)
    assert list(config["objects"]) == ["obj1", "rand_000"]
    assert config["objects"]["rand_000"] == {"shape": {"mesh": {"path": box.path, "scale": box.scale}}, "mass_kg": 0.1}


def test_the_installed_package_matches_the_shipped_manifest():
    root = Path(__file__).resolve().parents[1]
    spec = {
        "n_objects": 3,
        "seed": 2018,
        "longest_side_mm": [50, 110],
        "mass_kg": 0.1,
        "sha256_file": "config/examples/meshes/pybullet_random_urdfs.sha256",
    }
    drawn = ro.drawn_objects(spec, root)
    expected = np.sort(np.random.default_rng(2018).choice(1000, 3, replace=False))
    assert [d.index for d in drawn] == expected.tolist()
    assert [d.problem for d in drawn] == ["", "", ""]
    assert all(50 <= d.longest_side_mm <= 110 and d.scale > 0 for d in drawn)


def test_summary_rows_and_intervals_from_hand_made_tables():
    rates = pd.DataFrame(
        {
            "object": ["a"] * 5,
            "view": "object",
            "set_id": ["1", "1-2", "1-2-3", "2", "3"],
            "success_rate": [40.0, 100.0, 100.0, 50.0, 10.0],
        }
    )
    preservation = pd.DataFrame({"object": ["a", "a"], "k": [1.0, np.nan], "preserved_percent": [50.0, 75.0]})
    graspable = pd.DataFrame({"object": ["a"], "graspable": [True], "reason": [np.nan], "force_closure_full_set": [9]})
    plans = pd.DataFrame(
        {
            "object": ["a"],
            "radius_deg": [10.0],
            "solve_share_percent": [12.5],
            "regret_percent": [3.0],
            "is_global_min": [False],
            "best_pose": [4],
        }
    )
    enrollment = pd.DataFrame(
        {"object": "a", "k": [1, 2, 3], "greedy_added": [2, 1, 3], "greedy_success_rate": [50.0, 100.0, 100.0]}
    )
    rows = object_rows(rates, preservation, graspable, plans, enrollment, n_full=3, hierarchy_first=3)
    row = rows.iloc[0]
    assert row["preserved_percent"] == 75.0 and row["s1_minus_best_other"] == -10.0
    assert row["k_full"] == 2 and row["greedy_k_full"] == 2 and row["greedy_order"] == "2-1-3"
    assert row["solve_share_percent_10"] == 12.5 and not row["global_min_10"]
    summary = across_objects(pd.concat([rows] * 3, ignore_index=True), ["k_full", "global_min_10"]).set_index("quantity")
    assert summary.loc["k_full", "mean"] == 2 and summary.loc["k_full", "low"] == 2 and summary.loc["k_full", "n_objects"] == 3
    assert summary.loc["global_min_10", "mean"] == 0.0 and summary.loc["global_min_10", "unit"] == "% of objects"
    # a mesh left out before the study: a row of the graspable table, then of the summary, with
    # its reason and no value, so the intervals over objects do not count it
    both = with_left_out(graspable, [("rand_439", "mesh cannot be read: non-manifold")])
    assert both["object"].tolist() == ["a", "rand_439"] and not both["graspable"].iloc[1]
    assert both["reason"].iloc[1] == "left out: mesh cannot be read: non-manifold" and both["poses"].iloc[1] == 0
    assert studied(both)["object"].tolist() == ["a"]
    rows = object_rows(rates, preservation, both, plans, enrollment, n_full=3, hierarchy_first=3)
    assert rows["reason"].iloc[1] == "left out: mesh cannot be read: non-manifold"
    assert np.isnan(rows["k_full"].iloc[1]) and np.isnan(rows["preserved_percent"].iloc[1])
    assert across_objects(rows, ["k_full"]).set_index("quantity").loc["k_full", "n_objects"] == 1


def test_planner_budget_counts_objects_within_each_aim():
    """Four objects at two radii, counted by hand: the aims are <= 20 % of the solves and a
    regret <= 5 %; an object without a plan (NaN) is not counted."""
    rows = pd.DataFrame(
        {
            "solve_share_percent_10": [12.0, 20.0, 35.0, np.nan],
            "regret_percent_10": [0.0, 7.5, 1.0, np.nan],
            "solve_share_percent_20": [60.0, 70.0, 90.0, np.nan],
            "regret_percent_20": [0.0, 5.0, 0.0, np.nan],
        }
    )
    budget = planner_budget(rows, [10.0, 20.0, 30.0]).set_index("radius_deg")
    assert budget.loc[10.0, ["objects", "within_solves", "within_regret", "within_both"]].tolist() == [3, 2, 2, 1]
    assert not budget.loc[10.0, "every_object_within_regret"]
    assert budget.loc[20.0, ["objects", "within_solves", "within_regret", "within_both"]].tolist() == [3, 0, 3, 0]
    assert budget.loc[20.0, "every_object_within_regret"]
    assert budget.loc[30.0, "objects"] == 0 and not budget.loc[30.0, "every_object_within_regret"]


@pytest.mark.parametrize(
    "changes, lines",
    [
        ({"n_objects": -1}, ["config error at 'random_objects.n_objects': -1 is less than the minimum of 1"]),
        (
            {"n_objects": "three", "seed": -1},
            [
                "config error at 'random_objects.n_objects': 'three' is not of type 'integer'",
                "config error at 'random_objects.seed': -1 is less than the minimum of 0",
            ],
        ),
        (
            {"longest_side_mm": [110, 50]},
            ["config error at 'random_objects.longest_side_mm': [110, 50] is reversed; give [shortest, longest] (mm)"],
        ),
        ({"mass_kg": 0.0}, ["config error at 'random_objects.mass_kg': 0.0 is less than or equal to the minimum of 0"]),
        ({"seed": None}, ["config error at 'random_objects': 'seed' is a required property"]),
    ],
)
def test_the_block_is_checked_before_numpy_sees_a_value(tmp_path, monkeypatch, changes, lines):
    """Every problem of the block, one line each under random_objects.*, and nothing drawn."""
    _fake_package(tmp_path, monkeypatch)
    spec = {
        k: v
        for k, v in (
            {"n_objects": 2, "seed": 1, "longest_side_mm": [50.0, 110.0], "mass_kg": 0.1, "sha256_file": "manifest.sha256"}
            | changes
        ).items()
        if v is not None
    }
    monkeypatch.setattr(ro, "drawn_objects", lambda *a, **k: pytest.fail("drawn before the block was checked"))
    config = {"random_objects": spec, "objects": {"obj1": {}}}
    with pytest.raises(ConfigError) as info:
        ro.add_random_objects(config, tmp_path)
    assert str(info.value).splitlines() == lines
    assert config["objects"] == {"obj1": {}}


def test_a_missing_manifest_and_an_object_named_like_a_drawn_one_are_named(tmp_path, monkeypatch):
    _fake_package(tmp_path, monkeypatch)
    spec = {"n_objects": 4, "seed": 1, "longest_side_mm": [50.0, 110.0], "mass_kg": 0.1, "sha256_file": "none"}
    with pytest.raises(ConfigError, match=r"^config error at 'random_objects.sha256_file': '.*none' cannot be read"):
        ro.add_random_objects({"random_objects": spec}, tmp_path)
    spec["sha256_file"] = "manifest.sha256"
    config = {"random_objects": spec, "objects": {"rand_000": {"shape": {"sphere": {"radius_mm": 20}}}, "rand_002": None}}
    with pytest.raises(ConfigError) as info:
        ro.add_random_objects(config, tmp_path)
    # rand_000 is studied and clashes; rand_002 (removed by null, and left out: its file is missing) does not
    assert str(info.value).splitlines() == [
        "config error at 'objects.rand_000': an object of the configuration has the name of an object random_objects "
        "draws (rand_000); rename the object or change random_objects.seed"
    ]
