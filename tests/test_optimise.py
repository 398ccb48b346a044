"""The study's optimisation step: the loop over poses against the per-problem path, the
shards, and the gfo table contract."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from conftest import study_gfo_params
from grasp_problems import random_grasp, random_synergies
from synergrasp import table_contracts
from synergrasp.config import defaults
from synergrasp.ids import synergy_sets
from synergrasp.optimisation.cones import PyramidCone
from synergrasp.optimisation.gfo import solve_gfo
from synergrasp.optimisation.ipm.solver import IPMSettings
from synergrasp.optimisation.optimise import mechanics_for, optimise_grasps
from synergrasp.optimisation.problem import GraspSets, SynergySets
from synergrasp.optimisation.shards import merge_shards, shard_positions

RTOL_NORM = 1e-4
PARAMS = study_gfo_params(gravity_direction=(0.0, 0.0, -1.0))


def test_optimise_grasps_matches_clarabel_per_grasp():
    rng = np.random.default_rng(21)
    grasps = [random_grasp(rng, int(rng.integers(3, 13)), palm_contacts=int(rng.integers(0, 2))) for _ in range(5)]
    grasps.insert(2, None)
    sets = SynergySets(
        random_synergies(rng),
        tuple([tuple(range(1, k + 1)) for k in (1, 2, 3, 7, 15)] + list(itertools.combinations(range(1, 8), 2))[:6]),
    )
    out = optimise_grasps(grasps, sets, PARAMS)
    n = len(sets)
    assert len(out["status"]) == len(grasps) * n
    for p, grasp in enumerate(grasps):
        rows = slice(p * n, (p + 1) * n)
        assert list(out["set_id"][rows]) == ["-".join(map(str, s)) for s in sets.sets]
        if grasp is None:
            assert set(out["status"][rows]) == {"no_grasp"} and not out["load_feasible"][rows].any()
            continue
        mech = mechanics_for(grasp, PARAMS)
        ref = solve_gfo(
            GraspSets(mech.f_p, mech.normals, mech.projector, mech.response_norm, sets, PARAMS.f_min_N, PARAMS.cone),
            "clarabel",
            strict_shrink=PARAMS.strict_shrink,
        )
        np.testing.assert_array_equal(out["status"][rows], ref.status)
        np.testing.assert_array_equal(out["e_s"][rows], ref.e_s)
        np.testing.assert_array_equal(out["force_closure_def1"][rows], ref.strict_internal)
        np.testing.assert_array_equal(out["load_feasible"][rows], ref.status == "feasible")
        fc = ref.feasible
        np.testing.assert_allclose(out["force_norm"][rows][fc], ref.force_norm[fc], rtol=RTOL_NORM)
        assert np.isnan(out["force_norm"][rows][~fc]).all()


def test_shards_partition_the_poses_in_order():
    parts = [shard_positions(10, k, 3).tolist() for k in range(3)]
    assert parts == [[0, 1, 2, 3], [4, 5, 6], [7, 8, 9]]
    with pytest.raises(ValueError, match="shard must be an int in 0..2"):
        shard_positions(10, 3, 3)
    with pytest.raises(ValueError, match="solver.pose_shards"):
        shard_positions(10, 0, 0)


def test_merge_shards_orders_poses_and_keeps_the_set_order():
    gfo = table_contracts.empty(table_contracts.GFO)
    a = pd.DataFrame({"pose": [2, 2, 0, 0], "set_id": ["1", "1-2", "1", "1-2"]})
    merged = merge_shards([a.iloc[:2], a.iloc[2:]])
    assert merged[["pose", "set_id"]].values.tolist() == [[0, "1"], [0, "1-2"], [2, "1"], [2, "1-2"]]
    assert list(gfo.columns) == list(table_contracts.GFO.names)


def test_pyramid_cone_study_runs_through_the_kernel_and_matches_clarabel():
    rng = np.random.default_rng(5)
    grasps = [random_grasp(rng, int(rng.integers(4, 10)), palm_contacts=1) for _ in range(3)]
    sets = SynergySets(random_synergies(rng), ((1,), (1, 2, 3), tuple(range(1, 16))))
    params = study_gfo_params(gravity_direction=(0.0, 0.0, -1.0), friction_cone="pyramid8_circumscribed")
    assert params.cone == PyramidCone(1.5, 8, inscribed=False)
    out = optimise_grasps(grasps, sets, params)
    n = len(sets)
    for p, grasp in enumerate(grasps):
        rows = slice(p * n, (p + 1) * n)
        mech = mechanics_for(grasp, params)
        if mech.rank_G < 6:
            continue
        ref = solve_gfo(
            GraspSets(mech.f_p, mech.normals, mech.projector, mech.response_norm, sets, params.f_min_N, params.cone),
            "clarabel",
            strict_shrink=params.strict_shrink,
        )
        np.testing.assert_array_equal(out["status"][rows], ref.status)
        np.testing.assert_array_equal(out["force_closure_def1"][rows], ref.strict_internal)
        assert set(out["solver"][rows]) <= {"ipm", "implied", "clarabel_fallback", "direct"}
        fc = ref.feasible
        np.testing.assert_allclose(out["force_norm"][rows][fc], ref.force_norm[fc], rtol=RTOL_NORM)
    with pytest.raises(ValueError, match="friction_cone must be one of"):
        study_gfo_params(friction_cone="pyramid6").cone


@pytest.mark.parametrize("cone", ["circular", "pyramid4_inscribed"])
def test_verdicts_implied_by_nested_sets_are_those_of_solving_every_set(cone):
    """The study's 75 sets on generated grasps, at two friction coefficients: the verdicts
    the kernel takes from the sets' nesting (`IPMSettings.nested`) against every set solved."""
    rng = np.random.default_rng(8)
    sets = SynergySets(random_synergies(rng), tuple(synergy_sets(defaults()["synergy_sets"]).values()))
    grasps = [random_grasp(rng, int(rng.integers(4, 13)), palm_contacts=int(rng.integers(0, 2))) for _ in range(24)]
    for mu in (0.4, 1.5):
        params = study_gfo_params(gravity_direction=(0.0, 0.0, -1.0), mu=mu, friction_cone=cone)
        nested = optimise_grasps(grasps, sets, params)
        every = optimise_grasps(grasps, sets, params, ipm=IPMSettings(nested=False))
        implied = nested["solver"] == "implied"
        assert implied.sum() > 100 and "implied" not in set(every["solver"])
        for name in ("status", "force_closure_def1", "e_s"):
            np.testing.assert_array_equal(nested[name], every[name])
        # a set of its superset's rank takes the superset's optimum, and a basis starts from
        # its parent's: the same problems on other bases of the same subspaces, equal to the
        # solvers' tolerance
        np.testing.assert_allclose(nested["force_norm"], every["force_norm"], rtol=1e-6)
        infeasible = nested["status"] == "infeasible"
        assert (implied & infeasible).sum() > 100 and (implied & ~infeasible).any()
        assert not nested["force_closure_def1"][infeasible].any()
        assert not nested["iterations"][implied].any()
        assert set(nested["solver"][~implied]) <= {"ipm", "clarabel_fallback"}


