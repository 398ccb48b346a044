"""Pyramid friction cones solved as QPs: hand-derived pinches, the nesting of the pyramids
and the circular cone on generated problems, and PIQP against Clarabel on the same pyramid."""

import math

import numpy as np
import pytest

from synergrasp.optimisation.cones import CircularCone, PyramidCone
from synergrasp.optimisation.gfo import solve_gfo
from synergrasp.optimisation.mechanics import contact_frames
from synergrasp.optimisation.problem import GFOProblem
from synergrasp.optimisation.problems import random_gfo_problems

W = 9.81
MU = 1.5
SQUEEZE = np.array([[1.0, 0, 0, -1.0, 0, 0]]).T / math.sqrt(2)
PINCH_NORMALS = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
#: (sides, inscribed) of the study's pyramid models (issue: 4 and 8 inscribed, 8 circumscribed)
MODELS = [(4, True), (8, True), (8, False)]


def pinch(load_direction, cone, f_min=0.1, method="piqp"):
    """Antipodal pinch along x carrying W/2 at each contact along `load_direction` (in the
    contacts' tangent plane y-z); the squeeze u is the only internal force."""
    d = np.asarray(load_direction, dtype=float) / np.linalg.norm(load_direction)
    fp = np.concatenate([W / 2 * d, W / 2 * d])
    return solve_gfo([GFOProblem(fp, SQUEEZE, PINCH_NORMALS, f_min, cone)], method)


def test_pinch_frames_put_an_edge_along_the_load():
    """For normals +-x the frame's t1 is +z at the first contact and -z at the second: a load
    along z runs along an edge of every pyramid (the stated tangent axis)."""
    frames = contact_frames(PINCH_NORMALS)
    np.testing.assert_allclose(frames[:, 1], [[0, 0, 1], [0, 0, -1]])


@pytest.mark.parametrize("method", ["piqp", "clarabel"])
@pytest.mark.parametrize("sides,inscribed", MODELS)
def test_pinch_closed_form(sides, inscribed, method):
    """f_i = (+-u, W/2 d): feasible iff W/2 <= mu_eff u, so u* = max(f_min, W / (2 mu_eff)) and
    ||f*|| = sqrt(2 u*^2 + W^2 / 2). Along an edge (d = z) mu_eff is mu (inscribed) or
    mu / cos(pi / sides) (circumscribed); for the 4-sided inscribed pyramid, across a face's
    middle (d at 45 deg between t1 and t2 at both contacts, (z - y) / sqrt 2) it is mu cos(pi / 4)."""
    cone = PyramidCone(MU, sides, inscribed)
    mu_edge = MU if inscribed else MU / math.cos(math.pi / sides)
    cases = [((0, 0, 1), mu_edge)]
    if (sides, inscribed) == (4, True):
        cases.append(((0, -1, 1), MU * math.cos(math.pi / 4)))
    for d, mu_eff in cases:
        for f_min in (0.1, 5.0):
            sol = pinch(d, cone, f_min, method)
            u = max(f_min, W / (2 * mu_eff))
            assert sol.status[0] == "force_closure" and sol.solver[0] == method
            assert sol.force_norm[0] == pytest.approx(math.sqrt(2 * u**2 + W**2 / 2), rel=1e-6)
    # a load the cone cannot carry at any squeeze: tangential only, no normal force possible
    bad = GFOProblem(np.array([0, 0, 1.0, 0, 0, 1.0]), np.zeros((6, 0)), PINCH_NORMALS, 0.1, cone)
    assert solve_gfo([bad], method).status[0] == "infeasible"


@pytest.fixture(scope="module")
def generated():
    problems = random_gfo_problems(31, 150)
    base = [p.problem for p in problems]

    def with_cone(cone_of):
        return [GFOProblem(p.f_p, p.E, p.normals, p.f_min, cone_of(p.cone.mu)) for p in base]

    return {
        "circular": solve_gfo(base, "clarabel"),
        **{(s, i): solve_gfo(with_cone(lambda mu, s=s, i=i: PyramidCone(mu, s, i)), "piqp") for s, i in MODELS},
        "clarabel_pyramids": {(s, i): solve_gfo(with_cone(lambda mu, s=s, i=i: PyramidCone(mu, s, i)), "clarabel")
                              for s, i in MODELS},
    }


def test_inscribed_pyramids_inside_the_circular_cone_inside_the_circumscribed(generated):
    """Inscribed 4 in inscribed 8 in the circle in circumscribed 8: a problem feasible for a
    smaller cone is feasible for every larger one, at no larger optimal force."""
    chain = [generated[(4, True)], generated[(8, True)], generated["circular"], generated[(8, False)]]
    for small, large in zip(chain, chain[1:]):
        ok = small.force_closure
        assert np.all(large.force_closure[ok] | (large.status[ok] == "numerical_failure"))
        both = ok & large.force_closure
        assert np.all(large.force_norm[both] <= small.force_norm[both] * (1 + 1e-6))
    counts = [int(s.force_closure.sum()) for s in chain]
    assert counts == sorted(counts) and counts[0] < counts[-1]


def test_piqp_agrees_with_clarabel_on_the_same_pyramid(generated):
    for model in MODELS:
        a, b = generated[model], generated["clarabel_pyramids"][model]
        decided = np.isin(a.status, ("force_closure", "infeasible")) & np.isin(b.status, ("force_closure", "infeasible"))
        assert decided.mean() > 0.95
        differ = decided & (a.status != b.status)
        assert differ.sum() <= 0.02 * len(a), (model, np.flatnonzero(differ))
        both = decided & a.force_closure & b.force_closure
        np.testing.assert_allclose(a.force_norm[both], b.force_norm[both], rtol=1e-4)


def test_methods_refuse_cones_they_do_not_solve():
    problem = GFOProblem(np.zeros(6), SQUEEZE, PINCH_NORMALS, 0.1, PyramidCone(MU))
    with pytest.raises(ValueError, match="method 'ipm' accepts the friction cones"):
        solve_gfo([problem], "ipm")
    circular = GFOProblem(np.zeros(6), SQUEEZE, PINCH_NORMALS, 0.1, CircularCone(MU))
    with pytest.raises(ValueError, match="method 'piqp' accepts"):
        solve_gfo([circular], "piqp")
    with pytest.raises(ValueError, match="cone.sides"):
        PyramidCone(MU, sides=2)
