"""The documentation generated from the code agrees with it."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _tool(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_design_md_schemas_are_the_table_contracts():
    """docs/design.md's Parquet schemas are what tools/design_schemas.py writes from
    synergrasp.table_contracts (rerun the tool after changing a contract)."""
    design = _tool("design_schemas")
    text = (ROOT / "docs" / "design.md").read_text()
    assert design.rewritten(text) == text
    assert "| `force_norm` | float64 | N |" in text and "| `set_id` | string |" in text


def test_every_doc_the_docs_cite_exists():
    """A path docs/<name>.md named anywhere in the documentation, the config or the code is there."""
    import re

    cited = set()
    for path in [
        *ROOT.glob("*.md"),
        *(ROOT / "docs").glob("*.md"),
        *(ROOT / "config").glob("*"),
        *(ROOT / "src").rglob("*.py"),
        *(ROOT / "workflow").rglob("*"),
    ]:
        if path.is_file():
            cited |= set(re.findall(r"docs/([a-z_]+\.md)", path.read_text(errors="ignore")))
    assert cited and not [name for name in cited if not (ROOT / "docs" / name).is_file()]


def test_measurements_page_is_what_the_tool_writes_from_the_committed_files():
    """docs/measurements.md is tools/measurements.py's page of benchmarks/results/ (rerun the tool,
    or `make bench`, after changing a file there), and every section of it the documentation
    links to is on it."""
    import re

    page = (ROOT / "docs" / "measurements.md").read_text()
    assert _tool("measurements").page() == page
    anchors = {
        re.sub(r"[^a-z0-9 -]", "", title.lower()).replace(" ", "-") for title in re.findall(r"^## (.+)$", page, flags=re.M)
    }
    linked = {
        anchor
        for path in [*ROOT.glob("*.md"), *(ROOT / "docs").glob("*.md")]
        for anchor in re.findall(r"measurements\.md#([a-z0-9-]+)", path.read_text())
    }
    assert "closure" in anchors and not linked - anchors


def test_every_module_of_the_package_is_in_design_md():
    """docs/design.md's module table names every module of src/synergrasp (a new module is
    described where a contributor looks for it)."""
    text = (ROOT / "docs" / "design.md").read_text()
    package = ROOT / "src" / "synergrasp"
    modules = [
        "/".join(p.relative_to(package).with_suffix("").parts) for p in sorted(package.rglob("*.py")) if p.name != "__init__.py"
    ]
    missing = [m for m in modules if f"| `{m}` |" not in text]
    assert len(modules) > 50 and missing == []


#: A number with a short unit of time (µs, ms) or a long one (min, h): always a cost here.
_COST_TIME = r"[0-9](?:[.,][0-9]+)?\s?(?:µs|us|ms|min|minutes?|h|hours?|CPU ?(?:s|seconds?))\b"
#: A number of seconds: a cost when words of _COST_WORDS are near it, else a model parameter.
_SECONDS = r"[0-9](?:[.,][0-9]+)?\s?(?:s|sec|seconds?)\b"
#: A rate of work (solves per second, pairs per CPU s, 3× faster): a cost whatever its unit.
_RATE = (
    r"[0-9][0-9,.]*(?:\s?[→–-]\s?[0-9][0-9,.]*)?\s+(?:\S+\s+){0,3}?(?:per (?:CPU )?s(?:econd)?\b|solves/s\b)"
    r"|[0-9] ?(?:×|x) (?:faster|slower|cheaper|dearer)\b"
)
#: Words that make seconds a cost (what the software spends), not a parameter.
_COST_WORDS = (
    r"\bCPU\b|\bwall\b|per (?:grasp|job|pose|problem|posture|target|shard)\b|\btook\b"
    r"|\bcosts?\b|\bruns? in\b|\bfaster\b|\bslower\b|\bspeed-?ups?\b|\bbenchmark|\bprofil|\bload average\b"
    r"|\bcores?\b|\bimports?\b|\bjobs?\b"
)
#: A commit hash: 7-40 hex digits with at least one letter and one digit, as a word.
_COMMIT = r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b"


def _markdown_pages():
    pages = [
        ROOT / "README.md",
        ROOT / "config" / "README.md",
        *(ROOT / "docs").glob("*.md"),
        *(ROOT / "docs" / "figures").glob("*.md"),
        *(ROOT / "config" / "examples").rglob("README.md"),
        *(ROOT / "src" / "synergrasp" / "data").rglob("README.md"),
    ]
    return sorted(p for p in pages if p.name != "measurements.md" or p.parent.name != "docs")


def _sections(path):
    """(section heading, line number, line, context) of every line of ``path``: a heading is a `## `
    line; the context is the line with the one before and after it, and a table row's header."""
    lines = path.read_text().splitlines()
    section, header = None, ""
    for number, line in enumerate(lines, 1):
        if line.startswith("## "):
            section = line.strip()
        if line.startswith("|") and not (number > 1 and lines[number - 2].startswith("|")):
            header = line
        context = " ".join(lines[max(number - 2, 0) : number + 1]) + (header if line.startswith("|") else "")
        yield section, number, line, context


