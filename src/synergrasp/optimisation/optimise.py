"""The study's optimisation step: every (pose, synergy set) of one shard of an object's
poses, through the front door `gfo.solve_gfo`, into the gfo table (`table_contracts.GFO`).

Per pose the mechanics (G, K, G_K^R, f_p, the internal-force projector) is built once;
the pose's sets are then one `GraspSets` problem. Poses without a grasp give 'no_grasp',
grasps with rank(G) < 6 'rank_deficient', both without any solve (solver 'none').
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from synergrasp import resolved
from synergrasp.config import build, dataclass_fields
from synergrasp.ids import set_id, synergy_sets
from synergrasp.optimisation.cones import FrictionCone, cone_model
from synergrasp.optimisation.gfo import FASTEST_METHOD, solve_gfo
from synergrasp.optimisation.ipm.solver import IPMSettings
from synergrasp.optimisation.mechanics import (
    BASIS_RTOL,
    GRASP_RANK_RTOL,
    Grasp,
    GraspMechanics,
    first_same_grasp,
    grasp_mechanics,
    read_grasps,
    weight_wrench,
)
from synergrasp.optimisation.problem import DEFAULT_TOL, MAX_ITER, STRICT_SHRINK, GraspSets, SynergySets
from synergrasp.optimisation.shards import shard_positions

__all__ = ["GFOParams", "OptimiseParams", "UNSOLVED_STATUSES", "gfo_table", "mechanics_for", "optimise_grasps", "optimise_shard"]

#: The gfo table's statuses of a problem given before any solve: no grasp at the pose, and
#: rank(G) < 6 (the solved ones are ``problem.SOLVER_STATUSES``).
UNSOLVED_STATUSES: tuple[str, ...] = ("no_grasp", "rank_deficient")
NO_GRASP, RANK_DEFICIENT = UNSOLVED_STATUSES


@dataclass(frozen=True, kw_only=True)
class GFOParams:
    """Parameters of the grasp-force optimisation of one object.

    The study's values come from the configuration's ``mechanics`` block and the object's
    ``mass_kg`` through :meth:`OptimiseParams.from_config`; the schema holds their defaults
    and checks them; the field names are the config keys.

    gravity_direction: unit vector of gravity in the palm frame
    mu: Coulomb friction coefficient; f_min_N: least normal force at every contact, N
    friction_cone: the friction-cone model, one of cones.CONE_MODELS ('circular', the exact
        Coulomb cone; the pyramids), both solved by the compiled interior-point kernel
    k_stru_N_per_mm: structural contact stiffness, N/mm; k_ss_Nmm_per_rad: joint stiffness, N·mm/rad
    weight_N: the object's weight m·g, N (synergrasp.resolved.weight_N)
    basis_rtol: rank tolerance of E_s; grasp_rank_rtol: rank tolerance of G
    strict_shrink: relative narrowing of the cone in the strict internal-force test
    tol: Clarabel feasibility and gap tolerance; max_iter: its iteration cap
    (the last five are numerical settings of the solvers, not choices of the study)
    """

    gravity_direction: tuple[float, float, float]
    mu: float
    f_min_N: float
    friction_cone: str
    k_stru_N_per_mm: float
    k_ss_Nmm_per_rad: float
    weight_N: float
    basis_rtol: float = BASIS_RTOL
    grasp_rank_rtol: float = GRASP_RANK_RTOL
    strict_shrink: float = STRICT_SHRINK
    tol: float = DEFAULT_TOL
    max_iter: int = MAX_ITER

    def __post_init__(self) -> None:
        # The configuration is checked by its schema; a direction is normalised here
        # because every consumer relies on |d| = 1.
        d = np.asarray(self.gravity_direction, dtype=float)
        norm = float(np.linalg.norm(d)) if d.shape == (3,) and np.all(np.isfinite(d)) else 0.0
        if norm == 0.0:
            raise ValueError(f"gravity_direction must be a finite non-zero 3-vector, got {self.gravity_direction!r}")
        object.__setattr__(self, "gravity_direction", tuple(float(v) for v in d / norm))
        for name in ("mu", "f_min_N", "k_stru_N_per_mm", "k_ss_Nmm_per_rad", "weight_N"):
            object.__setattr__(self, name, float(getattr(self, name)))
        if not np.isfinite(self.weight_N) or self.weight_N < 0:
            raise ValueError(f"weight_N must be a finite number >= 0, got {self.weight_N}")
        # once per parameters, not per grasp (the study's loop reads it for every pose)
        wrench = weight_wrench(self.weight_N, np.asarray(self.gravity_direction))
        wrench.setflags(write=False)
        object.__setattr__(self, "_wrench", wrench)

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> GFOParams:
        """The configuration's ``mechanics`` with the weight of the object ``obj`` (μ and the
        weight as resolved, ``synergrasp.resolved``)."""
        return build(
            cls,
            "mechanics",
            **{**dataclass_fields(cls, config["mechanics"]), "mu": resolved.friction_mu(config)},
            weight_N=resolved.weight_N(config, obj),
        )

    def wrench(self) -> NDArray:
        """w_e (6,) the contacts must apply against the weight, N and N·mm (read-only)."""
        return self._wrench

    @property
    def cone(self) -> FrictionCone:
        """The friction-cone model of every contact."""
        return cone_model(self.friction_cone, self.mu)


@dataclass(frozen=True)
class OptimiseParams:
    """The optimisation of one object (the ``optimise`` step): the synergy file (None: the
    shipped table), the study's synergy sets by id, the GFO parameters (mechanics and the
    object's weight) and the number of pose shards."""

    synergies: str | None
    sets: dict[str, tuple[int, ...]]
    gfo: GFOParams
    pose_shards: int
    hand: str | None = None  # the hand file (None: the shipped hand), whose joints order the table's rows

    @classmethod
    def from_config(cls, config: Mapping[str, Any], obj: str) -> OptimiseParams:
        """From a configuration or the step's own part of it, for the object ``obj``."""
        return cls(
            config["synergies"],
            synergy_sets(config["synergy_sets"]),
            GFOParams.from_config(config, obj),
            int(config["solver"]["pose_shards"]),
            config["hand"],
        )


