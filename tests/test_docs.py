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