def test_docs_state_no_cost_and_no_commit():
    """The docs describe the software; docs/measurements.md records what it cost and when.

    Outside docs/measurements.md (README.md, config/README.md, docs/*.md, docs/figures/*.md,
    config/examples/**/README.md, src/synergrasp/data/**/README.md) no line states
    - a **cost**: a number of µs, ms, minutes, hours or CPU seconds (no parameter of the model
      is stated in those units); a rate of work (a number at most three words before "per second", "per CPU s"
      or "solves/s"; "3× faster"); or a number of seconds when that line, the line before or after it, or (in a
      table) the table's header says CPU, wall, per grasp/job/pose/problem/posture/target/
      shard, took, cost(s), runs in, faster, slower, speed-up, benchmark, profile, load average,
      core(s), import(s) or job(s) (file paths left out: a pointer to benchmarks/results/ is no
      cost). Seconds without such a word near them are a
      parameter of the model (a time step of 1/240 s, a ramp of 0.3 s, a settle window) and
      pass. A cost is written as a pointer to the measurements page and its file in
      benchmarks/results/ instead;
    - a **commit hash**: 7-40 hex digits with at least one letter and one digit, as a word,
      except in docs/placement_search.md's "## Changes since pre-registration" section (the
      pre-registration commits). Describe the state of the software instead ("before the
      closure was compiled")."""
    import re

    found = []
    for path in _markdown_pages():
        name = path.relative_to(ROOT).as_posix()
        for section, number, line, context in _sections(path):
            words = re.sub(r"\S*/\S*", "", context)
            if (
                re.search(_COST_TIME, line)
                or re.search(_RATE, line)
                or re.search(_SECONDS, line)
                and re.search(_COST_WORDS, words, flags=re.I)
            ):
                found.append(f"{name}:{number}: cost: {line.strip()}")
            changelog = name == "docs/placement_search.md" and section == "## Changes since pre-registration"
            if re.search(_COMMIT, line) and not changelog:
                found.append(f"{name}:{number}: commit: {line.strip()}")
    assert found == [], "\n".join(found)


def test_readme_lists_every_page_of_docs():
    """The README's "## Documentation" section names every page of docs/ (a new page is found
    where a reader looks first), and links docs/method.md, the method in equations."""
    import re

    readme = (ROOT / "README.md").read_text()
    section = readme.split("\n## Documentation\n", 1)[1].split("\n## ", 1)[0]
    pages = sorted(p.name for p in (ROOT / "docs").glob("*.md"))
    missing = [name for name in pages if f"docs/{name}" not in section]
    assert len(pages) > 15 and missing == []
    assert re.search(r"\]\(docs/method\.md\)", readme)


