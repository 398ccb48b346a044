"""Writing figures to files with the same bytes on every run."""

from __future__ import annotations

from pathlib import Path
from typing import Any

__all__ = ["save_figure"]

#: Metadata that would change between runs (dates) or versions (software) are left out.
_PNG_METADATA = {"Software": None}
_PDF_METADATA = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}


def save_figure(fig: Any, png_path: str | Path, pdf_path: str | Path | None, dpi: int = 150,
                tight: bool = False) -> None:
    """Write a matplotlib figure as PNG (``dpi``) and PDF (none if ``pdf_path`` is None)
    without dates or software versions in their metadata, so that a rerun writes the same
    bytes; then close it."""
    import matplotlib.pyplot as plt

    extra = {"bbox_inches": "tight"} if tight else {}
    fig.savefig(png_path, dpi=dpi, metadata=_PNG_METADATA, **extra)
    if pdf_path is not None:
        fig.savefig(pdf_path, metadata=_PDF_METADATA, **extra)
    plt.close(fig)
