"""synergrasp.snakemake_adapter, the one module that uses Snakemake's internals: each behaviour
it provides on a small workflow of its own run by the installed Snakemake (a few seconds
each), its refusal of another Snakemake release, and a scan of the sources: no other module
names a private Snakemake module or attribute."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from synergrasp import snakemake_adapter as adapter

ROOT = Path(__file__).resolve().parents[1]


def _snakemake(workdir: Path, *args: str) -> subprocess.CompletedProcess:
    """Run the installed Snakemake on ``workdir``'s Snakefile, from there (the checkout's profile
    unread); a hang guard of two minutes, never reached by a run of these workflows."""
    return subprocess.run(
        [sys.executable, "-m", "snakemake", "-c1", "-s", str(workdir / "Snakefile"), *args],
        cwd=workdir,
        capture_output=True,
        text=True,
        timeout=120,
    )


# --------------------------------------------------------------------------- the version


def test_a_release_of_the_series_it_was_written_for_is_accepted():
    assert adapter.version_problem(adapter.WRITTEN_FOR + ".0") is None
    assert adapter.version_problem(adapter.WRITTEN_FOR + ".13") is None
    adapter.check_version()  # the installed Snakemake (environment.lock's)


@pytest.mark.parametrize("version", ["9.28.0", "9.2.7", "10.0.0", "8.27.1"])
def test_another_snakemake_release_is_refused_with_one_line(version, capsys):
    with pytest.raises(SystemExit) as stop:
        adapter.check_version(version)
    assert stop.value.code == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"Snakemake {version}" in err and "snakemake_adapter" in err
    assert f"Snakemake {adapter.WRITTEN_FOR}.x" in err


# --------------------------------------------------------------------------- the recursion guard

_PERIODIC = """
from synergrasp.snakemake_adapter import accept_configured_wildcards

NAME = "obj_" + "0" * 20
{accept}

rule all:
    input:
        f"out/{{NAME}}.txt",


rule make:
    output:
        "out/{{name}}.txt",
    shell:
        "echo > {{output}}"
"""


@pytest.mark.parametrize(
    "accept, planned",
    [
        ("accept_configured_wildcards([NAME])", True),
        ("accept_configured_wildcards(['obj_1'])", False),  # another name: Snakemake's own guard
        ("", False),
    ],
    ids=["configured", "other name configured", "none configured"],
)
def test_the_recursion_guard_accepts_the_configured_names_only(tmp_path, accept, planned):
    (tmp_path / "Snakefile").write_text(_PERIODIC.format(accept=accept))
    out = _snakemake(tmp_path, "-n")
    text = out.stdout + out.stderr
    assert (out.returncode == 0) is planned, text[-2000:]
    assert ("periodically repeated" in text) is not planned, text[-2000:]


# --------------------------------------------------------------------------- outputs kept, outdated

_FAILING = """
from synergrasp.snakemake_adapter import keep_outputs_until_replaced, outdate_failed_outputs


rule make:
    input:
        "in.txt",
    output:
        "out.txt",
        directory("pages"),
    script:
        "make.py"


{keep}
"""

#: The job: its input copied to both outputs, or a failure on an input starting with "bad".
_MAKE = """
import os

text = open(snakemake.input[0]).read()
if text.startswith("bad"):
    raise ValueError("bad input")
open(snakemake.output[0], "w").write(text)
os.makedirs(snakemake.output[1], exist_ok=True)
open(os.path.join(snakemake.output[1], "index.html"), "w").write(text)
"""

_KEEP = """keep_outputs_until_replaced(workflow)


onerror:
    outdate_failed_outputs(workflow)
"""


def _failing_run(tmp_path: Path, keep: bool) -> Path:
    """A finished run of the small workflow, then its input corrupted and the run failed."""
    (tmp_path / "Snakefile").write_text(_FAILING.format(keep=_KEEP if keep else ""))
    (tmp_path / "make.py").write_text(_MAKE)
    (tmp_path / "in.txt").write_text("first")
    assert _snakemake(tmp_path).returncode == 0
    (tmp_path / "in.txt").write_text("bad")
    failed = _snakemake(tmp_path)
    assert failed.returncode != 0 and "bad input" in failed.stdout + failed.stderr
    return tmp_path


def test_a_failed_job_keeps_the_outputs_it_would_replace(tmp_path):
    run = _failing_run(tmp_path, keep=True)
    assert (run / "out.txt").read_text() == "first"
    assert (run / "pages" / "index.html").read_text() == "first"


def test_without_the_adapter_snakemake_deletes_a_failed_jobs_outputs(tmp_path):
    """What the adapter changes (the test above could fail): Snakemake's own behaviour."""
    run = _failing_run(tmp_path, keep=False)
    assert not (run / "out.txt").exists() and not (run / "pages").exists()


