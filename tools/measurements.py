"""docs/measurements.md, the one page of what the study and its parts cost, written from the
reference run's files in benchmarks/results/ (do not edit the page by hand).

    .venv/bin/python tools/measurements.py                                  write the page
    .venv/bin/python tools/measurements.py record NAME [--timed] -- COMMAND  run and record COMMAND
    .venv/bin/python tools/measurements.py jobs [results]                   record a study's jobs

`record` runs COMMAND, passes its output through and writes benchmarks/results/NAME.csv: one
row per machine-read line it printed (`key: number`, optionally followed by two spaces and
`(what it is)`) with the load average before and after, the machine and the command; with
`--timed` also the command's wall time and the CPU time of it and its children. `jobs` writes
benchmarks/results/study_jobs.csv from a run's Snakemake benchmark files and its per-object
tables (how many poses and (pose, set) problems each rule did). `make bench` and
`make bench-study` do both, then write the page; tests/test_docs.py checks the page is what
this writes from the committed files.
"""

from __future__ import annotations

import csv
import os
import platform
import re
import resource
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from job_times import job_times  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
PAGE = ROOT / "docs" / "measurements.md"

#: A machine-read line of a benchmark's output: `key: number`, then optionally `  (what it is)`.
FIGURE_LINE = re.compile(r"^([a-z][a-z0-9_]*): ([-+]?[0-9][0-9.eE+-]*)(?:  \((.*)\))?$")
FIGURE_COLUMNS = ("figure", "value", "description", "load_average", "machine", "command", "note")

#: What one unit of a rule's work is, and the per-object table that counts it.
UNITS = {
    "simulate": ("pose", "contacts.parquet"),
    "optimise_shard": ("(pose, set)", "gfo.parquet"),
    "optimise": ("(pose, set)", "gfo.parquet"),
    "minima": ("(pose, set)", "gfo.parquet"),
    "fig4": ("(pose, set)", "gfo.parquet"),
}

