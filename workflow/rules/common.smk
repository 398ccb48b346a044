# Shared definitions: configuration checks (before any job runs), where each step's outputs
# live (synergrasp.steps.STEPS), code dependencies that trigger reruns, and the target lists.
import functools
import math
import re
import sys
import threading
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.logging import logger

from synergrasp.config import ConfigError, check_relations, scenario_names, synergy_problems
from synergrasp.config import scenario_config as checked_scenario_config
from synergrasp.config import overlay
from synergrasp.preflight import accept_configured_wildcards, configfile_problems, slurm_problems
from synergrasp.steps import STEPS, TABLES, step_config, step_hash, upstream_when

ROOT = Path(workflow.basedir)
SRC = ROOT / "src" / "synergrasp"


@functools.cache
def _hand(path):
    """The hand of a ``hand:`` value, checked for what the study asks of it (one line per
    problem naming the file and the field); its warnings printed once."""
    from synergrasp.hand.checks import check_hand

    hand, problems, warnings = check_hand(path)
    for warning in warnings:
        logger.warning(f"Warning: {warning}")
    return hand, problems


@functools.cache
def scenario(name):
    """The complete configuration of scenario ``name`` (``default``: the configuration
    itself), checked with its hand and synergy files when a target first needs it, before
    any job runs (config/README.md): `figures` reads the default only, `sensitivity` all."""
    from synergrasp.hand.synergies import load_synergies
    from synergrasp.simulation.objects import object_problems

    try:
        cfg = checked_scenario_config(config, name)
        hand, hand_problems = _hand(cfg["hand"])
        problems = list(hand_problems)
        synergies = load_synergies(cfg["synergies"], joint_names=hand.joint_names)
        problems += check_relations(cfg, synergies.matrix.shape[1])
        problems += synergy_problems(cfg, synergies.mean, synergies.matrix)
        problems += object_problems(cfg)
        if problems:
            where = "" if name == "default" else f"scenario '{name}': "
            raise ConfigError("\n".join(where + p for p in problems))
    except ValueError as err:  # ConfigError, SynergyFileError, hand/YAML file errors
        raise WorkflowError(f"Invalid input, nothing was run:\n{err}") from None
    return cfg


# Objects drawn from pybullet's random meshes (config/examples/random_objects.yaml): added to
# `objects` before anything is checked; a mesh left out is listed with its reason by the summary.
if config.get("random_objects"):
    from synergrasp.simulation.random_objects import add_random_objects

    add_random_objects(config, ROOT)

# Snakemake read the configuration files itself and kept a repeated key's last value.
_PROBLEMS = configfile_problems(workflow.configfiles)
if _PROBLEMS:
    raise WorkflowError("Invalid input, nothing was run:\n" + "\n".join(_PROBLEMS))

#: The main configuration (scenario `default`), complete (defaults filled in) and checked.
STUDY = scenario("default")
OBJECTS = list(STUDY["objects"])
#: The scenarios' names, default first (config/README.md).
SCENARIOS = scenario_names(config)

# Scenarios (config/README.md): each one's outputs live under its root; the default keeps
# results/. A step's output (per object or per scenario) is made once, under the root of the
# first scenario (default first) whose step reads the same keys and the same upstream
# outputs (synergrasp.steps.step_hash), and shared.
SCENARIO_ROOT = {
    name: "results" if name == "default" else f"results/scenarios/{name}" for name in SCENARIOS
}
_ROOT_SCENARIO = {root: name for name, root in SCENARIO_ROOT.items()}


def scenario_config(wildcards):
    """The complete configuration of the scenario whose root a job's {root} names."""
    return scenario(_ROOT_SCENARIO[wildcards.root])


@functools.cache
def _hashes(name):
    """Memo of scenario ``name``'s step hashes, filled as they are asked for."""
    return {}


def _step_hash(name, step, obj=None):
    return step_hash(scenario(name), step, obj, _hashes(name))


@functools.cache
def step_root(name, step, obj=None):
    """The root under which scenario ``name``'s output of ``step`` (for ``obj``, a per-object
    step's object) lives: that of the first scenario whose step has the same hash."""
    key = _step_hash(name, step, obj)
    owner = next(
        other
        for other in SCENARIOS
        if (obj is None or obj in scenario(other)["objects"])
        and _step_hash(other, step, obj) == key
    )
    return SCENARIO_ROOT[owner]


def drops_unloaded(name, obj):
    """Whether scenario ``name`` keeps only the load-carrying contacts of ``obj``'s closure
    (else the `contacts` step has nothing to select and is the closure's own table)."""
    cfg = scenario(name)["closure"]
    return cfg["model"] == "dynamic" and cfg["dynamic"]["unloaded_contacts"] == "drop"


def step_file(name, step, obj):
    """Where scenario ``name``'s output of the per-object ``step`` for ``obj`` lives."""
    if step == "contacts" and not drops_unloaded(name, obj):
        step = "simulate"
    (rel,) = STEPS[step].outputs.values()
    return f"{step_root(name, step, obj)}/objects/{obj}/{rel}"


