"""Fixtures shared by the test modules: the shipped hand and its synergies, the generated
GFO problems that the solvers are checked on, the study's GFO parameters."""

import os

# One BLAS thread per test process, set before numpy loads: the tests' matrices are small, and
# OpenBLAS's threads spinning beside the test process took about half of the fast tier's CPU
# time on the 2-core machine (a generated problem set: 4.5 s against 2.4 s).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import warnings  # noqa: E402
from dataclasses import replace  # noqa: E402

import pytest  # noqa: E402

from synergrasp.analysis.summaries import TablesParams  # noqa: E402
from synergrasp.config import _resolve, defaults, load_schema  # noqa: E402
from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.optimisation.optimise import OptimiseParams  # noqa: E402
from synergrasp.optimisation.gfo import solve_gfo  # noqa: E402
from synergrasp.simulation.closure import SimulateParams  # noqa: E402
from grasp_problems import random_gfo_problems  # noqa: E402


@pytest.fixture(scope="session")
def hand():
    return load_hand()


@pytest.fixture(scope="session")
def synergies(hand):
    return load_synergies(None, joint_names=hand.joint_names)


@pytest.fixture(scope="session")
def generated_problems():
    """600 generated GFO problems (`grasp_problems.random_gfo_problems`, seed 2018), made once
    for the modules that check the solvers on them (each problem's critical friction is
    bisected: they take about 16 CPU s to make)."""
    return random_gfo_problems(2018, 600)


@pytest.fixture(scope="session")
def generated_cvxpy(generated_problems):
    """The independent cvxpy reference's solution of every generated problem (test_gfo checks
    Clarabel against it, test_ipm_kernel the kernel)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy's "may be inaccurate" near the boundary
        return solve_gfo([p.problem for p in generated_problems], "cvxpy")


#: Near-boundary band (docs/ipm_solver.md): problems whose friction coefficient is within
#: this relative distance of the critical one may get either verdict from solvers with 1e-8
#: tolerances.
BAND = 1e-4


def study_gfo_params(**changes):
    """The study's GFO parameters (the configuration's defaults, obj1's weight) with
    ``changes`` replacing fields; the one path from configuration to parameters."""
    return replace(OptimiseParams.from_config(defaults(), "obj1").gfo, **changes)


def study_placement(obj="obj1", **changes):
    """The study's placement of ``obj`` with its pose grid (the configuration's defaults) in
    its ``approach`` preset (the palm centre: a searched target needs the search's output),
    with ``changes`` replacing fields."""
    return replace(SimulateParams.from_config(defaults(), obj).placement, **{"mode": "approach", **changes})


def study_dynamic_params(**changes):
    """The dynamic closure's settings of the configuration's defaults, ``changes`` replaced."""
    return replace(SimulateParams.from_config(defaults(), "obj1").closure.dynamic, **changes)


def study_closure_params(**changes):
    """The study's closure settings (the configuration's defaults), ``changes`` replaced."""
    return replace(SimulateParams.from_config(defaults(), "obj1").closure, **changes)


def study_analysis_settings(**changes):
    """The study's analysis settings (the configuration's defaults) for tables of made-up
    objects (no weights, no α-periods), with ``changes`` replacing fields."""
    return replace(TablesParams.from_config(defaults()).settings, weights_N={}, periods_deg={}, **changes)


def schema_leaf_paths(node=None, prefix=""):
    """Every key path of the configuration schema, objects' own keys as objects.*.<key>."""
    schema = _resolve(load_schema() if node is None else node)
    props = schema.get("properties", {})
    extra = schema.get("additionalProperties")
    if not props and isinstance(extra, dict) and _resolve(extra).get("properties"):
        return schema_leaf_paths(extra, f"{prefix}*.")
    if not props:
        return [prefix.rstrip(".")]
    return [p for name, sub in props.items() for p in schema_leaf_paths(sub, f"{prefix}{name}.")]


def scenario_configs(config):
    """Every scenario's complete configuration by name (``config.scenario_config``), ``default``
    first; every problem of every scenario in one ConfigError."""
    from synergrasp.config import ConfigError, scenario_config, scenario_names, validate_config

    out, problems = {}, []
    for name in scenario_names(validate_config(config)):
        try:
            out[name] = scenario_config(config, name)
        except ConfigError as err:
            problems += str(err).splitlines()
    if problems:
        raise ConfigError("\n".join(problems))
    return out
