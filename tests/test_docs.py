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