#: The page's sections of figures: title, the files of benchmarks/results/ they show, what they are.
SECTIONS = (
    (
        "The default study",
        ("study", "fresh_clone", "fresh_venv"),
        "`make bench-study`: `snakemake -j2 figures` from an empty `results/`, the solver kernel compiled "
        "(`make bench-study` refuses a `results/` that is not empty); its jobs, per rule, below.",
    ),
    (
        "Other runs",
        (
            "sensitivity",
            "sensitivity_grasp_type",
            "dynamic_study",
            "everyday_objects",
            "random_objects",
            "shadow_hand",
            "inspire_hand",
            "cluster_test",
            "dry_run",
            "cluster_thousand",
            "cluster_groups",
            "tables_memory",
            "tables_memory_1000",
            "realism_memory",
        ),
        "Whole runs besides the default study; `tools/measurements.py record NAME --timed -- COMMAND` records one "
        "(a workflow from an empty `results/`).",
    ),
    (
        "Closure",
        ("closure",),
        "`benchmarks/bench_closure.py` (in `make bench`): CPU time per grasp (`time.process_time`, one core), "
        "placement included, over poses spread over the grid; the study's closure settings.",
    ),
    (
        "Grasp-force optimisation",
        ("gfo", "pyramid", "compile", "study_rate"),
        "`benchmarks/bench_gfo.py`, `bench_pyramid.py`, `bench_compile.py` and `bench_study.py` (in `make bench`; "
        "one core, OMP_NUM_THREADS=1); docs/ipm_solver.md says what made each figure.",
    ),
    (
        "Planners",
        ("set_size", "plan_on_demand", "plan_on_demand_random5_random_1200", "plan_on_demand_random5_straight_m3_r45"),
        "`benchmarks/bench_set_size.py` (in `make bench`; one core): CPU time of one (grasp, set) problem per size k of "
        "{S1..Sk}, one call of `optimise_grasps` per set as a planner's level makes it, the grasp's mechanics "
        "included; its ratios to the full set's weigh the planners' solve time (docs/planner.md). "
        "`benchmarks/bench_plan_on_demand.py` (in `make bench`, after a study: it reads the searched targets and "
        "the gfo tables): `synergrasp plan --on-demand` with the default planner on each box, the hand closed "
        "only where it asks; closures, wall time of the plan and regret against the study's exhaustive minimum; "
        "also on the first five random objects (`--configfile config/examples/random_objects.yaml "
        "config/examples/random_objects_5.yaml`, after their study) with the default planner and with the one the "
        "rule selects on them.",
    ),
    (
        "One grasp in full",
        ("inspector",),
        "`benchmarks/bench_inspector.py` (in `make bench`, after a study: it reads obj4's searched target): "
        "`synergrasp grasp obj4 --alpha -30 --beta 0` with its 29 default sets, warm, each run in a fresh process "
        "(median of 3), alone and with `--png` and `--html`; the target is at most 3 s wall on a quiet machine. "
        "Then the 3-D pages of the workflow's `fig2` step in one process: Fig. 2's 12 grasps from the "
        "study's contacts (docs/inspector.md).",
    ),
    (
        "Placement search",
        ("search",),
        "`benchmarks/bench_search.py` (in `make bench`): the default study's search of each object with 2 "
        "processes; the target is at most 30 s wall per object on 2 quiet cores (the study's own searches: "
        "`search` in the jobs table above).",
    ),
    (
        "One random object",
        ("object_cost",),
        "`benchmarks/bench_object.py` (not in `make bench`: a few minutes): three random mesh objects of "
        "`config/examples/random_objects.yaml` (`n_objects: 3`, seed 2018) each through the placement search (one "
        "process), the closure at its target, the optimisation of every (pose, set) and the planner, in one process: "
        "CPU s per step (`time.process_time`); it prints a digest of each step's table, the same before and after a "
        "change that keeps the results (docs/random_objects.md). Before the closure's query and the planner's solver "
        "were made cheaper: `object_cost_history.csv` below.",
    ),
    (
        "Snakemake's own cost",
        ("scheduler",),
        "`benchmarks/bench_scheduler.py` (in `make bench`): the CPU time of Snakemake's own process (the jobs "
        "excluded) per job, on the small sweep from an empty directory with -j2 and the workflow profile "
        "(profiles/default/config.yaml says what it grows with on long runs).",
    ),
    (
        "Figure jobs' imports",
        ("figure_imports",),
        "`benchmarks/bench_figure_imports.py` (in `make bench`, after a study): per figure rule, the CPU time of "
        "its script's imports in a fresh interpreter (start-up subtracted, median of 3) against its jobs' CPU time "
        "in the last study's benchmark files.",
    ),
    (
        "Measured while the software was built",
        ("closure_history", "dynamic_closure_history", "solver_history", "parts_history", "object_cost_history", "job_resources"),
        "The figures behind design decisions that the pages of docs/ describe, each measured once when the decision "
        "was made and recorded by hand (the note names the page; `make bench` does not rerun them): they compare the "
        "alternatives of their day, not what the software costs today (the sections above).",
    ),
)


def machine() -> str:
    """This machine in a few words (recorded beside each figure)."""
    return f"{platform.machine()}, {os.cpu_count()} cores, {platform.python_implementation()} {platform.python_version()}"


def figures(output: str) -> list[tuple[str, str, str]]:
    """The (key, value, description) of every machine-read line of a benchmark's ``output``."""
    found = (FIGURE_LINE.match(line.rstrip()) for line in output.splitlines())
    return [(m[1], m[2], m[3] or "") for m in found if m]


