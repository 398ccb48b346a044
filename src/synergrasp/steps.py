"""The steps of the workflow, each declared once (docs/design.md, "Adding a step").

:data:`STEPS` is data only: for every step, its rules and the measured cost and threads of
one job of each, the files it writes (and which of them the report shows), the configuration
keys it reads (and those it reads only when
another key has a given value), the steps whose outputs it reads, the files each rule reads
(``inputs``), what its script is handed, and the class whose ``from_config`` builds its
typed parameters. The step hash, ``synergrasp.wiring`` (every rule's inputs, outputs, log,
benchmark, threads, requests and params, the targets, where a shared output lives;
``workflow/rules/steps.smk`` makes every rule from it) and the tests all read it. A step's last
rule, the one that writes its ``outputs``, is named as the step; an earlier rule of it is
named ``<step>_<what>``; every rule's log and benchmark live in a folder (one file for a
step run once) named as the rule.

A rule is handed only the part of its scenario's configuration that its step reads
(:func:`step_config`); so a job reruns only when a key it reads changes, and two scenarios
share a step's outputs when their steps read the same values and the same upstream outputs
(:func:`step_hash`). A step that reads only some synergies of the synergy table is handed
their values (``synergrasp.hand.synergies.synergy_values``), not the table, so that what its hash says is what
it reads.

Layer: above the stages (it reads the hand and synergy files); imported only by the
workflow and the tests.
"""

from __future__ import annotations

import copy
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from synergrasp.config import DEFAULT_SCENARIO
from synergrasp.hand.synergies import synergy_values
from synergrasp.resolved import effective_placement
from synergrasp.table_contracts import STUDY_TABLES

__all__ = [
    "Cost",
    "Step",
    "STEPS",
    "UNITS",
    "WORKFLOW_KEYS",
    "CLOSURE_COST_FACTOR",
    "SOLVER_COMPILE",
    "step_keys",
    "step_config",
    "step_hash",
    "upstream_when",
    "rule_costs",
    "rule_step",
    "rule_inputs",
    "rule_handed",
    "reads_key",
    "HAND_FILES",
    "HANDED",
    "INPUT_SOURCES",
    "step_for_object",
    "step_made",
    "RESULTS",
    "scenario_root",
    "made_by",
    "object_file",
]

#: Where the workflow writes the default scenario's outputs (a scenario's own: ``scenario_root``).
RESULTS = "results"

#: Units of work a job's cost is counted in (``wiring.job_size`` counts them for a scenario).
UNITS = ("none", "pose", "closure_pose", "shard_pose_set", "pose_set", "object_pose", "object_pose_set")
#: Closure cost per pose relative to the kinematic closure measured in STEPS, per closure
#: model (docs/cluster.md); a model not listed is charged ``None``'s factor until measured.
CLOSURE_COST_FACTOR = {"kinematic": 1.0, "dynamic": 9.0, None: 20.0}
#: A cold compiled-solver cache (a node whose CPU model has no cached build) compiles the
#: solver once in a job of a rule with ``Cost.compiles``: about 50 s and 150 MB (s, MB).
SOLVER_COMPILE = (60.0, 150)


@dataclass(frozen=True)
class Cost:
    """Measured cost of one job of a rule: fixed wall time (s) and memory (MB) of the job
    itself (imports, reading inputs), plus wall time and memory per unit of work (UNITS).
    ``local``: a job of seconds, run where Snakemake runs rather than submitted.
    ``threads``: the processes (cores) a job uses. ``compiles``: a job may compile the
    solver (a cold cache on its node, ``SOLVER_COMPILE``)."""

    unit: str
    fixed_s: float
    fixed_mb: float
    unit_s: float = 0.0
    unit_mb: float = 0.0
    local: bool = True
    threads: int = 1
    compiles: bool = False


