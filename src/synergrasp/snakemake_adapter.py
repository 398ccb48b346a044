"""Every use of a Snakemake internal, in one place: what the workflow needs from Snakemake that
its public interfaces (the Snakefile's directives, ``snakemake.api``, ``snakemake.exceptions``,
``snakemake.logging``, ``snakemake.utils``) do not give. Written for one Snakemake release
series, :data:`WRITTEN_FOR`; :func:`check_version` refuses any other with one line before the
workflow is read, so an upgrade cannot silently break what is below. The behaviours, each
tested on a small workflow of its own (tests/test_snakemake_adapter.py):

- the wildcard-recursion guard accepts the configured names (:func:`accept_configured_wildcards`);
- every output is kept until its replacement is complete (:func:`keep_outputs_until_replaced`)
  and a failed job's kept outputs are outdated (:func:`outdate_failed_outputs`);
- the scheduler's timers are cancelled at the end of a run (:func:`cancel_scheduler_timers`);
- what the workflow object holds: its configuration files, the SLURM executor's settings, the
  groups and the limits a group's jobs are laid within, its rules, the rules run where
  Snakemake runs (:func:`config_files`, :func:`slurm_settings`, :func:`group_limits`,
  :func:`workflow_rules`, :func:`run_locally`);
- what Snakemake asks the scheduler for a group job (:func:`group_request`);
- the modules a job's script and the ``snakemake`` command load (:func:`load_snakemake_modules`,
  which ``synergrasp.warm_up`` runs to write their bytecode).

No other module of the project names a private Snakemake module or attribute
(tests/test_snakemake_adapter.py scans the sources). Imports nothing of the project.
"""

from __future__ import annotations

import importlib.metadata
import os
import shutil
import sys
import threading
from collections.abc import Iterable, Mapping
from pathlib import Path
from types import SimpleNamespace
from typing import Any

__all__ = [
    "WRITTEN_FOR",
    "check_version",
    "accept_configured_wildcards",
    "keep_outputs_until_replaced",
    "outdate_failed_outputs",
    "cancel_scheduler_timers",
    "config_files",
    "slurm_settings",
    "group_limits",
    "group_request",
    "load_snakemake_modules",
    "run_locally",
    "workflow_rules",
]

#: The Snakemake release series (major.minor) whose internals this module was written for and
#: tested on (environment.lock pins one release of it).
WRITTEN_FOR = "9.27"


def version_problem(version: str) -> str | None:
    """The one line refusing Snakemake ``version``, None for a release of :data:`WRITTEN_FOR`."""
    if version.split(".")[:2] == WRITTEN_FOR.split("."):
        return None
    return (
        f"synergrasp's workflow uses Snakemake internals written for Snakemake {WRITTEN_FOR}.x "
        f"(synergrasp.snakemake_adapter), and this is Snakemake {version}: install the locked "
        f"environment (make venv), or port snakemake_adapter and its tests to {version}"
    )


def check_version(version: str | None = None) -> None:
    """Stop with :func:`version_problem`'s line alone and exit status 1 unless Snakemake
    ``version`` (default: the installed one) is of the series :data:`WRITTEN_FOR`."""
    problem = version_problem(version or importlib.metadata.version("snakemake"))
    if problem:
        print(problem, file=sys.stderr, flush=True)
        raise SystemExit(1)


# --------------------------------------------------------------------------- the recursion guard


def accept_configured_wildcards(values: Iterable[str]) -> None:
    """Let Snakemake's guard against endlessly recursing wildcards (a value ending in one
    substring repeated 20 times, e.g. ``obj_`` and twenty zeros) accept ``values``.

    The guard protects rules whose wildcards may match anything; this workflow constrains
    each wildcard to the configured names exactly (common.smk), so a configured name cannot
    recurse. Every other value is still checked by Snakemake's own detector. Snakemake has no
    public setting for the guard (its ``snakemake.dag.PeriodicityDetector`` is replaced)."""
    import snakemake.dag

    base = getattr(snakemake.dag.PeriodicityDetector, "_snakemake_detector", snakemake.dag.PeriodicityDetector)
    accepted = frozenset(values)

    class ConfiguredNames(base):  # type: ignore[misc, valid-type]
        _snakemake_detector = base

        def is_periodic(self, value: str) -> Any:
            return None if value in accepted else super().is_periodic(value)

    snakemake.dag.PeriodicityDetector = ConfiguredNames


# --------------------------------------------------------------------------- outputs kept, outdated


def keep_outputs_until_replaced(workflow: Any) -> None:
    """Keep every output of the workflow's rules until its replacement is complete.

    Snakemake deletes a job's existing outputs before the job starts and deletes what is
    there again when it fails, so a failing rerun (a corrupted input, a full disk) would cost
    finished results. Outputs flagged ``update`` (Snakemake's public flag, set here on every
    rule's outputs, those of rules written later in any style included) are kept instead:
    Snakemake copies each to ``.snakemake/backups`` before the job and copies it back when
    the job fails. The package's writers replace a file or folder only once its new content
    is complete (``synergrasp.file_output``), so an output is always its old or its new
    complete content. A backup of a folder left by a killed run is replaced (Snakemake's own
    copy would fail on it). :func:`outdate_failed_outputs` makes the next run redo the
    outputs restored this way. Call once after every rule is defined."""
    import snakemake.persistence

    for rule in workflow.rules:
        for output in rule.output:
            flags = dict(output.flags)
            output.clone_flags(output)  # a plain name gets a flags mapping of its own (emptied)
            output.flags.update(flags, update=True)
    persistence = snakemake.persistence.FileBackupMixin
    if not getattr(persistence.backup_output, "_replaces_stale", False):
        backup = persistence.backup_output

        def backup_output(self: Any, path: Path) -> None:
            stale = self._get_backup_path(path)
            if stale.is_dir() and path.is_dir():
                shutil.rmtree(stale)
            backup(self, path)

        backup_output._replaces_stale = True  # type: ignore[attr-defined]
        persistence.backup_output = backup_output


