# Shared definitions: configuration checks (before any job runs), object and synergy-set
# lists, code dependencies that trigger reruns, and the target lists.
import functools
import math
import re
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.logging import logger

from synergrasp.config import (
    ConfigError,
    check_relations,
    scenario_configs,
    step_config,
    step_hash,
    step_params,
    synergy_problems,
)
from synergrasp.preflight import accept_configured_wildcards, configfile_problems, slurm_problems

ROOT = Path(workflow.basedir)
SRC = ROOT / "src" / "synergrasp"


def _check_inputs(raw):
    """Every scenario's complete configuration (``default`` first), checked with its hand
    and synergy files before any job runs (config/README.md); warnings on hands far from a
    human hand's dimensions are printed."""
    from synergrasp.hand.checks import check_hand
    from synergrasp.hand.synergies import load_synergies

    # Snakemake read the configuration files itself and kept a repeated key's last value
    problems = configfile_problems(workflow.configfiles)
    if problems:
        raise ConfigError("\n".join(problems))
    scenarios = scenario_configs(raw)
    hands = {}
    for name, cfg in scenarios.items():
        where = "" if name == "default" else f"scenario '{name}': "
        if cfg["hand"] not in hands:
            hands[cfg["hand"]] = check_hand(cfg["hand"])
            problems += hands[cfg["hand"]][1]
            for warning in hands[cfg["hand"]][2]:
                logger.warning(f"Warning: {warning}")
        hand = hands[cfg["hand"]][0]
        synergies = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
        problems += [where + p for p in check_relations(cfg, synergies.matrix.shape[1])]
        problems += [where + p for p in synergy_problems(cfg, synergies.mean, synergies.matrix)]
    if problems:
        raise ConfigError("\n".join(problems))
    return scenarios


try:
    SCENARIOS = _check_inputs(config)
except ValueError as err:  # ConfigError, SynergyFileError, hand/YAML file errors
    raise WorkflowError(f"Invalid input, nothing was run:\n{err}") from None

#: The main configuration (scenario `default`), complete (defaults filled in) and checked.
STUDY = SCENARIOS["default"]
OBJECTS = list(STUDY["objects"])

# Scenarios (config/README.md): each one's outputs live under its root; the default keeps
# results/. A step's output (per object or per scenario) is made once, under the root of the
# first scenario (default first) whose step reads the same keys and the same upstream
# outputs (synergrasp.config.step_hash), and shared.
SCENARIO_ROOT = {
    name: "results" if name == "default" else f"results/scenarios/{name}" for name in SCENARIOS
}
_ROOT_SCENARIO = {root: name for name, root in SCENARIO_ROOT.items()}
#: The file each per-object step writes under its root's objects/<object>/: the closure's
#: contacts (every touching link), the contacts that count (only where unloaded ones are
#: dropped: the `contacts` step), the optimisation and the minima.
STEP_FILES = {
    "simulate": "contacts.parquet",
    "contacts": "load_carrying_contacts.parquet",
    "optimise": "gfo.parquet",
    "minima": "minima.parquet",
}


def scenario_config(wildcards):
    """The complete configuration of the scenario whose root a job's {root} names."""
    return SCENARIOS[_ROOT_SCENARIO[wildcards.root]]


@functools.cache
def step_root(scenario, step, obj=None):
    """The root under which ``scenario``'s output of ``step`` (for ``obj``, a per-object
    step's object) lives: that of the first scenario whose step has the same hash."""
    key = step_hash(SCENARIOS[scenario], step, obj)
    owner = next(
        name
        for name, cfg in SCENARIOS.items()
        if (obj is None or obj in cfg["objects"]) and step_hash(cfg, step, obj) == key
    )
    return SCENARIO_ROOT[owner]


def drops_unloaded(scenario, obj):
    """Whether ``scenario`` keeps only the load-carrying contacts of ``obj``'s closure
    (else the `contacts` step has nothing to select and is the closure's own table)."""
    return step_params(SCENARIOS[scenario], "contacts", obj).drop_unloaded


def step_file(scenario, step, obj):
    """Where ``scenario``'s output of per-object ``step`` (STEP_FILES) for ``obj`` lives."""
    if step == "contacts" and not drops_unloaded(scenario, obj):
        step = "simulate"
    return f"{step_root(scenario, step, obj)}/objects/{obj}/{STEP_FILES[step]}"


def step_input(step):
    """Input function: the job's object's ``step`` output in the job's scenario."""
    return lambda w: step_file(_ROOT_SCENARIO[w.root], step, w.object)


def step_inputs(step):
    """Input function: every object's ``step`` output in the job's scenario."""
    return lambda w: [
        step_file(_ROOT_SCENARIO[w.root], step, o) for o in scenario_config(w)["objects"]
    ]


def step_cfg(step):
    """A rule's ``params``: the part of the job's scenario configuration its step reads (for
    the job's object; synergrasp.config.STEP_KEYS), so that a job reruns only when a key it
    reads changes. Its script turns it into typed parameters with synergrasp.config.step_params."""
    return lambda wildcards: step_config(scenario_config(wildcards), step, wildcards.get("object"))


def _exactly(values):
    """A wildcard constraint matching exactly one of ``values`` (longest first)."""
    return "|".join(re.escape(v) for v in sorted(set(values), key=lambda v: (-len(v), v)))


# Wildcards match the configured names exactly, so Snakemake's guard against endless
# recursion may accept a configured name ending in a repeated character (obj_000...0).
_OBJECT_NAMES = {o for cfg in SCENARIOS.values() for o in cfg["objects"]}
accept_configured_wildcards([*_OBJECT_NAMES, *SCENARIO_ROOT.values()])


wildcard_constraints:
    root=_exactly(SCENARIO_ROOT.values()),
    object=_exactly(_OBJECT_NAMES),
    shard=r"\d+",