@dataclass(frozen=True)
class Step:
    """One step of the workflow.

    rules:     its rules, each with the cost of one job; the last one writes ``outputs``.
    outputs:   the files it writes, by output name: under ``{root}/objects/{object}/`` for a
               step run per object, under ``{root}/`` for one run per scenario, under
               ``results/`` for one run once for the whole workflow (``scope``).
    scope:     ``object`` | ``scenario`` | ``workflow``.
    reads:     configuration keys it reads ("objects.{object}" is the step's object,
               "objects.*" every object).
    reads_when: keys it reads only when another key has a value: ((key, value, keys), ...).
    not_reads: keys inside a block it reads that it does not read itself.
    upstream:  steps whose outputs it reads (its hash holds theirs): for a step run per
               object, that object's; for one run per scenario, every object's.
    upstream_when: steps it reads only when a key of the object's effective placement
               (the global one with the object's override) has a value: ((key, value, step), ...).
    synergy_columns: the synergies (1-based) it reads besides the mean posture; it is handed
               their values instead of the synergy table.
    params:    "module:Class" whose ``from_config`` builds its typed parameters.
    optional:  made only by its own target (``snakemake -j2 placement_claims``, ``sensitivity``),
               not by the study's (``figures``, ``scenario_<name>``).
    placement_when: made for an object only where its effective placement has these values
               ((key, value), ...): the search only for a searched placement.
    made_when: made only where the configuration has these values ((key, value), ...);
               elsewhere its output is its first upstream step's own (nothing to select).
    report:    the outputs the report shows: output name -> (caption, category); the caption
               is ``workflow/report/<caption>.rst``; a step per object is filed by object.
    folders:   the outputs that are folders (of pages), in the report only when it is an archive.
    rule_outputs: the files of a rule before the last (kept only until the last has run),
               under the same folder as ``outputs``: rule -> path (with its own wildcards).
    inputs:    the files the step's last rule reads, by the name its script reads them under:
               input name -> source (:data:`INPUT_SOURCES`): ``"<step>"`` (that step's one
               output), ``"<step>.<output>"`` (its output of that name), ``"<rule>"`` (an earlier
               rule of this step: every shard's file), or a file of the study's own
               (``SHIPPED_DATA``, ``USER_FILES``, ``MANIFEST``, ``MESH``, ``RULE_FILES``,
               ``SNAKEFILE``). Which object's or scenario's file a source is follows from the
               two steps' scopes (``wiring.Wiring.inputs``); every rule is handed the digest
               of the code it runs as its ``code`` param (``wiring.Wiring.code_digest``).
    rule_inputs: the same for a rule before the last: rule -> its inputs.
    handed:    what a rule's script is handed as ``params``, where it differs from the default
               (``("cfg",)``, the part of the configuration its step reads, for a step that
               reads any key; nothing otherwise): rule -> names of :data:`HANDED`.
    """

    rules: Mapping[str, Cost]
    outputs: Mapping[str, str]
    scope: str = "scenario"
    reads: tuple[str, ...] = ()
    reads_when: tuple[tuple[str, Any, tuple[str, ...]], ...] = ()
    not_reads: tuple[str, ...] = ()
    upstream: tuple[str, ...] = ()
    upstream_when: tuple[tuple[str, Any, str], ...] = ()
    synergy_columns: tuple[int, ...] = ()
    params: str | None = None
    optional: bool = False
    placement_when: tuple[tuple[str, Any], ...] = ()
    made_when: tuple[tuple[str, Any], ...] = ()
    report: Mapping[str, tuple[str, str]] = field(default_factory=dict)
    folders: tuple[str, ...] = ()
    rule_outputs: Mapping[str, str] = field(default_factory=dict)
    inputs: Mapping[str, str] = field(default_factory=dict)
    rule_inputs: Mapping[str, Mapping[str, str]] = field(default_factory=dict)
    handed: Mapping[str, tuple[str, ...]] = field(default_factory=dict)


#: A rule's inputs that are files of the study's own, not a step's outputs: the shipped hand
#: and synergy files; the scenario's own hand, synergy and mesh files with the meshes' convex
#: parts; the sha256 manifest of its random objects; the mesh file whose parts a job makes;
#: the workflow's rule files and its Snakefile (``wiring.Wiring.inputs`` resolves them).
SHIPPED_DATA, USER_FILES, MANIFEST, MESH, RULE_FILES, SNAKEFILE = (
    "@shipped_data",
    "@user_files",
    "@manifest",
    "@mesh",
    "@rule_files",
    "@snakefile",
)
INPUT_SOURCES = (SHIPPED_DATA, USER_FILES, MANIFEST, MESH, RULE_FILES, SNAKEFILE)
#: The hand a step's code loads (``hand.kinematics.load_hand``, ``hand.synergies.load_synergies``),
#: with the meshes of its objects: the shipped files and the scenario's own.
HAND_FILES = {"data": SHIPPED_DATA, "user": USER_FILES}
#: What a rule's script may be handed as ``params`` (``wiring.Wiring.params``): the part of the
#: scenario's configuration its step reads; the shipped configuration file; the scenarios'
#: names; how each scenario places the boxes.
HANDED = ("cfg", "configfile", "scenarios", "placements")


def _files(names: tuple[str, ...], folder: str, exts: tuple[str, ...], named: bool = True) -> dict[str, str]:
    """Output name ``<name>_<ext>`` (``<ext>`` where not ``named``) -> ``<folder>/<name>.<ext>``
    for every name and extension."""
    return {f"{n}_{e}" if named else e: f"{folder}/{n}.{e}".lstrip("/") for n in names for e in exts}


