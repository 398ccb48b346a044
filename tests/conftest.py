"""Fixtures shared by the test modules: the shipped hand and its synergies, the study's
GFO parameters."""
from dataclasses import replace

import pytest

from synergrasp.config import defaults, step_params

from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies


@pytest.fixture(scope="session")
def hand():
    return load_hand()


@pytest.fixture(scope="session")
def synergies(hand):
    return load_synergies(None, joint_names=hand.joint_names)


def study_gfo_params(**changes):
    """The study's GFO parameters (the configuration's defaults, obj1's weight) with
    ``changes`` replacing fields; the one path from configuration to parameters."""
    return replace(step_params(defaults(), "optimise", "obj1").gfo, **changes)


def study_analysis_settings(**changes):
    """The study's analysis settings (the configuration's defaults) for tables of made-up
    objects (no weights, no α-periods), with ``changes`` replacing fields."""
    return replace(step_params(defaults(), "tables").settings, weights_N={}, periods_deg={}, **changes)