def mechanics_for(grasp: Grasp, params: GFOParams) -> GraspMechanics:
    """`grasp_mechanics` with the weight, stiffnesses and rank tolerance of `params`."""
    return grasp_mechanics(
        grasp, params.wrench(), params.k_stru_N_per_mm, params.k_ss_Nmm_per_rad, rank_rtol=params.grasp_rank_rtol
    )


def optimise_grasps(
    grasps: Sequence[Grasp | None],
    synergies: SynergySets,
    params: GFOParams,
    *,
    strict: bool = True,
    forces: bool = False,
    ipm: IPMSettings = IPMSettings(),
    mechanics: Sequence[GraspMechanics | None] | None = None,
) -> dict[str, NDArray]:
    """GFO verdict, optimal force and strict internal-force test of every (grasp, set).

    grasps: poses (None or no contacts: 'no_grasp'). Solved with the fastest method for the
    cone (`gfo.FASTEST_METHOD`: the compiled kernel, with Clarabel for what it leaves
    undecided, for every cone kind). strict=False skips the strict
    test (column all False). Returns columns, one row per (grasp, set), grasp-major:
    set_id, n_synergies, status, load_feasible, force_closure_def1 (rank(G) = 6 and the strict
    test), force_norm (N), e_s,
    rank_G, n_contacts, iterations, solver; with forces=True also ``forces``, each row's optimal
    contact forces (3m,) N (None unless load-feasible; the one-grasp inspector reads them).
    mechanics: each grasp's ``mechanics_for(grasp, params)`` (None where the grasp is None),
    when the caller keeps them (a caller that solves one grasp for many sets in turn, the
    planner); by default computed here.
    """
    n_sets, n_poses = len(synergies), len(grasps)
    if mechanics is not None and len(mechanics) != n_poses:
        raise ValueError(f"mechanics: one per grasp ({n_poses}), got {len(mechanics)}")
    total = n_sets * n_poses
    out = {
        "set_id": np.array([set_id(s) for s in synergies.sets] * n_poses, dtype=object),
        "n_synergies": np.tile(synergies.sizes.astype(np.int32), n_poses),
        "status": np.full(total, NO_GRASP, dtype=object),
        "load_feasible": np.zeros(total, dtype=bool),
        "force_closure_def1": np.zeros(total, dtype=bool),
        "force_norm": np.full(total, np.nan),
        "e_s": np.zeros(total, dtype=np.int32),
        "rank_G": np.zeros(total, dtype=np.int32),
        "n_contacts": np.zeros(total, dtype=np.int32),
        "iterations": np.zeros(total, dtype=np.int32),
        "solver": np.full(total, "none", dtype=object),
    }
    if forces:
        out["forces"] = np.full(total, None, dtype=object)
    cone = params.cone
    method = FASTEST_METHOD[cone.kind]
    for p, grasp in enumerate(grasps):
        if grasp is None or grasp.n_contacts == 0:
            continue
        rows = slice(p * n_sets, (p + 1) * n_sets)
        mech = mechanics_for(grasp, params) if mechanics is None else mechanics[p]
        out["rank_G"][rows] = mech.rank_G
        out["n_contacts"][rows] = mech.n_contacts
        if mech.rank_G < 6 or mech.projector is None:
            out["status"][rows] = RANK_DEFICIENT
            continue
        problems = GraspSets(
            mech.f_p,
            mech.normals,
            mech.projector,
            mech.response_norm,
            synergies,
            params.f_min_N,
            cone,
            params.basis_rtol,
            mech.frames,
        )
        sol = solve_gfo(
            problems,
            method,
            strict_shrink=params.strict_shrink if strict else None,
            tol=params.tol,
            max_iter=params.max_iter,
            ipm=ipm,
        )
        out["status"][rows], out["force_norm"][rows], out["e_s"][rows] = sol.status, sol.force_norm, sol.e_s
        out["iterations"][rows], out["solver"][rows] = sol.iterations, sol.solver
        if strict:  # rank(G) = 6 here, so the strict test is Definition 1
            out["force_closure_def1"][rows] = sol.strict_internal
        if forces:
            out["forces"][rows] = sol.forces
    out["load_feasible"] = out["status"] == "feasible"
    return out


