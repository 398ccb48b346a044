"""The real study's optimisation rate and fallback share, from a finished run's files.

Reads the optimisation jobs' benchmark files (`<root>/benchmarks/optimise_shard/*.tsv`, column
cpu_time: CPU seconds of each job, imports and I/O included) and the gfo tables
(`<root>/objects/*/gfo.parquet`), and prints (pose, set) rows per CPU second, over all rows
and over the rows that reached the solver (solver not 'none'), how many of them were solved
(poses whose grasps are one share one solve: `mechanics.first_same_grasp` on the contacts
tables), and the share of rows the Clarabel fallback decided. Nothing is run: it describes the last `make study` (or any root
given), so run that first. The last two lines are machine-read.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from synergrasp import table_contracts
from synergrasp.optimisation.mechanics import first_same_grasp, read_grasps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--root", type=Path, default=Path("results"), help="results directory of a finished study")
    args = ap.parse_args()
    bench = sorted((args.root / "benchmarks" / "optimise_shard").glob("*.tsv"))
    gfo_files = sorted((args.root / "objects").glob("*/gfo.parquet"))
    if not bench or not gfo_files:
        raise SystemExit(f"no optimisation benchmark files or gfo tables under {args.root}: run `make study` first")
    cpu = sum(float(pd.read_csv(f, sep="\t")["cpu_time"].iloc[-1]) for f in bench)
    solver = pd.concat([table_contracts.read(table_contracts.GFO, f)["solver"] for f in gfo_files], ignore_index=True)
    n, solved = len(solver), int((solver != "none").sum())
    fallback = int((solver == "clarabel_fallback").sum())
    own = [_solved_here(f) for f in gfo_files]
    distinct, own_solved = sum(d for d, _ in own), sum(r for _, r in own)
    print(f"{args.root}: {len(gfo_files)} objects, {len(bench)} optimisation jobs, {cpu:.2f} CPU s of jobs")
    print(
        f"(pose, set) rows: {n} ({solved} decided by a solver, {n - solved} without a solve); "
        f"{n / cpu:.0f} rows per CPU s, {solved / cpu:.0f} solver-decided rows per CPU s"
    )
    print(
        f"grasps solved once for all their poses: {distinct} distinct grasps; {own_solved} (pose, set) problems "
        f"solved, {own_solved / cpu:.0f} per CPU s"
    )
    print(f"fallback: {fallback} rows, {fallback / n:.4f} of all rows, {fallback / max(solved, 1):.4f} of the solved")
    print(
        f"study_problems_per_cpu_s: {n / cpu:.0f}  (the last study's optimisation jobs, (pose, set) rows per CPU "
        f"second, imports and I/O included)"
    )
    print(f"study_fallback_share: {fallback / n:.4f}  (share of the last study's rows the Clarabel fallback decided)")


def _solved_here(gfo_file: Path) -> tuple[int, int]:
    """Of one object: its distinct grasps (poses whose grasp is the first of its kind, solved
    rather than shared) and their rows decided by a solver. Reads the contacts the optimisation
    read when they are in the object's folder: the load-carrying selection if the run made one,
    else the closure's table; (0, 0) if neither is there (a step shared from another root)."""
    folder = gfo_file.parent
    found = [f for f in (folder / "load_carrying_contacts.parquet", folder / "contacts.parquet") if f.exists()]
    if not found:
        return 0, 0
    contacts = table_contracts.read(table_contracts.CONTACTS, found[0])
    first = first_same_grasp(read_grasps(contacts))
    own = set(contacts["pose"].to_numpy()[first == range(len(first))].tolist())
    gfo = table_contracts.read(table_contracts.GFO, gfo_file)
    return len(own), int((gfo["pose"].isin(own) & (gfo["solver"] != "none")).sum())


if __name__ == "__main__":
    main()
