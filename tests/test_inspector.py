"""The one-grasp inspector against the study's own steps on the small configuration."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from synergrasp.cli import main
from synergrasp.config import validate_config
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.ids import set_id
from synergrasp.inspector import default_sets, inspect_grasp, parse_sets
from synergrasp.optimisation.optimise import OptimiseParams, gfo_table
from synergrasp.optimisation.problem import SynergySets
from synergrasp.simulation.closure import SimulateParams, simulate_object
from synergrasp.steps import step_config

SMALL = Path(__file__).parent / "config" / "small.yaml"
POSES = [("obj1", -30.0, 0.0), ("obj1", 90.0, 40.0), ("obj4", -150.0, -20.0)]
SETS = [(1,), (1, 2), (2, 5), tuple(range(1, 16))]


@pytest.fixture(scope="module")
def small():
    return yaml.safe_load(SMALL.read_text())


@pytest.fixture(scope="module")
def study_rows(small):
    """The rows of the study's contacts and gfo tables at POSES, made as the workflow's
    simulate and optimise steps make them (every pose of the object's grid, then the pose)."""
    cfg = validate_config(small)
    rows = {}
    for obj in sorted({p[0] for p in POSES}):
        sim = SimulateParams.from_config(step_config(cfg, "simulate", obj), obj)
        hand = load_hand(sim.hand)
        contacts = simulate_object(hand, sim.synergies(hand.joint_names), sim.object, sim.placement, sim.closure)
        opt = OptimiseParams.from_config(step_config(cfg, "optimise", obj), obj)
        full = load_synergies(opt.synergies, joint_names=hand.joint_names)
        gfo = gfo_table(contacts, SynergySets(full.matrix, tuple(SETS)), opt.gfo)
        rows[obj] = (contacts, gfo)
    return rows


@pytest.mark.parametrize("obj, alpha, beta", POSES)
def test_the_inspector_agrees_with_the_study_tables(small, study_rows, obj, alpha, beta):
    result = inspect_grasp(small, obj, alpha, beta, SETS)
    contacts, gfo = study_rows[obj]
    row = contacts[(contacts["alpha_deg"] == alpha) & (contacts["beta_deg"] == beta)].iloc[0]
    assert result.pose == int(row["pose"]) and result.closure_status == row["status"]
    assert list(result.contacts["link"]) == list(row["contact_link"])
    assert np.array_equal(np.ravel(list(result.contacts["point_mm"])), np.asarray(row["contact_point"]))
    rows = gfo[gfo["pose"] == row["pose"]].set_index("set_id")
    assert [s.set_id for s in result.sets] == [set_id(s) for s in SETS]
    for s in result.sets:
        expected = rows.loc[s.set_id]
        assert s.status == expected["status"]
        assert s.force_closure == bool(expected["force_closure_def1"])
        assert s.e_s == expected["e_s"]
        assert s.force_N == pytest.approx(expected["force_norm"], rel=1e-12, nan_ok=True)
        if s.load_feasible:  # the optimal forces lie in the cones (the solver's own tolerance)
            assert s.cone_use <= 1.0 + 1e-6


def test_sets_are_parsed_as_singles_ranges_and_lists():
    assert parse_sets(["3", "1-5", "2,5"], 15) == [(3,), (1, 2, 3, 4, 5), (2, 5)]
    assert default_sets(3) == [(1,), (2,), (3,), (1, 2), (1, 2, 3)]


@pytest.mark.parametrize(
    "argv, names",
    [
        (["grasp", "obj9", "--alpha", "0", "--beta", "0"], "object"),
        (["grasp", "obj1", "--alpha", "7", "--beta", "0"], "--alpha/--beta"),
        (["grasp", "obj1", "--alpha", "0", "--beta", "0", "--sets", "16"], "--sets"),
        (["grasp", "obj1", "--alpha", "0", "--beta", "0", "--sets", "1-x"], "--sets"),
    ],
)
def test_bad_arguments_give_one_line_naming_the_argument(capsys, argv, names):
    assert main(argv + ["--configfile", str(SMALL)]) == 2
    err = [line for line in capsys.readouterr().err.strip().splitlines() if ": warning: " not in line]
    assert len(err) == 1 and names in err[0]


def test_json_output_holds_the_same_numbers(capsys, small):
    assert (
        main(["grasp", "obj4", "--alpha", "-150", "--beta", "-20", "--sets", "1-15", "--json", "--configfile", str(SMALL)]) == 0
    )
    data = json.loads(capsys.readouterr().out)
    direct = inspect_grasp(small, "obj4", -150.0, -20.0, [tuple(range(1, 16))])
    assert data["pose"] == direct.pose
    assert data["sets"][0]["force_N"] == pytest.approx(direct.sets[0].force_N, nan_ok=True)
    assert data["quality"]["epsilon"] == pytest.approx(direct.quality.epsilon)


def test_a_searched_placement_takes_its_target_from_the_search_table(small, tmp_path):
    from synergrasp import table_contracts

    target = (38.0, 5.0, 112.0)
    folder = tmp_path / "objects" / "obj1"
    folder.mkdir(parents=True)
    row = {
        "object": "obj1",
        "rank": 1,
        "chosen": True,
        "distinct_rank": 1,
        "x_mm": target[0],
        "y_mm": target[1],
        "z_mm": target[2],
        "round": 0,
        "n_poses": 27,
        "grasp_type": "precision",
        "typed_percent": 100.0,
        "force_closure_percent": 100.0,
        "median_force_per_weight": 1.0,
        "median_contacts": 5.0,
        "distance_to_chosen_mm": 0.0,
    }
    import pandas as pd

    pd.DataFrame([{c: row.get(c, 0) for c in table_contracts.PLACEMENT.names}]).to_csv(folder / "placement.csv", index=False)
    searched = {**small, "placement": {**small["placement"], "mode": "searched"}}
    fixed = {**small, "placement": {**small["placement"], "mode": "fixed", "center_mm": list(target)}}
    a = inspect_grasp(searched, "obj1", -30.0, 0.0, [(1, 2)], results=tmp_path)
    b = inspect_grasp(fixed, "obj1", -30.0, 0.0, [(1, 2)])
    assert a.to_dict() == b.to_dict()
    with pytest.raises(ValueError, match="placement: mode 'searched'"):
        inspect_grasp(searched, "obj1", -30.0, 0.0, [(1, 2)], results=tmp_path / "nowhere")


def test_the_optimal_forces_are_kept_per_contact(small):
    result = inspect_grasp(small, "obj4", -150.0, -20.0, [(1,), tuple(range(1, 16))])
    assert result.closure_status == "grasp" and len(result.contacts)
    for s in result.sets:
        if s.load_feasible:
            assert len(s.forces_N) == 3 * len(result.contacts)
            assert np.linalg.norm(s.forces_N) == pytest.approx(s.force_N, rel=1e-9)
        else:
            assert s.forces_N == ()
    assert any(s.load_feasible for s in result.sets)


def test_png_draws_the_grasp_from_two_views_with_its_touching_links(tmp_path):
    from matplotlib.image import imread

    from synergrasp.figures.hand_pictures import TOUCHING

    out = tmp_path / "grasp.png"
    assert (
        main(
            ["grasp", "obj4", "--alpha", "-150", "--beta", "-20", "--sets", "1-15", "--png", str(out), "--configfile", str(SMALL)]
        )
        == 0
    )
    rgb = imread(out)[..., :3].astype(float)
    # the highlight's hue (shading scales brightness, not hue) in the left and in the right view
    chroma = rgb / np.maximum(rgb.sum(axis=2, keepdims=True), 1e-9)
    lit = np.linalg.norm(chroma - np.asarray(TOUCHING) / sum(TOUCHING), axis=2) < 0.03
    half = rgb.shape[1] // 2
    assert lit[:, :half].sum() > 500 and lit[:, half:].sum() > 500


def test_the_inspector_names_the_blockers_of_the_blockers_table(small, study_rows):
    """docs/blockers.md: each failing set's blockers at a pose, as the per-object table has them."""
    from synergrasp.analysis.blockers import BlockersParams, blockers_table
    from synergrasp.ids import incremental_set_id
    from synergrasp.simulation.opposition import HandAxes

    cfg = validate_config(small)
    obj = "obj1"
    contacts, gfo = study_rows[obj]
    full_id = incremental_set_id(15)
    base = BlockersParams.from_config(cfg, obj)
    params = BlockersParams(
        base.hand, base.synergies, base.gfo, {set_id(s): s for s in SETS if set_id(s) != full_id}, full_id, base.rule, base.shape
    )
    hand = load_hand(params.hand)
    table = blockers_table(
        contacts,
        gfo,
        hand.link_names,
        HandAxes.from_hand(hand),
        load_synergies(params.synergies, joint_names=hand.joint_names).matrix,
        params,
    )
    assert len(table) and set(table["reason"]) <= {"contacts", "no_internal_force"}
    row = table[table["reason"] == "contacts"].iloc[0]
    result = inspect_grasp(small, obj, float(row["alpha_deg"]), float(row["beta_deg"]), SETS)
    inspected = {s.set_id: s for s in result.sets}
    for _, expected in table[table["pose"] == row["pose"]].iterrows():
        s = inspected[expected["set_id"]]
        assert not s.force_closure and s.blocked_by == expected["reason"]
        assert [b.contact for b in s.blockers] == list(expected["blocker_contact"])
        assert [b.link_name for b in s.blockers] == list(expected["blocker_link_name"])
        assert s.margin == pytest.approx(expected["margin"], abs=1e-9, nan_ok=True)
    assert inspected[full_id].blocked_by == "" and not inspected[full_id].blockers
    text = __import__("synergrasp.cli", fromlist=["format_inspection"]).format_inspection(result)
    assert "what blocks each set not in force closure" in text and str(row["blocker_link_name"][0]) in text
