import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.minima import FORCE_TIE_RTOL, local_minima, minima_table, preserved, preserved_counts


def ring(forces: dict[float, float], default: float = 5.0):
    """alpha = -180..170 step 10 at beta = 0; all force closure."""
    alpha = np.arange(-180.0, 180.0, 10.0)
    force = np.array([forces.get(a, default) for a in alpha])
    return alpha, np.zeros_like(alpha), force, np.ones(alpha.size, bool)


def test_alpha_wraps_around():
    alpha, beta, force, fc = ring({-180.0: 1.0, 170.0: 2.0})
    got = local_minima(alpha, beta, force, fc)
    # -180 is 10 deg from 170 across the wrap: only -180 survives
    assert alpha[got].tolist() == [-180.0]
    # without the wrap (period large) 170 would have no lower neighbour
    got = local_minima(alpha, beta, force, fc, alpha_period_deg=1000.0)
    assert alpha[got].tolist() == [-180.0, 170.0]


def test_ties_discard_both():
    alpha, beta, force, fc = ring({0.0: 1.0, 10.0: 1.0, 100.0: 2.0})
    got = local_minima(alpha, beta, force, fc)
    assert alpha[got].tolist() == [100.0]
    # forces within the optimiser's accuracy are a tie too; a clear difference is not
    alpha, beta, force, fc = ring({0.0: 1.0, 10.0: 1.0 + 2e-6, 100.0: 2.0, 110.0: 2.0 * (1 + 1e-4)})
    got = local_minima(alpha, beta, force, fc)
    assert alpha[got].tolist() == [100.0]


def test_no_force_closure_neighbour_is_a_minimum():
    alpha, beta, force, fc = ring({0.0: 1.0, 100.0: 3.0, 110.0: 4.0, 120.0: 3.0})
    fc = np.isin(alpha, [0.0, 100.0, 110.0, 120.0])
    force[~fc] = np.nan
    # median of (1, 3, 4, 3) is 3: only the isolated 1.0 is a candidate, and it has no
    # force-closure neighbour
    got = local_minima(alpha, beta, force, fc)
    assert alpha[got].tolist() == [0.0]


def test_beta_does_not_wrap():
    beta = np.arange(-180.0, 180.0, 10.0)
    force = np.full(beta.size, 5.0)
    force[0], force[-1] = 2.0, 1.0  # beta = -180 and 170
    got = local_minima(np.zeros_like(beta), beta, force, np.ones(beta.size, bool))
    assert beta[got].tolist() == [-180.0, 170.0]


def test_square_neighbourhood_3x3():
    # rows beta 0, 10, 20; columns alpha 0, 10, 20
    grid = np.array([[4, 6, 7], [8, 1, 9], [2, 5, 3]], float)
    alpha, beta = np.meshgrid([0.0, 10.0, 20.0], [0.0, 10.0, 20.0])
    args = (alpha.ravel(), beta.ravel(), grid.ravel(), np.ones(9, bool))
    # median 5: candidates 1, 2, 3, 4; each of 2, 3, 4 has the diagonal/edge neighbour 1
    assert np.flatnonzero(local_minima(*args)).tolist() == [4]
    # radius 5: nobody has a neighbour, every candidate is a minimum
    assert np.flatnonzero(local_minima(*args, radius_deg=5.0)).tolist() == [0, 4, 6, 8]


def test_copies_at_the_median_are_decided_alike():
    """Four isolated copies of one grasp whose forces differ by round-off (1e-8): whether
    they lie below the median must not depend on it, so all or none are minima."""
    alpha, beta, force, fc = ring({-180.0: 3.0, -90.0: 3.0 + 1e-8, 0.0: 3.0 - 1e-8, 90.0: 3.0 + 2e-8}, default=np.nan)
    fc = np.isfinite(force)
    assert local_minima(alpha, beta, force, fc).sum() in (0, 4)


def test_no_force_closure_at_all():
    alpha, beta, force, fc = ring({})
    assert not local_minima(alpha, beta, force, np.zeros_like(fc)).any()


