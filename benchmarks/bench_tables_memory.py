"""Peak resident memory of every study-wide job against the number of objects (issue 47).

The default study's objects (``--results``: a results folder of the default study) are
copied under new names (``obj1_0``, ``obj2_0``, ..., ``obj4_0``, ``obj1_1``, ...), their
object column renamed, into a scratch results folder, to make N objects; for each N every
study-wide job that reads every object's files (planners, tables, realism, blockers_table,
fig2) runs its own workflow script (``workflow/scripts/<job>.py``, handed the files its rule
would be handed) in a fresh process, and its peak resident memory (ru_maxrss, imports
included, as the job's benchmark file's max_rss) and CPU time are printed. Synthetic
objects: the tables' values mean nothing, their size and the work on them are a real study's.

``--jobs a,b``: only those jobs (the tables job then reads the study's own planners table
for claim 8 where the planners job does not run).

``--aggregation N``: the tables' aggregation over N objects' summaries (1,000 in the issue),
synthetic: the default study's objects reduced one at a time as the tables job does
(``StudyReduction.add``), then what it keeps of each copied under new names to make N, then
every table made (``StudyReduction.tables``); peak resident MB and CPU s in a fresh process.

    .venv/bin/python benchmarks/bench_tables_memory.py --results results [N ...]    (default N: 10 25 50 100)
    .venv/bin/python benchmarks/bench_tables_memory.py --results results --jobs tables,realism [N ...]
    .venv/bin/python benchmarks/bench_tables_memory.py --results results --aggregation 1000
"""

from __future__ import annotations

import copy
import json
import resource
import runpy
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: The study-wide jobs that read every object's files, in an order that hands each its inputs
#: (tables reads planners' table), with the per-object files their rules read.
JOBS = {
    "planners": {"contacts": "contacts.parquet", "gfo": "gfo.parquet"},
    "tables": {"gfo": "gfo.parquet", "minima": "minima.parquet"},
    "realism": {"contacts": "contacts.parquet", "gfo": "gfo.parquet", "placements": "placement.csv"},
    "blockers_table": {"blockers": "blockers.parquet"},
    "fig2": {"contacts": "contacts.parquet"},
}
_COPIED = {"gfo.parquet": "GFO", "minima.parquet": "MINIMA", "contacts.parquet": "CONTACTS", "blockers.parquet": "BLOCKERS"}


class _Named(list):
    """Snakemake's named lists (``snakemake.input.gfo``, ``snakemake.output["csv"]``)."""

    def __init__(self, named: dict):
        super().__init__(named.values())
        self._named = dict(named)
        self.__dict__.update(named)

    def __getitem__(self, key):
        return self._named[key] if isinstance(key, str) else super().__getitem__(key)


def _names(n: int, base: list[str]) -> list[str]:
    return [f"{base[i % len(base)]}_{i // len(base)}" for i in range(n)]


def _config(n: int) -> dict:
    import yaml

    from synergrasp.input_checks import checked_scenario

    cfg, _ = checked_scenario(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    base = list(cfg["objects"])
    cfg["objects"] = {name: copy.deepcopy(cfg["objects"][name.rsplit("_", 1)[0]]) for name in _names(n, base)}
    return cfg


def make_objects(results: Path, scratch: Path, n: int) -> None:
    """Copies of the default study's objects under new names in ``scratch/objects/``."""
    from synergrasp import table_contracts

    base = sorted(p.name for p in (results / "objects").iterdir() if (p / "gfo.parquet").exists())
    for name in _names(n, base):
        folder = scratch / "objects" / name
        if folder.exists():
            continue
        folder.mkdir(parents=True)
        source = results / "objects" / name.rsplit("_", 1)[0]
        for file, table in _COPIED.items():
            contract = getattr(table_contracts, table)
            table_contracts.write(contract, table_contracts.read(contract, source / file).assign(object=name), folder / file)
        shutil.copy(source / "placement.csv", folder / "placement.csv")


def one(spec_path: str) -> None:
    """Run one job's workflow script on the files of ``spec`` and print its peak MB and CPU s."""
    from synergrasp.steps import STEPS, step_config

    spec = json.loads(Path(spec_path).read_text())
    job, scratch, out, n = spec["job"], Path(spec["scratch"]), Path(spec["out"]), spec["n"]
    cfg = _config(n)
    objects = list(cfg["objects"])
    inputs = {key: [str(scratch / "objects" / o / file) for o in objects] for key, file in JOBS[job].items()}
    inputs["manifest"] = []
    inputs["planners"] = str(out / "tables" / "planners.csv")
    outputs = {name: str(out / rel) for name, rel in STEPS[job].outputs.items()}
    for path in outputs.values():
        Path(path).parent.mkdir(parents=True, exist_ok=True)

    class Snakemake:
        input, output, log = _Named(inputs), _Named(outputs), [str(out / "logs" / f"{job}.log")]
        params = _Named({"cfg": step_config(cfg, job)})

    Path(Snakemake.log[0]).parent.mkdir(parents=True, exist_ok=True)
    start = time.process_time()
    runpy.run_path(str(ROOT / "workflow" / "scripts" / f"{job}.py"), init_globals={"snakemake": Snakemake()})
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"{job}_peak_mb_{n}_objects: {peak:.0f}  (peak resident MB of the {job} job over {n} objects)")
    print(f"{job}_cpu_s_{n}_objects: {time.process_time() - start:.1f}  (CPU s of the {job} job after its imports)")


