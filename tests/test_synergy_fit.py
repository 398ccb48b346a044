"""synergies fit: principal components of postures (docs/synergies.md, "Synergies from data")."""

import numpy as np
import pytest

from synergrasp.cli import main
from synergrasp.hand.synergies import HUMAN_JOINT_NAMES, SynergyFileError, load_human_synergies, load_synergies
from synergrasp.hand.synergy_fit import fit_synergies, orient_columns, read_postures


def exact_postures(mean, columns, variances, m=60, seed=3):
    """m postures whose sample mean is ``mean`` and whose sample covariance is exactly
    columns · diag(variances) · columnsᵀ: coefficients from an orthonormal, zero-mean design."""
    rng = np.random.default_rng(seed)
    design = rng.standard_normal((m, len(variances)))
    design -= design.mean(axis=0)
    q, _ = np.linalg.qr(design)  # orthonormal columns, each orthogonal to the ones vector
    coefficients = q * np.sqrt((m - 1) * np.asarray(variances))
    return mean + coefficients @ columns.T


def test_recovers_known_components_of_synthetic_postures():
    rng = np.random.default_rng(7)
    n = 8
    basis, _ = np.linalg.qr(rng.standard_normal((n, 3)))
    basis = orient_columns(basis)
    variances = [0.4, 0.1, 0.025]  # rad²
    mean = rng.uniform(0.0, 1.0, n)
    fit = fit_synergies(tuple(f"j{i}" for i in range(n)), exact_postures(mean, basis, variances))
    assert fit.synergies.n_synergies == 3  # the five directions without variance are not synergies
    np.testing.assert_allclose(fit.synergies.mean, mean, atol=1e-12)
    np.testing.assert_allclose(fit.synergies.matrix, basis, atol=1e-10)  # same sign rule: equal, not only up to sign
    np.testing.assert_allclose(fit.variance_rad2, variances, rtol=1e-10)
    np.testing.assert_allclose(fit.explained, np.array(variances) / 0.525, rtol=1e-10)


def test_human_table_reconstruction_recovers_its_columns_up_to_sign():
    human = load_human_synergies()
    s = human.matrix
    # the published columns are not orthogonal (|cos| between two columns up to 0.34):
    # PCA returns orthogonal columns, so it recovers the table's orthonormalised columns
    # (Gram–Schmidt in the table's order: the same nested spans S1, S1..S2, ...) exactly, up to sign
    cos = (s.T @ s) / np.outer(np.linalg.norm(s, axis=0), np.linalg.norm(s, axis=0))
    assert np.max(np.abs(cos - np.eye(15))) > 0.3
    q, _ = np.linalg.qr(s)
    variances = 0.5 ** np.arange(15)  # decreasing, as in the table's order
    fit = fit_synergies(HUMAN_JOINT_NAMES, exact_postures(human.mean, q, variances, m=80), 15)
    signs = np.sign(np.sum(fit.synergies.matrix * q, axis=0))
    np.testing.assert_allclose(fit.synergies.matrix * signs, q, atol=1e-9)
    np.testing.assert_allclose(fit.synergies.mean, human.mean, atol=1e-12)
    # and the fitted S1..Sk span the published S1..Sk for every k (largest principal angle ~ 0)
    for k in range(1, 16):
        cosines = np.linalg.svd(fit.synergies.matrix[:, :k].T @ np.linalg.qr(s[:, :k])[0], compute_uv=False)
        assert np.min(cosines) > 1 - 1e-12
    # the sign rule: every fitted column sums to a positive number
    assert np.all(fit.synergies.matrix.sum(axis=0) > 0)


def test_sign_rule_by_hand():
    out = orient_columns(np.array([[1.0, 0.0, -3.0], [-2.0, 2.0, 1.0], [0.5, -2.0, 2.0]]))
    # sums -0.5 (flipped), 0 (largest entry 2.0, kept: the first of equal magnitudes), 0 (largest -3, flipped)
    np.testing.assert_array_equal(out, [[-1.0, 0.0, 3.0], [2.0, 2.0, -1.0], [-0.5, -2.0, -2.0]])


