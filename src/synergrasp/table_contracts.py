"""Table contracts: the columns, types and units of every table passed between steps.

One :class:`Table` per table; writers, readers, workflow scripts and ``docs/design.md``
take their columns from here. :func:`write` checks a frame against its contract and
writes Parquet with the exact types; :func:`read` checks what it reads.
Units are in the column names where a column has one (``_mm``, ``_deg``, ``_N``) and in
``Column.unit`` always. :data:`CONTRACTS` holds every contract by table name.

The step ``tables`` (its rule, its script and ``results/tables/``) is another thing: it writes
the study's tables, named in :data:`STUDY_TABLES`, which are shown to the reader and have no
contract here. In their names and columns, "first7" (the table ``full_not_first7``, its
columns ``first7_status``, ``first7_force_closure``, ``first7_load_feasible``) means the
first ``synergy_sets.hierarchy_first`` synergies, {S1..S_hierarchy_first}: 7 in the default
study, the name kept so that the results' files and columns stay those of earlier runs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from synergrasp.file_output import replacing

__all__ = [
    "Column",
    "Table",
    "CONTRACTS",
    "STUDY_TABLES",
    "CONTACTS",
    "GFO",
    "MINIMA",
    "GRASP_REALISM",
    "GRASPABLE_OBJECTS",
    "PLACEMENT",
    "HAND_REACH",
    "PLAN",
    "ENROLLMENT",
    "PLANNERS",
    "PLANNERS_ACROSS",
    "PLAN_ON_DEMAND",
    "BLOCKERS",
    "QUALITY",
    "TARGET_CLAIMS",
    "write",
    "read",
    "older_version",
    "write_csv",
    "read_csv",
    "empty",
    "write_study_table",
]


@dataclass(frozen=True)
class Column:
    """One column: name, Arrow type name, unit ('' if none) and meaning."""

    name: str
    dtype: str  # "string", "int32", "float64", "bool", "list<float64>", "list<int32>", "list<string>"
    unit: str
    meaning: str


@dataclass(frozen=True)
class Table:
    """A table's name, one-line description, row key and columns in order; ``renamed``: the
    columns an older version wrote under another name, (old name, new name) each, so that
    :func:`read` refuses a file of that version instead of reading it under the old meaning."""

    name: str
    rows: str
    columns: tuple[Column, ...]
    renamed: tuple[tuple[str, str], ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.columns)

    def arrow_schema(self):
        import pyarrow as pa

        scalar = {"string": pa.string(), "int32": pa.int32(), "float64": pa.float64(), "bool": pa.bool_()}

        def arrow(t: str):
            return pa.list_(scalar[t[5:-1]]) if t.startswith("list<") else scalar[t]

        return pa.schema([(c.name, arrow(c.dtype)) for c in self.columns])


def _pose_columns() -> tuple[Column, ...]:
    return (
        Column("object", "string", "", "object name"),
        Column("pose", "int32", "", "pose index, alpha_index * n_beta + beta_index"),
        Column("alpha_deg", "float64", "deg", "rotation about the palm normal"),
        Column("beta_deg", "float64", "deg", "rotation about the long-finger axis"),
    )


CONTACTS = Table(
    "contacts",
    "one row per pose",
    _pose_columns()
    + (
        Column(
            "status",
            "string",
            "",
            "grasp (closure ran), intersects_open_hand, no_contact, caged (dynamic model: the hand moved the object, nothing touches it, its centre is inside the closed hand), lost (likewise, pushed out of the hand)",
        ),
        Column("q", "list<float64>", "rad", "final joint angles (19)"),
        Column(
            "finger_state",
            "list<string>",
            "",
            "per finger thumb..little: contact (box), self (blocked by the hand), limit (end of the closure path)",
        ),
        Column("n_contacts", "int32", "", "number of contacts m"),
        Column("contact_link", "list<int32>", "", "link index per contact (Hand.link_names)"),
        Column("contact_point", "list<float64>", "mm", "contact points on the box surface, palm frame, 3m row-major"),
        Column("contact_normal", "list<float64>", "", "object's inward unit normals, palm frame, 3m"),
        Column("jacobian", "list<float64>", "mm/rad", "translational Jacobian rows, 3m x 19 row-major"),
        Column("object_center", "list<float64>", "mm", "box centre, palm frame (3)"),
        Column("object_rotation", "list<float64>", "", "box orientation, row-major rotation matrix (9)"),
        Column("max_penetration_mm", "float64", "mm", "deepest contact penetration"),
        Column(
            "closure_model",
            "string",
            "",
            "closure model that made the row: kinematic, dynamic (a free box) or dynamic_held (closure.dynamic.object: held)",
        ),
        Column(
            "contact_normal_force_N",
            "list<float64>",
            "N",
            "normal force each contact carries at the settled state (m; NaN for the kinematic model)",
        ),
        Column(
            "object_translation_mm",
            "list<float64>",
            "mm",
            "settled box centre minus its initial centre, palm frame (3; zero for the kinematic model)",
        ),
        Column("object_rotation_deg", "float64", "deg", "angle of the box's rotation from its initial orientation"),
        Column("settled", "bool", "", "the closure ended at rest (false: at the dynamic model's time limit)"),
    ),
)

GFO = Table(
    "gfo",
    "one row per (pose, synergy set)",
    _pose_columns()
    + (
        Column("set_id", "string", "", "enrolled synergies, 1-based, sorted, joined by '-'"),
        Column("n_synergies", "int32", "", "number of enrolled synergies s"),
        Column(
            "status",
            "string",
            "",
            "the optimisation under the object's weight: feasible, infeasible, rank_deficient, no_grasp, numerical_failure",
        ),
        Column(
            "load_feasible",
            "bool",
            "",
            "the grasp-force optimisation under the object's weight is feasible (status feasible); not Definition 1",
        ),
        Column(
            "force_closure_def1",
            "bool",
            "",
            "force closure, the study's Definition 1: rank(G) = 6 and Bicchi's strict internal-force test (some E_s y strictly inside every friction cone); independent of the weight",
        ),
        Column("force_norm", "float64", "N", "optimal contact-force norm under the weight (NaN unless load_feasible)"),
        Column("e_s", "int32", "", "rank of the internal-force basis"),
        Column("rank_G", "int32", "", "rank of the grasp matrix"),
        Column("n_contacts", "int32", "", "number of contacts"),
        Column("iterations", "int32", "", "interior-point iterations of the GFO (0 unless solver ipm or clarabel_fallback)"),
        Column(
            "solver",
            "string",
            "",
            "back end that decided the problem: ipm (compiled interior-point kernel), implied (not solved: range(E_s) lies in that of each superset of its synergies, so infeasible where a superset is, and of a superset of equal rank the same problem, whose verdict and force_norm it takes; 0 iterations, e_s its own rank), clarabel_fallback (the kernel left it undecided), direct (e_s = 0: f = f_p judged without a solver), none (no_grasp, rank_deficient: nothing solved)",
        ),
    ),
    renamed=(("force_closure", "load_feasible"), ("strict_internal", "force_closure_def1")),
)

MINIMA = Table(
    "minima",
    "one row per local minimum of (object, synergy set)",
    (
        Column("object", "string", "", "object name"),
        Column("set_id", "string", "", "enrolled synergies"),
        Column("n_synergies", "int32", "", "number of enrolled synergies"),
        Column("pose", "int32", "", "pose index"),
        Column("alpha_deg", "float64", "deg", "rotation about the palm normal"),
        Column("beta_deg", "float64", "deg", "rotation about the long-finger axis"),
        Column("force_norm", "float64", "N", "optimal contact-force norm at the minimum"),
    ),
)


def _target_columns() -> tuple[Column, ...]:
    return tuple(Column(f"{axis}_mm", "float64", "mm", "target point, palm frame") for axis in "xyz")


def _realism_columns() -> tuple[Column, ...]:
    bins = tuple(Column(f"pct_m{m}", "float64", "%", f"grasps with exactly {m} contacts") for m in range(6))
    return (
        (
            Column("object", "string", "", "object name"),
            Column("closure_model", "string", "", "closure model that made the grasps (contacts table)"),
            Column("poses", "int32", "", "poses of the grid"),
            Column("simulated", "int32", "", "poses whose closure ran (status grasp or no_contact)"),
            Column("dropped", "int32", "", "poses whose closure did not run (any other status)"),
            Column("dropped_by", "string", "", "dropped poses per status"),
            Column("contacts_median", "float64", "", "median contacts per simulated grasp"),
        )
        + bins
        + (
            Column("pct_m6plus", "float64", "%", "grasps with 6 or more contacts"),
            Column("pct_thumb", "float64", "%", "grasps with a contact on a thumb link"),
            Column("pct_palm", "float64", "%", "grasps with a contact on the palm"),
            Column("pct_proximal_or_middle", "float64", "%", "grasps with a contact on a proximal or middle phalanx"),
            Column("pct_index", "float64", "%", "grasps with a contact on an index-finger link"),
            Column("pct_middle", "float64", "%", "grasps with a contact on a middle-finger link"),
            Column("pct_ring", "float64", "%", "grasps with a contact on a ring-finger link"),
            Column("pct_little", "float64", "%", "grasps with a contact on a little-finger link"),
            Column("grasp_type", "string", "", "the object's grasp type (objects.<name>.grasp_type; docs/opposition.md)"),
            Column("pct_palm_opposition", "float64", "%", "grasps in palm opposition (held against the palm: a power grasp)"),
            Column(
                "pct_pad_opposition",
                "float64",
                "%",
                "grasps in pad opposition (thumb pad against finger pads, no palm contact: a precision grip)",
            ),
            Column(
                "pct_side_opposition",
                "float64",
                "%",
                "grasps in side opposition (thumb pad against the side of the index: a lateral pinch)",
            ),
            Column("pct_no_opposition", "float64", "%", "grasps in which no two contact groups push against each other"),
            Column("pct_of_grasp_type", "float64", "%", "grasps whose opposition is of the object's grasp type"),
            Column(
                "pct_of_grasp_type_force_closure",
                "float64",
                "%",
                "grasps of the object's grasp type and in force closure with every synergy",
            ),
            Column(
                "pct_contacts_on_edges", "float64", "%", "contacts (of all simulated grasps) on an edge or a corner of the object"
            ),
            Column("pct_rank6", "float64", "%", "grasps whose grasp matrix G has rank 6"),
            Column(
                "pct_force_closure",
                "float64",
                "%",
                "grasps in force closure (rank(G) = 6 and the strict internal-force test) with every synergy",
            ),
            Column(
                "pct_load_feasible", "float64", "%", "grasps whose optimisation under the weight is feasible with every synergy"
            ),
            Column(
                "median_force_per_weight",
                "float64",
                "",
                "median optimal contact-force norm with every synergy over the force-closure grasps, in multiples of the weight m*g",
            ),
            Column(
                "loaded_contacts_median",
                "float64",
                "",
                "median contacts per grasp carrying normal force (NaN without per-contact forces)",
            ),
            Column(
                "median_torque_residual",
                "float64",
                "",
                "median relative torque residual of the end state, min over f in the friction cones of "
                "|tau_B - J_B^T f| / |tau_B|, tau = k_ss (q_r - q) on the joints moving a box contact "
                "(synergrasp.optimisation.equilibrium)",
            ),
            Column(
                "pct_s1_outside_cone",
                "float64",
                "%",
                "grasps with a contact that S1's closing motion J S1 pushes outside its friction cone "
                "(angle to the inward normal > atan mu)",
            ),
        )
    )


#: Percentages are of the simulated grasps. Written as CSV and Markdown (results/tables).
GRASP_REALISM = Table("grasp_realism", "one row per (object, closure model)", _realism_columns())

#: Whether each object can be grasped at all, and why not (synergrasp.analysis.graspability).
#: Written as CSV and Markdown (results/tables) by the grasp-realism step.
GRASPABLE_OBJECTS = Table(
    "graspable_objects",
    "one row per object",
    (
        Column("object", "string", "", "object name"),
        Column("poses", "int32", "", "poses of the grid"),
        Column("simulated", "int32", "", "poses whose closure ran (status grasp or no_contact)"),
        Column("grasps", "int32", "", "closures that end touching the box (status grasp)"),
        Column("settled", "int32", "", "grasps that came to rest (all of them for the kinematic closure)"),
        Column("force_closure_full_set", "int32", "", "poses in force closure with every synergy enrolled"),
        Column("graspable", "bool", "", "some pose reaches force closure with the full set"),
        Column(
            "reason",
            "string",
            "",
            "why no pose does: every pose dropped, nothing touched, no pose settled, "
            "no force closure with the full set (empty when graspable)",
        ),
        Column(
            "stated_type",
            "string",
            "",
            "the object's stated grasp type (with its shape class where the placement search read it)",
        ),
        Column(
            "effective_type",
            "string",
            "",
            "the grasp type its grasps are counted as (the search's effective type, version 3; the stated type without a search)",
        ),
        Column("type_reason", "string", "", "why the effective type differs from the stated one (the search's reason)"),
    ),
)

#: The placement search of one object (docs/placement_search.md), written as CSV
#: (results/objects/<object>/placement.csv).
PLACEMENT = Table(
    "placement",
    "one row per scored target of one object, best first",
    (
        Column("object", "string", "", "object name"),
        Column("rank", "int32", "", "rank by the tie rules, 1 = the chosen target"),
        Column("chosen", "bool", "", "rank 1"),
        Column(
            "distinct_rank", "int32", "", "rank among the targets at least search.distinct_mm from every better one (0: closer)"
        ),
        *_target_columns(),
        Column("round", "int32", "", "search round that scored it (0 = the coarse lattice)"),
        Column("n_poses", "int32", "", "scored poses"),
        Column("grasp_type", "string", "", "the object's grasp type (power, precision, any) the search scored"),
        Column(
            "typed_percent",
            "float64",
            "%",
            "the score T: share of the scored poses whose grasp is of the object's grasp type and in force closure with the full set",
        ),
        Column(
            "force_closure_percent",
            "float64",
            "%",
            "share of the scored poses in force closure with the full set, any opposition",
        ),
        Column("median_force_per_weight", "float64", "", "median optimal force over the poses counted by T / weight (inf: none)"),
        Column("median_contacts", "float64", "", "median contacts per scored pose"),
        Column("distance_to_chosen_mm", "float64", "mm", "distance to the chosen target"),
        Column(
            "stated_type",
            "string",
            "",
            "the object's stated grasp type with its shape class (power-circular, precision-prismatic, ..., any)",
        ),
        Column("effective_type", "string", "", "the grasp type the chosen target was searched for (version 3's fallback chain)"),
        Column(
            "type_reason",
            "string",
            "",
            "why the effective type differs from the stated one (each fallback with its numbers), or that the stated type was kept",
        ),
        Column(
            "region_mm",
            "string",
            "mm",
            "the region of targets at the end of the search, grown where the chosen target lay on its boundary",
        ),
    ),
)

#: What grasps the hand can make (docs/hand_reach.md, ``synergrasp.simulation.reach``): one
#: row per finger of the hand. Written as CSV and Markdown (results/tables/hand_reach).
HAND_REACH = Table(
    "hand_reach",
    "one row per finger",
    (
        Column("finger", "string", "", "thumb, index, middle, ring, little"),
        Column(
            "reach_s1_mm",
            "float64",
            "mm",
            "farthest point along the palm normal of the finger's link surfaces on the free S1 closure path, palm frame",
        ),
        Column("reach_any_mm", "float64", "mm", "the same over a lattice of every posture within the finger's joint limits"),
        Column("reach_s1_over_palm_mm", "float64", "mm", "reach_s1_mm less the palm face's position along the normal"),
        Column("reach_any_over_palm_mm", "float64", "mm", "reach_any_mm less the palm face's position along the normal"),
        Column(
            "press_mm",
            "float64",
            "mm",
            "d_max of the finger: the thickest slab lying on the palm that one of its links presses toward the palm when the hand closes along S1 with soft adaptation (0: none)",
        ),
        Column(
            "aperture_mm",
            "float64",
            "mm",
            "largest gap between the thumb's pad and this finger's pad on the free S1 path (NaN for the thumb)",
        ),
    ),
)

#: Quality indices of every pose of one object (docs/quality.md), Parquet
#: (results/objects/<object>/quality.parquet).
QUALITY = Table(
    "quality",
    "one row per pose",
    _pose_columns()
    + (
        Column("n_contacts", "int32", "", "contacts of the grasp"),
        Column("rank_G", "int32", "", "rank of the grasp matrix (0: no grasp)"),
        Column(
            "sigma_min",
            "float64",
            "",
            "smallest singular value of G with torques / torque_length_mm (0: rank < 6; NaN: no grasp)",
        ),
        Column("isotropy", "float64", "", "sigma_min / sigma_max of that matrix"),
        Column(
            "epsilon",
            "float64",
            "",
            "Ferrari-Canny epsilon (L1, 8-edge cones) of the fully actuated hand, in units of the total normal force",
        ),
        Column(
            "manipulability",
            "list<float64>",
            "mm",
            "semi-axes of the all-synergy manipulability ellipsoid, largest first (rotations x torque_length_mm)",
        ),
        Column("force_closure", "bool", "", "force closure (Definition 1) with the full synergy set"),
        Column(
            "force_per_weight",
            "float64",
            "",
            "optimal contact-force norm with the full set over the weight (NaN: not load-feasible)",
        ),
        Column("torque_length_mm", "float64", "mm", "the length torques are divided by: the object's bounding radius"),
        Column("opposition", "string", "", "the grasp's opposition: palm, pad, side or none (docs/opposition.md)"),
    ),
)

#: The study's claims at every scored target of one object's placement search
#: (docs/placement_search.md), Parquet (results/objects/<object>/target_claims.parquet).
TARGET_CLAIMS = Table(
    "target_claims",
    "one row per (scored target, claim), targets best first",
    (
        Column("object", "string", "", "object name"),
        Column("rank", "int32", "", "the target's rank in the placement search (1 = the chosen target)"),
        *_target_columns(),
        Column("force_closure_percent", "float64", "%", "the search's score F at the target"),
        Column("n_poses", "int32", "", "poses of the lattice the claims rest on (first alpha-period)"),
        Column("claim", "int32", "", "claim number (docs/analyses.md)"),
        Column("view", "string", "", "the claim's headline view"),
        Column("verdict", "string", "", "holds | does not hold | undefined, by the study's rules"),
        Column("difference", "float64", "", "the compared difference (unit as in the claims table)"),
        Column("low", "float64", "", "its interval's lower end"),
        Column("high", "float64", "", "its interval's upper end"),
        Column("n_distinct_poses", "int32", "", "distinct poses behind the comparison"),
        Column("reason", "string", "", "why the verdict"),
    ),
)

#: What blocks each synergy set where the full set succeeds (docs/blockers.md), Parquet
#: (results/objects/<object>/blockers.parquet). Margins and forces are those of the internal
#: force with the largest least cone margin, scaled to a total normal force of 1 N.
BLOCKERS = Table(
    "blockers",
    "one row per (pose, synergy set) failing Definition 1 where the full set succeeds",
    _pose_columns()
    + (
        Column("set_id", "string", "", "enrolled synergies ({S1..Sk} and {Sk}, k = 1..synergy_sets.hierarchy_first)"),
        Column("n_synergies", "int32", "", "number of enrolled synergies s"),
        Column("e_s", "int32", "", "rank of the set's internal-force basis E_s"),
        Column("rank_G", "int32", "", "rank of the grasp matrix"),
        Column("n_contacts", "int32", "", "contacts of the grasp"),
        Column(
            "reason",
            "string",
            "",
            "contacts (the blockers are named), no_internal_force (e_s = 0), rank_deficient, "
            "no_squeeze (every reachable internal force has zero total normal force), numerical_failure",
        ),
        Column(
            "margin",
            "float64",
            "N/N",
            "t*: the largest least cone margin mu f_n - |f_t| over the set's internal forces, "
            "per N of total normal force (<= 0: blocked; NaN unless reason contacts)",
        ),
        Column("n_blockers", "int32", "", "contacts whose margin is within 1e-6 of t* (the blockers)"),
        Column("blocker_contact", "list<int32>", "", "index of each blocker among the grasp's contacts"),
        Column("blocker_link", "list<int32>", "", "hand link of each blocker (Hand.link_names)"),
        Column("blocker_link_name", "list<string>", "", "its link's name"),
        Column(
            "blocker_link_kind",
            "list<string>",
            "",
            "its link's kind (opposition.LINK_KINDS: palm, palm_side, finger_middle, finger_pad, thumb_pad, thumb_base)",
        ),
        Column("blocker_face", "list<string>", "", "the box face it pushes on (opposition.FACE_CLASSES)"),
        Column("blocker_feature", "list<string>", "", "where it sits: face, edge or corner (opposition.SURFACE_FEATURES)"),
        Column("blocker_margin", "list<float64>", "N/N", "its cone margin at the optimum, per N of total normal force"),
        Column(
            "blocker_normal_force",
            "list<float64>",
            "N/N",
            "its normal force n.f at the optimum, per N of total normal force (<= 0: pulls)",
        ),
        Column(
            "blocker_angle_outside_deg",
            "list<float64>",
            "deg",
            "angle of its force from the inward normal minus atan(mu) (> 0: outside the circular cone; NaN: no force)",
        ),
        Column("n_outside", "int32", "", "contacts with margin <= 0 at the optimum"),
        Column("outside_link_kind", "list<string>", "", "link kind of each of them"),
    ),
)

#: The incremental planner on one object (docs/planner.md), CSV (results/objects/<object>/plan.csv).
PLAN = Table(
    "plan",
    "one row per neighbourhood radius",
    (
        Column("object", "string", "", "object name"),
        Column(
            "radius_deg", "float64", "deg", "neighbourhood half-width around the previous level's minima (alpha wrapped, beta)"
        ),
        Column("n_levels", "int32", "", "n: the full set is {S1..Sn}"),
        Column("n_solves", "int32", "", "(pose, set) problems the planner solved over every level"),
        Column("n_exhaustive_solves", "int32", "", "(pose, set) problems of the exhaustive search: poses x n"),
        Column("solve_share_percent", "float64", "%", "100 n_solves / n_exhaustive_solves"),
        Column("levels_from_minima", "int32", "", "levels whose seeds were local minima (the others: the best success, or none)"),
        Column("best_pose", "int32", "", "the planner's pose with the full set (-1: none succeeds)"),
        Column("best_alpha_deg", "float64", "deg", "its alpha"),
        Column("best_beta_deg", "float64", "deg", "its beta"),
        Column("best_force_N", "float64", "N", "its optimal force with the full set"),
        Column("exhaustive_min_force_N", "float64", "N", "least optimal force of the full set over every pose"),
        Column("exhaustive_best_pose", "int32", "", "the first pose with that force"),
        Column("is_global_min", "bool", "", "the planner's force equals the exhaustive minimum (within 1e-5 relative)"),
        Column("rank", "int32", "", "1 + poses whose full-set force is lower (twins share a rank; 0: none found)"),
        Column("n_ranked", "int32", "", "poses in force closure with the full set"),
        Column("regret", "float64", "", "best_force_N / exhaustive_min_force_N"),
        Column("regret_percent", "float64", "%", "100 (regret - 1)"),
        Column(
            "study_rows_differing",
            "int32",
            "",
            "rows solved anew at the poses that steered the plans (every level's seeds, the best pose) whose verdict or force (1e-5 relative) differs from the gfo table's",
        ),
    ),
)

#: Greedy enrollment order against the PCA order, one object (results/objects/<object>/enrollment.csv).
ENROLLMENT = Table(
    "enrollment",
    "one row per k",
    (
        Column("object", "string", "", "object name"),
        Column("k", "int32", "", "synergies enrolled"),
        Column("greedy_added", "int32", "", "the k-th synergy of the greedy order (1-based)"),
        Column("greedy_set", "string", "", "the greedy set's id"),
        Column("greedy_n_success", "int32", "", "grid poses where the greedy set succeeds"),
        Column("greedy_success_rate", "float64", "%", "of the full set's successes"),
        Column("pca_n_success", "int32", "", "grid poses where {S1..Sk} succeeds"),
        Column("pca_success_rate", "float64", "%", "of the full set's successes"),
        Column("full_n_success", "int32", "", "grid poses where the full set succeeds"),
    ),
)

#: A plan on demand (``synergrasp plan --on-demand --csv``): the hand closed only where the planner asks.
PLAN_ON_DEMAND = Table(
    "plan_on_demand",
    "one row per plan",
    (
        Column("object", "string", "", "object name"),
        Column("planner", "string", "", "the candidate planner (docs/planner.md)"),
        Column("seed", "int32", "", "numpy.random.default_rng seed of a randomised planner"),
        Column("pose", "int32", "", "its pose (-1: none succeeds)"),
        Column("alpha_deg", "float64", "deg", "its alpha"),
        Column("beta_deg", "float64", "deg", "its beta"),
        Column("force_N", "float64", "N", "its optimal force with the full set"),
        Column("closures", "int32", "", "closures run: the poses the planner asked"),
        Column("n_poses", "int32", "", "the grid's poses (the exhaustive search's closures)"),
        Column("problems", "int32", "", "(grasp, set) problems solved"),
        Column("wall_s", "float64", "s", "wall time of the plan: closures and solves"),
        Column("exhaustive_min_force_N", "float64", "N", "the study's least full-set force over every pose (NaN: no study)"),
        Column("regret_percent", "float64", "%", "100 (force_N / exhaustive_min_force_N - 1) (NaN: no study)"),
    ),
)

#: Planners compared at equal cost on one scenario's objects (results/tables/planners.csv).
PLANNERS = Table(
    "planners",
    "one row per object and candidate planner",
    (
        Column("object", "string", "", "object name"),
        Column("planner", "string", "", "the candidate planner (docs/planner.md)"),
        Column("family", "string", "", "incremental (solves reduced sets first) or full_set (solves only the full set)"),
        Column("randomised", "bool", "", "whether it draws poses at random (200 fixed seeds)"),
        Column("runs", "int32", "", "runs: one per seed, 1 for a deterministic planner"),
        Column("closures", "float64", "", "distinct poses asked anything (a closure each for a new object), mean over runs"),
        Column("closure_share_percent", "float64", "%", "100 closures / the grid's poses"),
        Column(
            "solve_cost",
            "float64",
            "full-set solves",
            "(grasp, set) problems handed to the solver, each weighted by its set size's measured solve time over the full set's, mean over runs",
        ),
        Column("problems", "float64", "", "(grasp, set) problems handed to the solver, unweighted, mean over runs"),
        Column(
            "regret_percent_mean",
            "float64",
            "%",
            "100 (its pose's full-set force / the exhaustive minimum - 1), mean over runs (NaN: no force-closure pose)",
        ),
        Column("regret_percent_max", "float64", "%", "the same, largest over runs"),
        Column("global_min_probability", "float64", "", "share of runs ending at the exhaustive minimum (within 1e-5 relative)"),
        Column("within_aim_probability", "float64", "", "share of runs with a regret of at most 5 %"),
        Column("meets_aim", "bool", "", "within_aim_probability >= 0.95"),
    ),
)

#: The planners across the objects, and the one the pre-registered rule recommends
#: (results/tables/planners_across.csv).
PLANNERS_ACROSS = Table(
    "planners_across",
    "one row per candidate planner",
    (
        Column("planner", "string", "", "the candidate planner (docs/planner.md)"),
        Column("family", "string", "", "incremental (solves reduced sets first) or full_set (solves only the full set)"),
        Column("randomised", "bool", "", "whether it draws poses at random (200 fixed seeds)"),
        Column("objects", "int32", "", "objects with a force-closure pose of the full set"),
        Column("objects_meeting_aim", "int32", "", "objects where it meets the aim (regret <= 5 % with probability >= 0.95)"),
        Column("meeting_aim_percent", "float64", "%", "100 objects_meeting_aim / objects"),
        Column("closures", "float64", "", "mean over objects"),
        Column("closure_share_percent", "float64", "%", "mean over objects"),
        Column("solve_cost", "float64", "full-set solves", "mean over objects"),
        Column("regret_percent_mean", "float64", "%", "mean over objects"),
        Column("regret_percent_max", "float64", "%", "largest over objects and runs"),
        Column("within_aim_probability", "float64", "", "least over objects"),
        Column(
            "recommended",
            "bool",
            "",
            "the planner the rule selects: fewest closures among those meeting the aim on >= 95 % of the objects (docs/planner.md)",
        ),
    ),
)

#: The study's tables, in this order (the ``tables`` step's outputs ``tables/<name>.{csv,md}``, made by
#: ``analysis.study_tables.study_tables``): shown to the reader, no contract between steps.
STUDY_TABLES: tuple[str, ...] = (
    "success_rates",
    "table2_success_rates",
    "hierarchy",
    "minimum_preservation",
    "full_not_first7",
    "verdict_disagreements",
    "preservation_vs_chance",
    "invariant_checks",
    "claims",
)
#: Every contract of a table passed between steps, by table name.
CONTRACTS: dict[str, Table] = {
    t.name: t
    for t in (
        CONTACTS,
        GFO,
        MINIMA,
        GRASP_REALISM,
        GRASPABLE_OBJECTS,
        PLACEMENT,
        HAND_REACH,
        QUALITY,
        TARGET_CLAIMS,
        BLOCKERS,
        PLAN,
        ENROLLMENT,
        PLANNERS,
        PLANNERS_ACROSS,
        PLAN_ON_DEMAND,
    )
}


def _check(table: Table, frame: pd.DataFrame, where: str) -> None:
    missing = [c for c in table.names if c not in frame.columns]
    if missing:
        raise ValueError(f"{table.name} table ({where}): missing column(s) {missing}; required: {list(table.names)}")


def empty(table: Table) -> pd.DataFrame:
    """A frame with the table's columns and no rows, with the contract's types."""
    return table.arrow_schema().empty_table().to_pandas()


def write(table: Table, frame: pd.DataFrame, path: str | Path) -> None:
    """Write ``frame`` as Parquet with exactly the contract's columns, order and types."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    _check(table, frame, str(path))
    arrow = pa.Table.from_pandas(frame[list(table.names)], schema=table.arrow_schema(), preserve_index=False)
    with replacing(path) as partial:
        pq.write_table(arrow, str(partial))


