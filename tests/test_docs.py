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
    synergrasp.tables (rerun the tool after changing a contract)."""
    design = _tool("design_schemas")
    text = (ROOT / "docs" / "design.md").read_text()
    assert design.rewritten(text) == text
    assert "| `force_norm` | float64 | N |" in text and "| `set_id` | string |" in text


def test_every_doc_the_docs_cite_exists():
    """A path docs/<name>.md named anywhere in the documentation, the config or the code is there."""
    import re

    cited = set()
    for path in [*ROOT.glob("*.md"), *(ROOT / "docs").glob("*.md"), *(ROOT / "config").glob("*"),
                 *(ROOT / "src").rglob("*.py"), *(ROOT / "workflow").rglob("*")]:
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
    anchors = {re.sub(r"[^a-z0-9 -]", "", title.lower()).replace(" ", "-")
               for title in re.findall(r"^## (.+)$", page, flags=re.M)}
    linked = {anchor for path in [*ROOT.glob("*.md"), *(ROOT / "docs").glob("*.md")]
              for anchor in re.findall(r"measurements\.md#([a-z0-9-]+)", path.read_text())}
    assert "closure" in anchors and not linked - anchors


def test_every_module_of_the_package_is_in_design_md():
    """docs/design.md's module table names every module of src/synergrasp (a new module is
    described where a contributor looks for it)."""
    text = (ROOT / "docs" / "design.md").read_text()
    package = ROOT / "src" / "synergrasp"
    modules = ["/".join(p.relative_to(package).with_suffix("").parts) for p in sorted(package.rglob("*.py"))
               if p.name != "__init__.py"]
    missing = [m for m in modules if f"| `{m}` |" not in text]
    assert len(modules) > 50 and missing == []


#: A number with a short unit of time (µs, ms) or a long one (min, h): always a cost here.
_COST_TIME = r"[0-9](?:[.,][0-9]+)?\s?(?:µs|us|ms|min|minutes?|h|hours?|CPU ?(?:s|seconds?))\b"
#: A number of seconds: a cost when words of _COST_WORDS are near it, else a model parameter.
_SECONDS = r"[0-9](?:[.,][0-9]+)?\s?(?:s|sec|seconds?)\b"
#: A rate of work (solves per second, pairs per CPU s, 3× faster): a cost whatever its unit.
_RATE = (r"[0-9][0-9,.]*(?:\s?[→–-]\s?[0-9][0-9,.]*)?\s+(?:\S+\s+){0,3}?(?:per (?:CPU )?s(?:econd)?\b|solves/s\b)"
         r"|[0-9] ?(?:×|x) (?:faster|slower|cheaper|dearer)\b")
#: Words that make seconds a cost (what the software spends), not a parameter.
_COST_WORDS = (r"\bCPU\b|\bwall\b|per (?:grasp|job|pose|problem|posture|target|shard)\b|\btook\b"
               r"|\bcosts?\b|\bruns? in\b|\bfaster\b|\bslower\b|\bspeed-?ups?\b|\bbenchmark|\bprofil|\bload average\b"
               r"|\bcores?\b|\bimports?\b|\bjobs?\b")
#: A commit hash: 7-40 hex digits with at least one letter and one digit, as a word.
_COMMIT = r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b"


def _markdown_pages():
    pages = [ROOT / "README.md", ROOT / "config" / "README.md", *(ROOT / "docs").glob("*.md"),
             *(ROOT / "docs" / "figures").glob("*.md"), *(ROOT / "config" / "examples").rglob("README.md"),
             *(ROOT / "src" / "synergrasp" / "data").rglob("README.md")]
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
        context = " ".join(lines[max(number - 2, 0):number + 1]) + (header if line.startswith("|") else "")
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
            if (re.search(_COST_TIME, line) or re.search(_RATE, line)
                    or re.search(_SECONDS, line) and re.search(_COST_WORDS, words, flags=re.I)):
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
