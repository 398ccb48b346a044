"""Writing a figure to its PNG and PDF files, identically from run to run."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["PNG_DPI", "save_figure"]

#: Resolution of every PNG figure (dots per inch).
PNG_DPI = 150


def save_figure(fig: Any, png: str | Path, pdf: str | Path, tight: bool = False) -> None:
    """Write ``fig`` as PNG (``PNG_DPI``) and PDF, then close it. The PDF carries no creation
    date, so the same figure gives the same bytes in every run; ``tight`` crops the
    figure to its drawn extent."""
    import matplotlib.pyplot as plt

    bbox = "tight" if tight else None
    fig.savefig(png, dpi=PNG_DPI, bbox_inches=bbox)
    fig.savefig(pdf, bbox_inches=bbox, metadata={"CreationDate": None})
    plt.close(fig)