# --------------------------------------------------------------------------- names the docs cite

#: Names the docs cite that belong to other packages (a module or object of theirs first).
_OTHER_PACKAGES = {
    "np",
    "numpy",
    "pd",
    "pandas",
    "scipy",
    "pybullet",
    "mujoco",
    "plotly",
    "time",
    "os",
    "snakemake",
    "matplotlib",
    "numba",
    "cvxpy",
    "clarabel",
    "piqp",
    "json",
    "yaml",
    "re",
    "math",
    "shutil",
    "threading",
    "importlib",
    "subprocess",
    "pytest",
    "sys",
    "pathlib",
    "warnings",
    "jsonschema",
}
#: Variables the docs name the members of (an object, not a module): `hand.point_jacobian` is a
#: method of a `Hand` called ``hand``, `params.cone` a field of a problem's parameters.
#: `W.step_input` a method of the `Wiring` common.smk calls ``W``; `palm.shapes` a hand file's field;
#: `ipm_solver` the name gfo.py imports ``ipm.solver`` as.
_OBJECTS = {
    "hand",
    "params",
    "problem",
    "problems",
    "self",
    "out",
    "snakemake",
    "spec",
    "cfg",
    "config",
    "grasp",
    "rule",
    "job",
    "workflow",
    "wildcards",
    "W",
    "palm",
    "fingers",
    "cp",
    "table",
    "settings",
    "result",
    "GROUP",
    "ipm_solver",
}
_FILE_SUFFIXES = (".py", ".smk")
#: Other files the docs name (outputs, data, pages): not checked.
_DATA_SUFFIXES = {
    "md",
    "yaml",
    "csv",
    "toml",
    "lock",
    "html",
    "png",
    "pdf",
    "parquet",
    "js",
    "json",
    "rst",
    "txt",
    "tsv",
    "zip",
    "dot",
    "sh",
    "obj",
    "stl",
    "urdf",
    "xml",
    "svg",
    "log",
    "cfg",
    "dae",
}


def _doc_texts():
    pages = [*_markdown_pages(), *(ROOT / "workflow" / "report").glob("*.rst")]
    return {p.relative_to(ROOT).as_posix(): p.read_text() for p in pages}


def _schema_paths() -> set[tuple[str, ...]]:
    """Every key path of the configuration schema (``placement.search.distinct_mm``), through
    its `$defs`."""
    import yaml

    schema = yaml.safe_load((ROOT / "src" / "synergrasp" / "data" / "config.schema.yaml").read_text())
    paths: set[tuple[str, ...]] = set()

    def walk(node, prefix, depth=0):
        if not isinstance(node, dict) or depth > 12:
            return
        if "$ref" in node:
            walk(schema["$defs"][node["$ref"].rsplit("/", 1)[1]], prefix, depth + 1)
        for key in ("properties", "patternProperties"):
            for name, sub in (node.get(key) or {}).items():
                here = prefix + ((name,) if key == "properties" else ())
                paths.add(here)
                walk(sub, here, depth + 1)
        for key in ("items", "additionalProperties"):
            walk(node.get(key), prefix, depth + 1)
        for key in ("oneOf", "anyOf", "allOf"):
            for sub in node.get(key) or ():
                walk(sub, prefix, depth + 1)

    walk(schema, ())
    return paths


def _modules() -> dict[tuple[str, ...], Path]:
    """The package's modules and packages by dotted parts (``("optimisation", "optimise")``)."""
    package = ROOT / "src" / "synergrasp"
    found = {}
    for path in package.rglob("*.py"):
        parts = path.relative_to(package).with_suffix("").parts
        found[parts[:-1] if parts[-1] == "__init__" else parts] = path
    return found