def gfo_table(
    contacts: pd.DataFrame, synergies: SynergySets, params: GFOParams, *, strict: bool = True, shard: int = 0, n_shards: int = 1
) -> pd.DataFrame:
    """The gfo table (columns of `table_contracts.GFO`) of the poses of a contacts table, or of shard
    `shard` of `n_shards` of them, in pose order, each pose's sets in their given order.

    Poses with one grasp (`mechanics.first_same_grasp` over the whole table: a box's poses one
    α-period apart) share one solve, of the first of them, so every row of a pose is a function
    of that grasp alone, the same for any number of shards. A shard takes an equal share of
    the distinct grasps (`shards.shard_positions` over them) with every pose that has one of
    them, and its share of the poses without a grasp (over the table's positions)."""
    grasps = read_grasps(contacts)
    first = first_same_grasp(grasps)
    kinds = np.unique(first[first >= 0])
    mine = kinds[shard_positions(len(kinds), shard, n_shards)]
    bare = np.flatnonzero(first < 0)
    bare = bare[np.isin(bare, shard_positions(len(contacts), shard, n_shards))]
    picked = np.union1d(np.flatnonzero(np.isin(first, mine)), bare)
    # one block of n_sets rows per solved grasp, and a last block of no_grasp rows
    block = np.searchsorted(mine, first[picked])
    block[first[picked] < 0] = len(mine)
    out = optimise_grasps([grasps[i] for i in mine] + [None], synergies, params, strict=strict)
    n_sets = len(synergies)
    take = (block[:, None] * n_sets + np.arange(n_sets)).ravel()
    part = contacts.iloc[picked]
    table = pd.DataFrame({c: np.repeat(part[c].to_numpy(), n_sets) for c in ("object", "pose", "alpha_deg", "beta_deg")})
    for name, column in out.items():
        table[name] = column[take]
    return table


def optimise_shard(contacts: pd.DataFrame, shard: int, n_shards: int, synergies: SynergySets, params: GFOParams) -> pd.DataFrame:
    """The gfo table of one shard of an object's contacts table (`gfo_table`)."""
    return gfo_table(contacts, synergies, params, shard=shard, n_shards=n_shards)
