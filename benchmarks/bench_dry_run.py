"""The dry run of many random objects on a machine that has never seen the meshes:
`snakemake -n across_objects --configfile config/examples/random_objects.yaml` with an overlay
setting `n_objects`, in an empty working directory, XDG_CACHE_HOME a new empty folder (no
per-user mesh cache). Prints the wall and CPU seconds, the jobs planned and whether any mesh
was decomposed (the per-user cache or results/meshes written) as machine-read lines.

The package's compiled code is set-up, not mesh work: by default the dry run reads it where
this user's warm-up left it (``NUMBA_CACHE_DIR`` set to that folder), as after the README's
set-up on a fresh machine. ``--cold`` empties that too: the dry run then compiles the hand's
capsule code for the thumb-opposition check it runs on the configured hand.

    .venv/bin/python benchmarks/bench_dry_run.py [N_OBJECTS] [--cold]     (default 1000)
"""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> None:
    cold = "--cold" in argv
    numbers = [a for a in argv if a != "--cold"]
    n = int(numbers[0]) if numbers else 1000
    compiled = os.environ.get("NUMBA_CACHE_DIR") or os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    with tempfile.TemporaryDirectory(prefix="synergrasp-dry-") as work:
        overlay = Path(work) / "n_objects.yaml"
        overlay.write_text(f"random_objects:\n  n_objects: {n}\n")
        env = {**os.environ, "XDG_CACHE_HOME": f"{work}/cache"}
        if not cold:
            env["NUMBA_CACHE_DIR"] = compiled
        command = [
            str(ROOT / ".venv" / "bin" / "snakemake"),
            "-s",
            str(ROOT / "Snakefile"),
            "-d",
            f"{work}/run",
            "-n",
            "across_objects",
            "--configfile",
            str(ROOT / "config" / "examples" / "random_objects.yaml"),
            str(overlay),
        ]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        wall = time.perf_counter()
        out = subprocess.run(command, env=env, capture_output=True, text=True, cwd=ROOT)
        wall = time.perf_counter() - wall
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if out.returncode:
            raise SystemExit(f"the dry run failed:\n{out.stderr[-3000:]}")
        jobs = re.search(r"^total\s+(\d+)$", out.stdout, re.MULTILINE)
        parts = re.search(r"^mesh_parts\s+(\d+)$", out.stdout, re.MULTILINE)
        made = (Path(work) / "cache" / "synergrasp-meshes").exists() or (Path(work) / "run" / "results" / "meshes").exists()
    note = ", compiled code not cached" if cold else ""
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    print(f"dry_run_wall_s_{n}_objects: {wall:.1f}  (snakemake -n across_objects, {n} objects drawn, wall s{note})")
    print(f"dry_run_cpu_s_{n}_objects: {cpu:.1f}  (the same, CPU s of Snakemake's process)")
    print(f"dry_run_jobs_{n}_objects: {int(jobs.group(1)) if jobs else -1}  (jobs planned)")
    print(
        f"dry_run_mesh_parts_jobs_{n}_objects: {int(parts.group(1)) if parts else 0}  (of which mesh_parts: one per mesh studied)"
    )
    print(
        f"dry_run_meshes_decomposed_{n}_objects: {int(made)}  "
        "(1 if the dry run wrote any mesh's parts, per-user cache or results/meshes)"
    )


if __name__ == "__main__":
    main(sys.argv[1:])