def record(name: str, command: list[str], timed: bool = False, out: Path = RESULTS) -> Path:
    """Run ``command``, echo its output and write ``out/<name>.csv``, one row per figure it printed
    (with ``timed``: its wall seconds and the CPU seconds of it and its children, first)."""
    load, wall, cpu = os.getloadavg()[0], time.perf_counter(), _children_cpu_s()
    output = []
    with subprocess.Popen(command, stdout=subprocess.PIPE, text=True) as run:
        for line in run.stdout:  # passed through as it comes: a study takes minutes
            sys.stdout.write(line)
            sys.stdout.flush()
            output.append(line)
    wall, cpu = time.perf_counter() - wall, _children_cpu_s() - cpu
    if run.returncode:
        raise SystemExit(f"record {name}: {' '.join(command)} failed (exit code {run.returncode}); nothing recorded")
    rows = (
        [
            ("wall_s", f"{wall:.0f}", f"wall time of the command, s ({wall // 60:.0f} min {wall % 60:.0f} s)"),
            ("cpu_s", f"{cpu:.0f}", "CPU time of the command and its children, s"),
        ]
        if timed
        else []
    )
    rows += figures("".join(output))
    where = {
        "load_average": f"{load:.1f}-{os.getloadavg()[0]:.1f}",
        "machine": machine(),
        "command": " ".join(command),
        "note": "",
    }
    path = out / f"{name}.csv"
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, FIGURE_COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows({"figure": k, "value": v, "description": d, **where} for k, v, d in rows)
    print(f"recorded {len(rows)} figures in {path}")
    return path


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def units_done(results: Path, table: str) -> int:
    """Rows of every object's ``table`` under ``results`` (the default study's only)."""
    return sum(len(pd.read_parquet(p, columns=["pose"])) for p in sorted((results / "objects").glob(f"*/{table}")))


def study_jobs(results: Path) -> pd.DataFrame:
    """Per rule of the run under ``results``: jobs, wall and CPU seconds, peak MB and the units of
    work its per-object tables count (0 where a rule has none)."""
    times = job_times(results).drop(columns=["cpu_percent", "logged"])
    units = {rule: units_done(results, table) for rule, (_, table) in UNITS.items() if rule in times.index}
    times["units"] = [units.get(rule, 0) for rule in times.index]
    times["unit"] = [UNITS[rule][0] if units.get(rule) else "" for rule in times.index]
    return times.round({"wall_s": 1, "cpu_s": 1, "peak_mb": 0}).reset_index()


def _figure_table(inputs: Path, name: str) -> list[str]:
    """A figures file as tables, one per run: consecutive rows with the same command, load and note."""
    path = inputs / f"{name}.csv"
    if not path.exists():
        return [f"`benchmarks/results/{name}.csv`: not recorded yet (`make bench` writes it).", ""]
    rows = pd.read_csv(path, dtype=str, keep_default_na=False)
    lines = [f"`benchmarks/results/{name}.csv`:", ""]
    run = rows[["command", "load_average", "note"]].apply(tuple, axis=1)
    for _, group in rows.groupby((run != run.shift()).cumsum(), sort=False):
        first = group.iloc[0]
        lines += [
            f"`{first.command}`, load average {first.load_average}" + (f"; {first.note}" if first.note else "") + ":",
            "",
            "| figure | value | what |",
            "|---|---|---|",
        ]
        lines += [f"| `{r.figure}` | {r.value} | {r.description} |" for r in group.itertuples(index=False)]
        lines.append("")
    return lines