def read(table: Table, path: str | Path) -> pd.DataFrame:
    """Read a Parquet table and check it holds the contract's columns; ValueError naming the
    table and the file if it cannot be read, was written by an older version (a column of
    ``table.renamed`` under its old name: rerun) or lacks a column."""
    try:
        frame = pd.read_parquet(path)
    except (OSError, ValueError) as err:  # pyarrow's read errors are either
        raise ValueError(f"{table.name} table '{path}': cannot be read as Parquet ({err})") from None
    problem = _older(table, path, frame.columns)
    if problem:
        raise ValueError(problem)
    _check(table, frame, str(path))
    return frame


def _older(table: Table, path: str | Path, columns: Any) -> str:
    """The line saying that a file of ``table`` with ``columns`` was written by an older
    version (a column of ``table.renamed`` under its old name); '' if it was not."""
    old = [(was, now) for was, now in table.renamed if was in columns and now not in columns]
    if not old:
        return ""
    names = ", ".join(f"'{was}' (now '{now}')" for was, now in old)
    return (
        f"{table.name} table '{path}': written by an older version of the study (column {names}); "
        "delete it (or its results folder) and rerun the study"
    )


def older_version(table: Table, path: str | Path) -> str:
    """:func:`read`'s line on a file of ``table`` written by an older version, from the
    Parquet file's schema alone (no row is read); '' if it was not, or cannot be read (the
    step reading it says so)."""
    import pyarrow.parquet as pq

    try:
        columns = pq.read_schema(str(path)).names
    except (OSError, ValueError):
        return ""
    return _older(table, path, columns)


def write_csv(table: Table, frame: pd.DataFrame, path: str | Path) -> None:
    """Write ``frame`` as CSV (full precision) with exactly the contract's columns and order."""
    _check(table, frame, str(path))
    with replacing(path) as partial:
        frame[list(table.names)].to_csv(partial, index=False)


def read_csv(table: Table, path: str | Path) -> pd.DataFrame:
    """Read a CSV table and check it holds the contract's columns."""
    frame = pd.read_csv(path)
    _check(table, frame, str(path))
    return frame


def write_study_table(
    table: pd.DataFrame, csv_path: str | Path, md_path: str | Path, title: str | None = None, floatfmt: str = ".4g"
) -> None:
    """Write one of the study's result tables as CSV (full precision) and as Markdown (for
    reading, numbers to ``floatfmt``, under the heading ``title``)."""
    with replacing(csv_path) as partial:
        table.to_csv(partial, index=False)
    text = table.to_markdown(index=False, floatfmt=floatfmt) if len(table) else "(no rows)"
    with replacing(md_path) as partial:
        partial.write_text((f"# {title}\n\n" if title else "") + text + "\n", encoding="utf-8")
