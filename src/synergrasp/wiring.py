"""What the workflow's rules are made of, from the step registry (``synergrasp.steps.STEPS``):
each rule's output, log and benchmark paths, threads and requests, the files of each
scenario's study, where a step's output shared between scenarios lives, the code a rule's
script runs. ``workflow/rules/common.smk`` builds one :class:`Wiring` from Snakemake's
configuration and ``workflow/rules/steps.smk`` makes every rule from its answers
(:meth:`Wiring.inputs`, :class:`RuleFiles`, :meth:`Wiring.resources`, :meth:`Wiring.params`).

Paths: a step per object writes under ``{root}/objects/{object}/``, one per scenario under
``{root}/``, one for the whole workflow under ``results/``; ``{root}`` is ``results`` for the
default scenario and ``results/scenarios/<name>`` otherwise (config/README.md). A rule's
log and benchmark: ``<root>/logs/<rule>/<wildcards>.log`` for a step per object,
``<root>/logs/<rule>.log`` otherwise (likewise ``benchmarks/``, ``.tsv``).

Layer: above the step registry (it checks a scenario's hand, synergy and object files).
"""

from __future__ import annotations

import functools
import hashlib
import math
import re
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from synergrasp.config import DEFAULT_SCENARIO, ConfigError, grid_axis_deg, object_names, scenario_names
from synergrasp.ids import synergy_sets
from synergrasp.input_checks import checked_scenario, search_table_or_refuse, searched_objects_or_refuse
from synergrasp.steps import (
    CLOSURE_COST_FACTOR,
    MANIFEST,
    MESH,
    RESULTS,
    RULE_FILES,
    SHIPPED_DATA,
    SNAKEFILE,
    SOLVER_COMPILE,
    STEPS,
    USER_FILES,
    made_by,
    reads_key,
    rule_costs,
    rule_handed,
    rule_inputs,
    rule_step,
    scenario_root,
    step_config,
    step_for_object,
    step_hash,
)

__all__ = [
    "Wiring",
    "RuleFiles",
    "code_files",
    "code_digest",
    "report_archive",
    "job_size",
    "runtime_min",
    "mem_mb",
    "RUNTIME_MARGIN",
    "MEMORY_MARGIN",
]

#: Requests are the measured cost times a margin (slower nodes, shared file systems),
#: rounded up to whole minutes and to 100 MB (docs/cluster.md).
RUNTIME_MARGIN, MEMORY_MARGIN = 3.0, 1.5
_PREFIX = {"object": "{root}/objects/{object}/", "scenario": "{root}/", "workflow": f"{RESULTS}/"}
_WILDCARD = re.compile(r"\{(\w+)\}")


# --------------------------------------------------------------------------- one rule's files


class RuleFiles:
    """The paths of one rule, from its step's entry in the registry."""

    def __init__(self, rule: str):
        self.rule = rule
        self.step = rule_step()[rule]
        self.spec = STEPS[self.step]
        self.cost = rule_costs()[rule]

    @property
    def prefix(self) -> str:
        return _PREFIX[self.spec.scope]

    def outputs(self) -> dict[str, str]:
        """Output name -> path pattern of what the rule writes (the registry's ``outputs`` for
        the step's last rule, its ``rule_outputs`` entry for an earlier one)."""
        if self.rule in self.spec.rule_outputs:
            return {"out": self.prefix + self.spec.rule_outputs[self.rule]}
        return {name: self.prefix + rel for name, rel in self.spec.outputs.items()}

    def _wildcards(self) -> list[str]:
        names = []
        for path in self.outputs().values():
            names += [w for w in _WILDCARD.findall(path) if w != "root" and w not in names]
        return names

    def _under(self, kind: str, ext: str) -> str:
        root = RESULTS if self.spec.scope == "workflow" else "{root}"
        wildcards = self._wildcards()
        if not wildcards:
            return f"{root}/{kind}/{self.rule}.{ext}"
        return f"{root}/{kind}/{self.rule}/" + "_".join(f"{{{w}}}" for w in wildcards) + f".{ext}"

    def log(self) -> str:
        """The rule's log file (pattern)."""
        return self._under("logs", "log")

    def benchmark(self) -> str:
        """The rule's benchmark file (pattern)."""
        return self._under("benchmarks", "tsv")

    def snakemake_outputs(self, report: Callable, directory: Callable, temp: Callable, archive: bool) -> dict[str, Any]:
        """The rule's ``output`` with Snakemake's flags (``report``, ``directory``, ``temp``
        passed in): a file the report shows in the report; a folder of pages in it only when
        the report is an archive (``archive``: Snakemake's one-file HTML report refuses
        folders, and a browser would not open a page of several MB from it); the file of a
        rule before the step's last kept only until the last has run."""
        out: dict[str, Any] = {}
        for name, path in self.outputs().items():
            entry = self.report(name)
            if self.rule in self.spec.rule_outputs:
                out[name] = temp(path)
            elif name in self.spec.folders:
                out[name] = report(directory(path), htmlindex="index.html", **entry) if entry and archive else directory(path)
            else:
                out[name] = report(path, **entry) if entry else path
        return out

    def report(self, name: str) -> dict[str, str] | None:
        """The report entry of output ``name`` (caption, category, subcategory), None if not shown."""
        if self.rule in self.spec.rule_outputs or name not in self.spec.report:
            return None
        caption, category = self.spec.report[name]
        entry = {"caption": f"../report/{caption}.rst", "category": category}
        if self.spec.scope == "object":
            entry["subcategory"] = "{object}"
        return entry


