"""Write the Parquet schemas of docs/design.md from the table contracts (synergrasp.table_contracts).

    .venv/bin/python tools/design_schemas.py        rewrite the section in docs/design.md

The section lies between the two marker lines below; tests/test_docs.py checks that it is
what this writes, so a contract and its documentation cannot drift apart.
"""

from __future__ import annotations

import sys
from pathlib import Path

from synergrasp.steps import STEPS
from synergrasp.table_contracts import BLOCKERS, CONTACTS, GFO, MINIMA, PLACEMENT, QUALITY, TARGET_CLAIMS, Table

DESIGN = Path(__file__).resolve().parents[1] / "docs" / "design.md"
BEGIN = "<!-- schemas: written by tools/design_schemas.py from src/synergrasp/table_contracts.py; do not edit -->"
END = "<!-- end of schemas -->"


def _object_file(step: str, output: str) -> str:
    """A per-object step's output under a scenario's root (the registry's path)."""
    return f"objects/<object>/{STEPS[step].outputs[output]}"


#: Each table between steps (Parquet; the placement search's CSV) and the files that hold it,
#: under a scenario's root: (table, step, output name).
FILES: tuple[tuple[Table, str], ...] = tuple(
    (table, _object_file(step, output))
    for table, step, output in (
        (CONTACTS, "simulate", "contacts"),
        (GFO, "optimise", "gfo"),
        (MINIMA, "minima", "minima"),
        (QUALITY, "quality", "table"),
        (BLOCKERS, "blockers", "blockers"),
        (PLACEMENT, "search", "placement"),
        (TARGET_CLAIMS, "target_claims", "claims"),
    )
)


def schema(table: Table) -> str:
    """One contract as a Markdown table: column, Arrow type, unit, meaning."""
    lines = ["| column | type | unit | meaning |", "|---|---|---|---|"]
    lines += [f"| `{c.name}` | {c.dtype} | {c.unit or '–'} | {c.meaning} |" for c in table.columns]
    return "\n".join(lines)


def section() -> str:
    """The generated section, markers included."""
    parts = [BEGIN]
    for table, path in FILES:
        parts += ["", f"### `results/{path}` — {table.rows}", "", schema(table)]
    return "\n".join(parts + ["", END])


def rewritten(text: str) -> str:
    """``text`` (docs/design.md) with its schema section replaced by :func:`section`."""
    start, end = text.index(BEGIN), text.index(END) + len(END)
    return text[:start] + section() + text[end:]


if __name__ == "__main__":
    DESIGN.write_text(rewritten(DESIGN.read_text()))
    print(f"wrote the schemas of {DESIGN}", file=sys.stderr)
