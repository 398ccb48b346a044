# Shared definitions: configuration checks (before any job runs), object and synergy-set
# lists, code dependencies that trigger reruns, and the target lists.
import math
from pathlib import Path

from snakemake.exceptions import WorkflowError

from synergrasp.config import ConfigError, merge_config, synergy_sets, validate_config

ROOT = Path(workflow.basedir)
SRC = ROOT / "src" / "synergrasp"
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


def _check_inputs(cfg):
    """Validate config, hand, synergies and objects; return the synergy count."""
    from synergrasp.hand import load_hand
    from synergrasp.objects import boxes_from_config
    from synergrasp.synergies import load_synergies

    validate_config(cfg, SCHEMA)
    hand = load_hand(cfg["hand"])
    synergies = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
    boxes_from_config([{"name": name, **spec} for name, spec in cfg["objects"].items()])
    validate_config(cfg, SCHEMA, n_synergies=synergies.matrix.shape[1])


try:
    _check_inputs(config)
except (ValueError, FileNotFoundError) as err:  # ConfigError, SynergyFileError, ... are ValueErrors
    raise WorkflowError(f"Invalid input, nothing was run:\n{err}") from None


OBJECTS = list(config["objects"])
SETS = synergy_sets(config["synergy_sets"])
SHARDS = list(range(config["solver"]["pose_shards"]))
FIG4_OBJECT = config["analyses"]["fig4"]["object"]


wildcard_constraints:
    object="|".join(OBJECTS),
    shard=r"\d+",


def code(*modules):
    """Source files whose change must rerun a rule (Snakemake does not track src/)."""
    return [str(SRC / f"{m}.py") for m in modules] + [str(ROOT / "environment.lock")]


def user_files():
    """User-supplied hand/synergy files: a change of their content reruns what uses them."""
    return [p for p in (config["hand"], config["synergies"]) if p]


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
    }


def optimisation_params(wildcards):
    return {
        "mechanics": config["mechanics"],
        "mass_kg": config["objects"][wildcards.object]["mass_kg"],
        "sets": SETS,
        "solver": config["solver"],
        "synergies": config["synergies"],
        "shard": int(wildcards.shard),
    }


def object_dir(name):
    return f"results/objects/{name}"


def fig4_files(name):
    return [f"{object_dir(name)}/fig4_{kind}.{ext}" for kind in ("force_maps", "exploded") for ext in ("png", "pdf")]


def object_targets(name):
    d = object_dir(name)
    return [f"{d}/contacts.parquet", f"{d}/gfo.parquet", f"{d}/minima.parquet", *fig4_files(name)]


TABLES = [
    "success_rates",
    "table2_success_rates",
    "hierarchy",
    "minimum_preservation",
    "full_not_first7",
    "verdict_disagreements",
]


def study_targets():
    figures = [
        f"results/figures/{name}.{ext}"
        for name in ("fig1_synergy_postures", "fig2_example_grasps", "fig3_rulegraph",
                     "fig5a_hierarchy_success", "fig5b_hierarchy_force")
        for ext in ("png", "pdf")
    ]
    tables = [f"results/tables/{t}.{ext}" for t in TABLES for ext in ("csv", "md")]
    per_object = [f for name in OBJECTS for f in object_targets(name)]
    return figures + tables + per_object
