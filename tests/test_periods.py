"""α-period from the shape, the placement and the rotation order; distinct poses; the check
that results repeat with the period."""

import numpy as np
import pandas as pd
import pytest

from conftest import study_placement
from synergrasp.config import defaults
from synergrasp.analysis.periods import alpha_period_deg, distinct_pose_mask, object_periods, period_violations
from synergrasp.simulation.shapes import Box

GRID = dict(alpha_deg=(-180.0, 175.0, 5.0), beta_deg=(-60.0, 60.0, 5.0))


@pytest.mark.parametrize(
    "size, axes, order, beta, period",
    [
        ((30, 30, 30), (0, 1, 2), "alpha_then_beta", GRID["beta_deg"], 90.0),  # cube
        ((100, 30, 30), (0, 1, 2), "alpha_then_beta", GRID["beta_deg"], 90.0),  # bar, square end toward the palm
        ((30, 100, 30), (1, 0, 2), "alpha_then_beta", GRID["beta_deg"], 90.0),  # the same bar, named otherwise
        ((30, 30, 100), (0, 1, 2), "alpha_then_beta", GRID["beta_deg"], 180.0),  # bar lying across: 30 x 100 face
        ((100, 60, 100), (1, 0, 2), "alpha_then_beta", GRID["beta_deg"], 90.0),  # obj4: 100 x 100 face toward the palm
        ((60, 30, 100), (0, 1, 2), "alpha_then_beta", GRID["beta_deg"], 180.0),  # no square face at all
        ((30, 30, 30), (0, 1, 2), "beta_then_alpha", GRID["beta_deg"], 360.0),  # a tilted cube is not symmetric about n
        ((30, 30, 30), (0, 1, 2), "beta_then_alpha", (0.0, 0.0, 5.0), 90.0),  # ... unless beta is always 0
    ],
)
def test_period_of_boxes(size, axes, order, beta, period):
    placement = study_placement(
        center_mm=(40.0, 5.0, 110.0), box_axes=axes, rotation_order=order, alpha_deg=GRID["alpha_deg"], beta_deg=beta
    )
    assert alpha_period_deg(placement, Box(size)) == period


def test_object_periods_from_the_config():
    placement = {**defaults()["placement"], "mode": "fixed", "center_mm": [38, 5, 112]}  # the effective placement
    objects = {
        "cube": {"shape": {"box": {"size_mm": [30, 30, 30]}}, "placement": placement},
        "slab": {"shape": {"box": {"size_mm": [30, 60, 100]}}, "placement": {**placement, "box_axes": [0, 1, 2]}},
    }
    grid = {"alpha_deg": {"start": -180, "stop": 175, "step": 5}, "beta_deg": {"start": -60, "stop": 60, "step": 5}}
    assert object_periods(objects, grid) == {"cube": 90.0, "slab": 180.0}


def test_distinct_pose_mask_keeps_one_period():
    alpha = np.arange(-180.0, 180.0, 5.0)
    mask = distinct_pose_mask(alpha, 90.0)
    assert mask.sum() == 18 and alpha[mask].min() == -180.0 and alpha[mask].max() == -95.0
    assert distinct_pose_mask(alpha, 360.0).all()


def periodic_table(period: float) -> pd.DataFrame:
    """Verdicts and forces that depend on alpha only through alpha mod period."""
    rows = []
    for alpha in np.arange(-180.0, 180.0, 30.0):
        for beta in (-10.0, 0.0, 10.0):
            phase = (alpha % period) + beta
            ok = phase % 20 != 0
            rows.append(
                dict(
                    object="o",
                    set_id="1",
                    alpha_deg=alpha,
                    beta_deg=beta,
                    verdict_force_closure=ok,
                    verdict_load_feasible=True,
                    force_norm=1.0 + abs(phase),
                )
            )
    return pd.DataFrame(rows)


def test_period_violations_on_periodic_and_broken_results():
    table = periodic_table(90.0)
    assert period_violations(table, 90.0).empty
    assert period_violations(table, 180.0).empty
    broken = table.copy()
    at = (broken["alpha_deg"] == 0.0) & (broken["beta_deg"] == 10.0)
    broken.loc[at, "force_norm"] *= 1.01
    bad = period_violations(broken, 90.0)
    # the pose (0, 10) differs from (90, 10), and (-90, 10) differs from it
    assert sorted(bad["alpha_deg"].tolist()) == [-90.0, 0.0] and set(bad["what"]) == {"force"}
    broken.loc[at, "verdict_force_closure"] = ~broken.loc[at, "verdict_force_closure"]
    assert set(period_violations(broken, 90.0)["what"]) == {"verdict"}
    assert period_violations(broken, 360.0).empty  # nothing to compare