def _jobs_table(inputs: Path) -> list[str]:
    if not (inputs / "study_jobs.csv").exists():
        return ["`benchmarks/results/study_jobs.csv`: not recorded yet (`make bench-study` writes it).", ""]
    jobs = pd.read_csv(inputs / "study_jobs.csv", keep_default_na=False)
    total_cpu = jobs["cpu_s"].sum()
    lines = [
        *textwrap.wrap(
            "The jobs' own costs, from their Snakemake `benchmark:` files (`tools/measurements.py jobs "
            "results`, written to `benchmarks/results/study_jobs.csv`); CPU per unit is over the work of "
            "every job of the rule:",
            100,
        ),
        "",
        "| rule | jobs | wall s | CPU s | CPU % | peak MB | CPU per unit |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in jobs.itertuples(index=False):
        per = f"{1e3 * r.cpu_s / r.units:.3g} ms per {r.unit} over {r.units:,}" if r.units else ""
        lines.append(
            f"| `{r.rule}` | {r.jobs} | {r.wall_s:.1f} | {r.cpu_s:.1f} | {100 * r.cpu_s / total_cpu:.0f} | "
            f"{r.peak_mb:.0f} | {per} |"
        )
    return lines + [
        "",
        f"Total: {jobs['jobs'].sum()} jobs, {jobs['wall_s'].sum():.0f} job-seconds, {total_cpu:.0f} CPU seconds.",
        "",
    ]


def closure_engines(inputs: Path) -> list[str]:
    """The section on the dynamic closure's engines and variants (tools/closure_agreement.py)."""
    if not (inputs / "closure_engines.csv").exists():
        return []
    table = pd.read_csv(inputs / "closure_engines.csv", keep_default_na=False)
    lines = [
        "## Dynamic closure: engines and variants",
        "",
        "From `benchmarks/results/closure_engines.csv` (docs/dynamic_closure.md, Cost): CPU ms per grasp",
        "(`time.process_time`, one core) and, on the 240 poses of `benchmarks/bench_closure.py` (60 per",
        "study box), the share of poses with the same status and the same full-set force-closure",
        "verdict as main's pybullet model before this work (table made with main's code). Measured",
        "on the shared 2-core machine (load average 9-15): the ms are inflated alike; the two medians",
        'of 5 were interleaved, the single runs were not, except the engine-parameter rows from "the',
        'reference again" on (load average ~4), each run between two runs of the reference: their',
        '"per step" is CPU per engine step against those neighbours\'. "In distribution":',
        "`tools/closure_agreement.py distribution` against the reference and its four moved-box copies.",
        "",
        "| engine / variant | ms per grasp | same status | same verdict | grasps | force closure | command |",
        "|---|---|---|---|---|---|---|",
    ]

    def pct(value: object) -> str:
        return f"{value} %" if str(value)[:1].isdigit() else str(value)

    for row in table.itertuples(index=False):
        lines.append(
            f"| {row.variant} | {row.ms_per_grasp} | {pct(row.same_status_pct)} | {pct(row.same_verdict_pct)} | "
            f"{row.grasps} | {row.force_closure} | `{row.command}` |"
        )
    return lines + [""]


def _machines(inputs: Path) -> list[str]:
    """Every machine the figures under ``inputs`` were measured on."""
    tables = (pd.read_csv(p, dtype=str, keep_default_na=False) for p in sorted(inputs.glob("*.csv")))
    return sorted({m for t in tables if "machine" in t for m in t["machine"] if m})


def page(inputs: Path = RESULTS) -> str:
    """The measurements page, from the files of ``inputs`` (benchmarks/results/) alone."""
    lines = [
        "# Measurements",
        "",
        "What the study and its parts cost, in one place: written by `.venv/bin/python tools/measurements.py`",
        "from the reference run's files in `benchmarks/results/` (do not edit by hand; `make bench` and",
        "`make bench-study` measure again and rewrite it). Each figure comes with the command that measured",
        "it and the machine's load average (1-minute, before and after) while it ran: CPU times are steadier",
        "than wall times on a loaded machine, but both grow with the load. Machine: " + "; ".join(_machines(inputs)) + ".",
        "A figure whose note says *not rerun* was taken from the documentation or a commit of the run that",
        "measured it, before this page had its files.",
        "",
    ]
    for title, names, intro in SECTIONS:
        lines += [f"## {title}", "", *textwrap.wrap(intro, 100), ""]
        for name in names:
            lines += _figure_table(inputs, name)
            if name == "study":
                lines += _jobs_table(inputs)
    return "\n".join(lines + closure_engines(inputs))


def main(argv: list[str]) -> None:
    if argv[:1] == ["record"]:
        if "--" not in argv or argv.index("--") < 2:
            raise SystemExit("usage: tools/measurements.py record NAME [--timed] -- COMMAND ...")
        at = argv.index("--")
        record(argv[1], argv[at + 1 :], timed="--timed" in argv[2:at])
    elif argv[:1] == ["jobs"]:
        results = Path(argv[1] if len(argv) > 1 else "results")
        study_jobs(results).to_csv(RESULTS / "study_jobs.csv", index=False, lineterminator="\n")
        print(f"wrote {RESULTS / 'study_jobs.csv'}")
    else:
        PAGE.write_text(page())
        print(f"wrote {PAGE}")


if __name__ == "__main__":
    main(sys.argv[1:])