def test_a_kept_output_is_outdated_so_the_next_run_redoes_it(tmp_path):
    run = _failing_run(tmp_path, keep=True)
    plan = _snakemake(run, "-n")
    assert plan.returncode == 0 and "rule make:" in plan.stdout + plan.stderr, plan.stdout[-2000:]
    (run / "in.txt").write_text("second")
    assert _snakemake(run).returncode == 0
    assert (run / "out.txt").read_text() == "second"
    assert (run / "pages" / "index.html").read_text() == "second"


def test_a_killed_runs_backup_of_a_folder_does_not_stop_the_next_backup(tmp_path):
    """Snakemake copies a kept folder output to .snakemake/backups before its job; a backup
    left by a killed run made that copy fail. The adapter replaces it, and a failing job
    restores the folder's current content, not the stale one."""
    (tmp_path / "Snakefile").write_text(_FAILING.format(keep=_KEEP))
    (tmp_path / "make.py").write_text(_MAKE)
    (tmp_path / "in.txt").write_text("current")
    assert _snakemake(tmp_path).returncode == 0
    stale = tmp_path / ".snakemake" / "backups" / "pages"
    stale.mkdir(parents=True)
    (stale / "index.html").write_text("stale")
    (tmp_path / "in.txt").write_text("bad")
    out = _snakemake(tmp_path)
    assert "bad input" in out.stdout + out.stderr and "FileExistsError" not in out.stdout + out.stderr
    assert (tmp_path / "pages" / "index.html").read_text() == "current"


# --------------------------------------------------------------------------- the scheduler's timers

_TIMERS = """
import threading

from synergrasp.snakemake_adapter import cancel_scheduler_timers


rule all:
    input:
        "b.txt",


rule a:
    output:
        "a.txt",
    shell:
        "echo > {output}"


rule b:
    input:
        "a.txt",
    output:
        "b.txt",
    shell:
        "echo > {output}"


def _pending():
    return [t for t in threading.enumerate() if isinstance(t, threading.Timer) and not t.finished.is_set()]


onsuccess:
    before = len(_pending())
    cancel_scheduler_timers()
    open("timers.txt", "w").write(f"{before} {len(_pending())}")
"""


def test_the_schedulers_timers_are_cancelled_at_the_end_of_a_run(tmp_path):
    """With the profile's job-rate timespan (1000 s) Snakemake leaves a timer per scheduling
    round; at the end of the run the adapter cancels every one, so Snakemake exits."""
    (tmp_path / "Snakefile").write_text(_TIMERS)
    out = _snakemake(tmp_path, "--max-jobs-per-timespan", "10000/1000s")
    assert out.returncode == 0, out.stderr[-2000:]
    before, after = map(int, (tmp_path / "timers.txt").read_text().split())
    assert before > 0 and after == 0


def test_a_pending_timer_is_cancelled():
    timer = threading.Timer(60.0, lambda: None)
    timer.start()
    adapter.cancel_scheduler_timers()
    timer.join(5.0)
    assert not timer.is_alive()


# --------------------------------------------------------------------------- the workflow object


def test_the_workflows_rules_are_snakemakes_parse():
    names = {rule.name for rule in adapter.workflow_rules(ROOT / "Snakefile", ROOT)}
    assert {"all", "figures", "simulate", "optimise_shard", "optimise", "tables"} <= names


# --------------------------------------------------------------------------- job groups

#: A workflow of N objects, each with the profile's grouped rules mesh_parts -> simulate; when it
#: runs, it prints the run's groups and limits as the adapter reads them (Snakemake hands the
#: workflow its groups only to run it).
_GROUPED = """
from synergrasp.snakemake_adapter import group_limits


onstart:
    print("LIMITS", group_limits(workflow))


rule all:
    input:
        expand("out/{{object}}.sim", object=range({n})),


rule mesh_parts:
    output:
        "out/{{object}}.parts",
    shell:
        "touch {{output}}"


rule simulate:
    input:
        "out/{{object}}.parts",
    output:
        "out/{{object}}.sim",
    shell:
        "touch {{output}}"
"""


