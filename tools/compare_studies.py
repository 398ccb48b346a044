"""Whether two finished studies give the same results: what a change to the solver (or any
change meant to keep the science) must leave unchanged.

    .venv/bin/python tools/compare_studies.py REF OTHER [--rtol 1e-6]

REF and OTHER are results folders. Compared: every object's Parquet tables
(`objects/<object>/*.parquet`: gfo, minima, quality, contacts; and its placement.csv) and
every study table (`tables/*.csv`), row by row in file order. Text, integer and boolean columns (statuses,
strict verdicts, set ids, ranks) must be equal; float columns (force norms in N, ...) equal
within `rtol` relative to REF, NaN where REF has NaN. The gfo table's `solver` and
`iterations` say how a problem was decided, not what: they are counted per study, not
compared. Prints one line per file and exits 1 if any file differs or is missing.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

#: Columns of a table that may differ between equal studies (how, not what, was decided).
HOW_DECIDED = {"gfo": ("solver", "iterations")}


def _equal(x, y) -> bool:
    """Exact equality of two cells, NaN equal to NaN (list cells: arrays, element by element)."""
    if isinstance(x, np.ndarray):
        return np.array_equal(x, y, equal_nan=x.dtype.kind == "f")
    return x == y or (x != x and y != y)


def _column_difference(name: str, ref: pd.Series, other: pd.Series, rtol: float) -> str | None:
    """None if the column agrees, else what differs (rows, the largest relative difference)."""
    if pd.api.types.is_float_dtype(ref) and pd.api.types.is_numeric_dtype(other):
        a, b = ref.to_numpy(float), other.to_numpy(float)
        bad = ~np.isclose(b, a, rtol=rtol, atol=0.0, equal_nan=True)
        if not bad.any():
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            worst = np.nanmax(np.abs(b[bad] - a[bad]) / np.abs(a[bad]))
        return f"{name}: {bad.sum()} rows beyond rtol {rtol:g} (largest relative difference {worst:.3g})"
    same = np.array([_equal(x, y) for x, y in zip(ref, other)], dtype=bool)
    return None if same.all() else f"{name}: {(~same).sum()} rows differ (first at row {np.argmin(same)})"


def frame_differences(ref: pd.DataFrame, other: pd.DataFrame, rtol: float, ignore: tuple[str, ...] = ()) -> list[str]:
    """What differs between two tables of the same kind, row by row (empty list: equal)."""
    if list(ref.columns) != list(other.columns):
        return [f"columns differ: {list(ref.columns)} vs {list(other.columns)}"]
    if len(ref) != len(other):
        return [f"rows differ: {len(ref)} vs {len(other)}"]
    out = [
        _column_difference(c, ref[c].reset_index(drop=True), other[c].reset_index(drop=True), rtol)
        for c in ref.columns
        if c not in ignore
    ]
    return [d for d in out if d]


def _read(path: Path) -> pd.DataFrame:
    return pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)


def compare(ref_root: Path, other_root: Path, rtol: float) -> dict[str, tuple[int, list[str]]]:
    """Per file of REF (path relative to the roots): its rows and what differs in OTHER."""
    files = [f for pattern in ("objects/*/*.parquet", "objects/*/*.csv", "tables/*.csv") for f in sorted(ref_root.glob(pattern))]
    result = {}
    for path in files:
        rel, ref = path.relative_to(ref_root), _read(path)
        diffs = (
            frame_differences(ref, _read(other_root / rel), rtol, HOW_DECIDED.get(path.stem, ()))
            if (other_root / rel).exists()
            else ["missing"]
        )
        result[str(rel)] = (len(ref), diffs)
    return result


def _solver_counts(root: Path) -> str:
    solver = pd.concat([pd.read_parquet(f, columns=["solver"])["solver"] for f in sorted(root.glob("objects/*/gfo.parquet"))])
    return ", ".join(f"{k} {v}" for k, v in solver.value_counts().sort_index().items())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ref", type=Path)
    ap.add_argument("other", type=Path)
    ap.add_argument("--rtol", type=float, default=1e-6, help="relative tolerance of float columns")
    args = ap.parse_args()
    result = compare(args.ref, args.other, args.rtol)
    if not result:
        sys.exit(f"no tables under {args.ref}/objects or {args.ref}/tables")
    for rel, (rows, diffs) in result.items():
        print(f"{rel} ({rows} rows): {'equal' if not diffs else 'DIFFERS: ' + '; '.join(diffs)}")
    for root in (args.ref, args.other):
        print(f"{root}: gfo rows by solver: {_solver_counts(root)}")
    differ = sum(bool(d) for _, d in result.values())
    print(f"{len(result) - differ} of {len(result)} files equal (rtol {args.rtol:g})")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