#: The keys of the choice of which contacts count (the ``contacts`` step).
_CONTACT_SELECTION = ("closure.dynamic.unloaded_contacts", "closure.dynamic.load_threshold_N")
#: The keys of the force bound of ``analyses.success: force_closure_bounded``.
_FORCE_BOUND = ("analyses.marginal_weight_multiple", "objects.{object}.mass_kg", "mechanics.g_m_per_s2")
#: The keys of a placement mode's target (the search reads none of them).
_PLACEMENT_TARGETS = ("mode", "search_rank", "approach_point_mm", "center_mm")
_PNG_PDF = ("png", "pdf")
#: The keys the placement search reads (and the map of its results).
STEPS_SEARCH_READS = (
    "hand",
    "synergies",
    "grid",
    "placement",
    "closure",
    "mechanics",
    "synergy_sets.incremental_max",
    "objects.{object}.shape",
    "objects.{object}.mass_kg",
    "objects.{object}.placement",
    "objects.{object}.grasp_type",
    "grasp_type",
    "opposition",
    "hand_reach",
)
STEPS_SEARCH_NOT_READS = (
    "closure.model",
    "closure.dynamic",
    *(f"{where}.{key}" for where in ("placement", "objects.{object}.placement") for key in _PLACEMENT_TARGETS),
)