def _contacts_of(grasps) -> pd.DataFrame:
    """A contacts table holding the given grasps (None: a pose without a grasp)."""
    rows = []
    for pose, g in enumerate(grasps):
        m = 0 if g is None else g.n_contacts
        rows.append(
            {
                "object": "box",
                "pose": pose,
                "alpha_deg": 5.0 * pose,
                "beta_deg": 0.0,
                "status": "no_grasp" if g is None else "grasp",
                "n_contacts": m,
                "contact_link": [] if g is None else g.links.tolist(),
                "contact_point": [] if g is None else g.points.ravel().tolist(),
                "contact_normal": [] if g is None else g.normals.ravel().tolist(),
                "jacobian": [] if g is None else g.jacobian.ravel().tolist(),
                "object_center": [0.0] * 3 if g is None else g.center.tolist(),
            }
        )
    return pd.DataFrame(rows)


def _twin(grasp, delta_mm=1e-12):
    return type(grasp)(
        points=grasp.points + delta_mm, normals=grasp.normals, links=grasp.links, jacobian=grasp.jacobian, center=grasp.center
    )


def test_first_same_grasp_points_each_grasp_at_the_first_of_its_kind():
    from synergrasp.optimisation.mechanics import first_same_grasp

    rng = np.random.default_rng(5)
    a, b = random_grasp(rng, 5), random_grasp(rng, 6)
    grasps = [a, None, b, _twin(a), _twin(b, 1e-6), _twin(b)]
    assert first_same_grasp(grasps).tolist() == [0, -1, 2, 0, 4, 2]