# --------------------------------------------------------------------------- code a rule runs

#: `import synergrasp.x[, ...]` and `from synergrasp.x import a, b` (or a parenthesised list),
#: at any indentation (lazy imports inside functions included).
_IMPORT = re.compile(
    r"^[ \t]*(?:import[ \t]+(synergrasp[\w.]*(?:[ \t]*,[ \t]*[\w.]+)*)"
    r"|from[ \t]+(synergrasp[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*))",
    re.MULTILINE,
)


@functools.cache
def imported_modules(path: Path) -> frozenset[str]:
    """Names of the synergrasp modules a Python file imports, at any depth of the file (read
    as text: parsing every module would cost a second at each start of Snakemake); a name
    imported from a package may be a module (``from pkg import module``)."""
    found = set()
    for plain, module, names in _IMPORT.findall(Path(path).read_text()):
        if plain:
            found |= {n.strip() for n in plain.split(",") if n.strip().startswith("synergrasp")}
        else:
            found.add(module)
            names = names.split("#")[0] if not names.startswith("(") else names
            for name in re.split(r"[\s,()]+", re.sub(r"#[^\n]*", "", names)):
                if name and name != "as":
                    found.add(f"{module}.{name}")
    return frozenset(found)


@functools.cache
def _module_file(src: Path, name: str) -> Path | None:
    """Source file of a synergrasp module or package under ``src``, None for another name."""
    rel = Path(*name.split("."))
    for candidate in (src / rel.with_suffix(".py"), src / rel / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def code_files(script: Path, src: Path) -> list[Path]:
    """The synergrasp modules ``script`` imports, transitively (lazy imports inside functions
    included), with their packages' ``__init__.py``; ``src`` holds the ``synergrasp`` package.
    Derived from the code, so a new import cannot be missed (Snakemake does not track src/)."""
    todo, files = [Path(script)], set()
    while todo:
        for name in imported_modules(todo.pop()):
            parts = name.split(".")
            for depth in range(1, len(parts) + 1):  # a module's packages run their __init__
                path = _module_file(src, ".".join(parts[:depth]))
                if path is not None and path not in files:
                    files.add(path)
                    todo.append(path)
    return sorted(files)


def code_digest(files: Sequence[Path], root: Path) -> str:
    """``compiled_cache.files_digest`` of ``files`` (under ``root``), named by their sorted
    paths relative to it: the same code gives the same digest from any checkout, an edited
    line another."""
    from synergrasp.compiled_cache import files_digest  # numba's import only when asked

    return files_digest(sorted(Path(f).relative_to(root).as_posix() for f in files), root)


# --------------------------------------------------------------------------- requests


def job_size(rule: str, cfg: Mapping[str, Any]) -> float:
    """Units of work (``synergrasp.steps.UNITS``) of one job of ``rule`` under the scenario
    configuration ``cfg``: the closure's cost follows the grid and the closure model, the
    optimisation's its grid, synergy sets and shards."""
    n_poses = len(grid_axis_deg(cfg["grid"]["alpha_deg"])) * len(grid_axis_deg(cfg["grid"]["beta_deg"]))
    n_sets = len(synergy_sets(cfg["synergy_sets"]))
    factor = CLOSURE_COST_FACTOR.get(cfg["closure"]["model"], CLOSURE_COST_FACTOR[None])
    return {
        "none": 0,
        "pose": n_poses,
        "closure_pose": n_poses * factor,
        "shard_pose_set": math.ceil(n_poses / cfg["solver"]["pose_shards"]) * n_sets,
        "pose_set": n_poses * n_sets,
        "object_pose": len(cfg["objects"]) * n_poses,
        "object_pose_set": len(cfg["objects"]) * n_poses * n_sets,
    }[rule_costs()[rule].unit]


def runtime_min(rule: str, cfg: Mapping[str, Any]) -> int:
    """Wall-time request of one job of ``rule`` under ``cfg``, whole minutes (at least 1)."""
    cost = rule_costs()[rule]
    seconds = cost.fixed_s + cost.unit_s * job_size(rule, cfg) + (SOLVER_COMPILE[0] if cost.compiles else 0.0)
    return max(1, math.ceil(RUNTIME_MARGIN * seconds / 60.0))


def mem_mb(rule: str, cfg: Mapping[str, Any]) -> int:
    """Memory request of one job of ``rule`` under ``cfg``, MB rounded up to 100 MB."""
    cost = rule_costs()[rule]
    mb = cost.fixed_mb + cost.unit_mb * job_size(rule, cfg) + (SOLVER_COMPILE[1] if cost.compiles else 0.0)
    return 100 * math.ceil(MEMORY_MARGIN * mb / 100.0)


# --------------------------------------------------------------------------- Snakemake's run


def report_archive(argv: Sequence[str]) -> bool:
    """Whether the command line writes the report as an archive (``--report <path>.zip``)."""
    for k, arg in enumerate(argv):
        path = arg.split("=", 1)[1] if arg.startswith("--report=") else None
        if arg == "--report" and k + 1 < len(argv):
            path = argv[k + 1]
        if path is not None:
            return path.endswith(".zip")
    return False


# --------------------------------------------------------------------------- the study's files


class Wiring:
    """The workflow of one Snakemake run: its scenarios (each checked when a target first
    needs it), where each step's outputs live, the study's targets and the rules' inputs.

    ``config``: Snakemake's configuration (scenarios included); ``basedir``: the checkout;
    ``error``: the exception class of bad input (Snakemake's WorkflowError); ``warn``: where
    warnings on the configuration go (each once); ``stop``: called with the lines of bad input
    before ``error`` is raised (the workflow's ``preflight.refuse`` stops the run there, with
    the lines alone)."""

    def __init__(
        self,
        config: Mapping[str, Any],
        basedir: str | Path,
        error: type[Exception] = ValueError,
        warn: Callable[[str], Any] = print,
        stop: Callable[[list[str]], Any] = lambda lines: None,
    ):
        self.config, self.root, self.error, self.warn, self.stop = config, Path(basedir), error, warn, stop
        if config.get("random_objects") is not None:  # objects drawn from pybullet's meshes, added before any check
            from synergrasp.simulation.random_objects import add_random_objects

            try:  # the block is checked before any value of it is used
                add_random_objects(config, self.root)
            except ConfigError as err:
                self.stop(str(err).splitlines())
                raise self.error(f"Invalid input, nothing was run:\n{err}") from None
        self._warned: set[str] = set()
        self.src = self.root / "src"
        self._checked: dict[str, dict[str, Any]] = {}
        self._hands: dict[str, Any] = {}
        self._hashes: dict[str, dict] = {}
        self._roots: dict[tuple, str] = {}
        self._for: dict[tuple[str, str, str], bool] = {}
        self._requests: dict[tuple[str, str], dict[str, int]] = {}
        #: Mesh files by the name of their parts file (``mesh_parts``'s wildcard ``mesh``).
        self.meshes: dict[str, str] = {}
        #: The scenarios' names, default first, and their roots.
        self.scenarios = scenario_names(config)
        self.scenario_root = {n: scenario_root(n) for n in self.scenarios}
        self._root_scenario = {root: name for name, root in self.scenario_root.items()}
        #: The main configuration (scenario ``default``), complete and checked.
        self.study = self.scenario(DEFAULT_SCENARIO)
        self.objects = list(self.study["objects"])

    # ---- configurations

    def scenario(self, name: str) -> dict[str, Any]:
        """The complete configuration of scenario ``name``, checked with its hand, synergy
        and object files the first time it is asked for, before any job runs
        (``input_checks.checked_scenario``, the inspector's checks too)."""
        if name in self._checked:
            return self._checked[name]
        try:
            cfg, warnings = checked_scenario(self.config, name)
        except ConfigError as err:
            self.stop(str(err).splitlines())
            raise self.error(f"Invalid input, nothing was run:\n{err}") from None
        for warning in warnings:
            if warning not in self._warned:
                self._warned.add(warning)
                self.warn(f"Warning: {warning}")
        self._name_parts(cfg)
        self._checked[name] = cfg
        return cfg

    def _name_parts(self, cfg: dict[str, Any]) -> None:
        """Give every mesh object of a checked configuration its ``parts``: the file the rule
        ``mesh_parts`` makes, ``results/meshes/<key>.obj`` (``convex_parts.parts_key`` of the
        file's bytes), unless the configuration names one."""
        from synergrasp.simulation.shapes.convex_parts import parts_key

        for spec in cfg["objects"].values():
            mesh = spec["shape"].get("mesh")
            if mesh is None or mesh.get("parts"):
                continue
            key = parts_key(hashlib.sha256(Path(mesh["path"]).read_bytes()).hexdigest())
            self.meshes.setdefault(key, mesh["path"])
            mesh["parts"] = RuleFiles("mesh_parts").outputs()["obj"].format(mesh=key)

    def mesh_file(self, wildcards: Any) -> str:
        """Input function of ``mesh_parts``: the mesh file whose parts file the job makes."""
        return self.meshes[wildcards.mesh]

    def job_scenario(self, wildcards: Any) -> str:
        """The scenario whose root a job's ``{root}`` names (the default outside any root)."""
        return self._root_scenario[wildcards.root] if "root" in wildcards.keys() else DEFAULT_SCENARIO

    def job_config(self, wildcards: Any) -> dict[str, Any]:
        """The complete configuration of a job's scenario."""
        return self.scenario(self.job_scenario(wildcards))

    def object_names(self) -> set[str]:
        """Every object name the configuration or a scenario's overlay gives (read without
        checking the scenarios: a superset of the objects any checked scenario has)."""
        return set(object_names(self.config, self.objects))

    @staticmethod
    def exactly(values: Any) -> str:
        """A wildcard constraint matching exactly one of ``values`` (longest first)."""
        return "|".join(re.escape(v) for v in sorted(set(values), key=lambda v: (-len(v), v)))

    # ---- where a step's output lives

    def step_root(self, name: str, step: str, obj: str | None = None) -> str:
        """The root of scenario ``name``'s output of ``step`` (for ``obj``): that of the first
        scenario (default first) whose step reads the same keys and upstream outputs."""
        if (name, step, obj) not in self._roots:
            key = self._step_hash(name, step, obj)
            owner = next(
                other
                for other in self.scenarios
                if (obj is None or obj in self.scenario(other)["objects"]) and self._step_hash(other, step, obj) == key
            )
            self._roots[name, step, obj] = self.scenario_root[owner]
        return self._roots[name, step, obj]

    def _step_hash(self, name: str, step: str, obj: str | None) -> str:
        return step_hash(self.scenario(name), step, obj, self._hashes.setdefault(name, {}))

    def step_file(self, name: str, step: str, obj: str) -> str:
        """Where scenario ``name``'s one output of the per-object ``step`` for ``obj`` lives
        (a step not made there, ``made_when``, hands on its first upstream step's)."""
        made = made_by(self.scenario(name), step)
        (rel,) = STEPS[made].outputs.values()
        return f"{self.step_root(name, made, obj)}/objects/{obj}/{rel}"

    def scenario_file(self, name: str, step: str, rel: str) -> str:
        """Where scenario ``name``'s file ``rel`` (one of the step's outputs) lives."""
        return f"{self.step_root(name, step)}/{rel}"

    # ---- a rule's inputs and params, from the registry

    def inputs(self, rule: str) -> dict[str, Any]:
        """A rule's ``input``: each of its registry inputs (``steps.rule_inputs``) as the path,
        list or input function Snakemake takes (the code its script runs is a param, :meth:`params`).

        A source ``"<step>"`` or ``"<step>.<output>"`` is, by the two steps' scopes: for a
        rule per object reading a step per object, the job's object's file; for a rule per
        scenario, every object's file of a step per object, or the scenario's file of a step
        per scenario; for a rule run once for the workflow, every scenario's file. A source
        naming an earlier rule of the same step is every one of its shards' files."""
        scope = STEPS[rule_step()[rule]].scope
        return {name: self._source(rule, scope, source) for name, source in rule_inputs(rule).items()}

    def _source(self, rule: str, scope: str, source: str) -> Any:
        special = {
            SHIPPED_DATA: self.shipped_data,
            USER_FILES: lambda: self.user_files,
            MANIFEST: lambda: self.random_objects_manifest,
            MESH: lambda: self.mesh_file,
            RULE_FILES: lambda: [str(p) for p in sorted((self.root / "workflow" / "rules").glob("*.smk"))],
            SNAKEFILE: lambda: str(self.root / "Snakefile"),
        }
        if source in special:
            return special[source]()
        step, _, output = source.partition(".")
        if step not in STEPS:  # an earlier rule of the same step: every shard's file
            return self.shard_files(step)
        producer = STEPS[step].scope
        if producer == "object" and scope == "object" and not output:
            return self.search_input(rule_step()[rule]) if step == "search" else self.step_input(step)
        if producer == "object" and scope == "scenario":
            return self.object_files(step, output) if output else self.step_inputs(step)
        rel = STEPS[step].outputs[output] if output else next(iter(STEPS[step].outputs.values()))
        if producer == "scenario" and scope in ("scenario", "object"):
            return self.scenario_input(step, rel)
        if producer == "scenario" and scope == "workflow":
            return lambda w: [self.scenario_file(s, step, rel) for s in self.scenarios]
        raise ValueError(f"rule {rule!r}: no input of a rule per {scope} from {source!r} (a step per {producer})")

    def params(self, rule: str) -> dict[str, Any]:
        """A rule's ``params`` (``steps.rule_handed``): ``cfg``, the part of the job's scenario
        configuration its step reads; ``configfile``, the shipped configuration file;
        ``scenarios``, the scenarios' names; ``placements``, how each places the boxes. And, for
        every rule, ``code``: the digest of the code its script runs (:meth:`code`), so that an
        edited module reruns the rules that load it (Snakemake's ``params`` rerun trigger; as
        inputs, its hundred files cost a dry run of 1,000 objects a fifth of its time)."""
        handed = {
            "cfg": lambda: self.step_cfg(rule_step()[rule]),
            "configfile": lambda: str(self.root / "config" / "config.yaml"),
            "scenarios": lambda: list(self.scenarios),
            "placements": lambda: lambda w: [self.placement_label(s) for s in self.scenarios],
        }
        return {**{name: handed[name]() for name in rule_handed(rule)}, "code": self.code_digest(rule)}

    # ---- input functions of the rules

    def step_input(self, step: str) -> Callable[[Any], str | list[str]]:
        """Input function: the job's object's ``step`` output in the job's scenario (the path;
        none, ``[]``, where the scenario does not make it for the object, ``placement_when``)."""

        def file(w: Any) -> str | list[str]:
            name = self.job_scenario(w)
            return self.step_file(name, step, w.object) if self._for_object(name, step, w.object) else []

        return file

    def search_input(self, reader: str) -> Callable[[Any], str | list[str]]:
        """Input function: the job's object's placement-search table where its placement is
        searched; for a ``reader`` step that reads ``placement.search_rank``, a rank beyond
        the distinct targets of a table that exists already stops the run before any job
        (``input_checks.search_rank_problems``)."""
        if not reads_key(reader, "placement.search_rank"):
            return self.step_input("search")

        def file(w: Any) -> str | list[str]:
            path = self.step_input("search")(w)
            return search_table_or_refuse(self.job_config(w), w.object, path, self._refuse) if path else path

        return file

    def step_inputs(self, step: str) -> Callable[[Any], list[str]]:
        """Input function: every object's ``step`` output in the job's scenario."""

        def files(w: Any) -> list[str]:
            name = self.job_scenario(w)
            return [self.step_file(name, step, o) for o in self.scenario(name)["objects"] if self._for_object(name, step, o)]

        return files

    def _refuse(self, lines: list[str]) -> None:
        if lines:
            self.stop(lines)
            raise self.error("Invalid input, nothing was run:\n" + "\n".join(lines))

    def scenario_input(self, step: str, rel: str) -> Callable[[Any], str]:
        """Input function: the job's scenario's file ``rel`` of the per-scenario ``step``."""
        return lambda w: self.scenario_file(self.job_scenario(w), step, rel)

    def shard_files(self, rule: str) -> Callable[[Any], list[str]]:
        """Input function: the job's object's files of every shard of ``rule`` (``solver.pose_shards``)."""
        (path,) = RuleFiles(rule).outputs().values()
        return lambda w: [
            path.format(root=w.root, object=w.object, shard=i) for i in range(self.job_config(w)["solver"]["pose_shards"])
        ]

    def step_cfg(self, step: str) -> Callable[[Any], dict[str, Any]]:
        """A rule's ``params``: the part of the job's scenario configuration its step reads
        (for the job's object), so that a job reruns only when a key it reads changes."""
        return lambda w: step_config(self.job_config(w), step, w.get("object"))

    def code(self, script: str) -> list[str]:
        """The files whose change reruns the rule running ``workflow/scripts/<script>.py``:
        the modules it imports, transitively, and the lock."""
        files = code_files(self.root / "workflow" / "scripts" / f"{script}.py", self.src)
        return [str(f) for f in files] + [str(self.root / "environment.lock")]

    def code_digest(self, script: str) -> str:
        """:func:`code_digest` of :meth:`code`'s files (paths relative to the checkout)."""
        return code_digest([Path(f) for f in self.code(script)], self.root)

    def user_files(self, wildcards: Any) -> list[str]:
        """Input function: the scenario's own hand/synergy files and the mesh files of its
        objects with their convex parts (``mesh_parts``; the job's object only, for a job per
        object)."""
        from synergrasp.hand.description import SHIPPED_HANDS
        from synergrasp.hand.synergies import SHIPPED_TABLES

        cfg = self.job_config(wildcards)
        obj = getattr(wildcards, "object", None)
        objects = [obj] if obj in cfg["objects"] else list(cfg["objects"])
        meshes = [
            file
            for o in objects
            if "mesh" in cfg["objects"][o]["shape"]
            for file in (cfg["objects"][o]["shape"]["mesh"]["path"], cfg["objects"][o]["shape"]["mesh"]["parts"])
        ]
        shipped = (*SHIPPED_TABLES, *SHIPPED_HANDS)  # by name: their files are under shipped_data()
        return [p for p in (cfg["hand"], cfg["synergies"]) if p and p not in shipped] + meshes

    def shipped_data(self) -> list[str]:
        """The shipped hand and synergy files (not the schema: its defaults reach a job
        through its params, so a new key reruns nothing)."""
        data = self.src / "synergrasp" / "data"
        return sorted(
            str(p)
            for p in [*data.glob("*"), *data.glob("hands/**/*")]
            if p.is_file() and p.name not in ("config.schema.yaml", "README.md")
        )

    def resources(self, rule: str) -> dict[str, Callable[[Any], int]]:
        """A rule's ``resources``: memory and run time of one job in its scenario."""
        return {"mem_mb": lambda w: self._request(rule, w)["mem_mb"], "runtime": lambda w: self._request(rule, w)["runtime"]}

    def _request(self, rule: str, wildcards: Any) -> dict[str, int]:
        """The requests of a job of ``rule`` (its wildcards name its scenario)."""
        return self.scenario_request(rule, self.job_scenario(wildcards))

    def scenario_request(self, rule: str, name: str) -> dict[str, int]:
        """The requests of a job of ``rule`` in scenario ``name``, computed once per scenario
        (the same for every job): ``mem_mb`` (MB) and ``runtime`` (minutes)."""
        key = (rule, name)
        if key not in self._requests:
            cfg = self.scenario(name)
            self._requests[key] = {"mem_mb": mem_mb(rule, cfg), "runtime": runtime_min(rule, cfg)}
        return self._requests[key]

    def memory_requests(self) -> list[tuple[str, int]]:
        """(rule, memory request of one job in MB) of every rule in every scenario checked so far:
        every scenario a job of the run belongs to (a job's inputs check its scenario), for the
        check that no job asks for more than a node has (``preflight.group_problems``)."""
        return [(rule, self.scenario_request(rule, name)["mem_mb"]) for name in list(self._checked) for rule in rule_costs()]

    # ---- targets

    def _for_object(self, name: str, step: str, obj: str) -> bool:
        """Whether scenario ``name`` runs the per-object ``step`` for ``obj`` (``placement_when``)."""
        key = (name, step, obj)
        if key not in self._for:
            self._for[key] = step_for_object(self.scenario(name), step, obj)
        return self._for[key]

    def object_targets(self, obj: str, name: str = DEFAULT_SCENARIO) -> list[str]:
        """One object's outputs in a scenario: every per-object step's (wherever shared)."""
        files: dict[str, None] = {}
        for step, spec in STEPS.items():
            if spec.scope != "object" or spec.optional or not self._for_object(name, step, obj):
                continue
            if len(spec.outputs) == 1:
                files[self.step_file(name, step, obj)] = None
            else:
                root = self.step_root(name, step, obj)
                files.update(dict.fromkeys(f"{root}/objects/{obj}/{rel}" for rel in spec.outputs.values()))
        return list(files)

    def workflow_files(self, step: str) -> list[str]:
        """The files of a step run once for the whole workflow (under results/)."""
        return [f"{RESULTS}/{rel}" for rel in STEPS[step].outputs.values()]

    def scenario_targets(self, name: str = DEFAULT_SCENARIO) -> list[str]:
        """Every output of one scenario's study, each where it is made (Fig. 3, the rule
        graph, is the same for all; the sweep's summary is `sensitivity`'s)."""
        files = [
            self.scenario_file(name, step, rel)
            for step, spec in STEPS.items()
            if spec.scope == "scenario" and not spec.optional
            for rel in spec.outputs.values()
        ]
        files += [
            f for step, spec in STEPS.items() if spec.scope == "workflow" and not spec.optional for f in self.workflow_files(step)
        ]
        return files + [f for obj in self.scenario(name)["objects"] for f in self.object_targets(obj, name)]

    def optional_object_targets(self, step: str, name: str = DEFAULT_SCENARIO) -> list[str]:
        """The outputs of the optional per-object ``step`` for every object of scenario ``name``."""
        return [
            f"{self.step_root(name, step, obj)}/objects/{obj}/{rel}"
            for obj in self.scenario(name)["objects"]
            for rel in STEPS[step].outputs.values()
        ]

    def object_files(self, step: str, output: str) -> Callable[[Any], list[str]]:
        """Input function: every object's file ``output`` (an output name) of the per-object
        ``step`` in the job's scenario."""
        rel = STEPS[step].outputs[output]
        return lambda w: [
            f"{self.step_root(self.job_scenario(w), step, o)}/objects/{o}/{rel}" for o in self.job_config(w)["objects"]
        ]

    def random_objects_manifest(self, wildcards: Any) -> list[str]:
        """Input function: the sha256 manifest of the scenario's random objects (none without them)."""
        spec = self.job_config(wildcards).get("random_objects")
        return [str(self.root / spec["sha256_file"])] if spec else []

    def optional_targets(self, step: str, name: str = DEFAULT_SCENARIO) -> list[str]:
        """The files of the optional per-scenario ``step`` of scenario ``name``."""
        return [self.scenario_file(name, step, rel) for rel in STEPS[step].outputs.values()]

    def searched_targets(self, step: str, target: str, name: str = DEFAULT_SCENARIO) -> list[str]:
        """:meth:`optional_targets` of a ``step`` that reads the placement search's targets;
        where no object of scenario ``name`` is searched, ``target`` (the rule asking) is
        refused before any job (``input_checks.searched_objects_or_refuse``)."""
        searched = [o for o in self.scenario(name)["objects"] if self._for_object(name, "search", o)]
        searched_objects_or_refuse(searched, target, self.scenario(name), self._refuse)
        return self.optional_targets(step, name)

    def placement_label(self, name: str) -> str:
        """How scenario ``name`` places the boxes, for the sweep's summary: the mode; for a
        searched placement the rank and whether the scenario searched again or uses another
        scenario's targets (docs/sensitivity.md)."""
        cfg = self.scenario(name)
        if cfg["placement"]["mode"] != "searched":
            return cfg["placement"]["mode"]
        roots = {self.step_root(name, "search", o) for o in cfg["objects"] if self._for_object(name, "search", o)}
        own = self.scenario_root[name] in roots
        where = "own search" if own else "targets of " + ", ".join(sorted(self._root_scenario[r] for r in roots))
        return f"searched, rank {cfg['placement']['search_rank']} ({where})"
