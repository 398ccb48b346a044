"""Peak resident memory of the study's tables (the `tables` step's computation,
`synergrasp.analysis.summaries.study_tables`) against the number of objects: the default
study's objects' gfo and minima tables, copied under new names (`obj1_0`, `obj1_1`, ...) to
make 4 x M objects, each count in a fresh process. Synthetic objects: the tables' values
mean nothing, their size and the work on them are a real study's.

    .venv/bin/python benchmarks/bench_tables_memory.py --results results [M ...]   (default M: 1 4 10)
"""

from __future__ import annotations

import copy
import resource
import subprocess
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def one(results: Path, copies: int) -> None:
    """Print the peak MB and CPU s of the tables over ``copies`` copies of the study's objects."""
    import pandas as pd
    import yaml

    from synergrasp.analysis.summaries import TablesParams, study_tables
    from synergrasp.steps import step_config
    from synergrasp.study_checks import checked_scenario
    from synergrasp.tables import GFO, MINIMA, read

    cfg, _ = checked_scenario(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    base = list(cfg["objects"])
    cfg["objects"] = {f"{o}_{k}": copy.deepcopy(cfg["objects"][o]) for k in range(copies) for o in base}
    params = TablesParams.from_config(step_config(cfg, "tables"))
    warnings.simplefilter("ignore")
    start = time.process_time()
    gfo = pd.concat(
        [read(GFO, results / "objects" / o / "gfo.parquet").assign(object=f"{o}_{k}") for k in range(copies) for o in base],
        ignore_index=True,
    )
    minima = pd.concat(
        [read(MINIMA, results / "objects" / o / "minima.parquet").assign(object=f"{o}_{k}") for k in range(copies) for o in base],
        ignore_index=True,
    )
    read_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    study_tables(gfo, minima, params.synergy_sets, params.table2_k_max, params.settings)
    n = len(cfg["objects"])
    print(
        f"tables_read_peak_mb_{n}_objects: {read_mb:.0f}  (peak resident MB once the {n} objects' gfo and minima "
        f"tables are read, {len(gfo)} gfo rows)"
    )
    print(
        f"tables_peak_mb_{n}_objects: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}  "
        f"(peak resident MB of the study's tables over {n} objects)"
    )
    print(f"tables_cpu_s_{n}_objects: {time.process_time() - start:.1f}  (CPU s, reading and tables)")


def main(argv: list[str]) -> None:
    if argv[:1] == ["--one"]:
        one(Path(argv[1]), int(argv[2]))
        return
    if argv[:1] != ["--results"] or len(argv) < 2:
        raise SystemExit("usage: bench_tables_memory.py --results RESULTS [M ...]")
    results = Path(argv[1])
    for copies in [int(m) for m in argv[2:]] or [1, 4, 10]:
        run = subprocess.run([sys.executable, __file__, "--one", str(results), str(copies)], capture_output=True, text=True)
        if run.returncode:
            raise SystemExit(f"{copies} copies failed:\n{run.stderr[-2000:]}")
        sys.stdout.write(run.stdout)
        sys.stdout.flush()


if __name__ == "__main__":
    main(sys.argv[1:])
