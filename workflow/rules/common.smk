# Shared definitions: configuration checks (before any job runs), object and synergy-set
# lists, code dependencies that trigger reruns, and the target lists.
import math
from pathlib import Path

from snakemake.exceptions import WorkflowError

from synergrasp.config import (
    ConfigError,
    incremental_set_id,
    merge_config,
    synergy_sets,
    validate_config,
)

ROOT = Path(workflow.basedir)
SRC = ROOT / "src" / "synergrasp"
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


def _check_inputs(cfg):
    """Validate config, hand, synergies and objects; return the synergy count."""
    from synergrasp.hand.kinematics import load_hand
    from synergrasp.simulation.objects import boxes_from_config
    from synergrasp.hand.synergies import load_synergies

    validate_config(cfg, SCHEMA)
    hand = load_hand(cfg["hand"])
    synergies = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
    boxes_from_config([{"name": name, **spec} for name, spec in cfg["objects"].items()])
    validate_config(cfg, SCHEMA, n_synergies=synergies.matrix.shape[1])


try:
    _check_inputs(config)  # ConfigError, SynergyFileError, ... are ValueErrors
except (ValueError, FileNotFoundError) as err:
    raise WorkflowError(f"Invalid input, nothing was run:\n{err}") from None


OBJECTS = list(config["objects"])
SETS = synergy_sets(config["synergy_sets"])
SHARDS = list(range(config["solver"]["pose_shards"]))
FIG4_OBJECT = config["analyses"]["fig4"]["object"]


wildcard_constraints:
    object="|".join(OBJECTS),
    shard=r"\d+",


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


def user_files():
    """User-supplied hand/synergy files: a change of their content reruns what uses them
    (a shipped synergy table given by name is under SHIPPED_DATA)."""
    from synergrasp.hand.synergies import SHIPPED_TABLES

    return [p for p in (config["hand"], config["synergies"]) if p and p not in SHIPPED_TABLES]


SHIPPED_DATA = sorted(str(p) for p in (SRC / "data").glob("*") if p.is_file())


def object_config(name):
    """The object's box and its effective placement (global placement + its override)."""
    spec = dict(config["objects"][name])
    placement = merge_config(config["placement"], spec.pop("placement", {}))
    return {"name": name, **spec, "placement": placement}


def simulation_params(wildcards):
    return {
        "object": object_config(wildcards.object),
        "grid": config["grid"],
        "closure": config["closure"],
        "hand": config["hand"],
        "synergies": config["synergies"],
        # the dynamic closure needs k_ss, mu and gravity; the kinematic one does not rerun on them
        "mechanics": config["mechanics"] if config["closure"].get("model") == "dynamic" else None,
    }


def optimisation_params(wildcards):
    return {
        "mechanics": config["mechanics"],
        "mass_kg": config["objects"][wildcards.object]["mass_kg"],
        "sets": SETS,
        "synergies": config["synergies"],
        "shard": int(wildcards.shard),
    }


def object_dir(name):
    return f"results/objects/{name}"


def fig4_files(name):
    return [
        f"{object_dir(name)}/fig4_{kind}.{ext}"
        for kind in ("force_maps", "exploded")
        for ext in ("png", "pdf")
    ]


def object_targets(name):
    d = object_dir(name)
    return [
        f"{d}/contacts.parquet",
        f"{d}/gfo.parquet",
        f"{d}/minima.parquet",
        *fig4_files(name),
    ]


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


def study_targets():
    figures = [
        f"results/figures/{name}.{ext}"
        for name in (
            "fig1_synergy_postures",
            "fig2_example_grasps",
            "fig3_rulegraph",
            "fig5a_hierarchy_success",
            "fig5b_hierarchy_force",
            "grasp_realism",
        )
        for ext in ("png", "pdf")
    ]
    tables = [
        f"results/tables/{t}.{ext}" for t in [*TABLES, "grasp_realism"] for ext in ("csv", "md")
    ]
    per_object = [f for name in OBJECTS for f in object_targets(name)]
    return figures + tables + per_object
