"""The null model of minimum preservation on grids where the answer is known."""

import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.chance import allowed_offsets, identical_force_maps, preservation_vs_chance, reflected

ALPHAS = np.arange(-180.0, 180.0, 5.0)  # 72
BETAS = np.arange(-60.0, 61.0, 5.0)  # 25


def grid_table(obj: str, forces: dict[str, np.ndarray]) -> pd.DataFrame:
    """A success everywhere, one force map per set (72 x 25 poses)."""
    a, b = np.meshgrid(ALPHAS, BETAS, indexing="ij")
    parts = [
        pd.DataFrame(
            {
                "object": obj,
                "set_id": sid,
                "pose": np.arange(a.size),
                "alpha_deg": a.ravel(),
                "beta_deg": b.ravel(),
                "success": True,
                "success_force": f.ravel(),
            }
        )
        for sid, f in forces.items()
    ]
    return pd.concat(parts, ignore_index=True)


def minima_rows(obj: str, sid: str, alpha: np.ndarray, beta: np.ndarray) -> pd.DataFrame:
    return pd.DataFrame({"object": obj, "set_id": sid, "alpha_deg": alpha, "beta_deg": beta})


def random_minima(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n distinct grid poses at random."""
    picks = rng.choice(ALPHAS.size * BETAS.size, size=n, replace=False)
    return ALPHAS[picks // BETAS.size], BETAS[picks % BETAS.size]


def test_allowed_offsets_exclude_the_identity_up_to_period_and_radius():
    offsets = {tuple(o) for o in allowed_offsets(ALPHAS, BETAS, 10.0, 90.0)}
    for excluded in [(0, 0), (2, 2), (18, 0), (36, 1), (70, -2), (16, -1)]:  # 90 deg = 18 steps; alpha wraps
        assert excluded not in offsets, excluded
    for kept in [(3, 0), (18, 3), (9, 12), (0, 3), (0, -24), (0, 24), (70, 23)]:  # beta does not wrap: 23 steps is far
        assert kept in offsets, kept
    # beta offsets -24..24; excluded: 5 alpha offsets per period (0, +-5, +-10 deg) x 4 periods, times 5 beta offsets
    assert len(offsets) == ALPHAS.size * (2 * BETAS.size - 1) - 20 * 5


def test_beta_shift_reflects_at_the_ends_and_keeps_every_point():
    index = np.arange(25)
    assert reflected(index + 3, 25).tolist()[-4:] == [24, 23, 22, 21]  # 24..27: the end, then back
    assert reflected(np.array([-1, -2, 24, 25, 26, 48, 49]), 25).tolist() == [1, 2, 24, 23, 22, 0, 1]
    shifted = reflected(index + 10, 25)
    assert shifted.min() >= 0 and shifted.max() <= 24 and len(shifted) == 25


def test_identical_maps_are_fully_preserved_and_above_the_null():
    rng = np.random.default_rng(1)
    force = rng.uniform(1, 2, (ALPHAS.size, BETAS.size))
    table = grid_table("o", {"1": force, "1-2": force})
    assert identical_force_maps(table, "1", "1-2")
    alpha, beta = random_minima(rng, 12)
    minima = pd.concat([minima_rows("o", "1", alpha, beta), minima_rows("o", "1-2", alpha, beta)])
    summary, pairs = preservation_vs_chance(table, minima, 2, 10.0, {"o": 360.0}, 500, 7)
    row = summary.set_index(["object", "pairs"]).loc[("all", "all")]
    assert row["preserved_percent"] == 100.0 and row["above_chance"]
    assert row["null_high_percent"] < 60.0
    assert pairs["identical_maps"].tolist() == [True]
    # without the identical pair nothing is left to test
    assert np.isnan(summary.set_index(["object", "pairs"]).loc[("all", "non_identical"), "preserved_percent"])


def test_independent_random_maps_land_inside_the_null_interval():
    """Minima of the two sets drawn independently: preservation is chance, and the observed
    share falls inside the null's 95 % interval in most of 30 independent studies."""
    inside = 0
    for seed in range(30):
        rng = np.random.default_rng(100 + seed)
        table = grid_table("o", {"1": rng.uniform(1, 2, (72, 25)), "1-2": rng.uniform(1, 2, (72, 25))})
        mine, theirs = random_minima(rng, 15), random_minima(rng, 15)
        minima = pd.concat([minima_rows("o", "1", *mine), minima_rows("o", "1-2", *theirs)])
        summary, pairs = preservation_vs_chance(table, minima, 2, 10.0, {"o": 360.0}, 200, seed)
        row = summary.set_index(["object", "pairs"]).loc[("all", "all")]
        inside += row["null_low_percent"] <= row["preserved_percent"] <= row["null_high_percent"]
        assert not pairs["identical_maps"].any()
    assert inside >= 25


def test_null_is_deterministic_for_a_seed_and_draws_are_checked():
    rng = np.random.default_rng(3)
    table = grid_table("o", {"1": rng.uniform(1, 2, (72, 25)), "1-2": rng.uniform(1, 2, (72, 25))})
    minima = pd.concat([minima_rows("o", "1", *random_minima(rng, 10)), minima_rows("o", "1-2", *random_minima(rng, 10))])
    one = preservation_vs_chance(table, minima, 2, 10.0, {}, 100, 5)[0]
    two = preservation_vs_chance(table, minima, 2, 10.0, {}, 100, 5)[0]
    pd.testing.assert_frame_equal(one, two)
    with pytest.raises(ValueError, match="analyses.null_model.draws"):
        preservation_vs_chance(table, minima, 2, 10.0, {}, 0, 5)
