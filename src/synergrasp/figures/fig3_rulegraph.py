"""Fig. 3: the workflow's own rule graph, from Snakemake's ``--rulegraph`` DOT text.

Its own module so that its job imports matplotlib alone (no pandas, no analysis): the
drawing takes a fraction of a second.
"""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: figures are files, never windows
import matplotlib.pyplot as plt  # noqa: E402

from synergrasp.figures.output import save_figure  # noqa: E402

__all__ = ["parse_rulegraph", "canonical_rulegraph", "figure_rulegraph"]

_NODE = re.compile(r'^\s*(\d+)\s*\[.*?label\s*=\s*"([^"]+)"')
_EDGE = re.compile(r"^\s*(\d+)\s*->\s*(\d+)")


def parse_rulegraph(dot: str) -> tuple[dict[int, str], list[tuple[int, int]]]:
    """Nodes (id → rule name) and edges (from, to) of Snakemake's ``--rulegraph`` DOT text."""
    nodes: dict[int, str] = {}
    edges: list[tuple[int, int]] = []
    for line in dot.splitlines():
        if (match := _EDGE.match(line)) is not None:
            edges.append((int(match.group(1)), int(match.group(2))))
        elif (match := _NODE.match(line)) is not None:
            nodes[int(match.group(1))] = match.group(2)
    return nodes, edges


def canonical_rulegraph(dot: str) -> str:
    """Snakemake's ``--rulegraph`` DOT text in one fixed order: nodes numbered by rule name,
    edges sorted, header and node attributes kept. Snakemake's own numbering and edge order
    depend on set iteration, which varies from run to run."""
    nodes, edges = parse_rulegraph(dot)
    new_id = {old: new for new, old in enumerate(sorted(nodes, key=lambda n: nodes[n]))}
    header: list[str] = []
    node_lines: dict[int, str] = {}
    for line in dot.splitlines():
        if _EDGE.match(line) is not None or line.strip() == "}":
            continue
        if (match := _NODE.match(line)) is not None:
            old = int(match.group(1))
            node_lines[new_id[old]] = line[: match.start(1)] + str(new_id[old]) + line[match.end(1) :]
        else:
            header.append(line)
    indent = "\t"
    body = [node_lines[n] for n in sorted(node_lines)]
    body += [f"{indent}{a} -> {b}" for a, b in sorted({(new_id[a], new_id[b]) for a, b in edges})]
    return "\n".join(header + body + ["}"]) + "\n"


def figure_rulegraph(dot: str, png: str | Path, pdf: str | Path) -> None:
    """Fig. 3: the workflow's rule graph (the block scheme of the procedure), drawn in
    layers: a rule sits one layer below the deepest rule it consumes."""
    nodes, edges = parse_rulegraph(dot)
    parents: dict[int, list[int]] = {n: [] for n in nodes}
    for src, dst in edges:
        parents[dst].append(src)
    layer: dict[int, int] = {}

    def depth(n: int) -> int:
        if n not in layer:
            layer[n] = 1 + max((depth(p) for p in parents[n]), default=-1)
        return layer[n]

    for n in nodes:
        depth(n)
    n_layers = max(layer.values(), default=0) + 1
    by_layer = [sorted((n for n in nodes if layer[n] == d), key=lambda n: nodes[n]) for d in range(n_layers)]
    width = max((len(ns) for ns in by_layer), default=1)
    pos = {n: ((i + 0.5) / len(ns) * width, -d) for d, ns in enumerate(by_layer) for i, n in enumerate(ns)}
    fig, ax = plt.subplots(figsize=(max(6.0, 2.3 * width), 1.1 * n_layers + 0.5))
    for src, dst in edges:
        (x0, y0), (x1, y1) = pos[src], pos[dst]
        ax.annotate("", xy=(x1, y1 + 0.18), xytext=(x0, y0 - 0.18), arrowprops={"arrowstyle": "->", "color": "0.4", "lw": 0.8})
    for n, (x, y) in pos.items():
        ax.text(
            x,
            y,
            nodes[n],
            ha="center",
            va="center",
            fontsize=8,
            bbox={"boxstyle": "round,pad=0.3", "fc": "#e8eef7", "ec": "#4a6fa5"},
        )
    ax.set_xlim(-0.2, width + 0.2)
    ax.set_ylim(-n_layers + 0.4, 0.6)
    ax.axis("off")
    save_figure(fig, png, pdf, tight=True)