onstart:
    # A cluster profile on a machine or shell that cannot submit: one line, before any job.
    if workflow.executor_plugin.name == "slurm":
        _raw = {k: r.raw for k, r in workflow.resource_settings.default_resources.items()}
        _problems = slurm_problems(workflow.executor_settings, _raw)
        if _problems:
            raise WorkflowError(
                "The SLURM profile cannot submit from this shell, nothing was run: "
                + "; ".join(_problems)
            )


def _imported_modules(path):
    """Names of the synergrasp modules a Python file imports, at any depth of the file."""
    import ast

    found = set()
    for node in ast.walk(ast.parse(Path(path).read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("synergrasp")}
        elif (
            isinstance(node, ast.ImportFrom)
            and node.module
            and node.module.startswith("synergrasp")
        ):
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names}  # `from pkg import module`
    return found


def _module_file(name):
    """Source file of a synergrasp module or package, or None for a name that is not one."""
    rel = Path(*name.split("."))
    for candidate in (
        SRC.parent / rel.with_suffix(".py"),
        SRC.parent / rel / "__init__.py",
    ):
        if candidate.is_file():
            return candidate
    return None


def code(script):
    """Source files whose change must rerun the rule that runs ``workflow/scripts/<script>.py``,
    i.e. the synergrasp modules it imports, transitively (lazy imports inside functions
    included), their packages' ``__init__.py``, and the lock. Derived from the code, so a
    new import cannot be missed; Snakemake itself does not track src/."""
    todo = [ROOT / "workflow" / "scripts" / f"{script}.py"]
    files = set()
    while todo:
        for name in _imported_modules(todo.pop()):
            parts = name.split(".")
            for depth in range(1, len(parts) + 1):  # a module's packages run their __init__
                path = _module_file(".".join(parts[:depth]))
                if path is not None and path not in files:
                    files.add(path)
                    todo.append(path)
    return sorted(str(f) for f in files) + [str(ROOT / "environment.lock")]


def user_files(wildcards):
    """Input function: the scenario's own hand/synergy files, so that a change of their
    content reruns what uses them (a shipped synergy table given by name is under SHIPPED_DATA)."""
    from synergrasp.hand.synergies import SHIPPED_TABLES

    cfg = scenario_config(wildcards)
    return [p for p in (cfg["hand"], cfg["synergies"]) if p and p not in SHIPPED_TABLES]


SHIPPED_DATA = sorted(str(p) for p in (SRC / "data").glob("*") if p.is_file())


def fig4_files(scenario, name):
    """Fig. 4 of object ``name`` in ``scenario`` (wherever shared)."""
    return [
        f"{step_root(scenario, 'fig4', name)}/objects/{name}/fig4_{kind}.{ext}"
        for kind in ("force_maps", "exploded")
        for ext in ("png", "pdf")
    ]


def object_targets(name, scenario="default"):
    """One object's outputs in a scenario: its per-object tables and Fig. 4 (wherever shared)."""
    files = dict.fromkeys(step_file(scenario, step, name) for step in STEP_FILES)
    return list(files) + fig4_files(scenario, name)


TABLES = [
    "success_rates",
    "table2_success_rates",
    "hierarchy",
    "minimum_preservation",
    "full_not_first7",
    "verdict_disagreements",
    "preservation_vs_chance",
    "invariant_checks",
    "claims",
]


#: The files each step run once per scenario writes under its root.
STUDY_FILES = {
    "fig1": [f"figures/fig1_synergy_postures.{ext}" for ext in ("png", "pdf")],
    "fig2": [f"figures/fig2_example_grasps.{ext}" for ext in ("png", "pdf")],
    "tables": [f"tables/{t}.{ext}" for t in TABLES for ext in ("csv", "md")],
    "realism": [
        f"tables/{t}.{ext}" for t in ("grasp_realism", "graspable_objects") for ext in ("csv", "md")
    ]
    + [f"figures/grasp_realism.{ext}" for ext in ("png", "pdf")],
    "fig5": [
        f"figures/{name}.{ext}"
        for name in (
            "fig5a_hierarchy_success",
            "fig5a_hierarchy_success_pooled",
            "fig5b_hierarchy_force",
        )
        for ext in ("png", "pdf")
    ],
}


def study_file(scenario, step, rel):
    """Where ``scenario``'s file ``rel`` (one of STUDY_FILES[step]) lives (wherever shared)."""
    return f"{step_root(scenario, step)}/{rel}"


def study_input(step, rel):
    """Input function: the job's scenario's file ``rel`` of the per-scenario ``step``."""
    return lambda w: study_file(_ROOT_SCENARIO[w.root], step, rel)


def study_targets(scenario="default"):
    """Every output of one scenario's study, each where it is made (a shared file counts;
    Fig. 3, the rule graph, is the same for all)."""
    files = [study_file(scenario, step, rel) for step, rels in STUDY_FILES.items() for rel in rels]
    files += [f"results/figures/fig3_rulegraph.{ext}" for ext in ("png", "pdf")]
    per_object = [
        f for name in SCENARIOS[scenario]["objects"] for f in object_targets(name, scenario)
    ]
    return files + per_object


# The sensitivity sweep's summary across every scenario (docs/sensitivity.md).
def scenario_tables(table):
    """Every scenario's (default first) study table ``table``.csv."""
    return [study_file(s, "tables", f"tables/{table}.csv") for s in SCENARIOS]


SENSITIVITY_FILES = [
    f"results/sensitivity/{name}.{ext}"
    for name, exts in (
        ("claims", ("csv", "md")),
        ("claims_grid", ("png", "pdf")),
        ("table2_curves", ("png", "pdf")),
    )
    for ext in exts
]