def searched(name, obj):
    """Whether ``obj``'s placement in scenario ``name`` is the searched one (its closure reads
    the placement search's targets, docs/placement_search.md)."""
    return "search" in upstream_when(scenario(name), "simulate", obj)


def searched_input(wildcards):
    """Input function: the placement search's table of the job's object, where its placement
    is searched (none otherwise)."""
    name = _ROOT_SCENARIO[wildcards.root]
    return step_file(name, "search", wildcards.object) if searched(name, wildcards.object) else []


def _shown(name, step, obj):
    """Whether scenario ``name`` makes the per-object ``step`` for ``obj``: the search where
    the placement is searched, the placement map where it is at the chosen target."""
    if step not in ("search", "placement_map"):
        return True
    if not searched(name, obj):
        return False
    cfg = scenario(name)
    rank = overlay(cfg["placement"], cfg["objects"][obj].get("placement"))["search_rank"]
    return step == "search" or rank == 1


def placement_label(name):
    """How scenario ``name`` places the boxes, for the sweep's summary: the mode; for a
    searched placement the rank and whether the scenario searched again or uses another
    scenario's targets (docs/sensitivity.md)."""
    cfg = scenario(name)
    if cfg["placement"]["mode"] != "searched":
        return cfg["placement"]["mode"]
    roots = {step_root(name, "search", o) for o in cfg["objects"] if searched(name, o)}
    own = SCENARIO_ROOT[name] in roots
    where = (
        "own search" if own else "targets of " + ", ".join(sorted(_ROOT_SCENARIO[r] for r in roots))
    )
    return f"searched, rank {cfg['placement']['search_rank']} ({where})"


def step_input(step):
    """Input function: the job's object's ``step`` output in the job's scenario."""
    return lambda w: step_file(_ROOT_SCENARIO[w.root], step, w.object)


def step_inputs(step):
    """Input function: every object's ``step`` output in the job's scenario."""
    return lambda w: [
        step_file(_ROOT_SCENARIO[w.root], step, o) for o in scenario_config(w)["objects"]
    ]


def searched_inputs(step):
    """Input function: the per-object ``step`` output of every object of the job's scenario
    whose placement is searched."""
    return lambda w: [
        step_file(_ROOT_SCENARIO[w.root], step, o)
        for o in scenario_config(w)["objects"]
        if searched(_ROOT_SCENARIO[w.root], o)
    ]


def step_cfg(step):
    """A rule's ``params``: the part of the job's scenario configuration its step reads (for
    the job's object; synergrasp.steps.STEPS), so that a job reruns only when a key it reads
    changes. Its script builds typed parameters from it (the step's ``params`` class)."""
    return lambda wildcards: step_config(scenario_config(wildcards), step, wildcards.get("object"))


def _exactly(values):
    """A wildcard constraint matching exactly one of ``values`` (longest first)."""
    return "|".join(re.escape(v) for v in sorted(set(values), key=lambda v: (-len(v), v)))


#: Every object name the configuration or a scenario's overlay gives (read without checking
#: the scenarios: a superset of the objects any checked scenario has).
_OBJECT_NAMES = set(OBJECTS) | {
    o
    for over in (config.get("scenarios") or {}).values()
    if isinstance(over, dict)
    for o in map(str, over.get("objects") or {})
}
# Wildcards match the configured names exactly, so Snakemake's guard against endless
# recursion may accept a configured name ending in a repeated character (obj_000...0).
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


def cancel_scheduler_timers():
    """Cancel the scheduler's pending re-evaluation timers (threading.Timer, not daemon
    threads) once the run is over, so that Snakemake exits at once instead of a job-rate
    timespan later (profiles/default/config.yaml). The workflow starts no timer of its own."""
    for thread in threading.enumerate():
        if isinstance(thread, threading.Timer):
            thread.cancel()


onsuccess:
    cancel_scheduler_timers()


onerror:
    cancel_scheduler_timers()


#: `import synergrasp.x[, ...]` and `from synergrasp.x import a, b` (or a parenthesised list),
#: at any indentation (lazy imports inside functions included).
_IMPORT = re.compile(
    r"^[ \t]*(?:import[ \t]+(synergrasp[\w.]*(?:[ \t]*,[ \t]*[\w.]+)*)"
    r"|from[ \t]+(synergrasp[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*))",
    re.MULTILINE,
)


@functools.cache
def _imported_modules(path):
    """Names of the synergrasp modules a Python file imports, at any depth of the file (read
    as text: parsing every module would cost a second at each start of Snakemake)."""
    found = set()
    for plain, module, names in _IMPORT.findall(Path(path).read_text()):
        if plain:
            found |= {n.strip() for n in plain.split(",") if n.strip().startswith("synergrasp")}
        else:
            found.add(module)
            names = names.split("#")[0] if not names.startswith("(") else names
            for name in re.split(r"[\s,()]+", re.sub(r"#[^\n]*", "", names)):
                if name and name != "as":
                    found.add(f"{module}.{name}")  # `from pkg import module`
    return found


