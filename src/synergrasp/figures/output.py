"""Writing figures to files with the same bytes on every run, and what every figure shares:
the colour of each verdict of the study's claims."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from synergrasp.analysis.claims import FAILS, HOLDS, UNDEFINED
from synergrasp.file_output import replacing

__all__ = ["save_figure", "colour_range", "VERDICT_COLOURS"]

#: Fill colour of each verdict of a claim (``claims.CLAIM_VERDICTS``), in every figure.
VERDICT_COLOURS = {HOLDS: "#9fd89f", FAILS: "#f19c9c", UNDEFINED: "#f3e08a"}

#: Metadata that would change between runs (dates) or versions (software) are left out.
_PNG_METADATA = {"Software": None}
_PDF_METADATA = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}


def save_figure(fig: Any, png_path: str | Path, pdf_path: str | Path | None, dpi: int = 150, tight: bool = False) -> None:
    """Write a matplotlib figure as PNG (``dpi``) and PDF (none if ``pdf_path`` is None)
    without dates or software versions in their metadata, so that a rerun writes the same
    bytes; then close it."""
    import matplotlib.pyplot as plt

    extra = {"bbox_inches": "tight"} if tight else {}
    with replacing(png_path) as partial:
        fig.savefig(partial, dpi=dpi, metadata=_PNG_METADATA, **extra)
    if pdf_path is not None:
        with replacing(pdf_path) as partial:
            fig.savefig(partial, metadata=_PDF_METADATA, **extra)
    plt.close(fig)


#: A map whose values differ by less than this (relatively) is drawn as constant.
CONSTANT_RTOL = 1e-6


def colour_range(values: Any) -> tuple[float, float]:
    """The colour limits of a map: the 1st and 99th percentiles of its finite values ((0, 1)
    if none). A map constant to round-off (a sphere's grasp is the same at every pose, its
    numbers to ~1e-12) gets a range centred on its value, so that it is one colour and not
    its round-off drawn as a pattern."""
    import numpy as np

    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if not finite.size:
        return 0.0, 1.0
    lo, hi = (float(v) for v in np.percentile(finite, [1, 99]))
    if hi - lo <= CONSTANT_RTOL * max(abs(lo), abs(hi), 1e-12):
        mid = 0.5 * (lo + hi)
        lo, hi = mid - 0.5 * max(abs(mid), 1e-3), mid + 0.5 * max(abs(mid), 1e-3)
    return lo, hi
