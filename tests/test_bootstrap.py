"""The block bootstrap over distinct poses: blocks, weights, weighted medians, and the
coverage of its intervals on synthetic grids with a known difference of rates, with
independent and with spatially correlated poses."""

import numpy as np
import pandas as pd
import pytest
from scipy.ndimage import gaussian_filter
from scipy.stats import norm

from synergrasp.analysis.bootstrap import BootstrapSettings, PoseResampler, block_index, interval, weighted_median

ALPHAS = np.arange(-180.0, 180.0, 5.0)  # 72, folded to 18 by a 90 deg period
BETAS = np.arange(-60.0, 61.0, 5.0)  # 25
A, B = np.meshgrid(ALPHAS, BETAS, indexing="ij")


def poses(objects=("o",)) -> pd.DataFrame:
    return pd.concat(
        [pd.DataFrame({"object": o, "pose": np.arange(A.size), "alpha_deg": A.ravel(), "beta_deg": B.ravel()}) for o in objects],
        ignore_index=True,
    )


def settings(seed: int = 0, resamples: int = 1000, block_deg: float = 15.0) -> BootstrapSettings:
    return BootstrapSettings(resamples=resamples, seed=seed, block_deg=block_deg, level=0.95)


def test_blocks_of_the_folded_grid():
    r = PoseResampler(poses(), {"o": 90.0}, settings(resamples=10))
    assert len(r.poses("o")) == 450 and r.n_blocks("o") == 6 * 9  # 18 / 3 in alpha; 25 = 8 x 3 + 1 in beta
    w = r.weights("o")
    assert w.shape == (11, 450) and (w[0] == 1).all()
    # every resample draws as many blocks as there are: the block weights sum to 54
    assert (r._block_weights["o"][1:].sum(axis=1) == 54).all()
    # poses of one block share their weight
    ids = block_index(A.ravel()[:75], B.ravel()[:75], 15.0, -180.0, -60.0)  # alpha -180, -175, -170
    assert len(set(ids)) == 9 and (ids.reshape(3, 25)[0] == ids.reshape(3, 25)[2]).all()


def test_seeded_and_deterministic():
    one = PoseResampler(poses(("a", "b")), {}, settings(seed=5, resamples=50))
    two = PoseResampler(poses(("b", "a")), {}, settings(seed=5, resamples=50))
    assert np.array_equal(one.weights("b"), two.weights("b"))
    three = PoseResampler(poses(("a", "b")), {}, settings(seed=6, resamples=50))
    assert not np.array_equal(one.weights("a"), three.weights("a"))


def test_weighted_median_matches_numpy_and_repeats():
    rng = np.random.default_rng(0)
    v = rng.normal(size=11)
    for n in (10, 11):
        assert weighted_median(v[:n], np.ones((1, n)))[0] == pytest.approx(np.median(v[:n]))
    counts = rng.integers(0, 4, size=11)
    assert weighted_median(v, counts[None, :])[0] == pytest.approx(np.median(np.repeat(v, counts)))
    assert np.isnan(weighted_median(v, np.zeros((1, 11)))[0])
    assert interval(np.array([np.nan, *range(101)]), 0.9) == pytest.approx((5.0, 95.0))


def difference_interval(a: np.ndarray, b: np.ndarray, seed: int) -> tuple[float, float]:
    """Interval of 100 · (mean a − mean b) over the distinct poses (the full set everywhere)."""
    r = PoseResampler(poses(), {"o": 90.0}, settings(seed=seed))
    keep = r.poses("o")
    sums = r.sums("o", np.column_stack([a.ravel()[keep], b.ravel()[keep], np.ones(keep.size)]))
    diff = 100.0 * (sums[:, 0] - sums[:, 1]) / sums[:, 2]
    return interval(diff[1:], 0.95)


def coverage(draw, truth: float, repeats: int = 200) -> float:
    hits = 0
    for seed in range(repeats):
        a, b = draw(np.random.default_rng(1000 + seed))
        low, high = difference_interval(a, b, seed)
        hits += low <= truth <= high
    return hits / repeats


def periodic_field(rng: np.random.Generator, sigma_cells: float) -> np.ndarray:
    """A smooth Gaussian field with unit marginal variance on the grid, repeating every 90 deg
    in alpha (as the study's results do), correlated over about sigma_cells cells."""
    period = rng.normal(size=(18, 25))
    smooth = gaussian_filter(period, sigma_cells, mode=("wrap", "reflect"))
    smooth /= np.sqrt(
        (gaussian_filter(np.eye(1, 18 * 25, 212).reshape(18, 25), sigma_cells, mode=("wrap", "reflect")) ** 2).sum()
    )
    return np.tile(smooth, (4, 1))