def test_command_writes_a_loadable_table_and_the_variance(tmp_path, capsys):
    rng = np.random.default_rng(1)
    names = [f"j{i}" for i in range(5)]
    x = rng.standard_normal((30, 5)) @ np.diag([1.0, 0.5, 0.3, 0.2, 0.1])
    postures = tmp_path / "postures.csv"
    postures.write_text(",".join(names) + "\n" + "\n".join(",".join(f"{v:.17g}" for v in row) for row in x) + "\n")
    out, png = tmp_path / "syn.csv", tmp_path / "variance.png"
    assert main(["synergies", "fit", str(postures), "--out", str(out), "--png", str(png)]) == 0
    table = load_synergies(out, joint_names=names)
    fit = fit_synergies(*read_postures(postures))
    np.testing.assert_array_equal(table.matrix, fit.synergies.matrix)
    np.testing.assert_allclose(table.matrix.T @ table.matrix, np.eye(5), atol=1e-12)
    text = capsys.readouterr().out
    assert "S1" in text and "100.00%" in text and png.stat().st_size > 1000


def test_bad_postures_file_is_one_line_naming_the_file_and_field(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n0.1,0.2\n0.3,x\n")
    assert main(["synergies", "fit", str(bad), "--out", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "bad.csv" in err and "row 2, joint 'b'" in err
    bad.write_text("a,a\n0.1,0.2\n0.3,0.4\n")
    with pytest.raises(SynergyFileError, match="repeated"):
        read_postures(bad)


def _problems(x, names=("a", "b", "c")):
    from synergrasp.hand.synergy_fit import posture_problems

    return posture_problems(tuple(names), np.asarray(x, dtype=float))


def test_postures_a_fit_should_question_are_one_line_each():
    rng = np.random.default_rng(2)
    x = rng.uniform(0.0, 1.0, (20, 3))
    assert _problems(x) == []
    # identical up to rounding noise: the fit would explain "100 %" with an S1 of noise
    same = np.tile(x[0], (20, 1)) + 1e-12 * rng.standard_normal((20, 3))
    assert _problems(same) == [
        "the 20 postures do not differ (every joint spreads by at most "
        f"{np.ptp(same, axis=0).max():.3g} rad): no variance to fit synergies to"
    ]
    # a CSV saved with its index: a nameless column, or a column counting the rows
    assert _problems(x, ("", "b", "c"))[0].startswith("column 1 has no joint name")
    counted = np.column_stack([np.arange(20), x[:, 1:]])
    assert _problems(counted)[0].startswith("column 1 ('a') counts the rows 0, 1, …, 19")
    # degrees: most postures beyond a full turn; an outlier: a few, named by row (1-based)
    assert _problems(np.degrees(x)) == [
        f"20 of 20 postures have angles beyond 2π (up to {np.degrees(x).max():.4g}); "
        "postures are in rad (is the table in degrees?)"
    ]
    outlier = x.copy()
    outlier[[3, 7], 2] = [50.0, -7.0]
    assert _problems(outlier) == [
        "row(s) 4, 8 beyond a full turn (row 4, joint 'c' is 50 rad, beyond 2π): an outlier "
        "no joint reaches; remove or correct it"
    ]
    # 2π itself is a posture a joint may have (inclusive bound)
    edge = x.copy()
    edge[0, 0] = 2 * np.pi
    assert _problems(edge) == []


def test_fit_refuses_postures_that_differ_by_rounding_noise_alone():
    x = np.tile([0.1, 0.2, 0.3], (30, 1)) + 1e-15 * np.arange(30)[:, None]
    with pytest.raises(ValueError, match="the 30 postures do not differ"):
        fit_synergies(("a", "b", "c"), x)
