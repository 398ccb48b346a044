"""Realistic random grasp and grasp-force problems for tests and benchmarks.

Everything is deterministic from a seed. Magnitudes follow the hand: boxes of 30-100 mm,
contact lever arms about the joints of 20-90 mm, stiffnesses and weight of the study
(docs/force_optimisation.md).
Link layout used here (one link per joint, distal to proximal along a chain):
link 0 = palm; links 1-3 = thumb (joints 0..k-1 move link k); links 4-7 index,
8-11 middle, 12-15 ring, 16-19 little (link 4f+4+k is moved by the first k+1 joints of
long finger f). A contact's Jacobian rows are non-zero only on its chain's joints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from synergrasp.optimisation.cones import CircularCone, FrictionCone
from synergrasp.optimisation.gfo import solve_gfo
from synergrasp.optimisation.mechanics import Grasp, grasp_mechanics, internal_force_basis, weight_wrench
from synergrasp.optimisation.problem import GFOProblem

__all__ = [
    "GeneratedProblem",
    "LINK_CHAINS",
    "N_JOINTS",
    "critical_friction",
    "random_gfo_problems",
    "random_grasp",
    "random_synergies",
    "random_unit_vector",
]

N_JOINTS = 19


def _link_chains() -> tuple[tuple[int, ...], ...]:
    chains: list[tuple[int, ...]] = [()]  # palm: no joint moves it
    chains += [tuple(range(k + 1)) for k in range(3)]  # thumb joints 0, 1, 2
    for finger in range(4):
        first = 3 + 4 * finger
        chains += [tuple(range(first, first + k + 1)) for k in range(4)]
    return tuple(chains)


#: Joints that move each link (index = link index).
LINK_CHAINS: tuple[tuple[int, ...], ...] = _link_chains()
#: Links a finger contact is put on: phalanges, i.e. links moved by at least two joints.
_PHALANX_LINKS = np.array([k for k, chain in enumerate(LINK_CHAINS) if len(chain) >= 2])


@dataclass(frozen=True)
class GeneratedProblem:
    """One generated grasp-force optimisation problem (`problem` gives it to `solve_gfo`)
    and how it was made.

    f_p: (c,) N; E: (c, e_s) orthonormal; normals: (m, 3); mu; f_min: N.
    kind: 'nominal' (mu as asked), 'feasible' / 'infeasible' (mu = mu* (1 + delta),
    |delta| 5-50 %), 'near_boundary' (|delta| 1e-6 .. 1e-2), 'infeasible_any_mu'
    (no mu up to the search limit makes it feasible).
    mu_star: critical friction coefficient (least feasible mu; inf if none; NaN if not
    computed, for 'nominal'); delta: mu / mu_star - 1 (NaN if not computed).
    """

    f_p: NDArray
    E: NDArray
    normals: NDArray
    mu: float
    f_min: float
    kind: str
    delta: float = float("nan")
    mu_star: float = float("nan")
    n_palm: int = 0
    s: int = 0
    index: int = 0

    @property
    def n_contacts(self) -> int:
        return int(self.normals.shape[0])

    @property
    def problem(self) -> GFOProblem:
        """The problem with the exact (circular) Coulomb cone of friction coefficient mu."""
        return GFOProblem(self.f_p, self.E, self.normals, self.f_min, CircularCone(self.mu))

    @property
    def e_s(self) -> int:
        return int(self.E.shape[1])


def random_unit_vector(rng: np.random.Generator, size: int | None = None) -> NDArray:
    """Uniform random unit vector(s) (3,) or (size, 3)."""
    v = rng.normal(size=(1 if size is None else size, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v[0] if size is None else v


def random_grasp(
    rng: np.random.Generator,
    n_contacts: int,
    palm_contacts: int = 0,
    *,
    box_half_size: tuple[float, float] = (15.0, 50.0),
    lever_arm: tuple[float, float] = (20.0, 90.0),
    center: tuple[float, float, float] = (35.0, 0.0, 110.0),
) -> Grasp:
    """A random grasp of a box: contacts on its faces with inward normals.

    Half sizes of the box uniform in `box_half_size` (mm). The first `palm_contacts`
    contacts lie on the face toward the palm (-x side, inward normal +x) and have zero
    Jacobian rows; the others sit on random faces and random phalanx links. Jacobian column
    of joint j for contact point p: u_j x r, u_j a random joint axis shared by the grasp,
    r a random lever arm with |r| uniform in `lever_arm` (mm), so entries are mm/rad.
    """
    if not (isinstance(n_contacts, (int, np.integer)) and n_contacts >= 1):
        raise ValueError(f"n_contacts must be an int >= 1, got {n_contacts!r}")
    if not (isinstance(palm_contacts, (int, np.integer)) and 0 <= palm_contacts <= n_contacts):
        raise ValueError(f"palm_contacts must be an int in 0..n_contacts ({n_contacts}), got {palm_contacts!r}")
    m, n_palm = int(n_contacts), int(palm_contacts)
    half = rng.uniform(*box_half_size, size=3)
    o = np.asarray(center, dtype=float) + rng.uniform(-5.0, 5.0, size=3)

    # Face of each contact: axis a in {0,1,2}, side +-1; palm contacts on the -x face.
    axis = rng.integers(0, 3, size=m)
    side = rng.choice([-1.0, 1.0], size=m)
    axis[:n_palm], side[:n_palm] = 0, -1.0
    local = rng.uniform(-1.0, 1.0, size=(m, 3)) * half
    local[np.arange(m), axis] = side * half[axis]
    points = o + local
    normals = np.zeros((m, 3))
    normals[np.arange(m), axis] = -side  # inward

    links = np.zeros(m, dtype=np.int64)
    links[n_palm:] = rng.choice(_PHALANX_LINKS, size=m - n_palm)
    joint_axes = random_unit_vector(rng, N_JOINTS)
    levers = random_unit_vector(rng, m * N_JOINTS).reshape(m, N_JOINTS, 3)
    levers *= rng.uniform(*lever_arm, size=(m, N_JOINTS, 1))
    columns = np.cross(joint_axes[None, :, :], levers)  # (m, n, 3): d p_i / d q_j
    mask = np.zeros((m, N_JOINTS))
    for i, link in enumerate(links):
        mask[i, list(LINK_CHAINS[link])] = 1.0
    jacobian = (columns * mask[:, :, None]).transpose(0, 2, 1).reshape(3 * m, N_JOINTS)
    return Grasp(points=points, normals=normals, links=links, jacobian=jacobian, center=o)


def random_synergies(rng: np.random.Generator, n: int = N_JOINTS, k: int = 15) -> NDArray:
    """A random n x k synergy matrix with orthonormal columns (rad per unit activation)."""
    if not (1 <= k <= n):
        raise ValueError(f"need 1 <= k <= n, got n={n}, k={k}")
    Q, R = np.linalg.qr(rng.normal(size=(n, k)))
    return Q * np.sign(np.diag(R))


def critical_friction(
    f_p: NDArray,
    E: NDArray,
    normals: NDArray,
    f_min: float,
    *,
    rtol: float = 1e-9,
    mu_start: float = 1.5,
    mu_max: float = 1e3,
    mu_min: float = 1e-6,
    cone: FrictionCone = CircularCone(1.0),
) -> float:
    """Least mu at which the GFO problem is feasible, by bisection on log(mu).

    cone: the friction-cone model whose mu is varied (its own mu is ignored; a pyramid keeps
    its sides and inscription).

    Feasibility is monotone in mu (the cones grow with it). Returns inf if the problem is
    infeasible at `mu_max`, 0.0 if feasible at `mu_min`; otherwise the upper end of a
    bracket [lo, hi] with hi / lo - 1 <= rtol (hi feasible, lo infeasible, by `solve_gfo`).
    """

    def feasible(mu: float) -> bool:
        problem = GFOProblem(f_p, E, normals, f_min, replace(cone, mu=mu))
        return solve_gfo([problem], "clarabel").status[0] == "feasible"

    if feasible(mu_start):
        hi, lo = mu_start, mu_start / 2
        while feasible(lo):
            hi, lo = lo, lo / 2
            if lo < mu_min:
                return 0.0
    else:
        lo, hi = mu_start, mu_start * 2
        while not feasible(hi):
            lo, hi = hi, hi * 2
            if hi > mu_max:
                return math.inf
    while hi / lo - 1.0 > rtol:
        mid = math.sqrt(lo * hi)
        if feasible(mid):
            hi = mid
        else:
            lo = mid
    return hi


#: Shares of problem kinds drawn by `random_gfo_problems` (nominal, far from the
#: boundary on either side, near the boundary).
_KIND_SHARES = (0.4, 0.2, 0.4)


def random_gfo_problems(
    seed: int,
    count: int,
    *,
    mu: float = 1.5,
    f_min: float = 0.1,
    k_stru: float = 1.0,
    k_ss: float = 200.0,
    contacts: tuple[int, int] = (3, 20),
    synergies: tuple[int, int] = (1, 15),
    max_palm: int = 2,
    near_delta: tuple[float, float] = (1e-6, 1e-2),
) -> list[GeneratedProblem]:
    """`count` GFO problems from random grasps, deterministic from `seed`.

    Each problem: m contacts uniform in `contacts` (up to `max_palm` of them on the palm,
    always leaving one finger contact), random gravity direction with a 1 kg weight,
    s synergies uniform in `synergies` from a random orthonormal synergy matrix, E_s from
    `internal_force_basis`. About 40 % keep mu ('nominal'), 20 % get mu = mu* (1 +- 5..50 %)
    ('feasible' / 'infeasible'), 40 % mu = mu* (1 + delta) with |delta| log-uniform in
    `near_delta` and a random sign ('near_boundary'); mu* from `critical_friction`.
    Grasps with rank(G) < 6 are redrawn; so are (up to 10 times) off-nominal problems that
    no mu makes feasible, which are kept as 'infeasible_any_mu' only if every redraw fails.
    """
    if not (isinstance(count, int) and count >= 0):
        raise ValueError(f"count must be an int >= 0, got {count!r}")
    problems: list[GeneratedProblem] = []
    for index in range(count):
        rng = np.random.default_rng([int(seed), index])
        u = rng.random()
        # Problems off the nominal mu need a finite mu*: redraw (a few times) those that no
        # friction makes feasible, so near-boundary problems keep their share.
        for attempt in range(_REDRAWS):
            f_p, E, normals, n_palm, s = _random_instance(rng, contacts, synergies, max_palm, k_stru, k_ss)
            if u < _KIND_SHARES[0]:
                break
            mu_star = critical_friction(f_p, E, normals, f_min)
            if not math.isinf(mu_star):
                break
        common = dict(f_p=f_p, E=E, normals=normals, f_min=f_min, n_palm=n_palm, s=s, index=index)
        if u < _KIND_SHARES[0]:
            problems.append(GeneratedProblem(mu=mu, kind="nominal", **common))
        elif math.isinf(mu_star):
            problems.append(GeneratedProblem(mu=mu, kind="infeasible_any_mu", delta=-1.0, mu_star=mu_star, **common))
        elif mu_star == 0.0:
            problems.append(GeneratedProblem(mu=mu, kind="feasible", delta=math.inf, mu_star=0.0, **common))
        else:
            sign = rng.choice([-1.0, 1.0])
            if u < _KIND_SHARES[0] + _KIND_SHARES[1]:
                delta = sign * rng.uniform(0.05, 0.5)
                kind = "feasible" if delta > 0 else "infeasible"
            else:
                delta = sign * math.exp(rng.uniform(math.log(near_delta[0]), math.log(near_delta[1])))
                kind = "near_boundary"
            problems.append(
                GeneratedProblem(mu=mu_star * (1.0 + delta), kind=kind, delta=float(delta), mu_star=mu_star, **common)
            )
    return problems


_REDRAWS = 10


def _random_instance(rng, contacts, synergies, max_palm, k_stru, k_ss):
    """f_p, E, normals, number of palm contacts and s of one random grasp (rank(G) = 6)."""
    while True:
        m = int(rng.integers(contacts[0], contacts[1] + 1))
        n_palm = int(rng.integers(0, min(max_palm, m - 1) + 1))
        grasp = random_grasp(rng, m, palm_contacts=n_palm)
        mech = grasp_mechanics(grasp, weight_wrench(9.81, random_unit_vector(rng)), k_stru, k_ss)
        if mech.rank_G == 6:
            break
    s = int(rng.integers(synergies[0], synergies[1] + 1))
    S = random_synergies(rng)
    subset = np.sort(rng.choice(S.shape[1], size=s, replace=False))
    E = internal_force_basis(mech.projector, S[:, subset], mech.response_norm)
    return mech.f_p, E, grasp.normals, n_palm, s
