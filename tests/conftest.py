"""Fixtures shared by the test modules: the shipped hand and its synergies."""
import pytest

from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies


@pytest.fixture(scope="session")
def hand():
    return load_hand()


@pytest.fixture(scope="session")
def synergies(hand):
    return load_synergies(None, joint_names=hand.joint_names)
