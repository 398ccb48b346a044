"""The claims' verdicts from intervals on hand-made study tables: where a claim holds, does
not hold, is a tie, rests on too few poses or on nothing; both views of "averaged over
objects"; forces compared like with like."""

import numpy as np
import pandas as pd
import pytest

from synergrasp.analysis.bootstrap import BootstrapSettings, PoseResampler
from synergrasp.analysis.claims import FAILS, HOLDS, UNDEFINED, Difference, VerdictRules, claims_table, interval_verdict
from synergrasp.analysis.intervals import StudyCounts

FULL = "1-2-3-4-5-6-7"
ALPHAS = np.arange(0.0, 90.0, 5.0)  # 18
BETAS = np.arange(0.0, 50.0, 5.0)  # 10: 180 poses, 6 x 4 blocks of 15 deg
N = ALPHAS.size * BETAS.size
RULES = VerdictRules(rate_points=1.0, force_relative=0.05, min_distinct_poses=30, headline_view="per_object")
SETTINGS = BootstrapSettings(resamples=300, seed=1, block_deg=15.0, level=0.95)
SETS = [str(i) for i in range(1, 8)] + [f"{i}-{j}" for i in range(1, 8) for j in range(i + 1, 8)] + [FULL]


def study(objects: dict[str, dict[str, np.ndarray]], forces: dict[str, dict[str, np.ndarray]] | None = None) -> StudyCounts:
    """A study of objects on an 18 x 10 grid (period 360: every pose distinct); per object
    the poses (bool, length N) where each set succeeds (absent sets: nowhere; the full set:
    wherever any set does unless given) and optional forces (N) per set."""
    a, b = np.meshgrid(ALPHAS, BETAS, indexing="ij")
    parts = []
    for obj, succeeds in objects.items():
        full = succeeds.get(FULL, np.any([v for v in succeeds.values()], axis=0) if succeeds else np.zeros(N, bool))
        for sid in SETS:
            ok = full if sid == FULL else succeeds.get(sid, np.zeros(N, bool))
            force = (forces or {}).get(obj, {}).get(sid, np.ones(N))
            parts.append(
                pd.DataFrame(
                    {
                        "object": obj,
                        "pose": np.arange(N),
                        "alpha_deg": a.ravel(),
                        "beta_deg": b.ravel(),
                        "set_id": sid,
                        "success": ok,
                        "success_force": np.where(ok, force, np.nan),
                    }
                )
            )
    table = pd.concat(parts, ignore_index=True)
    return StudyCounts(table, FULL, PoseResampler(table[table["set_id"] == FULL], {}, SETTINGS))


def claims(counts: StudyCounts) -> pd.DataFrame:
    minima = pd.DataFrame(
        {
            "object": counts.objects,
            "n_minima": [np.zeros(counts.rows)] * len(counts.objects),
            "n_preserved": [np.zeros(counts.rows)] * len(counts.objects),
        }
    )
    chance = pd.DataFrame({"object": ["all"], "pairs": ["all"], "null_high_percent": [30.0]})
    return claims_table(counts, minima, chance, RULES).set_index(["claim", "view"])


def every(step: int, offset: int = 0) -> np.ndarray:
    """Every ``step``-th pose from ``offset``: spread over the grid, so each block holds a share."""
    out = np.zeros(N, bool)
    out[offset::step] = True
    return out


def test_interval_rules():
    d = dict(band=1.0, n=100)
    assert interval_verdict(Difference(5.0, 2.0, 8.0, **d), 30)[0] == HOLDS
    assert interval_verdict(Difference(-5.0, -8.0, -2.0, **d), 30)[0] == FAILS
    assert interval_verdict(Difference(1.5, 0.5, 2.5, **d), 30) == (UNDEFINED, "interval overlaps the tie band (±1)")
    assert interval_verdict(Difference(0.0, -0.5, 0.5, **d), 30)[1].startswith("interval inside the tie band")
    assert interval_verdict(Difference(5.0, 2.0, 8.0, band=1.0, n=29), 30) == (UNDEFINED, "fewer than 30 distinct poses: 29")
    assert interval_verdict(Difference(5.0, 2.0, 8.0, band=1.0, n=0), 30)[1].startswith("nothing to compare")
    # a claim of equality: "reaches 100 %" (d <= 0) holds within the band, fails beyond it
    assert interval_verdict(Difference(-0.5, -0.9, 0.0, band=1.0, n=50, kind="within_below"), 30)[0] == HOLDS
    assert interval_verdict(Difference(-5.0, -7.0, -2.0, band=1.0, n=50, kind="within_below"), 30)[0] == FAILS
    assert interval_verdict(Difference(0.5, 0.0, 3.0, band=1.0, n=50, kind="within_above"), 30)[0] == UNDEFINED