def test_coverage_with_independent_poses():
    """Each distinct pose succeeds with probability 0.3 (set a) and 0.2 (set b), independently:
    the true difference is 10 percentage points."""

    def draw(rng):
        one = rng.random((18, 25))
        return np.tile(one < 0.3, (4, 1)), np.tile(rng.random((18, 25)) < 0.2, (4, 1))

    assert 0.9 <= coverage(draw, 10.0) <= 0.99


def test_coverage_with_spatially_correlated_poses():
    """Success where a smooth field exceeds a threshold: P = 0.3 and 0.2 at every pose,
    neighbours succeed together (field correlation exp(-d^2 / (4 sigma^2)), sigma = 0.5 cell:
    0.37 at 5 deg, 0.02 at 10 deg); the true difference is 10 points. (With sigma = 1 cell,
    correlated over 15 deg, 15 deg blocks cover 0.79: docs/analyses.md.)"""

    def draw(rng):
        return (periodic_field(rng, 0.5) > norm.ppf(0.7)), (periodic_field(rng, 0.5) > norm.ppf(0.8))

    assert 0.9 <= coverage(draw, 10.0) <= 0.99


def test_weighted_median_a_few_rows_at_a_time_is_every_row_at_once(monkeypatch):
    """Weights handed three rows at a time (a tiny cap on the weights held) give each row's
    median as with every row at once; unit weights give numpy's median."""
    from synergrasp.analysis import bootstrap

    rng = np.random.default_rng(4)
    values = rng.normal(size=41)
    weights = rng.integers(0, 4, size=(10, 41)).astype(float)
    weights[0] = 1.0
    weights[3] = 0.0  # no weight: NaN
    whole = bootstrap.weighted_median(values, weights)
    monkeypatch.setattr(bootstrap, "_CELLS", 3 * values.size)
    handed = []
    chunked = bootstrap.weighted_median_rows(values, lambda rows: handed.append(rows) or weights[rows], len(weights))
    assert len(handed) == 4 and all(r.stop - r.start <= 3 for r in handed)
    np.testing.assert_array_equal(chunked, whole)
    assert chunked[0] == np.median(values) and np.isnan(chunked[3])


def test_block_weighted_median_by_hand():
    """Values 1..5 in blocks (0, 0, 1, 2, 2): weights per block (1, 1, 1) give numpy's median
    3; (2, 0, 1) give 1, 1, 2, 2, 4, 5 -> 2; (1, 0, 1) give 1, 2, 4, 5 -> (2 + 4) / 2 = 3;
    (0, 0, 3) give 4, 4, 4, 5, 5, 5 -> 4.5; all zero: NaN."""
    from synergrasp.analysis.bootstrap import block_weighted_median

    weights = np.array([[1, 1, 1], [2, 0, 1], [1, 0, 1], [0, 0, 3], [0, 0, 0]], dtype=np.uint8)
    out = block_weighted_median(np.array([5.0, 1.0, 3.0, 4.0, 2.0]), np.array([2, 0, 1, 2, 0]), lambda rows: weights[rows], 5)
    np.testing.assert_array_equal(out[:4], [3.0, 2.0, 3.0, 4.5])
    assert np.isnan(out[4])


def test_block_weighted_median_is_weighted_median_rows_to_the_bit(monkeypatch):
    """On random values with ties, blocks with and without values, zero-weight rows and rows
    whose median lies far from the middle (a small window, widened), the medians of the block
    weights are those of every pose's weight, bit for bit; a few rows at a time too."""
    from synergrasp.analysis import bootstrap

    rng = np.random.default_rng(7)
    monkeypatch.setattr(bootstrap, "_WINDOW", 4)
    for trial in range(60):
        n, n_blocks, n_rows = int(rng.integers(1, 900)), int(rng.integers(1, 80)), int(rng.integers(1, 30))
        values = np.round(rng.normal(size=n), int(rng.integers(0, 3)))  # ties
        blocks = rng.integers(0, n_blocks, size=n)
        weights = rng.integers(0, 4, size=(n_rows, n_blocks)).astype(np.uint8)
        weights[0] = 1
        weights[n_rows // 2, : n_blocks // 2] = 0  # most of the weight on the upper blocks
        if n_rows > 2:
            weights[-1] = 0
        if trial % 2:
            monkeypatch.setattr(bootstrap, "_BLOCK_CELLS", 3 * n_blocks)
        expected = bootstrap.weighted_median_rows(values, lambda rows: weights[rows][:, blocks].astype(float), n_rows)
        got = bootstrap.block_weighted_median(values, blocks, lambda rows: weights[rows], n_rows)
        np.testing.assert_array_equal(got, expected)
    with pytest.raises(ValueError, match="integers"):
        bootstrap.block_weighted_median(np.ones(3), np.zeros(3, int), lambda rows: np.ones((1, 1)), 1)