def _with_slurm_profile(tmp_path: Path, n: int, *args: str) -> str:
    """Snakemake's output on the workflow of ``n`` objects with profiles/slurm and ``args``."""
    (tmp_path / "Snakefile").write_text(_GROUPED.format(n=n))
    env = {**os.environ, "SBATCH_PARTITION": "main", "SBATCH_ACCOUNT": ""}
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "-s",
            str(tmp_path / "Snakefile"),
            "--workflow-profile",
            str(ROOT / "profiles" / "slurm"),
        ]
        + ["--slurm-no-account", *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout + out.stderr


def test_the_slurm_profile_groups_twenty_objects_a_job_within_a_node(tmp_path):
    # planned on SLURM: 45 objects' 90 jobs, 20 objects a group job: 3 jobs (20, 20 and 5 objects)
    assert _with_slurm_profile(tmp_path, 45, "-n").count("Group job object") == 3
    assert _with_slurm_profile(tmp_path, 45, "-n", "--group-components", "object=1").count("Group job object") == 45
    # run here (the profile's settings, the executor aside): its groups, cores 4 and mem_mb 16000
    groups = {"mesh_parts": "object", "search": "object", "simulate": "object", "optimise_shard": "object"}
    assert f"LIMITS ({groups!r}, 4, 16000)" in _with_slurm_profile(tmp_path, 3, "--executor", "local")
    # the node size given on the command line replaces the profile's
    text = _with_slurm_profile(tmp_path, 3, "--executor", "local", "-F", "--cores", "2", "--resources", "mem_mb=3000")
    assert f"LIMITS ({groups!r}, 2, 3000)" in text


def test_a_group_jobs_request_is_laid_within_the_node_by_hand():
    shard = {"threads": 1, "mem_mb": 700, "runtime": 4}
    # 20 shards side by side: 20 CPUs, 14,000 MB, 4 min - more than a 2-CPU node has
    assert adapter.group_request([[shard] * 20], None, None) == {"threads": 20, "mem_mb": 14000, "runtime": 4}
    # within 2 cores: two at a time, 10 layers of 4 min
    assert adapter.group_request([[shard] * 20], 2, 16000) == {"threads": 2, "mem_mb": 1400, "runtime": 40}
    # within 2,000 MB (4 cores): two at a time again, by memory
    assert adapter.group_request([[shard] * 20], 4, 2000) == {"threads": 2, "mem_mb": 1400, "runtime": 40}
    # levels: three 2-thread searches of 7 min, then three 1-thread closures of 1 min, on 4 cores:
    # 2 + 1 searches (14 min, 2 x 1,300 MB), then the 3 closures in one layer (1 min)
    search, closure = {"threads": 2, "mem_mb": 1300, "runtime": 7}, {"threads": 1, "mem_mb": 300, "runtime": 1}
    assert adapter.group_request([[search] * 3, [closure] * 3], 4, 16000) == {"threads": 4, "mem_mb": 2600, "runtime": 15}
    # on 2 cores: one search at a time (21 min), closures 2 + 1 (2 min)
    assert adapter.group_request([[search] * 3, [closure] * 3], 2, 16000) == {"threads": 2, "mem_mb": 1300, "runtime": 23}


# --------------------------------------------------------------------------- the scan

#: Snakemake's public modules (its documented API and what a Snakefile is documented to import).
PUBLIC_MODULES = {"api", "settings", "exceptions", "logging", "utils"}
#: The attributes of the ``snakemake`` object a rule's script is handed.
SCRIPT_OBJECT = {
    "input",
    "output",
    "params",
    "wildcards",
    "threads",
    "resources",
    "log",
    "config",
    "rule",
    "scriptdir",
    "bench_iteration",
}
#: The attributes of the Snakefile's ``workflow`` object the documentation describes.
PUBLIC_WORKFLOW = {"basedir", "current_basedir", "snakefile", "source_path"}


def private_uses(text: str, snakefile: bool) -> list[str]:
    """The private Snakemake names ``text`` uses: a ``snakemake.<module>`` outside the public
    modules (imported or named), ``from snakemake import <name>``, an attribute with a
    leading underscore of a Snakemake API object, and in a Snakefile or rule file a
    ``workflow.<attribute>`` the documentation does not describe."""
    found = [f"snakemake.{m}" for m in re.findall(r"\bsnakemake\.(\w+)", text) if m not in PUBLIC_MODULES | SCRIPT_OBJECT]
    found += [f"from snakemake import {n}" for n in re.findall(r"^\s*from snakemake import (\w+)", text, re.M)]
    found += re.findall(r"\b(?:api|wf|dag|workflow)\._\w+", text)
    if snakefile:
        found += [f"workflow.{a}" for a in re.findall(r"(?<![\w./])workflow\.(\w+)", text) if a not in PUBLIC_WORKFLOW]
    return found


def _sources() -> list[Path]:
    files = [ROOT / "Snakefile", *(ROOT / "workflow").rglob("*.smk")]
    for folder in ("src", "workflow", "tests", "tools", "benchmarks"):
        files += (ROOT / folder).rglob("*.py")
    mine = {ROOT / "src" / "synergrasp" / "snakemake_adapter.py", Path(__file__).resolve()}
    return sorted(set(files) - mine)


def test_the_scan_finds_a_planted_private_name():
    planted = "import snakemake.dag\nfrom snakemake.persistence import FileBackupMixin\nrules = wf._workflow.rules\n"
    assert private_uses(planted, snakefile=False) == ["snakemake.dag", "snakemake.persistence", "wf._workflow"]
    assert private_uses("print(snakemake.output.table, snakemake.params.cfg)", snakefile=False) == []
    assert private_uses("x = workflow.scheduler\ny = workflow.basedir\n", snakefile=True) == ["workflow.scheduler"]


def test_no_module_outside_the_adapter_uses_a_private_snakemake_name():
    found = {}
    for path in _sources():
        uses = private_uses(path.read_text(), snakefile=path.suffix != ".py")
        if uses:
            found[path.relative_to(ROOT).as_posix()] = uses
    assert len(_sources()) > 100 and found == {}
