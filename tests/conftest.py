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


#: Near-boundary band (docs/batched_solver.md): problems whose friction coefficient is within
#: this relative distance of the critical one may get either verdict from solvers with 1e-8
#: tolerances.
BAND = 1e-4


def study_gfo_params(**changes):
    """The study's GFO parameters (the configuration's defaults, obj1's weight) with
    ``changes`` replacing fields; the one path from configuration to parameters."""
    return replace(step_params(defaults(), "optimise", "obj1").gfo, **changes)


def study_placement(obj="obj1", **changes):
    """The study's placement of ``obj`` with its pose grid (the configuration's defaults) in
    its ``approach`` preset (the palm centre: a searched target needs the search's output),
    with ``changes`` replacing fields."""
    return replace(step_params(defaults(), "simulate", obj).placement, **{"mode": "approach", **changes})


def study_dynamic_params(**changes):
    """The dynamic closure's settings of the configuration's defaults, ``changes`` replaced."""
    return replace(step_params(defaults(), "simulate", "obj1").closure.dynamic, **changes)


def study_closure_params(**changes):
    """The study's closure settings (the configuration's defaults), ``changes`` replaced."""
    return replace(step_params(defaults(), "simulate", "obj1").closure, **changes)


def study_analysis_settings(**changes):
    """The study's analysis settings (the configuration's defaults) for tables of made-up
    objects (no weights, no α-periods), with ``changes`` replacing fields."""
    return replace(step_params(defaults(), "tables").settings, weights_N={}, periods_deg={}, **changes)