def _defines(path: Path, name: str) -> bool:
    """Whether module ``path`` defines ``name`` (a function, class, constant or import), or
    is a package holding a module ``name``."""
    import re

    if path.name == "__init__.py" and ((path.parent / f"{name}.py").is_file() or (path.parent / name).is_dir()):
        return True
    pattern = (
        rf"^\s*(?:def|class)\s+{name}\b|^\s*{name}\s*[:=]|^\s*from\s+\S+\s+import\s+[^(\n]*\b{name}\b"
        rf"|^\s+{name},?\s*(?:#.*)?$|\b{name}\s*=\s*|namedtuple\([^)]*\b{name}\b"
    )  # an import block's line
    return re.search(pattern, path.read_text(), flags=re.M) is not None


def stale_names(text: str, modules: dict[tuple[str, ...], Path], schema: set[tuple[str, ...]], files: set[str]) -> list[str]:
    """The backticked names in ``text`` that name nothing of the code: a ``.py`` or ``.smk`` file
    no folder of the checkout holds; a dotted name (``optimise.optimise_grasps``,
    ``synergrasp.wiring.Wiring``, ``Wiring.step_file``) whose leading parts are no module of
    the package (by its full or any shorter trailing dotted path) or whose first member that
    module does not define. Configuration keys (a trailing part of a schema path), other
    packages' names and an object's members (`_OBJECTS`) are left out."""
    import re

    stale = []
    for token in re.findall(r"`([A-Za-z_][\w.]*?)(?:\(\))?`", text):
        if token.endswith(_FILE_SUFFIXES):
            if token.rsplit("/", 1)[-1] not in files:
                stale.append(token)
            continue
        parts = tuple(token.split("."))
        if len(parts) < 2 or "" in parts or parts[-1] in _DATA_SUFFIXES:
            continue
        if parts[0] == "synergrasp":
            parts = parts[1:]
        elif parts[0] in _OTHER_PACKAGES | _OBJECTS:
            continue
        if any(parts == path[-len(parts) :] for path in schema if len(path) >= len(parts)):
            continue  # a configuration key
        if parts[0][:1].isupper():  # Class.member: the class is defined once, the member in it
            owners = [p for p in modules.values() if re.search(rf"^(?:class {parts[0]}\b|{parts[0]} = )", p.read_text(), re.M)]
            if not owners or not any(_defines(p, parts[1]) for p in owners):
                stale.append(token)
            continue
        for k in range(len(parts), 0, -1):  # the longest leading parts that are a module
            owners = [path for key, path in modules.items() if key[-k:] == parts[:k]]
            if owners:
                if k < len(parts) and not any(_defines(p, parts[k]) for p in owners):
                    stale.append(token)
                break
        else:
            stale.append(token)
    return stale


def _file_names() -> set[str]:
    names = {p.name for folder in ("src", "workflow", "tests", "tools", "benchmarks") for p in (ROOT / folder).rglob("*")}
    return names | {"Snakefile"}


def test_every_module_file_and_name_the_docs_cite_exists():
    """Every backticked module name, short (`optimise.optimise_grasps`, `gfo.solve_gfo`) or
    full (`synergrasp.wiring.Wiring`), every class member (`Wiring.step_file`) and every
    ``.py``/``.smk`` file name the documentation cites exists in the code: a rename that
    leaves a page behind fails here."""
    modules, schema, files = _modules(), _schema_paths(), _file_names()
    found = {name: stale for name, text in _doc_texts().items() if (stale := stale_names(text, modules, schema, files))}
    assert found == {}


def test_every_module_file_and_name_the_code_cites_exists():
    """Likewise in the code's docstrings and comments (``name``), the rules, the Snakefile and
    the profiles."""
    modules, schema, files = _modules(), _schema_paths(), _file_names()
    sources = [ROOT / "Snakefile", *(ROOT / "workflow").rglob("*.smk"), *(ROOT / "profiles").rglob("*.yaml")]
    for folder in ("src", "benchmarks", "tools", "workflow"):
        sources += (ROOT / folder).rglob("*.py")
    found = {
        p.relative_to(ROOT).as_posix(): stale
        for p in sorted(sources)
        if (stale := stale_names(p.read_text().replace("``", "`"), modules, schema, files))
    }
    assert len(sources) > 100 and found == {}