def outdate_failed_outputs(workflow: Any) -> list[str]:
    """After a failed run: make the next run redo each output a failed job kept
    (:func:`keep_outputs_until_replaced`). Snakemake records a failed job as finished, with
    its inputs' checksums, and would take the kept old output for the new one; so the
    record is removed (Snakemake's clean-up of a job's metadata) and the output dated one
    second before the job's newest input. Returns the paths outdated."""
    scheduler = getattr(workflow, "scheduler", None)
    outdated = []
    for job in getattr(scheduler, "failed", ()):
        inputs = [os.stat(f).st_mtime for f in job.input if os.path.exists(f)]
        if not inputs:
            continue
        workflow.persistence.cleanup(job)
        when = max(inputs) - 1.0
        for output in job.output:
            path = Path(output)
            for stamped in (path, path / ".snakemake_timestamp"):
                if stamped.exists():
                    os.utime(stamped, (when, when))
            if path.exists():
                outdated.append(str(path))
    return outdated


# --------------------------------------------------------------------------- the scheduler's timers


def cancel_scheduler_timers() -> None:
    """Cancel the scheduler's pending re-evaluation timers (``threading.Timer``, not daemon
    threads: Snakemake's job-rate limiter starts one per finished job) once the run is over,
    so that Snakemake exits at once instead of a job-rate timespan later
    (profiles/default/config.yaml). The workflow starts no timer of its own."""
    for thread in threading.enumerate():
        if isinstance(thread, threading.Timer):
            thread.cancel()


# --------------------------------------------------------------------------- the workflow object


def config_files(workflow: Any) -> list[str]:
    """The configuration files Snakemake read (the Snakefile's ``configfile:`` and ``--configfile``)."""
    return [str(path) for path in workflow.configfiles]


def slurm_settings(workflow: Any) -> tuple[Any, dict[str, Any]] | None:
    """For a run on the SLURM executor: its settings and the default resources as written in
    the profile (``$SBATCH_ACCOUNT`` unexpanded); None for any other executor."""
    if workflow.executor_plugin.name != "slurm":
        return None
    raw = {key: value.raw for key, value in workflow.resource_settings.default_resources.items()}
    return workflow.executor_settings, raw


def group_limits(workflow: Any) -> tuple[dict[str, str], int | None, int | None]:
    """The run's job groups (``--groups``: rule -> group) and the limits Snakemake lays a group
    job's jobs within: ``--cores`` (CPUs) and ``--resources mem_mb`` (MB), None where not given."""
    limits = workflow.global_resources
    return dict(workflow.group_settings.overwrite_groups), limits.get("_cores").value, limits.get("mem_mb").value


def group_request(levels: Iterable[Iterable[Mapping[str, int]]], cores: int | None, mem_mb: int | None) -> dict[str, int]:
    """What Snakemake asks the scheduler for a group job: ``threads`` (CPUs), ``mem_mb`` (MB) and
    ``runtime`` (minutes), from its jobs' (``threads``, ``mem_mb``, ``runtime``) level by level
    (a level's jobs need only earlier levels' outputs), within ``cores`` and ``mem_mb`` (the
    run's ``--cores`` and ``--resources mem_mb``; None: no limit). Snakemake's own computation
    (its GroupResources.basic_layered): a level's jobs run side by side as far as the limits
    allow, the rest in further layers one after another; CPUs and memory are a layer's sum,
    the largest over layers; the runtime is a layer's longest job, summed over layers."""
    from snakemake.resources import GroupResources, Resources

    jobs = [
        [
            SimpleNamespace(resources={"_cores": j["threads"], "mem_mb": j["mem_mb"], "runtime": j["runtime"]}, pipe_group=None)
            for j in level
        ]
        for level in levels
    ]
    limits = {name: value for name, value in (("_cores", cores), ("mem_mb", mem_mb)) if value is not None}
    asked = GroupResources.basic_layered(
        jobs, Resources.from_mapping(limits), run_local=False, additive_resources=["runtime"], sortby=["runtime"]
    )
    return {"threads": asked["_cores"], "mem_mb": asked["mem_mb"], "runtime": asked["runtime"]}


def run_locally(workflow: Any, rules: Iterable[str]) -> None:
    """Run ``rules`` where Snakemake runs, not on the cluster (the ``localrules:`` directive,
    which takes only names written in the Snakefile)."""
    workflow.localrules(*rules)


def workflow_rules(snakefile: Path, workdir: Path) -> list[Any]:
    """Every rule of the workflow in ``snakefile`` as Snakemake parses it (its ``name``,
    ``output``, ``log``, ``benchmark``, ``script``), without running anything."""
    from snakemake.api import SnakemakeApi
    from snakemake.settings.types import ConfigSettings, OutputSettings, ResourceSettings

    with SnakemakeApi(OutputSettings(quiet={"all"})) as api:
        parsed = api.workflow(
            resource_settings=ResourceSettings(),
            snakefile=Path(snakefile),
            workdir=Path(workdir),
            config_settings=ConfigSettings(),
        )
        return list(parsed._workflow.rules)


def load_snakemake_modules() -> None:
    """Import the Snakemake modules a job loads (its script's preamble imports ``snakemake.script``
    and unpickles objects of ``snakemake.io``) and those the ``snakemake`` command loads."""
    import snakemake.cli  # noqa: F401
    import snakemake.io  # noqa: F401
    import snakemake.script  # noqa: F401