@functools.cache
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
    """Input function: the scenario's own hand/synergy files and the mesh files of its objects
    (the job's object only, for a job per object), so that a change of their content reruns
    what uses them (a shipped synergy table given by name is under SHIPPED_DATA)."""
    from synergrasp.hand.synergies import SHIPPED_TABLES

    cfg = scenario_config(wildcards)
    obj = getattr(wildcards, "object", None)
    objects = [obj] if obj in cfg["objects"] else list(cfg["objects"])
    meshes = [
        cfg["objects"][o]["shape"]["mesh"]["path"]
        for o in objects
        if "mesh" in cfg["objects"][o]["shape"]
    ]
    return [p for p in (cfg["hand"], cfg["synergies"]) if p and p not in SHIPPED_TABLES] + meshes


#: The shipped hand and synergy files. Not the schema: its defaults reach a job through its
#: params (the step's part of the configuration), so a new key reruns nothing.
SHIPPED_DATA = sorted(
    str(p)
    for p in (SRC / "data").glob("*")
    if p.is_file() and p.name not in ("config.schema.yaml", "README.md")
)


def object_targets(name, scenario_name="default"):
    """One object's outputs in a scenario: the outputs of every per-object step (wherever shared)."""
    files = {}
    for step, spec in STEPS.items():
        if spec.scope != "object" or spec.optional or not _shown(scenario_name, step, name):
            continue
        if len(spec.outputs) == 1:
            files[step_file(scenario_name, step, name)] = None
        else:
            root = step_root(scenario_name, step, name)
            files.update(
                dict.fromkeys(f"{root}/objects/{name}/{rel}" for rel in spec.outputs.values())
            )
    return list(files)


def optional_object_targets(step, name="default"):
    """The outputs of the optional per-object ``step`` for every object of scenario ``name``."""
    return [
        f"{step_root(name, step, obj)}/objects/{obj}/{rel}"
        for obj in scenario(name)["objects"]
        for rel in STEPS[step].outputs.values()
    ]


def plan_inputs(rel):
    """Input function: every object's file ``rel`` of the `plan` step in the job's scenario."""
    return lambda w: [
        f"{step_root(_ROOT_SCENARIO[w.root], 'plan', o)}/objects/{o}/{rel}"
        for o in scenario_config(w)["objects"]
    ]


def random_objects_manifest(wildcards):
    """Input function: the sha256 manifest of the scenario's random objects (none without them)."""
    spec = scenario_config(wildcards).get("random_objects")
    return [str(ROOT / spec["sha256_file"])] if spec else []


def study_file(name, step, rel):
    """Where scenario ``name``'s file ``rel`` (one of the step's outputs) lives (wherever shared)."""
    return f"{step_root(name, step)}/{rel}"


def study_input(step, rel):
    """Input function: the job's scenario's file ``rel`` of the per-scenario ``step``."""
    return lambda w: study_file(_ROOT_SCENARIO[w.root], step, rel)


def workflow_files(step):
    """The files of a step run once for the whole workflow (under results/)."""
    return [f"results/{rel}" for rel in STEPS[step].outputs.values()]


def study_targets(name="default"):
    """Every output of one scenario's study, each where it is made (a shared file counts;
    Fig. 3, the rule graph, is the same for all; the sweep's summary is `sensitivity`'s)."""
    files = [
        study_file(name, step, rel)
        for step, spec in STEPS.items()
        if spec.scope == "scenario" and not spec.optional
        for rel in spec.outputs.values()
    ]
    files += workflow_files("fig3")
    return files + [f for obj in scenario(name)["objects"] for f in object_targets(obj, name)]


def scenario_targets(name):
    """Input function: scenario ``name``'s study (its configuration is read only when asked)."""
    return lambda wildcards: study_targets(name)


def every_scenario_targets(wildcards):
    """Input function: every scenario's study."""
    return [f for name in SCENARIOS for f in study_targets(name)]


# The sensitivity sweep's summary across every scenario (docs/sensitivity.md).
def scenario_tables(table, step="tables"):
    """Input function: every scenario's (default first) table ``table``.csv made by ``step``."""
    return lambda wildcards: [study_file(s, step, f"tables/{table}.csv") for s in SCENARIOS]


SENSITIVITY_FILES = workflow_files("sensitivity")


def placement_claims_targets(name="default"):
    """The claims over the placement search's targets (the optional steps) of scenario ``name``."""
    return [
        study_file(name, "placement_claims", rel)
        for rel in STEPS["placement_claims"].outputs.values()
    ]


def _report_archive(argv):
    """Whether the command writes the report as an archive (`--report <path>.zip`)."""
    for k, arg in enumerate(argv):
        path = arg.split("=", 1)[1] if arg.startswith("--report=") else None
        if arg == "--report" and k + 1 < len(argv):
            path = argv[k + 1]
        if path is not None:
            return path.endswith(".zip")
    return False


def pages_in_report(path, **report_args):
    """A folder of pages (its index.html first), in the report when the report is an archive:
    Snakemake's one-file HTML report refuses folders (and Chromium would not open a page of
    several MB from it), so results/report.zip holds the 3-D pages and report.html does not."""
    if _report_archive(sys.argv):
        return report(directory(path), htmlindex="index.html", **report_args)
    return directory(path)