#: Every step of the workflow, in the order they run. Costs: from results/benchmarks/*.tsv
#: (columns s, cpu_time and max_rss) of the default study and of tests/config/small.yaml on a
#: 2-core x86_64 machine running two jobs at a time; the slope is between the two sizes
#: (docs/cluster.md).
STEPS: dict[str, Step] = {
    # a mesh's convex parts (docs/shapes.md): its hull, or V-HACD's decomposition of a concave
    # mesh, one file per mesh named by its content and the decomposition's parameters
    # (``convex_parts.parts_key``), shared by every object and scenario with that file; made
    # for the objects' meshes that a job reads (Wiring.user_files), never while the DAG is built
    "mesh_parts": Step(
        # a job: 3.4 s of CPU and 122-126 MB on two of the random meshes (their benchmark files)
        rules={"mesh_parts": Cost("none", 10.0, 160, local=False)},
        outputs={"obj": "meshes/{mesh}.obj"},
        scope="workflow",
        optional=True,
        inputs={"mesh": MESH},
    ),
    # what grasps the hand can make (docs/hand_reach.md), once per hand: per finger the reach
    # along S1 and in any posture, d_max (~60 kinematic closures on slabs lying on the palm)
    # and the aperture; the search's gate and the hand_reach table read it
    "reach": Step(
        rules={"reach": Cost("none", 4.0, 300)},
        outputs={"reach": "hand/reach.parquet"},
        reads=("hand", "synergies", "closure", "opposition.angle_deg", "hand_reach"),
        not_reads=("closure.model", "closure.dynamic"),
        params="synergrasp.simulation.reach:ReachStepParams",
        inputs={**HAND_FILES},
    ),
    # the placement search (docs/placement_search.md): the kinematic closure and the
    # optimisation with the full set {S1..S_incremental_max} only; one job per object with
    # 2 processes: ~30 s of CPU (186-195 targets x 27 poses) plus a cold solver cache's compile
    "search": Step(
        rules={"search": Cost("none", 80.0, 700, local=False, threads=2, compiles=True)},
        outputs={"placement": "placement.csv"},
        scope="object",
        reads=STEPS_SEARCH_READS,
        not_reads=STEPS_SEARCH_NOT_READS,
        upstream=("reach",),
        params="synergrasp.optimisation.placement_search:SearchStepParams",
        placement_when=(("mode", "searched"),),
        inputs={**HAND_FILES, "reach": "reach"},
    ),
    "simulate": Step(
        rules={"simulate": Cost("closure_pose", 1.5, 178, 4.5e-3, 7.6e-3, local=False)},
        outputs={"contacts": "contacts.parquet"},
        scope="object",
        reads=("hand", "synergies", "grid", "placement", "closure", "objects.{object}.shape", "objects.{object}.placement"),
        # the dynamic closure: a free box of the object's mass, μ, k_ss and gravity of mechanics
        reads_when=(("closure.model", "dynamic", ("objects.{object}.mass_kg", "mechanics")),),
        # which contacts count is the `contacts` step's choice: `drop` and `keep` share one closure
        # nor the search's settings (a searched placement reads the search's output)
        not_reads=(*_CONTACT_SELECTION, "placement.search", "objects.{object}.placement.search"),
        upstream_when=(("placement.mode", "searched", "search"),),
        synergy_columns=(1,),
        params="synergrasp.simulation.closure:SimulateParams",
        inputs={**HAND_FILES, "search": "search"},
    ),
    "contacts": Step(
        rules={"contacts": Cost("pose", 1.0, 150, 5.0e-4, 7.6e-3)},
        outputs={"contacts": "load_carrying_contacts.parquet"},
        scope="object",
        reads=("closure.model",),
        # only the dynamic model records the load each contact carries
        reads_when=(("closure.model", "dynamic", _CONTACT_SELECTION),),
        upstream=("simulate",),
        params="synergrasp.simulation.contacts:ContactsParams",
        made_when=(("closure.model", "dynamic"), ("closure.dynamic.unloaded_contacts", "drop")),
        inputs={"contacts": "simulate"},
    ),
    "optimise": Step(
        rules={
            "optimise_shard": Cost("shard_pose_set", 2.2, 271, 6.1e-5, 1.1e-3, local=False, compiles=True),
            "optimise": Cost("pose_set", 0.6, 134, 2.0e-6, 6.0e-4),
        },
        outputs={"gfo": "gfo.parquet"},
        scope="object",
        reads=(
            "synergies",
            "mechanics",
            "synergy_sets",
            "solver.pose_shards",
            "objects.{object}.mass_kg",
            "hand",
        ),  # the hand's joints order the synergy table's rows
        upstream=("contacts",),
        params="synergrasp.optimisation.optimise:OptimiseParams",
        rule_outputs={"optimise_shard": "gfo_shards/{shard}.parquet"},
        rule_inputs={"optimise_shard": {"contacts": "contacts", **HAND_FILES}},
        inputs={"shards": "optimise_shard"},
        handed={"optimise": ()},  # merges the shards: reads no configuration
    ),
    "minima": Step(
        rules={"minima": Cost("pose_set", 0.6, 136, 1.35e-5, 6.0e-4)},
        outputs={"minima": "minima.parquet"},
        scope="object",
        reads=("analyses.minima_radius_deg", "analyses.success"),
        # force closure within a multiple of the weight: the minima and Fig. 4 read the bound
        reads_when=(("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
        upstream=("optimise",),
        params="synergrasp.analysis.minima:MinimaParams",
        inputs={"gfo": "optimise"},
    ),
    # quality indices of every pose and their maps (docs/quality.md)
    "quality": Step(
        rules={"quality": Cost("pose", 3.0, 300, 6.0e-3, 0.05)},
        outputs={"table": "quality.parquet", "png": "quality_maps.png", "pdf": "quality_maps.pdf"},
        scope="object",
        reads=(
            "hand",
            "synergies",
            "mechanics.mu",
            "mechanics.g_m_per_s2",
            "synergy_sets.incremental_max",
            "objects.{object}.shape",
            "objects.{object}.mass_kg",
            "opposition",
        ),
        upstream=("contacts", "optimise"),
        params="synergrasp.optimisation.quality:QualityParams",
        report={"png": ("quality_maps", "Quality")},
        inputs={"contacts": "contacts", "gfo": "optimise", **HAND_FILES},
    ),
    # what blocks each set of the hierarchy table where the full set succeeds (docs/blockers.md):
    # one small conic problem per distinct failing (grasp, set), ~1.5 ms of CPU per pose
    "blockers": Step(
        rules={"blockers": Cost("pose", 3.0, 300, 1.5e-3, 0.05)},
        outputs={"blockers": "blockers.parquet"},
        scope="object",
        reads=(
            "hand",
            "synergies",
            "mechanics",
            "synergy_sets",
            "opposition",
            "objects.{object}.shape",
            "objects.{object}.mass_kg",
        ),
        upstream=("contacts", "optimise"),
        params="synergrasp.analysis.blockers:BlockersParams",
        inputs={"contacts": "contacts", "gfo": "optimise", **HAND_FILES},
    ),
    "blockers_table": Step(
        rules={"blockers_table": Cost("none", 4.0, 300)},
        outputs={
            "csv": "tables/blockers.csv",
            "md": "tables/blockers.md",
            **_files(("blockers",), "figures", _PNG_PDF, named=False),
        },
        reads=("synergy_sets.hierarchy_first", "synergy_sets.incremental_max"),
        upstream=("blockers",),
        report={"csv": ("blockers_table", "Tables"), "png": ("blockers", "Figures")},
        inputs={"blockers": "blockers"},
    ),
    # the incremental planner against the exhaustive search (docs/planner.md): {S1} over the
    # grid, then {S1..Sk} near the previous level's minima, at 3 radii, and the greedy order:
    # 7.7-8.3 CPU s, 356-371 MB per box of 1800 poses (default study)
    "plan": Step(
        rules={"plan": Cost("pose", 3.0, 300, 3.0e-3, 0.04)},
        outputs={"plan": "plan.csv", "enrollment": "enrollment.csv", **_files(("plan",), "", _PNG_PDF, named=False)},
        scope="object",
        reads=(
            "synergies",
            "mechanics",
            "synergy_sets.incremental_max",
            "objects.{object}.mass_kg",
            "analyses.minima_radius_deg",
            "analyses.success",
            "analyses.planner_radii_deg",
            "hand",
        ),
        reads_when=(("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
        upstream=("contacts", "optimise"),
        params="synergrasp.analysis.plan_study:PlanParams",
        optional=True,
        inputs={"contacts": "contacts", "gfo": "optimise", **HAND_FILES},
    ),
    # planners compared at equal cost, replayed on every object's gfo table (docs/planner.md):
    # 28 candidates, the randomised ones over 200 seeds: 8.2 CPU s, 294 MB for the four boxes of
    # 1800 poses (default study). Before `tables`, whose claims table holds claim 8 from it.
    "planners": Step(
        rules={"planners": Cost("object_pose", 3.0, 300, 1.5e-3, 0.0)},
        outputs={
            "csv": "tables/planners.csv",
            "md": "tables/planners.md",
            "across_csv": "tables/planners_across.csv",
            "across_md": "tables/planners_across.md",
            **_files(("planners",), "figures", _PNG_PDF, named=False),
        },
        reads=("synergy_sets.incremental_max", "analyses.minima_radius_deg", "analyses.success"),
        reads_when=(
            (
                "analyses.success",
                "force_closure_bounded",
                ("analyses.marginal_weight_multiple", "objects.*.mass_kg", "mechanics.g_m_per_s2"),
            ),
        ),
        upstream=("contacts", "optimise"),
        params="synergrasp.analysis.plan_study:PlannersParams",
        report={"across_csv": ("planners_across", "Tables"), "png": ("planners", "Figures")},
        inputs={"contacts": "contacts", "gfo": "optimise"},
    ),
    "tables": Step(
        # one object at a time: 581 MB over the 97 random objects (1800 poses x 75 sets each),
        # 7,874 MB when every object's rows were held (docs/random_objects.md, "Cost")
        rules={"tables": Cost("object_pose_set", 2.3, 400, 3.2e-6, 1.4e-5)},
        outputs=_files(STUDY_TABLES, "tables", ("csv", "md")),
        reads=(
            "synergy_sets",
            "analyses.minima_radius_deg",
            "analyses.table2_k_max",
            "analyses.success",
            "analyses.marginal_weight_multiple",
            "analyses.success_rate_tolerance_percent",
            "analyses.null_model",
            "analyses.headline_view",
            "analyses.tie_band",
            "analyses.min_distinct_poses",
            "analyses.bootstrap",
            "objects",
            "placement",
            "grid",
            "hand",
            "mechanics.g_m_per_s2",
        ),
        upstream=("optimise", "minima", "planners"),
        params="synergrasp.analysis.summaries:TablesParams",
        report={f"{t}_csv": (t, "Tables") for t in STUDY_TABLES},
        inputs={"gfo": "optimise", "minima": "minima", "planners": "planners.csv", **HAND_FILES},
    ),
    "realism": Step(
        # with the equilibrium checks of every grasp: ~0.5 ms of CPU per grasp over 75 sets.
        # Memory: one object at a time, resident ~0.3 MB more an object (379 MB before the 9th
        # of 97, 407 before the 97th); the fixed part holds its figure's canvas, which stops
        # growing at 100 rows (figures/grasp_realism.py): peak 639 MB on 97 objects.
        rules={"realism": Cost("object_pose_set", 4.0, 650, 1.1e-5, 2.2e-6)},
        outputs={
            "csv": "tables/grasp_realism.csv",
            "md": "tables/grasp_realism.md",
            "links_csv": "tables/grasp_links.csv",
            "links_md": "tables/grasp_links.md",
            "png": "figures/grasp_realism.png",
            "pdf": "figures/grasp_realism.pdf",
            "graspable_csv": "tables/graspable_objects.csv",
            "graspable_md": "tables/graspable_objects.md",
        },
        reads=(
            "hand",
            "synergies",
            "synergy_sets.incremental_max",
            "objects.*.mass_kg",
            "mechanics.g_m_per_s2",
            "mechanics.k_ss_Nmm_per_rad",
            "mechanics.mu",
            "closure.model",
            "objects.*.shape",
            "objects.*.grasp_type",
            "grasp_type",
            "opposition",
            "random_objects",
        ),
        reads_when=(("closure.model", "dynamic", ("closure.dynamic.load_threshold_N",)),),
        upstream=("contacts", "optimise"),
        synergy_columns=(1,),
        params="synergrasp.analysis.realism:RealismParams",
        report={
            "csv": ("grasp_realism_table", "Tables"),
            "png": ("grasp_realism", "Figures"),
            "graspable_csv": ("graspable_objects", "Tables"),
        },
        inputs={"contacts": "contacts", "gfo": "optimise", "placements": "search", "manifest": MANIFEST, **HAND_FILES},
    ),
    "fig1": Step(
        rules={"fig1": Cost("none", 3.0, 565)},
        outputs=_files(("fig1_synergy_postures",), "figures", _PNG_PDF, named=False),
        reads=("hand", "synergies"),
        params="synergrasp.figures.fig1_fig2_postures_grasps:Fig1Params",
        report={"png": ("fig1", "Figures")},
        inputs={**HAND_FILES},
    ),
    # the hand's reach as a table and a side view with the study's objects (docs/hand_reach.md)
    "hand_reach": Step(
        rules={"hand_reach": Cost("none", 4.0, 300)},
        outputs={
            "csv": "tables/hand_reach.csv",
            "md": "tables/hand_reach.md",
            **_files(("hand_reach",), "figures", _PNG_PDF, named=False),
        },
        reads=("hand", "synergies", "opposition.angle_deg", "hand_reach", "objects.*.shape"),
        upstream=("reach",),
        params="synergrasp.simulation.reach:HandReachStepParams",
        report={"csv": ("hand_reach_table", "Tables"), "png": ("hand_reach", "Figures")},
        inputs={**HAND_FILES, "reach": "reach"},
    ),
    # Fig. 2 and the same grasps in 3-D with the full set's optimal forces: pages sharing one
    # plotly script (docs/inspector.md); one job, so that the pages' imports (the solver, a
    # dozen optimisations) are not paid by a job of their own
    "fig2": Step(
        rules={"fig2": Cost("none", 4.5, 510)},
        outputs={**_files(("fig2_example_grasps",), "figures", _PNG_PDF, named=False), "pages": "figures/grasps_3d"},
        reads=(
            "hand",
            "synergies",
            "mechanics",
            "synergy_sets.incremental_max",
            "objects.*.shape",
            "objects.*.mass_kg",
            "opposition",
        ),
        upstream=("contacts",),
        params="synergrasp.figures.grasp_3d:Grasps3dParams",
        report={"png": ("fig2", "Figures"), "pages": ("grasps_3d", "Figures")},
        folders=("pages",),
        inputs={"contacts": "contacts", **HAND_FILES},
    ),
    "fig4": Step(
        rules={"fig4": Cost("pose_set", 4.3, 257, 5.1e-6, 4.0e-4)},
        outputs={
            "maps_png": "fig4_force_maps.png",
            "maps_pdf": "fig4_force_maps.pdf",
            "exploded_png": "fig4_exploded.png",
            "exploded_pdf": "fig4_exploded.pdf",
        },
        scope="object",
        reads=("analyses.fig4", "analyses.success"),
        reads_when=(("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
        upstream=("optimise", "minima"),
        params="synergrasp.figures.fig4_fig5_forces_hierarchy:Fig4Params",
        report={"maps_png": ("fig4_force_maps", "Fig. 4"), "exploded_png": ("fig4_exploded", "Fig. 4")},
        inputs={"gfo": "optimise", "minima": "minima"},
    ),
    # the placement map: the search's score over its targets, grasps at the chosen target
    "placement_map": Step(
        rules={"placement_map": Cost("none", 6.0, 400)},
        outputs=_files(("placement_map",), "", _PNG_PDF, named=False),
        scope="object",
        reads=STEPS_SEARCH_READS,
        not_reads=STEPS_SEARCH_NOT_READS,
        upstream=("search", "contacts"),
        params="synergrasp.optimisation.placement_search:SearchStepParams",
        placement_when=(("mode", "searched"), ("search_rank", 1)),
        report={"png": ("placement_map", "Placement search")},
        inputs={"placement": "search", "contacts": "contacts", **HAND_FILES},
    ),
    # the study's claims at every scored target of the search (docs/placement_search.md): the
    # closure and every set's optimisation on a 117-pose lattice, ~1 s of CPU per target, 2 processes
    "target_claims": Step(
        rules={"target_claims": Cost("none", 400.0, 900, local=False, threads=2)},
        outputs={"claims": "target_claims.parquet"},
        scope="object",
        reads=(*STEPS_SEARCH_READS, "synergy_sets", "analyses", "objects.{object}"),
        reads_when=(("analyses.success", "force_closure_bounded", _FORCE_BOUND),),
        not_reads=(*STEPS_SEARCH_NOT_READS, "analyses.fig4"),
        upstream=("search",),
        params="synergrasp.analysis.target_claims:TargetClaimsParams",
        optional=True,
        placement_when=(("mode", "searched"),),
        inputs={"placement": "search", **HAND_FILES},
    ),
    # their summary: made by the target `placement_claims`
    "summarise_target_claims": Step(
        rules={"summarise_target_claims": Cost("none", 4.0, 300)},
        outputs={
            "csv": "tables/placement_claims.csv",
            "md": "tables/placement_claims.md",
            **_files(("placement_claims",), "figures", _PNG_PDF, named=False),
        },
        upstream=("target_claims",),
        optional=True,
        report={"csv": ("placement_claims", "Placement search"), "png": ("placement_claims", "Placement search")},
        inputs={"claims": "target_claims"},
    ),
    # the study across its objects, with the planner (docs/random_objects.md): made by
    # `snakemake -j2 across_objects`, not by `figures`
    "objects_summary": Step(
        rules={"objects_summary": Cost("none", 5.0, 300)},
        outputs={
            "csv": "tables/objects_summary.csv",
            "md": "tables/objects_summary.md",
            "intervals_csv": "tables/objects_intervals.csv",
            "intervals_md": "tables/objects_intervals.md",
            "drawn_csv": "tables/random_objects.csv",
            "drawn_md": "tables/random_objects.md",
            **_files(("objects_summary",), "figures", _PNG_PDF, named=False),
            **_files(("planner_tradeoff",), "figures", _PNG_PDF),
        },
        reads=("synergy_sets", "analyses.planner_radii_deg", "random_objects"),
        upstream=("tables", "realism", "plan"),
        params="synergrasp.analysis.objects_summary:ObjectsSummaryParams",
        optional=True,
        inputs={
            "success_rates": "tables.success_rates_csv",
            "preservation": "tables.minimum_preservation_csv",
            "graspable": "realism.graspable_csv",
            "plans": "plan.plan",
            "enrollment": "plan.enrollment",
            "manifest": MANIFEST,
        },
    ),
    "fig5": Step(
        rules={"fig5": Cost("none", 9.6, 268)},
        outputs={
            "success_png": "figures/fig5a_hierarchy_success.png",
            "success_pdf": "figures/fig5a_hierarchy_success.pdf",
            "pooled_png": "figures/fig5a_hierarchy_success_pooled.png",
            "pooled_pdf": "figures/fig5a_hierarchy_success_pooled.pdf",
            "force_png": "figures/fig5b_hierarchy_force.png",
            "force_pdf": "figures/fig5b_hierarchy_force.pdf",
        },
        reads=("synergy_sets.hierarchy_first", "analyses.success"),
        upstream=("tables",),
        params="synergrasp.figures.fig4_fig5_forces_hierarchy:Fig5Params",
        report={
            "success_png": ("fig5a", "Figures"),
            "pooled_png": ("fig5a_pooled", "Figures"),
            "force_png": ("fig5b", "Figures"),
        },
        inputs={"hierarchy": "tables.hierarchy_csv"},
    ),
    # the workflow's own rule graph: drawn with the shipped configuration, so it reads no key
    "fig3": Step(
        rules={"fig3": Cost("none", 5.3, 380)},
        outputs={**_files(("fig3_rulegraph",), "figures", _PNG_PDF, named=False), "dot": "figures/fig3_rulegraph.dot"},
        scope="workflow",
        report={"png": ("fig3", "Figures")},
        inputs={"rules": RULE_FILES, "snakefile": SNAKEFILE},
        # the rule graph does not depend on the configuration's values: drawn with the shipped
        # configuration file, so that neither a config value nor a config file's path reruns it
        handed={"fig3": ("configfile",)},
    ),
    # the sweep's summary across every scenario (docs/sensitivity.md): its rule is the target
    "sensitivity": Step(
        rules={"sensitivity": Cost("none", 5.0, 300)},
        outputs={
            "csv": "sensitivity/claims.csv",
            "md": "sensitivity/claims.md",
            "grid_png": "sensitivity/claims_grid.png",
            "grid_pdf": "sensitivity/claims_grid.pdf",
            "curves_png": "sensitivity/table2_curves.png",
            "curves_pdf": "sensitivity/table2_curves.pdf",
        },
        scope="workflow",
        upstream=("tables", "realism"),
        optional=True,
        report={
            "csv": ("sensitivity_claims", "Sensitivity"),
            "grid_png": ("sensitivity_grid", "Sensitivity"),
            "curves_png": ("sensitivity_table2", "Sensitivity"),
        },
        inputs={
            "claims": "tables.claims_csv",
            "table2": "tables.table2_success_rates_csv",
            "success_rates": "tables.success_rates_csv",
            "preservation": "tables.minimum_preservation_csv",
            "realism": "realism.csv",
        },
        handed={"sensitivity": ("scenarios", "placements")},
    ),
}
#: Keys read by the workflow itself, not by a step.
WORKFLOW_KEYS: tuple[str, ...] = ("scenarios",)

_MISSING = object()


def rule_costs() -> dict[str, Cost]:
    """Every rule of every step, with the cost of one of its jobs."""
    return {rule: cost for step in STEPS.values() for rule, cost in step.rules.items()}


def rule_step() -> dict[str, str]:
    """Every rule of every step -> its step."""
    return {rule: name for name, step in STEPS.items() for rule in step.rules}


def rule_inputs(rule: str) -> Mapping[str, str]:
    """The inputs of ``rule`` (input name -> source, :class:`Step`'s ``inputs``): its step's
    ``inputs`` for the step's last rule, its ``rule_inputs`` entry for an earlier one."""
    step = STEPS[rule_step()[rule]]
    return step.rule_inputs.get(rule, {}) if rule != list(step.rules)[-1] else step.inputs


def rule_handed(rule: str) -> tuple[str, ...]:
    """What ``rule``'s script is handed as ``params`` (names of :data:`HANDED`): its step's
    ``handed`` entry, else the part of the configuration its step reads where it reads any key."""
    step = STEPS[rule_step()[rule]]
    return step.handed.get(rule, ("cfg",) if step.reads else ())


def reads_key(step: str, path: str) -> bool:
    """Whether ``step`` reads the configuration key ``path`` under every configuration: a key
    of its ``reads`` is ``path`` or a block holding it, and none of its ``not_reads`` is."""

    def within(key: str) -> bool:
        return path == key or path.startswith(key + ".")

    return any(within(key) for key in STEPS[step].reads) and not any(within(key) for key in STEPS[step].not_reads)


def step_for_object(config: Mapping[str, Any], step: str, obj: str) -> bool:
    """Whether the per-object ``step`` runs for ``obj`` under ``config``: its ``placement_when``
    holds for the object's effective placement."""
    if not STEPS[step].placement_when:  # most steps: no placement to resolve (a copy per call)
        return True
    placement = effective_placement(config, obj)
    return all(placement.get(key) == value for key, value in STEPS[step].placement_when)


def step_made(config: Mapping[str, Any], step: str) -> bool:
    """Whether ``step`` makes its own output under ``config`` (its ``made_when`` holds), else
    its output is its first upstream step's."""
    return all(_get(config, key) == value for key, value in STEPS[step].made_when)


def made_by(config: Mapping[str, Any], step: str) -> str:
    """The step whose output stands for ``step``'s under ``config``: ``step`` itself where it
    makes its own output (:func:`step_made`), else, in turn, its first upstream step."""
    while not step_made(config, step):
        step = STEPS[step].upstream[0]
    return step


def scenario_root(name: str) -> str:
    """The folder of scenario ``name``'s outputs: :data:`RESULTS` for the default scenario,
    ``results/scenarios/<name>`` for another (config/README.md)."""
    return RESULTS if name == DEFAULT_SCENARIO else f"{RESULTS}/scenarios/{name}"


def object_file(config: Mapping[str, Any], step: str, obj: str, root: str | Path = RESULTS) -> Path:
    """The one output of the per-object ``step`` for ``obj`` in the outputs under ``root``, the
    file the workflow's rules read for it under ``config`` (a step not made there hands on its
    first upstream step's, :func:`made_by`): the one answer for the commands (``synergrasp
    plan``, ``synergrasp grasp``) and the workflow (``wiring.Wiring.step_file``)."""
    (rel,) = STEPS[made_by(config, step)].outputs.values()
    return Path(root) / "objects" / obj / rel


def _get(config: Mapping[str, Any], path: str) -> Any:
    node: Any = config
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return _MISSING
        node = node[part]
    return node


def _put(out: dict[str, Any], path: str, value: Any) -> None:
    *parents, last = path.split(".")
    for part in parents:
        out = out.setdefault(part, {})
    out[last] = copy.deepcopy(value)


def step_keys(config: Mapping[str, Any], step: str, obj: str | None = None) -> list[str]:
    """The key paths ``step`` reads in ``config`` (for object ``obj`` where it matters)."""
    if step not in STEPS:
        raise ValueError(f"unknown step {step!r}; allowed values: {sorted(STEPS)}")
    paths = list(STEPS[step].reads)
    for key, value, reads in STEPS[step].reads_when:
        if _get(config, key) == value:
            paths += reads
    out = []
    for path in paths:
        if path.startswith("objects.*"):
            out += [path.replace("*", name, 1) for name in config["objects"]]
        elif "{object}" in path:
            if obj is None:
                raise ValueError(f"step {step!r} reads {path}: an object is required")
            out.append(path.format(object=obj))
        else:
            out.append(path)
    return out


def step_config(config: Mapping[str, Any], step: str, obj: str | None = None) -> dict[str, Any]:
    """The part of ``config`` that ``step`` reads, in the configuration's own shape; for a
    step with ``synergy_columns``, ``synergies`` holds their values (``synergrasp.hand.synergies.synergy_values``)."""
    out: dict[str, Any] = {}
    for path in step_keys(config, step, obj):
        value = _get(config, path)
        if value is not _MISSING:
            _put(out, path, value)
    for path in STEPS[step].not_reads:
        if "{object}" in path:
            if obj is None:
                continue
            path = path.format(object=obj)
        *parents, last = path.split(".")
        node = _get(out, ".".join(parents))
        if isinstance(node, dict):
            node.pop(last, None)
    columns = STEPS[step].synergy_columns
    if columns and not isinstance(out.get("synergies"), Mapping):
        out["synergies"] = synergy_values(out.get("hand"), out.get("synergies"), columns)
    return out


def step_hash(config: Mapping[str, Any], step: str, obj: str | None = None, _memo: dict | None = None) -> str:
    """Hash of what a step's outputs depend on: the keys it reads and, through its
    ``upstream`` steps, those of the steps before it (12 hex digits). ``obj``: the object of
    a step run per object; None for a step run once per scenario."""
    memo = {} if _memo is None else _memo
    if (step, obj) in memo:
        return memo[step, obj]
    parts: list[Any] = [step_config(config, step, obj)]
    for upstream in (*STEPS[step].upstream, *upstream_when(config, step, obj)):
        if STEPS[upstream].scope == "object" and obj is None:
            parts.append([[name, step_hash(config, upstream, name, memo)] for name in config["objects"]])
        else:
            parts.append(step_hash(config, upstream, obj if STEPS[upstream].scope == "object" else None, memo))
    text = json.dumps(parts, sort_keys=True, default=str)
    memo[step, obj] = hashlib.sha256(text.encode()).hexdigest()[:12]
    return memo[step, obj]


def upstream_when(config: Mapping[str, Any], step: str, obj: str | None = None) -> tuple[str, ...]:
    """The steps ``step`` reads for ``obj`` besides its ``upstream``, from the object's
    effective placement (``upstream_when``): ``search`` for a searched placement."""
    if obj is None or not STEPS[step].upstream_when:
        return ()
    placement = effective_placement(config, obj)
    return tuple(up for key, value, up in STEPS[step].upstream_when if placement.get(key.removeprefix("placement.")) == value)