def test_bad_input():
    with pytest.raises(ValueError, match="beta_deg"):
        local_minima([0, 1], [0], [1, 1], [True, True])
    with pytest.raises(ValueError, match="finite"):
        local_minima([0, 1], [0, 0], [np.nan, 1], [True, True])
    with pytest.raises(ValueError, match="radius_deg"):
        local_minima([0], [0], [1], [True], radius_deg=-1)


def brute_force(alpha, beta, force, fc, radius):
    out = np.zeros(alpha.size, bool)
    median = np.median(force[fc])
    for i in range(alpha.size):
        if not fc[i] or not force[i] < median * (1 - FORCE_TIE_RTOL):
            continue
        lower_or_equal = False
        for j in range(alpha.size):
            da = abs(alpha[i] - alpha[j]) % 360
            da = min(da, 360 - da)
            near = da <= radius and abs(beta[i] - beta[j]) <= radius
            if j != i and fc[j] and near and force[i] >= force[j] * (1 - FORCE_TIE_RTOL):
                lower_or_equal = True
        out[i] = not lower_or_equal
    return out


def test_matches_brute_force_on_random_grids():
    rng = np.random.default_rng(3)
    a, b = np.meshgrid(np.arange(-180.0, 180.0, 5.0), np.arange(-60.0, 61.0, 5.0))
    for trial in range(4):
        force = np.round(rng.uniform(1, 10, a.size), 1)  # rounding makes ties happen
        fc = rng.random(a.size) < 0.6
        force[~fc] = np.nan
        got = local_minima(a.ravel(), b.ravel(), force, fc)
        np.testing.assert_array_equal(got, brute_force(a.ravel(), b.ravel(), force, fc, 10.0))
        assert got.any()


def test_preserved():
    got = preserved([-180.0, 0.0, 0.0, 50.0], [0.0, -60.0, 0.0, 0.0], [175.0, 0.0, 60.0], [5.0, 60.0, 10.0])
    # (-180,0)~(175,5) across the wrap; (0,-60) vs (0,60): beta does not wrap;
    # (0,0)~... nothing within 10 in alpha except (0,60) which is 60 away in beta; (50,0)~(60,10) at exactly 10
    assert got.tolist() == [True, False, False, True]
    assert preserved([1.0], [1.0], [], []).tolist() == [False]
    assert preserved([], [], [1.0], [1.0]).shape == (0,)


def test_minima_table():
    alpha, beta, force, fc = ring({-180.0: 1.0, 170.0: 2.0, 90.0: 3.0})
    rows = []
    for set_id, n, f in (("1", 1, force), ("1-2", 2, np.where(alpha == 90.0, 9.0, force))):
        for pose, (a, b, x) in enumerate(zip(alpha, beta, f)):
            rows.append(
                dict(
                    object="obj1", pose=pose, alpha_deg=a, beta_deg=b, set_id=set_id, n_synergies=n, success=True, success_force=x
                )
            )
    table = minima_table(pd.DataFrame(rows))
    assert table[["set_id", "alpha_deg"]].values.tolist() == [["1", -180.0], ["1", 90.0], ["1-2", -180.0]]
    assert list(table.columns) == ["object", "set_id", "n_synergies", "pose", "alpha_deg", "beta_deg", "force_norm"]


def test_preserved_counts_equal_the_per_row_preserved_sums():
    # 600 random rows (more than one chunk) against the one-row function, α wrapping included
    rng = np.random.default_rng(7)
    a, b = rng.choice(np.arange(-180, 180, 5.0), 30), rng.choice(np.arange(-60, 65, 5.0), 30)
    na, nb = rng.choice(np.arange(-180, 180, 5.0), (600, 25)), rng.choice(np.arange(-60, 65, 5.0), (600, 25))
    counts = preserved_counts(a, b, na, nb, radius_deg=10.0)
    expected = [int(preserved(a, b, na[i], nb[i], radius_deg=10.0).sum()) for i in range(600)]
    assert counts.tolist() == expected
    assert 0 < counts.min() and counts.max() < 30  # neither trivially none nor all
    assert preserved_counts(a[:0], b[:0], na, nb).tolist() == [0] * 600
    with pytest.raises(ValueError, match="next_alpha and next_beta"):
        preserved_counts(a, b, na[0], nb[0])