def aggregation(results: Path, n: int) -> None:
    """The tables' aggregation over ``n`` objects' summaries: the default study's objects
    reduced, their kept state copied under new names (synthetic), every table made."""
    import warnings

    from synergrasp.analysis.study_tables import StudyReduction, object_loaders
    from synergrasp.analysis.summaries import TablesParams
    from synergrasp.steps import step_config
    from synergrasp.table_contracts import PLANNERS, read_csv

    warnings.simplefilter("ignore")
    cfg = _config(n)
    base = sorted(p.name for p in (results / "objects").iterdir() if (p / "gfo.parquet").exists())
    params = TablesParams.from_config(step_config(cfg, "tables"))
    start = time.process_time()
    reduction = StudyReduction(params.synergy_sets, params.settings)
    for obj, load in object_loaders(*([results / "objects" / o / f for o in base] for f in ("gfo.parquet", "minima.parquet"))):
        reduction.add(obj, *load())
    _copy_kept(reduction, [name for name in cfg["objects"] if name.rsplit("_", 1)[0] in base])
    reduction.tables(params.table2_k_max, read_csv(PLANNERS, results / "tables" / "planners.csv"))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"aggregation_peak_mb_{n}_objects: {peak:.0f}  (peak resident MB of the tables' aggregation of {n} objects' summaries)")
    print(
        f"aggregation_cpu_s_{n}_objects: {time.process_time() - start:.1f}  (CPU s: {len(base)} objects reduced, the tables made)"
    )


def _copy_kept(reduction, names: list[str]) -> None:
    """What ``reduction`` keeps of each object, copied under ``names`` (``<object>_<k>``),
    the objects kept in sorted order (synthetic summaries: the benchmark's alone)."""
    import numpy as np
    import pandas as pd

    r, counts, resampler = reduction, reduction.counts, reduction.resampler
    renamed = {name: name.rsplit("_", 1)[0] for name in sorted(names)}
    for store in (resampler._poses, resampler._blocks, resampler._block_weights):
        kept = dict(store)
        store.clear()
        store.update({name: np.copy(kept[base]) for name, base in renamed.items()})
    for store in (counts._success, counts._sums, counts._n, counts._own_sets, counts._force):
        kept = dict(store)
        store.clear()
        store.update({name: copy.deepcopy(kept[base]) for name, base in renamed.items()})

    def rows(items: list[dict]) -> list[dict]:
        return [
            {**copy.deepcopy(row), "object": name} for name, base in renamed.items() for row in items if row["object"] == base
        ]

    r._pairs, r._kept, r._checks, r._preservation = rows(r._pairs), rows(r._kept), rows(r._checks), rows(r._preservation)
    for frames in (r._rates, r._lost, r._disagree):
        by_object = {str(f["object"].iat[0]) if len(f) else None: f for f in frames}
        frames[:] = [by_object[base].assign(object=name) for name, base in renamed.items() if base in by_object] or [
            pd.concat(frames).iloc[:0]
        ]
    r.objects = list(renamed)


def _run(job: str, scratch: Path, n: int) -> None:
    out = scratch / f"out_{n}"
    spec = scratch / f"{job}_{n}.json"
    spec.write_text(json.dumps({"job": job, "scratch": str(scratch), "out": str(out), "n": n}))
    run = subprocess.run([sys.executable, __file__, "--one", str(spec)], capture_output=True, text=True)
    if run.returncode:
        raise SystemExit(f"{job} on {n} objects failed:\n{run.stderr[-3000:]}")
    sys.stdout.write("".join(line + "\n" for line in run.stdout.splitlines() if "_objects:" in line))
    sys.stdout.flush()


def main(argv: list[str]) -> None:
    if argv[:1] == ["--one"]:
        one(argv[1])
        return
    if argv[:1] == ["--aggregate"]:
        aggregation(Path(argv[1]), int(argv[2]))
        return
    if argv[:1] != ["--results"] or len(argv) < 2:
        raise SystemExit("usage: bench_tables_memory.py --results RESULTS [N ...] | --results RESULTS --aggregation N")
    results = Path(argv[1])
    if argv[2:3] == ["--aggregation"]:
        run = subprocess.run([sys.executable, __file__, "--aggregate", str(results), argv[3]], capture_output=True, text=True)
        if run.returncode:
            raise SystemExit(f"the aggregation failed:\n{run.stderr[-3000:]}")
        sys.stdout.write(run.stdout)
        return
    jobs = list(JOBS)
    if argv[2:3] == ["--jobs"]:
        jobs, argv = argv[3].split(","), argv[:2] + argv[4:]
    scratch = Path(tempfile.mkdtemp(prefix="bench_tables_memory_"))
    try:
        for n in [int(m) for m in argv[2:]] or [10, 25, 50, 100]:
            make_objects(results, scratch, n)
            if "planners" not in jobs:  # claim 8's planners table: the study's own
                (scratch / f"out_{n}" / "tables").mkdir(parents=True, exist_ok=True)
                shutil.copy(results / "tables" / "planners.csv", scratch / f"out_{n}" / "tables" / "planners.csv")
            for job in [j for j in JOBS if j in jobs]:
                _run(job, scratch, n)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main(sys.argv[1:])
