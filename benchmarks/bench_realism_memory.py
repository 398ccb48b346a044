"""Peak resident memory of the realism job on the first N of a random-objects study's objects (issue 47).

The realism workflow script (``workflow/scripts/realism.py``) runs in a fresh process on the
files its rule would be handed for the first N objects (sorted) of a finished run of
``config/examples/random_objects.yaml`` (``--results``: its results folder, read only; its
``meshes/`` are the convex parts the shapes read, found through a scratch folder's
``results/meshes`` link). Prints its peak resident MB (ru_maxrss, imports included) and CPU s,
and its resident MB before each object's files are read (in the job's log: ``VmRSS``), so that
memory kept per object shows apart from the job's end (the tables, the figure).

    .venv/bin/python benchmarks/bench_realism_memory.py --results RESULTS [N ...]    (default N: 5 20 50 97)
"""

from __future__ import annotations

import json
import os
import resource
import runpy
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_tables_memory import _Named  # noqa: E402  (Snakemake's named lists)


def _vmrss_mb() -> int:
    return next(int(line.split()[1]) // 1024 for line in open("/proc/self/status") if line.startswith("VmRSS"))


def _merged(base: dict, over: dict) -> dict:
    for key, value in over.items():
        base[key] = _merged(base[key], value) if isinstance(value, dict) and isinstance(base.get(key), dict) else value
    return base


def one(spec_path: str) -> None:
    """The realism script on the first ``n`` objects of ``spec``'s results; its figures printed."""
    import yaml

    import synergrasp.analysis.realism as realism
    from synergrasp.steps import STEPS
    from synergrasp.table_contracts import CONTACTS
    from synergrasp.wiring import Wiring

    spec = json.loads(Path(spec_path).read_text())
    results, out, n = Path(spec["results"]), Path(spec["out"]), spec["n"]
    read = (ROOT / "config" / "config.yaml", ROOT / "config" / "examples" / "random_objects.yaml")
    wiring = Wiring(_merged(*(yaml.safe_load(p.read_text()) for p in read)), ROOT)
    names = sorted(o for o in wiring.objects if (results / "objects" / o / "contacts.parquet").exists())[:n]
    files = {"contacts": "contacts.parquet", "gfo": "gfo.parquet", "placements": "placement.csv"}
    inputs = {key: [str(results / "objects" / o / f) for o in names] for key, f in files.items()}
    inputs["manifest"] = [str(ROOT / "config" / "examples" / "meshes" / "pybullet_random_urdfs.sha256")]
    outputs = {name: str(out / rel) for name, rel in STEPS["realism"].outputs.items()}
    for path in outputs.values():
        Path(path).parent.mkdir(parents=True, exist_ok=True)

    class Keys(dict):
        def keys(self):  # no wildcards: the default scenario
            return []

    class Snakemake:
        input, output, log = _Named(inputs), _Named(outputs), [str(out / "logs" / "realism.log")]
        params = _Named({"cfg": wiring.params("realism")["cfg"](Keys())})

    Path(Snakemake.log[0]).parent.mkdir(parents=True, exist_ok=True)
    read_table = realism.read

    def reading(contract, path):  # the resident memory before each object's files
        if contract is CONTACTS:
            print(f"VmRSS before {Path(path).parent.name}: {_vmrss_mb()} MB", file=sys.stderr)
        return read_table(contract, path)

    realism.read = reading
    os.chdir(out)  # the shapes read their parts from results/meshes/
    (out / "results").mkdir(exist_ok=True)
    if not (out / "results" / "meshes").exists():
        (out / "results" / "meshes").symlink_to(results / "meshes")
    start = time.process_time()
    runpy.run_path(str(ROOT / "workflow" / "scripts" / "realism.py"), init_globals={"snakemake": Snakemake()})
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"realism_peak_mb_{n}_objects: {peak:.0f}  (peak resident MB of the realism job over the first {n} objects)")
    print(f"realism_cpu_s_{n}_objects: {time.process_time() - start:.1f}  (CPU s of the realism job after its imports)")


def main(argv: list[str]) -> None:
    if argv[:1] == ["--one"]:
        one(argv[1])
        return
    if argv[:1] != ["--results"] or len(argv) < 2:
        raise SystemExit("usage: bench_realism_memory.py --results RESULTS [N ...]")
    results = Path(argv[1]).resolve()
    if not (results / "meshes").is_dir():
        raise SystemExit(f"--results: '{results}' has no meshes/ folder (a finished random-objects run's results)")
    scratch = Path(tempfile.mkdtemp(prefix="bench_realism_memory_"))
    for n in [int(m) for m in argv[2:]] or [5, 20, 50, 97]:
        spec = scratch / f"{n}.json"
        spec.write_text(json.dumps({"results": str(results), "out": str(scratch / f"out_{n}"), "n": n}))
        run = subprocess.run([sys.executable, __file__, "--one", str(spec)], capture_output=True, text=True)
        if run.returncode:
            raise SystemExit(f"realism on {n} objects failed:\n{run.stderr[-3000:]}")
        sys.stdout.write("".join(line + "\n" for line in run.stdout.splitlines() if "_objects:" in line))
        sys.stdout.flush()
    print(f"(the jobs' outputs and logs: {scratch})")


if __name__ == "__main__":
    main(sys.argv[1:])