def test_a_claim_with_nothing_to_compare_is_undefined():
    """No pose reaches force closure: nothing holds (claim 2 said "holds: 0 poses" before)."""
    table = claims(study({"a": {}, "b": {}}))
    assert (table["verdict"] == UNDEFINED).all()
    assert "nothing to compare" in table.loc[(2, "per_object"), "reason"]
    assert "nothing to compare" in table.loc[(1, "each_object"), "reason"]


def test_too_few_poses_and_a_tie_are_undefined():
    s1 = np.zeros(N, bool)
    s1[:10] = True  # S1 alone on 10 poses, every other single nowhere
    few = claims(study({"a": {"1": s1, FULL: every(2)}}))
    assert few.loc[(4, "per_object"), "verdict"] == UNDEFINED
    assert few.loc[(4, "per_object"), "reason"] == "fewer than 30 distinct poses: 10"
    # S1 and S7 succeed on the same 60 poses: a difference of 0 in every resample
    tie = claims(study({"a": {"1": every(3), "7": every(3), FULL: every(2)}}))
    row = tie.loc[(4, "per_object")]
    assert row["verdict"] == UNDEFINED and row["reason"].startswith("interval inside the tie band")
    assert row["low"] == row["high"] == 0.0 and row["n_distinct_poses"] == 60


def test_pooled_and_per_object_views_on_two_objects():
    """a: the full set at all 180 poses, S1 at 90, S7 nowhere; b: the full set at 45 poses,
    S7 at all of them. Per object: S1 (50 + 0) / 2 = 25 %, S7 (0 + 100) / 2 = 50 %: claim 4
    does not hold. Pooled: S1 90 / 225 = 40 %, S7 45 / 225 = 20 %: it holds."""
    b_full = every(4)
    counts = study({"a": {"1": every(2), FULL: np.ones(N, bool)}, "b": {"7": b_full, FULL: b_full}})
    assert counts.rate("1", "per_object")[0] == pytest.approx(25.0)
    assert counts.rate("7", "per_object")[0] == pytest.approx(50.0)
    assert counts.rate("1", "pooled")[0] == pytest.approx(40.0)
    assert counts.rate("7", "pooled")[0] == pytest.approx(20.0)
    table = claims(counts)
    assert table.loc[(4, "per_object"), "difference"] == pytest.approx(-25.0)
    assert table.loc[(4, "pooled"), "difference"] == pytest.approx(20.0)
    assert table.loc[(4, "per_object"), "verdict"] == FAILS and table.loc[(4, "per_object"), "headline"]
    assert table.loc[(4, "pooled"), "verdict"] == HOLDS and not table.loc[(4, "pooled"), "headline"]
    assert list(table.loc[4].index) == ["per_object", "pooled"]  # the study's view first


def forces_case(shared_with_s7: int) -> pd.DataFrame:
    """Every single succeeds on the same 60 poses, where S1, S4, S5 need 1 N and the others
    2 N; S1 also succeeds alone on 90 more poses at 100 N (a plain mean over each set's own
    successes would rank S1 last). S7 shares ``shared_with_s7`` of the 60 poses."""
    common = every(3)
    extra = every(3, 1) | every(6, 2)
    s7 = common.copy()
    s7[np.flatnonzero(common)[shared_with_s7:]] = False
    succeeds = {str(i): common for i in range(2, 7)} | {"1": common | extra, "7": s7, FULL: np.ones(N, bool)}
    force = {str(i): np.full(N, 2.0) for i in (2, 3, 6, 7)} | {s: np.ones(N) for s in ("4", "5")}
    force["1"] = np.where(extra, 100.0, 1.0)
    return claims(study({"a": succeeds}, {"a": force}))


def test_claim7_compares_like_with_like_on_unequal_success_sets():
    row = forces_case(60).loc[(7, "pooled")]
    assert row["verdict"] == HOLDS and row["n_distinct_poses"] == 60
    assert np.exp(row["difference"]) == pytest.approx(2.0)  # F(other) / F(named) on the common poses
    short = forces_case(10).loc[(7, "pooled")]
    assert short["verdict"] == UNDEFINED
    assert "S1-S7 (10)" in short["reason"] and "S4-S7 (10)" in short["reason"]


def test_an_object_with_too_few_poses_is_left_out_of_claim1():
    """Here {S1..S7} is the full set, so it reaches 100 % on a (180 poses); b has 10 poses
    only: it is left out and named, and the claim cannot hold."""
    b_full = np.zeros(N, bool)
    b_full[:10] = True
    row = claims(study({"a": {FULL: np.ones(N, bool)}, "b": {FULL: b_full}})).loc[(1, "each_object")]
    assert row["difference"] == 0.0 and row["n_distinct_poses"] == 180
    assert row["verdict"] == UNDEFINED
    assert row["reason"] == "comparisons with fewer than 30 distinct poses: b (10)"