def test_gfo_table_solves_one_grasp_once_whatever_the_shards(monkeypatch):
    from synergrasp.optimisation import optimise

    rng = np.random.default_rng(8)
    a, b = random_grasp(rng, 6), random_grasp(rng, 7, palm_contacts=1)
    grasps = [a, b, None, _twin(a), _twin(b), _twin(a, 1e-6)]  # the last is not a's: solved apart
    sets = SynergySets(random_synergies(rng), tuple(tuple(range(1, k + 1)) for k in (1, 3, 7, 15)))
    contacts = _contacts_of(grasps)
    solved = []
    real = optimise.optimise_grasps
    monkeypatch.setattr(
        optimise,
        "optimise_grasps",
        lambda gs, *args, **kw: solved.append(sum(g is not None for g in gs)) or real(gs, *args, **kw),
    )
    whole = optimise.gfo_table(contacts, sets, PARAMS)
    assert solved == [3]
    sharded = merge_shards([optimise.optimise_shard(contacts, k, 4, sets, PARAMS) for k in range(4)])
    assert solved == [3, 1, 1, 1, 0]  # the shards split the distinct grasps; the fourth has none left
    # bit for bit (an empty shard leaves the string columns' dtype to pandas' concat)
    pd.testing.assert_frame_equal(sharded, whole, check_exact=True, check_dtype=False)
    n = len(sets)
    rows = lambda p: whole.iloc[p * n : (p + 1) * n].drop(columns=["pose", "alpha_deg"]).reset_index(drop=True)  # noqa: E731
    pd.testing.assert_frame_equal(rows(3), rows(0))
    pd.testing.assert_frame_equal(rows(4), rows(1))
    assert set(whole["status"].iloc[2 * n : 3 * n]) == {"no_grasp"}
    # solving every pose on its own decides the same and finds the same forces to round-off
    alone = optimise_grasps(grasps, sets, PARAMS)
    np.testing.assert_array_equal(whole["status"].to_numpy(), alone["status"])
    np.testing.assert_array_equal(whole["force_closure_def1"].to_numpy(), alone["force_closure_def1"])
    np.testing.assert_allclose(whole["force_norm"].to_numpy(), alone["force_norm"], rtol=1e-6)


def test_mechanics_kept_by_the_caller_give_the_same_results_bit_for_bit():
    """The planner keeps each grasp's mechanics (and contact frames) across the sets it solves
    in turn: a solve with them is the solve without them, to the last bit; a list of the
    wrong length is refused."""
    rng = np.random.default_rng(5)
    grasps = [random_grasp(rng, int(rng.integers(3, 10)), palm_contacts=int(rng.integers(0, 2))) for _ in range(4)]
    grasps.insert(1, None)
    kept = [None if g is None else mechanics_for(g, PARAMS) for g in grasps]
    synergies = random_synergies(rng)
    for sets in (((1,),), ((1, 2, 3),), ((1, 2), (1, 2, 3, 4, 5))):  # one set at a time, as the planner asks
        chosen = SynergySets(synergies, sets)
        fresh = optimise_grasps(grasps, chosen, PARAMS)
        again = optimise_grasps(grasps, chosen, PARAMS, mechanics=kept)
        assert fresh.keys() == again.keys()
        for name in fresh:
            np.testing.assert_array_equal(again[name], fresh[name], err_msg=name)
    with pytest.raises(ValueError, match="mechanics: one per grasp"):
        optimise_grasps(grasps, SynergySets(synergies, ((1,),)), PARAMS, mechanics=kept[:2])