def test_a_planted_stale_name_is_found():
    modules, schema, files = _modules(), _schema_paths(), _file_names()
    planted = (
        "the step (`study.py`) runs `study.optimise_grasps`; rules in `resources.smk`; "
        "`optimise.optimise_grasps`, `gfo.solve_gfo`, `Wiring.step_file`, `placement.search.distinct_mm`, "
        "`synergrasp.wiring.code_files`, `np.linalg.svd` and `hand.point_jacobian` exist; "
        "`gfo.solve_everything`, `Wiring.no_such_member` and `synergrasp.studies` do not"
    )
    assert stale_names(planted, modules, schema, files) == [
        "study.py",
        "study.optimise_grasps",
        "resources.smk",
        "gfo.solve_everything",
        "Wiring.no_such_member",
        "synergrasp.studies",
    ]


def test_the_old_names_of_renamed_modules_are_stale():
    """The names renamed for one meaning each (docs/design.md, "Names") fail the check where a
    page still cites them, and the new names pass."""
    modules, schema, files = _modules(), _schema_paths(), _file_names()
    old = [
        "`synergrasp.tables.read`",  # old name
        "`tables.CONTACTS`",  # old name
        "`study_checks.checked_scenario`",  # old name
        "`hand_figures.draw_grasp`",  # old name
        "`study_figures.figure_hierarchy`",  # old name
        "`study_figures.py`",  # old name
        "`closure_steps.march`",  # old name
        "`Wiring.study_input`",  # old name
    ]
    new = [
        "`synergrasp.table_contracts.read`",
        "`table_contracts.CONTACTS`",
        "`input_checks.checked_scenario`",
        "`fig1_fig2_postures_grasps.draw_grasp`",
        "`fig4_fig5_forces_hierarchy.figure_hierarchy`",
        "`fig4_fig5_forces_hierarchy.py`",
        "`closure_march.march`",
        "`Wiring.scenario_input`",
    ]
    assert [stale_names(name, modules, schema, files) for name in old] == [[name.strip("`")] for name in old]
    assert stale_names(" ".join(new), modules, schema, files) == []


def _status_values() -> set[str]:
    """Every status and reason value the code writes: the solvers' (`problem.SOLVER_STATUSES`), the
    gfo table's unsolved ones, the closure's and the blockers' reasons."""
    from synergrasp.optimisation.blocking import REASONS
    from synergrasp.optimisation.optimise import UNSOLVED_STATUSES
    from synergrasp.optimisation.problem import SOLVER_STATUSES
    from synergrasp.simulation.contacts import CLOSURE_STATUSES

    return {*SOLVER_STATUSES, *UNSOLVED_STATUSES, *CLOSURE_STATUSES, *REASONS}


def stale_statuses(text: str, known: set[str]) -> list[str]:
    """The backticked values a text gives as a status ("statuses to `a`, `b` or `c`", "status
    `grasp`") that no status of the code is."""
    import re

    flat = re.sub(r"\s+", " ", text)
    found = []
    for listed in re.findall(r"\bstatus(?:es)?\b(?: (?:to|is|are|of|as|becomes))?:? ((?:`\w+`(?:, | or | and )?)+)", flat):
        found += [value for value in re.findall(r"`(\w+)`", listed) if value not in known]
    return found


def test_every_status_the_docs_give_is_one_the_code_writes():
    known = _status_values()
    assert stale_statuses("mapping its statuses to `force_closure`, `infeasible` or `numerical_failure`", known) == [
        "force_closure"
    ]
    found = {name: stale for name, text in _doc_texts().items() if (stale := stale_statuses(text, known))}
    assert found == {}
